//! `summary.json` of a dynamic hexapod run: what the planar run writes,
//! plus Newton iterations per step, the peak torque and power of every
//! joint, the distance the body moved and its final height.

use std::collections::BTreeMap;

use fbd_contact::{StateCode, Surface};
use fbd_dynamics::PointKind;
use fbd_sim::robot::RobotRecord;
use fbd_sim::spatial::{SpatialControl, SpatialParams};
use fbd_sim::{Event, RunSummary};
use serde::Serialize;

use super::Layout;
use super::csv::Slots;
use crate::output::{self, Energy, EventJson, PeakForce};
use crate::steptime::StepTimes;

/// The largest actuator torque and power of one joint over the run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct JointPeak {
    /// Leg number (1–6).
    pub leg: usize,
    /// `theta1`, `theta2` or `theta3`.
    pub joint: &'static str,
    /// Largest |τ| (N·m).
    pub torque: f64,
    /// Largest |τ·θ̇| (W).
    pub power: f64,
}

/// `summary.json` of a dynamic hexapod run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SpatialSummary {
    /// Status, error and the solver's counters (as every dynamic run).
    #[serde(flatten)]
    pub head: output::RunHead,
    /// Wall time (s) of the start-up stability check of the joint
    /// controller (before the stepping loop, not in `wall_seconds`); near
    /// zero when an earlier run of the process had the same robot and
    /// poses.
    pub stability_check_seconds: f64,
    /// Contact, joint-limit and retried-step events, as `events.csv`.
    pub events: Vec<EventJson>,
    /// Retries, state-search closures and the law audit (as every dynamic
    /// run).
    #[serde(flatten)]
    pub audit: output::RunAudit,
    /// `"hexapod"`.
    pub model: &'static str,
    /// `"dynamic"` (the 3D FBD dynamics; a kinematic run says `walking` or
    /// `standing`).
    pub run: &'static str,
    /// The joint controller: `none`, `pd`, `trajectory` or `gait`.
    pub control: &'static str,
    /// Leg numbers of the model.
    pub legs: Vec<usize>,
    /// Time step (s).
    pub dt: f64,
    /// Configured duration (s).
    pub duration: f64,
    /// Steps the run was to solve.
    pub steps_planned: usize,
    /// Every `stride`-th step is in `trajectory.csv`.
    pub stride: usize,
    /// Rows of `trajectory.csv`.
    pub rows_written: usize,
    /// Contact points of the model, e.g. `["tip1", "knee1", "hip1", …]`.
    pub contact_points: Vec<String>,
    /// First change of each leg's foot out of ST1 (s), e.g. `"leg4"`.
    pub first_touchdown: BTreeMap<String, Option<f64>>,
    /// First change of each leg's foot into ST3 (s).
    pub first_slip: BTreeMap<String, Option<f64>>,
    /// Largest normal force `n` and tangential force magnitude `fa` of
    /// each contact point (N).
    pub peak_contact_force: BTreeMap<String, PeakForce>,
    /// Largest force magnitude of each joint, `hip{n}` and `knee{n}` (N).
    pub peak_joint_force: BTreeMap<String, f64>,
    /// Largest joint force magnitude of all joints (N).
    pub peak_joint_force_max: f64,
    /// Per joint: the largest |τ| and |τ·θ̇|, legs in order, θ1 to θ3.
    pub peak_actuation: Vec<JointPeak>,
    /// Largest |τ| over all joints (N·m).
    pub peak_torque_max: f64,
    /// Largest |τ·θ̇| over all joints (W).
    pub peak_power_max: f64,
    /// Body centre `(Rx, Ry, Rz)` at the first step (m; null if none).
    pub initial_position: Option<[f64; 3]>,
    /// Body centre at the last solved step (m; null if none).
    pub final_position: Option<[f64; 3]>,
    /// `final_position − initial_position` (m).
    pub displacement: [f64; 3],
    /// Horizontal distance the body centre moved, `√(Δx² + Δz²)` (m).
    pub distance: f64,
    /// Horizontal path length of the body centre over every step (m).
    pub path_length: f64,
    /// Body height `Ry` at the last solved step (m; null if none).
    pub final_height: Option<f64>,
    /// Energy at the last solved step (null if none).
    pub final_energy: Option<Energy>,
}

/// What the summary needs, gathered at every step without allocating.
pub(crate) struct Collector {
    surface: Surface,
    iter_max: usize,
    /// `|τ|` and `|τ·θ̇|` peaks per leg of the layout and joint.
    torque: Vec<[f64; 3]>,
    power: Vec<[f64; 3]>,
    /// Per leg of the layout: hip and knee force magnitude peaks.
    joint_force: Vec<[f64; 2]>,
    /// Per contact row of the record (matched to names at the end).
    contact: Vec<(usize, PointKind, PeakForce)>,
    first: Option<[f64; 3]>,
    last: Option<(usize, f64, [f64; 3], f64, f64)>,
    path: f64,
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

impl Collector {
    pub fn new(layout: &Layout, surface: &Surface) -> Self {
        let n = layout.legs.len();
        Self {
            surface: surface.clone(),
            iter_max: 0,
            torque: vec![[0.0; 3]; n],
            power: vec![[0.0; 3]; n],
            joint_force: vec![[0.0; 2]; n],
            contact: Vec::new(),
            first: None,
            last: None,
            path: 0.0,
        }
    }

    /// Adds one step; `s` matches the record's rows to the layout.
    pub fn push(&mut self, r: &RobotRecord, s: &Slots) {
        self.iter_max = self.iter_max.max(r.newton_iterations);
        for i in 0..s.legs.len() {
            let Some(l) = s.leg(r, i) else {
                continue;
            };
            for j in 0..3 {
                self.torque[i][j] = self.torque[i][j].max(l.torque[j].abs());
                self.power[i][j] = self.power[i][j].max((l.torque[j] * l.rate[j]).abs());
            }
            self.joint_force[i][0] = self.joint_force[i][0].max(norm(l.hip_force));
            self.joint_force[i][1] = self.joint_force[i][1].max(norm(l.knee_force));
        }
        if self.contact.is_empty() {
            self.contact = s
                .contacts
                .iter()
                .map(|&(leg, kind)| (leg, kind, PeakForce::default()))
                .collect();
        }
        for (p, c) in self.contact.iter_mut().zip(&r.contacts) {
            // The tangential part: the force less its normal component
            // along the terrain normal at the point.
            let nu = self.surface.normal(c.point[0], c.point[2]);
            let ft = norm(std::array::from_fn(|i| c.force[i] - c.normal * nu[i]));
            p.2.n = p.2.n.max(c.normal.abs());
            p.2.fa = p.2.fa.max(ft);
        }
        let pos = [r.q[0], r.q[1], r.q[2]];
        if self.first.is_none() {
            self.first = Some(pos);
        }
        if let Some(last) = &self.last {
            self.path += (pos[0] - last.2[0]).hypot(pos[2] - last.2[2]);
        }
        self.last = Some((r.step, r.t, pos, r.kinetic, r.potential));
    }

    /// The summary of the run.
    pub fn finish(
        self,
        params: &SpatialParams,
        steps_planned: usize,
        layout: &Layout,
        run: &RunSummary,
        rows: usize,
    ) -> SpatialSummary {
        let times = StepTimes::new(params.dt);
        let by_leg = |pred: &dyn Fn(&Event) -> bool| -> BTreeMap<String, Option<f64>> {
            layout
                .legs
                .iter()
                .map(|&n| {
                    let t = run
                        .events
                        .iter()
                        .find(|e| e.leg == n && e.point == PointKind::Tip && pred(e))
                        .map(|e| times.value(e.step, e.t));
                    (format!("leg{n}"), t)
                })
                .collect()
        };
        let mut peak_joint_force = BTreeMap::new();
        let mut peak_actuation = Vec::with_capacity(3 * layout.legs.len());
        for (i, &n) in layout.legs.iter().enumerate() {
            peak_joint_force.insert(format!("hip{n}"), self.joint_force[i][0]);
            peak_joint_force.insert(format!("knee{n}"), self.joint_force[i][1]);
            for (j, joint) in ["theta1", "theta2", "theta3"].into_iter().enumerate() {
                peak_actuation.push(JointPeak {
                    leg: n,
                    joint,
                    torque: self.torque[i][j],
                    power: self.power[i][j],
                });
            }
        }
        let max = |it: &mut dyn Iterator<Item = f64>| it.fold(0.0, f64::max);
        let (first, last) = (self.first, self.last);
        let displacement = match (first, &last) {
            (Some(a), Some(b)) => [b.2[0] - a[0], b.2[1] - a[1], b.2[2] - a[2]],
            _ => [0.0; 3],
        };
        SpatialSummary {
            head: output::RunHead::of(run, steps_planned, self.iter_max),
            stability_check_seconds: 0.0,
            events: output::run_events(run, &times)
                .into_iter()
                .map(|e| e.2)
                .collect(),
            audit: output::RunAudit::of(run),
            model: "hexapod",
            run: "dynamic",
            control: match params.control {
                SpatialControl::None => "none",
                SpatialControl::Pd { .. } => "pd",
                SpatialControl::Trajectory { .. } => "trajectory",
                SpatialControl::Gait { .. } => "gait",
            },
            legs: layout.legs.clone(),
            dt: params.dt,
            duration: params.duration,
            steps_planned,
            stride: params.stride.max(1),
            rows_written: rows,
            contact_points: layout.point_names(params),
            first_touchdown: by_leg(&|e| e.from == StateCode::St1 && e.to != StateCode::St1),
            first_slip: by_leg(&|e| e.to == StateCode::St3),
            peak_contact_force: self
                .contact
                .into_iter()
                .map(|(leg, kind, p)| (format!("{}{leg}", kind.as_str()), p))
                .collect(),
            peak_joint_force_max: max(&mut peak_joint_force.values().copied()),
            peak_joint_force,
            peak_torque_max: max(&mut peak_actuation.iter().map(|p| p.torque)),
            peak_power_max: max(&mut peak_actuation.iter().map(|p| p.power)),
            peak_actuation,
            initial_position: first,
            final_position: last.as_ref().map(|l| l.2),
            displacement,
            distance: displacement[0].hypot(displacement[2]),
            path_length: self.path,
            final_height: last.as_ref().map(|l| l.2[1]),
            final_energy: last.map(|(step, t, _, kinetic, potential)| {
                Energy::at(&times, step, t, kinetic, potential)
            }),
        }
    }
}

//! `summary.json` of every model on the tree equations (the paper's
//! hexapod and every imported robot): one schema, [`TreeSummary`], and one
//! collector of its figures, [`Collector`], fed by the one record of every
//! robot ([`RobotRecord`]) without allocating. What is model-specific is
//! data the model supplies: the keys of its contact points, joints,
//! reactions and feet ([`Keys`]: the hexapod's `tip4`, `hip1`, `leg4`,
//! `theta1` of leg 4; a robot's point and joint names) and the facts
//! about the run ([`Facts`]: the `model` string, a robot's name, the
//! hexapod's `run`, `control` and `legs`). The events keep each model's
//! own type (the hexapod's [`crate::output::EventJson`] with legs, a
//! robot's [`crate::robot_run::RobotEvent`] with points).

use std::collections::BTreeMap;

use fbd_contact::{StateCode, Surface};
use fbd_sim::RunSummary;
use fbd_sim::robot::RobotRecord;
use serde::Serialize;

use crate::output::{Energy, PeakForce, RunAudit, RunExtent, RunHead};
use crate::steptime::StepTimes;

/// The largest actuator torque and power of one joint over the run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct JointPeak {
    /// The hexapod's leg number (1–6; absent for a robot).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub leg: Option<usize>,
    /// The joint: the hexapod's `theta1`, `theta2` or `theta3` of its leg;
    /// a robot's joint name.
    pub joint: String,
    /// Largest |τ| (N·m).
    pub torque: f64,
    /// Largest |τ·θ̇| (W).
    pub power: f64,
}

/// The hexapod's description of its run in `summary.json` (after
/// `model`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HexapodRun {
    /// `"dynamic"` (the 3D FBD dynamics; a kinematic run says `walking` or
    /// `standing`).
    pub run: &'static str,
    /// The joint controller: `none`, `pd`, `trajectory` or `gait`.
    pub control: &'static str,
    /// Leg numbers of the model.
    pub legs: Vec<usize>,
}

/// `summary.json` of a run of any model on the tree equations, with the
/// model's events `E`. The peaks, positions, path and final energy are
/// over the steps the summary is given ([`Collector::push`]): every step
/// of a hexapod run, the written rows (every `[output] stride`-th step) of
/// a robot's; the first touchdowns and slips are over every step (the
/// run's events).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct TreeSummary<E> {
    /// Status, error and the solver's counters (as every dynamic run).
    #[serde(flatten)]
    pub head: RunHead,
    /// Wall time (s) of the start-up stability check of the hexapod's joint
    /// controller (before the stepping loop, not in `wall_seconds`); near
    /// zero when an earlier run of the process had the same robot and
    /// poses. Absent for a model without one (a robot).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stability_check_seconds: Option<f64>,
    /// Contact, joint-limit and retried-step events, as `events.csv`.
    pub events: Vec<E>,
    /// Retries, state-search closures and the law audit (as every dynamic
    /// run).
    #[serde(flatten)]
    pub audit: RunAudit,
    /// `"hexapod"` or `"robot"`.
    pub model: &'static str,
    /// A robot's name (from its description; absent for the hexapod).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub robot: Option<String>,
    /// The hexapod's `run`, `control` and `legs` (absent for a robot).
    #[serde(flatten)]
    pub hexapod: Option<HexapodRun>,
    /// The run's extent and its contact points' figures (the hexapod's
    /// feet by leg, `"leg4"`; a robot's by contact point).
    #[serde(flatten)]
    pub extent: RunExtent,
    /// A robot's largest normal force of any contact point (N; the largest
    /// `n` of `peak_contact_force`, 0 without contact points; absent for
    /// the hexapod).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub peak_normal_force: Option<f64>,
    /// Largest force magnitude of each joint's reaction (N): the
    /// hexapod's `hip{n}` and `knee{n}`, a robot's by the reaction's first
    /// joint (as its `<joint>_fx` columns).
    pub peak_joint_force: BTreeMap<String, f64>,
    /// Largest joint force magnitude of all joints (N).
    pub peak_joint_force_max: f64,
    /// Per joint: the largest |τ| and |τ·θ̇| (the hexapod's legs in order,
    /// θ1 to θ3; a robot's joints in model order).
    pub peak_actuation: Vec<JointPeak>,
    /// Largest |τ| over all joints (N·m).
    pub peak_torque_max: f64,
    /// Largest |τ·θ̇| over all joints (W).
    pub peak_power_max: f64,
    /// Root (body centre) `(Rx, Ry, Rz)` at the first step (m; null if
    /// none).
    pub initial_position: Option<[f64; 3]>,
    /// Root at the last step given (m; null if none); a robot's after its
    /// last solved step ([`Collector::end_at`]).
    pub final_position: Option<[f64; 3]>,
    /// `final_position − initial_position` (m).
    pub displacement: [f64; 3],
    /// Horizontal distance the root moved, `√(Δx² + Δz²)` (m).
    pub distance: f64,
    /// Horizontal path length of the root over the steps given (m).
    pub path_length: f64,
    /// Root height `Ry` of `final_position` (m; null if none).
    pub final_height: Option<f64>,
    /// Energy at the last step given (null if none).
    pub final_energy: Option<Energy>,
}

/// The keys of a model's figures in `summary.json`, each with where its
/// values are in the model's [`RobotRecord`]s (`None`: the model has no
/// such value; its figure stays 0 or null).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Keys {
    /// Per row of `record.contacts`: its key in `peak_contact_force`.
    pub contacts: Vec<String>,
    /// The keys of `first_touchdown` and `first_slip`, each with the
    /// contact row whose events count.
    pub feet: Vec<(String, Option<usize>)>,
    /// The keys of `peak_joint_force`, each with its reaction row.
    pub reactions: Vec<(String, Option<usize>)>,
    /// The entries of `peak_actuation`: leg (the hexapod's), joint name,
    /// and the joint's index in `record.torque` and `record.rate`.
    pub joints: Vec<(Option<usize>, String, Option<usize>)>,
}

/// What a model says about its run in `summary.json`, besides the run's
/// own figures.
#[derive(Clone, Debug, PartialEq)]
pub struct Facts {
    /// `"hexapod"` or `"robot"`.
    pub model: &'static str,
    /// A robot's name.
    pub robot: Option<String>,
    /// The hexapod's `run`, `control` and `legs`.
    pub hexapod: Option<HexapodRun>,
    /// Time step (s).
    pub dt: f64,
    /// Configured duration (s).
    pub duration: f64,
    /// Steps planned.
    pub steps_planned: usize,
    /// `[output] stride`.
    pub stride: usize,
    /// The contact points' names.
    pub contact_points: Vec<String>,
    /// The start-up stability check's wall time (s), for a model that has
    /// one.
    pub stability_check_seconds: Option<f64>,
    /// Whether `summary.json` has `peak_normal_force` (a robot's).
    pub peak_normal_force: bool,
}

/// The last step given: its step, time, root position and energies.
#[derive(Clone, Copy, Debug)]
struct Last {
    step: usize,
    t: f64,
    position: [f64; 3],
    kinetic: f64,
    potential: f64,
}

/// What the summary needs, gathered at every step given without
/// allocating.
#[derive(Clone, Debug)]
pub struct Collector {
    keys: Keys,
    surface: Surface,
    /// Steps given.
    given: usize,
    /// `|τ|` and `|τ·θ̇|` peaks per entry of `keys.joints`.
    torque: Vec<f64>,
    power: Vec<f64>,
    /// Force magnitude peaks per entry of `keys.reactions`.
    joint_force: Vec<f64>,
    /// Per contact row of the record.
    contact: Vec<PeakForce>,
    first: Option<[f64; 3]>,
    last: Option<Last>,
    /// The root after the last solved step, when the model gives it.
    end: Option<[f64; 3]>,
    path: f64,
}

fn norm(v: [f64; 3]) -> f64 {
    (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt()
}

impl Collector {
    /// A collector of the figures named by `keys`, the tangential contact
    /// forces measured against the normal of `surface`.
    pub fn new(keys: Keys, surface: &Surface) -> Self {
        Self {
            torque: vec![0.0; keys.joints.len()],
            power: vec![0.0; keys.joints.len()],
            joint_force: vec![0.0; keys.reactions.len()],
            contact: vec![PeakForce::default(); keys.contacts.len()],
            keys,
            surface: surface.clone(),
            given: 0,
            first: None,
            last: None,
            end: None,
            path: 0.0,
        }
    }

    /// Adds one step.
    pub fn push(&mut self, r: &RobotRecord) {
        self.given += 1;
        for (k, (_, _, j)) in self.keys.joints.iter().enumerate() {
            if let Some(j) = *j {
                self.torque[k] = self.torque[k].max(r.torque[j].abs());
                self.power[k] = self.power[k].max((r.torque[j] * r.rate[j]).abs());
            }
        }
        for (k, (_, i)) in self.keys.reactions.iter().enumerate() {
            if let Some(i) = *i {
                self.joint_force[k] = self.joint_force[k].max(norm(r.reaction_force[i]));
            }
        }
        for (p, c) in self.contact.iter_mut().zip(&r.contacts) {
            // The tangential part: the force less its normal component
            // along the terrain normal at the point.
            let nu = self.surface.normal(c.point[0], c.point[2]);
            let ft = norm(std::array::from_fn(|i| c.force[i] - c.normal * nu[i]));
            p.n = p.n.max(c.normal.abs());
            p.fa = p.fa.max(ft);
        }
        let position = [r.q[0], r.q[1], r.q[2]];
        if self.first.is_none() {
            self.first = Some(position);
        }
        if let Some(last) = &self.last {
            self.path += (position[0] - last.position[0]).hypot(position[2] - last.position[2]);
        }
        self.last = Some(Last {
            step: r.step,
            t: r.t,
            position,
            kinetic: r.kinetic,
            potential: r.potential,
        });
    }

    /// The model's coordinates `q` after its last solved step (a robot's
    /// run knows them; the steps given may stop short of it): the final
    /// position, the path's last stretch, and the initial position when no
    /// step was given (none solved: `q` is the start).
    pub fn end_at(&mut self, q: &[f64]) {
        let position = [q[0], q[1], q[2]];
        if let Some(last) = &self.last {
            self.path += (position[0] - last.position[0]).hypot(position[2] - last.position[2]);
        }
        self.first.get_or_insert(position);
        self.end = Some(position);
    }

    /// The summary of `run`, of which `rows` rows were written, with its
    /// `events` (the model's, in `events.csv`'s order).
    pub fn finish<E>(
        self,
        facts: Facts,
        run: &RunSummary,
        rows: usize,
        events: Vec<E>,
    ) -> TreeSummary<E> {
        let times = StepTimes::new(facts.dt);
        let foot = |pred: &dyn Fn(&fbd_sim::Event) -> bool| -> BTreeMap<String, Option<f64>> {
            self.keys
                .feet
                .iter()
                .map(|(key, c)| {
                    let t = c.and_then(|c| {
                        run.events
                            .iter()
                            .find(|e| e.contact == c && pred(e))
                            .map(|e| times.value(e.step, e.t))
                    });
                    (key.clone(), t)
                })
                .collect()
        };
        let first_touchdown = foot(&|e| e.from == StateCode::St1 && e.to != StateCode::St1);
        let first_slip = foot(&|e| e.to == StateCode::St3);
        let peak_joint_force: BTreeMap<String, f64> = self
            .keys
            .reactions
            .iter()
            .zip(&self.joint_force)
            .map(|((key, _), &f)| (key.clone(), f))
            .collect();
        let peak_actuation: Vec<JointPeak> = self
            .keys
            .joints
            .iter()
            .enumerate()
            .map(|(k, (leg, joint, _))| JointPeak {
                leg: *leg,
                joint: joint.clone(),
                torque: self.torque[k],
                power: self.power[k],
            })
            .collect();
        let peak_contact_force: BTreeMap<String, PeakForce> = if self.given > 0 {
            self.keys
                .contacts
                .iter()
                .cloned()
                .zip(self.contact)
                .collect()
        } else {
            BTreeMap::new()
        };
        let max = |it: &mut dyn Iterator<Item = f64>| it.fold(0.0, f64::max);
        let first = self.first;
        let last = self.last;
        let end = self.end.or(last.map(|l| l.position));
        let displacement = match (first, end) {
            (Some(a), Some(b)) => [b[0] - a[0], b[1] - a[1], b[2] - a[2]],
            _ => [0.0; 3],
        };
        TreeSummary {
            head: RunHead::of(run, facts.steps_planned, run.max_newton_iterations),
            stability_check_seconds: facts.stability_check_seconds,
            events,
            audit: RunAudit::of(run),
            model: facts.model,
            robot: facts.robot,
            hexapod: facts.hexapod,
            peak_normal_force: facts
                .peak_normal_force
                .then(|| max(&mut peak_contact_force.values().map(|p| p.n))),
            extent: RunExtent {
                dt: facts.dt,
                duration: facts.duration,
                steps_planned: facts.steps_planned,
                stride: facts.stride.max(1),
                rows_written: rows,
                contact_points: facts.contact_points,
                first_touchdown,
                first_slip,
                peak_contact_force,
            },
            peak_joint_force_max: max(&mut peak_joint_force.values().copied()),
            peak_joint_force,
            peak_torque_max: max(&mut peak_actuation.iter().map(|p| p.torque)),
            peak_power_max: max(&mut peak_actuation.iter().map(|p| p.power)),
            peak_actuation,
            initial_position: first,
            final_position: end,
            displacement,
            distance: displacement[0].hypot(displacement[2]),
            path_length: self.path,
            final_height: end.map(|p| p[1]),
            final_energy: last.map(|l| Energy::at(&times, l.step, l.t, l.kinetic, l.potential)),
        }
    }
}

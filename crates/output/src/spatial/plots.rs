//! The plots of a dynamic hexapod run, drawn from every step (min/max
//! reduced per time column, [`crate::plot::MinMax`]), one colour per leg
//! (the plots' shared palette):
//!
//! * `feet.svg` — the normal force of every foot, and its height against
//!   the height of the terrain under it (`ϱ(x, z)` at the foot, dashed);
//! * `torques.svg` — the actuator torques τ1, τ2, τ3 of every leg, one
//!   chart per joint;
//! * `body.svg` — the forward position, the body height `Ry`, roll and
//!   pitch, and the heading (the attitude derived from φ);
//! * `energy.svg` — kinetic, potential and total energy (as the planar
//!   run draws it).

use fbd_contact::Surface;
use fbd_sim::RunSummary;
use fbd_sim::robot::RobotRecord;
use plotters::style::RGBColor;

use super::Layout;
use super::csv::Slots;
use crate::plot::{
    self, Columns, EventMark, MinMax, PALETTE, PlotData, PlotResult, Style, Trace,
    stacked_time_chart,
};

/// The colour of leg `n` (1–6): the palette's `n`-th colour, as in every
/// hexapod plot.
fn leg_color(n: usize) -> RGBColor {
    PALETTE[(n + PALETTE.len() - 1) % PALETTE.len()]
}

/// Gathers the curves of a run step by step.
pub struct Recorder {
    /// The time columns of every curve below.
    columns: Columns,
    legs: Vec<usize>,
    normal: Vec<MinMax>,
    /// Per leg: the foot's height and the terrain's under it.
    height: Vec<[MinMax; 2]>,
    surface: Option<Surface>,
    torque: Vec<[MinMax; 3]>,
    body: [MinMax; 4],
    /// Forward position (m), roll, pitch, heading (°).
    attitude: [MinMax; 4],
    /// The first step's position and horizontal forward direction.
    origin: Option<([f64; 3], [f64; 2])>,
    energy: [MinMax; 3],
}

impl Recorder {
    /// For a run from `t = 0` to `t_end` of a model with `layout`.
    pub fn new(layout: &Layout, t_end: f64) -> Self {
        let m = || MinMax::new(0.0, t_end);
        Self {
            columns: Columns::new(0.0, t_end),
            legs: layout.legs.clone(),
            normal: layout.legs.iter().map(|_| m()).collect(),
            height: layout
                .legs
                .iter()
                .map(|_| std::array::from_fn(|_| m()))
                .collect(),
            surface: None,
            torque: layout
                .legs
                .iter()
                .map(|_| std::array::from_fn(|_| m()))
                .collect(),
            body: std::array::from_fn(|_| m()),
            attitude: std::array::from_fn(|_| m()),
            origin: None,
            energy: std::array::from_fn(|_| m()),
        }
    }

    /// Draws each foot's height against the terrain `surface` under it.
    pub fn with_surface(mut self, surface: &Surface) -> Self {
        self.surface = surface.exists().then(|| surface.clone());
        self
    }

    /// Adds one step; `s` matches the record's rows to the layout.
    ///
    /// Runs for every step: the step's time column is found once for all
    /// the curves ([`Columns::of`]).
    pub fn push(&mut self, r: &RobotRecord, s: &Slots) {
        let t = r.t;
        let col = self.columns.of(t);
        for (i, m) in self.normal.iter_mut().enumerate() {
            m.push_at(col, t, s.tips[i].map_or(0.0, |c| r.contacts[c].normal));
        }
        if let Some(surface) = &self.surface {
            for (i, [foot, ground]) in self.height.iter_mut().enumerate() {
                if let Some(c) = s.tips[i] {
                    let p = r.contacts[c].point;
                    foot.push_at(col, t, p[1]);
                    ground.push_at(col, t, surface.height(p[0], p[2]));
                }
            }
        }
        for (i, ms) in self.torque.iter_mut().enumerate() {
            let tau = s.legs[i].map_or([0.0; 3], |l| {
                let j = l.joint;
                [r.torque[j], r.torque[j + 1], r.torque[j + 2]]
            });
            for (m, v) in ms.iter_mut().zip(tau) {
                m.push_at(col, t, v);
            }
        }
        self.body[0].push_at(col, t, r.q[1]);
        let pose =
            fbd_kinematics::pose::BodyPose::new([r.q[0], r.q[1], r.q[2]], [r.q[3], r.q[4], r.q[5]]);
        let [roll, pitch, heading] = pose.attitude();
        let (o, f) = *self
            .origin
            .get_or_insert_with(|| ([r.q[0], r.q[1], r.q[2]], [-heading.sin(), -heading.cos()]));
        let forward = (r.q[0] - o[0]) * f[0] + (r.q[2] - o[2]) * f[1];
        for (m, v) in self.attitude.iter_mut().zip([
            forward,
            roll.to_degrees(),
            pitch.to_degrees(),
            heading.to_degrees(),
        ]) {
            m.push_at(col, t, v);
        }
        for k in 0..3 {
            self.body[1 + k].push_at(col, t, r.q[3 + k].to_degrees());
        }
        self.energy[0].push_at(col, t, r.kinetic);
        self.energy[1].push_at(col, t, r.potential);
        self.energy[2].push_at(col, t, r.kinetic + r.potential);
    }

    /// The curves, with the contact events of `run`.
    pub fn finish(self, run: &RunSummary) -> SpatialPlotData {
        let trace = |label: String, m: MinMax| Trace {
            label,
            pts: m.finish(),
        };
        let mut torques: [Vec<Trace>; 3] = Default::default();
        for (&n, ms) in self.legs.iter().zip(self.torque) {
            for (j, m) in ms.into_iter().enumerate() {
                torques[j].push(trace(format!("leg {n}"), m));
            }
        }
        let [height, phi_x, phi_y, phi_z] = self.body;
        let [forward, roll, pitch, heading] = self.attitude;
        let [kinetic, potential, total] = self.energy;
        let mut heights = Vec::new();
        if self.surface.is_some() {
            for (&n, [foot, ground]) in self.legs.iter().zip(self.height) {
                heights.push(trace(format!("foot {n}"), foot));
                heights.push(trace(format!("ground under {n}"), ground));
            }
        }
        SpatialPlotData {
            heights,
            feet: self
                .legs
                .iter()
                .zip(self.normal)
                .map(|(n, m)| trace(format!("leg {n}"), m))
                .collect(),
            torques,
            height: trace("Ry".into(), height),
            forward: trace("forward".into(), forward),
            attitude: vec![trace("roll".into(), roll), trace("pitch".into(), pitch)],
            heading: trace("heading".into(), heading),
            angles: vec![
                trace("φx".into(), phi_x),
                trace("φy".into(), phi_y),
                trace("φz".into(), phi_z),
            ],
            energy: vec![
                trace("kinetic".into(), kinetic),
                trace("potential".into(), potential),
                trace("total".into(), total),
            ],
            legs: self.legs,
            events: run.events.iter().map(EventMark::of).collect(),
        }
    }
}

/// Everything the plots of a dynamic hexapod run show.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SpatialPlotData {
    /// Leg numbers, in the order of the per-leg curves.
    pub legs: Vec<usize>,
    /// Normal force of each leg's foot, labelled `leg n` (N).
    pub feet: Vec<Trace>,
    /// Per leg: its foot's height and the terrain's under it (m); empty
    /// without ground.
    pub heights: Vec<Trace>,
    /// Torques τ1, τ2, τ3 (one vector per joint), one curve per leg,
    /// labelled `leg n` (N·m).
    pub torques: [Vec<Trace>; 3],
    /// Body height `Ry` (m).
    pub height: Trace,
    /// Body angles φx, φy, φz (degrees).
    pub angles: Vec<Trace>,
    /// Body centre's horizontal distance along the first step's heading
    /// (m).
    pub forward: Trace,
    /// Roll and pitch (degrees; `trajectory.csv`'s `roll`, `pitch`).
    pub attitude: Vec<Trace>,
    /// Heading, yaw about the vertical (degrees).
    pub heading: Trace,
    /// Kinetic, potential and total energy (J).
    pub energy: Vec<Trace>,
    /// Contact events.
    pub events: Vec<EventMark>,
}

impl SpatialPlotData {
    fn t_range(&self) -> (f64, f64) {
        let (lo, hi) = self
            .height
            .pts
            .iter()
            .map(|p| p.0)
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
                (a.min(t), b.max(t))
            });
        if lo < hi { (lo, hi) } else { (0.0, 1.0) }
    }

    /// One solid curve per leg, in the leg's colour.
    fn per_leg<'a>(&self, traces: &'a [Trace]) -> Vec<(&'a Trace, Style)> {
        traces
            .iter()
            .zip(&self.legs)
            .map(|(t, &n)| {
                (
                    t,
                    Style {
                        color: leg_color(n),
                        width: 2,
                        dashed: false,
                    },
                )
            })
            .collect()
    }
}

/// `feet.svg`: the normal force of every foot versus time.
pub fn feet_svg(d: &SpatialPlotData) -> PlotResult<String> {
    let series = d.per_leg(&d.feet);
    if d.heights.is_empty() {
        return stacked_time_chart(
            None,
            &[("Normal forces of the feet", "normal force (N)", &series)],
            &d.events,
            d.t_range(),
        );
    }
    // Each foot solid, the terrain under it dashed, in the leg's colour.
    let heights: Vec<(&Trace, Style)> = d
        .heights
        .iter()
        .enumerate()
        .map(|(k, t)| {
            (
                t,
                Style {
                    color: leg_color(d.legs[k / 2]),
                    width: if k % 2 == 0 { 2 } else { 1 },
                    dashed: k % 2 == 1,
                },
            )
        })
        .collect();
    stacked_time_chart(
        None,
        &[
            ("Normal forces of the feet", "normal force (N)", &series),
            (
                "Foot heights (solid) and the terrain under each foot (dashed)",
                "height (m)",
                &heights,
            ),
        ],
        &d.events,
        d.t_range(),
    )
}

/// `torques.svg`: the actuator torques of every leg, one chart per joint
/// (θ1, θ2, θ3).
pub fn torques_svg(d: &SpatialPlotData) -> PlotResult<String> {
    let series: Vec<Vec<(&Trace, Style)>> = d.torques.iter().map(|t| d.per_leg(t)).collect();
    stacked_time_chart(
        Some("Joint torques"),
        &[
            (
                "τ1 (hip, about the body's vertical axis)",
                "torque (N·m)",
                &series[0],
            ),
            ("τ2 (hip, lift)", "torque (N·m)", &series[1]),
            ("τ3 (knee)", "torque (N·m)", &series[2]),
        ],
        &d.events,
        d.t_range(),
    )
}

/// `body.svg`: the body height and the three body angles versus time.
pub fn body_svg(d: &SpatialPlotData) -> PlotResult<String> {
    let style = |k: usize| Style {
        color: PALETTE[k],
        width: 2,
        dashed: false,
    };
    let height = [(&d.height, style(0))];
    let forward = [(&d.forward, style(4))];
    let attitude: Vec<(&Trace, Style)> = d
        .attitude
        .iter()
        .enumerate()
        .map(|(k, t)| (t, style(k + 1)))
        .collect();
    let heading = [(&d.heading, style(3))];
    stacked_time_chart(
        Some("Body pose"),
        &[
            (
                "Forward position (along the initial heading)",
                "distance (m)",
                &forward,
            ),
            ("Body height Ry", "height (m)", &height),
            (
                "Roll (right side down +) and pitch (nose up +)",
                "angle (°)",
                &attitude,
            ),
            ("Heading (yaw about the vertical +Y)", "angle (°)", &heading),
        ],
        &d.events,
        d.t_range(),
    )
}

/// `energy.svg`: kinetic, potential and total energy, drawn as the planar
/// run draws it.
pub fn energy_svg(d: &SpatialPlotData) -> PlotResult<String> {
    plot::energy_svg(&PlotData {
        energy: d.energy.clone(),
        events: d.events.clone(),
        ..PlotData::default()
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leg_colours_follow_the_hexapod_palette() {
        assert_eq!(leg_color(1), PALETTE[0]);
        assert_eq!(leg_color(6), PALETTE[5]);
    }
}

//! The plots of a run of any model on the tree equations (the paper's
//! hexapod, every imported robot), drawn from every step (min/max reduced
//! per time column, [`crate::plot::MinMax`]); the model names and colours
//! its curves ([`PlotPlan`]: the hexapod one colour per leg, in the plots'
//! shared palette):
//!
//! * `feet.svg` — the normal force of every foot, and its height against
//!   the height of the terrain under it (`ϱ(x, z)` at the foot, dashed);
//! * `torques.svg` — the actuator torques, one chart per group of joints
//!   (the hexapod's τ1, τ2, τ3 of every leg);
//! * `body.svg` — the forward position, the root's height `Ry`, roll and
//!   pitch, and the heading (the attitude derived from φ);
//! * `energy.svg` — kinetic, potential and total energy (as the planar
//!   run draws it).

use fbd_contact::Surface;
use fbd_sim::robot::RobotRecord;
use plotters::style::RGBColor;

use crate::plot::{
    self, Columns, EventMark, MinMax, PALETTE, PlotData, PlotResult, Style, Trace,
    stacked_time_chart,
};

/// The colour of leg `n` (1–6): the palette's `n`-th colour, as in every
/// hexapod plot.
pub fn leg_color(n: usize) -> RGBColor {
    PALETTE[(n + PALETTE.len() - 1) % PALETTE.len()]
}

/// One curve of a foot or a joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Curve {
    /// Its legend label (`leg 3`, a point's or a joint's name).
    pub label: String,
    /// The name of a foot in its height curves (`foot 3`, `ground under
    /// 3`).
    pub short: String,
    /// Its colour.
    pub color: RGBColor,
    /// Where its values are in the record: a contact point (a foot's
    /// curves) or a joint (a torque); `None` draws a foot that is not a
    /// contact point at zero force and without height.
    pub source: Option<usize>,
}

/// What the plots of a model show, as its names and colours.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlotPlan {
    /// The feet (`feet.svg`).
    pub feet: Vec<Curve>,
    /// The charts of `torques.svg`: each one's title and joints.
    pub torques: Vec<(String, Vec<Curve>)>,
    /// The title of `torques.svg`.
    pub torques_title: String,
}

/// Gathers the curves of a run step by step.
pub struct Recorder {
    /// The time columns of every curve below.
    columns: Columns,
    plan: PlotPlan,
    normal: Vec<MinMax>,
    /// Per foot: its height and the terrain's under it.
    height: Vec<[MinMax; 2]>,
    surface: Option<Surface>,
    /// Per chart, per joint.
    torque: Vec<Vec<MinMax>>,
    body: [MinMax; 4],
    /// Forward position (m), roll, pitch, heading (°).
    attitude: [MinMax; 4],
    /// The first step's position and horizontal forward direction.
    origin: Option<([f64; 3], [f64; 2])>,
    energy: [MinMax; 3],
}

impl Recorder {
    /// For a run from `t = 0` to `t_end` of a model whose curves are
    /// `plan`.
    pub fn new(plan: PlotPlan, t_end: f64) -> Self {
        let m = || MinMax::new(0.0, t_end);
        Self {
            columns: Columns::new(0.0, t_end),
            normal: plan.feet.iter().map(|_| m()).collect(),
            height: plan
                .feet
                .iter()
                .map(|_| std::array::from_fn(|_| m()))
                .collect(),
            surface: None,
            torque: plan
                .torques
                .iter()
                .map(|(_, joints)| joints.iter().map(|_| m()).collect())
                .collect(),
            plan,
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

    /// Adds one step.
    ///
    /// Runs for every step: the step's time column is found once for all
    /// the curves ([`Columns::of`]).
    pub fn push(&mut self, r: &RobotRecord) {
        let t = r.t;
        let col = self.columns.of(t);
        for (m, foot) in self.normal.iter_mut().zip(&self.plan.feet) {
            m.push_at(col, t, foot.source.map_or(0.0, |c| r.contacts[c].normal));
        }
        if let Some(surface) = &self.surface {
            for ([foot, ground], curve) in self.height.iter_mut().zip(&self.plan.feet) {
                if let Some(c) = curve.source {
                    let p = r.contacts[c].point;
                    foot.push_at(col, t, p[1]);
                    ground.push_at(col, t, surface.height(p[0], p[2]));
                }
            }
        }
        for (ms, (_, joints)) in self.torque.iter_mut().zip(&self.plan.torques) {
            for (m, joint) in ms.iter_mut().zip(joints) {
                m.push_at(col, t, joint.source.map_or(0.0, |j| r.torque[j]));
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

    /// The curves, with the contact events `events`.
    pub fn finish(self, events: Vec<EventMark>) -> TreePlotData {
        let trace = |label: String, m: MinMax| Trace {
            label,
            pts: m.finish(),
        };
        let torques = self
            .plan
            .torques
            .iter()
            .zip(self.torque)
            .map(|((title, joints), ms)| {
                let curves = joints
                    .iter()
                    .zip(ms)
                    .map(|(j, m)| (trace(j.label.clone(), m), j.color))
                    .collect();
                (title.clone(), curves)
            })
            .collect();
        let [height, phi_x, phi_y, phi_z] = self.body;
        let [forward, roll, pitch, heading] = self.attitude;
        let [kinetic, potential, total] = self.energy;
        let mut heights = Vec::new();
        if self.surface.is_some() {
            for (f, [foot, ground]) in self.plan.feet.iter().zip(self.height) {
                heights.push((trace(format!("foot {}", f.short), foot), f.color));
                heights.push((trace(format!("ground under {}", f.short), ground), f.color));
            }
        }
        TreePlotData {
            heights,
            feet: self
                .plan
                .feet
                .iter()
                .zip(self.normal)
                .map(|(f, m)| (trace(f.label.clone(), m), f.color))
                .collect(),
            torques,
            torques_title: self.plan.torques_title,
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
            events,
        }
    }
}

/// Everything the plots of a run on the tree equations show.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TreePlotData {
    /// Normal force of each foot, with its colour (N).
    pub feet: Vec<(Trace, RGBColor)>,
    /// Per foot: its height and the terrain's under it (m), with its
    /// colour; empty without ground.
    pub heights: Vec<(Trace, RGBColor)>,
    /// The torque charts: each one's title and curves (N·m).
    pub torques: Vec<(String, Vec<(Trace, RGBColor)>)>,
    /// The title of `torques.svg`.
    pub torques_title: String,
    /// Root height `Ry` (m).
    pub height: Trace,
    /// Root angles φx, φy, φz (degrees).
    pub angles: Vec<Trace>,
    /// The root's horizontal distance along the first step's heading (m).
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

impl TreePlotData {
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
}

/// Solid curves, each in its colour.
fn solid(traces: &[(Trace, RGBColor)]) -> Vec<(&Trace, Style)> {
    traces
        .iter()
        .map(|(t, color)| {
            (
                t,
                Style {
                    color: *color,
                    width: 2,
                    dashed: false,
                },
            )
        })
        .collect()
}

/// Writes `feet.svg`, `torques.svg`, `body.svg` and `energy.svg` of `d`
/// into `dir` (each attempted, the first failure kept).
pub fn write(dir: &std::path::Path, d: &TreePlotData, keep: &mut crate::output::FirstError) {
    crate::driver::write_svgs(
        dir,
        [
            ("feet.svg", feet_svg(d)),
            ("torques.svg", torques_svg(d)),
            ("body.svg", body_svg(d)),
            ("energy.svg", energy_svg(d)),
        ],
        keep,
    );
}

/// `feet.svg`: the normal force of every foot versus time.
pub fn feet_svg(d: &TreePlotData) -> PlotResult<String> {
    let series = solid(&d.feet);
    if d.heights.is_empty() {
        return stacked_time_chart(
            None,
            &[("Normal forces of the feet", "normal force (N)", &series)],
            &d.events,
            d.t_range(),
        );
    }
    // Each foot solid, the terrain under it dashed, in the foot's colour.
    let heights: Vec<(&Trace, Style)> = d
        .heights
        .iter()
        .enumerate()
        .map(|(k, (t, color))| {
            (
                t,
                Style {
                    color: *color,
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

/// `torques.svg`: the actuator torques, one chart per group of joints.
pub fn torques_svg(d: &TreePlotData) -> PlotResult<String> {
    let series: Vec<Vec<(&Trace, Style)>> = d.torques.iter().map(|(_, t)| solid(t)).collect();
    let panels: Vec<_> = d
        .torques
        .iter()
        .zip(&series)
        .map(|((title, _), s)| (title.as_str(), "torque (N·m)", &s[..]))
        .collect();
    stacked_time_chart(Some(&d.torques_title), &panels, &d.events, d.t_range())
}

/// `body.svg`: the root's forward position, height, roll, pitch and
/// heading versus time.
pub fn body_svg(d: &TreePlotData) -> PlotResult<String> {
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
pub fn energy_svg(d: &TreePlotData) -> PlotResult<String> {
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

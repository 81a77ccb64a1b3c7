//! `trajectory.csv` of a 3D (spatial) hexapod run: the columns, named from
//! the model's legs and contact points (`{leg, kind}` data), and the
//! streaming writer.

use std::path::{Path, PathBuf};

use fbd_contact::StateCode;
use fbd_dynamics::PointKind;
use fbd_scenario::OutputFormat;
use fbd_sim::robot::RobotRecord;
use fbd_sim::spatial::{LegIndex, RecordIndex, SpatialParams};

use super::Layout;
use crate::OutputError;
use crate::output;

/// The body pose columns after `t`.
pub const POSE_COLUMNS: [&str; 6] = ["rx", "ry", "rz", "phi_x", "phi_y", "phi_z"];

/// The name prefix of a knee or hip contact point's columns
/// (`kneepoint3_fx`): distinct from the joint columns (`knee3_fx`).
pub fn point_prefix(kind: PointKind) -> &'static str {
    match kind {
        PointKind::Tip => "foot",
        PointKind::Knee => "kneepoint",
        PointKind::Hip => "hippoint",
    }
}

/// The columns of `trajectory.csv`, in order, for the legs and contact
/// points of `layout`:
///
/// * `t, rx, ry, rz, phi_x, phi_y, phi_z`;
/// * `theta1_n, theta2_n, theta3_n` for each leg n of the model;
/// * per leg n: `foot{n}_x, foot{n}_y, foot{n}_z, state{n}, foot{n}_fx,
///   foot{n}_fy, foot{n}_fz, foot{n}_n`, `hip{n}_fx, hip{n}_fy, hip{n}_fz,
///   hip{n}_mx, hip{n}_my, hip{n}_mz`, `knee{n}_fx, …, knee{n}_mz`,
///   `tau1_{n}, tau2_{n}, tau3_{n}`;
/// * per knee or hip contact point (leg by leg, knee before hip):
///   `kneepoint{n}_state, kneepoint{n}_fx, kneepoint{n}_fy,
///   kneepoint{n}_fz, kneepoint{n}_n` (`hippoint{n}_…` alike);
/// * `kinetic, potential, newton_iterations`;
/// * `roll, pitch, heading`: the body's attitude derived from φ
///   ([`crate::hexapod::ATTITUDE_COLUMNS`]).
pub fn columns(layout: &Layout) -> Vec<String> {
    let mut c: Vec<String> = std::iter::once("t")
        .chain(POSE_COLUMNS)
        .map(str::to_owned)
        .collect();
    for n in &layout.legs {
        for j in 1..=3 {
            c.push(format!("theta{j}_{n}"));
        }
    }
    for n in &layout.legs {
        for a in ["x", "y", "z"] {
            c.push(format!("foot{n}_{a}"));
        }
        c.push(format!("state{n}"));
        for a in ["fx", "fy", "fz", "n"] {
            c.push(format!("foot{n}_{a}"));
        }
        for joint in ["hip", "knee"] {
            for a in ["fx", "fy", "fz", "mx", "my", "mz"] {
                c.push(format!("{joint}{n}_{a}"));
            }
        }
        for j in 1..=3 {
            c.push(format!("tau{j}_{n}"));
        }
    }
    for &(n, kind) in &layout.extra_points {
        let p = point_prefix(kind);
        for a in ["state", "fx", "fy", "fz", "n"] {
            c.push(format!("{p}{n}_{a}"));
        }
    }
    c.extend(["kinetic", "potential", "newton_iterations"].map(str::to_owned));
    c.extend(crate::hexapod::ATTITUDE_COLUMNS.map(str::to_owned));
    c
}

/// Where each column group of a row is found in a hexapod's
/// [`RobotRecord`] (the one record of every robot), by `{leg, kind}`.
#[derive(Clone, Debug, Default)]
pub struct Slots {
    /// Per leg of the layout: where its values are.
    pub legs: Vec<Option<LegIndex>>,
    /// Per leg of the layout: its foot's row in `record.contacts`.
    pub tips: Vec<Option<usize>>,
    /// Per extra point of the layout: its row in `record.contacts`.
    pub extras: Vec<Option<usize>>,
    /// Per row of `record.contacts`: its leg number and kind.
    pub contacts: Vec<(usize, PointKind)>,
}

impl Slots {
    /// The rows of `layout` in the records of a model whose values are
    /// where `index` says ([`SpatialParams::record_index`]).
    pub fn of(layout: &Layout, index: &RecordIndex) -> Self {
        let contact =
            |leg: usize, kind: PointKind| index.contacts.iter().position(|&c| c == (leg, kind));
        Self {
            legs: layout
                .legs
                .iter()
                .map(|&n| index.legs.iter().find(|l| l.leg == n).copied())
                .collect(),
            tips: layout
                .legs
                .iter()
                .map(|&n| contact(n, PointKind::Tip))
                .collect(),
            extras: layout
                .extra_points
                .iter()
                .map(|&(n, kind)| contact(n, kind))
                .collect(),
            contacts: index.contacts.clone(),
        }
    }

    /// The values of the `i`-th leg of the layout in `r`, if it is a leg
    /// of the model.
    pub fn leg(&self, r: &RobotRecord, i: usize) -> Option<fbd_sim::spatial::LegRow> {
        self.legs[i].map(|l| l.row(r))
    }
}

/// Receives the values of a row ([`row_values`]); the planar and the 3D
/// files share it.
pub use crate::output::RowSink;

/// Hands the values of the row of `r` to `sink`, in the order of
/// [`columns`]`(layout)`; `slots` are those of `layout` ([`Slots::of`]),
/// `feet` places the feet that are not contact points. No allocation.
pub fn row_values(
    layout: &Layout,
    slots: &Slots,
    feet: &mut super::Feet,
    r: &RobotRecord,
    sink: &mut dyn RowSink,
) {
    sink.time(r.step, r.t);
    for &x in &r.q {
        sink.num(x);
    }
    // Without a foot contact point, the foot is placed by the kinematics.
    if slots.tips.iter().any(Option::is_none) {
        feet.update(&r.q);
    }
    let zero = [0.0; 3];
    for i in 0..layout.legs.len() {
        let tip = slots.tips[i].map(|c| &r.contacts[c]);
        let p = tip.map_or_else(|| feet.tip(i), |c| c.point);
        for x in p {
            sink.num(x);
        }
        sink.state(tip.map_or(StateCode::St1, |c| c.state));
        let (f, n) = tip.map_or((zero, 0.0), |c| (c.force, c.normal));
        for x in f {
            sink.num(x);
        }
        sink.num(n);
        let leg = slots.leg(r, i);
        for v in [
            leg.map_or(zero, |l| l.hip_force),
            leg.map_or(zero, |l| l.hip_moment),
            leg.map_or(zero, |l| l.knee_force),
            leg.map_or(zero, |l| l.knee_moment),
            leg.map_or(zero, |l| l.torque),
        ] {
            for x in v {
                sink.num(x);
            }
        }
    }
    for slot in &slots.extras {
        let c = slot.map(|c| &r.contacts[c]);
        sink.state(c.map_or(StateCode::St1, |c| c.state));
        let (f, n) = c.map_or((zero, 0.0), |c| (c.force, c.normal));
        for x in f {
            sink.num(x);
        }
        sink.num(n);
    }
    sink.num(r.kinetic);
    sink.num(r.potential);
    sink.count(r.newton_iterations);
    let pose =
        fbd_kinematics::pose::BodyPose::new([r.q[0], r.q[1], r.q[2]], [r.q[3], r.q[4], r.q[5]]);
    for a in pose.attitude() {
        sink.num(a);
    }
}

/// Streams the trajectory (`trajectory.csv` or `trajectory.parquet`)
/// into a temporary file; no allocation per CSV row.
pub struct TrajectoryWriter {
    table: output::Table,
    layout: Layout,
    slots: Slots,
    feet: super::Feet,
    rows: usize,
}

impl TrajectoryWriter {
    /// Opens the temporary `trajectory.csv` in `dir` and writes the header.
    pub fn create(dir: &Path, params: &SpatialParams) -> Result<Self, OutputError> {
        Self::create_as(dir, params, OutputFormat::Csv)
    }

    /// [`TrajectoryWriter::create`] in `format` (`[output] format`).
    pub fn create_as(
        dir: &Path,
        params: &SpatialParams,
        format: OutputFormat,
    ) -> Result<Self, OutputError> {
        let layout = Layout::of(params);
        Ok(Self {
            table: output::Table::create(dir, format, columns(&layout), params.dt)?,
            feet: super::Feet::new(params),
            slots: Slots::of(&layout, &params.record_index()),
            layout,
            rows: 0,
        })
    }

    /// Rows written so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Appends the row of `r`. An I/O error is kept and reported by
    /// [`TrajectoryWriter::finish`]; later rows are skipped.
    pub fn write(&mut self, r: &RobotRecord) {
        let (layout, slots, feet) = (&self.layout, &self.slots, &mut self.feet);
        self.table
            .row(|sink| row_values(layout, slots, feet, r, sink));
        if !self.table.failed() {
            self.rows += 1;
        }
    }

    /// Flushes and renames the file into place.
    pub fn finish(self) -> Result<PathBuf, OutputError> {
        self.table.finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joint_and_contact_point_columns_never_clash() {
        let layout = Layout::of(&SpatialParams::default());
        let c = columns(&layout);
        let mut sorted = c.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(sorted.len(), c.len(), "duplicate column names");
        assert!(c.contains(&"kneepoint6_fz".to_owned()));
        assert!(c.contains(&"hippoint1_state".to_owned()));
    }
}

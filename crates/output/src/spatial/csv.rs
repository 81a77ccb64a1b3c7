//! `trajectory.csv` of a 3D (spatial) hexapod run: the columns, named from
//! the model's legs and contact points (`{leg, kind}` data), and the
//! streaming writer.

use fbd_dynamics::PointKind;
use fbd_sim::robot::RobotRecord;
use fbd_sim::spatial::{LegIndex, RecordIndex};

use super::Layout;
use crate::tree::{Plan, Source};

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
    plan(layout, &Slots::default()).names
}

/// The hexapod's [`Plan`]: the columns of [`columns`], each from where
/// `slots` finds it in the record; a foot that is not a contact point
/// (no slot) is placed by the kinematics ([`super::Feet`]), free and
/// without force, a leg without a slot has no forces or torques.
pub fn plan(layout: &Layout, slots: &Slots) -> Plan {
    let mut p = Plan::default();
    p.push("t", Source::Time);
    for (i, name) in POSE_COLUMNS.iter().enumerate() {
        p.push(*name, Source::Q(i));
    }
    // The joint angles, in the record's order.
    let mut q = POSE_COLUMNS.len();
    for n in &layout.legs {
        for j in 1..=3 {
            p.push(format!("theta{j}_{n}"), Source::Q(q));
            q += 1;
        }
    }
    let xyz = ["x", "y", "z"];
    for (i, n) in layout.legs.iter().enumerate() {
        let foot = format!("foot{n}_");
        match slots.tips.get(i).copied().flatten() {
            Some(c) => {
                p.push_each(&foot, xyz, |a| Source::ContactPoint(c, a));
                p.push(format!("state{n}"), Source::ContactState(c));
                p.push_each(&foot, ["fx", "fy", "fz"], |a| Source::ContactForce(c, a));
                p.push(format!("{foot}n"), Source::ContactNormal(c));
            }
            None => {
                p.push_each(&foot, xyz, |a| Source::Foot(i, a));
                p.push(format!("state{n}"), Source::Free);
                p.push_each(&foot, ["fx", "fy", "fz", "n"], |_| Source::Zero);
            }
        }
        let leg = slots.legs.get(i).copied().flatten();
        for (joint, reaction) in [("hip", leg.map(|l| l.hip)), ("knee", leg.map(|l| l.knee))] {
            let prefix = format!("{joint}{n}_");
            match reaction {
                Some(r) => {
                    p.push_each(&prefix, ["fx", "fy", "fz"], |a| Source::ReactionForce(r, a));
                    p.push_each(&prefix, ["mx", "my", "mz"], |a| {
                        Source::ReactionMoment(r, a)
                    });
                }
                None => p.push_each(&prefix, ["fx", "fy", "fz", "mx", "my", "mz"], |_| {
                    Source::Zero
                }),
            }
        }
        for j in 0..3 {
            p.push(
                format!("tau{}_{n}", j + 1),
                leg.map_or(Source::Zero, |l| Source::Torque(l.joint + j)),
            );
        }
    }
    for (e, &(n, kind)) in layout.extra_points.iter().enumerate() {
        let prefix = format!("{}{n}_", point_prefix(kind));
        match slots.extras.get(e).copied().flatten() {
            Some(c) => {
                p.push(format!("{prefix}state"), Source::ContactState(c));
                p.push_each(&prefix, ["fx", "fy", "fz"], |a| Source::ContactForce(c, a));
                p.push(format!("{prefix}n"), Source::ContactNormal(c));
            }
            None => {
                p.push(format!("{prefix}state"), Source::Free);
                p.push_each(&prefix, ["fx", "fy", "fz", "n"], |_| Source::Zero);
            }
        }
    }
    p.push("kinetic", Source::Kinetic);
    p.push("potential", Source::Potential);
    p.push("newton_iterations", Source::Iterations);
    for (a, name) in crate::hexapod::ATTITUDE_COLUMNS.iter().enumerate() {
        p.push(*name, Source::Attitude(a));
    }
    p
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn joint_and_contact_point_columns_never_clash() {
        let layout = Layout::of(&fbd_sim::spatial::SpatialParams::default());
        let c = columns(&layout);
        let mut sorted = c.clone();
        sorted.sort();
        sorted.dedup();
        assert_eq!(sorted.len(), c.len(), "duplicate column names");
        assert!(c.contains(&"kneepoint6_fz".to_owned()));
        assert!(c.contains(&"hippoint1_state".to_owned()));
    }
}

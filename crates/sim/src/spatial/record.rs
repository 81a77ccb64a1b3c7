//! The hexapod's view of the one record of every robot
//! ([`RobotRecord`], [`crate::engine::tree_record`]): its values leg by
//! leg, read from the record, not recorded apart.

use super::model::{SpatialModel, hexapod_contacts};
use super::params::SpatialParams;
use crate::engine::tree_record::RobotRecord;
use crate::record::LimitCode;
use fbd_dynamics::PointKind;
use fbd_dynamics::tree::{TreeMechanism, contacts_by_kind};

/// Where a hexapod's values are in its records: each contact point's
/// identity and each leg's values.
#[derive(Clone, Debug, PartialEq)]
pub struct RecordIndex {
    /// Per contact point of the record (`RobotRecord::contacts`), its leg
    /// number (1–6) and kind.
    pub contacts: Vec<(usize, PointKind)>,
    /// Per leg slot (`SpatialParams::legs`), where its values are.
    pub legs: Vec<LegIndex>,
}

impl RecordIndex {
    fn of(mech: &TreeMechanism, legs: &[usize]) -> Self {
        Self {
            contacts: hexapod_contacts(mech, legs)
                .iter()
                .map(|c| (c.leg, c.kind))
                .collect(),
            legs: (0..legs.len())
                .map(|s| LegIndex::of(mech, legs, s))
                .collect(),
        }
    }
}

impl SpatialParams {
    /// Where the values of a model of these parameters are in its records
    /// (as [`SpatialModel::record_index`], without building the model).
    pub fn record_index(&self) -> RecordIndex {
        let robot = self.robot_model();
        let mech = TreeMechanism::with_contacts(&robot, self.gravity, &contacts_by_kind(&robot));
        RecordIndex::of(&mech, &self.legs)
    }
}

/// Where one leg's values are in a [`RobotRecord`] of a [`SpatialModel`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LegIndex {
    /// Hexapod leg number (1–6).
    pub leg: usize,
    /// Its hip's reaction (the two-axis joint of θ1 and θ2).
    pub hip: usize,
    /// Its knee's reaction (θ3).
    pub knee: usize,
    /// The model joint of its θ1 (θ2 and θ3 follow).
    pub joint: usize,
}

impl LegIndex {
    /// The leg in slot `s` of a hexapod mechanism with legs `legs`: model
    /// joints `3s..3s + 3` are its θ1, θ2, θ3.
    fn of(mech: &TreeMechanism, legs: &[usize], s: usize) -> Self {
        Self {
            leg: legs[s],
            hip: mech.reaction_of[3 * s],
            knee: mech.reaction_of[3 * s + 2],
            joint: 3 * s,
        }
    }

    /// The values of the leg in `r`.
    pub fn row(&self, r: &RobotRecord) -> LegRow {
        let j = self.joint;
        LegRow {
            leg: self.leg,
            hip_force: r.reaction_force[self.hip],
            hip_moment: r.reaction_moment[self.hip],
            knee_force: r.reaction_force[self.knee],
            knee_moment: r.reaction_moment[self.knee],
            torque: [r.torque[j], r.torque[j + 1], r.torque[j + 2]],
            rate: [r.rate[j], r.rate[j + 1], r.rate[j + 2]],
            limit: [r.limit[j], r.limit[j + 1], r.limit[j + 2]],
        }
    }
}

/// One leg's joint values at step k.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LegRow {
    /// Hexapod leg number (1–6).
    pub leg: usize,
    /// Force exerted by the body on the upper link at the hip (N, inertial).
    pub hip_force: [f64; 3],
    /// Moment about the hip point exerted by the body on the upper link,
    /// actuator torques and limit stops included (N·m, inertial).
    pub hip_moment: [f64; 3],
    /// Force of the upper link on the lower link at the knee (N, inertial).
    pub knee_force: [f64; 3],
    /// Moment about the knee point of the upper link on the lower link,
    /// actuator torque and limit stop included (N·m, inertial).
    pub knee_moment: [f64; 3],
    /// Actuator torques `(τ1, τ2, τ3)` (N·m), positive towards larger angles.
    pub torque: [f64; 3],
    /// Joint rates `(θ̇1, θ̇2, θ̇3)` at k (rad/s, backward difference; the
    /// initial rates at k = 0), for the actuator power `τ·θ̇`.
    pub rate: [f64; 3],
    /// Limit state of `(θ1, θ2, θ3)` at step k.
    pub limit: [LimitCode; 3],
}

impl SpatialModel {
    /// Where the values of the model are in its records.
    pub fn record_index(&self) -> RecordIndex {
        RecordIndex::of(&self.mech, &self.legs)
    }

    /// The values of the leg in slot `s` (of `params.legs`) in `r`.
    pub fn leg_row(&self, r: &RobotRecord, s: usize) -> LegRow {
        LegIndex::of(&self.mech, &self.legs, s).row(r)
    }
}

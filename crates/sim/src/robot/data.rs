//! The mutable workspace of a robot's run ([`RobotData`]), built from a
//! [`RobotSim`]: the generic [`RunData`] of the staged step.

use super::model::RobotSim;
use crate::engine::RunData;
use crate::engine::data::Parts;
use crate::engine::tree_record::RobotRecord;
use fbd_dynamics::tree::TreeFbdData;
use fbd_dynamics::tree::assemble::{set_configuration, set_previous};
use fbd_solver::NewtonSolver;

/// Everything that changes during a robot's run (see [`RunData`]); every
/// buffer is allocated here, once.
pub type RobotData = RunData<RobotSim>;

impl RunData<RobotSim> {
    /// A fresh workspace at the model's initial state.
    pub fn new(model: &RobotSim) -> Self {
        let mech = &model.mech;
        let q0 = &model.params.q0;
        let mut fbd = TreeFbdData::new(mech);
        set_configuration(mech, &mut fbd, q0);
        set_previous(mech, &mut fbd, q0);
        let record = RobotRecord::new(mech, q0);
        RunData::build(Parts {
            q0: q0.clone(),
            dim: mech.dim(),
            limits: mech.limits.len(),
            initial_states: model.initial_states.clone(),
            fbd,
            solver: NewtonSolver::new(model.newton),
            record,
            control: model.params.control.work(),
        })
    }
}

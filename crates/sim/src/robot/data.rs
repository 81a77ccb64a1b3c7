//! The mutable workspace of a robot's run ([`RobotData`]), built from a
//! [`RobotSim`]: the generic [`RunData`] of the staged step.

use super::model::RobotSim;
use super::record::{RobotContactRow, RobotRecord};
use crate::engine::RunData;
use crate::engine::data::Parts;
use crate::record::LimitCode;
use fbd_contact::StateCode;
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
        let nj = mech.model.joints.len();
        let nr = mech.reactions.len();
        let record = RobotRecord {
            step: 0,
            t: 0.0,
            q: q0.clone(),
            contacts: vec![
                RobotContactRow {
                    point: [0.0; 3],
                    state: StateCode::St1,
                    force: [0.0; 3],
                    normal: 0.0,
                };
                mech.contacts.len()
            ],
            reaction_force: vec![[0.0; 3]; nr],
            reaction_moment: vec![[0.0; 3]; nr],
            torque: vec![0.0; nj],
            rate: vec![0.0; nj],
            limit: vec![LimitCode::Free; nj],
            stop: vec![0.0; nj],
            kinetic: 0.0,
            potential: 0.0,
            momentum: [0.0; 3],
            angular_momentum: [0.0; 3],
            com: [0.0; 3],
            newton_iterations: 0,
            state_trials: 0,
        };
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

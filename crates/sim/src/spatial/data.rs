//! The mutable workspace of a spatial run ([`SpatialData`]), built from a
//! [`SpatialModel`]: the generic [`RunData`] of the staged step for the
//! spatial model.

use super::model::SpatialModel;
use crate::engine::RunData;
use crate::engine::data::Parts;
use crate::engine::tree_record::RobotRecord;
use crate::gait::GaitData;
use crate::spatial::params::SpatialControl;
use fbd_dynamics::tree::TreeFbdData;
use fbd_dynamics::tree::assemble::set_configuration;
use fbd_solver::NewtonSolver;

/// Everything that changes during a spatial run (see [`RunData`]); every
/// buffer is allocated here, once.
pub type SpatialData = RunData<SpatialModel>;

impl RunData<SpatialModel> {
    /// A fresh workspace at the model's initial state.
    pub fn new(model: &SpatialModel) -> Self {
        let mech = &model.mech;
        let q0 = &model.params.q0;
        let mut fbd = TreeFbdData::new(mech);
        set_configuration(mech, &mut fbd, q0);
        let record = RobotRecord::new(mech, q0);
        let gait = match &model.params.control {
            SpatialControl::Gait { gait, .. } => Some(Box::new(GaitData::new(gait))),
            _ => None,
        };
        RunData::build(Parts {
            q0: q0.clone(),
            dim: mech.dims().dim(),
            limits: mech.limits.len(),
            initial_states: model.initial_states.clone(),
            fbd,
            solver: NewtonSolver::new(model.newton),
            record,
            control: gait,
        })
    }
}

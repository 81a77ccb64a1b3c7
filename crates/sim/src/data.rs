//! The mutable workspace of a planar run ([`Data`]), built from a
//! [`Model`]: the generic [`RunData`] of the staged step for the planar
//! model.

use crate::Model;
use crate::engine::RunData;
use crate::engine::data::Parts;
use crate::robot::RobotRecord;
use fbd_dynamics::FbdData;
use fbd_solver::NewtonSolver;

/// Everything that changes during a planar run (see [`RunData`]). All
/// buffers are allocated here, once; the stepping loop reuses them.
pub type Data = RunData<Model>;

impl RunData<Model> {
    /// A fresh workspace at the model's initial state.
    pub fn new(model: &Model) -> Self {
        let mech = &model.mech;
        let lay = mech.layout();
        let mut fbd = FbdData::new(mech);
        fbd_dynamics::set_configuration(mech, &mut fbd, &model.params.q0);
        RunData::build(Parts {
            q0: model.params.q0.to_vec(),
            dim: lay.dim(),
            limits: lay.limits,
            initial_states: model.initial_states.clone(),
            fbd,
            solver: NewtonSolver::new(model.newton),
            record: RobotRecord::planar(lay.contacts, lay.joints),
            control: (),
        })
    }

    /// Time of the next step to solve (s).
    pub fn time(&self, model: &Model) -> f64 {
        self.k as f64 * model.dt()
    }
}

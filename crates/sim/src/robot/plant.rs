//! [`RobotSim`] as a [`Plant`] of the stepping API
//! ([`crate::simulator`]): any imported robot stepped one Δt at a time by
//! a controller outside the simulator.
//!
//! * actuated joints: every joint of the model, in model order (`q` index
//!   `6 + j`);
//! * torques from outside replace the configured controller's as given
//!   (no effort limit applied: the caller's torques are the caller's);
//! * readouts: every body of the model (the root first, model order), the
//!   joints, one reaction per [`fbd_dynamics::tree::TreeMechanism`]
//!   reaction ([`crate::simulator::ReactionReadout`]), every contact point
//!   (model order, named in `mech.contacts`), energies.

use super::model::RobotSim;
use crate::engine::RunData;
use crate::simulator::{Plant, ReactionReadout, Readout};
use fbd_dynamics::tree::kin::BASE_DOF;

impl Plant for RobotSim {
    fn fresh(&self) -> RunData<Self> {
        RunData::<RobotSim>::new(self)
    }
    fn joint_indices(&self) -> Vec<usize> {
        (BASE_DOF..BASE_DOF + self.mech.model.joints.len()).collect()
    }
    fn set_torques(&self, data: &mut RunData<Self>, tau: &[f64]) {
        match &mut data.external_torque {
            Some(t) => t.copy_from_slice(tau),
            None => data.external_torque = Some(tau.to_vec()),
        }
    }
    fn read(&self, data: &RunData<Self>, out: &mut Readout) {
        crate::simulator::read_tree(self, data, 0..data.fbd.kin.com.len(), out);
        let rec = &data.record;
        out.legs.clear();
        out.reactions
            .resize(rec.reaction_force.len(), ReactionReadout::default());
        for ((r, f), m) in out
            .reactions
            .iter_mut()
            .zip(&rec.reaction_force)
            .zip(&rec.reaction_moment)
        {
            r.force = *f;
            r.moment = *m;
        }
    }
}

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
use crate::simulator::{BodyReadout, ContactReadout, Plant, ReactionReadout, Readout};
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
        let dt = self.params.dt;
        let moved = data.k > 0;
        let (kin, prev) = (&data.fbd.kin, &data.fbd.kin_prev);
        out.bodies.resize(kin.com.len(), BodyReadout::default());
        for (b, body) in out.bodies.iter_mut().enumerate() {
            let r = kin.rotation[b];
            let c = kin.com[b];
            body.position = [c.x, c.y, c.z];
            body.rotation = std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)]));
            if moved {
                let v = (c - prev.com[b]) / dt;
                let w =
                    r * fbd_dynamics::spatial::so3::log(&(prev.rotation[b].transpose() * r)) / dt;
                body.velocity = [v.x, v.y, v.z];
                body.angular_velocity = [w.x, w.y, w.z];
            } else {
                body.velocity = [0.0; 3];
                body.angular_velocity = [0.0; 3];
            }
        }
        let rec = &data.record;
        for (joint, &tau) in out.joints.iter_mut().zip(&rec.torque) {
            joint.torque = tau;
        }
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
        out.contacts
            .resize(self.mech.contacts.len(), ContactReadout::default());
        let ground = self.params.terrain.as_ref();
        for (c, tc) in self.mech.contacts.iter().enumerate() {
            let p = kin.contact[tc.model_contact];
            let p = [p.x, p.y, p.z];
            let normal = ground.map_or([0.0, 1.0, 0.0], |s| s.normal(p[0], p[2]));
            let before = moved.then(|| {
                let q = prev.contact[tc.model_contact];
                [q.x, q.y, q.z]
            });
            let row = &rec.contacts[c];
            let state = if moved {
                row.state
            } else {
                data.states[c].code()
            };
            out.contacts[c] = crate::simulator::contact_readout(
                &self.contact_specs[c],
                [p, normal],
                before,
                dt,
                state,
                (row.force, row.normal),
            );
        }
        out.kinetic = rec.kinetic;
        out.potential = rec.potential;
    }
}

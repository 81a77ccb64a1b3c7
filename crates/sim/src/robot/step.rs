//! A robot's stages of the staged step: [`RobotSim`] as an [`Engine`] of
//! the generic step ([`crate::engine`]) and a [`SurfaceEngine`] (the 3D
//! contact machinery shared with the hexapod, [`crate::engine::surface`]).
//! What is the robot's here: the generic tree assembly
//! ([`fbd_dynamics::tree`]), its controller ([`super::control`]) and its
//! record.

use super::control::{joint_rates, joint_torques};
use super::data::RobotData;
use super::model::RobotSim;
use super::record::RobotRecord;
use crate::SimError;
use crate::engine::surface;
use crate::engine::tree_record;
use crate::engine::{Engine, LimitInfo, Settings};
use crate::record::LimitCode;
use fbd_contact::{Friction, Surface};
use fbd_kinematics::Joint;
use fbd_kinematics::nalgebra::Vector3;

/// Solves step `data.k` (its record in `data.record`) and advances to
/// `k + 1`, retrying in substeps when the whole step cannot be solved
/// ([`crate::engine::step`]).
///
/// # Errors
/// A [`SimError`] naming the step and time.
pub fn step(model: &RobotSim, data: &mut RobotData) -> Result<(), SimError> {
    crate::engine::step::step(model, data)
}

crate::engine::surface::tree_surface_engine!(RobotSim);

impl Engine for RobotSim {
    type Record = RobotRecord;
    type Torques = Vec<f64>;
    type ControlData = Option<Box<super::control::GaitWork>>;

    fn settings(&self) -> Settings<'_, Surface> {
        Settings {
            dt: self.params.dt,
            max_substeps: self.max_substeps,
            cycle_tolerance: self.cycle_tolerance,
            exact: true,
            qdot0: &self.params.qdot0,
            steps: self.steps,
            stride: self.params.stride,
            bodies: self.mech.bodies.len(),
            contacts: &self.contact_specs,
            limits: self.mech.limits.len(),
            ground: self.params.terrain.as_ref().unwrap_or(&self.no_ground),
            friction: &self.params.friction,
            contact: &self.params.contact,
        }
    }
    fn limit(&self, l: usize) -> LimitInfo {
        let lim = &self.mech.limits[l];
        LimitInfo {
            q_index: lim.q_index,
            joint_index: lim.joint,
            joint: Joint::Theta1,
            leg: 0,
            range: lim.range,
        }
    }
    fn limit_name(&self, l: usize) -> String {
        self.mech.model.joints[self.mech.limits[l].joint]
            .name
            .clone()
    }
    crate::engine::surface::surface_stages!();
    fn torques(&self, data: &mut RobotData) -> Result<(), SimError> {
        joint_torques(self, data)
    }
    fn friction_at(&self, at: [f64; 2]) -> Friction {
        match &self.params.terrain {
            Some(s) => surface::friction_on(s, &self.params.friction, at),
            None => self.params.friction,
        }
    }
    fn make_record(&self, data: &mut RobotData, iterations: usize, trials: usize, h: f64) {
        make_record(self, data, iterations, trials, h);
    }
}

/// Fills `data.record` for the solved (sub)step of length `h`.
fn make_record(
    model: &RobotSim,
    data: &mut RobotData,
    newton_iterations: usize,
    state_trials: usize,
    h: f64,
) {
    let mech = &model.mech;
    let dims = mech.dims();
    let fbd = &data.fbd;
    let z = &data.z;
    let rec = &mut data.record;
    rec.step = data.k;
    rec.t = data.k as f64 * model.params.dt;
    rec.q.copy_from_slice(&data.q);
    rec.newton_iterations = newton_iterations;
    rec.state_trials = state_trials;
    for (c, row) in rec.contacts.iter_mut().enumerate() {
        (row.point, row.force, row.normal) = tree_record::contact_force(mech, fbd, z, c);
        row.state = data.trial[c].code();
    }
    rec.torque.copy_from_slice(&fbd.torque);
    for i in 0..mech.reactions.len() {
        let (f, m) = tree_record::reaction_wrench(mech, fbd, z, i);
        rec.reaction_force[i] = f.into();
        rec.reaction_moment[i] = m.into();
    }
    rec.limit.fill(LimitCode::Free);
    rec.stop.fill(0.0);
    for (l, lim) in mech.limits.iter().enumerate() {
        let stop = z[dims.limit_moment(l)];
        let m = Vector3::from(rec.reaction_moment[lim.reaction]) + stop * fbd.kin.axis[lim.joint];
        rec.reaction_moment[lim.reaction] = m.into();
        rec.limit[lim.joint] = LimitCode::of(&data.limit_trial[l]);
        rec.stop[lim.joint] = stop;
    }
    for j in 0..mech.model.joints.len() {
        let r = joint_rates(model, data, j);
        data.record.rate[j] = r;
    }
    let m = tree_record::momenta(mech, &mut data.fbd, h);
    let rec = &mut data.record;
    rec.kinetic = m.kinetic;
    rec.potential = m.potential;
    rec.momentum = m.momentum;
    rec.angular_momentum = m.angular_momentum;
    rec.com = m.com;
}

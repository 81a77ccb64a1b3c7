//! The spatial model's stages of the staged step: [`SpatialModel`] as an
//! [`Engine`] of the generic step ([`crate::engine`]: the stages, the
//! state search with its cycle fallbacks and the retry in substeps are the
//! planar model's, one source) and a [`SurfaceEngine`] (the 3D contact
//! machinery of [`crate::engine::surface`], shared with every imported
//! robot).
//!
//! The hexapod's equations are every robot's (the generic tree assembly,
//! [`fbd_dynamics::tree`], on its D-H instance); what is the hexapod's
//! here: its controller, its joint limits by leg and the record with its
//! legs.

use super::control::{joint_rates, joint_torques};
use super::data::SpatialData;
use super::model::SpatialModel;
use crate::SimError;
use crate::engine::surface::{self, SurfaceSystem};
use crate::engine::tree_record;
use crate::engine::{Engine, LimitInfo, Settings};
use crate::record::LimitCode;
use fbd_contact::{Friction, Surface};
use fbd_dynamics::tree::TreeMechanism;

pub use crate::engine::surface::{LIMIT_RELEASE_ANGLE, SLIP_RESOLUTION, UNLOADED_STICK_DRIFT};

/// One spatial step's equations as a [`fbd_solver::NewtonSystem`].
pub type SpatialSystem<'a> = SurfaceSystem<'a, TreeMechanism>;

/// Solves step `data.k` (its record in `data.record`) and advances to
/// `k + 1`, retrying in substeps when the whole step cannot be solved
/// ([`crate::engine::step`]).
///
/// # Errors
/// A [`SimError`] naming the step and time.
pub fn step(model: &SpatialModel, data: &mut SpatialData) -> Result<(), SimError> {
    crate::engine::step::step(model, data)
}

crate::engine::surface::tree_surface_engine!(SpatialModel);

impl Engine for SpatialModel {
    type Record = super::record::SpatialRecord;
    type Torques = Vec<[f64; 3]>;
    type ControlData = Option<Box<crate::gait::GaitData>>;

    fn settings(&self) -> Settings<'_, Surface> {
        Settings {
            dt: SpatialModel::dt(self),
            max_substeps: self.max_substeps,
            cycle_tolerance: self.cycle_tolerance,
            exact: true,
            qdot0: &self.params.qdot0,
            steps: self.steps,
            stride: self.params.stride,
            bodies: self.mech.bodies.len(),
            contacts: &self.contacts,
            limits: self.mech.limits.len(),
            ground: &self.params.terrain,
            friction: &self.params.friction,
            contact: &self.params.contact,
        }
    }
    fn limit(&self, l: usize) -> LimitInfo {
        let lim = &self.limits[l];
        LimitInfo {
            q_index: lim.q_index,
            joint_index: lim.q_index,
            joint: lim.joint,
            leg: self.legs[lim.slot],
            range: self.params.joint_limits.range(lim.joint),
        }
    }
    fn limit_name(&self, l: usize) -> String {
        let lim = &self.limits[l];
        format!("theta{}_{}", lim.joint.index() + 1, self.legs[lim.slot])
    }
    crate::engine::surface::surface_stages!();
    fn torques(&self, data: &mut SpatialData) -> Result<(), SimError> {
        joint_torques(self, data)
    }
    fn friction_at(&self, at: [f64; 2]) -> Friction {
        surface::friction_on(&self.params.terrain, &self.params.friction, at)
    }
    fn make_record(&self, data: &mut SpatialData, iterations: usize, trials: usize, h: f64) {
        make_record(self, data, iterations, trials, h);
    }
}

/// Stage 4's system for the accepted states of `data` (for benchmarks,
/// which time the assembly and the factorisation apart).
pub fn system_for_bench<'a>(
    model: &'a SpatialModel,
    data: &'a mut SpatialData,
) -> SpatialSystem<'a> {
    data.trial.copy_from_slice(&data.states);
    data.limit_trial.copy_from_slice(&data.limit_states);
    surface::system(model, data).0
}

/// Fills `data.record` for the solved (sub)step of length `h`: per leg,
/// its hip's (the two-axis reaction of θ1 and θ2) and its knee's (θ3)
/// force and moment, actuator torques and stops included.
fn make_record(
    model: &SpatialModel,
    data: &mut SpatialData,
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
    rec.t = data.k as f64 * model.dt();
    rec.q.copy_from_slice(&data.q);
    rec.newton_iterations = newton_iterations;
    rec.state_trials = state_trials;
    for (c, row) in rec.contacts.iter_mut().enumerate() {
        (row.point, row.force, row.normal) = tree_record::contact_force(mech, fbd, z, c);
        row.state = data.trial[c].code();
    }
    for (s, row) in rec.legs.iter_mut().enumerate() {
        let (hip_force, mut hip_moment) =
            tree_record::reaction_wrench(mech, fbd, z, mech.reaction_of[3 * s]);
        let (knee_force, mut knee_moment) =
            tree_record::reaction_wrench(mech, fbd, z, mech.reaction_of[3 * s + 2]);
        let mut limit = [LimitCode::Free; 3];
        for (l, lim) in model.limits.iter().enumerate() {
            if lim.slot == s {
                let j = lim.joint.index();
                let stop = z[dims.limit_moment(l)] * fbd.kin.axis[3 * s + j];
                if j < 2 {
                    hip_moment += stop;
                } else {
                    knee_moment += stop;
                }
                limit[j] = LimitCode::of(&data.limit_trial[l]);
            }
        }
        row.hip_force = hip_force.into();
        row.hip_moment = hip_moment.into();
        row.knee_force = knee_force.into();
        row.knee_moment = knee_moment.into();
        row.torque = std::array::from_fn(|j| fbd.torque[3 * s + j]);
        row.limit = limit;
    }
    // Rates need `data` immutably: a second pass.
    for s in 0..model.legs.len() {
        let r = joint_rates(model, data, s);
        data.record.legs[s].rate = r;
    }
    let m = tree_record::momenta(mech, &mut data.fbd, h);
    let rec = &mut data.record;
    rec.kinetic = m.kinetic;
    rec.potential = m.potential;
    rec.momentum = m.momentum;
    rec.angular_momentum = m.angular_momentum;
}

//! The spatial model's stages of the staged step: [`SpatialModel`] as an
//! [`Engine`] of the generic step ([`crate::engine`]: the stages, the
//! state search with its cycle fallbacks and the retry in substeps are the
//! planar model's, one source) and a [`SurfaceEngine`] (the 3D contact
//! machinery of [`crate::engine::surface`], shared with every imported
//! robot).
//!
//! What is the hexapod's here: its assembly
//! ([`fbd_dynamics::spatial`]: the kinematics of the 13 bodies and the
//! constraint directions), its controller, its joint limits by leg and the
//! record with its legs and momenta.

use super::control::{joint_rates, joint_torques};
use super::data::SpatialData;
use super::model::SpatialModel;
use crate::SimError;
use crate::engine::surface::{self, SurfaceEngine, SurfaceSystem};
use crate::engine::{Engine, LimitInfo, Settings};
use crate::record::LimitCode;
use fbd_contact::{Friction, SpatialState, SpatialTrial, Surface};
use fbd_dynamics::spatial::{SpatialFbdData, SpatialMechanism, half_momentum_and_rotation};
use fbd_kinematics::nalgebra::Vector3;

pub use crate::engine::surface::{LIMIT_RELEASE_ANGLE, SLIP_RESOLUTION, UNLOADED_STICK_DRIFT};

/// One spatial step's equations as a [`fbd_solver::NewtonSystem`].
pub type SpatialSystem<'a> = SurfaceSystem<'a, SpatialMechanism>;

/// Solves step `data.k` (its record in `data.record`) and advances to
/// `k + 1`, retrying in substeps when the whole step cannot be solved
/// ([`crate::engine::step`]).
///
/// # Errors
/// A [`SimError`] naming the step and time.
pub fn step(model: &SpatialModel, data: &mut SpatialData) -> Result<(), SimError> {
    crate::engine::step::step(model, data)
}

impl SurfaceEngine for SpatialModel {
    type Mech = SpatialMechanism;
    fn mech(&self) -> &SpatialMechanism {
        &self.mech
    }
    fn complementarity_rows(&self) -> bool {
        self.complementarity
    }
    fn bumper(&self, c: usize) -> f64 {
        self.contact_bumper[c]
    }
    fn total_mass(&self) -> f64 {
        self.mech.total_mass()
    }
}

impl Engine for SpatialModel {
    type State = SpatialState;
    type Trial = SpatialTrial;
    type Ground = Surface;
    type Fbd = SpatialFbdData;
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
            contacts: &self.mech.contacts,
            limits: self.mech.limits.len(),
            ground: &self.params.terrain,
            friction: &self.params.friction,
            contact: &self.params.contact,
        }
    }
    fn limit(&self, l: usize) -> LimitInfo {
        let lim = &self.mech.limits[l];
        LimitInfo {
            q_index: lim.q_index,
            joint_index: lim.q_index,
            joint: lim.joint,
            leg: self.mech.legs[lim.slot],
            range: self.params.joint_limits.range(lim.joint),
        }
    }
    fn limit_name(&self, l: usize) -> String {
        let lim = &self.mech.limits[l];
        format!(
            "theta{}_{}",
            lim.joint.index() + 1,
            self.mech.legs[lim.slot]
        )
    }
    fn limit_moment_index(&self, l: usize) -> usize {
        self.mech.layout().limit_moment(l)
    }

    crate::engine::surface::surface_stages!(fbd_dynamics::spatial);
    fn torques(&self, data: &mut SpatialData) -> Result<(), SimError> {
        joint_torques(self, data)
    }
    fn friction_at(&self, at: [f64; 2]) -> Friction {
        surface::friction_on(&self.params.terrain, &self.params.friction, at)
    }
    fn make_record(&self, data: &mut SpatialData, iterations: usize, trials: usize, h: f64) {
        make_record(self, data, iterations, trials, h);
    }
    fn skip_record(&self, data: &mut SpatialData, h: f64) {
        carry_momenta(self, data, h);
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

/// Fills `data.record` for the solved (sub)step of length `h`.
fn make_record(
    model: &SpatialModel,
    data: &mut SpatialData,
    newton_iterations: usize,
    state_trials: usize,
    h: f64,
) {
    let mech = &model.mech;
    let lay = mech.layout();
    let fbd = &data.fbd;
    let z = &data.z;
    let rec = &mut data.record;
    rec.step = data.k;
    rec.t = data.k as f64 * model.dt();
    rec.q.copy_from_slice(&data.q);
    rec.newton_iterations = newton_iterations;
    rec.state_trials = state_trials;
    for (c, spec) in mech.contacts.iter().enumerate() {
        let p = fbd.kin.point(mech, spec.point / 3, spec.kind);
        let eq = &fbd.contact[c];
        let fl = [
            z[lay.contact_force(c, 0)],
            z[lay.contact_force(c, 1)],
            z[lay.contact_force(c, 2)],
        ];
        let [t1, n, t2] = eq.frame;
        let row = &mut rec.contacts[c];
        row.point = [p.x, p.y, p.z];
        row.state = data.trial[c].code();
        row.force = std::array::from_fn(|i| fl[0] * t1[i] + fl[1] * n[i] + fl[2] * t2[i]);
        row.normal = fl[1];
    }
    for s in 0..lay.legs {
        let [z0, z1, z2] = fbd.axes[s];
        let tau = fbd.torque[s];
        let mut stop = [0.0; 3];
        let mut limit = [LimitCode::Free; 3];
        for (l, lim) in mech.limits.iter().enumerate() {
            if lim.slot == s {
                let j = lim.joint.index();
                stop[j] = z[lay.limit_moment(l)];
                limit[j] = LimitCode::of(&data.limit_trial[l]);
            }
        }
        let v = |i: usize| Vector3::new(z[i], z[i + 1], z[i + 2]);
        let hip_m = z[lay.hip_moment(s)] * fbd.hip_dir[s]
            + (tau[0] + stop[0]) * z0
            + (tau[1] + stop[1]) * z1;
        let [b1, b2] = fbd.knee_dir[s];
        let knee_m =
            z[lay.knee_moment(s, 0)] * b1 + z[lay.knee_moment(s, 1)] * b2 + (tau[2] + stop[2]) * z2;
        let row = &mut rec.legs[s];
        row.hip_force = v(lay.hip_force(s, 0)).into();
        row.hip_moment = hip_m.into();
        row.knee_force = v(lay.knee_force(s, 0)).into();
        row.knee_moment = knee_m.into();
        row.torque = tau;
        row.limit = limit;
    }
    // Rates need `data` immutably: a second pass.
    for s in 0..lay.legs {
        let r = joint_rates(model, data, s);
        data.record.legs[s].rate = r;
    }
    // Energies and momenta over the step k → k+1 (the scheme's own); the
    // momenta are the next step's L[k−½] when this step is accepted whole.
    let fbd = &mut data.fbd;
    let mut carry = std::mem::take(&mut fbd.l_carry);
    let g = model.params.gravity;
    let (mut kinetic, mut potential) = (0.0, 0.0);
    let (mut p, mut hmom) = (Vector3::zeros(), Vector3::zeros());
    for (b, body) in mech.bodies.iter().enumerate() {
        let (c0, c1) = (fbd.kin.com[b], fbd.kin_next.com[b]);
        let v = (c1 - c0) / h;
        let (l, psi) =
            half_momentum_and_rotation(&fbd.kin.rot[b], &fbd.kin_next.rot[b], &body.inertia, h);
        carry[b] = l;
        kinetic +=
            0.5 * body.mass * v.norm_squared() + 0.5 * psi.dot(&(body.inertia * psi)) / (h * h);
        potential += body.mass * g * 0.5 * (c0.y + c1.y);
        p += body.mass * v;
        hmom += body.mass * c0.cross(&v) + l;
    }
    fbd.l_carry = carry;
    fbd.l_carry_dt = h;
    let rec = &mut data.record;
    rec.kinetic = kinetic;
    rec.potential = potential;
    rec.momentum = p.into();
    rec.angular_momentum = hmom.into();
}

/// The bodies' momenta `L[k+½]` over the step, kept for the next step's
/// `L[k−½]` (as [`make_record`] keeps them), for a step without a record.
fn carry_momenta(model: &SpatialModel, data: &mut SpatialData, h: f64) {
    let fbd = &mut data.fbd;
    for (b, body) in model.mech.bodies.iter().enumerate() {
        let (l, _) =
            half_momentum_and_rotation(&fbd.kin.rot[b], &fbd.kin_next.rot[b], &body.inertia, h);
        fbd.l_carry[b] = l;
    }
    fbd.l_carry_dt = h;
}

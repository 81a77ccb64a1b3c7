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
use crate::engine::surface::{self, SurfaceEngine};
use crate::engine::{Engine, LimitInfo, Settings};
use crate::record::LimitCode;
use fbd_contact::{Friction, SpatialState, SpatialTrial, Surface};
use fbd_dynamics::spatial::half_momentum_and_rotation;
use fbd_dynamics::tree::{TreeFbdData, TreeMechanism};
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

impl SurfaceEngine for RobotSim {
    type Mech = TreeMechanism;
    fn mech(&self) -> &TreeMechanism {
        &self.mech
    }
    fn complementarity_rows(&self) -> bool {
        self.complementarity
    }
    fn bumper(&self, _c: usize) -> f64 {
        0.0
    }
    fn total_mass(&self) -> f64 {
        self.mech.total_mass()
    }
}

impl Engine for RobotSim {
    type State = SpatialState;
    type Trial = SpatialTrial;
    type Ground = Surface;
    type Fbd = TreeFbdData;
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
    fn limit_moment_index(&self, l: usize) -> usize {
        self.mech.dims().limit_moment(l)
    }

    crate::engine::surface::surface_stages!(fbd_dynamics::tree::assemble);
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
    fn skip_record(&self, data: &mut RobotData, h: f64) {
        carry_momenta(self, data, h);
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
    for (c, tc) in mech.contacts.iter().enumerate() {
        let p = fbd.kin.contact[tc.model_contact];
        let eq = &fbd.contact[c];
        let fl = [
            z[dims.contact_force(c, 0)],
            z[dims.contact_force(c, 1)],
            z[dims.contact_force(c, 2)],
        ];
        let [t1, n, t2] = eq.frame;
        let row = &mut rec.contacts[c];
        row.point = [p.x, p.y, p.z];
        row.state = data.trial[c].code();
        row.force = std::array::from_fn(|i| fl[0] * t1[i] + fl[1] * n[i] + fl[2] * t2[i]);
        row.normal = fl[1];
    }
    rec.torque.copy_from_slice(&fbd.torque);
    let v3 = |i: usize| Vector3::new(z[i], z[i + 1], z[i + 2]);
    for (i, re) in mech.reactions.iter().enumerate() {
        let [d1, d2] = fbd.moment_dir[i];
        let mut m = z[mech.reaction_moment(i, 0)] * d1;
        if !re.compound {
            m += z[mech.reaction_moment(i, 1)] * d2;
        }
        for &j in re.joint_list() {
            m += fbd.torque[j] * fbd.kin.axis[j];
        }
        rec.reaction_force[i] = v3(mech.reaction_force(i, 0)).into();
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
    // Energies and momenta over the step k → k+1 (the scheme's own); the
    // momenta are the next step's L[k−½] when this step is accepted whole.
    let fbd = &mut data.fbd;
    let g = mech.gravity;
    let (mut kinetic, mut potential) = (0.0, 0.0);
    let (mut p, mut hm, mut c) = (Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
    for (b, body) in mech.bodies.iter().enumerate() {
        let mb = body.model_body;
        let (c0, c1) = (fbd.kin.com[mb], fbd.kin_next.com[mb]);
        let v = (c1 - c0) / h;
        let (l, psi) = half_momentum_and_rotation(
            &fbd.kin.rotation[mb],
            &fbd.kin_next.rotation[mb],
            &body.inertia,
            h,
        );
        fbd.l_carry[b] = l;
        kinetic +=
            0.5 * body.mass * v.norm_squared() + 0.5 * psi.dot(&(body.inertia * psi)) / (h * h);
        potential += body.mass * g * 0.5 * (c0.y + c1.y);
        p += body.mass * v;
        hm += body.mass * c0.cross(&v) + l;
        c += body.mass * c0;
    }
    fbd.l_carry_dt = h;
    let rec = &mut data.record;
    rec.kinetic = kinetic;
    rec.potential = potential;
    rec.momentum = p.into();
    rec.angular_momentum = hm.into();
    rec.com = (c / mech.total_mass()).into();
}

/// The bodies' momenta `L[k+½]` over the step, kept for the next step's
/// `L[k−½]` (as [`make_record`] keeps them), for a step without a record.
fn carry_momenta(model: &RobotSim, data: &mut RobotData, h: f64) {
    let fbd = &mut data.fbd;
    for (b, body) in model.mech.bodies.iter().enumerate() {
        let mb = body.model_body;
        let (l, _) = half_momentum_and_rotation(
            &fbd.kin.rotation[mb],
            &fbd.kin_next.rotation[mb],
            &body.inertia,
            h,
        );
        fbd.l_carry[b] = l;
    }
    fbd.l_carry_dt = h;
}

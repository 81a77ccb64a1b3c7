//! The planar model's stages of the staged step: [`Model`] as an
//! [`Engine`] of the generic step ([`crate::engine`], which holds the
//! control flow, the state search and the retry in substeps for the plane
//! and 3D alike).
//!
//! What is planar here: the kinematics of the 7-DOF chains, the FBD
//! assembly of [`fbd_dynamics`] as a Newton system (contact equations in
//! the terrain frame at the anchor or under the point), a contact point's
//! trial and its violation, the rigid placement of anchors on one body,
//! and the step's [`RobotRecord`], the one record of every model (its
//! plane embedded in 3D: [`RobotRecord::planar`]).
//!
//! **Joint limits** are one-sided, plastic stops (`fbd_dynamics::assemble`):
//! a free joint whose trial angle crosses an end of its range is held at
//! that end; a joint at an end is released when the stop's moment would
//! pull it there instead of pushing it away.

use crate::energy;
use crate::engine::{Engine, Law, LimitInfo, Settings};
use crate::record::LimitCode;
use crate::robot::{RobotContactRow, RobotRecord};
use crate::rules::regularization;
pub use crate::system::StepSystem;
use crate::system::row_scales;
use crate::{Data, Model, SimError};
use fbd_contact::{ContactState, Friction, Terrain, Trial, friction_at};
use fbd_dynamics::{
    ContactEquation, FbdData, History, LimitEquation, advance, evaluate_next, prepare_step,
};
use fbd_solver::{NewtonReport, NewtonSolver, SolverError};

/// Solves step `data.k` and advances the state to `k + 1`, retrying in
/// substeps when the whole step cannot be solved ([`crate::engine::step`]).
/// Returns the step's record (also in `data.record`).
///
/// # Errors
/// A [`SimError`] naming the step and time.
pub fn step<'a>(model: &Model, data: &'a mut Data) -> Result<&'a RobotRecord, SimError> {
    crate::engine::step::step(model, data)?;
    Ok(&data.record)
}

impl Engine for Model {
    type State = ContactState;
    type Trial = Trial;
    type Ground = Terrain;
    type Fbd = FbdData;
    type Record = RobotRecord;
    type Torques = Vec<f64>;
    type ControlData = ();

    fn settings(&self) -> Settings<'_, Terrain> {
        Settings {
            dt: Model::dt(self),
            max_substeps: self.max_substeps,
            cycle_tolerance: self.cycle_tolerance,
            exact: false,
            qdot0: &self.params.qdot0,
            steps: self.steps,
            stride: self.params.stride,
            bodies: self.mech.bodies.len(),
            contacts: &self.mech.contacts,
            limits: self.mech.limits.len(),
            ground: &self.params.terrain,
            friction: &self.params.friction,
            contact: &self.contact,
        }
    }
    fn limit(&self, l: usize) -> LimitInfo {
        let j = self.mech.limits[l];
        LimitInfo {
            q_index: self.mech.joints[j].q_index,
            joint_index: j,
            joint: self.limit_joint[l],
            leg: self.limit_leg[l],
            range: self.params.joint_limits.range(self.limit_joint[l]),
        }
    }
    fn limit_name(&self, l: usize) -> String {
        self.mech.joints[self.mech.limits[l]].name.clone()
    }
    fn limit_moment_index(&self, l: usize) -> usize {
        self.mech.layout().limit_moment(l)
    }

    fn kinematics(&self, data: &mut Data, history: History<'_>, h: f64) {
        prepare_step(&self.mech, &mut data.fbd, history, h);
    }
    fn torques(&self, data: &mut Data) -> Result<(), SimError> {
        crate::control::joint_torques(self, data);
        Ok(())
    }
    fn solve(&self, data: &mut Data) -> Result<NewtonReport, SolverError> {
        let (mut sys, solver, z) = system(self, data);
        solver.solve(&mut sys, z)
    }
    fn evaluate_next(&self, data: &mut Data) {
        let nq = self.mech.layout().nq;
        evaluate_next(&self.mech, &mut data.fbd, &data.z[..nq]);
    }
    fn trial(&self, data: &Data, c: usize) -> Trial {
        let lay = self.mech.layout();
        let point = self.mech.contacts[c].point;
        Trial {
            p_k: data.fbd.kin.pos[point],
            p_next: data.fbd.kin_next.pos[point],
            fa: data.z[lay.contact_fa(c)],
            n: data.z[lay.contact_n(c)],
            tangent: data.fbd.contact[c].tangent,
            dt: data.fbd.dt,
        }
    }
    fn friction_at(&self, at: [f64; 2]) -> Friction {
        friction_at(&self.params.patches, &self.params.friction, at[0], at[1])
    }
    fn contact_violation(&self, data: &Data, state: &ContactState, t: &Trial) -> (f64, Law) {
        // The planar model keeps its search's measure (its outputs are
        // unchanged; it is not audited, see `Settings::exact`).
        let k = data.fbd.position_gain;
        let mu = self.friction_at([t.p_k[0], 0.0]).mu_static;
        match *state {
            ContactState::Free => (
                k * (-self.params.terrain.clearance(t.p_next)).max(0.0),
                Law::Penetration,
            ),
            ContactState::Stick { .. } => {
                let (pull, cone) = ((-t.n).max(0.0), (t.fa.abs() - mu * t.n).max(0.0));
                (
                    pull + cone,
                    if pull >= cone {
                        Law::Pull
                    } else {
                        Law::StaticCone
                    },
                )
            }
            ContactState::Slide { dir } => {
                let along = (t.p_next[0] - t.p_k[0]) * t.tangent[0]
                    + (t.p_next[1] - t.p_k[1]) * t.tangent[1];
                let (pull, back) = ((-t.n).max(0.0), k * (-along * dir).max(0.0));
                let law = if pull >= back {
                    Law::Pull
                } else {
                    Law::SlideBackwards
                };
                (pull + back, law)
            }
        }
    }
    fn limit_gain(&self, data: &Data) -> f64 {
        data.fbd.limit_gain
    }
    fn length_scale(&self, data: &Data) -> f64 {
        data.fbd.length_scale
    }
    fn anchor_at_distance(
        &self,
        data: &Data,
        reference: usize,
        from: [f64; 2],
        c: usize,
    ) -> [f64; 2] {
        let pos = &data.fbd.kin.pos;
        let p_ref = pos[self.mech.contacts[reference].point];
        let p = pos[self.mech.contacts[c].point];
        let dist = (p[0] - p_ref[0]).hypot(p[1] - p_ref[1]);
        self.params
            .terrain
            .point_at_distance(from, dist, p[0] - p_ref[0])
    }
    fn set_previous(&self, data: &mut Data) {
        self.mech
            .chains
            .eval_positions(&data.q_prev, &mut data.fbd.kin_prev);
    }
    fn reset_kinematics(&self, data: &mut Data) {
        let chains = &self.mech.chains;
        chains.eval_positions(&data.grid_q, &mut data.fbd.kin);
        chains.eval_jacobians(&mut data.fbd.kin);
        chains.eval_positions(&data.grid_q_prev, &mut data.fbd.kin_prev);
    }
    fn make_record(&self, data: &mut Data, iterations: usize, trials: usize, h: f64) {
        make_record(self, data, iterations, trials, h);
    }
    fn add_to_record(record: &mut RobotRecord, iterations: usize, trials: usize) {
        record.newton_iterations += iterations;
        record.state_trials += trials;
    }
    fn advance(&self, data: &mut Data) {
        advance(&self.mech, &mut data.fbd);
    }
}

/// Stage 4's inputs for the current trial states (contact and limit
/// equations, row scales), split from `data`: the step's
/// [`NewtonSystem`](fbd_solver::NewtonSystem), the solver and the unknowns
/// `z`. Public for benchmarks.
pub fn system<'a>(
    model: &'a Model,
    data: &'a mut Data,
) -> (StepSystem<'a>, &'a mut NewtonSolver, &'a mut [f64]) {
    set_contact_equations(model, data);
    let regularization = beta(model, data.fbd.dt);
    for (eq, &state) in data.fbd.limit.iter_mut().zip(&data.limit_trial) {
        *eq = LimitEquation {
            state,
            regularization,
            complementarity: false,
        };
    }
    row_scales(
        &model.mech,
        &data.fbd,
        data.q[0].abs().max(data.q[1].abs()),
        &mut data.scales,
        &mut data.weights,
    );
    let sys = StepSystem {
        mech: &model.mech,
        terrain: &model.params.terrain,
        fbd: &mut data.fbd,
        scales: &data.scales,
        weights: &data.weights,
    };
    (sys, &mut data.solver, &mut data.z)
}

/// The equations of each contact point for its trial state: the terrain
/// frame at the anchor (ST2), under the point at k (ST1, ST3).
fn set_contact_equations(model: &Model, data: &mut Data) {
    let terrain = &model.params.terrain;
    let beta = beta(model, data.fbd.dt);
    for (c, spec) in model.mech.contacts.iter().enumerate() {
        let state = data.trial[c];
        let x = match state {
            ContactState::Stick { anchor } => anchor[0],
            _ => data.fbd.kin.pos[spec.point][0],
        };
        let (tangent, normal) = terrain.frame(x);
        data.fbd.contact[c] = ContactEquation {
            state,
            tangent,
            normal,
            mu_dynamic: friction_at(&model.params.patches, &model.params.friction, x, 0.0)
                .mu_dynamic,
            regularization: beta + model.contact_bumper[c],
        };
    }
}

/// The regularisation β of the contact and stop rows for a (sub)step of
/// length `h` ([`crate::rules::regularization`]).
fn beta(model: &Model, h: f64) -> f64 {
    regularization(model.contact.regularization, h)
}

/// Fills `data.record` ([`RobotRecord::planar`], sized by [`Data::new`])
/// for the solved step: the plane embedded in 3D (z = 0), joint `j`'s
/// force as reaction `j`'s; no joint rates, momenta or centre of mass
/// (left zero: the planar files read none, and they would cost the step).
fn make_record(
    model: &Model,
    data: &mut Data,
    newton_iterations: usize,
    state_trials: usize,
    h: f64,
) {
    let mech = &model.mech;
    let lay = mech.layout();
    let dt = model.dt();
    let r = &mut data.record;
    r.step = data.k;
    r.t = data.k as f64 * dt;
    r.potential = energy::potential(mech, &data.fbd.kin);
    r.newton_iterations = newton_iterations;
    r.state_trials = state_trials;
    r.set_plane_q(&data.q[..lay.nq]);
    // The unknowns by block: joint forces (x, y), contact forces (Fa, N),
    // stop moments.
    let (joint_forces, rest) = data.z[lay.joint_force(0, 0)..].split_at(2 * lay.joints);
    let (contact_forces, moments) = rest.split_at(2 * mech.contacts.len());
    let contacts = (mech.contacts.iter().zip(contact_forces.chunks_exact(2)))
        .zip(data.fbd.contact.iter().zip(&data.trial));
    for (((spec, f), (eq, trial)), row) in contacts.zip(&mut r.contacts) {
        let p = data.fbd.kin.pos[spec.point];
        let (t, n) = (eq.tangent, eq.normal);
        *row = RobotContactRow {
            point: [p[0], p[1], 0.0],
            state: trial.code(),
            force: [f[0] * t[0] + f[1] * n[0], f[0] * t[1] + f[1] * n[1], 0.0],
            normal: f[1],
            tangential: [f[0], 0.0],
        };
    }
    r.torque.copy_from_slice(&data.fbd.torque);
    r.limit.fill(LimitCode::Free);
    r.stop.fill(0.0);
    for ((&j, state), &moment) in mech.limits.iter().zip(&data.limit_trial).zip(moments) {
        r.limit[j] = LimitCode::of(state);
        r.stop[j] = moment;
    }
    let joints = (mech.joints.iter().zip(joint_forces.chunks_exact(2)))
        .zip(r.torque.iter().zip(&r.stop))
        .zip(r.reaction_force.iter_mut().zip(&mut r.reaction_moment));
    for (((spec, f), (tau, stop)), (force, moment)) in joints {
        *force = [f[0], f[1], 0.0];
        *moment = [0.0, 0.0, spec.axis_z * (tau + stop)];
    }
    r.kinetic = if data.k == 0 {
        energy::kinetic_exact(mech, &data.fbd.kin, &model.params.qdot0)
    } else {
        energy::kinetic_central(mech, &data.fbd.kin_prev, &data.fbd.kin_next, h)
    };
}

//! The stepping API: any model stepped one Δt at a time by a controller
//! outside the simulator, for every model ([`Plant`]: the planar
//! [`crate::Model`], the spatial [`crate::spatial::SpatialModel`] and any
//! imported robot, [`crate::robot::RobotSim`]).
//!
//! * [`Simulator::new`] from a validated model (`fbd-scenario` builds them
//!   from TOML);
//! * [`Simulator::step`] with an [`Action`]: the configured controller,
//!   joint torques, or position/velocity targets PD-tracked inside the step
//!   by the controllers' own law ([`crate::control::pd_torque`], one source
//!   with `[control] kind = "pd"`);
//! * [`Simulator::state`] / [`Simulator::set_state`]: everything the next
//!   step depends on (`q[k]`, `q[k−1]`, `q[k−2]`, the contact states and
//!   anchors, the limit states, the predictor's history, the controller's
//!   memory, the assembly's carried momenta and the solver's kept
//!   factorisations): stepping after a restore is bit-identical to
//!   stepping on;
//! * [`Simulator::readout`]: body poses and twists, joint angles, rates and
//!   torques, joint reaction forces and moments (per leg, or per reaction
//!   of an imported robot), every contact point's
//!   position, state, force, normal and slip velocity, energies
//!   ([`Readout`]).
//!
//! ```
//! use fbd_sim::simulator::{Action, Simulator};
//! use fbd_sim::spatial::{SpatialModel, SpatialParams};
//! let model = SpatialModel::new(&SpatialParams::default()).unwrap();
//! let mut sim = Simulator::new(model);
//! let saved = sim.state();
//! sim.step(&Action::Torques(&[0.0; 18])).unwrap();
//! let after = sim.q().to_vec();
//! sim.set_state(&saved);
//! sim.step(&Action::Torques(&[0.0; 18])).unwrap();
//! assert_eq!(sim.q(), &after[..]);
//! let r = sim.readout();
//! assert_eq!(r.joints.len(), 18);
//! ```

use crate::engine::{Engine, RunData};
use crate::spatial::SpatialModel;
use crate::{Model, SimError};
use fbd_contact::StateCode;
use fbd_dynamics::PointKind;

/// What a model must give the stepping API beyond the generic step: its
/// fresh workspace, its actuated joints, how external torques are set and
/// its readouts. Implemented by [`Model`], [`SpatialModel`] and
/// [`crate::robot::RobotSim`].
pub trait Plant: Engine<Fbd: Clone, Record: Clone, Torques: Clone, ControlData: Clone> {
    /// The workspace at the model's initial state.
    fn fresh(&self) -> RunData<Self>;
    /// The actuated joints' indices in `q`, in the order of the torques:
    /// the planar model's hip3, knee3, hip4, knee4; the hexapod's
    /// `(θ1, θ2, θ3)` of each leg of the model in order; an imported
    /// robot's every joint in model order (`6 + j`).
    fn joint_indices(&self) -> Vec<usize>;
    /// Sets the external torques of the next step from a flat slice in the
    /// order of [`Self::joint_indices`].
    fn set_torques(&self, data: &mut RunData<Self>, tau: &[f64]);
    /// Fills `out` from the state after the last step ([`Readout`]).
    fn read(&self, data: &RunData<Self>, out: &mut Readout);
}

/// A control action for one step.
#[derive(Clone, Copy, Debug)]
pub enum Action<'a> {
    /// The configured controller (`[control]`).
    Controller,
    /// Joint torques (N·m, positive towards larger angles), one per joint
    /// in the order of [`Plant::joint_indices`], applied as given.
    Torques(&'a [f64]),
    /// PD tracking of targets, evaluated in the step from `q[k]`, `q[k−1]`.
    Pd(&'a PdTargets),
}

/// Per-joint PD targets: `τ = kp·(θ* − θ[k]) + kd·(θ̇* − θ̇[k])`, clamped to
/// `±torque_limit`, with `θ̇[k] = (θ[k] − θ[k−1])/Δt` (the initial rate at
/// k = 0), exactly the law of `[control] kind = "pd"`
/// ([`crate::control::pd_torque`]). Every vector has one value per joint
/// (order of [`Plant::joint_indices`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PdTargets {
    /// Stiffness per joint (N·m/rad).
    pub kp: Vec<f64>,
    /// Damping per joint (N·m·s/rad).
    pub kd: Vec<f64>,
    /// Saturation `|τ| ≤ limit` (N·m); `None` for no limit.
    pub torque_limit: Option<f64>,
    /// Target angles θ* (rad).
    pub position: Vec<f64>,
    /// Target rates θ̇* (rad/s).
    pub velocity: Vec<f64>,
}

impl PdTargets {
    /// Uniform gains, the given angles, zero target rates.
    pub fn hold(kp: f64, kd: f64, torque_limit: Option<f64>, position: &[f64]) -> Self {
        let n = position.len();
        Self {
            kp: vec![kp; n],
            kd: vec![kd; n],
            torque_limit,
            position: position.to_vec(),
            velocity: vec![0.0; n],
        }
    }
}

/// A saved state of a [`Simulator`] (see [`Simulator::state`]).
pub struct SimState<M: Plant> {
    data: RunData<M>,
}

impl<M: Plant> Clone for SimState<M> {
    fn clone(&self) -> Self {
        Self {
            data: self.data.clone(),
        }
    }
}

impl<M: Plant> SimState<M> {
    /// Steps solved at this state (`k`).
    pub fn k(&self) -> usize {
        self.data.k
    }
    /// `q[k]`.
    pub fn q(&self) -> &[f64] {
        &self.data.q
    }
}

/// One body's pose and twist at `q[k]`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyReadout {
    /// Centre of mass, inertial frame (m).
    pub position: [f64; 3],
    /// Rotation body → inertial, row-major.
    pub rotation: [[f64; 3]; 3],
    /// Centre-of-mass velocity, inertial frame (m/s): the backward
    /// difference over the last step (the spatial model), the exact rate
    /// of the backward-difference `q̇` (the planar model); zero at k = 0.
    pub velocity: [f64; 3],
    /// Angular velocity, inertial frame (rad/s): `log(R[k]·R[k−1]ᵀ)/Δt`
    /// (spatial), the angle's rate (planar, along Z); zero at k = 0.
    pub angular_velocity: [f64; 3],
}

/// One actuated joint.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct JointReadout {
    /// Angle `θ[k]` (rad).
    pub angle: f64,
    /// Rate `(θ[k] − θ[k−1])/Δt` (rad/s; the initial rate at k = 0).
    pub rate: f64,
    /// Actuator torque of the step solved last (N·m).
    pub torque: f64,
}

/// One leg's joint reactions at the step solved last (inertial frame):
/// the force and moment of the body on the upper link at the hip, of the
/// upper link on the lower link at the knee (actuator torques and limit
/// stops included in the moments).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LegReadout {
    /// Leg number (1–6).
    pub leg: usize,
    /// Hip force (N).
    pub hip_force: [f64; 3],
    /// Hip moment about the hip point (N·m).
    pub hip_moment: [f64; 3],
    /// Knee force (N).
    pub knee_force: [f64; 3],
    /// Knee moment about the knee point (N·m).
    pub knee_moment: [f64; 3],
}

/// One joint reaction of an imported robot at the step solved last
/// (inertial frame): the force of the parent on the child body at the
/// reaction's first joint's origin and the moment on the child about that
/// point (constraint moments, actuator torques and stops), the columns
/// `<joint>_fx … <joint>_mz` of its `trajectory.csv`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct ReactionReadout {
    /// Force (N).
    pub force: [f64; 3],
    /// Moment (N·m).
    pub moment: [f64; 3],
}

/// One contact point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactReadout {
    /// Leg number (an imported robot: the point's index + 1).
    pub leg: usize,
    /// Tip, knee or hip (an imported robot's points: tip).
    pub kind: PointKind,
    /// Position at `q[k]`, inertial frame (m).
    pub position: [f64; 3],
    /// State the point was solved in at the step solved last.
    pub state: StateCode,
    /// Force of the ground on the point at the step solved last, inertial
    /// frame (N).
    pub force: [f64; 3],
    /// Its normal component (N).
    pub normal_force: f64,
    /// The terrain's unit normal below the point at `q[k]`.
    pub normal: [f64; 3],
    /// Slip velocity: the tangential part of `(p[k] − p[k−1])/Δt` (m/s),
    /// the sliding velocity of the contact law at the step solved last;
    /// zero at k = 0.
    pub slip_velocity: [f64; 3],
}

impl Default for ContactReadout {
    fn default() -> Self {
        Self {
            leg: 0,
            kind: PointKind::Tip,
            position: [0.0; 3],
            state: StateCode::St1,
            force: [0.0; 3],
            normal_force: 0.0,
            normal: [0.0, 1.0, 0.0],
            slip_velocity: [0.0; 3],
        }
    }
}

/// What a controller can read after a step (the planar model's are 3D
/// with z = 0, angular velocities along Z). Forces, torques and energies
/// are those of the step solved last (step `k − 1`, evaluated at
/// `q[k−1]`, zero before the first step); positions and rates are at the
/// current state `q[k]`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Readout {
    /// Steps solved (`k`).
    pub k: usize,
    /// Time `k·Δt` (s).
    pub t: f64,
    /// `q[k]`.
    pub q: Vec<f64>,
    /// `(q[k] − q[k−1])/Δt` (the initial velocities at k = 0).
    pub qdot: Vec<f64>,
    /// Every rigid body: the central body first, then per leg the upper
    /// and the lower link; an imported robot's every body in model order
    /// (the root first).
    pub bodies: Vec<BodyReadout>,
    /// Actuated joints, order of [`Plant::joint_indices`].
    pub joints: Vec<JointReadout>,
    /// Joint reactions per leg (the planar model and the hexapod; empty
    /// for an imported robot).
    pub legs: Vec<LegReadout>,
    /// Joint reactions of an imported robot, one per reaction of its
    /// mechanism ([`fbd_dynamics::tree::TreeMechanism::reactions`]; empty
    /// for the planar model and the hexapod).
    pub reactions: Vec<ReactionReadout>,
    /// Contact points, the model's order.
    pub contacts: Vec<ContactReadout>,
    /// Kinetic energy (J).
    pub kinetic: f64,
    /// Potential energy (J).
    pub potential: f64,
}

/// A model stepped one Δt at a time (see the module docs).
pub struct Simulator<M: Plant> {
    model: M,
    data: RunData<M>,
    joints: Vec<usize>,
    tau: Vec<f64>,
    /// The record before the step being solved (a failed step's retries
    /// overwrite `data.record`; it is put back).
    kept: M::Record,
}

impl<M: Plant> Simulator<M> {
    /// A simulator at the model's initial state.
    pub fn new(model: M) -> Self {
        let data = model.fresh();
        let joints = model.joint_indices();
        let tau = vec![0.0; joints.len()];
        let kept = data.record.clone();
        Self {
            model,
            data,
            joints,
            tau,
            kept,
        }
    }

    /// The model.
    pub fn model(&self) -> &M {
        &self.model
    }

    /// The run's workspace (read-only: the record of the last step is
    /// `data().record`).
    pub fn data(&self) -> &RunData<M> {
        &self.data
    }

    /// Actuated joints.
    pub fn joints(&self) -> usize {
        self.joints.len()
    }

    /// Steps solved (`k`).
    pub fn k(&self) -> usize {
        self.data.k
    }

    /// Time of the current state, `k·Δt` (s).
    pub fn t(&self) -> f64 {
        self.data.k as f64 * self.model.dt()
    }

    /// `q[k]`.
    pub fn q(&self) -> &[f64] {
        &self.data.q
    }

    /// `q[k−1]` (`q[0]` at k = 0).
    pub fn q_prev(&self) -> &[f64] {
        &self.data.q_prev
    }

    /// The backward-difference velocity `(q[k] − q[k−1])/Δt`, the initial
    /// velocity at `k = 0`: the rate the PD law uses.
    pub fn qdot(&self, out: &mut [f64]) {
        let dt = self.model.dt();
        for (i, v) in out.iter_mut().enumerate() {
            *v = if self.data.k == 0 {
                self.model.qdot0()[i]
            } else {
                (self.data.q[i] - self.data.q_prev[i]) / dt
            };
        }
    }

    /// Solves one step with `action`.
    ///
    /// # Errors
    /// The step's [`SimError`]; the state and the readouts are then those
    /// before the step was tried, and the simulator may be restored.
    ///
    /// # Panics
    /// When the torques or targets do not have one value per joint.
    pub fn step(&mut self, action: &Action<'_>) -> Result<(), SimError> {
        match action {
            Action::Controller => self.data.external_torque = None,
            Action::Torques(tau) => {
                assert_eq!(tau.len(), self.joints.len(), "one torque per joint");
                self.model.set_torques(&mut self.data, tau);
            }
            Action::Pd(pd) => {
                self.pd_torques(pd);
                self.model.set_torques(&mut self.data, &self.tau);
            }
        }
        self.kept.clone_from(&self.data.record);
        let result = crate::engine::step::step(&self.model, &mut self.data);
        self.data.external_torque = None;
        if result.is_err() {
            std::mem::swap(&mut self.data.record, &mut self.kept);
        }
        result
    }

    /// The PD torques of `pd` at the current state into `self.tau`.
    fn pd_torques(&mut self, pd: &PdTargets) {
        let n = self.joints.len();
        assert!(
            pd.kp.len() == n
                && pd.kd.len() == n
                && pd.position.len() == n
                && pd.velocity.len() == n,
            "PD targets: one value per joint ({n})"
        );
        let dt = self.model.dt();
        for (j, &i) in self.joints.iter().enumerate() {
            let rate = if self.data.k == 0 {
                self.model.qdot0()[i]
            } else {
                (self.data.q[i] - self.data.q_prev[i]) / dt
            };
            self.tau[j] = crate::control::pd_torque(
                pd.kp[j],
                pd.kd[j],
                pd.torque_limit,
                pd.position[j],
                pd.velocity[j],
                self.data.q[i],
                rate,
            );
        }
    }

    /// Everything the next step depends on.
    pub fn state(&self) -> SimState<M> {
        SimState {
            data: self.data.clone(),
        }
    }

    /// Back to a saved state (of a simulator of the same model).
    pub fn set_state(&mut self, state: &SimState<M>) {
        self.data.clone_from(&state.data);
    }

    /// Back to the initial state.
    pub fn reset(&mut self) {
        self.data = self.model.fresh();
    }

    /// The readouts of the current state (allocates; see
    /// [`Self::readout_into`]).
    pub fn readout(&self) -> Readout {
        let mut r = Readout::default();
        self.readout_into(&mut r);
        r
    }

    /// The readouts into `out` (its vectors are resized).
    pub fn readout_into(&self, out: &mut Readout) {
        out.k = self.data.k;
        out.t = self.t();
        out.q.clone_from(&self.data.q);
        out.qdot.resize(self.data.q.len(), 0.0);
        self.qdot(&mut out.qdot);
        out.joints
            .resize(self.joints.len(), JointReadout::default());
        for (j, &i) in self.joints.iter().enumerate() {
            out.joints[j].angle = self.data.q[i];
            out.joints[j].rate = out.qdot[i];
        }
        self.model.read(&self.data, out);
    }
}

/// A contact point's readout: `spec` its identity, `at` its position at
/// `q[k]` and the terrain's normal there, `before` its position at
/// `q[k−1]` (`None` before the first step: no slip), `state` and `force`
/// (with its normal component) of the step solved last.
pub(crate) fn contact_readout(
    spec: &fbd_dynamics::ContactSpec,
    at: [[f64; 3]; 2],
    before: Option<[f64; 3]>,
    dt: f64,
    state: StateCode,
    force: ([f64; 3], f64),
) -> ContactReadout {
    let [p, normal] = at;
    ContactReadout {
        leg: spec.leg,
        kind: spec.kind,
        position: p,
        state,
        force: force.0,
        normal_force: force.1,
        normal,
        slip_velocity: before.map_or([0.0; 3], |q| tangential(sub(p, q).map(|x| x / dt), normal)),
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn tangential(v: [f64; 3], n: [f64; 3]) -> [f64; 3] {
    let d = v[0] * n[0] + v[1] * n[1] + v[2] * n[2];
    [v[0] - d * n[0], v[1] - d * n[1], v[2] - d * n[2]]
}

impl Plant for SpatialModel {
    fn fresh(&self) -> RunData<Self> {
        RunData::<SpatialModel>::new(self)
    }
    fn joint_indices(&self) -> Vec<usize> {
        (0..self.legs.len())
            .flat_map(|s| (0..3).map(move |j| fbd_dynamics::spatial::q_joint(s, j)))
            .collect()
    }
    fn set_torques(&self, data: &mut RunData<Self>, tau: &[f64]) {
        let legs = self.legs.len();
        let t = data
            .external_torque
            .get_or_insert_with(|| vec![[0.0; 3]; legs]);
        for (s, t) in t.iter_mut().enumerate() {
            *t = [tau[3 * s], tau[3 * s + 1], tau[3 * s + 2]];
        }
    }
    fn read(&self, data: &RunData<Self>, out: &mut Readout) {
        read_tree(
            self,
            data,
            self.mech.bodies.iter().map(|b| b.model_body),
            out,
        );
        out.reactions.clear();
        out.legs.resize(self.legs.len(), LegReadout::default());
        for (s, l) in out.legs.iter_mut().enumerate() {
            let leg = self.leg_row(&data.record, s);
            *l = LegReadout {
                leg: leg.leg,
                hip_force: leg.hip_force,
                hip_moment: leg.hip_moment,
                knee_force: leg.knee_force,
                knee_moment: leg.knee_moment,
            };
        }
    }
}

/// The readout every model on the tree equations shares (the hexapod's
/// and every imported robot's): the model bodies `bodies` (position,
/// rotation and velocities from `q[k−1]` → `q[k]`), the joints' torques,
/// every contact point and the energies, from the one record
/// ([`crate::robot::RobotRecord`]).
pub(crate) fn read_tree<M>(
    model: &M,
    data: &RunData<M>,
    bodies: impl ExactSizeIterator<Item = usize>,
    out: &mut Readout,
) where
    M: crate::engine::surface::SurfaceEngine<
            Mech = fbd_dynamics::tree::TreeMechanism,
            Fbd = fbd_dynamics::tree::TreeFbdData,
            Record = crate::robot::RobotRecord,
        >,
{
    let mech = model.mech();
    let dt = model.dt();
    let moved = data.k > 0;
    let (kin, prev) = (&data.fbd.kin, &data.fbd.kin_prev);
    out.bodies.resize(bodies.len(), BodyReadout::default());
    for (body, b) in out.bodies.iter_mut().zip(bodies) {
        let r = kin.rotation[b];
        let c = kin.com[b];
        body.position = [c.x, c.y, c.z];
        body.rotation = std::array::from_fn(|i| std::array::from_fn(|j| r[(i, j)]));
        if moved {
            let v = (c - prev.com[b]) / dt;
            let w = r * fbd_dynamics::spatial::so3::log(&(prev.rotation[b].transpose() * r)) / dt;
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
    let specs = model.settings().contacts;
    let ground = model.ground();
    out.contacts
        .resize(mech.contacts.len(), ContactReadout::default());
    for (c, tc) in mech.contacts.iter().enumerate() {
        let p = kin.contact[tc.model_contact];
        let p = [p.x, p.y, p.z];
        let normal = ground.normal(p[0], p[2]);
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
        out.contacts[c] = contact_readout(
            &specs[c],
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

impl Plant for Model {
    fn fresh(&self) -> RunData<Self> {
        crate::Data::new(self)
    }
    fn joint_indices(&self) -> Vec<usize> {
        self.mech.joints.iter().map(|j| j.q_index).collect()
    }
    fn set_torques(&self, data: &mut RunData<Self>, tau: &[f64]) {
        match &mut data.external_torque {
            Some(t) => t.copy_from_slice(tau),
            None => data.external_torque = Some(tau.to_vec()),
        }
    }
    fn read(&self, data: &RunData<Self>, out: &mut Readout) {
        let moved = data.k > 0;
        let chains = &self.mech.chains;
        let kin = &data.fbd.kin;
        out.bodies
            .resize(self.mech.bodies.len(), BodyReadout::default());
        for (body, spec) in out.bodies.iter_mut().zip(&self.mech.bodies) {
            let p = kin.pos[spec.com];
            let a = kin.angle[spec.angle];
            let (s, c) = a.sin_cos();
            body.position = [p[0], p[1], 0.0];
            body.rotation = [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]];
            if moved {
                let v = chains.point_velocity(kin, spec.com, &out.qdot);
                body.velocity = [v[0], v[1], 0.0];
                body.angular_velocity = [0.0, 0.0, chains.angles[spec.angle].rate(&out.qdot)];
            } else {
                body.velocity = [0.0; 3];
                body.angular_velocity = [0.0; 3];
            }
        }
        let rec = &data.record;
        for (j, joint) in out.joints.iter_mut().enumerate() {
            joint.torque = rec.torque[j];
        }
        // Joints in pairs (hip, knee) per leg: legs 3 and 4.
        let legs = self.mech.joints.len() / 2;
        out.legs.resize(legs, LegReadout::default());
        for (l, leg) in out.legs.iter_mut().enumerate() {
            *leg = LegReadout {
                leg: 3 + l,
                hip_force: rec.reaction_force[2 * l],
                hip_moment: rec.reaction_moment[2 * l],
                knee_force: rec.reaction_force[2 * l + 1],
                knee_moment: rec.reaction_moment[2 * l + 1],
            };
        }
        let mut prev = chains.new_data();
        if moved {
            chains.eval_positions(&data.q_prev, &mut prev);
        }
        let dt = Model::dt(self);
        out.contacts
            .resize(self.mech.contacts.len(), ContactReadout::default());
        for (c, spec) in self.mech.contacts.iter().enumerate() {
            let p = kin.pos[spec.point];
            let p3 = [p[0], p[1], 0.0];
            let (_, n) = self.params.terrain.frame(p[0]);
            let normal = [n[0], n[1], 0.0];
            let slip = if moved {
                let q = prev.pos[spec.point];
                tangential(sub(p3, [q[0], q[1], 0.0]).map(|x| x / dt), normal)
            } else {
                [0.0; 3]
            };
            // The force along the tangent and normal at the step's point.
            let row = &rec.contacts[c];
            let (t, nn) = self.params.terrain.frame(row.point[0]);
            let (fa, fn_) = (row.tangential[0], row.normal);
            out.contacts[c] = ContactReadout {
                leg: spec.leg,
                kind: spec.kind,
                position: p3,
                state: if moved {
                    row.state
                } else {
                    data.states[c].code()
                },
                force: [fa * t[0] + fn_ * nn[0], fa * t[1] + fn_ * nn[1], 0.0],
                normal_force: fn_,
                normal,
                slip_velocity: slip,
            };
        }
        out.kinetic = rec.kinetic;
        out.potential = rec.potential;
    }
}

#[cfg(test)]
mod tests {
    use super::{Action, PdTargets, Plant, Simulator};
    use crate::spatial::{SpatialControl, SpatialModel, SpatialParams};
    use crate::{Control, Model, PlanarParams};

    /// The hexapod of `examples/hexapod_stand.toml`: every leg at
    /// (0°, −20°, 290°), the feet 5 mm above the ground; `steps` steps.
    fn stand(control: SpatialControl, steps: usize) -> SpatialParams {
        let mut p = SpatialParams {
            duration: steps as f64 * 0.001,
            control,
            ..SpatialParams::default()
        };
        p.friction.mu_static = 0.8;
        p.friction.mu_dynamic = 0.6;
        p.q0[1] = 0.3566;
        for s in 0..6 {
            p.q0[6 + 3 * s..9 + 3 * s].copy_from_slice(&[
                0.0,
                (-20f64).to_radians(),
                290f64.to_radians(),
            ]);
        }
        p
    }

    fn bits(v: &[f64]) -> Vec<u64> {
        v.iter().map(|x| x.to_bits()).collect()
    }

    fn hold(model: &impl Plant, q0: &[f64]) -> PdTargets {
        let angles: Vec<f64> = model.joint_indices().iter().map(|&i| q0[i]).collect();
        PdTargets::hold(300.0, 8.0, None, &angles)
    }

    /// Stepping after `set_state` repeats stepping on, bit for bit, with
    /// the feet touching down in between (contact states, anchors, the
    /// predictor and the solver's kept factorisations all restored).
    #[test]
    fn restore_is_bit_identical_hexapod() {
        let model = SpatialModel::new(&stand(SpatialControl::None, 80)).unwrap();
        let pd = hold(&model, &model.params.q0);
        let mut sim = Simulator::new(model);
        for _ in 0..5 {
            sim.step(&Action::Pd(&pd)).unwrap();
        }
        let saved = sim.state();
        let run = |sim: &mut Simulator<SpatialModel>| {
            let mut out = Vec::new();
            for k in 0..40 {
                // Torques of their own every other step.
                if k % 2 == 0 {
                    sim.step(&Action::Pd(&pd)).unwrap();
                } else {
                    sim.step(&Action::Torques(&[0.5; 18])).unwrap();
                }
                let r = sim.readout();
                out.push(bits(&r.q));
                out.push(bits(
                    &r.contacts.iter().map(|c| c.force[1]).collect::<Vec<_>>(),
                ));
            }
            out
        };
        let first = run(&mut sim);
        let touched = sim.readout().contacts.iter().any(|c| c.normal_force > 0.0);
        assert!(touched, "the feet touched down in the compared steps");
        sim.set_state(&saved);
        assert_eq!(run(&mut sim), first);
        // A copy of the state stepped in another simulator.
        let mut other = Simulator::new(sim.model().clone());
        other.set_state(&saved);
        assert_eq!(run(&mut other), first);
    }

    /// The same for the planar model (the paper's fall, touchdown at
    /// 0.19 s).
    #[test]
    fn restore_is_bit_identical_planar() {
        let p = PlanarParams {
            duration: 0.3,
            ..PlanarParams::default()
        };
        let mut sim = Simulator::new(Model::planar(&p).unwrap());
        for _ in 0..15 {
            sim.step(&Action::Torques(&[0.0; 4])).unwrap();
        }
        let saved = sim.state();
        let run = |sim: &mut Simulator<Model>| {
            (0..12)
                .map(|_| {
                    sim.step(&Action::Controller).unwrap();
                    bits(&sim.readout().q)
                })
                .collect::<Vec<_>>()
        };
        let a = run(&mut sim);
        assert!(sim.readout().contacts.iter().any(|c| c.normal_force > 0.0));
        sim.set_state(&saved);
        assert_eq!(run(&mut sim), a);
    }

    /// PD targets set through the API give the run of `[control] kind =
    /// "pd"` bit for bit (the hexapod, through touchdown and standing).
    #[test]
    fn pd_through_the_api_is_the_configured_pd_hexapod() {
        let steps = 120;
        let passive = stand(SpatialControl::None, steps);
        let target: Vec<[f64; 3]> = (0..6)
            .map(|s| std::array::from_fn(|j| passive.q0[6 + 3 * s + j]))
            .collect();
        let pd = SpatialControl::Pd {
            kp: 300.0,
            kd: 8.0,
            torque_limit: Some(60.0),
            target,
        };
        let configured = SpatialModel::new(&stand(pd, steps)).unwrap();
        let (rows, summary) = crate::spatial::run_collect(&configured);
        assert!(summary.error.is_none());
        let model = SpatialModel::new(&passive).unwrap();
        let mut targets = hold(&model, &passive.q0);
        targets.torque_limit = Some(60.0);
        let mut sim = Simulator::new(model);
        for row in rows.iter().skip(1) {
            sim.step(&Action::Pd(&targets)).unwrap();
            assert_eq!(bits(sim.q()), bits(&row.q), "step {}", row.step);
        }
        assert!(rows.last().unwrap().contacts.iter().any(|c| c.normal > 0.0));
        // The readouts of the step solved last (k − 1) are the run's row
        // k − 1: forces, states, torques, energies.
        let r = sim.readout();
        assert_eq!(r.k, rows.len() - 1);
        let row = &rows[r.k - 1];
        for (c, want) in r.contacts.iter().zip(&row.contacts) {
            assert_eq!(
                (c.force, c.normal_force, c.state),
                (want.force, want.normal, want.state)
            );
        }
        for (j, joint) in r.joints.iter().enumerate() {
            assert_eq!(joint.torque, row.torque[j]);
        }
        assert_eq!((r.kinetic, r.potential), (row.kinetic, row.potential));
        assert_eq!(r.legs[2].knee_force, sim.model().leg_row(row, 2).knee_force);
    }

    /// The same for the planar model's `Control::Pd`.
    #[test]
    fn pd_through_the_api_is_the_configured_pd_planar() {
        let target = [[0.1, 4.3], [-0.1, 4.4]];
        let base = PlanarParams {
            duration: 0.3,
            ..PlanarParams::default()
        };
        let configured = Model::planar(&PlanarParams {
            control: Control::Pd {
                kp: 200.0,
                kd: 3.0,
                torque_limit: Some(40.0),
                target,
            },
            ..base.clone()
        })
        .unwrap();
        let (rows, _) = crate::run_collect(&configured);
        let mut sim = Simulator::new(Model::planar(&base).unwrap());
        let pd = PdTargets {
            torque_limit: Some(40.0),
            ..PdTargets::hold(200.0, 3.0, None, &[0.1, 4.3, -0.1, 4.4])
        };
        for row in rows.iter().skip(1) {
            sim.step(&Action::Pd(&pd)).unwrap();
            assert_eq!(bits(sim.q()), bits(&row.plane_q()), "step {}", row.step);
        }
    }

    /// Readouts: the body's twist is the backward difference of its pose,
    /// a sticking foot does not slip, the forces of a standing robot carry
    /// its weight.
    #[test]
    fn readouts_agree_with_the_state() {
        let model = SpatialModel::new(&stand(SpatialControl::None, 200)).unwrap();
        let pd = hold(&model, &model.params.q0);
        let mut sim = Simulator::new(model);
        for _ in 0..200 {
            sim.step(&Action::Pd(&pd)).unwrap();
        }
        let r = sim.readout();
        let dt = 0.001;
        let b = &r.bodies[0];
        for i in 0..3 {
            assert_eq!(b.position[i], r.q[i]);
            let v = (sim.q()[i] - sim.q_prev()[i]) / dt;
            assert!((b.velocity[i] - v).abs() < 1e-9, "{} {}", b.velocity[i], v);
        }
        let tips: Vec<_> = r
            .contacts
            .iter()
            .filter(|c| c.kind == fbd_dynamics::PointKind::Tip)
            .collect();
        assert_eq!(tips.len(), 6);
        let mut weight = 0.0;
        for c in &tips {
            assert_eq!(c.state, fbd_contact::StateCode::St2);
            assert!(c.slip_velocity.iter().all(|v| v.abs() < 1e-9));
            assert_eq!(c.normal, [0.0, 1.0, 0.0]);
            weight += c.force[1];
        }
        let m = 10.0 + 6.0 * (0.3 + 1.1);
        assert!((weight - m * 9.81).abs() < 0.05 * m * 9.81, "{weight}");
        assert!(r.kinetic >= 0.0 && r.legs.len() == 6);
    }
}

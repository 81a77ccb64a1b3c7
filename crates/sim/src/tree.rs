//! A flight stepper for any robot model ([`fbd_robot::RobotModel`]): the
//! FBD step equations of [`fbd_dynamics::tree`] driven by Newton, as the
//! spatial hexapod's engine ([`crate::spatial`]) drives
//! [`fbd_dynamics::spatial`]'s, without ground and without joint stops.
//!
//! * [`TreeFlight`] (immutable): the mechanism, `Δt`, the number of steps
//!   and the Newton parameters, built from the model, `Δt`, the duration
//!   and gravity;
//! * [`TreeFlightData`] (the mutable workspace, allocated once): the
//!   assembly's workspace, the solver, `q[k]` and `q[k−1]`, the unknowns
//!   and the record of the last solved step ([`TreeFlightRecord`]);
//! * [`step`]: one time step with given joint torques (passive joints:
//!   zeros).
//!
//! The layout of `q` is the spatial model's: `(R, φ)` of the floating base,
//! then the joint angles in model order; the initial rates `q̇0` have the
//! same layout, the base's angular velocity entering as `φ̇` (as
//! [`crate::spatial::SpatialParams::qdot0`]). The first step takes its
//! history from `q̇0` ([`History::Initial`]), every later one from
//! `q[k−1]`.
//!
//! What is **not** modelled: contact with the ground (the mechanism has no
//! contact points) and joint stops (every stop row is free: a joint that
//! leaves its limits ends the run with an error rather than being held).

use crate::SimError;
use crate::predictor::Predictor;
use crate::rules::Sink;
use fbd_contact::Surface;
use fbd_dynamics::spatial::half_momentum_and_rotation;
use fbd_dynamics::tree::TreeFbdData;
use fbd_dynamics::tree::TreeMechanism;
use fbd_dynamics::tree::assemble::{
    advance, eval, evaluate_next, pattern, pattern_key, prepare_step, set_configuration,
    set_previous,
};
use fbd_dynamics::{History, LimitEquation, NoJacobian};
use fbd_kinematics::nalgebra::Vector3;
use fbd_robot::RobotModel;
use fbd_solver::{NewtonParams, NewtonSolver, NewtonSystem};

/// Everything fixed during a flight of a robot model.
#[derive(Clone, Debug)]
pub struct TreeFlight {
    /// The FBD mechanism (no contact points).
    pub mech: TreeMechanism,
    /// Time step Δt (s).
    pub dt: f64,
    /// Steps to solve: `round(duration/dt) + 1` (as the spatial model).
    pub steps: usize,
    /// Newton tolerances (the spatial model's by default).
    pub newton: NewtonParams,
    /// The (unused) ground of the assembly: there are no contact points.
    surface: Surface,
}

impl TreeFlight {
    /// The flight of `model` at step `dt` (s) over `duration` (s) under
    /// `gravity` (m/s², along −Y).
    ///
    /// # Errors
    /// [`SimError::InvalidParameter`] for a step that is not positive and
    /// finite or a negative or non-finite duration.
    pub fn new(model: &RobotModel, dt: f64, duration: f64, gravity: f64) -> Result<Self, SimError> {
        let invalid = |key: &str, got: f64, expected: &str| SimError::InvalidParameter {
            key: key.to_owned(),
            what: "out of range".to_owned(),
            got: got.to_string(),
            expected: expected.to_owned(),
        };
        if !(dt.is_finite() && dt > 0.0) {
            return Err(invalid("time.dt", dt, "> 0"));
        }
        if !(duration.is_finite() && duration >= 0.0) {
            return Err(invalid("time.duration", duration, "≥ 0"));
        }
        if !gravity.is_finite() {
            return Err(invalid("gravity", gravity, "finite"));
        }
        Ok(Self {
            mech: TreeMechanism::with_contacts(model, gravity, &[]),
            dt,
            steps: (duration / dt).round() as usize + 1,
            newton: NewtonParams {
                chord_steps: 6,
                residual_tol: 1e-9,
                max_iterations: 50,
                max_backtracks: 30,
                ..NewtonParams::default()
            },
            surface: Surface::default(),
        })
    }

    /// Number of generalised coordinates, `6 + joints`.
    pub fn nq(&self) -> usize {
        self.mech.nq()
    }
}

/// What one flight step produced (refilled every step, no allocation).
#[derive(Clone, Debug, PartialEq)]
pub struct TreeFlightRecord {
    /// Step index k.
    pub step: usize,
    /// Time k·Δt (s).
    pub t: f64,
    /// `q[k]` (m, rad).
    pub q: Vec<f64>,
    /// Per reaction ([`TreeMechanism::reactions`]), the force at its first
    /// joint's origin on the child body (N, inertial; the parent gets its
    /// opposite).
    pub reaction_force: Vec<[f64; 3]>,
    /// Per reaction, the moment on the child body about that point:
    /// constraint moments, actuator torques `Σ τ_j·u_j` and stop moments
    /// (N·m, inertial).
    pub reaction_moment: Vec<[f64; 3]>,
    /// Per model joint, its actuator torque at k (N·m).
    pub torque: Vec<f64>,
    /// Total linear momentum over the step k → k+1 (kg·m/s).
    pub momentum: [f64; 3],
    /// Total angular momentum about the origin over the step (kg·m²/s).
    pub angular_momentum: [f64; 3],
    /// Centre of mass of the whole robot at `q[k]` (m).
    pub com: [f64; 3],
    /// Kinetic energy over the step (J, the scheme's).
    pub kinetic: f64,
    /// Gravitational potential energy, mean of k and k+1 (J).
    pub potential: f64,
    /// Newton iterations of this step.
    pub newton_iterations: usize,
}

/// The mutable workspace of a flight (see the module docs).
#[derive(Clone, Debug)]
pub struct TreeFlightData {
    /// The assembly's workspace.
    pub fbd: TreeFbdData,
    /// The Newton solver (its pattern caches).
    pub solver: NewtonSolver,
    /// Next step index k.
    pub k: usize,
    /// `q[k]`.
    pub q: Vec<f64>,
    /// `q[k−1]` (`q[0]` at k = 0).
    pub q_prev: Vec<f64>,
    /// The initial rates `q̇0`.
    pub qdot0: Vec<f64>,
    /// The unknowns of the last solve: `q[k+1]`, the reactions, the stop
    /// moments.
    pub z: Vec<f64>,
    /// The record of the last solved step.
    pub record: TreeFlightRecord,
    predictor: Predictor,
    scales: Vec<f64>,
}

impl TreeFlightData {
    /// A workspace at `q0` with rates `qdot0` (layouts in the module docs).
    ///
    /// # Panics
    /// If `q0` or `qdot0` does not have [`TreeFlight::nq`] entries.
    pub fn new(flight: &TreeFlight, q0: &[f64], qdot0: &[f64]) -> Self {
        let mech = &flight.mech;
        let nq = mech.nq();
        assert_eq!(q0.len(), nq, "q0 has {} entries, expected {nq}", q0.len());
        assert_eq!(qdot0.len(), nq, "qdot0 has {} entries", qdot0.len());
        let n = mech.dim();
        let mut fbd = TreeFbdData::new(mech);
        set_configuration(mech, &mut fbd, q0);
        set_previous(mech, &mut fbd, q0);
        let mut z = vec![0.0; n];
        z[..nq].copy_from_slice(q0);
        let nr = mech.reactions.len();
        let nj = mech.model.joints.len();
        Self {
            fbd,
            solver: NewtonSolver::new(flight.newton),
            k: 0,
            q: q0.to_vec(),
            q_prev: q0.to_vec(),
            qdot0: qdot0.to_vec(),
            predictor: Predictor::new(q0, &z),
            z,
            record: TreeFlightRecord {
                step: 0,
                t: 0.0,
                q: q0.to_vec(),
                reaction_force: vec![[0.0; 3]; nr],
                reaction_moment: vec![[0.0; 3]; nr],
                torque: vec![0.0; nj],
                momentum: [0.0; 3],
                angular_momentum: [0.0; 3],
                com: [0.0; 3],
                kinetic: 0.0,
                potential: 0.0,
                newton_iterations: 0,
            },
            scales: vec![1.0; n],
        }
    }
}

/// One flight step's equations as a [`NewtonSystem`].
struct TreeSystem<'a> {
    mech: &'a TreeMechanism,
    surface: &'a Surface,
    data: &'a mut TreeFbdData,
    scales: &'a [f64],
}

impl NewtonSystem for TreeSystem<'_> {
    fn dim(&self) -> usize {
        self.mech.dim()
    }
    fn pattern_key(&self) -> u64 {
        pattern_key(self.data)
    }
    fn pattern(&self, entries: &mut Vec<(usize, usize)>) {
        pattern(self.mech, self.data, entries);
    }
    fn eval(&mut self, x: &[f64], r: &mut [f64], jac: Option<&mut fbd_solver::JacobianSink<'_>>) {
        match jac {
            Some(j) => eval(self.mech, self.surface, self.data, x, r, &mut Sink(j)),
            None => eval(self.mech, self.surface, self.data, x, r, &mut NoJacobian),
        }
    }
    fn residual_scale(&self, row: usize) -> f64 {
        self.scales[row]
    }
}

/// Convergence scales as the spatial engine's: forces to the weight with a
/// round-off floor, moments times the length scale.
fn row_scales(mech: &TreeMechanism, data: &mut TreeFlightData) {
    let dims = mech.dims();
    let k = data.fbd.position_gain;
    let q = &data.q;
    let extent = q[0].abs().max(q[1].abs()).max(q[2].abs());
    let force = mech.total_mass() * mech.gravity.abs().max(1.0) + 1e-6 * k * (1.0 + extent);
    let moment = force * mech.length_scale();
    for b in 0..dims.bodies {
        let row = dims.body_row(b);
        data.scales[row..row + 3].fill(force);
        data.scales[row + 3..row + 6].fill(moment);
    }
    for c in 0..dims.contacts {
        let row = dims.contact_row(c);
        data.scales[row..row + 3].fill(force);
    }
    for l in 0..dims.limits {
        data.scales[dims.limit_row(l)] = moment;
    }
}

/// Solves step `data.k` with the joint torques `torques` (N·m, one per
/// model joint, positive towards larger angles), fills `data.record` and
/// advances to `k + 1`. No allocation after the first step.
///
/// # Errors
/// [`SimError::Newton`] when Newton fails, [`SimError::NonFinite`] for a
/// non-finite solution, [`SimError::Control`] when a joint ends the step
/// outside its limits (joint stops are not modelled by this stepper) —
/// each naming the step and time. The state is then left at step k.
///
/// # Panics
/// If `torques` does not have one entry per model joint.
pub fn step(
    flight: &TreeFlight,
    data: &mut TreeFlightData,
    torques: &[f64],
) -> Result<(), SimError> {
    let mech = &flight.mech;
    let nq = mech.nq();
    let dt = flight.dt;
    let k = data.k;
    let t = k as f64 * dt;
    assert_eq!(
        torques.len(),
        mech.model.joints.len(),
        "one torque per joint"
    );
    // Stage 1: kinematics at k and the step's constants.
    let history = if k == 0 {
        History::Initial { qdot: &data.qdot0 }
    } else {
        History::Previous
    };
    prepare_step(mech, &mut data.fbd, history, dt);
    data.fbd.torque.copy_from_slice(torques);
    for eq in &mut data.fbd.limit {
        *eq = LimitEquation::default();
    }
    // Stage 2: the predictor.
    if k == 0 {
        for ((z, &q), &v) in data.z.iter_mut().zip(&data.q).zip(&data.qdot0) {
            *z = q + dt * v;
        }
    } else {
        data.predictor.predict(&mut data.z);
    }
    // Stage 3: Newton.
    row_scales(mech, data);
    let mut sys = TreeSystem {
        mech,
        surface: &flight.surface,
        data: &mut data.fbd,
        scales: &data.scales,
    };
    let report = data
        .solver
        .solve(&mut sys, &mut data.z)
        .map_err(|source| SimError::Newton { step: k, t, source })?;
    if !data.z.iter().all(|v| v.is_finite()) {
        return Err(SimError::NonFinite {
            step: k,
            t,
            residual: report.residual,
        });
    }
    // Stage 4: the joints stay within their limits (no stops here).
    for lim in &mech.limits {
        let a = data.z[lim.q_index];
        if a < lim.range[0] || a > lim.range[1] {
            return Err(SimError::Control {
                step: k,
                t,
                message: format!(
                    "joint {} leaves its limits [{}, {}] rad (angle {a} rad at t + Δt): \
                     joint stops are not modelled by the tree flight stepper",
                    mech.model.joints[lim.joint].name, lim.range[0], lim.range[1]
                ),
            });
        }
    }
    evaluate_next(mech, &mut data.fbd, &data.z[..nq]);
    make_record(flight, data, report.iterations);
    // Stage 5: accept.
    data.predictor.record(&data.z, true);
    std::mem::swap(&mut data.q_prev, &mut data.q);
    data.q.copy_from_slice(&data.z[..nq]);
    advance(&mut data.fbd);
    data.fbd.l_carry_valid = true;
    data.k += 1;
    Ok(())
}

/// Fills `data.record` for the solved step k (and the bodies' momenta
/// `L[k+½]`, the next step's `L[k−½]`, as the spatial engine carries them).
fn make_record(flight: &TreeFlight, data: &mut TreeFlightData, iterations: usize) {
    let mech = &flight.mech;
    let dims = mech.dims();
    let h = flight.dt;
    let fbd = &mut data.fbd;
    let z = &data.z;
    let rec = &mut data.record;
    rec.step = data.k;
    rec.t = data.k as f64 * h;
    rec.q.copy_from_slice(&data.q);
    rec.newton_iterations = iterations;
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
    for (l, lim) in mech.limits.iter().enumerate() {
        let m = Vector3::from(rec.reaction_moment[lim.reaction])
            + z[dims.limit_moment(l)] * fbd.kin.axis[lim.joint];
        rec.reaction_moment[lim.reaction] = m.into();
    }
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
    rec.kinetic = kinetic;
    rec.potential = potential;
    rec.momentum = p.into();
    rec.angular_momentum = hm.into();
    rec.com = (c / mech.total_mass()).into();
}

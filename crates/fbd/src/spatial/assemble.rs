//! Residual and analytic Jacobian of one spatial time step (see the module
//! docs of [`crate::spatial`] for the unknowns, equations and the rotation
//! scheme). Written entry by entry through a [`JacobianSink`]; the same
//! code path declares the pattern ([`pattern`]), so the two cannot drift.

use super::kin::{Columns, SpatialKin};
use super::mechanism::{SpatialMechanism, lower_body, upper_body};
use super::so3;
use crate::assemble::{History, JacobianSink, LimitEquation};
use crate::mechanism::PointKind;
use crate::rows;
use fbd_contact::spatial::clearance;
use fbd_contact::{SpatialState, Surface};
use fbd_kinematics::nalgebra::{Matrix3, Vector3};

struct PatternSink<'a>(&'a mut Vec<(usize, usize)>);

impl JacobianSink for PatternSink<'_> {
    const ACTIVE: bool = true;
    #[inline]
    fn add(&mut self, row: usize, col: usize, _: f64) {
        self.0.push((row, col));
    }
}

/// The equations a contact point contributes in this step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpatialContactEquation {
    /// ST1 / ST2 (anchor) / ST3 (slip direction).
    pub state: SpatialState,
    /// The contact frame `(t1, n, t2)` the force is expressed in.
    pub frame: [[f64; 3]; 3],
    /// Dynamic friction coefficient μD (ST3).
    pub mu_dynamic: f64,
    /// Regularisation β of the position rows.
    pub regularization: f64,
}

impl Default for SpatialContactEquation {
    fn default() -> Self {
        Self {
            state: SpatialState::Free,
            frame: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            mu_dynamic: 0.0,
            regularization: 0.0,
        }
    }
}

/// Per-step constants of one body's six equations.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyStep3 {
    /// Coefficient of the `k+1` term (1, or 2 at k = 0).
    pub c_next: f64,
    /// Constant of the centre of mass's second difference:
    /// `−2c[k] + c[k−1]`, or `−2c[0] − 2Δt·ċ(0)` at k = 0.
    pub x_const: Vector3<f64>,
    /// Constant of the momentum difference: `L[k−½]`, or `2·L(0)` at k = 0.
    pub l_const: Vector3<f64>,
    /// Centre of mass at `q[k]` (the moment reference).
    pub com_k: Vector3<f64>,
}

impl Default for BodyStep3 {
    fn default() -> Self {
        Self {
            c_next: 1.0,
            x_const: Vector3::zeros(),
            l_const: Vector3::zeros(),
            com_k: Vector3::zeros(),
        }
    }
}

/// The discrete angular momentum of a body over a step (inertial frame):
/// `L = R[k]·exp(ψ/2)·I·ψ/Δt` with `ψ = log(R[k]ᵀ·R[k+1])`, and its
/// derivative `∂L/∂η` for a spatial perturbation `R[k+1] → exp([η]×)·R[k+1]`.
pub fn half_momentum(
    r_k: &Matrix3<f64>,
    r_next: &Matrix3<f64>,
    inertia: &Matrix3<f64>,
    dt: f64,
) -> (Vector3<f64>, Matrix3<f64>) {
    let psi = so3::log(&(r_k.transpose() * r_next));
    let r_mid = r_k * so3::exp(&(0.5 * psi));
    let ipsi = inertia * psi;
    // The same operations as `half_momentum_value`: bit-identical values.
    let l = r_k * so3::rotate(&(0.5 * psi), &ipsi) / dt;
    let d = r_mid
        * (inertia - 0.5 * so3::hat(&ipsi) * so3::right_jacobian(&(0.5 * psi)))
        * so3::right_jacobian_inv(&psi)
        * r_next.transpose()
        / dt;
    (l, d)
}

/// [`half_momentum`] without its derivative (residual-only evaluations).
pub fn half_momentum_value(
    r_k: &Matrix3<f64>,
    r_next: &Matrix3<f64>,
    inertia: &Matrix3<f64>,
    dt: f64,
) -> Vector3<f64> {
    half_momentum_and_rotation(r_k, r_next, inertia, dt).0
}

/// [`half_momentum_value`] and the step's rotation `ψ` it is made of.
pub fn half_momentum_and_rotation(
    r_k: &Matrix3<f64>,
    r_next: &Matrix3<f64>,
    inertia: &Matrix3<f64>,
    dt: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    let psi = so3::log(&(r_k.transpose() * r_next));
    (r_k * so3::rotate(&(0.5 * psi), &(inertia * psi)) / dt, psi)
}

/// Mutable workspace of the spatial assembly (allocated once).
#[derive(Clone, Debug)]
pub struct SpatialFbdData {
    /// Kinematics at `q[k−1]`.
    pub kin_prev: SpatialKin,
    /// Kinematics at `q[k]`.
    pub kin: SpatialKin,
    /// Kinematics at the current iterate of `q[k+1]`.
    pub kin_next: SpatialKin,
    /// Per-body constants of this step.
    pub body: Vec<BodyStep3>,
    /// Per-contact equations of this step.
    pub contact: Vec<SpatialContactEquation>,
    /// Per-limit equations (order of [`SpatialMechanism::limits`]).
    pub limit: Vec<LimitEquation>,
    /// Actuator torques `(τ1, τ2, τ3)` per slot at k (N·m).
    pub torque: Vec<[f64; 3]>,
    /// Time step (s).
    pub dt: f64,
    /// Scale of contact position rows `M/Δt²` (N/m).
    pub position_gain: f64,
    /// Scale of limit rows `(M/Δt²)·ℓ²` (N·m/rad).
    pub limit_gain: f64,
    /// Per slot, the joint axes `(z0, z1, z2)` at k.
    pub axes: Vec<[Vector3<f64>; 3]>,
    /// Per slot, the hip's constraint-moment direction `z0 × z1` at k.
    pub hip_dir: Vec<Vector3<f64>>,
    /// Per slot, the knee's constraint-moment directions `(b1, b2)` at k:
    /// `b1` along the upper link, `b2 = z2 × b1`.
    pub knee_dir: Vec<[Vector3<f64>; 2]>,
    /// Per body, `L[k+½]` at the last evaluated iterate.
    pub l_next: Vec<Vector3<f64>>,
    /// Per body, the sum of applied forces at k of the last evaluation (N).
    pub force: Vec<Vector3<f64>>,
    /// Per body, the sum of applied moments about its CoM at k (N·m).
    pub moment: Vec<Vector3<f64>>,
    /// `L[k+½]` of every body at the accepted `q[k+1]` over a step of
    /// `l_carry_dt`, handed to the next step's [`prepare_step`] as its
    /// `L[k−½]` (the same function of the same rotations, so the same
    /// numbers) when `l_carry_valid`; the stepping loop sets it.
    pub l_carry: Vec<Vector3<f64>>,
    /// The step length of `l_carry`.
    pub l_carry_dt: f64,
    /// Whether `l_carry` holds the last accepted step's momenta.
    pub l_carry_valid: bool,
    /// `ε = STOP_SPEED·Δt` (m) of [`slip_direction`].
    pub slip_bias: f64,
    /// Per contact, the slip direction `ŝ` at the last evaluated iterate
    /// (sliding points; `(t1, t2)` components).
    pub slip_hat: Vec<[f64; 2]>,
    /// Per contact: the slide's friction keeps its reference direction `u`
    /// (the planar rule, used when the implicit direction has no solution:
    /// a slide about to stop), instead of following the step's slip.
    pub fixed_direction: Vec<bool>,
    /// Per contact, `max(|w|, ε)` of [`slip_direction`] at the last
    /// evaluated iterate (m).
    pub slip_len: Vec<f64>,
    slip_n: Vec<f64>,
    rot_d: Vec<Matrix3<f64>>,
    /// The `q` `kin_next` was last evaluated at (NaN: none).
    kin_next_q: Vec<f64>,
    next_is_candidate: bool,
}

/// Slip speed (m/s) below which a slide has stopped (1e-9 m/s): the friction
/// direction is regularised below it (see [`slip_direction`]) and the
/// state machine switches such a slide to ST2.
pub use fbd_contact::spatial::STOP_SPEED;

/// The direction of a sliding point's friction over the step (`(t1, t2)`
/// components): `ŝ = w/max(|w|, ε)`, `w = s + ½ε·u`, with `s` the slip
/// from `p[k]` to `p[k+1]` in the tangent plane, `u` the slide's reference
/// direction (the last step's slip, or at the start of a slide the
/// opposite of the force sticking needed) and `ε = STOP_SPEED·Δt`.
/// Friction `−μD·N·ŝ` opposes the slip of the step itself (implicit, like
/// everything at k+1) — exactly Coulomb's `s/|s|` for every slip faster
/// than 1e-9 m/s; slower, it is regularised (linear in `w`), so that the
/// equations always have a solution, and the slide counts as stopped. The
/// bias `½ε·u` only picks the direction of a slip that has not started yet
/// and turns a real slip's direction by at most `ε/(2|s|)` (5e-8 rad at
/// 1 cm/s at Δt = 1 ms). Returns `(ŝ, max(|w|, ε))`.
#[inline]
pub fn slip_direction(s: [f64; 2], u: [f64; 2], eps: f64) -> ([f64; 2], f64) {
    let w = [s[0] + 0.5 * eps * u[0], s[1] + 0.5 * eps * u[1]];
    let len = w[0].hypot(w[1]).max(eps);
    ([w[0] / len, w[1] / len], len)
}

impl SpatialFbdData {
    /// A workspace for `mech`.
    pub fn new(mech: &SpatialMechanism) -> Self {
        let kin = SpatialKin::new(mech);
        let (nb, nl) = (mech.bodies.len(), mech.legs.len());
        Self {
            kin_prev: kin.clone(),
            kin_next: kin.clone(),
            kin,
            body: vec![BodyStep3::default(); nb],
            contact: vec![SpatialContactEquation::default(); mech.contacts.len()],
            limit: vec![LimitEquation::default(); mech.limits.len()],
            torque: vec![[0.0; 3]; nl],
            dt: 0.0,
            position_gain: 0.0,
            limit_gain: 0.0,
            axes: vec![[Vector3::zeros(); 3]; nl],
            hip_dir: vec![Vector3::zeros(); nl],
            knee_dir: vec![[Vector3::zeros(); 2]; nl],
            l_next: vec![Vector3::zeros(); nb],
            l_carry: vec![Vector3::zeros(); nb],
            l_carry_dt: 0.0,
            l_carry_valid: false,
            slip_bias: 0.0,
            slip_hat: vec![[0.0; 2]; mech.contacts.len()],
            slip_len: vec![1.0; mech.contacts.len()],
            fixed_direction: vec![false; mech.contacts.len()],
            slip_n: vec![0.0; mech.contacts.len()],
            force: vec![Vector3::zeros(); nb],
            moment: vec![Vector3::zeros(); nb],
            rot_d: vec![Matrix3::zeros(); nb],
            kin_next_q: vec![f64::NAN; mech.layout().nq],
            next_is_candidate: false,
        }
    }
}

/// Sets `q[k]` (at k = 0; afterwards [`advance`] does it).
pub fn set_configuration(mech: &SpatialMechanism, data: &mut SpatialFbdData, q: &[f64]) {
    data.kin.eval(mech, q);
}

/// Sets `q[k−1]` (for a restart in substeps).
pub fn set_previous(mech: &SpatialMechanism, data: &mut SpatialFbdData, q: &[f64]) {
    data.kin_prev.eval(mech, q);
}

/// Angular momentum `R·I·Rᵀ·ω` of body `b` at `kin` for `ω`.
pub fn momentum(
    mech: &SpatialMechanism,
    kin: &SpatialKin,
    b: usize,
    w: &Vector3<f64>,
) -> Vector3<f64> {
    let r = &kin.rot[b];
    r * (mech.bodies[b].inertia * (r.transpose() * w))
}

/// Stage "kinematics at k": every body's constants and the constraint
/// directions of this step, given `q[k]` (and `q[k−1]`) already set.
pub fn prepare_step(
    mech: &SpatialMechanism,
    data: &mut SpatialFbdData,
    history: History<'_>,
    dt: f64,
) {
    data.dt = dt;
    data.slip_bias = STOP_SPEED * dt;
    let carried = data.l_carry_valid;
    data.l_carry_valid = false;
    data.position_gain = mech.total_mass() / (dt * dt);
    let l = mech.length_scale();
    data.limit_gain = data.position_gain * l * l;
    for b in 0..mech.bodies.len() {
        let com_k = data.kin.com[b];
        data.body[b] = match history {
            History::Previous => BodyStep3 {
                c_next: 1.0,
                x_const: -2.0 * com_k + data.kin_prev.com[b],
                l_const: if carried && data.l_carry_dt == dt {
                    data.l_carry[b]
                } else {
                    half_momentum_value(
                        &data.kin_prev.rot[b],
                        &data.kin.rot[b],
                        &mech.bodies[b].inertia,
                        dt,
                    )
                },
                com_k,
            },
            History::Initial { qdot } => {
                let v = data.kin.com_jacobian(mech, b).apply(qdot);
                let w = data.kin.angular_jacobian(mech, b).apply(qdot);
                BodyStep3 {
                    c_next: 2.0,
                    x_const: -2.0 * com_k - 2.0 * dt * v,
                    l_const: 2.0 * momentum(mech, &data.kin, b, &w),
                    com_k,
                }
            }
        };
    }
    for s in 0..mech.legs.len() {
        let axes = data.kin.axes(mech, s);
        data.axes[s] = axes;
        data.hip_dir[s] = axes[0].cross(&axes[1]).normalize();
        let b1: Vector3<f64> = data.kin.rot[upper_body(s)].column(0).into();
        data.knee_dir[s] = [b1, axes[2].cross(&b1)];
    }
}

/// Evaluates the kinematics at a candidate `q[k+1]` into `kin_next` (after
/// the solve), so that [`advance`] can accept it.
pub fn evaluate_next(mech: &SpatialMechanism, data: &mut SpatialFbdData, q_next: &[f64]) {
    // The last evaluation is usually at the solution already.
    if data.kin_next_q != q_next {
        data.kin_next.eval(mech, q_next);
        data.kin_next_q.copy_from_slice(q_next);
    }
    data.next_is_candidate = true;
}

/// Accepts the candidate of [`evaluate_next`]: `q[k]` becomes the previous
/// configuration, `q[k+1]` the current one.
///
/// # Panics
/// If [`evaluate_next`] was not called since the last [`eval`].
pub fn advance(data: &mut SpatialFbdData) {
    assert!(
        data.next_is_candidate,
        "advance needs evaluate_next at the accepted configuration"
    );
    std::mem::swap(&mut data.kin_prev, &mut data.kin);
    std::mem::swap(&mut data.kin, &mut data.kin_next);
    data.kin_next_q.fill(f64::NAN);
    data.next_is_candidate = false;
}

/// The sparsity key: contact state codes in base 3, then one bit per limit.
pub fn pattern_key(data: &SpatialFbdData) -> u64 {
    rows::pattern_key(
        data.contact.iter().map(|c| c.state.code()),
        data.limit.iter().map(|l| l.state.is_at()),
    )
}

/// Pushes every structural `(row, col)` of the Jacobian for the current
/// states.
pub fn pattern(mech: &SpatialMechanism, data: &SpatialFbdData, entries: &mut Vec<(usize, usize)>) {
    let mut sink = PatternSink(entries);
    force_entries(mech, data, &mut sink);
    position_entries(mech, &Surface::default(), data, &mut sink);
}

#[inline]
fn v3(z: &[f64], i: usize) -> Vector3<f64> {
    Vector3::new(z[i], z[i + 1], z[i + 2])
}

#[inline]
fn frame_force(eq: &SpatialContactEquation, f: Vector3<f64>) -> Vector3<f64> {
    let [t1, n, t2] = eq.frame;
    Vector3::new(
        f[0] * t1[0] + f[1] * n[0] + f[2] * t2[0],
        f[0] * t1[1] + f[1] * n[1] + f[2] * t2[1],
        f[0] * t1[2] + f[1] * n[2] + f[2] * t2[2],
    )
}

/// The child and parent bodies of joint `j` (0–2) of slot `s`.
#[inline]
fn joint_bodies(s: usize, j: usize) -> (usize, usize) {
    if j < 2 {
        (upper_body(s), 0)
    } else {
        (lower_body(s), upper_body(s))
    }
}

/// The slot of a contact point.
#[inline]
fn slot_of(point: usize) -> usize {
    point / 3
}

/// Residual `r(z)` and, through `jac`, the analytic Jacobian.
pub fn eval<S: JacobianSink>(
    mech: &SpatialMechanism,
    surface: &Surface,
    data: &mut SpatialFbdData,
    z: &[f64],
    r: &mut [f64],
    jac: &mut S,
) {
    let lay = mech.layout();
    assert_eq!(z.len(), lay.dim(), "unknown vector has the wrong length");
    assert_eq!(r.len(), lay.dim(), "residual vector has the wrong length");
    if data.kin_next_q[..] != z[..lay.nq] {
        data.kin_next.eval(mech, &z[..lay.nq]);
        data.kin_next_q.copy_from_slice(&z[..lay.nq]);
    }
    data.next_is_candidate = false;
    let dt = data.dt;
    for (b, body) in mech.bodies.iter().enumerate() {
        data.force[b] = Vector3::new(0.0, -body.mass * mech.gravity, 0.0);
        data.moment[b] = Vector3::zeros();
    }
    let kin = &data.kin;
    for s in 0..lay.legs {
        let (u, l) = (upper_body(s), lower_body(s));
        let [z0, z1, z2] = data.axes[s];
        let tau = data.torque[s];
        // Hip: body on upper link.
        let p = kin.point(mech, s, PointKind::Hip);
        let f = v3(z, lay.hip_force(s, 0));
        let m = z[lay.hip_moment(s)] * data.hip_dir[s] + tau[0] * z0 + tau[1] * z1;
        for (b, sgn) in [(u, 1.0), (0, -1.0)] {
            data.force[b] += sgn * f;
            data.moment[b] += sgn * ((p - data.body[b].com_k).cross(&f) + m);
        }
        // Knee: upper link on lower link.
        let p = kin.point(mech, s, PointKind::Knee);
        let f = v3(z, lay.knee_force(s, 0));
        let [b1, b2] = data.knee_dir[s];
        let m = z[lay.knee_moment(s, 0)] * b1 + z[lay.knee_moment(s, 1)] * b2 + tau[2] * z2;
        for (b, sgn) in [(l, 1.0), (u, -1.0)] {
            data.force[b] += sgn * f;
            data.moment[b] += sgn * ((p - data.body[b].com_k).cross(&f) + m);
        }
    }
    for (li, lim) in mech.limits.iter().enumerate() {
        let j = lim.joint.index();
        let m = z[lay.limit_moment(li)] * data.axes[lim.slot][j];
        let (child, parent) = joint_bodies(lim.slot, j);
        data.moment[child] += m;
        data.moment[parent] -= m;
    }
    for (c, spec) in mech.contacts.iter().enumerate() {
        let eq = &data.contact[c];
        let f = frame_force(eq, v3(z, lay.contact_force(c, 0)));
        let p = kin.point(mech, slot_of(spec.point), spec.kind);
        data.force[spec.body] += f;
        data.moment[spec.body] += (p - data.body[spec.body].com_k).cross(&f);
    }
    for (b, body) in mech.bodies.iter().enumerate() {
        let bs = &data.body[b];
        let row = lay.body_row(b);
        let acc = (bs.c_next * data.kin_next.com[b] + bs.x_const) / (dt * dt);
        let l_next = if S::ACTIVE {
            let (l, d) = half_momentum(&data.kin.rot[b], &data.kin_next.rot[b], &body.inertia, dt);
            data.rot_d[b] = d * (bs.c_next / dt);
            l
        } else {
            half_momentum_value(&data.kin.rot[b], &data.kin_next.rot[b], &body.inertia, dt)
        };
        data.l_next[b] = l_next;
        let dl = (bs.c_next * l_next - bs.l_const) / dt;
        for i in 0..3 {
            r[row + i] = body.mass * acc[i] - data.force[b][i];
            r[row + 3 + i] = dl[i] - data.moment[b][i];
        }
    }
    let k = data.position_gain;
    for (c, spec) in mech.contacts.iter().enumerate() {
        let eq = &data.contact[c];
        let row = lay.contact_row(c);
        let fl = v3(z, lay.contact_force(c, 0));
        let p = data.kin_next.point(mech, slot_of(spec.point), spec.kind);
        let out = &mut r[row..row + 3];
        match eq.state {
            SpatialState::Free => rows::free_rows(fl.as_slice(), out),
            SpatialState::Stick { anchor } => {
                let f = frame_force(eq, fl);
                rows::stick_rows(
                    k,
                    p.as_slice(),
                    &anchor,
                    eq.regularization,
                    f.as_slice(),
                    out,
                );
            }
            SpatialState::Slide { dir } => {
                let d = p - data.kin.point(mech, slot_of(spec.point), spec.kind);
                let [t1, _, t2] = eq.frame;
                let s = [
                    d.x * t1[0] + d.y * t1[1] + d.z * t1[2],
                    d.x * t2[0] + d.y * t2[1] + d.z * t2[2],
                ];
                let (u, len) = if data.fixed_direction[c] {
                    (dir, f64::INFINITY)
                } else {
                    slip_direction(s, dir, data.slip_bias)
                };
                data.slip_hat[c] = u;
                data.slip_len[c] = len;
                data.slip_n[c] = fl[1];
                rows::slide_rows(
                    fl.as_slice(),
                    &u,
                    eq.mu_dynamic,
                    k,
                    clearance(surface, [p.x, p.y, p.z]),
                    eq.regularization,
                    out,
                );
            }
        }
    }
    for (li, lim) in mech.limits.iter().enumerate() {
        let lambda = z[lay.limit_moment(li)];
        let eq = &data.limit[li];
        r[lay.limit_row(li)] = rows::limit_row(eq, lambda, z[lim.q_index], data.limit_gain);
    }
    if S::ACTIVE {
        force_entries(mech, data, jac);
        position_entries(mech, surface, data, jac);
    }
}

/// `−∂(r × f)/∂f = −[r]×` into the rotation rows of body `b` for the three
/// force columns starting at `col` (times `sgn`).
#[inline]
fn arm_entries<S: JacobianSink>(jac: &mut S, row: usize, col: usize, r: &Vector3<f64>, sgn: f64) {
    let h = so3::hat(r);
    for i in 0..3 {
        for j in 0..3 {
            if i != j {
                jac.add(row + 3 + i, col + j, -sgn * h[(i, j)]);
            }
        }
        jac.add(row + i, col + i, -sgn);
    }
}

/// Entries in the force columns (constant within a step).
fn force_entries<S: JacobianSink>(mech: &SpatialMechanism, data: &SpatialFbdData, jac: &mut S) {
    let lay = mech.layout();
    let kin = &data.kin;
    for s in 0..lay.legs {
        let (u, l) = (upper_body(s), lower_body(s));
        let p = kin.point(mech, s, PointKind::Hip);
        for (b, sgn) in [(u, 1.0), (0, -1.0)] {
            let row = lay.body_row(b);
            arm_entries(
                jac,
                row,
                lay.hip_force(s, 0),
                &(p - data.body[b].com_k),
                sgn,
            );
            for i in 0..3 {
                jac.add(row + 3 + i, lay.hip_moment(s), -sgn * data.hip_dir[s][i]);
            }
        }
        let p = kin.point(mech, s, PointKind::Knee);
        for (b, sgn) in [(l, 1.0), (u, -1.0)] {
            let row = lay.body_row(b);
            arm_entries(
                jac,
                row,
                lay.knee_force(s, 0),
                &(p - data.body[b].com_k),
                sgn,
            );
            for m in 0..2 {
                for i in 0..3 {
                    jac.add(
                        row + 3 + i,
                        lay.knee_moment(s, m),
                        -sgn * data.knee_dir[s][m][i],
                    );
                }
            }
        }
    }
    for (c, spec) in mech.contacts.iter().enumerate() {
        let eq = &data.contact[c];
        let p = kin.point(mech, slot_of(spec.point), spec.kind);
        let arm = p - data.body[spec.body].com_k;
        let row = lay.body_row(spec.body);
        let crow = lay.contact_row(c);
        for (m, e) in eq.frame.iter().enumerate() {
            let e = Vector3::new(e[0], e[1], e[2]);
            let col = lay.contact_force(c, m);
            let me = arm.cross(&e);
            for i in 0..3 {
                jac.add(row + i, col, -e[i]);
                jac.add(row + 3 + i, col, -me[i]);
            }
            match eq.state {
                SpatialState::Free => jac.add(crow + m, col, 1.0),
                SpatialState::Stick { .. } => {
                    for i in 0..3 {
                        jac.add(crow + i, col, eq.regularization * e[i]);
                    }
                }
                SpatialState::Slide { .. } => match m {
                    0 => jac.add(crow, col, 1.0),
                    2 => jac.add(crow + 2, col, 1.0),
                    _ => {
                        let u = data.slip_hat[c];
                        jac.add(crow, col, u[0] * eq.mu_dynamic);
                        jac.add(crow + 1, col, eq.regularization);
                        jac.add(crow + 2, col, u[1] * eq.mu_dynamic);
                    }
                },
            }
        }
    }
    for (li, lim) in mech.limits.iter().enumerate() {
        let j = lim.joint.index();
        let axis = data.axes[lim.slot][j];
        let col = lay.limit_moment(li);
        let (child, parent) = joint_bodies(lim.slot, j);
        for i in 0..3 {
            jac.add(lay.body_row(child) + 3 + i, col, -axis[i]);
            jac.add(lay.body_row(parent) + 3 + i, col, axis[i]);
        }
        jac.add(
            lay.limit_row(li),
            col,
            rows::limit_row_diagonal(&data.limit[li]),
        );
    }
}

/// Entries in the `q[k+1]` columns at the iterate `kin_next`.
fn position_entries<S: JacobianSink>(
    mech: &SpatialMechanism,
    surface: &Surface,
    data: &SpatialFbdData,
    jac: &mut S,
) {
    let lay = mech.layout();
    let kin = &data.kin_next;
    let dt2 = data.dt * data.dt;
    for (b, body) in mech.bodies.iter().enumerate() {
        let row = lay.body_row(b);
        let g = body.mass * data.body[b].c_next / dt2;
        let jc: Columns = kin.com_jacobian(mech, b);
        for (i, v) in jc.iter() {
            for a in 0..3 {
                jac.add(row + a, *i, g * v[a]);
            }
        }
        let jw = kin.angular_jacobian(mech, b);
        let d = &data.rot_d[b];
        for (i, w) in jw.iter() {
            let col = d * w;
            for a in 0..3 {
                jac.add(row + 3 + a, *i, col[a]);
            }
        }
    }
    let k = data.position_gain;
    for (c, spec) in mech.contacts.iter().enumerate() {
        let row = lay.contact_row(c);
        match data.contact[c].state {
            SpatialState::Free => {}
            SpatialState::Stick { .. } => {
                let jp = kin.contact_jacobian(mech, slot_of(spec.point), spec.kind);
                for (i, v) in jp.iter() {
                    for a in 0..3 {
                        jac.add(row + a, *i, k * v[a]);
                    }
                }
            }
            SpatialState::Slide { .. } => {
                let p = kin.point(mech, slot_of(spec.point), spec.kind);
                let [gx, gz] = surface.gradient(p.x, p.z);
                let jp = kin.contact_jacobian(mech, slot_of(spec.point), spec.kind);
                // Friction rows: μ·N·∂ŝ/∂s·∂s/∂q, ∂ŝ/∂s = (I − ŝŝᵀ)/|w|
                // (Coulomb) or I/ε (regularised, |w| < ε).
                let eq = &data.contact[c];
                let [t1, _, t2] = eq.frame;
                let u = data.slip_hat[c];
                let len = data.slip_len[c];
                let g = eq.mu_dynamic * data.slip_n[c] / len;
                let p2 = if len > data.slip_bias {
                    [
                        [1.0 - u[0] * u[0], -u[0] * u[1]],
                        [-u[1] * u[0], 1.0 - u[1] * u[1]],
                    ]
                } else {
                    [[1.0, 0.0], [0.0, 1.0]]
                };
                for (i, v) in jp.iter() {
                    jac.add(row + 1, *i, k * (v[1] - gx * v[0] - gz * v[2]));
                    let ds = [
                        v[0] * t1[0] + v[1] * t1[1] + v[2] * t1[2],
                        v[0] * t2[0] + v[1] * t2[1] + v[2] * t2[2],
                    ];
                    jac.add(row, *i, g * (p2[0][0] * ds[0] + p2[0][1] * ds[1]));
                    jac.add(row + 2, *i, g * (p2[1][0] * ds[0] + p2[1][1] * ds[1]));
                }
            }
        }
    }
    for (li, lim) in mech.limits.iter().enumerate() {
        if data.limit[li].state.is_at() {
            jac.add(lay.limit_row(li), lim.q_index, data.limit_gain);
        }
    }
}

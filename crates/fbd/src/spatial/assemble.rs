//! Residual and analytic Jacobian of one spatial time step (see the module
//! docs of [`crate::spatial`] for the unknowns, equations and the rotation
//! scheme). The equations are assembled by the one assembly of the plane
//! and space, [`crate::assembly`]; this module supplies the hexapod's part
//! ([`FbdModel`] for [`SpatialMechanism`]): its kinematics, the joint
//! reactions with their constraint moments, the Lie-group discretisation of
//! Euler's equations and the implicit slip direction of a sliding foot.

use super::kin::{Columns, SpatialKin};
use super::mechanism::{SpatialMechanism, lower_body, upper_body};
use super::so3;
use crate::assemble::{History, JacobianSink, LimitEquation};
use crate::assembly::{self, At, ContactView, Dims, FbdModel, Reaction, RowState, Slip, StopView};
use crate::body::{BodyStep, Wrench};
use crate::mechanism::PointKind;
use crate::rows;
use crate::space::Space3;
use fbd_contact::spatial::clearance;
use fbd_contact::{SpatialState, Surface};
use fbd_kinematics::nalgebra::{Matrix3, Vector3};

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
    /// Static friction coefficient μS (a sticking complementarity point).
    pub mu_static: f64,
    /// ST2 and ST3 as complementarity rows
    /// ([`crate::rows::complementarity_rows`]): stick/slip and lift-off
    /// solved in the step; otherwise the fixed-state rows of
    /// [`crate::rows`].
    pub complementarity: bool,
    /// The complementarity rows' branches fixed for the solve (`None`:
    /// chosen by the iterate).
    pub frozen: Option<rows::Frozen>,
}

impl Default for SpatialContactEquation {
    fn default() -> Self {
        Self {
            state: SpatialState::Free,
            frame: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            mu_dynamic: 0.0,
            regularization: 0.0,
            mu_static: 0.0,
            complementarity: false,
            frozen: None,
        }
    }
}

/// Per-step constants of one body's six equations: `b` the centre of
/// mass's constant (`−2c[k] + c[k−1]`, or `−2c[0] − 2Δt·ċ(0)` at k = 0),
/// `ang` the momentum's (`L[k−½]`, or `2·L(0)` at k = 0).
pub type BodyStep3 = BodyStep<Space3>;

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
    /// Per body, the sum of applied forces and moments (about its CoM) at
    /// k of the last evaluation (N, N·m).
    pub wrench: Vec<Wrench<Space3>>,
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
    /// Per contact: its fixed direction was released to the implicit law
    /// once in this step's search (`fbd_sim`'s direction refinement does
    /// it at most once a step).
    pub released_direction: Vec<bool>,
    /// Per contact, `max(|w|, ε)` of [`slip_direction`] at the last
    /// evaluated iterate (m).
    pub slip_len: Vec<f64>,
    slip_n: Vec<f64>,
    /// Per contact, the branch of its complementarity rows at the last
    /// evaluated iterate.
    pub branch: Vec<rows::Branch>,
    /// Per contact, the branches fixed for the solves of this step's
    /// search (`fbd_sim`'s active-set fallback; reset every step).
    pub frozen: Vec<Option<rows::Frozen>>,
    /// This step's solves use fixed states, not complementarity rows
    /// (`fbd_sim`'s last fallback; reset every step).
    pub fixed_states: bool,
    /// The branches the active-set fallback froze first this step
    /// (`fbd_sim`'s second active-set attempt starts them again from the
    /// step's start).
    pub first_frozen: Vec<Option<rows::Frozen>>,
    /// Whether this step's active-set fallback has restarted from the
    /// step's start (reset every step).
    pub refrozen: bool,
    /// Per limit, whether its complementarity stop row is unloaded at the
    /// last evaluated iterate.
    pub limit_unloaded: Vec<bool>,
    rot_d: Vec<Matrix3<f64>>,
    /// The `q` `kin_next` was last evaluated at (NaN: none).
    kin_next_q: Vec<f64>,
    next_is_candidate: bool,
}

/// Slip speed (m/s) below which a slide has stopped (1e-9 m/s): the friction
/// direction is regularised below it (see [`slip_direction`]) and the
/// state machine switches such a slide to ST2.
pub use fbd_contact::spatial::STOP_SPEED;

/// The bias of [`slip_direction`] as a fraction of `ε`: `w = s + b·ε·u`.
/// Small enough that the direction of every slip faster than the stop
/// speed (`|s| > ε`) is the slip's own to `b` rad (1e-9), far below the
/// friction law's tolerance; nonzero, so that a slip that has not started
/// yet still has a direction.
pub const SLIP_BIAS: f64 = 1e-9;

/// The direction of a sliding point's friction over the step (`(t1, t2)`
/// components): `ŝ = w/max(|w|, ε)`, `w = s + b·ε·u` ([`SLIP_BIAS`]), with `s` the slip
/// from `p[k]` to `p[k+1]` in the tangent plane, `u` the slide's reference
/// direction (the last step's slip, or at the start of a slide the
/// opposite of the force sticking needed) and `ε = STOP_SPEED·Δt`.
/// Friction `−μD·N·ŝ` opposes the slip of the step itself (implicit, like
/// everything at k+1) — exactly Coulomb's `s/|s|` for every slip faster
/// than 1e-9 m/s; slower, it is regularised (linear in `w`), so that the
/// equations always have a solution, and the slide counts as stopped. The
/// bias `b·ε·u` only picks the direction of a slip that has not started yet
/// and turns a real slip's direction by at most `b·ε/|s|` ≤ 1e-9 rad.
/// Returns `(ŝ, max(|w|, ε))`.
#[inline]
pub fn slip_direction(s: [f64; 2], u: [f64; 2], eps: f64) -> ([f64; 2], f64) {
    let b = SLIP_BIAS * eps;
    let w = [s[0] + b * u[0], s[1] + b * u[1]];
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
            released_direction: vec![false; mech.contacts.len()],
            slip_n: vec![0.0; mech.contacts.len()],
            branch: vec![rows::Branch::default(); mech.contacts.len()],
            frozen: vec![None; mech.contacts.len()],
            fixed_states: false,
            first_frozen: vec![None; mech.contacts.len()],
            refrozen: false,
            limit_unloaded: vec![false; mech.limits.len()],
            wrench: vec![Wrench::default(); nb],
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
                b: (-2.0 * com_k + data.kin_prev.com[b]).into(),
                ang: if carried && data.l_carry_dt == dt {
                    data.l_carry[b]
                } else {
                    half_momentum_value(
                        &data.kin_prev.rot[b],
                        &data.kin.rot[b],
                        &mech.bodies[b].inertia,
                        dt,
                    )
                }
                .into(),
                com_k: com_k.into(),
            },
            History::Initial { qdot } => {
                let v = data.kin.com_jacobian(mech, b).apply(qdot);
                let w = data.kin.angular_jacobian(mech, b).apply(qdot);
                BodyStep3 {
                    c_next: 2.0,
                    b: (-2.0 * com_k - 2.0 * dt * v).into(),
                    ang: (2.0 * momentum(mech, &data.kin, b, &w)).into(),
                    com_k: com_k.into(),
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

/// The sparsity key: contact state codes in base 4 (one code for a
/// complementarity point in contact), then one bit per limit.
pub fn pattern_key(data: &SpatialFbdData) -> u64 {
    rows::pattern_key(
        data.contact.iter().map(|c| {
            let code = c.state.code();
            (!(c.complementarity && code != fbd_contact::StateCode::St1)).then_some(code)
        }),
        data.limit.iter().map(|l| l.state.is_at()),
    )
}

/// Pushes every structural `(row, col)` of the Jacobian for the current
/// states.
pub fn pattern(mech: &SpatialMechanism, data: &SpatialFbdData, entries: &mut Vec<(usize, usize)>) {
    assembly::pattern(mech, &Surface::default(), data, entries);
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

/// Residual `r(z)` and, through `jac`, the analytic Jacobian
/// ([`crate::assembly::eval`]).
pub fn eval<S: JacobianSink>(
    mech: &SpatialMechanism,
    surface: &Surface,
    data: &mut SpatialFbdData,
    z: &[f64],
    r: &mut [f64],
    jac: &mut S,
) {
    assembly::eval(mech, surface, data, z, r, jac);
}

#[inline]
fn columns(cols: &Columns, mut f: impl FnMut(usize, &[f64; 3])) {
    for (i, v) in cols.iter() {
        f(*i, &[v.x, v.y, v.z]);
    }
}

/// The hexapod's part of the assembly.
impl FbdModel for SpatialMechanism {
    type S = Space3;
    type Data = SpatialFbdData;
    type Ground = Surface;
    const IMPLICIT_SLIP: bool = true;

    fn dims(&self) -> Dims {
        self.layout().dims()
    }

    #[inline]
    fn gravity(&self) -> f64 {
        self.gravity
    }

    #[inline]
    fn mass(&self, b: usize) -> f64 {
        self.bodies[b].mass
    }

    #[inline]
    fn rotation_projection(&self, _: usize) -> f64 {
        1.0
    }

    #[inline]
    fn gains(&self, data: &SpatialFbdData) -> (f64, f64, f64) {
        (data.dt, data.position_gain, data.limit_gain)
    }

    fn kinematics_next(&self, data: &mut SpatialFbdData, q: &[f64], _: bool) {
        if data.kin_next_q[..] != q[..] {
            data.kin_next.eval(self, q);
            data.kin_next_q.copy_from_slice(q);
        }
        data.next_is_candidate = false;
    }

    #[inline]
    fn body_step<'a>(&self, data: &'a SpatialFbdData, b: usize) -> &'a BodyStep3 {
        &data.body[b]
    }

    #[inline]
    fn wrenches<'a>(&self, data: &'a mut SpatialFbdData) -> &'a mut [Wrench<Space3>] {
        &mut data.wrench
    }

    #[inline]
    fn com_next(&self, data: &SpatialFbdData, b: usize) -> [f64; 3] {
        data.kin_next.com[b].into()
    }

    /// `(c·L[k+½] − L[k−½])/Δt` ([`half_momentum`]); with `jacobian`, its
    /// derivative for [`FbdModel::rotation_entries`].
    fn angular_rate(&self, data: &mut SpatialFbdData, b: usize, jacobian: bool) -> [f64; 3] {
        let bs = data.body[b];
        let (dt, inertia) = (data.dt, &self.bodies[b].inertia);
        let (r_k, r_next) = (&data.kin.rot[b], &data.kin_next.rot[b]);
        let l_next = if jacobian {
            let (l, d) = half_momentum(r_k, r_next, inertia, dt);
            data.rot_d[b] = d * (bs.c_next / dt);
            l
        } else {
            half_momentum_value(r_k, r_next, inertia, dt)
        };
        data.l_next[b] = l_next;
        ((bs.c_next * l_next - Vector3::from(bs.ang)) / dt).into()
    }

    #[inline]
    fn reactions(&self) -> usize {
        2 * self.legs.len()
    }

    /// Reaction `2s` is slot `s`'s hip (body on upper link: force, the
    /// constraint moment along `z0 × z1`, torques `τ1·z0 + τ2·z1`), `2s + 1`
    /// its knee (upper on lower link: force, constraint moments along `b1`
    /// and `b2`, torque `τ3·z2`).
    fn reaction(&self, data: &SpatialFbdData, i: usize) -> Reaction<Space3> {
        let lay = self.layout();
        let s = i / 2;
        let [z0, z1, z2] = data.axes[s];
        let tau = data.torque[s];
        if i.is_multiple_of(2) {
            Reaction {
                child: upper_body(s),
                parent: 0,
                point: data.kin.point(self, s, PointKind::Hip).into(),
                force_col: lay.hip_force(s, 0),
                torque: (tau[0] * z0 + tau[1] * z1).into(),
                moments: [(lay.hip_moment(s), data.hip_dir[s].into()), (0, [0.0; 3])],
                n_moments: 1,
            }
        } else {
            let [b1, b2] = data.knee_dir[s];
            Reaction {
                child: lower_body(s),
                parent: upper_body(s),
                point: data.kin.point(self, s, PointKind::Knee).into(),
                force_col: lay.knee_force(s, 0),
                torque: (tau[2] * z2).into(),
                moments: [
                    (lay.knee_moment(s, 0), b1.into()),
                    (lay.knee_moment(s, 1), b2.into()),
                ],
                n_moments: 2,
            }
        }
    }

    #[inline]
    fn contact<'a>(&self, data: &'a SpatialFbdData, c: usize) -> ContactView<'a, Space3> {
        let eq = &data.contact[c];
        ContactView {
            body: self.contacts[c].body,
            frame: eq.frame,
            state: match &eq.state {
                SpatialState::Free => RowState::Free,
                SpatialState::Stick { anchor } if eq.complementarity => RowState::Contact {
                    anchor: Some(anchor),
                    mu: eq.mu_static,
                    frozen: eq.frozen,
                },
                SpatialState::Slide { .. } if eq.complementarity => RowState::Contact {
                    anchor: None,
                    mu: eq.mu_dynamic,
                    frozen: eq.frozen,
                },
                SpatialState::Stick { anchor } => RowState::Stick(anchor),
                SpatialState::Slide { dir } => RowState::Slide(dir),
            },
            mu_dynamic: eq.mu_dynamic,
            regularization: eq.regularization,
        }
    }

    #[inline]
    fn contact_point(&self, data: &SpatialFbdData, c: usize, at: At) -> [f64; 3] {
        let kin = match at {
            At::Now => &data.kin,
            At::Next => &data.kin_next,
        };
        let spec = &self.contacts[c];
        kin.point(self, slot_of(spec.point), spec.kind).into()
    }

    #[inline]
    fn stop<'a>(&self, data: &'a SpatialFbdData, l: usize) -> StopView<'a, Space3> {
        let lim = &self.limits[l];
        let j = lim.joint.index();
        let (child, parent) = joint_bodies(lim.slot, j);
        StopView {
            child,
            parent,
            axis: data.axes[lim.slot][j].into(),
            q_index: lim.q_index,
            equation: &data.limit[l],
        }
    }

    /// The step's own slip ([`slip_direction`]), or the reference direction
    /// of a slide that keeps it ([`SpatialFbdData::fixed_direction`]).
    fn slide_direction(
        &self,
        data: &mut SpatialFbdData,
        c: usize,
        p: &[f64; 3],
        dir: &[f64],
        normal: f64,
    ) -> [f64; 2] {
        let spec = &self.contacts[c];
        let d = Vector3::from(*p) - data.kin.point(self, slot_of(spec.point), spec.kind);
        let [t1, _, t2] = data.contact[c].frame;
        let s = [
            d.x * t1[0] + d.y * t1[1] + d.z * t1[2],
            d.x * t2[0] + d.y * t2[1] + d.z * t2[2],
        ];
        let dir = [dir[0], dir[1]];
        let (u, len) = if data.fixed_direction[c] {
            (dir, f64::INFINITY)
        } else {
            slip_direction(s, dir, data.slip_bias)
        };
        data.slip_hat[c] = u;
        data.slip_len[c] = len;
        data.slip_n[c] = normal;
        u
    }

    #[inline]
    fn slip(&self, data: &SpatialFbdData, c: usize) -> Slip {
        Slip {
            dir: data.slip_hat[c],
            len: data.slip_len[c],
            normal: data.slip_n[c],
            bias: data.slip_bias,
        }
    }

    #[inline]
    fn set_branch(&self, data: &mut SpatialFbdData, c: usize, branch: rows::Branch) {
        if branch.sliding {
            data.slip_hat[c] = [-branch.dir[0], -branch.dir[1]];
        }
        data.branch[c] = branch;
    }

    #[inline]
    fn branch(&self, data: &SpatialFbdData, c: usize) -> rows::Branch {
        data.branch[c]
    }

    #[inline]
    fn set_limit_unloaded(&self, data: &mut SpatialFbdData, l: usize, unloaded: bool) {
        data.limit_unloaded[l] = unloaded;
    }

    #[inline]
    fn limit_unloaded(&self, data: &SpatialFbdData, l: usize) -> bool {
        data.limit_unloaded[l]
    }

    #[inline]
    fn clearance(&self, surface: &Surface, p: &[f64; 3]) -> f64 {
        clearance(surface, *p)
    }

    #[inline]
    fn slope(&self, surface: &Surface, p: &[f64; 3]) -> [f64; 2] {
        surface.gradient(p[0], p[2])
    }

    #[inline]
    fn com_columns(&self, data: &SpatialFbdData, b: usize, f: impl FnMut(usize, &[f64; 3])) {
        columns(&data.kin_next.com_jacobian(self, b), f);
    }

    #[inline]
    fn contact_columns(&self, data: &SpatialFbdData, c: usize, f: impl FnMut(usize, &[f64; 3])) {
        let spec = &self.contacts[c];
        let slot = slot_of(spec.point);
        columns(&data.kin_next.contact_jacobian(self, slot, spec.kind), f);
    }

    /// `∂(c·L[k+½]/Δt)/∂q_i = D·ω_i`, `ω_i` the body's angular Jacobian
    /// column.
    fn rotation_entries<J: JacobianSink>(
        &self,
        data: &SpatialFbdData,
        b: usize,
        row: usize,
        jac: &mut J,
    ) {
        let d = &data.rot_d[b];
        for (i, w) in data.kin_next.angular_jacobian(self, b).iter() {
            let col = d * w;
            for a in 0..3 {
                jac.add(row + a, *i, col[a]);
            }
        }
    }
}

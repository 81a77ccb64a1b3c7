//! Residual and analytic Jacobian of one time step, assembled body by body.
//!
//! Unknowns `z = [q[k+1] | joint forces (x, y) | contact forces (Fa, N)]`,
//! equations `[3 per body (x, y, rotation) | 2 per contact]` (see
//! [`crate::Layout`]). Rows are in newtons (N·m for rotation rows); contact
//! position rows are multiplied by `K = M/Δt²` so that they are forces too,
//! which keeps the Jacobian well scaled for partial pivoting.
//!
//! Contact position rows carry a small dimensionless regularisation β
//! ([`ContactEquation::regularization`]): ST2 reads `K·(p − a) + β·F = 0`
//! and ST3's normal row `K·(p_y − ϱ(p_x)) + β·N = 0`. A point under load `N`
//! thus sits `β·N/K` below its anchor (≈ 1e-10 m for 1 kN in the default
//! experiment), and statically indeterminate contact sets — two sticking
//! points on one rigid body, a knee and a foot on one link — stay solvable:
//! their forces split as equal stiff springs would split them.
//!
//! Joint limits ([`Mechanism::with_limits`]) are one-sided stops: each
//! adds an unknown stop moment `λ` (N·m), acting on the joint's child as
//! `+axis·λ` and on its parent as `−axis·λ` like a joint torque (positive
//! `λ` drives the angle up), and one equation. A free joint reads `λ = 0`;
//! a joint at an end reads `Kθ·(θ[k+1] − θ_end) + β·λ = 0` with
//! `Kθ = (M/Δt²)·ℓ²` (ℓ: [`Mechanism::length_scale`]), so that its angle
//! stops at the end within one step — a plastic stop. Whether the stop
//! pushes (`λ` away from the end) is the state search's business.
//!
//! The Jacobian is written entry by entry through a [`JacobianSink`]; the
//! same code path with [`pattern`] declares the structure, so the two cannot
//! drift apart.

use crate::body::{BodyStep, cross};
use crate::mechanism::Mechanism;
use crate::rows;
use fbd_contact::{ContactState, Terrain};
use fbd_kinematics::LimitSide;
use fbd_kinematics::planar::PlanarData;

/// Receives Jacobian entries.
pub trait JacobianSink {
    /// `false` for a residual-only evaluation.
    const ACTIVE: bool;
    /// Adds `v` to entry `(row, col)`.
    fn add(&mut self, row: usize, col: usize, v: f64);
}

/// A sink that ignores entries: residual-only evaluation.
pub struct NoJacobian;

impl JacobianSink for NoJacobian {
    const ACTIVE: bool = false;
    #[inline]
    fn add(&mut self, _: usize, _: usize, _: f64) {}
}

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
pub struct ContactEquation {
    /// ST1 / ST2 (with anchor) / ST3 (with direction).
    pub state: ContactState,
    /// Unit tangent of the terrain frame the forces are expressed in.
    pub tangent: [f64; 2],
    /// Unit normal of that frame.
    pub normal: [f64; 2],
    /// Dynamic friction coefficient μD (used in ST3).
    pub mu_dynamic: f64,
    /// Regularisation β of the position rows (see the module docs).
    pub regularization: f64,
}

impl Default for ContactEquation {
    fn default() -> Self {
        Self {
            state: ContactState::Free,
            tangent: [1.0, 0.0],
            normal: [0.0, 1.0],
            mu_dynamic: 0.0,
            regularization: 0.0,
        }
    }
}

/// The state of one joint limit in a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LimitState {
    /// Inside its range: the stop exerts no moment.
    Free,
    /// At an end of its range: `θ[k+1]` is held at `angle`.
    At {
        /// Which end.
        side: LimitSide,
        /// The end's angle (rad).
        angle: f64,
    },
}

impl LimitState {
    /// 0 free, 1 at the lower end, 2 at the upper end.
    pub fn key(&self) -> u64 {
        match self {
            LimitState::Free => 0,
            LimitState::At {
                side: LimitSide::Lower,
                ..
            } => 1,
            LimitState::At { .. } => 2,
        }
    }

    /// `true` at an end.
    pub fn is_at(&self) -> bool {
        matches!(self, LimitState::At { .. })
    }
}

/// The equation a joint limit contributes in this step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LimitEquation {
    /// Free, or at an end.
    pub state: LimitState,
    /// Regularisation β of the stop row (see the module docs).
    pub regularization: f64,
}

impl Default for LimitEquation {
    fn default() -> Self {
        Self {
            state: LimitState::Free,
            regularization: 0.0,
        }
    }
}

/// Where the previous configuration comes from.
#[derive(Clone, Copy, Debug)]
pub enum History<'a> {
    /// `k ≥ 1`: the configuration before, kept in [`FbdData`] by [`advance`].
    Previous,
    /// `k = 0`: the initial generalised velocity `q̇(0)`.
    Initial {
        /// `q̇(0)`.
        qdot: &'a [f64],
    },
}

/// Mutable workspace of the assembly (allocated once per mechanism).
#[derive(Clone, Debug)]
pub struct FbdData {
    /// Kinematics at `q[k−1]`.
    pub kin_prev: PlanarData,
    /// Kinematics at `q[k]`: positions; Jacobians at `k = 0` only (see
    /// [`advance`]).
    pub kin: PlanarData,
    /// Kinematics at the current Newton iterate of `q[k+1]`.
    pub kin_next: PlanarData,
    /// Per-body constants of this step.
    pub body: Vec<BodyStep>,
    /// Per-contact equations of this step.
    pub contact: Vec<ContactEquation>,
    /// Per-limit equations of this step (order of [`Mechanism::limits`]).
    pub limit: Vec<LimitEquation>,
    /// Joint torques at `k` (N·m), positive towards larger joint angles.
    pub torque: Vec<f64>,
    /// Time step (s).
    pub dt: f64,
    /// Scale of contact position rows, `M/Δt²` (N/m).
    pub position_gain: f64,
    /// Scale of joint-limit rows, `Kθ = (M/Δt²)·ℓ²` (N·m/rad).
    pub limit_gain: f64,
    /// The mechanism's total mass `M` (kg), [`Mechanism::total_mass`].
    pub total_mass: f64,
    /// The mechanism's length scale `ℓ` (m), [`Mechanism::length_scale`].
    pub length_scale: f64,
    /// `kin_next` holds the positions of a candidate set by
    /// [`evaluate_next`] (and no Newton iterate since).
    next_is_candidate: bool,
    /// The `q[k+1]` at which `kin_next`'s positions were last evaluated
    /// (NaN before the first evaluation).
    next_q: Vec<f64>,
    acc: Vec<[f64; 3]>,
}

impl FbdData {
    /// A workspace for `mech`.
    pub fn new(mech: &Mechanism) -> Self {
        let kin = mech.chains.new_data();
        Self {
            kin_prev: kin.clone(),
            kin_next: kin.clone(),
            kin,
            body: vec![BodyStep::default(); mech.bodies.len()],
            contact: vec![ContactEquation::default(); mech.contacts.len()],
            limit: vec![LimitEquation::default(); mech.limits.len()],
            torque: vec![0.0; mech.joints.len()],
            dt: 0.0,
            position_gain: 0.0,
            limit_gain: 0.0,
            total_mass: mech.total_mass(),
            length_scale: mech.length_scale(),
            next_is_candidate: false,
            next_q: vec![f64::NAN; mech.layout().nq],
            acc: vec![[0.0; 3]; mech.bodies.len()],
        }
    }

    /// Body coordinates `(X, Y, ψ)` of body `b` in the kinematics `kin`.
    #[inline]
    pub fn body_coords(mech: &Mechanism, kin: &PlanarData, b: usize) -> [f64; 3] {
        let spec = &mech.bodies[b];
        let p = kin.pos[spec.com];
        [p[0], p[1], kin.angle[spec.angle]]
    }
}

/// Sets `q[k]` (used at `k = 0`; afterwards [`advance`] does it).
pub fn set_configuration(mech: &Mechanism, data: &mut FbdData, q: &[f64]) {
    mech.chains.eval_positions(q, &mut data.kin);
    mech.chains.eval_jacobians(&mut data.kin);
}

/// Stage "kinematics at k": the per-body constants of this step's second
/// differences, given `q[k]` already set.
pub fn prepare_step(mech: &Mechanism, data: &mut FbdData, history: History<'_>, dt: f64) {
    data.dt = dt;
    data.position_gain = data.total_mass / (dt * dt);
    let l = data.length_scale;
    data.limit_gain = data.position_gain * l * l;
    for b in 0..mech.bodies.len() {
        let x_k = FbdData::body_coords(mech, &data.kin, b);
        data.body[b] = match history {
            History::Previous => {
                BodyStep::from_history(x_k, FbdData::body_coords(mech, &data.kin_prev, b))
            }
            History::Initial { qdot } => {
                let spec = &mech.bodies[b];
                let v = mech.chains.point_velocity(&data.kin, spec.com, qdot);
                let w = mech.chains.angles[spec.angle].rate(qdot);
                BodyStep::from_velocity(x_k, [v[0], v[1], w], dt)
            }
        };
    }
}

/// Evaluates the point positions at a candidate `q[k+1]` into
/// `data.kin_next` (after the solve, for the contact check), so that
/// [`advance`] can accept it without evaluating them again. Nothing is
/// evaluated when `kin_next` already holds the positions at exactly
/// `q_next` (the solver's last evaluation is usually at its solution).
pub fn evaluate_next(mech: &Mechanism, data: &mut FbdData, q_next: &[f64]) {
    if data.next_q != q_next {
        mech.chains.eval_positions(q_next, &mut data.kin_next);
        data.next_q.copy_from_slice(q_next);
    }
    data.next_is_candidate = true;
}

/// Accepts the candidate of [`evaluate_next`]: `q[k]` becomes the previous
/// configuration and `q[k+1]` the current one (its positions are reused).
/// The Jacobians of `data.kin` are not evaluated: the step needs them at
/// `k = 0` only ([`set_configuration`]); call
/// [`PlanarChains::eval_jacobians`](fbd_kinematics::planar::PlanarChains::eval_jacobians)
/// for them.
///
/// # Panics
/// If [`evaluate_next`] was not called since the last [`eval`].
pub fn advance(_mech: &Mechanism, data: &mut FbdData) {
    assert!(
        data.next_is_candidate,
        "advance needs evaluate_next at the accepted configuration"
    );
    std::mem::swap(&mut data.kin_prev, &mut data.kin);
    std::mem::swap(&mut data.kin, &mut data.kin_next);
    // `kin_next` now holds what `kin_prev` held, which no longer matches
    // `next_q`.
    data.next_q.fill(f64::NAN);
    data.next_is_candidate = false;
}

/// A key identifying the sparsity pattern: the contact states' codes in
/// base 3 (the slide direction changes values, not structure), then one
/// bit per joint limit (free or at an end).
pub fn pattern_key(data: &FbdData) -> u64 {
    rows::pattern_key(
        data.contact.iter().map(|c| c.state.code()),
        data.limit.iter().map(|l| l.state.is_at()),
    )
}

/// Pushes every structural `(row, col)` of the Jacobian for the current
/// contact states.
pub fn pattern(mech: &Mechanism, data: &FbdData, entries: &mut Vec<(usize, usize)>) {
    let mut sink = PatternSink(entries);
    force_entries(mech, data, &mut sink);
    position_entries(mech, &Terrain::None, data, &mut sink);
}

/// Residual `r(z)` and, through `jac`, the analytic Jacobian.
pub fn eval<S: JacobianSink>(
    mech: &Mechanism,
    terrain: &Terrain,
    data: &mut FbdData,
    z: &[f64],
    r: &mut [f64],
    jac: &mut S,
) {
    let lay = mech.layout();
    assert_eq!(z.len(), lay.dim(), "unknown vector has the wrong length");
    assert_eq!(r.len(), lay.dim(), "residual vector has the wrong length");
    let nq = lay.nq;
    mech.chains.eval_positions(&z[..nq], &mut data.kin_next);
    data.next_q.copy_from_slice(&z[..nq]);
    data.next_is_candidate = false;
    if S::ACTIVE {
        mech.chains.eval_jacobians(&mut data.kin_next);
    }
    let inv_dt2 = 1.0 / (data.dt * data.dt);
    // Sum of applied forces and moments per body, at configuration k.
    for (b, acc) in data.acc.iter_mut().enumerate() {
        *acc = [0.0, -mech.bodies[b].mass * mech.gravity, 0.0];
    }
    for (j, spec) in mech.joints.iter().enumerate() {
        let f = [z[lay.joint_force(j, 0)], z[lay.joint_force(j, 1)]];
        let p = data.kin.pos[spec.point];
        let tz = spec.axis_z * data.torque[j];
        for (b, sgn) in [(spec.child, 1.0), (spec.parent, -1.0)] {
            let c = data.body[b].com_k;
            let a = &mut data.acc[b];
            a[0] += sgn * f[0];
            a[1] += sgn * f[1];
            a[2] += sgn * (cross([p[0] - c[0], p[1] - c[1]], f) + tz);
        }
    }
    for (ci, spec) in mech.contacts.iter().enumerate() {
        let eq = &data.contact[ci];
        let (fa, n) = (z[lay.contact_fa(ci)], z[lay.contact_n(ci)]);
        let f = [
            fa * eq.tangent[0] + n * eq.normal[0],
            fa * eq.tangent[1] + n * eq.normal[1],
        ];
        let p = data.kin.pos[spec.point];
        let c = data.body[spec.body].com_k;
        let a = &mut data.acc[spec.body];
        a[0] += f[0];
        a[1] += f[1];
        a[2] += cross([p[0] - c[0], p[1] - c[1]], f);
    }
    for (l, &j) in mech.limits.iter().enumerate() {
        let spec = &mech.joints[j];
        let m = spec.axis_z * z[lay.limit_moment(l)];
        data.acc[spec.child][2] += m;
        data.acc[spec.parent][2] -= m;
    }
    for (b, spec) in mech.bodies.iter().enumerate() {
        let x = FbdData::body_coords(mech, &data.kin_next, b);
        let bs = &data.body[b];
        let row = lay.body_row(b);
        let a = data.acc[b];
        r[row] = spec.mass * bs.acceleration(0, x[0], inv_dt2) - a[0];
        r[row + 1] = spec.mass * bs.acceleration(1, x[1], inv_dt2) - a[1];
        r[row + 2] = spec.versor_z * (spec.inertia * bs.acceleration(2, x[2], inv_dt2) - a[2]);
    }
    let k = data.position_gain;
    for (ci, spec) in mech.contacts.iter().enumerate() {
        let eq = &data.contact[ci];
        let row = lay.contact_row(ci);
        let (fa, n) = (z[lay.contact_fa(ci)], z[lay.contact_n(ci)]);
        let p = data.kin_next.pos[spec.point];
        let (force, out) = ([fa, n], &mut r[row..row + 2]);
        match eq.state {
            ContactState::Free => rows::free_rows(&force, out),
            ContactState::Stick { anchor } => {
                let f = [
                    fa * eq.tangent[0] + n * eq.normal[0],
                    fa * eq.tangent[1] + n * eq.normal[1],
                ];
                rows::stick_rows(k, &p, &anchor, eq.regularization, &f, out);
            }
            ContactState::Slide { dir } => rows::slide_rows(
                &force,
                &[dir],
                eq.mu_dynamic,
                k,
                terrain.clearance(p),
                eq.regularization,
                out,
            ),
        }
    }
    for (l, &j) in mech.limits.iter().enumerate() {
        let eq = &data.limit[l];
        let lambda = z[lay.limit_moment(l)];
        r[lay.limit_row(l)] =
            rows::limit_row(eq, lambda, z[mech.joints[j].q_index], data.limit_gain);
    }
    if S::ACTIVE {
        force_entries(mech, data, jac);
        position_entries(mech, terrain, data, jac);
    }
}

/// Entries in the force columns (they do not depend on the iterate).
fn force_entries<S: JacobianSink>(mech: &Mechanism, data: &FbdData, jac: &mut S) {
    let lay = mech.layout();
    for (j, spec) in mech.joints.iter().enumerate() {
        let (cx, cy) = (lay.joint_force(j, 0), lay.joint_force(j, 1));
        let p = data.kin.pos[spec.point];
        for (b, sgn) in [(spec.child, 1.0), (spec.parent, -1.0)] {
            let c = data.body[b].com_k;
            let v = mech.bodies[b].versor_z;
            let row = lay.body_row(b);
            let (rx, ry) = (p[0] - c[0], p[1] - c[1]);
            jac.add(row, cx, -sgn);
            jac.add(row + 1, cy, -sgn);
            // −v·∂(r × F)/∂F = −v·(−ry, rx)
            jac.add(row + 2, cx, v * sgn * ry);
            jac.add(row + 2, cy, -v * sgn * rx);
        }
    }
    for (ci, spec) in mech.contacts.iter().enumerate() {
        let eq = &data.contact[ci];
        let (ca, cn) = (lay.contact_fa(ci), lay.contact_n(ci));
        let p = data.kin.pos[spec.point];
        let c = data.body[spec.body].com_k;
        let rr = [p[0] - c[0], p[1] - c[1]];
        let v = mech.bodies[spec.body].versor_z;
        let row = lay.body_row(spec.body);
        jac.add(row, ca, -eq.tangent[0]);
        jac.add(row, cn, -eq.normal[0]);
        jac.add(row + 1, ca, -eq.tangent[1]);
        jac.add(row + 1, cn, -eq.normal[1]);
        jac.add(row + 2, ca, -v * cross(rr, eq.tangent));
        jac.add(row + 2, cn, -v * cross(rr, eq.normal));
        let crow = lay.contact_row(ci);
        match eq.state {
            ContactState::Free => {
                jac.add(crow, ca, 1.0);
                jac.add(crow + 1, cn, 1.0);
            }
            ContactState::Stick { .. } => {
                let b = eq.regularization;
                jac.add(crow, ca, b * eq.tangent[0]);
                jac.add(crow, cn, b * eq.normal[0]);
                jac.add(crow + 1, ca, b * eq.tangent[1]);
                jac.add(crow + 1, cn, b * eq.normal[1]);
            }
            ContactState::Slide { dir } => {
                jac.add(crow, ca, 1.0);
                jac.add(crow, cn, dir * eq.mu_dynamic);
                jac.add(crow + 1, cn, eq.regularization);
            }
        }
    }
    for (l, &j) in mech.limits.iter().enumerate() {
        let spec = &mech.joints[j];
        let col = lay.limit_moment(l);
        // r[rot] = v·(I·ψ̈ − Σ moments), the stop adds ±axis·λ.
        let (vc, vp) = (
            mech.bodies[spec.child].versor_z,
            mech.bodies[spec.parent].versor_z,
        );
        jac.add(lay.body_row(spec.child) + 2, col, -vc * spec.axis_z);
        jac.add(lay.body_row(spec.parent) + 2, col, vp * spec.axis_z);
        jac.add(
            lay.limit_row(l),
            col,
            rows::limit_row_diagonal(&data.limit[l]),
        );
    }
}

/// Entries in the `q[k+1]` columns: `∂(second difference)/∂q` of every body
/// and the contact position rows, at the iterate `data.kin_next`.
fn position_entries<S: JacobianSink>(
    mech: &Mechanism,
    terrain: &Terrain,
    data: &FbdData,
    jac: &mut S,
) {
    let lay = mech.layout();
    let kin_next = &data.kin_next;
    let dt2 = data.dt * data.dt;
    for (b, spec) in mech.bodies.iter().enumerate() {
        let row = lay.body_row(b);
        let g = spec.mass * data.body[b].c_next / dt2;
        for &i in mech.point_columns(spec.com) {
            jac.add(row, i, g * kin_next.jac_at(spec.com, 0, i));
            jac.add(row + 1, i, g * kin_next.jac_at(spec.com, 1, i));
        }
        let gi = spec.versor_z * spec.inertia * data.body[b].c_next / dt2;
        for &(i, coef) in &mech.chains.angles[spec.angle].terms {
            jac.add(row + 2, i, gi * coef);
        }
    }
    let k = data.position_gain;
    for (ci, spec) in mech.contacts.iter().enumerate() {
        let row = lay.contact_row(ci);
        match data.contact[ci].state {
            ContactState::Free => {}
            ContactState::Stick { .. } => {
                for &i in mech.point_columns(spec.point) {
                    jac.add(row, i, k * kin_next.jac_at(spec.point, 0, i));
                    jac.add(row + 1, i, k * kin_next.jac_at(spec.point, 1, i));
                }
            }
            ContactState::Slide { .. } => {
                let s = terrain.slope(kin_next.pos[spec.point][0]);
                for &i in mech.point_columns(spec.point) {
                    jac.add(
                        row + 1,
                        i,
                        k * (kin_next.jac_at(spec.point, 1, i)
                            - s * kin_next.jac_at(spec.point, 0, i)),
                    );
                }
            }
        }
    }
    for (l, &j) in mech.limits.iter().enumerate() {
        if data.limit[l].state.is_at() {
            jac.add(lay.limit_row(l), mech.joints[j].q_index, data.limit_gain);
        }
    }
}

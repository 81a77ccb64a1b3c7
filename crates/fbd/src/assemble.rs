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
//! The equations are assembled by the one assembly of the plane and space,
//! [`crate::assembly`]; this module supplies the planar model's part of it
//! ([`FbdModel`] for [`Mechanism`]): its kinematics, and the rotation row's
//! central difference of the body angle.

use crate::assembly::{
    At, ContactView, Dims, FbdModel, Reaction, RowState, Slip, StepTerms, StopView,
};
use crate::body::BodyStep;
use crate::mechanism::Mechanism;
use crate::rows;
use crate::space::Plane;
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
    /// At an end, the stop row as a complementarity row
    /// ([`crate::rows::limit_row`]): the stop pushes or the joint leaves
    /// the end, solved in the step.
    pub complementarity: bool,
}

impl Default for LimitEquation {
    fn default() -> Self {
        Self {
            state: LimitState::Free,
            regularization: 0.0,
            complementarity: false,
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

/// Mutable workspace of the assembly (allocated once per mechanism); it
/// dereferences to what every model's step holds alike ([`StepTerms`]:
/// the kinematics at `q[k−1]`, `q[k]` (positions; Jacobians at `k = 0`
/// only, see [`advance`]) and the iterate of `q[k+1]`, the contact
/// equations, each body's constants, the stops' equations, the torques,
/// `Δt` and the gains).
#[derive(Clone, Debug)]
pub struct FbdData {
    /// What every model's step holds.
    pub terms: StepTerms<Plane, PlanarData, ContactEquation>,
    /// The mechanism's total mass `M` (kg), [`Mechanism::total_mass`].
    pub total_mass: f64,
    /// The mechanism's length scale `ℓ` (m), [`Mechanism::length_scale`].
    pub length_scale: f64,
}

crate::assembly::step_terms!(FbdData, Plane, PlanarData, ContactEquation);

impl FbdData {
    /// A workspace for `mech`.
    pub fn new(mech: &Mechanism) -> Self {
        Self {
            terms: StepTerms::new(
                mech.chains.new_data(),
                mech.layout().nq,
                (mech.bodies.iter().map(|b| b.mass).collect(), mech.gravity),
                mech.contacts.len(),
                mech.limits.len(),
                mech.joints.len(),
            ),
            total_mass: mech.total_mass(),
            length_scale: mech.length_scale(),
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
    let (mass, length) = (data.total_mass, data.length_scale);
    data.terms.set_dt(dt, mass, length);
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
    data.terms
        .evaluate_candidate(q_next, |kin, q| mech.chains.eval_positions(q, kin));
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
    data.terms.accept_candidate();
}

/// A key identifying the sparsity pattern: the contact states' codes in
/// base 4 (the slide direction changes values, not structure), then one
/// bit per joint limit (free or at an end).
pub fn pattern_key(data: &FbdData) -> u64 {
    rows::pattern_key(
        data.contact.iter().map(|c| Some(c.state.code())),
        data.limit.iter().map(|l| l.state.is_at()),
    )
}

/// The planar model's part of the assembly.
impl FbdModel for Mechanism {
    type S = Plane;
    type Data = FbdData;
    type Kin = PlanarData;
    type Contact = ContactEquation;
    type Ground = Terrain;
    const IMPLICIT_SLIP: bool = false;

    fn dims(&self) -> Dims {
        self.layout().dims()
    }

    #[inline]
    fn rotation_projection(&self, b: usize) -> f64 {
        self.bodies[b].versor_z
    }

    fn kinematics_next(&self, data: &mut FbdData, q: &[f64], jacobians: bool) {
        self.chains.eval_positions(q, &mut data.kin_next);
        data.terms.set_iterate(q);
        if jacobians {
            self.chains.eval_jacobians(&mut data.kin_next);
        }
    }

    #[inline]
    fn com_next(&self, data: &FbdData, b: usize) -> [f64; 2] {
        data.kin_next.pos[self.bodies[b].com]
    }

    /// `I·(c·ψ[k+1] + b_ψ)/Δt²`, the paper's central difference.
    #[inline]
    fn angular_rate(&self, data: &mut FbdData, b: usize, _: bool) -> [f64; 1] {
        let spec = &self.bodies[b];
        let inv_dt2 = 1.0 / (data.dt * data.dt);
        let psi = data.kin_next.angle[spec.angle];
        [spec.inertia * data.body[b].angular_acceleration(psi, inv_dt2)]
    }

    #[inline]
    fn reactions(&self) -> usize {
        self.joints.len()
    }

    #[inline]
    fn reaction(&self, data: &FbdData, j: usize) -> Reaction<Plane> {
        let spec = &self.joints[j];
        Reaction {
            child: spec.child,
            parent: spec.parent,
            point: data.kin.pos[spec.point],
            force_col: self.layout().joint_force(j, 0),
            torque: [spec.axis_z * data.torque[j]],
            moments: [(0, [0.0]); 2],
            n_moments: 0,
        }
    }

    #[inline]
    fn contact<'a>(&self, data: &'a FbdData, c: usize) -> ContactView<'a, Plane> {
        let eq = &data.contact[c];
        ContactView {
            body: self.contacts[c].body,
            frame: [eq.tangent, eq.normal],
            state: match &eq.state {
                ContactState::Free => RowState::Free,
                ContactState::Stick { anchor } => RowState::Stick(anchor),
                ContactState::Slide { dir } => RowState::Slide(std::slice::from_ref(dir)),
            },
            mu_dynamic: eq.mu_dynamic,
            regularization: eq.regularization,
        }
    }

    #[inline]
    fn contact_point(&self, data: &FbdData, c: usize, at: At) -> [f64; 2] {
        data.kin_at(at).pos[self.contacts[c].point]
    }

    #[inline]
    fn stop<'a>(&self, data: &'a FbdData, l: usize) -> StopView<'a, Plane> {
        let spec = &self.joints[self.limits[l]];
        StopView {
            child: spec.child,
            parent: spec.parent,
            axis: [spec.axis_z],
            q_index: spec.q_index,
            equation: &data.limit[l],
        }
    }

    /// A planar slide keeps its direction (±1) for the step.
    #[inline]
    fn slide_direction(
        &self,
        _: &mut FbdData,
        _: usize,
        _: &[f64; 2],
        dir: &[f64],
        _: f64,
    ) -> [f64; 2] {
        [dir[0], 0.0]
    }

    fn slip(&self, data: &FbdData, c: usize) -> Slip {
        let dir = match data.contact[c].state {
            ContactState::Slide { dir } => dir,
            _ => 0.0,
        };
        Slip {
            dir: [dir, 0.0],
            len: f64::INFINITY,
            normal: 0.0,
            bias: 0.0,
        }
    }

    #[inline]
    fn clearance(&self, terrain: &Terrain, p: &[f64; 2]) -> f64 {
        terrain.clearance(*p)
    }

    #[inline]
    fn slope(&self, terrain: &Terrain, p: &[f64; 2]) -> [f64; 2] {
        [terrain.slope(p[0]), 0.0]
    }

    #[inline]
    fn com_columns(&self, data: &FbdData, b: usize, f: impl FnMut(usize, &[f64; 2])) {
        point_columns(self, &data.kin_next, self.bodies[b].com, f);
    }

    #[inline]
    fn contact_columns(&self, data: &FbdData, c: usize, f: impl FnMut(usize, &[f64; 2])) {
        point_columns(self, &data.kin_next, self.contacts[c].point, f);
    }

    /// `v·I·c/Δt²·∂ψ/∂q_i`: the angle is linear in `q`.
    fn rotation_entries<J: JacobianSink>(&self, data: &FbdData, b: usize, row: usize, jac: &mut J) {
        let spec = &self.bodies[b];
        let gi = spec.versor_z * spec.inertia * data.body[b].c_next / (data.dt * data.dt);
        for &(i, coef) in &self.chains.angles[spec.angle].terms {
            jac.add(row, i, gi * coef);
        }
    }
}

/// Visits `(i, ∂p/∂q_i)` of planar point `p` in `kin`.
#[inline]
fn point_columns(
    mech: &Mechanism,
    kin: &PlanarData,
    p: usize,
    mut f: impl FnMut(usize, &[f64; 2]),
) {
    for &i in mech.point_columns(p) {
        f(i, &[kin.jac_at(p, 0, i), kin.jac_at(p, 1, i)]);
    }
}

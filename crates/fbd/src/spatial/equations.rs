//! The pieces of the spatial (3D) FBD equations every robot's assembly
//! ([`crate::tree::assemble`]) is made of, beyond the one assembly of the
//! plane and space ([`crate::assembly`]): a contact point's equations in a
//! step, a body's per-step constants, the Lie-group discretisation of
//! Euler's equations (the discrete angular momentum [`half_momentum`] and
//! its derivative) and the implicit slip direction of a sliding point
//! ([`slip_direction`]). See [`crate::spatial`] for the scheme.

use super::so3;
use crate::body::BodyStep;
use crate::rows;
use crate::space::Space3;
use fbd_contact::SpatialState;
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

/// `aᵀ·b`, every entry summed as nalgebra's product sums it,
/// `(a₀ᵢ·b₀ⱼ + a₁ᵢ·b₁ⱼ) + a₂ᵢ·b₂ⱼ`: bit for bit `a.transpose() * b`, with
/// neither the transposed copy nor the product's shuffles.
#[inline]
fn tr_mul(a: &Matrix3<f64>, b: &Matrix3<f64>) -> Matrix3<f64> {
    let d =
        |i: usize, j: usize| a[(0, i)] * b[(0, j)] + a[(1, i)] * b[(1, j)] + a[(2, i)] * b[(2, j)];
    Matrix3::new(
        d(0, 0),
        d(0, 1),
        d(0, 2),
        d(1, 0),
        d(1, 1),
        d(1, 2),
        d(2, 0),
        d(2, 1),
        d(2, 2),
    )
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
    let (l, d, _) = half_momentum_derivative_and_rotation(r_k, r_next, inertia, dt);
    (l, d)
}

/// [`half_momentum`] and the step's rotation `ψ` it is made of.
pub fn half_momentum_derivative_and_rotation(
    r_k: &Matrix3<f64>,
    r_next: &Matrix3<f64>,
    inertia: &Matrix3<f64>,
    dt: f64,
) -> (Vector3<f64>, Matrix3<f64>, Vector3<f64>) {
    let psi = so3::log(&tr_mul(r_k, r_next));
    let r_mid = r_k * so3::exp(&(0.5 * psi));
    let ipsi = inertia * psi;
    // The same operations as `half_momentum_value`: bit-identical values.
    let l = r_k * so3::rotate(&(0.5 * psi), &ipsi) / dt;
    let d = r_mid
        * (inertia - 0.5 * so3::hat(&ipsi) * so3::right_jacobian(&(0.5 * psi)))
        * so3::right_jacobian_inv(&psi)
        * r_next.transpose()
        / dt;
    (l, d, psi)
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
#[inline]
pub fn half_momentum_and_rotation(
    r_k: &Matrix3<f64>,
    r_next: &Matrix3<f64>,
    inertia: &Matrix3<f64>,
    dt: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    let psi = so3::log(&tr_mul(r_k, r_next));
    (r_k * so3::rotate(&(0.5 * psi), &(inertia * psi)) / dt, psi)
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

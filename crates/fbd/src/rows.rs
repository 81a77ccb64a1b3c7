//! The contact and joint-stop equations, one source for the plane and 3D.
//!
//! A contact point contributes one row per force component, its unknowns
//! the force in the contact frame with the normal component second:
//! `(Fa, N)` in the plane, `(Ft1, N, Ft2)` in 3D. Per state:
//!
//! | state | rows |
//! |---|---|
//! | ST1 | `F = 0` (every component) |
//! | ST2 | `K·(p[k+1] − a) + β·F = 0`, `F` inertial (every component) |
//! | ST3 | normal: `K·clearance(p[k+1]) + β·N = 0`; tangential: `Ft_i + u_i·μD·N = 0` |
//!
//! with `K = M/Δt²` the position gain, `β` the regularisation and `u` the
//! slide's unit direction in the tangential components (the plane: ±1; 3D:
//! the step's slip direction). A joint stop contributes one row, its moment
//! `λ` free (`λ = 0`) or at an end (`Kθ·(θ − θ_end) + β·λ = 0`). The
//! assemblies of [`crate::assemble`] (planar) and [`crate::spatial`] (3D)
//! write these rows with these functions, and key their sparsity patterns
//! with [`pattern_key`].

use crate::LimitEquation;
use crate::LimitState;
use fbd_contact::StateCode;

/// Index of the normal component among a contact point's unknowns and rows.
pub const NORMAL: usize = 1;

/// ST1: `F = 0`.
#[inline]
pub fn free_rows(force: &[f64], r: &mut [f64]) {
    r.copy_from_slice(force);
}

/// ST2: `K·(p − a) + β·F = 0` per inertial component, `f` the contact
/// force in the inertial frame.
#[inline]
pub fn stick_rows(gain: f64, p: &[f64], anchor: &[f64], beta: f64, f: &[f64], r: &mut [f64]) {
    for (i, r) in r.iter_mut().enumerate() {
        *r = gain * (p[i] - anchor[i]) + beta * f[i];
    }
}

/// ST3: the normal row `K·clearance + β·N` and, for every tangential
/// component `i` (in order, skipping [`NORMAL`]), `Ft_i + u_j·μD·N` with
/// `u_j` the slide direction's next component.
#[inline]
pub fn slide_rows(
    force: &[f64],
    dir: &[f64],
    mu_dynamic: f64,
    gain: f64,
    clearance: f64,
    beta: f64,
    r: &mut [f64],
) {
    let n = force[NORMAL];
    let mut j = 0;
    for (i, r) in r.iter_mut().enumerate() {
        if i == NORMAL {
            *r = gain * clearance + beta * n;
        } else {
            *r = force[i] + dir[j] * mu_dynamic * n;
            j += 1;
        }
    }
}

/// The stop row of a joint limit with moment `lambda` at angle `angle`.
#[inline]
pub fn limit_row(eq: &LimitEquation, lambda: f64, angle: f64, gain: f64) -> f64 {
    match eq.state {
        LimitState::Free => lambda,
        LimitState::At { angle: end, .. } => gain * (angle - end) + eq.regularization * lambda,
    }
}

/// `∂(stop row)/∂λ`.
#[inline]
pub fn limit_row_diagonal(eq: &LimitEquation) -> f64 {
    match eq.state {
        LimitState::Free => 1.0,
        LimitState::At { .. } => eq.regularization,
    }
}

/// A key identifying the Jacobian's sparsity pattern: the contact states'
/// codes in base 3 (a slide's direction changes values, not structure),
/// then one bit per joint limit (free or at an end).
pub fn pattern_key(
    contacts: impl Iterator<Item = StateCode>,
    limits: impl Iterator<Item = bool>,
) -> u64 {
    let k = contacts.fold(0u64, |k, c| k * 3 + c as u64);
    limits.fold(k, |k, at| k * 2 + u64::from(at))
}

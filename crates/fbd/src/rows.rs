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

/// The branch a complementarity contact point's rows took at the last
/// evaluated iterate ([`complementarity_rows`]): what the Jacobian and the
/// state search need.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Branch {
    /// The normal row is `N` (no load: `N < K·gap + β·N`), otherwise the
    /// gap row `K·gap + β·N`.
    pub unloaded: bool,
    /// The friction projection is active: the point slides, `Ft = ρ·ŷ`.
    pub sliding: bool,
    /// `ŷ = y/|y|` (sliding; the step's slip direction is `−ŷ`).
    pub dir: [f64; 2],
    /// `ρ/|y|` (sliding), `ρ = μ·max(N, 0)`.
    pub ratio: f64,
    /// `∂ρ/∂N`: `μ` when `N > 0`, else 0.
    pub drho: f64,
    /// `|y| − ρ` (N): positive outside the disc (the point slides).
    pub excess: f64,
    /// `K·gap + β·N` (N): negative when the point would end below the
    /// surface without load.
    pub held: f64,
    /// `N` (N).
    pub normal: f64,
}

/// Branches fixed for a solve (an active-set Newton step): `unloaded` and
/// `sliding` as in [`Branch`]; `None` lets the rows choose
/// (semismooth Newton).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Frozen {
    /// The normal row's branch.
    pub unloaded: bool,
    /// The friction's branch.
    pub sliding: bool,
}

/// A contact point in contact whose stick/slip and lift-off are solved in
/// the step, as a complementarity problem with the exact Coulomb law:
///
/// * normal: `min(N, K·gap + β·N) = 0` — either the point is held on the
///   surface (`K·gap + β·N = 0`, the ST2/ST3 normal row) with `N ≥ 0`, or
///   it carries no load (`N = 0`) and is not below the surface;
/// * tangential: `Ft = proj_{|·| ≤ ρ}(Ft − e)`, `ρ = μ·max(N, 0)`, with
///   `e = K·(p[k+1] − r)_t + β·Ft` the stick rows' residual about the
///   reference `r` (the anchor, or the point at k). Inside the disc the
///   rows are `e = 0` (stick, `|Ft| ≤ μ·N`); outside, `Ft = ρ·ŷ`, `y = Ft −
///   e`, which makes `K·(p[k+1] − r)_t = −(|y|/ρ − 1 + β)·Ft`: the slip
///   opposes the friction exactly, and `|Ft| = μ·N` (Coulomb's sliding
///   law with the step's own slip, no division by the slip).
///
/// `t` holds the tangential components of `K·(p[k+1] − r)` and `gap` the
/// normal gap (m); `force` is `(Ft1, N, Ft2)` ([`NORMAL`] second).
/// With `frozen`, the branches are the given ones whatever the iterate
/// (the smooth extension of each: the active-set solve near a solution on
/// a branch's boundary, where semismooth Newton converges only linearly).
/// Writes the three rows into `r` and returns the branch taken.
#[inline]
#[allow(clippy::too_many_arguments)]
pub fn complementarity_rows(
    force: &[f64],
    t: [f64; 2],
    gap: f64,
    mu: f64,
    gain: f64,
    beta: f64,
    frozen: Option<Frozen>,
    r: &mut [f64],
) -> Branch {
    let n = force[NORMAL];
    let held = gain * gap + beta * n;
    let unloaded = frozen.map_or(n < held, |f| f.unloaded);
    r[NORMAL] = if unloaded { n } else { held };
    let ft = [force[0], force[2]];
    let e = [t[0] + beta * ft[0], t[1] + beta * ft[1]];
    let y = [ft[0] - e[0], ft[1] - e[1]];
    let rho = mu * n.max(0.0);
    let len = y[0].hypot(y[1]);
    let sliding = frozen.map_or(len > rho, |f| f.sliding);
    let base = Branch {
        unloaded,
        excess: len - rho,
        held,
        normal: n,
        ..Branch::default()
    };
    if !sliding {
        r[0] = e[0];
        r[2] = e[1];
        base
    } else {
        let (dir, ratio) = if len > 0.0 {
            ([y[0] / len, y[1] / len], rho / len)
        } else {
            ([1.0, 0.0], 0.0)
        };
        r[0] = ft[0] - rho * dir[0];
        r[2] = ft[1] - rho * dir[1];
        Branch {
            sliding: true,
            dir,
            ratio,
            drho: if n > 0.0 { mu } else { 0.0 },
            ..base
        }
    }
}

/// The stop row of a joint limit with moment `lambda` at angle `angle`,
/// and whether a complementarity stop is unloaded. At an end with
/// [`LimitEquation::complementarity`] the row is
/// `min(σ·λ, σ·(Kθ·(θ − end) + β·λ))`, `σ` the side's sign (+1 at the lower
/// end): the joint is held at the end by a pushing moment (`σ·λ ≥ 0`), or
/// the stop carries none (`λ = 0`) and the joint does not cross the end.
#[inline]
pub fn limit_row(eq: &LimitEquation, lambda: f64, angle: f64, gain: f64) -> (f64, bool) {
    match eq.state {
        LimitState::Free => (lambda, false),
        LimitState::At { angle: end, side } => {
            let held = gain * (angle - end) + eq.regularization * lambda;
            if eq.complementarity {
                let s = side.sign();
                let unloaded = s * lambda < s * held;
                (if unloaded { s * lambda } else { s * held }, unloaded)
            } else {
                (held, false)
            }
        }
    }
}

/// `∂(stop row)/∂λ` (`unloaded`: the branch of [`limit_row`]).
#[inline]
pub fn limit_row_diagonal(eq: &LimitEquation, unloaded: bool) -> f64 {
    match eq.state {
        LimitState::Free => 1.0,
        LimitState::At { side, .. } if eq.complementarity => {
            side.sign() * if unloaded { 1.0 } else { eq.regularization }
        }
        LimitState::At { .. } => eq.regularization,
    }
}

/// `∂(stop row)/∂θ` at an end (`gain` = Kθ; `unloaded`: the branch of
/// [`limit_row`]).
#[inline]
pub fn limit_row_angle(eq: &LimitEquation, unloaded: bool, gain: f64) -> f64 {
    match eq.state {
        LimitState::Free => 0.0,
        LimitState::At { side, .. } if eq.complementarity => {
            if unloaded {
                0.0
            } else {
                side.sign() * gain
            }
        }
        LimitState::At { .. } => gain,
    }
}

/// A key identifying the Jacobian's sparsity pattern: the contact states'
/// codes in base 4 (a slide's direction changes values, not structure;
/// `None`: a complementarity point, one pattern for ST2 and ST3), then one
/// bit per joint limit (free or at an end).
pub fn pattern_key(
    contacts: impl Iterator<Item = Option<StateCode>>,
    limits: impl Iterator<Item = bool>,
) -> u64 {
    let k = contacts.fold(0u64, |k, c| k * 4 + c.map_or(3, |c| c as u64));
    limits.fold(k, |k, at| k * 2 + u64::from(at))
}

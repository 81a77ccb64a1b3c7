//! One isolated rigid body: its discretised Newton–Euler equations
//! (paper eqs. 11–13 in the inertial frame, the contract).
//!
//! For body `b` with mass `m`, inertia `I`, versor `v` and coordinates
//! `X(q), Y(q), ψ(q)` (centre of mass and absolute angle):
//!
//! ```text
//! m (c·X(q[k+1]) + bX) / Δt² − ΣFx           = 0
//! m (c·Y(q[k+1]) + bY) / Δt² − ΣFy + m g     = 0
//! v·[ I (c·ψ(q[k+1]) + bψ) / Δt² − ΣMz − ΣT ] = 0
//! ```
//!
//! with `c = 1`, `b = −2x[k] + x[k−1]` for `k ≥ 1` and, from the initial
//! velocity, `c = 2`, `b = −2x[0] − 2Δt ẋ(0)` for `k = 0`. `ΣMz` is the sum of
//! `(P − X[k]) × F` over the forces applied at points `P` of configuration
//! `k`; `ΣT` the joint torques about Z.

use crate::space::{Plane, Space};

/// Per-step constants of one body's equations, in the plane or in space.
///
/// The linear rows read `m·(c·x(q[k+1]) + b)/Δt² − ΣF`, the rotation rows
/// `D_ang − ΣM` with `D_ang` the discrete rate of the body's angular
/// momentum, built from [`Self::ang`] (the plane: `I·(c·ψ[k+1] + b_ψ)/Δt²`;
/// space: `(c·L[k+½] − L[k−½])/Δt`, see `crate::spatial`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BodyStep<S: Space = Plane> {
    /// Coefficient of the `k+1` term (1, or 2 at k = 0).
    pub c_next: f64,
    /// Constant part of the centre of mass's second difference:
    /// `−2x[k] + x[k−1]`, or `−2x[0] − 2Δt·ẋ(0)` at k = 0.
    pub b: S::Lin,
    /// Constant part of the rotation: the plane: the angle's second
    /// difference, `−2ψ[k] + ψ[k−1]` (or `−2ψ[0] − 2Δt·ψ̇(0)`); space: the
    /// momentum `L[k−½]` (or `2·L(0)`).
    pub ang: S::Ang,
    /// Centre of mass at `q[k]`: the moment reference.
    pub com_k: S::Lin,
}

impl<S: Space> Default for BodyStep<S> {
    fn default() -> Self {
        Self {
            c_next: 1.0,
            b: S::Lin::default(),
            ang: S::Ang::default(),
            com_k: S::Lin::default(),
        }
    }
}

impl<S: Space> BodyStep<S> {
    /// The discrete acceleration `(c·x_next + b)/Δt²` of linear coordinate
    /// `axis`, given `inv_dt2 = 1/Δt²` (a product: the residual's
    /// evaluations take no division).
    #[inline]
    pub fn acceleration(&self, axis: usize, x_next: f64, inv_dt2: f64) -> f64 {
        (self.c_next * x_next + self.b.as_ref()[axis]) * inv_dt2
    }
}

impl BodyStep<Plane> {
    /// Constants from the two previous configurations `(X, Y, ψ)` (`k ≥ 1`).
    pub fn from_history(x_k: [f64; 3], x_prev: [f64; 3]) -> Self {
        Self {
            c_next: 1.0,
            b: [-2.0 * x_k[0] + x_prev[0], -2.0 * x_k[1] + x_prev[1]],
            ang: [-2.0 * x_k[2] + x_prev[2]],
            com_k: [x_k[0], x_k[1]],
        }
    }

    /// Constants of the first step from the initial velocity `ẋ(0)`:
    /// `x[−1] = x[1] − 2Δt ẋ(0)`.
    pub fn from_velocity(x_0: [f64; 3], xdot_0: [f64; 3], dt: f64) -> Self {
        Self {
            c_next: 2.0,
            b: [
                -2.0 * x_0[0] - 2.0 * dt * xdot_0[0],
                -2.0 * x_0[1] - 2.0 * dt * xdot_0[1],
            ],
            ang: [-2.0 * x_0[2] - 2.0 * dt * xdot_0[2]],
            com_k: [x_0[0], x_0[1]],
        }
    }

    /// The planar angle's discrete acceleration `(c·ψ_next + b_ψ)/Δt²`.
    #[inline]
    pub fn angular_acceleration(&self, psi_next: f64, inv_dt2: f64) -> f64 {
        (self.c_next * psi_next + self.ang[0]) * inv_dt2
    }
}

/// The sum of the forces and moments (about the centre of mass at `k`)
/// applied to one body in a step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wrench<S: Space> {
    /// `ΣF` (N), gravity included.
    pub force: S::Lin,
    /// `ΣM` (N·m).
    pub moment: S::Ang,
}

impl<S: Space> Default for Wrench<S> {
    fn default() -> Self {
        Self {
            force: S::Lin::default(),
            moment: S::Ang::default(),
        }
    }
}

/// 2-D cross product `r × F` (its Z component).
#[inline]
pub fn cross(r: [f64; 2], f: [f64; 2]) -> f64 {
    r[0] * f[1] - r[1] * f[0]
}

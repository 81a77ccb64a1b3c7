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

/// Per-step constants of one body's equations.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct BodyStep {
    /// Coefficient of `x(q[k+1])` in the second difference (1, or 2 at k = 0).
    pub c_next: f64,
    /// Constant part of the second difference for X, Y and ψ.
    pub b: [f64; 3],
    /// Centre of mass at `q[k]`: the moment reference.
    pub com_k: [f64; 2],
}

impl BodyStep {
    /// Constants from the two previous configurations (`k ≥ 1`).
    pub fn from_history(x_k: [f64; 3], x_prev: [f64; 3]) -> Self {
        Self {
            c_next: 1.0,
            b: [
                -2.0 * x_k[0] + x_prev[0],
                -2.0 * x_k[1] + x_prev[1],
                -2.0 * x_k[2] + x_prev[2],
            ],
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
                -2.0 * x_0[2] - 2.0 * dt * xdot_0[2],
            ],
            com_k: [x_0[0], x_0[1]],
        }
    }

    /// The discrete acceleration `(c·x_next + b)/Δt²` of coordinate `axis`,
    /// given `inv_dt2 = 1/Δt²` (a product: the residual's evaluations take
    /// no division).
    #[inline]
    pub fn acceleration(&self, axis: usize, x_next: f64, inv_dt2: f64) -> f64 {
        (self.c_next * x_next + self.b[axis]) * inv_dt2
    }
}

/// 2-D cross product `r × F` (its Z component).
#[inline]
pub fn cross(r: [f64; 2], f: [f64; 2]) -> f64 {
    r[0] * f[1] - r[1] * f[0]
}

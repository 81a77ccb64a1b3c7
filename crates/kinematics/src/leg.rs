//! One 3-DOF leg in its base frame 0 (paper eqs. 1–4, docs/reference.md).
//!
//! Expanding `0A1(θ1)·1A2(θ2)·2A3(θ3)·[0,0,0,1]ᵀ` (see [`crate::dh`]) gives
//!
//! ```text
//! ρ_k = −a·cosθ2                      ζ_k = −a·sinθ2
//! ρ   = −a·cosθ2 + c·cos(θ2+θ3)        ζ   = −a·sinθ2 + c·sin(θ2+θ3)
//! knee = (cosθ1·ρ_k, sinθ1·ρ_k, ζ_k)   tip = (cosθ1·ρ, sinθ1·ρ, ζ)
//! ```
//!
//! `ρ` is the coordinate along `x1` (horizontal in the body, in the leg's
//! vertical plane) and `ζ` along `z0` = body `+y` (up). With θ1 = 0 the
//! leg's `x1 = x0` points *towards* the body, so a leg standing outward has
//! `ρ < 0`. θ3 = π stretches the leg straight; θ3 = 0 folds the lower link
//! back onto the upper one.

use nalgebra::{Matrix3, Vector3};

/// Link lengths of one leg.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LegGeometry {
    /// Upper link length `a` (hip → knee), m.
    pub a: f64,
    /// Lower link length `c` (knee → tip), m.
    pub c: f64,
}

impl Default for LegGeometry {
    /// The paper's leg (docs/reference.md test vector):
    /// * `a = 0.2` m,
    /// * `c = 0.42` m.
    fn default() -> Self {
        Self { a: 0.2, c: 0.42 }
    }
}

/// Knee and tip of one leg in its base frame 0 (the hip is the origin).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LegPoints {
    /// Knee, `0A1·1A2·[0,0,0,1]ᵀ` (m).
    pub knee: Vector3<f64>,
    /// Tip, `0A1·1A2·2A3·[0,0,0,1]ᵀ` (m).
    pub tip: Vector3<f64>,
}

impl LegGeometry {
    /// Smallest hip–tip distance the leg reaches, `|a − c|` (m).
    pub fn min_reach(&self) -> f64 {
        (self.a - self.c).abs()
    }

    /// Largest hip–tip distance the leg reaches, `a + c` (m).
    pub fn max_reach(&self) -> f64 {
        self.a + self.c
    }

    /// Forward kinematics in frame 0, eq. (4); `theta = (θ1, θ2, θ3)` (rad).
    pub fn forward(&self, theta: [f64; 3]) -> LegPoints {
        let (s1, c1) = theta[0].sin_cos();
        let (s2, c2) = theta[1].sin_cos();
        let (s23, c23) = (theta[1] + theta[2]).sin_cos();
        let rho_k = -self.a * c2;
        let zeta_k = -self.a * s2;
        let rho = rho_k + self.c * c23;
        let zeta = zeta_k + self.c * s23;
        LegPoints {
            knee: Vector3::new(c1 * rho_k, s1 * rho_k, zeta_k),
            tip: Vector3::new(c1 * rho, s1 * rho, zeta),
        }
    }

    /// Tip position in frame 0 alone (eq. 4).
    pub fn tip(&self, theta: [f64; 3]) -> Vector3<f64> {
        self.forward(theta).tip
    }

    /// Analytic Jacobian `∂tip/∂(θ1, θ2, θ3)` in frame 0; column `j` is the
    /// derivative with respect to `theta[j]`.
    ///
    /// ```text
    /// ∂/∂θ1 = (−sinθ1·ρ, cosθ1·ρ, 0)
    /// ∂/∂θ2 = (cosθ1·ρ', sinθ1·ρ', ρ)       ρ' = a·sinθ2 − c·sin(θ2+θ3)
    /// ∂/∂θ3 = (−cosθ1·c·s23, −sinθ1·c·s23, c·c23)
    /// ```
    pub fn tip_jacobian(&self, theta: [f64; 3]) -> Matrix3<f64> {
        let (s1, c1) = theta[0].sin_cos();
        let (s2, c2) = theta[1].sin_cos();
        let (s23, c23) = (theta[1] + theta[2]).sin_cos();
        let rho = -self.a * c2 + self.c * c23;
        let drho2 = self.a * s2 - self.c * s23;
        let drho3 = -self.c * s23;
        #[rustfmt::skip]
        let j = Matrix3::new(
            -s1 * rho, c1 * drho2, c1 * drho3,
            c1 * rho,  s1 * drho2, s1 * drho3,
            0.0,       rho,        self.c * c23,
        );
        j
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dh::leg_chain;
    use crate::fd::{FdTolerance, check_jacobian};

    #[test]
    fn forward_matches_dh_product() {
        let g = LegGeometry { a: 0.3, c: 0.55 };
        for th in [[0.0, 0.0, 0.0], [0.4, -0.7, 4.2], [-2.5, 1.1, 0.3]] {
            let p = g.forward(th);
            let (k, t) = leg_chain(th, g.a, g.c);
            assert!((p.knee - k).norm() < 1e-14 && (p.tip - t).norm() < 1e-14);
        }
    }

    #[test]
    fn tip_jacobian_matches_finite_differences() {
        let g = LegGeometry::default();
        let th = [0.3, -0.4, 4.1];
        let j = g.tip_jacobian(th);
        check_jacobian(
            &th,
            3,
            |x, out| {
                let t = g.tip([x[0], x[1], x[2]]);
                out.copy_from_slice(t.as_slice());
            },
            |i, k| j[(i, k)],
            FdTolerance::default(),
        )
        .unwrap_or_else(|e| panic!("{e}"));
    }
}

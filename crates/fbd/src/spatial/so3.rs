//! The rotation group SO(3): hat, exponential and logarithm maps and the
//! right Jacobian with its inverse, with series near zero angle.
//!
//! `exp(φ)` is the rotation by `|φ|` about `φ/|φ|` (Rodrigues); `log` its
//! inverse for angles below π. The right Jacobian `Jr(φ)` maps a body-frame
//! perturbation of the rotation vector to the body-frame rotation:
//! `exp(φ + δφ) ≈ exp(φ)·exp(Jr(φ)·δφ)`; `Jr⁻¹(φ)` goes back:
//! `log(exp(φ)·exp(δξ)) ≈ φ + Jr⁻¹(φ)·δξ`.

use fbd_kinematics::nalgebra::{Matrix3, Vector3};

/// Below this angle (rad) the coefficient functions use their Taylor
/// series, to θ⁸ (the first term left out is below 3e-21 relative at
/// 0.05 rad): a step's rotation is far below it at any sensible Δt, and
/// the series needs no trigonometry.
const SMALL: f64 = 0.05;

/// The skew matrix `[v]×` with `[v]×·w = v × w`.
#[inline]
pub fn hat(v: &Vector3<f64>) -> Matrix3<f64> {
    Matrix3::new(0.0, -v.z, v.y, v.z, 0.0, -v.x, -v.y, v.x, 0.0)
}

/// `(sin θ/θ, (1 − cos θ)/θ², (θ − sin θ)/θ³)` at `θ = t`.
#[inline]
fn coefficients(t: f64) -> (f64, f64, f64) {
    let t2 = t * t;
    if t < SMALL {
        (
            1.0 - t2 / 6.0 * (1.0 - t2 / 20.0 * (1.0 - t2 / 42.0 * (1.0 - t2 / 72.0))),
            0.5 - t2 / 24.0 * (1.0 - t2 / 30.0 * (1.0 - t2 / 56.0 * (1.0 - t2 / 90.0))),
            1.0 / 6.0 - t2 / 120.0 * (1.0 - t2 / 42.0 * (1.0 - t2 / 72.0 * (1.0 - t2 / 110.0))),
        )
    } else {
        let (s, c) = t.sin_cos();
        (s / t, (1.0 - c) / t2, (t - s) / (t2 * t))
    }
}

/// `exp(φ)`: the rotation matrix of rotation vector `phi`.
#[inline]
pub fn exp(phi: &Vector3<f64>) -> Matrix3<f64> {
    let (a, b, _) = coefficients(phi.norm());
    let h = hat(phi);
    Matrix3::identity() + a * h + b * h * h
}

/// `exp(φ)·v` without forming the matrix (Rodrigues on a vector).
#[inline]
pub fn rotate(phi: &Vector3<f64>, v: &Vector3<f64>) -> Vector3<f64> {
    let (a, b, _) = coefficients(phi.norm());
    let c = phi.cross(v);
    v + a * c + b * phi.cross(&c)
}

/// `log(R)`: the rotation vector of `r` (angle in `[0, π)`; accurate for
/// small angles, where it is taken from the skew part).
#[inline]
pub fn log(r: &Matrix3<f64>) -> Vector3<f64> {
    // v = sin θ · axis, cos θ from the trace.
    let v = 0.5
        * Vector3::new(
            r[(2, 1)] - r[(1, 2)],
            r[(0, 2)] - r[(2, 0)],
            r[(1, 0)] - r[(0, 1)],
        );
    let s = v.norm();
    let c = 0.5 * (r.trace() - 1.0);
    let k = if s < SMALL && c > 0.0 {
        // θ/sin θ = asin(s)/s as a series in s² (θ < π/2).
        let s2 = s * s;
        1.0 + s2
            * (1.0 / 6.0
                + s2 * (3.0 / 40.0
                    + s2 * (5.0 / 112.0 + s2 * (35.0 / 1152.0 + s2 * 63.0 / 2816.0))))
    } else {
        s.atan2(c) / s
    };
    k * v
}

/// The right Jacobian `Jr(φ) = I − (1 − cos θ)/θ²·[φ]× + (θ − sin θ)/θ³·[φ]×²`.
#[inline]
pub fn right_jacobian(phi: &Vector3<f64>) -> Matrix3<f64> {
    let (_, b, c) = coefficients(phi.norm());
    let h = hat(phi);
    Matrix3::identity() - b * h + c * h * h
}

/// `Jr⁻¹(φ) = I + ½[φ]× + (1/θ² − (1 + cos θ)/(2θ sin θ))·[φ]×²`.
#[inline]
pub fn right_jacobian_inv(phi: &Vector3<f64>) -> Matrix3<f64> {
    let t = phi.norm();
    let d = if t < SMALL {
        let t2 = t * t;
        1.0 / 12.0 + t2 * (1.0 / 720.0 + t2 * (1.0 / 30240.0 + t2 / 1209600.0))
    } else {
        let (s, c) = t.sin_cos();
        1.0 / (t * t) - (1.0 + c) / (2.0 * t * s)
    };
    let h = hat(phi);
    Matrix3::identity() + 0.5 * h + d * h * h
}

#[cfg(test)]
mod tests {
    use super::*;

    fn vecs() -> Vec<Vector3<f64>> {
        vec![
            Vector3::new(0.3, -0.2, 0.5),
            Vector3::new(1e-4, 2e-4, -3e-4),
            Vector3::new(2e-3, 0.0, 0.0),
            Vector3::new(0.0, 0.0, 0.0),
            Vector3::new(-1.2, 0.9, 1.1),
            Vector3::new(5e-4, -5e-4, 5e-4),
            Vector3::new(0.03, -0.035, 0.01),
            Vector3::new(0.04, 0.0, -0.04),
            Vector3::new(0.2, 0.0, 0.0),
        ]
    }

    #[test]
    fn rotate_is_exp_times_a_vector() {
        let w = Vector3::new(0.7, -1.1, 0.4);
        for v in vecs() {
            assert!((rotate(&v, &w) - exp(&v) * w).norm() < 1e-15);
        }
    }

    #[test]
    fn log_inverts_exp() {
        for v in vecs() {
            let r = exp(&v);
            assert!((r.transpose() * r - Matrix3::identity()).norm() < 1e-15);
            assert!((log(&r) - v).norm() < 1e-15 * (1.0 + v.norm()), "{v:?}");
        }
    }

    #[test]
    fn right_jacobians_match_finite_differences_and_invert() {
        for v in vecs() {
            let j = right_jacobian(&v);
            let ji = right_jacobian_inv(&v);
            let e = (j * ji - Matrix3::identity()).norm();
            assert!(e < 1e-13, "{v:?}: {e:e}");
            // exp(φ + δφ) = exp(φ)·exp(Jr δφ): δξ = log(exp(φ)ᵀ exp(φ + δφ)).
            let h = 1e-6;
            for i in 0..3 {
                let mut e = Vector3::zeros();
                e[i] = h;
                let plus = log(&(exp(&v).transpose() * exp(&(v + e))));
                let minus = log(&(exp(&v).transpose() * exp(&(v - e))));
                let fd = (plus - minus) / (2.0 * h);
                assert!((fd - j.column(i)).norm() < 1e-9, "{v:?} col {i}");
            }
        }
    }
}

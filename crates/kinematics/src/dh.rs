//! The Denavit–Hartenberg matrices of the paper, eqs. (1)–(3) and (5),
//! written out literally as homogeneous 4×4 transforms.
//!
//! These are the reference definitions: the fast forward kinematics of
//! [`crate::hexapod`] expands the same products by hand, and the tests check
//! it against these matrices.
//!
//! * [`a01`] — `0A1(θ1)`, eq. (1): hip yaw about `z0` (the body's vertical).
//! * [`a12`] — `1A2(θ2)`, eq. (2): hip pitch about `z1`, upper link of length
//!   `a`. Note the `−a`: at θ2 = 0 the knee lies on `−x1`, which points away
//!   from the body.
//! * [`a23`] — `2A3(θ3)`, eq. (3): knee about `z2`, lower link of length `c`.
//! * [`body_to_leg_base`] — `cA0i(γi)`, eq. (5): body frame → leg base frame 0.

use nalgebra::{Matrix3, Matrix4, Vector3, Vector4};

/// `0A1(θ1)` of eq. (1).
///
/// ```text
/// [ cosθ1  0   sinθ1  0 ]
/// [ sinθ1  0  −cosθ1  0 ]
/// [   0    1     0    0 ]
/// [   0    0     0    1 ]
/// ```
pub fn a01(theta1: f64) -> Matrix4<f64> {
    let (s, c) = theta1.sin_cos();
    #[rustfmt::skip]
    let m = Matrix4::new(
        c,   0.0, s,   0.0,
        s,   0.0, -c,  0.0,
        0.0, 1.0, 0.0, 0.0,
        0.0, 0.0, 0.0, 1.0,
    );
    m
}

/// `1A2(θ2)` of eq. (2), upper link length `a`.
///
/// ```text
/// [ cosθ2  −sinθ2  0  −a·cosθ2 ]
/// [ sinθ2   cosθ2  0  −a·sinθ2 ]
/// [   0       0    1     0     ]
/// [   0       0    0     1     ]
/// ```
pub fn a12(theta2: f64, a: f64) -> Matrix4<f64> {
    let (s, c) = theta2.sin_cos();
    #[rustfmt::skip]
    let m = Matrix4::new(
        c,   -s,  0.0, -a * c,
        s,   c,   0.0, -a * s,
        0.0, 0.0, 1.0, 0.0,
        0.0, 0.0, 0.0, 1.0,
    );
    m
}

/// `2A3(θ3)` of eq. (3), lower link length `c`.
///
/// ```text
/// [ cosθ3  −sinθ3  0  c·cosθ3 ]
/// [ sinθ3   cosθ3  0  c·sinθ3 ]
/// [   0       0    1     0    ]
/// [   0       0    0     1    ]
/// ```
pub fn a23(theta3: f64, c: f64) -> Matrix4<f64> {
    let (s, co) = theta3.sin_cos();
    #[rustfmt::skip]
    let m = Matrix4::new(
        co,  -s,  0.0, c * co,
        s,   co,  0.0, c * s,
        0.0, 0.0, 1.0, 0.0,
        0.0, 0.0, 0.0, 1.0,
    );
    m
}

/// `cA0i(γi)` of eq. (5): leg base frame 0 → body frame, `d = L·cos(π/6)`.
///
/// ```text
/// [ −cosγ  sinγ  0   d·cosγ ]
/// [   0     0    1     0    ]
/// [  sinγ  cosγ  0  −d·sinγ ]
/// [   0     0    0     1    ]
/// ```
///
/// The leg base `z0` (the θ1 axis) is the body's `+y` (vertical), and the
/// hip sits at `(d·cosγ, 0, −d·sinγ)` in body coordinates.
pub fn body_to_leg_base(gamma: f64, d: f64) -> Matrix4<f64> {
    let (s, c) = gamma.sin_cos();
    #[rustfmt::skip]
    let m = Matrix4::new(
        -c,  s,   0.0, d * c,
        0.0, 0.0, 1.0, 0.0,
        s,   c,   0.0, -d * s,
        0.0, 0.0, 0.0, 1.0,
    );
    m
}

/// The leg chain of eq. (4) through the matrices: `(knee, tip)` in the leg
/// base frame 0, `knee = 0A1·1A2·[0,0,0,1]ᵀ`, `tip = 0A1·1A2·2A3·[0,0,0,1]ᵀ`
/// (the hip is the origin of frame 0). Reference implementation; see
/// [`crate::leg::LegGeometry::forward`] for the fast one.
pub fn leg_chain(theta: [f64; 3], a: f64, c: f64) -> (Vector3<f64>, Vector3<f64>) {
    let origin = Vector4::new(0.0, 0.0, 0.0, 1.0);
    let t02 = a01(theta[0]) * a12(theta[1], a);
    let knee = t02 * origin;
    let tip = t02 * a23(theta[2], c) * origin;
    (knee.xyz(), tip.xyz())
}

/// The rotation block (upper-left 3×3) of a homogeneous transform.
pub fn rotation_block(m: &Matrix4<f64>) -> Matrix3<f64> {
    m.fixed_view::<3, 3>(0, 0).into_owned()
}

/// The translation column of a homogeneous transform.
pub fn translation_block(m: &Matrix4<f64>) -> Vector3<f64> {
    m.fixed_view::<3, 1>(0, 3).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn assert_rotation(r: &Matrix3<f64>) {
        let e = (r.transpose() * r - Matrix3::identity()).norm();
        assert!(e < 1e-12, "not orthonormal: {e}");
        assert!(
            (r.determinant() - 1.0).abs() < 1e-12,
            "det {}",
            r.determinant()
        );
    }

    #[test]
    fn rotation_blocks_are_proper() {
        for &t in &[-2.0, -0.3, 0.0, 0.7, 3.0] {
            assert_rotation(&rotation_block(&a01(t)));
            assert_rotation(&rotation_block(&a12(t, 0.2)));
            assert_rotation(&rotation_block(&a23(t, 0.42)));
            assert_rotation(&rotation_block(&body_to_leg_base(t, 0.2)));
        }
    }

    #[test]
    fn hip_in_body_frame() {
        let d = 0.25 * (std::f64::consts::PI / 6.0).cos();
        for gd in [120.0f64, 60.0, 180.0, 0.0, 240.0, 300.0] {
            let g = gd.to_radians();
            let h = translation_block(&body_to_leg_base(g, d));
            let want = Vector3::new(d * g.cos(), 0.0, -d * g.sin());
            assert!((h - want).norm() < 1e-15);
        }
    }

    #[test]
    fn chain_matches_closed_form() {
        // tip0 = (c1·ρ, s1·ρ, ζ), ρ = −a·c2 + c·c23, ζ = −a·s2 + c·s23.
        let (a, c) = (0.2, 0.42);
        let th = [0.3, -0.4, 4.1];
        let (knee, tip) = leg_chain(th, a, c);
        let rho_k = -a * th[1].cos();
        let rho = rho_k + c * (th[1] + th[2]).cos();
        let zeta = -a * th[1].sin() + c * (th[1] + th[2]).sin();
        let kw = Vector3::new(th[0].cos() * rho_k, th[0].sin() * rho_k, -a * th[1].sin());
        let tw = Vector3::new(th[0].cos() * rho, th[0].sin() * rho, zeta);
        assert!((knee - kw).norm() < 1e-14 && (tip - tw).norm() < 1e-14);
    }
}

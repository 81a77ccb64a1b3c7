//! The swing foot's path from lift-off to touchdown.
//!
//! # Which curve, and why
//!
//! With `u = (t − t_lift)/T_sw ∈ [0, 1]`:
//!
//! ```text
//! p(u) = p0 + (p1 − p0)·q(u) + h·b(u)·Y
//! q(u) = 10u³ − 15u⁴ + 6u⁵          (minimum-jerk, quintic)
//! b(u) = 64·u³·(1 − u)³              (bump, 1 at u = ½)
//! ```
//!
//! Both `q` and `b` have zero first *and* second derivatives at both ends,
//! so the foot leaves and meets the ground with zero velocity and zero
//! acceleration: the joint velocities and accelerations are continuous at
//! lift-off and touchdown (a cubic, or a cycloid, leaves an acceleration
//! jump there that a motor has to deliver instantly). The quintic is the
//! lowest-degree polynomial with that property and the minimum-jerk path
//! between two rests; the bump is the lowest-degree symmetric polynomial
//! with it, and its peak `h` ([`super::GaitParams::swing_height`]) is
//! reached at mid-swing, above the straight line from `p0` to `p1`.

use fbd_kinematics::nalgebra::Vector3;

/// `(q, q′, q″)` of the quintic minimum-jerk blend at `u ∈ [0, 1]`.
#[inline]
pub fn blend(u: f64) -> (f64, f64, f64) {
    let u2 = u * u;
    let w = 1.0 - u;
    (
        u2 * u * (10.0 - 15.0 * u + 6.0 * u2),
        30.0 * u2 * w * w,
        60.0 * u * w * (1.0 - 2.0 * u),
    )
}

/// `(b, b′, b″)` of the lift bump `64·u³(1 − u)³`.
#[inline]
pub fn bump(u: f64) -> (f64, f64, f64) {
    let w = 1.0 - u;
    let (u2, w2) = (u * u, w * w);
    (
        64.0 * u2 * u * w2 * w,
        192.0 * u2 * w2 * (1.0 - 2.0 * u),
        384.0 * u * w * (w * (1.0 - 2.0 * u) - u * (1.0 - 2.0 * u) - u * w),
    )
}

/// Foot position, velocity and acceleration along the swing from `p0` to
/// `p1` lasting `duration` (s) with lift `height` (m), at fraction `u`.
#[inline]
pub fn swing(
    p0: &Vector3<f64>,
    p1: &Vector3<f64>,
    height: f64,
    duration: f64,
    u: f64,
) -> (Vector3<f64>, Vector3<f64>, Vector3<f64>) {
    let (q, qd, qdd) = blend(u);
    let (b, bd, bdd) = bump(u);
    let d = p1 - p0;
    let y = Vector3::y();
    let k = 1.0 / duration;
    (
        p0 + q * d + (height * b) * y,
        (qd * d + (height * bd) * y) * k,
        (qdd * d + (height * bdd) * y) * (k * k),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn derivatives_and_rests() {
        let h = 1e-6;
        for f in [blend, bump] {
            for u in [0.1, 0.33, 0.5, 0.8] {
                let (_, d, dd) = f(u);
                let fd = (f(u + h).0 - f(u - h).0) / (2.0 * h);
                let fdd = (f(u + h).1 - f(u - h).1) / (2.0 * h);
                assert!((d - fd).abs() < 1e-7 && (dd - fdd).abs() < 1e-6, "{u}");
            }
            for u in [0.0, 1.0] {
                let (_, d, dd) = f(u);
                assert!(d == 0.0 && dd.abs() < 1e-12);
            }
        }
        assert_eq!(blend(1.0).0, 1.0);
        assert_eq!(bump(0.5).0, 1.0);
        let (p0, p1) = (Vector3::new(0.0, 0.0, 0.0), Vector3::new(0.1, 0.02, -0.3));
        let (p, v, _) = swing(&p0, &p1, 0.05, 0.5, 0.5);
        assert!((p - (0.5 * (p0 + p1) + Vector3::new(0.0, 0.05, 0.0))).norm() < 1e-15);
        assert!((v.y - 0.02 * 1.875 / 0.5).abs() < 1e-12);
    }
}

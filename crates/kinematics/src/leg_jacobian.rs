//! Joint rates and accelerations of one leg from its analytic tip Jacobian
//! and the Jacobian's time derivative (differential inverse kinematics).
//!
//! With `p = tip(θ)` in the leg base frame 0 and `J = ∂p/∂θ`
//! ([`LegGeometry::tip_jacobian`]):
//!
//! ```text
//! ṗ = J·θ̇                 ⇒  θ̇ = J⁻¹·ṗ
//! p̈ = J·θ̈ + J̇·θ̇          ⇒  θ̈ = J⁻¹·(p̈ − J̇·θ̇)
//! ```
//!
//! `J̇ = Σₖ ∂J/∂θₖ·θ̇ₖ` is written out in closed form by
//! [`tip_jacobian_dot`]. `J` is singular when the leg is stretched or
//! folded (`sin θ3 = 0`) or the tip is on the θ1 axis (`ρ = 0`);
//! [`joint_rates`] reports it as [`SingularLeg`] rather than dividing by
//! zero.

use nalgebra::{Matrix3, Vector3};

use crate::leg::LegGeometry;

/// Smallest `|det J| / (a·c·(a + c))` accepted by [`joint_rates`] and
/// [`joint_accelerations`] (dimensionless: `det J = a·c·sin θ3·ρ`).
pub const SINGULAR_DET: f64 = 1e-9;

/// The tip Jacobian is (numerically) singular: the leg is stretched,
/// folded, or the tip is on the θ1 axis.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SingularLeg {
    /// `det J` (m³).
    pub det: f64,
}

/// Sines and cosines of a leg's joint angles, computed once and shared by
/// the Jacobian, its derivative and the solves.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LegTrig {
    /// `sin θ1`, `cos θ1`.
    pub s1: f64,
    /// `cos θ1`.
    pub c1: f64,
    /// `sin θ2`.
    pub s2: f64,
    /// `cos θ2`.
    pub c2: f64,
    /// `sin(θ2 + θ3)`.
    pub s23: f64,
    /// `cos(θ2 + θ3)`.
    pub c23: f64,
}

impl LegTrig {
    /// The sines and cosines of `theta = (θ1, θ2, θ3)` (rad).
    #[inline]
    pub fn new(theta: [f64; 3]) -> Self {
        let (s1, c1) = theta[0].sin_cos();
        let (s2, c2) = theta[1].sin_cos();
        let (s23, c23) = (theta[1] + theta[2]).sin_cos();
        Self {
            s1,
            c1,
            s2,
            c2,
            s23,
            c23,
        }
    }
}

impl LegTrig {
    /// The sines and cosines of the outward inverse-kinematics solution
    /// `theta` of a tip at `tip` (frame 0; the solution of
    /// [`crate::ik::leg_ik`], `ρ = −√(x² + y²) < 0`), with one `sin_cos`
    /// (of θ3) instead of three: the chain is inverted algebraically,
    /// `(c1, s1) = (x, y)/ρ`, and `(ρ, ζ) = Rot(θ2)·(A, B)` with
    /// `A = c·c3 − a`, `B = c·s3` gives
    /// `(c2, s2) = (A·ρ + B·ζ, A·ζ − B·ρ)/(A² + B²)`; then the sum formulas.
    /// Equal to [`LegTrig::new`]`(theta)` up to round-off.
    #[inline]
    pub fn of_solution(geom: &LegGeometry, theta: [f64; 3], tip: &Vector3<f64>) -> Self {
        let (a, c) = (geom.a, geom.c);
        let (s3, c3) = theta[2].sin_cos();
        let rho = -tip.x.hypot(tip.y);
        let (c1, s1) = (tip.x / rho, tip.y / rho);
        let (aa, bb) = (c * c3 - a, c * s3);
        let n = aa * aa + bb * bb;
        let z = tip.z;
        let c2 = (aa * rho + bb * z) / n;
        let s2 = (aa * z - bb * rho) / n;
        Self {
            s1,
            c1,
            s2,
            c2,
            s23: s2 * c3 + c2 * s3,
            c23: c2 * c3 - s2 * s3,
        }
    }
}

/// Closed-form `J̇ = d/dt ∂tip/∂θ` in the leg base frame 0, for joint angles
/// `theta` and rates `rate` (rad, rad/s). Column `j` is the time derivative
/// of column `j` of [`LegGeometry::tip_jacobian`].
///
/// With `ρ = −a·c2 + c·c23`, `ρ₂ = ∂ρ/∂θ2 = a·s2 − c·s23`,
/// `ρ₃ = ∂ρ/∂θ3 = −c·s23`, `ω23 = θ̇2 + θ̇3`:
///
/// ```text
/// ρ̇   = ρ₂·θ̇2 + ρ₃·θ̇3
/// ρ̇₂  = a·c2·θ̇2 − c·c23·ω23
/// ρ̇₃  = −c·c23·ω23
/// col1 = (−c1·ρ·θ̇1 − s1·ρ̇,  −s1·ρ·θ̇1 + c1·ρ̇,  0)
/// col2 = (−s1·ρ₂·θ̇1 + c1·ρ̇₂,  c1·ρ₂·θ̇1 + s1·ρ̇₂,  ρ̇)
/// col3 = (−s1·ρ₃·θ̇1 + c1·ρ̇₃,  c1·ρ₃·θ̇1 + s1·ρ̇₃,  −c·s23·ω23)
/// ```
pub fn tip_jacobian_dot(geom: &LegGeometry, theta: [f64; 3], rate: [f64; 3]) -> Matrix3<f64> {
    jacobian_dot(geom, &LegTrig::new(theta), rate)
}

/// [`tip_jacobian_dot`] from precomputed sines and cosines.
#[inline]
pub fn jacobian_dot(geom: &LegGeometry, t: &LegTrig, rate: [f64; 3]) -> Matrix3<f64> {
    let (a, c) = (geom.a, geom.c);
    let LegTrig {
        s1,
        c1,
        s2,
        c2,
        s23,
        c23,
    } = *t;
    let [w1, w2, w3] = rate;
    let w23 = w2 + w3;
    let rho = -a * c2 + c * c23;
    let rho2 = a * s2 - c * s23;
    let rho3 = -c * s23;
    let rho_dot = rho2 * w2 + rho3 * w3;
    let rho2_dot = a * c2 * w2 - c * c23 * w23;
    let rho3_dot = -c * c23 * w23;
    #[rustfmt::skip]
    let m = Matrix3::new(
        -c1 * rho * w1 - s1 * rho_dot, -s1 * rho2 * w1 + c1 * rho2_dot, -s1 * rho3 * w1 + c1 * rho3_dot,
        -s1 * rho * w1 + c1 * rho_dot, c1 * rho2 * w1 + s1 * rho2_dot,  c1 * rho3 * w1 + s1 * rho3_dot,
        0.0,                           rho_dot,                         -c * s23 * w23,
    );
    m
}

/// Solves `J·x = v` in closed form. Rotating by −θ1 about `z0` turns `J`
/// into `[[0, ρ₂, ρ₃], [ρ, 0, 0], [0, ρ, c·c23]]`: `x1 = v′y/ρ` and a 2×2
/// system for `(x2, x3)` with determinant `ρ₂·c·c23 − ρ₃·ρ`
/// (`det J = −ρ·(ρ₂·c·c23 − ρ₃·ρ) = a·c·sin θ3·ρ`).
#[inline]
fn solve(geom: &LegGeometry, t: &LegTrig, v: &Vector3<f64>) -> Result<Vector3<f64>, SingularLeg> {
    let (a, c) = (geom.a, geom.c);
    let rho = -a * t.c2 + c * t.c23;
    let rho2 = a * t.s2 - c * t.s23;
    let rho3 = -c * t.s23;
    let cc = c * t.c23;
    let det2 = rho2 * cc - rho3 * rho;
    let det = -rho * det2;
    if det.is_nan() || det.abs() <= SINGULAR_DET * a * c * (a + c) {
        return Err(SingularLeg { det });
    }
    let vx = t.c1 * v.x + t.s1 * v.y;
    let vy = -t.s1 * v.x + t.c1 * v.y;
    let x1 = vy / rho;
    let x2 = (vx * cc - rho3 * v.z) / det2;
    let x3 = (rho2 * v.z - rho * vx) / det2;
    Ok(Vector3::new(x1, x2, x3))
}

/// Joint rates `θ̇ = J⁻¹·ṗ` (rad/s) for a tip velocity `tip_velocity` in the
/// leg base frame 0 (m/s) at joint angles `theta`.
///
/// # Errors
/// [`SingularLeg`] when `|det J|` is below [`SINGULAR_DET`]`·a·c·(a + c)`.
pub fn joint_rates(
    geom: &LegGeometry,
    theta: [f64; 3],
    tip_velocity: &Vector3<f64>,
) -> Result<[f64; 3], SingularLeg> {
    joint_rates_trig(geom, &LegTrig::new(theta), tip_velocity)
}

/// [`joint_rates`] from precomputed sines and cosines of the joint angles.
///
/// # Errors
/// [`SingularLeg`] as [`joint_rates`].
#[inline]
pub fn joint_rates_trig(
    geom: &LegGeometry,
    trig: &LegTrig,
    tip_velocity: &Vector3<f64>,
) -> Result<[f64; 3], SingularLeg> {
    Ok(solve(geom, trig, tip_velocity)?.into())
}

/// Joint rates and accelerations: `θ̇ = J⁻¹·ṗ`,
/// `θ̈ = J⁻¹·(p̈ − J̇·θ̇)` for a tip velocity and acceleration in the leg
/// base frame 0 (m/s, m/s²); one evaluation of the sines and cosines.
///
/// # Errors
/// [`SingularLeg`] as [`joint_rates`].
#[inline]
pub fn joint_accelerations(
    geom: &LegGeometry,
    theta: [f64; 3],
    tip_velocity: &Vector3<f64>,
    tip_acceleration: &Vector3<f64>,
) -> Result<([f64; 3], [f64; 3]), SingularLeg> {
    joint_accelerations_trig(geom, &LegTrig::new(theta), tip_velocity, tip_acceleration)
}

/// [`joint_accelerations`] from precomputed sines and cosines of the
/// joint angles.
///
/// # Errors
/// [`SingularLeg`] as [`joint_rates`].
#[inline]
pub fn joint_accelerations_trig(
    geom: &LegGeometry,
    trig: &LegTrig,
    tip_velocity: &Vector3<f64>,
    tip_acceleration: &Vector3<f64>,
) -> Result<([f64; 3], [f64; 3]), SingularLeg> {
    let rate = solve(geom, trig, tip_velocity)?;
    let jdot = jacobian_dot(geom, trig, rate.into());
    let acc = solve(geom, trig, &(tip_acceleration - jdot * rate))?;
    Ok((rate.into(), acc.into()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fd::{FdTolerance, check_jacobian};

    /// `J̇` against the central difference of `J(θ + s·θ̇)` in `s`.
    #[test]
    fn jacobian_dot_matches_finite_differences() {
        let g = LegGeometry::default();
        for (theta, rate) in [
            ([0.3, -0.4, 4.1], [0.7, -1.3, 2.1]),
            ([-1.2, 0.5, 3.6], [-2.0, 0.4, -0.9]),
            ([0.0, 0.0, 245f64.to_radians()], [0.1, 0.2, 0.3]),
        ] {
            let jd = tip_jacobian_dot(&g, theta, rate);
            check_jacobian(
                &[0.0],
                9,
                |s, out| {
                    let th = [0, 1, 2].map(|k| theta[k] + s[0] * rate[k]);
                    let j = g.tip_jacobian(th);
                    for (o, v) in out.iter_mut().zip(j.iter()) {
                        *o = *v;
                    }
                },
                |i, _| jd.as_slice()[i],
                FdTolerance::default(),
            )
            .unwrap_or_else(|e| panic!("θ = {theta:?}, θ̇ = {rate:?}: {e}"));
        }
    }

    /// Rates and accelerations reproduce the tip's velocity and
    /// acceleration along a joint path `θ(s) = θ0 + θ̇·s + θ̈·s²/2`.
    #[test]
    fn rates_and_accelerations_invert_the_chain() {
        let g = LegGeometry::default();
        let th0 = [0.2, -0.3, 4.2];
        let w = [0.5, -1.1, 0.8];
        let al = [-0.7, 0.9, 1.5];
        let path = |s: f64| [0, 1, 2].map(|k| th0[k] + w[k] * s + 0.5 * al[k] * s * s);
        let h = 1e-4;
        let v = (g.tip(path(h)) - g.tip(path(-h))) / (2.0 * h);
        let acc = (g.tip(path(h)) - 2.0 * g.tip(path(0.0)) + g.tip(path(-h))) / (h * h);
        let (rate, alpha) = joint_accelerations(&g, th0, &v, &acc).unwrap();
        for k in 0..3 {
            assert!((rate[k] - w[k]).abs() < 1e-6, "rate {k}: {rate:?}");
            assert!((alpha[k] - al[k]).abs() < 1e-4, "acc {k}: {alpha:?}");
        }
        let r2 = joint_rates(&g, th0, &v).unwrap();
        assert_eq!(r2, rate);
        // The closed-form solve agrees with a general inverse of J.
        let inv = g.tip_jacobian(th0).try_inverse().unwrap() * v;
        for k in 0..3 {
            assert!((inv[k] - rate[k]).abs() < 1e-12, "{inv} vs {rate:?}");
        }
    }

    #[test]
    fn trig_of_the_ik_solution_is_the_trig_of_the_angles() {
        use crate::ik::{KneeBranch, leg_ik};
        let g = LegGeometry::default();
        for th in [[0.3, -0.4, 4.1], [-2.0, 0.7, 3.5], [1.0, 0.1, 2.0]] {
            let tip = g.tip(th);
            let sol = leg_ik(&g, &tip, KneeBranch::of(th[2])).unwrap();
            let (a, b) = (LegTrig::of_solution(&g, sol, &tip), LegTrig::new(sol));
            for (x, y) in [
                (a.s1, b.s1),
                (a.c1, b.c1),
                (a.s2, b.s2),
                (a.c2, b.c2),
                (a.s23, b.s23),
                (a.c23, b.c23),
            ] {
                assert!((x - y).abs() < 1e-13, "{a:?} vs {b:?}");
            }
        }
    }

    #[test]
    fn stretched_leg_is_singular() {
        let g = LegGeometry::default();
        let e = joint_rates(&g, [0.0, 0.3, std::f64::consts::PI], &Vector3::x()).unwrap_err();
        assert!(e.det.abs() < 1e-12, "{e:?}");
    }
}

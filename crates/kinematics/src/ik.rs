//! Closed-form inverse kinematics of one leg.
//!
//! # Derivation (from eqs. 1–4, see [`crate::leg`])
//!
//! The tip in the leg base frame 0 is `(cosθ1·ρ, sinθ1·ρ, ζ)` with
//!
//! ```text
//! ρ = −a·cosθ2 + c·cos(θ2+θ3),   ζ = −a·sinθ2 + c·sin(θ2+θ3).
//! ```
//!
//! 1. **θ1.** `(x, y) = ρ·(cosθ1, sinθ1)`, so `|ρ| = r = √(x²+y²)`. We take
//!    `ρ = −r ≤ 0`, the leg standing *outward* from the body (at θ1 = 0 frame
//!    0's `x` points towards the body and the upper link at θ2 = 0 points
//!    away from it), which gives `θ1 = atan2(−y, −x) ∈ (−π, π]`, with θ1 = 0
//!    for a tip straight out from the hip. (The other root, `θ1 + π` with
//!    `ρ = +r`, folds the leg under the body and is not offered.) If
//!    `r ≈ 0` the target is on the θ1 axis and θ1 is undetermined:
//!    [`KinematicsError::SingularHip`].
//! 2. **θ3.** In the leg plane `(ρ, ζ)` the tip is the knee vector
//!    `−a·(cosθ2, sinθ2)` plus the lower link `c·(cos(θ2+θ3), sin(θ2+θ3))`,
//!    so by the law of cosines `D² = ρ² + ζ² = a² + c² − 2ac·cosθ3`, i.e.
//!    `cosθ3 = (a² + c² − D²)/(2ac)`, reachable iff `|a − c| ≤ D ≤ a + c`
//!    (else [`KinematicsError::Unreachable`]). `D` is the hip–tip distance
//!    `|p|`. The sign of `sinθ3` is the [`KneeBranch`].
//! 3. **θ2.** Expanding the sums, `(ρ, ζ) = Rot2(θ2)·(A, B)` with
//!    `A = c·cosθ3 − a`, `B = c·sinθ3`, hence
//!    `θ2 = atan2(A·ζ − B·ρ, A·ρ + B·ζ) ∈ (−π, π]`.
//!
//! Everything is verified by forward-kinematics round trips in the tests,
//! not by this algebra.

use nalgebra::Vector3;

use crate::error::KinematicsError;
use crate::hexapod::HexapodModel;
use crate::leg::LegGeometry;
use crate::leg_jacobian::LegTrig;

/// Relative tolerance of the θ1 singularity: the target is "on the θ1 axis"
/// when its distance from it is `≤ SINGULAR_TOLERANCE·(a + c)`.
pub const SINGULAR_TOLERANCE: f64 = 1e-9;

/// Relative slack of the reach test: targets up to `REACH_SLACK·(a + c)`
/// outside `[|a − c|, a + c]` are treated as on the boundary (rounding).
pub const REACH_SLACK: f64 = 1e-12;

/// Which of the two knee solutions to return.
///
/// With the leg standing outward (`ρ ≤ 0`, see the module docs), draw the
/// leg's vertical plane with the horizontal axis pointing away from the body
/// and the vertical axis up: [`KneeBranch::Up`] puts the knee on the
/// counter-clockwise side of the hip→tip line, which for a foot below and
/// outside the hip is *above* that line — the paper's posture (θ3 = 245°).
///
/// `Default` is [`KneeBranch::Up`], the paper's posture.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum KneeBranch {
    /// `sinθ3 ≤ 0`, `θ3 ∈ [π, 2π]`: knee up (the paper's posture, default).
    #[default]
    Up,
    /// `sinθ3 ≥ 0`, `θ3 ∈ [0, π]`: knee down.
    Down,
}

impl KneeBranch {
    /// The branch a knee angle θ3 belongs to (`sinθ3 ≤ 0` → [`Self::Up`]).
    pub fn of(theta3: f64) -> Self {
        if theta3.sin() <= 0.0 {
            Self::Up
        } else {
            Self::Down
        }
    }
}

/// Inverse kinematics of one leg: the joint angles `(θ1, θ2, θ3)` (rad)
/// placing the tip at `target`, given in the leg base frame 0 (eq. 1).
///
/// Returns `θ1 ∈ (−π, π]` (tip outward, `ρ ≤ 0`), `θ2 ∈ (−π, π]`, and θ3
/// in `[π, 2π]` ([`KneeBranch::Up`]) or `[0, π]` ([`KneeBranch::Down`]).
///
/// # Errors
/// [`KinematicsError::NonFinite`], [`KinematicsError::Unreachable`] (hip–tip
/// distance outside `[|a − c|, a + c]`), [`KinematicsError::SingularHip`]
/// (target on the θ1 axis).
#[inline]
pub fn leg_ik(
    geom: &LegGeometry,
    target: &Vector3<f64>,
    branch: KneeBranch,
) -> Result<[f64; 3], KinematicsError> {
    leg_ik_trig(geom, target, branch).map(|(theta, _)| theta)
}

/// [`leg_ik`] with the sines and cosines of the solution, as the solve
/// finds them (no `sin_cos`): `(c1, s1) = (x, y)/ρ`, `cos θ3` from the law
/// of cosines and `sin θ3` of the branch, `(c2, s2)` from
/// `(ρ, ζ) = Rot(θ2)·(A, B)` (`A = c·c3 − a`, `B = c·s3`), then the sum
/// formulas. Equal to [`LegTrig::new`]`(theta)` up to round-off; the
/// Jacobians and [`crate::hexapod::forward_trig`] take them.
///
/// # Errors
/// As [`leg_ik`].
#[inline]
pub fn leg_ik_trig(
    geom: &LegGeometry,
    target: &Vector3<f64>,
    branch: KneeBranch,
) -> Result<([f64; 3], LegTrig), KinematicsError> {
    let (x, y, z) = (target.x, target.y, target.z);
    if !(x.is_finite() && y.is_finite() && z.is_finite()) {
        return Err(KinematicsError::NonFinite);
    }
    let (a, c) = (geom.a, geom.c);
    let r2 = x * x + y * y;
    let d2 = r2 + z * z;
    let (min_reach, max_reach) = (geom.min_reach(), geom.max_reach());
    let slack = REACH_SLACK * max_reach;
    let distance = d2.sqrt();
    if distance > max_reach + slack || distance < min_reach - slack {
        return Err(KinematicsError::Unreachable {
            distance,
            min_reach,
            max_reach,
        });
    }
    let r = r2.sqrt();
    let tolerance = SINGULAR_TOLERANCE * max_reach;
    if r <= tolerance {
        return Err(KinematicsError::SingularHip {
            radial: r,
            tolerance,
        });
    }
    let theta1 = (-y).atan2(-x);
    let rho = -r;
    let cos3 = ((a * a + c * c - d2) / (2.0 * a * c)).clamp(-1.0, 1.0);
    let s = ((1.0 - cos3) * (1.0 + cos3)).sqrt();
    let (sin3, theta3) = match branch {
        KneeBranch::Up => (-s, std::f64::consts::TAU - s.atan2(cos3)),
        KneeBranch::Down => (s, s.atan2(cos3)),
    };
    let big_a = c * cos3 - a;
    let big_b = c * sin3;
    let theta2 = (big_a * z - big_b * rho).atan2(big_a * rho + big_b * z);
    let n = big_a * big_a + big_b * big_b;
    let c2 = (big_a * rho + big_b * z) / n;
    let s2 = (big_a * z - big_b * rho) / n;
    let trig = LegTrig {
        s1: y / rho,
        c1: x / rho,
        s2,
        c2,
        s23: s2 * cos3 + c2 * sin3,
        c23: c2 * cos3 - s2 * sin3,
    };
    Ok(([theta1, theta2, theta3], trig))
}

/// Inverse kinematics of leg `leg` (array index 0–5, i.e. leg number − 1)
/// for a tip target in **body** coordinates: the target is mapped to the
/// leg base frame 0 with `cA0i⁻¹` (eq. 5), then solved by [`leg_ik`].
///
/// # Errors
/// As [`leg_ik`].
///
/// # Panics
/// If `leg ≥ 6`.
#[inline]
pub fn leg_ik_body(
    model: &HexapodModel,
    leg: usize,
    target_body: &Vector3<f64>,
    branch: KneeBranch,
) -> Result<[f64; 3], KinematicsError> {
    let p0 = model.mount(leg).body_to_base(target_body);
    leg_ik(model.leg(), &p0, branch)
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{PI, TAU};

    fn angle_eq(a: f64, b: f64) -> bool {
        let d = (a - b).rem_euclid(TAU);
        d.min(TAU - d) < 1e-9
    }

    #[test]
    fn trig_of_the_solve_is_that_of_the_angles() {
        let g = LegGeometry::default();
        for th in [
            [0.0, 0.0, 245f64.to_radians()],
            [0.3, -0.2, 4.0],
            [-1.0, 0.5, 3.5],
            [2.0, 1.0, 1.2],
        ] {
            let (theta, t) = leg_ik_trig(&g, &g.tip(th), KneeBranch::of(th[2])).unwrap();
            let want = LegTrig::new(theta);
            for (i, (a, b)) in [
                (t.s1, want.s1),
                (t.c1, want.c1),
                (t.s2, want.s2),
                (t.c2, want.c2),
                (t.s23, want.s23),
                (t.c23, want.c23),
            ]
            .into_iter()
            .enumerate()
            {
                assert!((a - b).abs() < 1e-14, "{th:?}: entry {i}: {a} vs {b}");
            }
            assert_eq!(
                theta,
                leg_ik(&g, &g.tip(th), KneeBranch::of(th[2])).unwrap()
            );
        }
    }

    #[test]
    fn round_trips_the_paper_posture() {
        let g = LegGeometry::default();
        for th in [
            [0.0, 0.0, 245f64.to_radians()],
            [0.3, -0.2, 4.0],
            [-1.0, 0.5, 3.5],
        ] {
            let p = g.tip(th);
            let got = leg_ik(&g, &p, KneeBranch::of(th[2])).unwrap();
            for k in 0..3 {
                assert!(angle_eq(got[k], th[k]), "{got:?} vs {th:?}");
            }
        }
    }

    #[test]
    fn both_branches_reach() {
        let g = LegGeometry { a: 0.3, c: 0.2 };
        let p = Vector3::new(-0.25, 0.1, -0.2);
        let up = leg_ik(&g, &p, KneeBranch::Up).unwrap();
        let down = leg_ik(&g, &p, KneeBranch::Down).unwrap();
        assert!((g.tip(up) - p).norm() < 1e-12 && (g.tip(down) - p).norm() < 1e-12);
        assert!(up[2] >= PI && down[2] <= PI && up[0] == down[0]);
    }

    #[test]
    fn errors() {
        let g = LegGeometry::default();
        let e = leg_ik(&g, &Vector3::new(-0.7, 0.0, 0.0), KneeBranch::Up).unwrap_err();
        assert!(matches!(e, KinematicsError::Unreachable { .. }));
        let msg = e.to_string();
        assert!(
            msg.contains("0.700000") && msg.contains("[0.220000, 0.620000]"),
            "{msg}"
        );
        let e = leg_ik(&g, &Vector3::new(0.0, 0.0, -0.5), KneeBranch::Up).unwrap_err();
        assert!(matches!(e, KinematicsError::SingularHip { .. }), "{e}");
        let e = leg_ik(&g, &Vector3::new(f64::NAN, 0.0, -0.5), KneeBranch::Up).unwrap_err();
        assert_eq!(e, KinematicsError::NonFinite);
    }
}

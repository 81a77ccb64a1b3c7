//! The hexagonal central body and where the legs are mounted (paper eq. 5,
//! docs/reference.md).
//!
//! Legs are numbered 1–6 as in docs/reference.md; arrays in this crate are indexed by
//! `leg number − 1`. In body coordinates `y` is vertical (up), `−z` is
//! forward, and the hip of leg `i` is `(d·cosγi, 0, −d·sinγi)` with
//! `d = L·cos(π/6)`.

use nalgebra::{Matrix3, Vector3};

/// Number of legs of the hexapod.
pub const LEG_COUNT: usize = 6;

/// `γi` of each leg (degrees), indexed by `leg number − 1`: legs 1–6 are
/// front-left, front-right, middle-left, middle-right, rear-left, rear-right.
pub const GAMMA_DEG: [f64; LEG_COUNT] = [120.0, 60.0, 180.0, 0.0, 240.0, 300.0];

/// `d = L·cos(π/6)`: distance from the body centre to every hip, for a
/// hexagonal body of side `L` (m).
pub fn hip_distance(side: f64) -> f64 {
    side * (std::f64::consts::PI / 6.0).cos()
}

/// The fixed transform `cA0i(γi)` of one leg (eq. 5), with its sine and
/// cosine precomputed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LegMount {
    /// `γi` (rad).
    pub gamma: f64,
    /// `cos γi`.
    pub cos_gamma: f64,
    /// `sin γi`.
    pub sin_gamma: f64,
    /// `d` (m).
    pub d: f64,
    /// The hip (origin of the leg base frame 0) in body coordinates,
    /// `(d·cosγ, 0, −d·sinγ)` (m).
    pub hip: Vector3<f64>,
}

impl LegMount {
    /// The mount of a leg at angle `gamma` (rad) and hip distance `d` (m).
    ///
    /// `sinγ` and `cosγ` are snapped to the exact values 0, ±½, ±1 when
    /// within `1e-15` of them, so that the table's γ's (multiples of 60°)
    /// are exact: legs 3 and 4 then stay exactly in the body's `z = 0`
    /// plane, as the planar model (docs/reference.md) requires.
    pub fn new(gamma: f64, d: f64) -> Self {
        let (s, c) = gamma.sin_cos();
        let (s, c) = (snap(s), snap(c));
        Self {
            gamma,
            cos_gamma: c,
            sin_gamma: s,
            d,
            hip: Vector3::new(d * c, 0.0, -d * s),
        }
    }

    /// The mount of leg `number` (1–6) for a body of side `side`, or `None`
    /// if the number is out of range.
    pub fn for_leg(number: usize, side: f64) -> Option<Self> {
        let i = number.checked_sub(1)?;
        let g = GAMMA_DEG.get(i)?;
        Some(Self::new(g.to_radians(), hip_distance(side)))
    }

    /// The rotation block of `cA0i`: leg base frame 0 → body frame.
    ///
    /// ```text
    /// [ −cosγ  sinγ  0 ]
    /// [   0     0    1 ]
    /// [  sinγ  cosγ  0 ]
    /// ```
    pub fn rotation(&self) -> Matrix3<f64> {
        let (s, c) = (self.sin_gamma, self.cos_gamma);
        Matrix3::new(-c, s, 0.0, 0.0, 0.0, 1.0, s, c, 0.0)
    }

    /// A point of the leg base frame 0 in body coordinates (`cA0i·p`).
    #[inline]
    pub fn base_to_body(&self, p0: &Vector3<f64>) -> Vector3<f64> {
        let (s, c) = (self.sin_gamma, self.cos_gamma);
        Vector3::new(
            -c * p0.x + s * p0.y + self.hip.x,
            p0.z,
            s * p0.x + c * p0.y + self.hip.z,
        )
    }

    /// A body-frame point in the leg base frame 0 (`cA0i⁻¹·p`).
    #[inline]
    pub fn body_to_base(&self, p_body: &Vector3<f64>) -> Vector3<f64> {
        let (s, c) = (self.sin_gamma, self.cos_gamma);
        let v = p_body - self.hip;
        Vector3::new(-c * v.x + s * v.z, s * v.x + c * v.z, v.y)
    }
}

/// `v` snapped to the nearest of 0, ±½, ±1 if within `1e-15` of it.
fn snap(v: f64) -> f64 {
    for exact in [0.0, 0.5, -0.5, 1.0, -1.0] {
        if (v - exact).abs() <= 1e-15 {
            return exact;
        }
    }
    v
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dh::{body_to_leg_base, rotation_block, translation_block};

    #[test]
    fn mount_matches_eq5() {
        for n in 1..=6 {
            let m = LegMount::for_leg(n, 0.25).unwrap();
            let t = body_to_leg_base(m.gamma, m.d);
            assert!((rotation_block(&t) - m.rotation()).norm() < 1e-15);
            assert!((translation_block(&t) - m.hip).norm() < 1e-15);
            let p = Vector3::new(0.3, -0.2, 0.7);
            let pb = (t * p.push(1.0)).xyz();
            assert!((m.base_to_body(&p) - pb).norm() < 1e-15);
            assert!((m.body_to_base(&pb) - p).norm() < 1e-15);
        }
        assert!(LegMount::for_leg(0, 0.25).is_none());
        assert!(LegMount::for_leg(7, 0.25).is_none());
    }

    #[test]
    fn leg_places() {
        // Legs 1, 3, 5 on the left (body x < 0), 2, 4, 6 on the right;
        // 1, 2 in front (body z < 0), 5, 6 behind.
        let h = |n| LegMount::for_leg(n, 1.0).unwrap().hip;
        for n in [1, 3, 5] {
            assert!(h(n).x < 0.0);
        }
        for n in [2, 4, 6] {
            assert!(h(n).x > 0.0);
        }
        assert!(h(1).z < 0.0 && h(2).z < 0.0 && h(5).z > 0.0 && h(6).z > 0.0);
    }
}

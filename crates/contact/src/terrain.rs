//! Rigid terrain `y = ϱ(x)` with its slope, tangent and normal.

use serde::{Deserialize, Serialize};

/// A rigid planar terrain. `y = ϱ(x)` in the inertial frame (Y up).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub enum Terrain {
    /// No ground at all: every contact stays in ST1.
    None,
    /// Horizontal ground `y = height`.
    Flat {
        /// Ground height (m).
        height: f64,
    },
}

impl Default for Terrain {
    /// Flat ground at `y = 0`.
    fn default() -> Self {
        Terrain::Flat { height: 0.0 }
    }
}

impl Terrain {
    /// `true` when there is a ground to touch.
    pub fn exists(&self) -> bool {
        !matches!(self, Terrain::None)
    }

    /// `ϱ(x)` (m). `-∞` without ground.
    #[inline]
    pub fn height(&self, x: f64) -> f64 {
        let _ = x;
        match self {
            Terrain::None => f64::NEG_INFINITY,
            Terrain::Flat { height } => *height,
        }
    }

    /// `ϱ′(x)`.
    #[inline]
    pub fn slope(&self, x: f64) -> f64 {
        let _ = x;
        match self {
            Terrain::None | Terrain::Flat { .. } => 0.0,
        }
    }

    /// Unit tangent `(1, ϱ′)/√(1+ϱ′²)` and unit normal `(−ϱ′, 1)/√(1+ϱ′²)`
    /// at `x` (SPEC §6).
    #[inline]
    pub fn frame(&self, x: f64) -> ([f64; 2], [f64; 2]) {
        let s = self.slope(x);
        let k = 1.0 / (1.0 + s * s).sqrt();
        ([k, s * k], [-s * k, k])
    }

    /// Height of `p` above the terrain, measured vertically: `p.y − ϱ(p.x)`.
    #[inline]
    pub fn clearance(&self, p: [f64; 2]) -> f64 {
        p[1] - self.height(p[0])
    }

    /// Where the straight path from `p0` to `p1` first crosses the terrain:
    /// the root of `g(s) = clearance(p0 + s·(p1 − p0))` on `[0, 1]`, found by
    /// safeguarded secant/bisection. When `p0` is already on or below the
    /// terrain the vertical projection of `p0` is returned.
    pub fn crossing(&self, p0: [f64; 2], p1: [f64; 2]) -> [f64; 2] {
        let at = |s: f64| [p0[0] + s * (p1[0] - p0[0]), p0[1] + s * (p1[1] - p0[1])];
        let g0 = self.clearance(p0);
        if !g0.is_finite() || g0 <= 0.0 {
            return [p0[0], self.height(p0[0])];
        }
        let g1 = self.clearance(p1);
        if g1 >= 0.0 {
            return [p1[0], self.height(p1[0])];
        }
        let (mut lo, mut hi, mut glo, mut ghi) = (0.0, 1.0, g0, g1);
        for _ in 0..100 {
            // Secant guess, kept inside the bracket; bisection when it stalls.
            let mut s = lo + glo * (hi - lo) / (glo - ghi);
            if !(s > lo && s < hi) || (hi - lo) < 1e-3 {
                s = 0.5 * (lo + hi);
            }
            let g = self.clearance(at(s));
            if g.abs() < 1e-14 || hi - lo < 1e-15 {
                lo = s;
                break;
            }
            if g > 0.0 {
                lo = s;
                glo = g;
            } else {
                hi = s;
                ghi = g;
            }
        }
        let p = at(lo);
        [p[0], self.height(p[0])]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_frame_is_axis_aligned() {
        let t = Terrain::Flat { height: 0.1 };
        assert_eq!(t.frame(3.0), ([1.0, 0.0], [0.0, 1.0]));
        assert_eq!(t.clearance([0.0, 0.3]), 0.3 - 0.1);
    }

    #[test]
    fn crossing_of_flat_ground_is_exact_interpolation() {
        let t = Terrain::Flat { height: 0.0 };
        let c = t.crossing([0.0, 0.1], [0.4, -0.3]);
        assert!((c[0] - 0.1).abs() < 1e-12 && c[1] == 0.0, "{c:?}");
    }

    #[test]
    fn no_ground_never_touches() {
        assert!(Terrain::None.clearance([0.0, -1e9]) > 0.0);
        assert!(!Terrain::None.exists());
    }
}

//! Rigid terrain `y = ϱ(x)` with its slope, tangent and normal.

use fbd_kinematics::num::Num;
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
    /// Inclined plane `y = height + slope·x` (build it from an angle with
    /// [`Terrain::slope_deg`]).
    Slope {
        /// `tan` of the inclination (positive: rising towards +X).
        slope: f64,
        /// Height at `x = 0` (m).
        height: f64,
    },
    /// Piecewise-linear profile through `points` (`[x, y]`, x strictly
    /// increasing, at least 2), flat beyond the ends.
    Profile {
        /// The vertices `[x, y]` (m).
        points: Vec<[f64; 2]>,
    },
    /// `y = height + amplitude·sin(2π x/wavelength + phase)`.
    Sine {
        /// Amplitude (m).
        amplitude: f64,
        /// Wavelength (m), > 0.
        wavelength: f64,
        /// Phase (rad).
        phase: f64,
        /// Mean height (m).
        height: f64,
    },
    /// A staircase `y = height + step_height·floor(x/step_width)`. The
    /// discontinuous risers at `x = n·step_width` are smoothed into linear
    /// ramps of width [`STEP_RAMP`] centred on them, so that the slope the
    /// FBD solve needs stays finite (`step_height/STEP_RAMP`).
    Steps {
        /// Rise of each step (m, negative for a descending staircase).
        step_height: f64,
        /// Run of each step (m), > 0.
        step_width: f64,
        /// Height of the step containing `x = 0` (m).
        height: f64,
    },
}

/// Width (m) of the linear ramp that replaces each riser of
/// [`Terrain::Steps`] (capped at half the step width).
pub const STEP_RAMP: f64 = 1e-3;

/// A terrain parameter that makes no sense: the configuration key (under
/// `[terrain]`) and what is wrong with it.
#[derive(Clone, Debug, PartialEq)]
pub struct TerrainIssue {
    /// Key under `[terrain]`, e.g. `wavelength`.
    pub key: &'static str,
    /// What is wrong.
    pub what: &'static str,
    /// The offending value.
    pub got: String,
    /// What was expected.
    pub expected: &'static str,
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

    /// An inclined plane of `angle_deg` degrees (positive: rising towards
    /// +X) through `(0, height)`.
    pub fn slope_deg(angle_deg: f64, height: f64) -> Self {
        Terrain::Slope {
            slope: angle_deg.to_radians().tan(),
            height,
        }
    }

    /// Checks the parameters: finite, `wavelength > 0`, `step_width > 0`,
    /// profile x strictly increasing with at least 2 points.
    pub fn validate(&self) -> Result<(), TerrainIssue> {
        let bad = |key, what, got: String, expected| {
            Err(TerrainIssue {
                key,
                what,
                got,
                expected,
            })
        };
        let finite = |key, v: f64| {
            if v.is_finite() {
                Ok(())
            } else {
                bad(key, "must be finite", v.to_string(), "a finite value")
            }
        };
        match self {
            Terrain::None => Ok(()),
            Terrain::Flat { height } => finite("height", *height),
            Terrain::Slope { slope, height } => {
                finite("angle_deg", *slope)?;
                finite("height", *height)
            }
            Terrain::Profile { points } => {
                if points.len() < 2 {
                    return bad(
                        "points",
                        "needs at least 2 points",
                        format!("{} points", points.len()),
                        "at least 2 [x, y] points",
                    );
                }
                for (i, p) in points.iter().enumerate() {
                    if !(p[0].is_finite() && p[1].is_finite()) {
                        return bad(
                            "points",
                            "must be finite",
                            format!("point {i} = {p:?}"),
                            "finite [x, y] points",
                        );
                    }
                    if i > 0 && p[0] <= points[i - 1][0] {
                        return bad(
                            "points",
                            "x must be strictly increasing",
                            format!(
                                "x = {} after {} (point {i})",
                                Num(p[0]),
                                Num(points[i - 1][0])
                            ),
                            "strictly increasing x",
                        );
                    }
                }
                Ok(())
            }
            Terrain::Sine {
                amplitude,
                wavelength,
                phase,
                height,
            } => {
                finite("amplitude", *amplitude)?;
                if !(wavelength.is_finite() && *wavelength > 0.0) {
                    return bad(
                        "wavelength",
                        "must be positive and finite",
                        Num(*wavelength).to_string(),
                        "a finite value > 0",
                    );
                }
                finite("phase_deg", *phase)?;
                finite("height", *height)
            }
            Terrain::Steps {
                step_height,
                step_width,
                height,
            } => {
                finite("step_height", *step_height)?;
                if !(step_width.is_finite() && *step_width > 0.0) {
                    return bad(
                        "step_width",
                        "must be positive and finite",
                        Num(*step_width).to_string(),
                        "a finite value > 0",
                    );
                }
                finite("height", *height)
            }
        }
    }

    /// `ϱ(x)` (m). `-∞` without ground.
    #[inline]
    pub fn height(&self, x: f64) -> f64 {
        match self {
            Terrain::None => f64::NEG_INFINITY,
            Terrain::Flat { height } => *height,
            Terrain::Slope { slope, height } => height + slope * x,
            Terrain::Profile { points } => {
                let (i, last) = (profile_segment(points, x), points.len() - 1);
                if x <= points[0][0] {
                    points[0][1]
                } else if x >= points[last][0] {
                    points[last][1]
                } else {
                    let (a, b) = (points[i], points[i + 1]);
                    a[1] + (b[1] - a[1]) * (x - a[0]) / (b[0] - a[0])
                }
            }
            Terrain::Sine {
                amplitude,
                wavelength,
                phase,
                height,
            } => height + amplitude * (std::f64::consts::TAU * x / wavelength + phase).sin(),
            Terrain::Steps {
                step_height,
                step_width,
                height,
            } => {
                let (n, d, ramp) = steps_position(x, *step_width);
                if d.abs() < 0.5 * ramp {
                    height + step_height * (n - 0.5 + d / ramp)
                } else if d < 0.0 {
                    height + step_height * (n - 1.0)
                } else {
                    height + step_height * n
                }
            }
        }
    }

    /// The constant slope `dϱ/ds` of a plane (none, flat or slope), `None`
    /// for the other kinds.
    pub fn plane_slope(&self) -> Option<f64> {
        match self {
            Terrain::None | Terrain::Flat { .. } => Some(0.0),
            Terrain::Slope { slope, .. } => Some(*slope),
            _ => None,
        }
    }

    /// `ϱ′(x)` (0 without ground; at a profile vertex, the slope of the
    /// segment to its right).
    #[inline]
    pub fn slope(&self, x: f64) -> f64 {
        match self {
            Terrain::None | Terrain::Flat { .. } => 0.0,
            Terrain::Slope { slope, .. } => *slope,
            Terrain::Profile { points } => {
                if x < points[0][0] || x >= points[points.len() - 1][0] {
                    0.0
                } else {
                    let i = profile_segment(points, x);
                    let (a, b) = (points[i], points[i + 1]);
                    (b[1] - a[1]) / (b[0] - a[0])
                }
            }
            Terrain::Sine {
                amplitude,
                wavelength,
                phase,
                ..
            } => {
                let w = std::f64::consts::TAU / wavelength;
                amplitude * w * (w * x + phase).cos()
            }
            Terrain::Steps {
                step_height,
                step_width,
                ..
            } => {
                let (_, d, ramp) = steps_position(x, *step_width);
                if d.abs() < 0.5 * ramp {
                    step_height / ramp
                } else {
                    0.0
                }
            }
        }
    }

    /// Unit tangent `(1, ϱ′)/√(1+ϱ′²)` and unit normal `(−ϱ′, 1)/√(1+ϱ′²)`
    /// at `x` (docs/reference.md).
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

    /// The point of the terrain at straight-line distance `dist` from
    /// `from` (a point on the terrain), on the side `side` (±1 along x): the
    /// root of `|(x, ϱ(x)) − from| = dist` between `from.x` and
    /// `from.x + side·dist`, by bisection. Two points of a rigid body that
    /// both rest on the terrain are this far apart.
    pub fn point_at_distance(&self, from: [f64; 2], dist: f64, side: f64) -> [f64; 2] {
        let gap = |x: f64| (x - from[0]).hypot(self.height(x) - from[1]) - dist;
        let (mut lo, mut hi) = (from[0], from[0] + side.signum() * dist);
        if gap(hi) < 0.0 {
            return [hi, self.height(hi)];
        }
        for _ in 0..100 {
            let mid = 0.5 * (lo + hi);
            if gap(mid) < 0.0 {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let x = 0.5 * (lo + hi);
        [x, self.height(x)]
    }
}

/// Index `i` of the profile segment `[points[i], points[i+1]]` holding `x`
/// (clamped to the first/last segment).
#[inline]
fn profile_segment(points: &[[f64; 2]], x: f64) -> usize {
    let n = points.partition_point(|p| p[0] <= x);
    n.clamp(1, points.len() - 1) - 1
}

/// For a staircase: the index `n` of the nearest riser `x = n·w`, the
/// offset `x − n·w` from it and the ramp width.
#[inline]
fn steps_position(x: f64, w: f64) -> (f64, f64, f64) {
    let n = (x / w).round();
    (n, x - n * w, STEP_RAMP.min(0.5 * w))
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
    fn point_at_distance_lies_on_the_terrain_at_that_distance() {
        for t in [
            Terrain::Flat { height: 0.1 },
            Terrain::slope_deg(10.0, 0.0),
            Terrain::Sine {
                amplitude: 0.03,
                wavelength: 0.37,
                phase: 0.4,
                height: 0.0,
            },
        ] {
            let from = [0.2, t.height(0.2)];
            for side in [1.0, -1.0] {
                let p = t.point_at_distance(from, 0.43, side);
                assert!(t.clearance(p).abs() < 1e-12, "{t:?}");
                let d = (p[0] - from[0]).hypot(p[1] - from[1]);
                assert!((d - 0.43).abs() < 1e-12, "{t:?}: distance {d}");
                assert!((p[0] - from[0]) * side > 0.0);
            }
        }
    }

    #[test]
    fn no_ground_never_touches() {
        assert!(Terrain::None.clearance([0.0, -1e9]) > 0.0);
        assert!(!Terrain::None.exists());
    }

    /// `slope(x)` against a central difference of `height(x)`.
    fn check_slope(t: &Terrain, xs: &[f64]) {
        for &x in xs {
            let h = 1e-7;
            let fd = (t.height(x + h) - t.height(x - h)) / (2.0 * h);
            assert!(
                (fd - t.slope(x)).abs() < 1e-6 * (1.0 + fd.abs()),
                "{t:?} at x = {x}: slope {} vs fd {fd}",
                t.slope(x)
            );
        }
    }

    #[test]
    fn slope_is_a_plane() {
        let t = Terrain::slope_deg(10.0, 0.05);
        assert!((t.height(2.0) - (0.05 + 2.0 * 10f64.to_radians().tan())).abs() < 1e-15);
        let (tg, n) = t.frame(-1.0);
        let a = 10f64.to_radians();
        assert!((tg[0] - a.cos()).abs() < 1e-15 && (tg[1] - a.sin()).abs() < 1e-15);
        assert!((n[0] + a.sin()).abs() < 1e-15 && (n[1] - a.cos()).abs() < 1e-15);
        check_slope(&t, &[-3.0, 0.0, 0.7]);
        assert!(t.validate().is_ok());
    }

    #[test]
    fn profile_interpolates_and_is_flat_beyond_the_ends() {
        let t = Terrain::Profile {
            points: vec![[0.0, 0.0], [1.0, 0.5], [3.0, 0.1]],
        };
        assert_eq!(t.height(-5.0), 0.0);
        assert_eq!(t.height(10.0), 0.1);
        assert!((t.height(0.5) - 0.25).abs() < 1e-15);
        assert!((t.height(2.0) - 0.3).abs() < 1e-15);
        assert_eq!(t.slope(-1.0), 0.0);
        assert_eq!(t.slope(0.5), 0.5);
        assert_eq!(t.slope(1.0), -0.2);
        assert_eq!(t.slope(3.5), 0.0);
        check_slope(&t, &[-1.0, 0.3, 0.9, 1.5, 2.9, 4.0]);
        let c = t.crossing([0.5, 1.0], [0.5, -1.0]);
        assert!((c[1] - 0.25).abs() < 1e-12, "{c:?}");
    }

    #[test]
    fn sine_height_and_slope() {
        let t = Terrain::Sine {
            amplitude: 0.02,
            wavelength: 0.5,
            phase: 0.3,
            height: 0.1,
        };
        assert!((t.height(0.0) - (0.1 + 0.02 * 0.3f64.sin())).abs() < 1e-15);
        assert!((t.height(0.5) - t.height(0.0)).abs() < 1e-15);
        check_slope(&t, &[-0.7, 0.0, 0.13, 0.4, 2.2]);
        let c = t.crossing([0.1, 0.5], [0.2, -0.5]);
        assert!(t.clearance(c).abs() < 1e-12 && t.clearance([c[0], c[1] + 1e-9]) > 0.0);
    }

    #[test]
    fn steps_are_floor_with_smoothed_risers() {
        let t = Terrain::Steps {
            step_height: 0.05,
            step_width: 0.3,
            height: 0.01,
        };
        assert!((t.height(0.1) - 0.01).abs() < 1e-15);
        assert!((t.height(0.4) - 0.06).abs() < 1e-15);
        assert!((t.height(-0.1) - (0.01 - 0.05)).abs() < 1e-15);
        assert_eq!(t.slope(0.45), 0.0);
        // The riser at x = 0.3 is a ramp of width STEP_RAMP.
        assert!((t.height(0.3) - 0.035).abs() < 1e-12);
        assert!((t.slope(0.3) - 0.05 / STEP_RAMP).abs() < 1e-9);
        assert!((t.height(0.3 + 0.5 * STEP_RAMP) - 0.06).abs() < 1e-12);
        check_slope(
            &t,
            &[0.1, 0.3, 0.3 + 0.3 * STEP_RAMP, 0.6 - 0.2 * STEP_RAMP, -0.2],
        );
    }

    #[test]
    fn validation_names_the_key() {
        let e = Terrain::Sine {
            amplitude: 0.1,
            wavelength: 0.0,
            phase: 0.0,
            height: 0.0,
        }
        .validate()
        .unwrap_err();
        assert_eq!(e.key, "wavelength");
        let e = Terrain::Steps {
            step_height: 0.1,
            step_width: -1.0,
            height: 0.0,
        }
        .validate()
        .unwrap_err();
        assert_eq!(e.key, "step_width");
        let e = Terrain::Profile {
            points: vec![[0.0, 0.0]],
        }
        .validate()
        .unwrap_err();
        assert_eq!(e.key, "points");
        let e = Terrain::Profile {
            points: vec![[0.0, 0.0], [0.0, 1.0]],
        }
        .validate()
        .unwrap_err();
        assert!(e.what.contains("strictly increasing"), "{e:?}");
        let e = Terrain::Flat { height: f64::NAN }.validate().unwrap_err();
        assert_eq!(e.key, "height");
    }
}

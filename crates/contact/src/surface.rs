//! The planar terrains extended to a surface `y = ϱ(x, z)` for the 3D
//! hexapod.
//!
//! Every planar [`Terrain`] (flat, slope, profile, sine, steps) becomes a
//! cylindrical surface: its profile `ϱ(s)` is laid along a horizontal
//! direction `u = (cos ψ, 0, −sin ψ)` (ψ measured from +X towards −Z, the
//! robot's forward direction at zero yaw) and extruded along the
//! perpendicular horizontal direction:
//!
//! ```text
//! ϱ(x, z) = ϱ_planar(s),   s = x·cos ψ − z·sin ψ
//! ∇ϱ = ϱ′(s)·(cos ψ, −sin ψ)          (∂/∂x, ∂/∂z)
//! H  = ϱ″(s)·(cos ψ, −sin ψ)ᵀ(cos ψ, −sin ψ)
//! ```
//!
//! With ψ = 0 (the default) `ϱ(x, z) = ϱ_planar(x)`: the planar model's
//! terrain, unchanged in every X–Y section. Every kind is covered; a fully
//! two-dimensional height map is not (no planar kind needs one).
//! `ϱ″` is zero for flat, slope, profile and steps (they are piecewise
//! linear; the kinks are a set of measure zero) and analytic for sine.
//!
//! [`Surface::mean_height`] is the surface without the risers of `steps`
//! (the staircase's mean line): a body that follows it climbs smoothly.

use crate::terrain::Terrain;

/// A terrain surface `y = ϱ(x, z)` (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// The planar profile `ϱ(s)`.
    pub terrain: Terrain,
    /// `cos ψ` of the profile direction.
    cos: f64,
    /// `sin ψ` of the profile direction.
    sin: f64,
}

impl Default for Surface {
    /// Flat ground at `y = 0`, profile along +X.
    fn default() -> Self {
        Self::new(Terrain::default(), 0.0)
    }
}

impl Surface {
    /// The profile `terrain` laid along the horizontal direction at angle
    /// `direction` (rad) from +X towards −Z (0: along +X, as the planar
    /// model; π/2: along −Z, the forward direction of a robot at zero yaw).
    pub fn new(terrain: Terrain, direction: f64) -> Self {
        let (sin, cos) = direction.sin_cos();
        Self { terrain, cos, sin }
    }

    /// The profile coordinate `s = x·cos ψ − z·sin ψ` (m).
    #[inline]
    pub fn along(&self, x: f64, z: f64) -> f64 {
        x * self.cos - z * self.sin
    }

    /// `true` when there is a ground.
    pub fn exists(&self) -> bool {
        self.terrain.exists()
    }

    /// `ϱ(x, z)` (m); `−∞` without ground.
    #[inline]
    pub fn height(&self, x: f64, z: f64) -> f64 {
        self.terrain.height(self.along(x, z))
    }

    /// `(∂ϱ/∂x, ∂ϱ/∂z)`.
    #[inline]
    pub fn gradient(&self, x: f64, z: f64) -> [f64; 2] {
        let d = self.terrain.slope(self.along(x, z));
        [d * self.cos, -d * self.sin]
    }

    /// The unit upward normal `(−ϱx, 1, −ϱz)/√(1 + ϱx² + ϱz²)`.
    pub fn normal(&self, x: f64, z: f64) -> [f64; 3] {
        let [gx, gz] = self.gradient(x, z);
        let k = 1.0 / (1.0 + gx * gx + gz * gz).sqrt();
        [-gx * k, k, -gz * k]
    }

    /// The height, gradient and second derivative along the profile of the
    /// smooth surface a walking body follows: `ϱ` itself for flat, slope,
    /// profile and sine, and for `steps` the staircase's mean line
    /// `height + step_height·(s/step_width − ½)` (the risers removed).
    /// Returns `(ϱ, [ϱx, ϱz], ϱ″)` with `H = ϱ″·u·uᵀ`.
    pub fn mean_height(&self, x: f64, z: f64) -> (f64, [f64; 2], f64) {
        let s = self.along(x, z);
        let (h, d, dd) = match &self.terrain {
            Terrain::Steps {
                step_height,
                step_width,
                height,
            } => {
                let k = step_height / step_width;
                (height + step_height * (s / step_width - 0.5), k, 0.0)
            }
            Terrain::Sine {
                amplitude,
                wavelength,
                phase,
                height,
            } => {
                let w = std::f64::consts::TAU / wavelength;
                let (sn, cs) = (w * s + phase).sin_cos();
                (
                    height + amplitude * sn,
                    amplitude * w * cs,
                    -amplitude * w * w * sn,
                )
            }
            Terrain::None => (0.0, 0.0, 0.0),
            t => (t.height(s), t.slope(s), 0.0),
        };
        (h, [d * self.cos, -d * self.sin], dd)
    }

    /// The unit profile direction `(cos ψ, −sin ψ)` in `(x, z)`.
    pub fn direction(&self) -> [f64; 2] {
        [self.cos, -self.sin]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_direction_is_the_planar_terrain() {
        let t = Terrain::Sine {
            amplitude: 0.1,
            wavelength: 2.0,
            phase: 0.3,
            height: 0.2,
        };
        let s = Surface::new(t.clone(), 0.0);
        for (x, z) in [(0.3, -1.0), (-2.0, 5.0)] {
            assert_eq!(s.height(x, z), t.height(x));
            assert_eq!(s.gradient(x, z), [t.slope(x), 0.0]);
        }
    }

    #[test]
    fn gradient_and_curvature_match_differences() {
        let t = Terrain::Sine {
            amplitude: 0.1,
            wavelength: 2.0,
            phase: 0.3,
            height: 0.2,
        };
        let s = Surface::new(t, 0.7);
        let (x, z, h) = (0.4, -0.3, 1e-5);
        let [gx, gz] = s.gradient(x, z);
        let fx = (s.height(x + h, z) - s.height(x - h, z)) / (2.0 * h);
        let fz = (s.height(x, z + h) - s.height(x, z - h)) / (2.0 * h);
        assert!((gx - fx).abs() < 1e-8 && (gz - fz).abs() < 1e-8);
        let (m, g, dd) = s.mean_height(x, z);
        assert_eq!(m, s.height(x, z));
        assert_eq!(g, [gx, gz]);
        let [ux, uz] = s.direction();
        let hh = 1e-4;
        let second = (s.height(x + hh * ux, z + hh * uz) - 2.0 * m
            + s.height(x - hh * ux, z - hh * uz))
            / (hh * hh);
        assert!((dd - second).abs() < 1e-5, "{dd} vs {second}");
        let n = s.normal(x, z);
        assert!((n[0] * n[0] + n[1] * n[1] + n[2] * n[2] - 1.0).abs() < 1e-15);
    }

    #[test]
    fn slope_along_forward_rises_ahead() {
        let s = Surface::new(Terrain::slope_deg(10.0, 0.0), std::f64::consts::FRAC_PI_2);
        assert!((s.height(0.0, -1.0) - 10f64.to_radians().tan()).abs() < 1e-12);
        assert!(s.height(1.0, 0.0).abs() < 1e-12);
        let st = Surface::new(
            Terrain::Steps {
                step_height: 0.1,
                step_width: 0.5,
                height: 0.0,
            },
            0.0,
        );
        // The mean line passes through the middle of every riser.
        assert!((st.mean_height(0.5, 0.0).0 - 0.05).abs() < 1e-12);
    }
}

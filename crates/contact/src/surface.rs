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
//! terrain, unchanged in every X–Y section. Every planar kind is covered; a
//! fully two-dimensional surface is a height map (below).
//! `ϱ″` is zero for flat, slope, profile and steps (they are piecewise
//! linear; the kinks are a set of measure zero) and analytic for sine.
//!
//! [`Surface::mean_height`] is the surface without the risers of `steps`
//! (the staircase's mean line): a body that follows it climbs smoothly.
//!
//! **Height maps.** A fully two-dimensional surface is a [`HeightGrid`]
//! ([`Surface::from_grid`]: a heightfield file or a generated terrain),
//! interpolated with a continuous normal and analytic gradient and Hessian
//! (see [`crate::grid`]). Its profile direction is +X (ψ = 0: the contact
//! frame's first tangent lies in the X–Y plane). Its
//! [`Surface::mean_height`] is the grid smoothed over [`MEAN_RADIUS`].
//!
//! **Friction patches.** A surface carries its [`FrictionPatch`]es:
//! [`Surface::friction_at`] is the friction at a point of the ground.

use std::sync::Arc;

use crate::grid::HeightGrid;
use crate::mode::Friction;
use crate::patch::{FrictionPatch, friction_at};
use crate::terrain::Terrain;

/// The smoothing radius (m) of a height map's mean surface, the ground a
/// walking body follows (about the size of a foot's reach, so that one
/// stair or bump under one foot does not shake the body).
pub const MEAN_RADIUS: f64 = 0.4;

/// A height map and its smoothed mean surface.
#[derive(Clone, Debug, PartialEq)]
struct Map {
    grid: HeightGrid,
    mean: HeightGrid,
}

/// A terrain surface `y = ϱ(x, z)` (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct Surface {
    /// The planar profile `ϱ(s)` (unused by a height map).
    pub terrain: Terrain,
    /// `cos ψ` of the profile direction.
    cos: f64,
    /// `sin ψ` of the profile direction.
    sin: f64,
    /// A height map replacing the extruded profile.
    map: Option<Arc<Map>>,
    /// Friction patches, the last listed winning.
    patches: Arc<[FrictionPatch]>,
    /// A plane's contact frame (flat or slope, no height map), the same
    /// at every point, with the slope it was made for
    /// ([`Self::plane_frame`]).
    plane: Option<(f64, [[f64; 3]; 3])>,
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
        let mut surface = Self {
            terrain,
            cos,
            sin,
            map: None,
            patches: Arc::from(Vec::new()),
            plane: None,
        };
        if let Some(slope) = surface.terrain.plane_slope() {
            surface.plane = Some((slope, crate::spatial::frame_at(&surface, 0.0, 0.0)));
        }
        surface
    }

    /// The contact frame of a plane, where the surface is one (flat or a
    /// slope, no height map; the same frame at every point, made once),
    /// for [`crate::spatial::frame`].
    pub(crate) fn plane_frame(&self) -> Option<[[f64; 3]; 3]> {
        match self.plane {
            Some((slope, frame))
                if self.map.is_none() && self.terrain.plane_slope() == Some(slope) =>
            {
                Some(frame)
            }
            _ => None,
        }
    }

    /// The height map `grid` (profile direction +X).
    pub fn from_grid(grid: HeightGrid) -> Self {
        let mean = grid.smoothed(MEAN_RADIUS);
        Self {
            map: Some(Arc::new(Map { grid, mean })),
            plane: None,
            ..Self::new(Terrain::Flat { height: 0.0 }, 0.0)
        }
    }

    /// The surface with friction `patches` (the last listed wins).
    pub fn with_patches(mut self, patches: Vec<FrictionPatch>) -> Self {
        self.patches = Arc::from(patches);
        self
    }

    /// The height map, if the surface is one.
    pub fn grid(&self) -> Option<&HeightGrid> {
        self.map.as_ref().map(|m| &m.grid)
    }

    /// The friction patches.
    pub fn patches(&self) -> &[FrictionPatch] {
        &self.patches
    }

    /// The friction at `(x, z)`: the last patch holding the point, else
    /// `base` (the ground's own).
    #[inline]
    pub fn friction_at(&self, base: &Friction, x: f64, z: f64) -> Friction {
        friction_at(&self.patches, base, x, z)
    }

    /// The Hessian `[ϱxx, ϱxz, ϱzz]` (zero on the piecewise-linear
    /// profile kinds, as [`Surface::mean_height`] says).
    pub fn hessian(&self, x: f64, z: f64) -> [f64; 3] {
        if let Some(m) = &self.map {
            return m.grid.eval(x, z).2;
        }
        let dd = match &self.terrain {
            Terrain::Sine { .. } => self.mean_height(x, z).2,
            _ => 0.0,
        };
        let [ux, uz] = self.direction();
        [dd * ux * ux, dd * ux * uz, dd * uz * uz]
    }

    /// `vᵀ·H̄·v` of the mean surface ([`Surface::mean_height`]) for the
    /// horizontal velocity `v = (vx, vz)`: the centripetal part of a
    /// terrain-following body's vertical acceleration.
    pub fn mean_curvature(&self, x: f64, z: f64, v: [f64; 2]) -> f64 {
        if let Some(m) = &self.map {
            let [hxx, hxz, hzz] = m.mean.eval(x, z).2;
            return hxx * v[0] * v[0] + 2.0 * hxz * v[0] * v[1] + hzz * v[1] * v[1];
        }
        let dd = self.mean_height(x, z).2;
        let [ux, uz] = self.direction();
        let vu = ux * v[0] + uz * v[1];
        dd * vu * vu
    }

    /// The profile coordinate `s = x·cos ψ − z·sin ψ` (m).
    #[inline]
    pub fn along(&self, x: f64, z: f64) -> f64 {
        x * self.cos - z * self.sin
    }

    /// `true` when there is a ground.
    pub fn exists(&self) -> bool {
        self.map.is_some() || self.terrain.exists()
    }

    /// `ϱ(x, z)` (m); `−∞` without ground.
    #[inline]
    pub fn height(&self, x: f64, z: f64) -> f64 {
        if let Some(m) = &self.map {
            return m.grid.height(x, z);
        }
        self.terrain.height(self.along(x, z))
    }

    /// `(∂ϱ/∂x, ∂ϱ/∂z)`.
    #[inline]
    pub fn gradient(&self, x: f64, z: f64) -> [f64; 2] {
        if let Some(m) = &self.map {
            return m.grid.eval(x, z).1;
        }
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
    /// Returns `(ϱ, [ϱx, ϱz], ϱ″)` with `H = ϱ″·u·uᵀ`. For a height map:
    /// the grid smoothed over [`MEAN_RADIUS`], `ϱ″` its `ϱxx`
    /// ([`Surface::mean_curvature`] has the whole Hessian).
    pub fn mean_height(&self, x: f64, z: f64) -> (f64, [f64; 2], f64) {
        if let Some(m) = &self.map {
            let (h, g, [hxx, _, _]) = m.mean.eval(x, z);
            return (h, g, hxx);
        }
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

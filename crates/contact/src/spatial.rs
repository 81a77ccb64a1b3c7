//! The ST1/ST2/ST3 machine of [`crate::mode`] on a surface `y = ϱ(x, z)`
//! (the 3D hexapod): the same rules, with the tangential force and the slip
//! as vectors of the tangent plane.
//!
//! The contact frame at a point is `(t1, n, t2)`: `n` the unit upward
//! normal, `t1` the unit tangent along the profile direction `u` of the
//! [`Surface`] (for ψ = 0: `(1, ϱ′, 0)/√(1+ϱ′²)`, the planar tangent) and
//! `t2 = t1 × n` (for ψ = 0: `+Z`). Forces are `(Ft1, N, Ft2)` in it.
//!
//! | state | equations (3 per point) |
//! |---|---|
//! | ST1 | `F = 0` |
//! | ST2 | the point held at its anchor `a` |
//! | ST3 | the point on the surface, `Ft = −μD·N·û` |
//!
//! **Slip direction.** Friction opposes the point's slip over the step,
//! `s = (p[k+1] − p[k])·(t1, t2)`: the equations take `Ft = −μD·N·ŝ`
//! with `ŝ = s/|s|` an implicit function of the step's unknowns (see
//! `fbd_dynamics::spatial::slip_direction`), so a slide may turn
//! freely. The state keeps a reference direction `û`: on ST2 → ST3 the
//! opposite of the tangential force sticking needed (`û = −Ft/|Ft|`:
//! friction keeps the force's direction, as in the plane), afterwards the
//! last accepted step's slip direction. ST3 → ST2 when `s·û ≤
//! v_stop·Δt`: the slide stopped (slower than `v_stop` = the larger of
//! `speed_tol` and [`STOP_SPEED`], 1e-9 m/s, below which the friction
//! direction is regularised) or turned back (by more than 90° in one
//! step) — the planar rule, the sliding velocity reversing or vanishing;
//! the point is anchored under `p[k]`. (When Newton cannot solve a
//! slide's implicit direction, `fbd_sim::spatial::step` fixes it at `û`
//! and moves it onto the slip found until the two agree: no written slide
//! keeps an earlier step's direction.)
//!
//! With motion in the X–Y plane every vector has a zero `t2` component, û
//! is `(±1, 0)` and each rule is the planar one: the planar engine and this
//! machine make the same switches (the planar consistency test checks it).

use crate::mode::{ContactParams, Friction, StateCode};

/// Slip speed (m/s) below which a 3D slide has stopped: 1e-9 m/s, the
/// planar `speed_tol` (the dynamics regularise the friction direction
/// below it).
pub const STOP_SPEED: f64 = 1e-9;
use crate::surface::Surface;

/// The state of one contact point on a surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SpatialState {
    /// ST1: no contact.
    Free,
    /// ST2: held at `anchor` (a point of the surface).
    Stick {
        /// The contact point (m).
        anchor: [f64; 3],
    },
    /// ST3: sliding along the unit tangent-plane direction `dir`
    /// (components along `t1`, `t2`); friction `Ft = −μD·N·dir`.
    Slide {
        /// Unit slip direction `(u1, u2)`.
        dir: [f64; 2],
    },
}

impl SpatialState {
    /// The state's code.
    pub fn code(&self) -> StateCode {
        match self {
            SpatialState::Free => StateCode::St1,
            SpatialState::Stick { .. } => StateCode::St2,
            SpatialState::Slide { .. } => StateCode::St3,
        }
    }

    /// The state at `t = 0`: within `tol` of the surface it starts in ST2
    /// at its vertical projection, above it in ST1; `Err(depth)` below.
    pub fn initial(p: [f64; 3], surface: &Surface, tol: f64) -> Result<Self, f64> {
        let g = clearance(surface, p);
        if g < -tol {
            Err(-g)
        } else if g <= tol {
            Ok(SpatialState::Stick {
                anchor: project(surface, p),
            })
        } else {
            Ok(SpatialState::Free)
        }
    }
}

/// Height of `p` above the surface, measured vertically.
#[inline]
pub fn clearance(surface: &Surface, p: [f64; 3]) -> f64 {
    p[1] - surface.height(p[0], p[2])
}

/// The point of the surface vertically below (or above) `p`.
#[inline]
pub fn project(surface: &Surface, p: [f64; 3]) -> [f64; 3] {
    [p[0], surface.height(p[0], p[2]), p[2]]
}

/// The point of the surface under `p` along the surface's normal there:
/// `p − c·n_y·n` with `c` the vertical clearance (exactly the foot of the
/// normal on a plane). Its tangential components in the contact frame at
/// `p` are `p`'s: a point anchored there where it stopped carries no
/// tangential preload (the vertical projection of [`project`] would shift
/// it along a slope's tangent by `c·sin`).
pub fn under_along_normal(surface: &Surface, p: [f64; 3]) -> [f64; 3] {
    let c = clearance(surface, p);
    let n = surface.normal(p[0], p[2]);
    let d = c * n[1];
    [p[0] - d * n[0], p[1] - d * n[1], p[2] - d * n[2]]
}

/// The contact frame `(t1, n, t2)` at `(x, z)` (see the module docs); a
/// plane's is made once, with the surface.
pub fn frame(surface: &Surface, x: f64, z: f64) -> [[f64; 3]; 3] {
    match surface.plane_frame() {
        Some(frame) => frame,
        None => frame_at(surface, x, z),
    }
}

/// [`frame`] computed at `(x, z)`.
pub(crate) fn frame_at(surface: &Surface, x: f64, z: f64) -> [[f64; 3]; 3] {
    let n = surface.normal(x, z);
    let [ux, uz] = surface.direction();
    let [gx, gz] = surface.gradient(x, z);
    // Tangent along the profile: u + (∇ϱ·u)·Y, normalised.
    let t = [ux, gx * ux + gz * uz, uz];
    let k = 1.0 / (t[0] * t[0] + t[1] * t[1] + t[2] * t[2]).sqrt();
    let t1 = [t[0] * k, t[1] * k, t[2] * k];
    let t2 = [
        t1[1] * n[2] - t1[2] * n[1],
        t1[2] * n[0] - t1[0] * n[2],
        t1[0] * n[1] - t1[1] * n[0],
    ];
    [t1, n, t2]
}

/// Where the straight path `p0 → p1` first crosses the surface (the planar
/// [`crate::Terrain::crossing`] in the profile's section, which holds the
/// whole path's height profile), on the surface.
pub fn crossing(surface: &Surface, p0: [f64; 3], p1: [f64; 3]) -> [f64; 3] {
    if surface.grid().is_some() {
        return crossing_3d(surface, p0, p1);
    }
    let (s0, s1) = (surface.along(p0[0], p0[2]), surface.along(p1[0], p1[2]));
    let c = surface.terrain.crossing([s0, p0[1]], [s1, p1[1]]);
    // Fraction of the path at the crossing (along s, or along y when the
    // path is vertical in the section).
    let f = if (s1 - s0).abs() > 1e-300 {
        (c[0] - s0) / (s1 - s0)
    } else if (p1[1] - p0[1]).abs() > 1e-300 {
        (c[1] - p0[1]) / (p1[1] - p0[1])
    } else {
        0.0
    };
    let f = f.clamp(0.0, 1.0);
    let x = p0[0] + f * (p1[0] - p0[0]);
    let z = p0[2] + f * (p1[2] - p0[2]);
    [x, surface.height(x, z), z]
}

/// [`crossing`] on a height map: the root of `g(s) = clearance(p0 +
/// s·(p1 − p0))` on `[0, 1]` by the safeguarded secant/bisection of
/// [`crate::Terrain::crossing`], put on the surface.
fn crossing_3d(surface: &Surface, p0: [f64; 3], p1: [f64; 3]) -> [f64; 3] {
    let at = |s: f64| {
        [
            p0[0] + s * (p1[0] - p0[0]),
            p0[1] + s * (p1[1] - p0[1]),
            p0[2] + s * (p1[2] - p0[2]),
        ]
    };
    let g0 = clearance(surface, p0);
    if !g0.is_finite() || g0 <= 0.0 {
        return project(surface, p0);
    }
    let g1 = clearance(surface, p1);
    if g1 >= 0.0 {
        return project(surface, p1);
    }
    let (mut lo, mut hi, mut glo, mut ghi) = (0.0, 1.0, g0, g1);
    for _ in 0..100 {
        let mut s = lo + glo * (hi - lo) / (glo - ghi);
        if !(s > lo && s < hi) || (hi - lo) < 1e-3 {
            s = 0.5 * (lo + hi);
        }
        let g = clearance(surface, at(s));
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
    project(surface, at(lo))
}

/// The point of the surface at straight-line distance `dist` from `from`
/// (a point on the surface) in the horizontal direction `dir` (unit, in
/// `(x, z)`), by bisection: two points of a rigid body that both rest on
/// the surface are this far apart (the planar
/// [`crate::Terrain::point_at_distance`] along any horizontal direction).
pub fn point_at_distance(surface: &Surface, from: [f64; 3], dist: f64, dir: [f64; 2]) -> [f64; 3] {
    let at = |s: f64| {
        let (x, z) = (from[0] + s * dir[0], from[2] + s * dir[1]);
        [x, surface.height(x, z), z]
    };
    let gap = |s: f64| {
        let p = at(s);
        let d = [p[0] - from[0], p[1] - from[1], p[2] - from[2]];
        (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() - dist
    };
    let (mut lo, mut hi) = (0.0, dist);
    if gap(hi) < 0.0 {
        return at(hi);
    }
    for _ in 0..100 {
        let mid = 0.5 * (lo + hi);
        if gap(mid) < 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    at(0.5 * (lo + hi))
}

/// A trial solution of one step seen from one contact point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpatialTrial {
    /// The point at the start of the step (m).
    pub p_k: [f64; 3],
    /// The point at the end of the step (m).
    pub p_next: [f64; 3],
    /// Tangential force `(Ft1, Ft2)` (N).
    pub ft: [f64; 2],
    /// Normal force (N).
    pub n: f64,
    /// The frame `(t1, n, t2)` the forces are expressed in.
    pub frame: [[f64; 3]; 3],
    /// Time step (s).
    pub dt: f64,
}

impl SpatialTrial {
    /// `p[k+1] − a` in `(t1, t2)` components (m): how far the point is
    /// from `a` along the surface.
    pub fn slip_from(&self, a: [f64; 3]) -> [f64; 2] {
        let d = [
            self.p_next[0] - a[0],
            self.p_next[1] - a[1],
            self.p_next[2] - a[2],
        ];
        let dot = |t: [f64; 3]| d[0] * t[0] + d[1] * t[1] + d[2] * t[2];
        [dot(self.frame[0]), dot(self.frame[2])]
    }

    /// The slip over the step in `(t1, t2)` components (m).
    pub fn slip(&self) -> [f64; 2] {
        self.slip_from(self.p_k)
    }
}

/// The switching rules (module docs; the planar [`crate::transition`]
/// generalised). `None` when `state` is consistent with the trial.
pub fn transition_spatial(
    state: &SpatialState,
    trial: &SpatialTrial,
    surface: &Surface,
    friction: &Friction,
    params: &ContactParams,
) -> Option<SpatialState> {
    crate::machine::switch(state, trial, surface, friction, params)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Terrain;

    fn flat() -> Surface {
        Surface::default()
    }

    fn trial(p_k: [f64; 3], p_next: [f64; 3], ft: [f64; 2], n: f64) -> SpatialTrial {
        SpatialTrial {
            p_k,
            p_next,
            ft,
            n,
            frame: frame(&flat(), 0.0, 0.0),
            dt: 0.01,
        }
    }

    fn tr(s: SpatialState, t: SpatialTrial) -> Option<SpatialState> {
        transition_spatial(
            &s,
            &t,
            &flat(),
            &Friction::default(),
            &ContactParams::default(),
        )
    }

    #[test]
    fn a_planes_frame_is_made_once_and_is_the_frame_everywhere() {
        for (terrain, direction) in [
            (Terrain::Flat { height: 0.2 }, 0.0),
            (Terrain::None, 0.3),
            (Terrain::slope_deg(3.5, 0.0), 0.0),
            (Terrain::slope_deg(-12.0, 0.1), 1.1),
        ] {
            let s = Surface::new(terrain, direction);
            assert!(s.plane_frame().is_some());
            for (x, z) in [(0.0, 0.0), (0.4, -0.2), (-3.7, 12.5), (1e3, -1e3)] {
                assert_eq!(frame(&s, x, z), frame_at(&s, x, z), "at ({x}, {z})");
            }
        }
        // A terrain changed after the surface was made is not served from
        // the frame made for the old one.
        let mut s = Surface::new(Terrain::slope_deg(10.0, 0.0), 0.0);
        s.terrain = Terrain::slope_deg(20.0, 0.0);
        assert_eq!(frame(&s, 0.4, 0.0), frame_at(&s, 0.4, 0.0));
        assert_ne!(
            frame(&s, 0.4, 0.0)[1],
            Surface::new(Terrain::slope_deg(10.0, 0.0), 0.0).normal(0.4, 0.0)
        );
        // No cached frame for the curved kinds.
        let sine = Terrain::Sine {
            amplitude: 0.1,
            wavelength: 2.0,
            phase: 0.0,
            height: 0.0,
        };
        assert!(Surface::new(sine, 0.0).plane_frame().is_none());
    }

    #[test]
    fn frame_is_orthonormal_and_planar_at_zero_direction() {
        let s = Surface::new(
            Terrain::Slope {
                slope: 0.3,
                height: 0.1,
            },
            0.0,
        );
        let [t1, n, t2] = frame(&s, 0.4, -0.2);
        let (pt, pn) = s.terrain.frame(0.4);
        assert!((t1[0] - pt[0]).abs() < 1e-15 && (t1[1] - pt[1]).abs() < 1e-15 && t1[2] == 0.0);
        assert!((n[0] - pn[0]).abs() < 1e-15 && (n[1] - pn[1]).abs() < 1e-15);
        assert!((t2[2] - 1.0).abs() < 1e-15);
        let s = Surface::new(
            Terrain::Slope {
                slope: 0.3,
                height: 0.1,
            },
            0.7,
        );
        let f = frame(&s, 0.4, -0.2);
        for i in 0..3 {
            for j in 0..3 {
                let d: f64 = (0..3).map(|k| f[i][k] * f[j][k]).sum();
                assert!((d - f64::from(u8::from(i == j))).abs() < 1e-14);
            }
        }
    }

    #[test]
    fn touchdown_at_the_crossing_in_3d() {
        let s = tr(
            SpatialState::Free,
            trial([0.0, 0.01, 0.0], [0.02, -0.01, 0.04], [0.0; 2], 0.0),
        );
        let Some(SpatialState::Stick { anchor }) = s else {
            panic!("{s:?}")
        };
        assert!((anchor[0] - 0.01).abs() < 1e-12 && (anchor[2] - 0.02).abs() < 1e-12);
        assert_eq!(anchor[1], 0.0);
    }

    #[test]
    fn cone_breaks_in_the_direction_of_the_needed_force() {
        let st = SpatialState::Stick { anchor: [0.0; 3] };
        // |Ft| = 5 > 0.4·10: slides against (3, 4)/5.
        assert_eq!(
            tr(st, trial([0.0; 3], [0.0; 3], [3.0, 4.0], 10.0)),
            Some(SpatialState::Slide { dir: [-0.6, -0.8] })
        );
        assert_eq!(tr(st, trial([0.0; 3], [0.0; 3], [2.0, 3.4], 10.0)), None);
        assert_eq!(
            tr(st, trial([0.0; 3], [0.0; 3], [0.0, 0.0], -1.0)),
            Some(SpatialState::Free)
        );
    }

    #[test]
    fn slide_turns_and_stops_when_it_reverses() {
        let sl = SpatialState::Slide { dir: [1.0, 0.0] };
        assert_eq!(
            tr(sl, trial([0.0; 3], [0.001, 0.0, 0.0], [-3.0, 0.0], 10.0)),
            None
        );
        // Turned by less than 90°: still sliding (the equations follow it).
        assert_eq!(
            tr(sl, trial([0.0; 3], [0.001, 0.0, 0.003], [-3.0, 0.0], 10.0)),
            None
        );
        // Backwards: sticks under p[k].
        assert_eq!(
            tr(
                sl,
                trial([0.2, 0.0, 0.1], [0.199, 0.0, 0.1], [-3.0, 0.0], 10.0)
            ),
            Some(SpatialState::Stick {
                anchor: [0.2, 0.0, 0.1]
            })
        );
    }

    #[test]
    fn initial_states() {
        let g = flat();
        assert_eq!(
            SpatialState::initial([0.0, 0.5, 0.0], &g, 1e-9),
            Ok(SpatialState::Free)
        );
        assert_eq!(
            SpatialState::initial([0.3, 5e-10, 0.2], &g, 1e-9),
            Ok(SpatialState::Stick {
                anchor: [0.3, 0.0, 0.2]
            })
        );
        assert_eq!(
            SpatialState::initial([0.0, -0.01, 0.0], &g, 1e-9),
            Err(0.01)
        );
    }
}

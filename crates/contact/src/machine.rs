//! The ST1/ST2/ST3 switching rules, one source for the plane and for 3D.
//!
//! The rules of docs/reference.md are written once, in [`switch`], over two
//! traits that carry the dimension:
//!
//! * [`ContactMode`] — a contact state (the planar [`ContactState`], the
//!   spatial [`SpatialState`]): its code, its anchor when it sticks, the
//!   slide opposite to a tangential force;
//! * [`ContactTrial`] — a trial solution seen from one point (the planar
//!   [`Trial`], the spatial [`SpatialTrial`]): its normal and tangential
//!   forces, its clearance, where its path crosses the ground, its slip
//!   along a slide's direction.
//!
//! The staged step of `fbd-sim` searches the states of every point through
//! the same two traits, so the plane and 3D share the state search too.

use crate::mode::{ContactParams, ContactState, Friction, StateCode, Trial};
use crate::spatial::{self, STOP_SPEED, SpatialState, SpatialTrial};
use crate::{Surface, Terrain};
use std::fmt::Debug;

/// A contact state of one dimension.
pub trait ContactMode: Copy + PartialEq + Debug {
    /// Where a sticking point is held (a point of the ground).
    type Anchor: Copy + PartialEq + Debug + Default;
    /// The tangential contact force (one or two components).
    type Tangent: Copy + Debug + Default;
    /// ST1.
    const FREE: Self;
    /// Distinct values of [`Self::search_key`].
    const KEY_BASE: u64;

    /// The state's code.
    fn code(&self) -> StateCode;
    /// The state for the state search's cycle detection: the code, and in
    /// the plane the slide's direction (turning in 3D is not a switch).
    fn search_key(&self) -> u64;
    /// ST2 at `anchor`.
    fn stick(anchor: Self::Anchor) -> Self;
    /// The anchor of a sticking point.
    fn anchor(&self) -> Option<Self::Anchor>;
    /// ST3 opposite to the tangential force `ft` sticking needed (friction
    /// keeps the force's direction); along the first tangent when `ft` is
    /// zero.
    fn slide_against(ft: Self::Tangent) -> Self;
    /// ST3 along `sign` times the first tangent (the exhaustive search's
    /// two slides).
    fn slide_along_first(sign: f64) -> Self;
    /// `|Ft|` (N).
    fn tangent_norm(ft: Self::Tangent) -> f64;
    /// `true` when `other` gives the point the same equations: the same
    /// state with the same anchor, and in the plane the same slide
    /// direction (in 3D a slide's direction is an unknown of the step,
    /// its reference direction is not part of the equations).
    fn same_law(&self, other: &Self) -> bool;
}

/// A trial solution of one step seen from one contact point.
pub trait ContactTrial {
    /// The states it is checked against.
    type Mode: ContactMode;
    /// The ground it touches.
    type Ground: ?Sized;

    /// Normal force `N` (N).
    fn normal(&self) -> f64;
    /// Tangential force (N).
    fn tangential(&self) -> <Self::Mode as ContactMode>::Tangent;
    /// Height of `p[k+1]` above the ground (m, vertical).
    fn clearance_next(&self, ground: &Self::Ground) -> f64;
    /// Where the straight path `p[k] → p[k+1]` crosses the ground.
    fn crossing(&self, ground: &Self::Ground) -> <Self::Mode as ContactMode>::Anchor;
    /// The ground under `p[k]` (where a stopping slide is anchored).
    fn under_start(&self, ground: &Self::Ground) -> <Self::Mode as ContactMode>::Anchor;
    /// The slip speed along the direction of the slide `state` (m/s).
    fn slip_speed(&self, state: &Self::Mode) -> f64;
    /// The speed below which a slide has stopped (m/s).
    fn stop_speed(params: &ContactParams) -> f64;
    /// Where the point is on the ground, `(x, z)` of `p[k]` (`z = 0` in the
    /// plane): where its friction is looked up.
    fn location(&self) -> [f64; 2];
}

/// The switching rules of docs/reference.md. `None` when `state` is
/// consistent with the trial, otherwise the state to re-solve the step in.
///
/// * ST1 → ST2 when the point would end the step below the ground; the
///   anchor is where the straight path `p[k] → p[k+1]` crosses it.
/// * ST2 → ST1 when `N < 0`; ST2 → ST3 when `|Ft| > μS·N`, sliding opposite
///   to the friction that sticking needed.
/// * ST3 → ST1 when `N < 0`; ST3 → ST2 when the slip along the slide's
///   direction reverses or vanishes (anchored under `p[k]`).
pub fn switch<T: ContactTrial>(
    state: &T::Mode,
    trial: &T,
    ground: &T::Ground,
    friction: &Friction,
    params: &ContactParams,
) -> Option<T::Mode> {
    let n = trial.normal();
    match state.code() {
        StateCode::St1 => (trial.clearance_next(ground) < -params.penetration_tol)
            .then(|| T::Mode::stick(trial.crossing(ground))),
        StateCode::St2 => {
            let ft = trial.tangential();
            if n < -params.force_tol {
                Some(T::Mode::FREE)
            } else if T::Mode::tangent_norm(ft) > friction.mu_static * n + params.force_tol {
                Some(T::Mode::slide_against(ft))
            } else {
                None
            }
        }
        StateCode::St3 => {
            if n < -params.force_tol {
                Some(T::Mode::FREE)
            } else if trial.slip_speed(state) <= T::stop_speed(params) {
                Some(T::Mode::stick(trial.under_start(ground)))
            } else {
                None
            }
        }
    }
}

impl ContactMode for ContactState {
    type Anchor = [f64; 2];
    type Tangent = f64;
    const FREE: Self = ContactState::Free;
    const KEY_BASE: u64 = 4;

    fn code(&self) -> StateCode {
        ContactState::code(self)
    }
    fn search_key(&self) -> u64 {
        self.key()
    }
    fn stick(anchor: [f64; 2]) -> Self {
        ContactState::Stick { anchor }
    }
    fn anchor(&self) -> Option<[f64; 2]> {
        match *self {
            ContactState::Stick { anchor } => Some(anchor),
            _ => None,
        }
    }
    fn slide_against(fa: f64) -> Self {
        ContactState::Slide { dir: -fa.signum() }
    }
    fn slide_along_first(sign: f64) -> Self {
        ContactState::Slide { dir: sign }
    }
    fn tangent_norm(fa: f64) -> f64 {
        fa.abs()
    }
    fn same_law(&self, other: &Self) -> bool {
        self == other
    }
}

impl ContactTrial for Trial {
    type Mode = ContactState;
    type Ground = Terrain;

    fn normal(&self) -> f64 {
        self.n
    }
    fn tangential(&self) -> f64 {
        self.fa
    }
    fn clearance_next(&self, terrain: &Terrain) -> f64 {
        terrain.clearance(self.p_next)
    }
    fn location(&self) -> [f64; 2] {
        [self.p_k[0], 0.0]
    }
    fn crossing(&self, terrain: &Terrain) -> [f64; 2] {
        terrain.crossing(self.p_k, self.p_next)
    }
    fn under_start(&self, terrain: &Terrain) -> [f64; 2] {
        [self.p_k[0], terrain.height(self.p_k[0])]
    }
    fn slip_speed(&self, state: &ContactState) -> f64 {
        match *state {
            ContactState::Slide { dir } => self.slide_velocity() * dir,
            _ => 0.0,
        }
    }
    fn stop_speed(params: &ContactParams) -> f64 {
        params.speed_tol
    }
}

impl ContactMode for SpatialState {
    type Anchor = [f64; 3];
    type Tangent = [f64; 2];
    const FREE: Self = SpatialState::Free;
    const KEY_BASE: u64 = 3;

    fn code(&self) -> StateCode {
        SpatialState::code(self)
    }
    fn search_key(&self) -> u64 {
        self.code() as u64
    }
    fn stick(anchor: [f64; 3]) -> Self {
        SpatialState::Stick { anchor }
    }
    fn anchor(&self) -> Option<[f64; 3]> {
        match *self {
            SpatialState::Stick { anchor } => Some(anchor),
            _ => None,
        }
    }
    fn slide_against(ft: [f64; 2]) -> Self {
        let len = ft[0].hypot(ft[1]);
        let dir = if len > 0.0 {
            [-ft[0] / len, -ft[1] / len]
        } else {
            [1.0, 0.0]
        };
        SpatialState::Slide { dir }
    }
    fn slide_along_first(sign: f64) -> Self {
        SpatialState::Slide { dir: [sign, 0.0] }
    }
    fn tangent_norm(ft: [f64; 2]) -> f64 {
        ft[0].hypot(ft[1])
    }
    fn same_law(&self, other: &Self) -> bool {
        match (self, other) {
            (SpatialState::Stick { anchor: a }, SpatialState::Stick { anchor: b }) => a == b,
            _ => self.code() == other.code(),
        }
    }
}

impl ContactTrial for SpatialTrial {
    type Mode = SpatialState;
    type Ground = Surface;

    fn normal(&self) -> f64 {
        self.n
    }
    fn tangential(&self) -> [f64; 2] {
        self.ft
    }
    fn clearance_next(&self, surface: &Surface) -> f64 {
        spatial::clearance(surface, self.p_next)
    }
    fn location(&self) -> [f64; 2] {
        [self.p_k[0], self.p_k[2]]
    }
    fn crossing(&self, surface: &Surface) -> [f64; 3] {
        spatial::crossing(surface, self.p_k, self.p_next)
    }
    fn under_start(&self, surface: &Surface) -> [f64; 3] {
        spatial::under_along_normal(surface, self.p_k)
    }
    fn slip_speed(&self, state: &SpatialState) -> f64 {
        match *state {
            SpatialState::Slide { dir } => {
                let s = self.slip();
                (s[0] * dir[0] + s[1] * dir[1]) / self.dt
            }
            _ => 0.0,
        }
    }
    fn stop_speed(params: &ContactParams) -> f64 {
        params.speed_tol.max(STOP_SPEED)
    }
}

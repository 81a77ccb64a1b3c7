//! The ST1/ST2/ST3 contact state machine of paper §5.4 and docs/reference.md.
//!
//! | state | meaning | equations the point contributes |
//! |---|---|---|
//! | ST1 | no contact | `N = 0`, `Fa = 0` |
//! | ST2 | contact, no sliding | the point stays at its anchor `(a, b)` |
//! | ST3 | contact, sliding | point on the surface, `Fa = −dir·μD·N` |
//!
//! [`transition`] looks at a trial solution of one step and says whether the
//! state it was solved in is consistent, and if not which state to solve in
//! next. The step is re-solved until no point wants to switch.

use crate::terrain::Terrain;
use std::fmt;

/// The three states of the paper, as written to the output files.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum StateCode {
    /// No contact.
    St1,
    /// Contact without sliding.
    St2,
    /// Contact with sliding.
    St3,
}

impl StateCode {
    /// `"ST1"`, `"ST2"` or `"ST3"`.
    pub fn as_str(self) -> &'static str {
        match self {
            StateCode::St1 => "ST1",
            StateCode::St2 => "ST2",
            StateCode::St3 => "ST3",
        }
    }
}

impl fmt::Display for StateCode {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// The state of one contact point, with what its equations need.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ContactState {
    /// ST1: no contact.
    Free,
    /// ST2: the point is held at `anchor` (on the terrain).
    Stick {
        /// The contact point `(a, b)`.
        anchor: [f64; 2],
    },
    /// ST3: the point slides on the surface in direction `dir` (±1 along the
    /// unit tangent); friction is `Fa = −dir·μD·N`.
    Slide {
        /// Slide direction along the tangent, +1 or −1.
        dir: f64,
    },
}

impl ContactState {
    /// The state's code.
    pub fn code(&self) -> StateCode {
        match self {
            ContactState::Free => StateCode::St1,
            ContactState::Stick { .. } => StateCode::St2,
            ContactState::Slide { .. } => StateCode::St3,
        }
    }

    /// A small integer identifying the equations' sparsity (0, 1, 2) and,
    /// with the slide direction, the state for cycle detection (0..=3).
    pub fn key(&self) -> u64 {
        match self {
            ContactState::Free => 0,
            ContactState::Stick { .. } => 1,
            ContactState::Slide { dir } if *dir > 0.0 => 2,
            ContactState::Slide { .. } => 3,
        }
    }

    /// The state of a point at `t = 0` (docs/reference.md): within `tol` of the terrain
    /// it starts in ST2 at its vertical projection, above it in ST1. Returns
    /// `Err(depth)` when the point is deeper than `tol` below the terrain.
    pub fn initial(p: [f64; 2], terrain: &Terrain, tol: f64) -> Result<Self, f64> {
        let g = terrain.clearance(p);
        if g < -tol {
            Err(-g)
        } else if g <= tol {
            Ok(ContactState::Stick {
                anchor: [p[0], terrain.height(p[0])],
            })
        } else {
            Ok(ContactState::Free)
        }
    }
}

/// Coulomb friction coefficients of the soil, `μS ≥ μD ≥ 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Friction {
    /// Static coefficient μS.
    pub mu_static: f64,
    /// Dynamic coefficient μD.
    pub mu_dynamic: f64,
}

impl Default for Friction {
    /// The paper's §6 values: μS = 0.4, μD = 0.3.
    fn default() -> Self {
        Self {
            mu_static: 0.4,
            mu_dynamic: 0.3,
        }
    }
}

impl Friction {
    /// Checks `0 ≤ μD ≤ μS` (and finiteness).
    pub fn validate(&self) -> Result<(), crate::ContactError> {
        let ok = self.mu_dynamic.is_finite()
            && self.mu_static.is_finite()
            && 0.0 <= self.mu_dynamic
            && self.mu_dynamic <= self.mu_static;
        if ok {
            Ok(())
        } else {
            Err(crate::ContactError::Friction {
                mu_static: self.mu_static,
                mu_dynamic: self.mu_dynamic,
            })
        }
    }
}

/// Tolerances of the switching rules.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactParams {
    /// A free point is "below the terrain" when deeper than this (m).
    /// Default `1e-10`: far below any physical scale, above round-off.
    pub penetration_tol: f64,
    /// Force tolerance (N): `N < −force_tol` lifts off; sticking fails when
    /// `|Fa| > μS·N + force_tol`. Default `1e-7`, above the Newton tolerance
    /// on forces.
    pub force_tol: f64,
    /// Sliding speed (m/s) at or below which a slide counts as vanished.
    /// Default `1e-9`.
    pub speed_tol: f64,
    /// A point within this distance of the terrain at `t = 0` starts in ST2
    /// (docs/reference.md). Default `1e-9` m.
    pub initial_tol: f64,
    /// Dimensionless regularisation β of the contact position rows
    /// (`K·(p − a) + β·F = 0` with `K = M/Δt²`, see `fbd_dynamics::assemble`):
    /// a point under load `N` sits `β·N·Δt²/M` below its anchor. It makes
    /// statically indeterminate contact sets (two sticking points on one
    /// body) solvable. Default `1e-8`: 1e-10 m for 1 kN on the default
    /// robot at Δt = 0.01 s, and far above round-off in the Jacobian. This
    /// is its value at Δt = 0.01 s: the stepping loop (`fbd_sim::step`)
    /// scales it as `(0.01 s/Δt)²`, so that the compliance `β·Δt²/M` is
    /// the same at every step length.
    pub regularization: f64,
    /// Dimensionless regularisation β_b added to β on the knees' and hips'
    /// contact rows: they read `K·(p − a) + (β + β_b)·F = 0` (ST2), a very
    /// stiff bumper rather than a rigid point, of compliance
    /// `β_b·Δt²/M` (m/N). With the rigid feet, rigid knees and hips
    /// over-constrain the mechanism (12 sticking constraints on 7 degrees
    /// of freedom when it lies on the ground), and a geometric mismatch at
    /// a landing becomes an unbounded force.
    ///
    /// The compliance scales with Δt², like β, so that the bumper's spring
    /// period (`2π·Δt·√(β_b·m/M)` for a body of mass `m`) is always far
    /// below one step: the implicit step damps it completely and every
    /// impact on a knee or hip is plastic at every Δt. (A fixed compliance
    /// is resolved once Δt is small enough, and the impacts become elastic:
    /// hips and knees bounce again and again.) Default `1e-3`: 7.8 nm per
    /// newton at Δt = 0.01 s on the default robot (M = 12.8 kg), 0.4 µm
    /// under the 50 N a hip carries at rest; 0.078 pm/N at Δt = 0.1 ms.
    /// The feet stay rigid, as in the paper.
    pub bumper_regularization: f64,
}

impl Default for ContactParams {
    fn default() -> Self {
        Self {
            penetration_tol: 1e-10,
            force_tol: 1e-7,
            speed_tol: 1e-9,
            initial_tol: 1e-9,
            regularization: 1e-8,
            bumper_regularization: 1e-3,
        }
    }
}

/// A trial solution of one step, seen from one contact point.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trial {
    /// The point at the start of the step, `p[k]`.
    pub p_k: [f64; 2],
    /// The point at the end of the step, `p[k+1]`.
    pub p_next: [f64; 2],
    /// Tangential contact force along the unit tangent (N).
    pub fa: f64,
    /// Normal contact force along the unit normal (N).
    pub n: f64,
    /// The unit tangent the forces were expressed in.
    pub tangent: [f64; 2],
    /// Time step (s).
    pub dt: f64,
}

impl Trial {
    /// Sliding velocity along the tangent, `(p[k+1] − p[k])·t / Δt`.
    pub fn slide_velocity(&self) -> f64 {
        ((self.p_next[0] - self.p_k[0]) * self.tangent[0]
            + (self.p_next[1] - self.p_k[1]) * self.tangent[1])
            / self.dt
    }
}

/// The switching rules of docs/reference.md. Returns `None` when `state` is consistent
/// with the trial, otherwise the state to re-solve the step in.
///
/// * ST1 → ST2 when the point would end the step below the terrain; the anchor
///   is where the straight path `p[k] → p[k+1]` crosses the terrain.
/// * ST2 → ST1 when `N < 0`; ST2 → ST3 when `|Fa| > μS·N`, sliding opposite
///   to the friction that sticking needed (so sliding friction keeps its sign).
/// * ST3 → ST1 when `N < 0`; ST3 → ST2 when the sliding velocity reverses or
///   vanishes (anchored at `p[k]`, where the slide stopped).
pub fn transition(
    state: &ContactState,
    trial: &Trial,
    terrain: &Terrain,
    friction: &Friction,
    params: &ContactParams,
) -> Option<ContactState> {
    crate::machine::switch(state, trial, terrain, friction, params)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trial(p_k: [f64; 2], p_next: [f64; 2], fa: f64, n: f64) -> Trial {
        Trial {
            p_k,
            p_next,
            fa,
            n,
            tangent: [1.0, 0.0],
            dt: 0.01,
        }
    }
    const G: Terrain = Terrain::Flat { height: 0.0 };

    fn tr(s: ContactState, t: Trial) -> Option<ContactState> {
        transition(&s, &t, &G, &Friction::default(), &ContactParams::default())
    }

    #[test]
    fn touchdown_anchors_at_the_crossing() {
        let s = tr(
            ContactState::Free,
            trial([0.0, 0.01], [0.02, -0.01], 0.0, 0.0),
        );
        assert_eq!(
            s,
            Some(ContactState::Stick {
                anchor: [0.01, 0.0]
            })
        );
        assert_eq!(
            tr(
                ContactState::Free,
                trial([0.0, 0.01], [0.0, 0.001], 0.0, 0.0)
            ),
            None
        );
    }

    #[test]
    fn sticking_breaks_above_mu_static() {
        let st = ContactState::Stick { anchor: [0.0, 0.0] };
        assert_eq!(tr(st, trial([0.0; 2], [0.0; 2], 3.9, 10.0)), None);
        // Friction needed +4.1 N > 0.4·10 N: slides towards −x, friction stays +.
        assert_eq!(
            tr(st, trial([0.0; 2], [0.0; 2], 4.1, 10.0)),
            Some(ContactState::Slide { dir: -1.0 })
        );
        assert_eq!(
            tr(st, trial([0.0; 2], [0.0; 2], 0.0, -1.0)),
            Some(ContactState::Free)
        );
    }

    #[test]
    fn sliding_stops_when_velocity_reverses() {
        let sl = ContactState::Slide { dir: 1.0 };
        assert_eq!(tr(sl, trial([0.0; 2], [0.001, 0.0], -3.0, 10.0)), None);
        assert_eq!(
            tr(sl, trial([0.2, 0.0], [0.199, 0.0], -3.0, 10.0)),
            Some(ContactState::Stick { anchor: [0.2, 0.0] })
        );
        assert_eq!(
            tr(sl, trial([0.0; 2], [0.001, 0.0], 0.0, -1.0)),
            Some(ContactState::Free)
        );
    }

    #[test]
    fn initial_states() {
        assert_eq!(
            ContactState::initial([0.0, 0.5], &G, 1e-9),
            Ok(ContactState::Free)
        );
        assert_eq!(
            ContactState::initial([0.3, 5e-10], &G, 1e-9),
            Ok(ContactState::Stick { anchor: [0.3, 0.0] })
        );
        assert_eq!(ContactState::initial([0.0, -0.01], &G, 1e-9), Err(0.01));
    }

    #[test]
    fn friction_validation() {
        assert!(
            Friction {
                mu_static: 0.3,
                mu_dynamic: 0.4
            }
            .validate()
            .is_err()
        );
        assert!(
            Friction {
                mu_static: 0.4,
                mu_dynamic: f64::NAN
            }
            .validate()
            .is_err()
        );
        assert!(Friction::default().validate().is_ok());
    }
}

//! One staged time step for every model: the planar 7-DOF two-leg model
//! ([`crate::Model`]) and the spatial 24-DOF hexapod
//! ([`crate::spatial::SpatialModel`]).
//!
//! The step's control flow — the stages, the contact and joint-limit state
//! search with its cycle fallbacks, the retry in substeps, events and
//! acceptance — is written once, in [`step`](mod@step) and [`search`],
//! generic over an [`Engine`]: the model, which supplies what depends on
//! the dimension (the FBD assembly and its Newton solve, the kinematics,
//! the controller, a contact point's trial and geometry, the record).
//! The workspace is one generic [`RunData`], sized from the model's
//! layout. Contact states and their switching rules are
//! [`fbd_contact::ContactMode`] and [`fbd_contact::switch`], one source
//! for both dimensions.
//!
//! Stages of [`step::step`]:
//!
//! 1. **kinematics at k** ([`Engine::kinematics`]): the per-body constants
//!    of the second differences;
//! 2. **joint torques at k** ([`Engine::torques`]): the controller's
//!    torques from `q[k]`, `q[k−1]`;
//! 3. **predictor** ([`crate::predictor`]; the initial velocity at k = 0);
//! 4. **solve** ([`Engine::solve`]): Newton on the FBD equations with the
//!    trial contact and joint-limit states;
//! 5. **state check** ([`search`]): every point's switching rule and every
//!    joint limit's on the trial solution; any switch → back to 4;
//! 6. **accept**: record, events, `q[k+1]` becomes the current state.

pub mod data;
pub mod run;
pub mod search;
pub mod step;
pub mod surface;
pub mod tree_record;

pub use data::RunData;

use crate::SimError;
use fbd_contact::{ContactMode, ContactParams, ContactTrial, Friction};
use fbd_dynamics::{ContactSpec, History, PointKind};
use fbd_kinematics::Joint;
use fbd_solver::{NewtonReport, SolverError};

/// The law a trial solution breaks ([`Engine::contact_violation`],
/// [`search::worst_violation`]), named in the error of a step that cannot
/// be closed exactly.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Law {
    /// Every law holds.
    None,
    /// A free point ends the step below the ground.
    Penetration,
    /// A contact pulls on the ground (`N < 0`).
    Pull,
    /// A sticking point needs more than `μS·N`.
    StaticCone,
    /// A sliding point slips backwards against its slide.
    SlideBackwards,
    /// A sliding point's friction is not `μD·N`.
    SlideMagnitude,
    /// A sliding point's friction does not oppose the step's slip.
    SlideDirection,
    /// A free joint ends the step beyond an end of its range.
    LimitCrossing,
    /// A joint stop pulls its joint towards the end.
    LimitPull,
}

impl Law {
    /// The law, as the error message names it.
    pub fn describe(self) -> &'static str {
        match self {
            Law::None => "no law",
            Law::Penetration => "no penetration of a free point (ST1)",
            Law::Pull => "N ≥ 0",
            Law::StaticCone => "|Ft| ≤ μS·N of a sticking point (ST2)",
            Law::SlideBackwards => "a slide (ST3) moves forwards",
            Law::SlideMagnitude => "|Ft| = μD·N of a sliding point (ST3)",
            Law::SlideDirection => "Ft = −μD·N·ŝ opposing the slip (ST3)",
            Law::LimitCrossing => "a free joint stays within its range",
            Law::LimitPull => "a joint stop pushes (never pulls)",
        }
    }
}

/// The largest of some `(violation, law)` pairs (the first of equals).
#[inline]
pub fn worst<const N: usize>(parts: [(f64, Law); N]) -> (f64, Law) {
    parts
        .into_iter()
        .fold((0.0, Law::None), |w, p| if p.0 > w.0 { p } else { w })
}

/// A joint limit's identity.
#[derive(Clone, Copy, Debug)]
pub struct LimitInfo {
    /// Index of the joint's angle in `q`.
    pub q_index: usize,
    /// The joint index written to the limit events.
    pub joint_index: usize,
    /// Which joint of its leg it is.
    pub joint: Joint,
    /// Hexapod leg number (0 for other robots: `joint_index` names it).
    pub leg: usize,
    /// The joint's range `[min, max]` (rad).
    pub range: [f64; 2],
}

/// The fixed settings and sizes of a model's step.
#[derive(Clone, Copy, Debug)]
pub struct Settings<'a, G: ?Sized> {
    /// Time step Δt (s).
    pub dt: f64,
    /// Finest subdivision of a step that cannot be solved whole.
    pub max_substeps: usize,
    /// A cycling state search is closed by its least inconsistent trial
    /// when that trial violates the laws by at most this force (N); every
    /// accepted solution obeys every law to this force (the law audit of
    /// [`search`]), or the step is retried in substeps and finally fails.
    pub cycle_tolerance: f64,
    /// Whether every written row must obey the laws (the spatial model):
    /// the law audit of [`search`] checks every accepted solution and a
    /// step that cannot be solved exactly fails instead of being closed by
    /// its least inconsistent trial at the finest substeps. `false` (the
    /// planar model) keeps the earlier rule: no audit, and at the finest
    /// substeps a cycling search is closed by its least inconsistent
    /// trial whatever its violation.
    pub exact: bool,
    /// Initial generalised velocities (one per coordinate of `q`).
    pub qdot0: &'a [f64],
    /// Steps of a run.
    pub steps: usize,
    /// A run hands every `stride`-th step's record to its observer.
    pub stride: usize,
    /// Rigid bodies.
    pub bodies: usize,
    /// Contact points, with their body and identity `{leg, kind}`.
    pub contacts: &'a [ContactSpec],
    /// Joint limits.
    pub limits: usize,
    /// The ground.
    pub ground: &'a G,
    /// Its Coulomb friction.
    pub friction: &'a Friction,
    /// The contact tolerances.
    pub contact: &'a ContactParams,
}

/// What the generic step needs from a model: its fixed data and the
/// stages that depend on the dimension. Implemented by [`crate::Model`]
/// (planar) and [`crate::spatial::SpatialModel`].
pub trait Engine: Sized {
    /// A contact point's state.
    type State: ContactMode;
    /// A contact point's view of a trial solution.
    type Trial: ContactTrial<Mode = Self::State, Ground = Self::Ground>;
    /// The ground (planar terrain, spatial surface).
    type Ground: ?Sized;
    /// The FBD assembly's workspace.
    type Fbd;
    /// The record of one step.
    type Record;
    /// Joint torques set from outside the simulator.
    type Torques;
    /// The controller's workspace.
    type ControlData;

    /// The fixed settings and sizes of the step.
    fn settings(&self) -> Settings<'_, Self::Ground>;
    /// Time step Δt (s).
    fn dt(&self) -> f64 {
        self.settings().dt
    }
    /// Finest subdivision of a retried step.
    fn max_substeps(&self) -> usize {
        self.settings().max_substeps
    }
    /// Largest violation a cycling search may close with (N).
    fn cycle_tolerance(&self) -> f64 {
        self.settings().cycle_tolerance
    }
    /// Whether rows must be exact ([`Settings::exact`]).
    fn exact(&self) -> bool {
        self.settings().exact
    }
    /// Initial generalised velocities.
    fn qdot0(&self) -> &[f64] {
        self.settings().qdot0
    }
    /// Coordinates in `q`.
    fn nq(&self) -> usize {
        self.settings().qdot0.len()
    }
    /// The ground.
    fn ground(&self) -> &Self::Ground {
        self.settings().ground
    }
    /// Coulomb friction.
    fn friction(&self) -> &Friction {
        self.settings().friction
    }
    /// The Coulomb friction at `(x, z)` of the ground (its friction
    /// patches; [`Engine::friction`] elsewhere).
    fn friction_at(&self, _at: [f64; 2]) -> Friction {
        *self.friction()
    }
    /// Contact tolerances.
    fn contact_params(&self) -> &ContactParams {
        self.settings().contact
    }
    /// Contact points.
    fn contacts(&self) -> usize {
        self.settings().contacts.len()
    }
    /// Bodies.
    fn bodies(&self) -> usize {
        self.settings().bodies
    }
    /// Joint limits.
    fn limits(&self) -> usize {
        self.settings().limits
    }
    /// The body contact point `c` belongs to.
    fn contact_body(&self, c: usize) -> usize {
        self.settings().contacts[c].body
    }
    /// Hexapod leg number and kind (tip, knee, hip) of point `c`.
    fn contact_identity(&self, c: usize) -> (usize, PointKind) {
        let spec = &self.settings().contacts[c];
        (spec.leg, spec.kind)
    }
    /// Name of point `c` in messages.
    fn contact_name(&self, c: usize) -> &str {
        &self.settings().contacts[c].name
    }
    /// Joint limit `l`.
    fn limit(&self, l: usize) -> LimitInfo;
    /// Name of limit `l`'s joint in messages.
    fn limit_name(&self, l: usize) -> String;
    /// Index in the unknowns of limit `l`'s stop moment.
    fn limit_moment_index(&self, l: usize) -> usize;

    /// Stage 1: the constants of the (sub)step of length `h` from `q[k]`,
    /// `q[k−1]` (or the initial velocity).
    fn kinematics(&self, data: &mut RunData<Self>, history: History<'_>, h: f64);
    /// Stage 2: the joint torques at k.
    ///
    /// # Errors
    /// A controller failure.
    fn torques(&self, data: &mut RunData<Self>) -> Result<(), SimError>;
    /// Stage 4: Newton on the equations of the trial states, from and into
    /// `data.z`.
    ///
    /// # Errors
    /// The solver's.
    fn solve(&self, data: &mut RunData<Self>) -> Result<NewtonReport, SolverError>;
    /// After a solve: the kinematics at `q[k+1] = z[..nq]`.
    fn evaluate_next(&self, data: &mut RunData<Self>);
    /// Point `c`'s view of the last solution.
    fn trial(&self, data: &RunData<Self>, c: usize) -> Self::Trial;
    /// How far a point's trial is from the law of `state`, the state it
    /// was solved in (N), and the law it breaks most.
    fn contact_violation(
        &self,
        data: &RunData<Self>,
        state: &Self::State,
        trial: &Self::Trial,
    ) -> (f64, Law);
    /// The position gain of the stop rows over the length scale (N/rad),
    /// which turns a joint's overshoot into a force.
    fn limit_gain(&self, data: &RunData<Self>) -> f64;
    /// The length scale turning moments into forces (m).
    fn length_scale(&self, data: &RunData<Self>) -> f64;
    /// The anchor of point `c`, which starts sticking on the body of
    /// `reference`, anchored at `from`: the point of the ground at the two
    /// points' distance, on `c`'s side of `reference` ([`search`]'s rigid
    /// anchors).
    fn anchor_at_distance(
        &self,
        data: &RunData<Self>,
        reference: usize,
        from: <Self::State as ContactMode>::Anchor,
        c: usize,
    ) -> <Self::State as ContactMode>::Anchor;
    /// After a converged solve, models whose contact rows solve stick/slip
    /// and lift-off in the step (complementarity rows) read the states
    /// from the solution: `true` when a point must be solved again in
    /// another state (a sticking point that slides: its friction drops
    /// from μS to μD). States whose equations the solution already
    /// satisfies (a stopped slide, a lift-off) change without a new solve.
    fn complementarity_switches(&self, _data: &mut RunData<Self>) -> bool {
        false
    }
    /// After a failed Newton solve: changes the trial states so that the
    /// search may go on (`true`), or gives up (`false`, the default).
    fn newton_fallback(&self, _data: &mut RunData<Self>) -> bool {
        false
    }
    /// After a converged solve: moves the fixed friction directions of
    /// slides that keep one ([`Engine::newton_fallback`]) to the slip the
    /// solution found, when they differ (`true`: solve again). Iterated,
    /// the fixed direction converges to the step's own slip direction, the
    /// solution of the implicit law that Newton could not reach directly.
    fn refine_directions(&self, _data: &mut RunData<Self>) -> bool {
        false
    }
    /// The kinematics at `q[k−1]` from `data.q_prev`.
    fn set_previous(&self, data: &mut RunData<Self>);
    /// The kinematics of the step's start again (`grid_q`, `grid_q_prev`)
    /// after a failed attempt in substeps.
    fn reset_kinematics(&self, data: &mut RunData<Self>);
    /// Fills `data.record` for the solved (sub)step of length `h`.
    fn make_record(&self, data: &mut RunData<Self>, iterations: usize, trials: usize, h: f64);
    /// Instead of [`Self::make_record`] for a step whose record nobody
    /// reads: what the record's making computes that the next step needs.
    fn skip_record(&self, _data: &mut RunData<Self>, _h: f64) {}
    /// Adds a later substep's iterations and solves to the record.
    fn add_to_record(record: &mut Self::Record, iterations: usize, trials: usize);
    /// Stage 6's model part: the assembly's state moves to the next
    /// (sub)step.
    fn advance(&self, data: &mut RunData<Self>);
    /// After a step solved whole has been accepted.
    fn accepted_whole(&self, _data: &mut RunData<Self>) {}
}

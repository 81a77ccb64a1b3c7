//! The stepping loop of a whole run.

use crate::record::{Event, LimitEvent, RetryEvent};
use crate::robot::RobotRecord;
use crate::{Data, Model, SimError};
use std::sync::atomic::AtomicBool;

/// Outcome of [`run`].
#[derive(Clone, Debug, Default)]
pub struct RunSummary {
    /// Steps solved.
    pub steps: usize,
    /// Newton iterations over all steps (chord steps included).
    pub newton_iterations: usize,
    /// Most Newton iterations of one step (all its state trials and
    /// substeps).
    pub max_newton_iterations: usize,
    /// Of [`Self::newton_iterations`], the chord steps: steps taken with a
    /// factorisation kept from an earlier iterate or step.
    pub chord_iterations: usize,
    /// Numeric LU factorisations over all steps.
    pub numeric_factorizations: u64,
    /// Wall time of the stepping loop alone (s): the loop's time without
    /// the observer's (the time inside [`crate::step()`]).
    pub wall_seconds: f64,
    /// Symbolic factorisations (one per contact-state pattern met, again
    /// after its eviction).
    pub symbolic_factorizations: usize,
    /// Patterns evicted from the solver's bounded cache
    /// (`NewtonParams::max_patterns`).
    pub evicted_patterns: usize,
    /// Contact events.
    pub events: Vec<Event>,
    /// Why the run stopped early, if it did.
    pub error: Option<SimError>,
    /// Joint-limit events.
    pub limit_events: Vec<LimitEvent>,
    /// Steps that were solved in substeps (see [`crate::step`]).
    pub retries: Vec<RetryEvent>,
    /// State searches that cycled and were closed by their least
    /// inconsistent combination (see [`crate::step`]).
    pub resolved_cycles: usize,
    /// State searches that cycled and were closed by a consistent
    /// combination found by trying every combination of the points
    /// involved.
    pub enumerated_cycles: usize,
    /// Solutions consistent by the switching rules that broke a law (the
    /// law audit) and were solved again in substeps.
    pub rejected_solutions: usize,
    /// Failed Newton solves the state search recovered from by changing
    /// the trial states.
    pub newton_fallbacks: usize,
    /// Crawling Newton solves given up because a free point was already
    /// below the ground at their kept iterate: the search touched it down
    /// and solved again (3D models).
    pub abandoned_crawls: usize,
    /// Substeps solved in retries, failed attempts included.
    pub substeps: usize,
    /// Re-solves that moved a fixed friction direction to the step's own
    /// slip (a slide Newton could not solve with the implicit direction).
    pub direction_refinements: usize,
    /// Accepted slides whose slip ran against their reference direction:
    /// in 3D a slide turning back (its friction follows the slip: lawful);
    /// in the plane a slide kept in ST3 running backwards (the planar
    /// model is not audited: its friction then pushes along the slip).
    pub backward_slides: usize,
    /// The largest violation of a contact or joint-limit law (N) over the
    /// written solutions: at most the model's cycle tolerance (1e-7 of the
    /// weight).
    pub max_law_violation: f64,
    /// `true` when the `stop` flag of [`run_until`] ended the run before
    /// its last step (the steps solved so far are valid).
    pub interrupted: bool,
}

impl RunSummary {
    /// Steps per second of wall time.
    pub fn steps_per_second(&self) -> f64 {
        if self.wall_seconds > 0.0 {
            self.steps as f64 / self.wall_seconds
        } else {
            0.0
        }
    }
}

/// Runs `model` from its initial state to the end (or the first error),
/// handing every `stride`-th record to `on_row`.
pub fn run(model: &Model, on_row: impl FnMut(&RobotRecord)) -> RunSummary {
    run_until(model, &AtomicBool::new(false), on_row)
}

/// [`run`], stopping before the next step once `stop` is set (e.g. by a
/// signal handler); the summary then says `interrupted`
/// ([`crate::engine::run::run_until`]).
pub fn run_until(model: &Model, stop: &AtomicBool, on_row: impl FnMut(&RobotRecord)) -> RunSummary {
    crate::engine::run::run_until(model, Data::new(model), stop, on_row)
}

/// Runs `model` and keeps every written record in memory (for tests and
/// small runs).
pub fn run_collect(model: &Model) -> (Vec<RobotRecord>, RunSummary) {
    let mut rows = Vec::with_capacity(model.steps / model.params.stride.max(1) + 1);
    let summary = run(model, |r| rows.push(r.clone()));
    (rows, summary)
}

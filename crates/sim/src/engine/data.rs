//! The mutable workspace of a run of any model ([`RunData`]): what the
//! generic step keeps, sized from the model's layout, plus the model's own
//! assembly workspace, record and controller state.

use super::Engine;
use crate::predictor::Predictor;
use crate::record::{Event, LimitEvent, RetryEvent};
use fbd_contact::ContactMode;
use fbd_dynamics::LimitState;
use fbd_solver::NewtonSolver;

/// Everything that changes during a run. All buffers are allocated when it
/// is built, once; the stepping loop reuses them. The planar
/// [`crate::Data`] and the spatial [`crate::spatial::SpatialData`] are this
/// type for their models.
pub struct RunData<M: Engine> {
    /// Index of the next step to solve.
    pub k: usize,
    /// `q[k−1]` (meaningful for `k ≥ 1`).
    pub q_prev: Vec<f64>,
    /// `q[k−2]` (meaningful for `k ≥ 2`; the predictor's third point).
    pub q_prev2: Vec<f64>,
    /// `q[k]`.
    pub q: Vec<f64>,
    /// Unknowns of the step: `[q[k+1] | joint reactions | contact forces |
    /// stop moments]`; the last solution.
    pub z: Vec<f64>,
    /// State each contact point was last solved in (accepted).
    pub states: Vec<M::State>,
    /// The FBD assembly's workspace.
    pub fbd: M::Fbd,
    /// Newton solver with its cached factorisations.
    pub solver: NewtonSolver,
    /// Contact events so far.
    pub events: Vec<Event>,
    /// State of each joint limit (order of the mechanism's limits), accepted.
    pub limit_states: Vec<LimitState>,
    /// Joint-limit events so far.
    pub limit_events: Vec<LimitEvent>,
    /// Steps solved in substeps so far.
    pub retries: Vec<RetryEvent>,
    /// Newton iterations so far (chord steps included).
    pub newton_iterations: usize,
    /// Of [`Self::newton_iterations`], the chord steps (a factorisation
    /// kept from an earlier iterate or step, see
    /// [`fbd_solver::NewtonParams::chord_steps`]).
    pub chord_iterations: usize,
    /// Most Newton iterations of one step so far (all its state trials and
    /// substeps).
    pub max_step_iterations: usize,
    /// State searches that cycled and were closed by their least
    /// inconsistent trial.
    pub resolved_cycles: usize,
    /// State searches that cycled and were closed by a consistent
    /// combination found by trying every combination of the points and
    /// joint limits involved (see [`super::search`]).
    pub enumerated_cycles: usize,
    /// Solutions consistent by the switching rules that the law audit
    /// rejected ([`super::search`]): the step was retried.
    pub rejected_solutions: usize,
    /// Failed Newton solves after which the search changed the trial
    /// states and went on ([`Engine::newton_fallback`]).
    pub newton_fallbacks: usize,
    /// Crawling solves given up at a certain touchdown, after which the
    /// search touched the points down and went on ([`super::search`]).
    pub abandoned_crawls: usize,
    /// Re-solves that moved a fixed friction direction to the step's slip
    /// ([`Engine::refine_directions`]).
    pub direction_refinements: usize,
    /// Accepted slides whose slip ran against their reference direction:
    /// in 3D a slide turning back (its friction follows the slip: lawful);
    /// in the plane a slide kept in ST3 running backwards (the planar
    /// model is not audited: its friction then pushes along the slip).
    pub backward_slides: usize,
    /// Substeps solved over all retries (all attempts, failed ones
    /// included).
    pub substeps: usize,
    /// The largest law violation (N) of the accepted solutions (at most the
    /// model's cycle tolerance).
    pub max_law_violation: f64,
    /// Joint torques applied at the next step instead of the controller's,
    /// when `Some`; kept until changed. For controllers outside the
    /// simulator.
    pub external_torque: Option<M::Torques>,
    /// The predictor of each step's unknowns ([`crate::predictor`]).
    pub predictor: Predictor,
    /// The record of the last step (refilled every step).
    pub record: M::Record,
    /// The controller's workspace.
    pub(crate) control: M::ControlData,
    /// Per-row convergence scales of the current trial states.
    pub(crate) scales: Vec<f64>,
    /// Their reciprocals.
    pub(crate) weights: Vec<f64>,
    /// Trial states of the state search.
    pub(crate) trial: Vec<M::State>,
    /// Trial states of the joint limits.
    pub(crate) limit_trial: Vec<LimitState>,
    /// State combinations visited in the current (sub)step's search.
    pub(crate) visited: Vec<u64>,
    /// Per contact, bit `i` set when the point was solved in state code `i`
    /// (0 = ST1, 1 = ST2, 2 = ST3) during the current search.
    pub(crate) seen: Vec<u8>,
    /// Per contact, the tangential force of its last sticking trial.
    pub(crate) stick_ft: Vec<<M::State as ContactMode>::Tangent>,
    /// Per contact, the anchor of its last sticking trial (meaningful when
    /// bit 1 of `seen` is set).
    pub(crate) stick_anchor: Vec<<M::State as ContactMode>::Anchor>,
    /// Per contact, whether the point slides since a step whose search
    /// tried sticking it and needed more than μS·N: while its slip runs
    /// forward it is not tried again ([`super::search`]).
    pub(crate) stick_refused: Vec<bool>,
    /// Per contact, the ST2 state of a slide that has stopped, from the last
    /// check of the switching rules (`None`: no such end).
    pub(crate) stops: Vec<Option<M::State>>,
    /// `stick_refused` at the step's start, kept for a retry in substeps.
    pub(crate) grid_stick_refused: Vec<bool>,
    /// The step's start, kept for a retry in substeps: `q[k]`, `q[k−1]`,
    /// `q[k−2]`, the accepted states and the event counts.
    pub(crate) grid_q: Vec<f64>,
    pub(crate) grid_q_prev: Vec<f64>,
    pub(crate) grid_q_prev2: Vec<f64>,
    pub(crate) grid_states: Vec<M::State>,
    pub(crate) grid_limits: Vec<LimitState>,
    pub(crate) grid_events: [usize; 2],
    /// The trial states at which the whole step failed (for the error).
    pub(crate) failed_trial: Vec<M::State>,
    pub(crate) failed_limits: Vec<LimitState>,
    /// The unknowns the (sub)step's search started from (the predictor).
    pub(crate) start_z: Vec<f64>,
    /// The (sub)step's first start, kept when a fallback moves `start_z`
    /// (the spatial active-set fallback starts from the failed iterate
    /// first, then from here).
    pub(crate) origin_z: Vec<f64>,
    /// The search's least inconsistent trial so far (see
    /// [`super::search`]): its violation (N), unknowns and states.
    pub(crate) best_violation: f64,
    pub(crate) best_z: Vec<f64>,
    pub(crate) best_trial: Vec<M::State>,
    pub(crate) best_limits: Vec<LimitState>,
    /// The states a solution was solved in, kept while the switching rules
    /// change the trial ones.
    pub(crate) checked_trial: Vec<M::State>,
    pub(crate) checked_limits: Vec<LimitState>,
    /// Set while solving the finest substeps of a retried step (a model
    /// without [`super::Settings::exact`] then closes a cycling search by
    /// its least inconsistent trial).
    pub(crate) last_resort: bool,
    /// Whether the next step's record is made (`true` unless a run skips
    /// the rows it does not hand out, [`super::run::run_until`]).
    pub(crate) want_record: bool,
    /// Whether that record is whole (`true` unless a run hands out records
    /// that are observed but not written, [`super::run::run_in_written`]:
    /// those leave out what no observer of them reads).
    pub(crate) whole_record: bool,
}

/// What a model gives [`RunData::build`].
pub(crate) struct Parts<M: Engine> {
    /// `q[0]`.
    pub q0: Vec<f64>,
    /// Unknowns of the system.
    pub dim: usize,
    /// Joint limits.
    pub limits: usize,
    /// Contact states at `t = 0`.
    pub initial_states: Vec<M::State>,
    pub fbd: M::Fbd,
    pub solver: NewtonSolver,
    pub record: M::Record,
    pub control: M::ControlData,
}

impl<M: Engine> RunData<M> {
    /// A fresh workspace at `q[0]`, every buffer sized here.
    pub(crate) fn build(parts: Parts<M>) -> Self {
        let Parts {
            q0,
            dim,
            limits,
            initial_states,
            fbd,
            solver,
            record,
            control,
        } = parts;
        let contacts = initial_states.len();
        let mut z = vec![0.0; dim];
        z[..q0.len()].copy_from_slice(&q0);
        let free = vec![LimitState::Free; limits];
        Self {
            k: 0,
            q_prev: q0.clone(),
            q_prev2: q0.clone(),
            predictor: Predictor::new(&q0, &z),
            z,
            states: initial_states.clone(),
            fbd,
            solver,
            events: Vec::with_capacity(64),
            limit_states: free.clone(),
            limit_events: Vec::with_capacity(64),
            retries: Vec::with_capacity(16),
            newton_iterations: 0,
            chord_iterations: 0,
            max_step_iterations: 0,
            resolved_cycles: 0,
            enumerated_cycles: 0,
            rejected_solutions: 0,
            newton_fallbacks: 0,
            abandoned_crawls: 0,
            substeps: 0,
            direction_refinements: 0,
            backward_slides: 0,
            max_law_violation: 0.0,
            external_torque: None,
            record,
            control,
            scales: vec![1.0; dim],
            weights: vec![1.0; dim],
            trial: initial_states.clone(),
            limit_trial: free.clone(),
            visited: Vec::with_capacity(64),
            seen: vec![0; contacts],
            stick_ft: vec![Default::default(); contacts],
            stick_anchor: vec![Default::default(); contacts],
            stick_refused: vec![false; contacts],
            stops: vec![None; contacts],
            grid_stick_refused: vec![false; contacts],
            grid_q: q0.clone(),
            grid_q_prev: q0.clone(),
            grid_q_prev2: q0.clone(),
            grid_states: initial_states.clone(),
            grid_limits: free.clone(),
            grid_events: [0, 0],
            failed_trial: initial_states.clone(),
            failed_limits: free.clone(),
            start_z: vec![0.0; dim],
            origin_z: vec![0.0; dim],
            best_violation: f64::INFINITY,
            best_z: vec![0.0; dim],
            checked_trial: initial_states.clone(),
            checked_limits: free.clone(),
            best_trial: initial_states,
            best_limits: free,
            last_resort: false,
            want_record: true,
            whole_record: true,
            q: q0,
        }
    }

    /// Symbolic factorisations done so far (one per contact-state pattern).
    pub fn symbolic_factorizations(&self) -> usize {
        self.solver.symbolic_factorizations()
    }
}

/// A clone is the whole state of the run: stepping the clone gives, bit
/// for bit, what stepping the original would (the solver's kept
/// factorisations included); the stepping API's `state()`
/// ([`crate::simulator`]).
impl<M: Engine> Clone for RunData<M>
where
    M::Fbd: Clone,
    M::Record: Clone,
    M::Torques: Clone,
    M::ControlData: Clone,
{
    fn clone(&self) -> Self {
        Self {
            k: self.k,
            q_prev: self.q_prev.clone(),
            q_prev2: self.q_prev2.clone(),
            q: self.q.clone(),
            z: self.z.clone(),
            states: self.states.clone(),
            fbd: self.fbd.clone(),
            solver: self.solver.clone(),
            events: self.events.clone(),
            limit_states: self.limit_states.clone(),
            limit_events: self.limit_events.clone(),
            retries: self.retries.clone(),
            newton_iterations: self.newton_iterations,
            chord_iterations: self.chord_iterations,
            max_step_iterations: self.max_step_iterations,
            resolved_cycles: self.resolved_cycles,
            enumerated_cycles: self.enumerated_cycles,
            rejected_solutions: self.rejected_solutions,
            newton_fallbacks: self.newton_fallbacks,
            abandoned_crawls: self.abandoned_crawls,
            direction_refinements: self.direction_refinements,
            backward_slides: self.backward_slides,
            substeps: self.substeps,
            max_law_violation: self.max_law_violation,
            external_torque: self.external_torque.clone(),
            predictor: self.predictor.clone(),
            record: self.record.clone(),
            control: self.control.clone(),
            scales: self.scales.clone(),
            weights: self.weights.clone(),
            trial: self.trial.clone(),
            limit_trial: self.limit_trial.clone(),
            visited: self.visited.clone(),
            seen: self.seen.clone(),
            stick_ft: self.stick_ft.clone(),
            stick_anchor: self.stick_anchor.clone(),
            stick_refused: self.stick_refused.clone(),
            stops: self.stops.clone(),
            grid_stick_refused: self.grid_stick_refused.clone(),
            grid_q: self.grid_q.clone(),
            grid_q_prev: self.grid_q_prev.clone(),
            grid_q_prev2: self.grid_q_prev2.clone(),
            grid_states: self.grid_states.clone(),
            grid_limits: self.grid_limits.clone(),
            grid_events: self.grid_events,
            failed_trial: self.failed_trial.clone(),
            failed_limits: self.failed_limits.clone(),
            start_z: self.start_z.clone(),
            origin_z: self.origin_z.clone(),
            best_violation: self.best_violation,
            best_z: self.best_z.clone(),
            best_trial: self.best_trial.clone(),
            best_limits: self.best_limits.clone(),
            checked_trial: self.checked_trial.clone(),
            checked_limits: self.checked_limits.clone(),
            last_resort: self.last_resort,
            want_record: self.want_record,
            whole_record: self.whole_record,
        }
    }
}

impl<M: Engine> std::fmt::Debug for RunData<M>
where
    M::State: std::fmt::Debug,
{
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("RunData")
            .field("k", &self.k)
            .field("q", &self.q)
            .field("states", &self.states)
            .field("limit_states", &self.limit_states)
            .field("newton_iterations", &self.newton_iterations)
            .finish_non_exhaustive()
    }
}

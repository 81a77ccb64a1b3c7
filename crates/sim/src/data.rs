//! The mutable workspace of a run ([`Data`]), built from a [`Model`].

use crate::Model;
use crate::predictor::Predictor;
use crate::record::{Event, LimitEvent, RetryEvent};
use fbd_contact::ContactState;
use fbd_dynamics::{FbdData, LimitState};
use fbd_solver::NewtonSolver;

/// Everything that changes during a run. All buffers are allocated here,
/// once; the stepping loop reuses them.
#[derive(Debug)]
pub struct Data {
    /// Index of the next step to solve.
    pub k: usize,
    /// `q[k−1]` (meaningful for `k ≥ 1`).
    pub q_prev: Vec<f64>,
    /// `q[k−2]` (meaningful for `k ≥ 2`; the predictor's third point).
    pub q_prev2: Vec<f64>,
    /// `q[k]`.
    pub q: Vec<f64>,
    /// Unknowns of the step: `[q[k+1] | joint forces | contact forces]`; the
    /// last solution, reused as the next step's starting guess for the forces.
    pub z: Vec<f64>,
    /// State each contact point was last solved in (accepted).
    pub states: Vec<ContactState>,
    /// FBD assembly workspace.
    pub fbd: FbdData,
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
    /// Joint torques (N·m, joint order) applied at the next step instead of
    /// the controller's, when `Some` ([`crate::control::joint_torques`]);
    /// kept until changed. For controllers outside the simulator.
    pub external_torque: Option<[f64; crate::record::MAX_JOINTS]>,
    /// Per-row convergence scales of the current contact states.
    pub(crate) scales: Vec<f64>,
    /// Their reciprocals.
    pub(crate) weights: Vec<f64>,
    /// The predictor's histories of the accepted steps.
    pub(crate) predictor: Predictor,
    /// Trial states of the state search.
    pub(crate) trial: Vec<ContactState>,
    /// State combinations visited in the current step's search.
    pub(crate) visited: Vec<u64>,
    /// Per contact, bit `i` set when the point was solved in state code `i`
    /// (0 = ST1, 1 = ST2, 2 = ST3) during the current step's search.
    pub(crate) seen: Vec<u8>,
    /// Per contact, the tangential force of its last sticking trial.
    pub(crate) stick_fa: Vec<f64>,
    /// Per contact, the anchor of its last sticking trial (meaningful when
    /// bit 1 of `seen` is set).
    pub(crate) stick_anchor: Vec<[f64; 2]>,
    /// Trial states of the joint limits.
    pub(crate) limit_trial: Vec<LimitState>,
    /// The step's start, kept for a retry in substeps: `q[k]`, `q[k−1]`,
    /// `q[k−2]`, the accepted states and the event counts.
    pub(crate) grid_q: Vec<f64>,
    pub(crate) grid_q_prev: Vec<f64>,
    pub(crate) grid_q_prev2: Vec<f64>,
    pub(crate) grid_states: Vec<ContactState>,
    pub(crate) grid_limits: Vec<LimitState>,
    pub(crate) grid_events: [usize; 2],
    /// The trial states at which the whole step failed (for the error).
    pub(crate) failed_trial: Vec<ContactState>,
    pub(crate) failed_limits: Vec<LimitState>,
    /// The state search's least inconsistent trial so far (see
    /// `step::violation`): its violation (N), unknowns and states.
    pub(crate) best_violation: f64,
    pub(crate) best_z: Vec<f64>,
    pub(crate) best_trial: Vec<ContactState>,
    pub(crate) best_limits: Vec<LimitState>,
    /// State searches that cycled and were closed by their least
    /// inconsistent trial.
    pub resolved_cycles: usize,
    /// State searches that cycled and were closed by a consistent
    /// combination found by trying every combination of the points and
    /// joint limits involved (see [`crate::step`]).
    pub enumerated_cycles: usize,
    /// Set while solving the finest substeps of a retried step.
    pub(crate) last_resort: bool,
}

impl Data {
    /// A fresh workspace at the model's initial state.
    pub fn new(model: &Model) -> Self {
        let mech = &model.mech;
        let lay = mech.layout();
        let mut fbd = FbdData::new(mech);
        fbd_dynamics::set_configuration(mech, &mut fbd, &model.params.q0);
        let mut z = vec![0.0; lay.dim()];
        z[..lay.nq].copy_from_slice(&model.params.q0);
        let predictor = Predictor::new(&model.params.q0, &z);
        Self {
            k: 0,
            q_prev: model.params.q0.to_vec(),
            q_prev2: model.params.q0.to_vec(),
            q: model.params.q0.to_vec(),
            z,
            states: model.initial_states.clone(),
            fbd,
            solver: NewtonSolver::new(model.newton),
            events: Vec::with_capacity(64),
            newton_iterations: 0,
            chord_iterations: 0,
            max_step_iterations: 0,
            external_torque: None,
            scales: vec![1.0; lay.dim()],
            weights: vec![1.0; lay.dim()],
            predictor,
            trial: model.initial_states.clone(),
            visited: Vec::with_capacity(64),
            seen: vec![0; lay.contacts],
            stick_fa: vec![0.0; lay.contacts],
            stick_anchor: vec![[0.0; 2]; lay.contacts],
            limit_states: vec![LimitState::Free; lay.limits],
            limit_events: Vec::with_capacity(64),
            retries: Vec::with_capacity(16),
            limit_trial: vec![LimitState::Free; lay.limits],
            grid_q: model.params.q0.to_vec(),
            grid_q_prev: model.params.q0.to_vec(),
            grid_q_prev2: model.params.q0.to_vec(),
            grid_states: model.initial_states.clone(),
            grid_limits: vec![LimitState::Free; lay.limits],
            grid_events: [0, 0],
            failed_trial: model.initial_states.clone(),
            failed_limits: vec![LimitState::Free; lay.limits],
            best_violation: f64::INFINITY,
            best_z: vec![0.0; lay.dim()],
            best_trial: model.initial_states.clone(),
            best_limits: vec![LimitState::Free; lay.limits],
            resolved_cycles: 0,
            enumerated_cycles: 0,
            last_resort: false,
        }
    }

    /// Symbolic factorisations done so far (one per contact-state pattern).
    pub fn symbolic_factorizations(&self) -> usize {
        self.solver.symbolic_factorizations()
    }

    /// Time of the next step to solve (s).
    pub fn time(&self, model: &Model) -> f64 {
        self.k as f64 * model.dt()
    }
}

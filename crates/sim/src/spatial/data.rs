//! The mutable workspace of a spatial run, built from a [`SpatialModel`].

use super::model::SpatialModel;
use super::record::{ContactRow, LegRow, SpatialRecord};
use crate::gait::GaitData;
use crate::record::{Event, LimitEvent, RetryEvent};
use crate::spatial::params::SpatialControl;
use fbd_contact::{SpatialState, StateCode};
use fbd_dynamics::LimitState;
use fbd_dynamics::spatial::{SpatialFbdData, set_configuration};
use fbd_solver::NewtonSolver;

/// Everything that changes during a spatial run; every buffer is allocated
/// here, once.
#[derive(Debug)]
pub struct SpatialData {
    /// Index of the next step to solve.
    pub k: usize,
    /// `q[k−1]`.
    pub q_prev: Vec<f64>,
    /// `q[k−2]`.
    pub q_prev2: Vec<f64>,
    /// `q[k]`.
    pub q: Vec<f64>,
    /// Unknowns of the step (last solution).
    pub z: Vec<f64>,
    /// Accepted contact states.
    pub states: Vec<SpatialState>,
    /// Assembly workspace.
    pub fbd: SpatialFbdData,
    /// Newton solver with its cached factorisations.
    pub solver: NewtonSolver,
    /// Contact events so far.
    pub events: Vec<Event>,
    /// Accepted joint-limit states.
    pub limit_states: Vec<LimitState>,
    /// Joint-limit events so far.
    pub limit_events: Vec<LimitEvent>,
    /// Steps solved in substeps so far.
    pub retries: Vec<RetryEvent>,
    /// Newton iterations so far.
    pub newton_iterations: usize,
    /// Of the Newton iterations, the chord steps (a factorisation reused).
    pub chord_iterations: usize,
    /// Most Newton iterations of one step so far.
    pub max_step_iterations: usize,
    /// Cycling state searches closed by their least inconsistent trial.
    pub resolved_cycles: usize,
    /// Joint torques `(τ1, τ2, τ3)` per leg applied at the next step
    /// instead of the controller's, when `Some` (kept until changed).
    pub external_torque: Option<Vec<[f64; 3]>>,
    /// The predictor of each step's unknowns ([`crate::predictor`]).
    pub predictor: crate::predictor::Predictor,
    /// The record of the last step (refilled every step).
    pub record: SpatialRecord,
    /// The gait generator's workspace (gait control only).
    pub(crate) gait: Option<Box<GaitData>>,
    pub(crate) scales: Vec<f64>,
    pub(crate) trial: Vec<SpatialState>,
    pub(crate) limit_trial: Vec<LimitState>,
    pub(crate) visited: Vec<u64>,
    pub(crate) seen: Vec<u8>,
    pub(crate) stick_ft: Vec<[f64; 2]>,
    pub(crate) grid_q: Vec<f64>,
    pub(crate) grid_q_prev: Vec<f64>,
    pub(crate) grid_q_prev2: Vec<f64>,
    pub(crate) grid_states: Vec<SpatialState>,
    pub(crate) grid_limits: Vec<LimitState>,
    pub(crate) grid_events: [usize; 2],
    pub(crate) failed_trial: Vec<SpatialState>,
    pub(crate) best_violation: f64,
    pub(crate) best_z: Vec<f64>,
    /// The unknowns the (sub)step's search started from (the predictor).
    pub(crate) start_z: Vec<f64>,
    pub(crate) best_trial: Vec<SpatialState>,
    pub(crate) best_limits: Vec<LimitState>,
    pub(crate) last_resort: bool,
}

impl SpatialData {
    /// A fresh workspace at the model's initial state.
    pub fn new(model: &SpatialModel) -> Self {
        let mech = &model.mech;
        let lay = mech.layout();
        let q0 = &model.params.q0;
        let mut fbd = SpatialFbdData::new(mech);
        set_configuration(mech, &mut fbd, q0);
        let mut z = vec![0.0; lay.dim()];
        z[..lay.nq].copy_from_slice(q0);
        let record = SpatialRecord {
            step: 0,
            t: 0.0,
            q: q0.clone(),
            contacts: mech
                .contacts
                .iter()
                .map(|c| ContactRow {
                    leg: c.leg,
                    kind: c.kind,
                    point: [0.0; 3],
                    state: StateCode::St1,
                    force: [0.0; 3],
                    normal: 0.0,
                })
                .collect(),
            legs: mech
                .legs
                .iter()
                .map(|&leg| LegRow {
                    leg,
                    ..LegRow::default()
                })
                .collect(),
            kinetic: 0.0,
            potential: 0.0,
            momentum: [0.0; 3],
            angular_momentum: [0.0; 3],
            newton_iterations: 0,
            state_trials: 0,
        };
        let gait = match &model.params.control {
            SpatialControl::Gait { gait, .. } => Some(Box::new(GaitData::new(gait))),
            _ => None,
        };
        let free = vec![LimitState::Free; lay.limits];
        let predictor = crate::predictor::Predictor::new(q0, &z);
        Self {
            k: 0,
            q_prev: q0.clone(),
            q_prev2: q0.clone(),
            q: q0.clone(),
            z,
            states: model.initial_states.clone(),
            fbd,
            solver: NewtonSolver::new(model.newton),
            events: Vec::with_capacity(64),
            limit_states: free.clone(),
            limit_events: Vec::with_capacity(64),
            retries: Vec::with_capacity(16),
            newton_iterations: 0,
            chord_iterations: 0,
            max_step_iterations: 0,
            resolved_cycles: 0,
            external_torque: None,
            predictor,
            record,
            gait,
            scales: vec![1.0; lay.dim()],
            trial: model.initial_states.clone(),
            limit_trial: free.clone(),
            visited: Vec::with_capacity(64),
            seen: vec![0; lay.contacts],
            stick_ft: vec![[0.0; 2]; lay.contacts],
            grid_q: q0.clone(),
            grid_q_prev: q0.clone(),
            grid_q_prev2: q0.clone(),
            grid_states: model.initial_states.clone(),
            grid_limits: free.clone(),
            grid_events: [0, 0],
            failed_trial: model.initial_states.clone(),
            best_violation: f64::INFINITY,
            best_z: vec![0.0; lay.dim()],
            start_z: vec![0.0; lay.dim()],
            best_trial: model.initial_states.clone(),
            best_limits: free,
            last_resort: false,
        }
    }

    /// Symbolic factorisations so far (one per contact-state pattern).
    pub fn symbolic_factorizations(&self) -> usize {
        self.solver.symbolic_factorizations()
    }
}

//! Errors of a simulation.

use fbd_kinematics::num::Fixed;
use fbd_solver::SolverError;

/// Why a model could not be built or a run stopped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// A parameter is out of its domain. `key` is the configuration key
    /// (docs/reference.md), e.g. `leg.upper_mass`.
    #[error("{key}: {what} (got {got}, expected {expected})")]
    InvalidParameter {
        /// Dotted configuration key.
        key: String,
        /// What is wrong.
        what: String,
        /// The offending value.
        got: String,
        /// What is accepted.
        expected: String,
    },
    /// A contact point starts below the terrain.
    #[error(
        "initial.{leg}: {point} starts {} m below the terrain (got depth {} m, expected ≤ 1e-9 m)",
        Fixed(*depth, 6), Fixed(*depth, 6)
    )]
    InitialPenetration {
        /// The leg table, e.g. `leg3`.
        leg: String,
        /// The point, e.g. `tip3`.
        point: String,
        /// How deep (m).
        depth: f64,
    },
    /// Newton's method failed.
    #[error("step {step} (t = {} s): {source}", Fixed(*t, 6))]
    Newton {
        /// Step index k.
        step: usize,
        /// Time k·Δt (s).
        t: f64,
        /// The solver's error (names the residual).
        source: SolverError,
    },
    /// The contact-state search revisited a state combination.
    #[error("step {step} (t = {} s): the contact-state search cycles at [{states}] (residual {residual:.3e})", Fixed(*t, 6))]
    Cycling {
        /// Step index k.
        step: usize,
        /// Time k·Δt (s).
        t: f64,
        /// The state combination seen twice, e.g. `tip3=ST2 tip4=ST3`.
        states: String,
        /// Scaled residual of the last solve.
        residual: f64,
    },
    /// The controller could not compute its torques (e.g. the gait
    /// generator cannot place a foot).
    #[error("step {step} (t = {} s): control: {message}", Fixed(*t, 6))]
    Control {
        /// Step index k.
        step: usize,
        /// Time k·Δt (s).
        t: f64,
        /// What failed.
        message: String,
    },
    /// No state combination of the step, down to its finest substeps,
    /// obeys every contact and joint-limit law: the step is not written
    /// rather than written inexactly.
    #[error("step {step} (t = {} s): no exact solution down to Δt/{substeps}: {point} breaks {law} by {amount:.3e} N (states [{states}])", Fixed(*t, 6))]
    Inexact {
        /// Step index k.
        step: usize,
        /// Time k·Δt (s).
        t: f64,
        /// The finest subdivision tried.
        substeps: usize,
        /// The contact point (e.g. `tip5`) or joint (e.g. `theta2_3`).
        point: String,
        /// The law it breaks, e.g. `N ≥ 0`.
        law: String,
        /// By how much, as a force (N).
        amount: f64,
        /// The state combination of the best solution.
        states: String,
    },
    /// The state became NaN or infinite.
    #[error("step {step} (t = {} s): the state is not finite (residual {residual:.3e})", Fixed(*t, 6))]
    NonFinite {
        /// Step index k.
        step: usize,
        /// Time k·Δt (s).
        t: f64,
        /// Scaled residual of the last solve.
        residual: f64,
    },
}

impl SimError {
    /// The step at which a run-time error occurred (`None` for set-up
    /// errors).
    pub fn step(&self) -> Option<usize> {
        match self {
            SimError::Newton { step, .. }
            | SimError::Cycling { step, .. }
            | SimError::NonFinite { step, .. }
            | SimError::Inexact { step, .. }
            | SimError::Control { step, .. } => Some(*step),
            _ => None,
        }
    }
}

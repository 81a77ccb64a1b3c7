//! What one step produces besides its record (the one record of every
//! model, [`crate::robot::RobotRecord`]): the joint limits' codes and the
//! events of contact points, joint limits and retried steps.

use fbd_contact::StateCode;
use fbd_dynamics::PointKind;
use fbd_kinematics::Joint;

/// The state of a joint limit as written to the output files.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum LimitCode {
    /// Inside the range.
    #[default]
    Free,
    /// At the lower end (`min`).
    Min,
    /// At the upper end (`max`).
    Max,
}

impl LimitCode {
    /// The code of a joint limit's state.
    pub fn of(state: &fbd_dynamics::LimitState) -> Self {
        match state.key() {
            0 => LimitCode::Free,
            1 => LimitCode::Min,
            _ => LimitCode::Max,
        }
    }

    /// `"free"`, `"min"` or `"max"`.
    pub fn as_str(self) -> &'static str {
        match self {
            LimitCode::Free => "free",
            LimitCode::Min => "min",
            LimitCode::Max => "max",
        }
    }
}

/// A change of a contact point's state (a row of `events.csv`).
#[derive(Clone, Debug, PartialEq)]
pub struct Event {
    /// Start of the first step solved in the new state (s).
    pub t: f64,
    /// Step index of that step.
    pub step: usize,
    /// Index of the contact point in the mechanism.
    pub contact: usize,
    /// Kind of contact point: tip, knee or hip (with `leg`, the point's
    /// identity; [`PointKind::as_str`] names it in `events.csv`).
    pub point: PointKind,
    /// Hexapod leg number (3 or 4).
    pub leg: usize,
    /// Previous state.
    pub from: StateCode,
    /// New state.
    pub to: StateCode,
}

/// A joint reaching or leaving an end of its range (a row of `events.csv`
/// with `point` = `hip_limit` or `knee_limit`).
#[derive(Clone, Debug, PartialEq)]
pub struct LimitEvent {
    /// Start of the first step solved in the new state (s).
    pub t: f64,
    /// Step index of that step.
    pub step: usize,
    /// Index of the joint in the mechanism.
    pub joint_index: usize,
    /// Which joint of the leg (θ2: hip, θ3: knee).
    pub joint: Joint,
    /// Hexapod leg number (3 or 4).
    pub leg: usize,
    /// Previous state.
    pub from: LimitCode,
    /// New state.
    pub to: LimitCode,
}

impl LimitEvent {
    /// `"hip_limit"` (θ2), `"knee_limit"` (θ3) or `"theta1_limit"`.
    pub fn point(&self) -> &'static str {
        Self::point_of(self.joint)
    }

    /// The `point` of a limit event of `joint` (`events.csv`).
    pub fn point_of(joint: Joint) -> &'static str {
        match joint {
            Joint::Theta1 => "theta1_limit",
            Joint::Theta2 => "hip_limit",
            Joint::Theta3 => "knee_limit",
        }
    }
}

/// A step that was solved in substeps (a row of `events.csv` with `point`
/// = `substeps`).
#[derive(Clone, Debug, PartialEq)]
pub struct RetryEvent {
    /// Start of the step (s).
    pub t: f64,
    /// Step index.
    pub step: usize,
    /// Number of substeps of Δt/`substeps` it took (2, 4, 8, …).
    pub substeps: usize,
    /// Why the step failed whole: `"newton"` (Newton did not converge),
    /// `"cycle"` (the contact-state search found no consistent
    /// combination) or `"non-finite"`.
    pub cause: &'static str,
    /// Solved with faer's pivoting LU (the reference path) after every
    /// attempt with the compiled LU had failed (`NewtonParams::compiled_lu`;
    /// `substeps` is then 1 for the whole step).
    pub reference_lu: bool,
}

//! What one step produces: a fixed-size, allocation-free record, and
//! contact events.

use fbd_contact::StateCode;
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

/// Most contact points a planar record holds (tips, knees, hips of 2 legs).
pub const MAX_CONTACTS: usize = 6;
/// Joints of the planar model (hip3, knee3, hip4, knee4).
pub const MAX_JOINTS: usize = 4;

/// Everything known about step `k` once it is solved. Row `k` of
/// `trajectory.csv` (docs/reference.md).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepRecord {
    /// Step index k.
    pub step: usize,
    /// Time k·Δt (s).
    pub t: f64,
    /// `q[k] = (Rx, Ry, φz, θ2₃, θ3₃, θ2₄, θ3₄)` (m, rad).
    pub q: [f64; 7],
    /// Number of contact points in use (`contacts` entries below are valid).
    pub contacts: usize,
    /// Inertial position of each contact point at `q[k]` (m).
    pub point: [[f64; 2]; MAX_CONTACTS],
    /// State each contact point was solved in at step k.
    pub state: [StateCode; MAX_CONTACTS],
    /// Tangential contact force along the terrain tangent (N).
    pub fa: [f64; MAX_CONTACTS],
    /// Normal contact force along the terrain normal (N).
    pub n: [f64; MAX_CONTACTS],
    /// Joint forces, parent on child, inertial frame (N):
    /// `[hip3, knee3, hip4, knee4]`.
    pub joint_force: [[f64; 2]; MAX_JOINTS],
    /// Joint torques (N·m), same order.
    pub torque: [f64; MAX_JOINTS],
    /// State of each joint's limit at step k, same order.
    pub limit: [LimitCode; MAX_JOINTS],
    /// Moment of each joint's limit stop (N·m, positive towards larger
    /// joint angles; 0 when free), same order.
    pub limit_moment: [f64; MAX_JOINTS],
    /// Kinetic energy at k, from central-difference velocities (J).
    pub kinetic: f64,
    /// Gravitational potential energy at k (J).
    pub potential: f64,
    /// Newton iterations spent on this step (all state trials).
    pub newton_iterations: usize,
    /// Number of solves of this step (1 + state switches).
    pub state_trials: usize,
}

impl StepRecord {
    /// A record of step `step` at time `t` with `contacts` points in use and
    /// every other field zero (states ST1).
    pub fn zeroed(step: usize, t: f64, contacts: usize) -> Self {
        Self {
            step,
            t,
            q: [0.0; 7],
            contacts,
            point: [[0.0; 2]; MAX_CONTACTS],
            state: [StateCode::St1; MAX_CONTACTS],
            fa: [0.0; MAX_CONTACTS],
            n: [0.0; MAX_CONTACTS],
            joint_force: [[0.0; 2]; MAX_JOINTS],
            torque: [0.0; MAX_JOINTS],
            limit: [LimitCode::Free; MAX_JOINTS],
            limit_moment: [0.0; MAX_JOINTS],
            kinetic: 0.0,
            potential: 0.0,
            newton_iterations: 0,
            state_trials: 0,
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
    /// Kind of contact point: `"tip"`, `"knee"` or `"hip"` (with `leg`, the
    /// mechanism's contact name, e.g. `tip4`).
    pub point: &'static str,
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
}

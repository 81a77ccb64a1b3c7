//! What one step produces: a record sized from the model's layout
//! (allocated once, refilled every step), and contact events.

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

/// Everything known about step `k` once it is solved: row `k` of
/// `trajectory.csv` (docs/reference.md). Sized from the model's layout
/// ([`StepRecord::new`]) once per run and refilled every step.
#[derive(Clone, Debug, PartialEq)]
pub struct StepRecord {
    /// Step index k.
    pub step: usize,
    /// Time k·Δt (s).
    pub t: f64,
    /// `q[k]`: body `(Rx, Ry, φz)` then the joint angles in the model's
    /// joint order (m, rad).
    pub q: Vec<f64>,
    /// Inertial position of each contact point at `q[k]` (m), in the
    /// model's contact order.
    pub point: Vec<[f64; 2]>,
    /// State each contact point was solved in at step k.
    pub state: Vec<StateCode>,
    /// Tangential contact force along the terrain tangent (N).
    pub fa: Vec<f64>,
    /// Normal contact force along the terrain normal (N).
    pub n: Vec<f64>,
    /// Joint forces, parent on child, inertial frame (N), in the model's
    /// joint order (the two-leg model: hip3, knee3, hip4, knee4).
    pub joint_force: Vec<[f64; 2]>,
    /// Joint torques (N·m), same order.
    pub torque: Vec<f64>,
    /// State of each joint's limit at step k, same order (free for a joint
    /// without one).
    pub limit: Vec<LimitCode>,
    /// Moment of each joint's limit stop (N·m, positive towards larger
    /// joint angles; 0 when free), same order.
    pub limit_moment: Vec<f64>,
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
    /// A record for a model of `nq` coordinates, `contacts` contact points
    /// and `joints` joints, every value zero (states ST1, limits free).
    pub fn new(nq: usize, contacts: usize, joints: usize) -> Self {
        Self {
            step: 0,
            t: 0.0,
            q: vec![0.0; nq],
            point: vec![[0.0; 2]; contacts],
            state: vec![StateCode::St1; contacts],
            fa: vec![0.0; contacts],
            n: vec![0.0; contacts],
            joint_force: vec![[0.0; 2]; joints],
            torque: vec![0.0; joints],
            limit: vec![LimitCode::Free; joints],
            limit_moment: vec![0.0; joints],
            kinetic: 0.0,
            potential: 0.0,
            newton_iterations: 0,
            state_trials: 0,
        }
    }

    /// Contact points of the record.
    pub fn contacts(&self) -> usize {
        self.state.len()
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

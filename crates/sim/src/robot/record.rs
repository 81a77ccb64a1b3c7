//! What one step of a robot produces: a record sized from the model
//! (allocated once, refilled every step).

use fbd_contact::StateCode;

use crate::record::LimitCode;

/// One contact point's row values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobotContactRow {
    /// Where it touches the ground at `q[k]` (a sphere's lowest point)
    /// (m, inertial).
    pub point: [f64; 3],
    /// State the point was solved in at step k.
    pub state: StateCode,
    /// Force of the ground on the point, inertial frame (N).
    pub force: [f64; 3],
    /// Normal component of that force (N, along the terrain normal).
    pub normal: f64,
}

/// Everything known about step `k` of a robot once it is solved: row `k`
/// of `trajectory.csv`.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotRecord {
    /// Step index k.
    pub step: usize,
    /// Time k·Δt (s).
    pub t: f64,
    /// `q[k]` (m, rad).
    pub q: Vec<f64>,
    /// Per contact point of the mechanism (model order).
    pub contacts: Vec<RobotContactRow>,
    /// Per reaction (`TreeMechanism::reactions`), the force at its first
    /// joint's origin on the child body (N, inertial; the parent gets its
    /// opposite).
    pub reaction_force: Vec<[f64; 3]>,
    /// Per reaction, the moment on the child body about that point:
    /// constraint moments, actuator torques and stop moments (N·m,
    /// inertial).
    pub reaction_moment: Vec<[f64; 3]>,
    /// Per model joint, its actuator torque at k (N·m).
    pub torque: Vec<f64>,
    /// Per model joint, its rate at k (rad/s, backward difference).
    pub rate: Vec<f64>,
    /// Per model joint, its stop's state at k (free for joints without
    /// limits).
    pub limit: Vec<LimitCode>,
    /// Per model joint, its stop moment at k (N·m, along the joint axis on
    /// the child).
    pub stop: Vec<f64>,
    /// Kinetic energy over the step (J, the scheme's).
    pub kinetic: f64,
    /// Gravitational potential energy, mean of k and k+1 (J).
    pub potential: f64,
    /// Total linear momentum over the step k → k+1 (kg·m/s).
    pub momentum: [f64; 3],
    /// Total angular momentum about the origin over the step (kg·m²/s).
    pub angular_momentum: [f64; 3],
    /// Centre of mass of the whole robot at `q[k]` (m).
    pub com: [f64; 3],
    /// Newton iterations of this step (every state trial and substep).
    pub newton_iterations: usize,
    /// State combinations solved in this step.
    pub state_trials: usize,
}

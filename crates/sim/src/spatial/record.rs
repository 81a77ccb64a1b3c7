//! What one spatial step produces: a record sized from the model's layout
//! (allocated once, refilled every step).

use fbd_contact::StateCode;
use fbd_dynamics::PointKind;

use crate::record::LimitCode;

/// One contact point's row values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactRow {
    /// Hexapod leg number (1–6).
    pub leg: usize,
    /// Tip, knee or hip.
    pub kind: PointKind,
    /// Inertial position at `q[k]` (m).
    pub point: [f64; 3],
    /// State the point was solved in at step k.
    pub state: StateCode,
    /// Force of the ground on the point, inertial frame (N).
    pub force: [f64; 3],
    /// Normal component of that force (N, along the terrain normal).
    pub normal: f64,
}

/// One leg's joint values at step k.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LegRow {
    /// Hexapod leg number (1–6).
    pub leg: usize,
    /// Force exerted by the body on the upper link at the hip (N, inertial).
    pub hip_force: [f64; 3],
    /// Moment about the hip point exerted by the body on the upper link,
    /// actuator torques and limit stops included (N·m, inertial).
    pub hip_moment: [f64; 3],
    /// Force of the upper link on the lower link at the knee (N, inertial).
    pub knee_force: [f64; 3],
    /// Moment about the knee point of the upper link on the lower link,
    /// actuator torque and limit stop included (N·m, inertial).
    pub knee_moment: [f64; 3],
    /// Actuator torques `(τ1, τ2, τ3)` (N·m), positive towards larger angles.
    pub torque: [f64; 3],
    /// Joint rates `(θ̇1, θ̇2, θ̇3)` at k (rad/s, backward difference; the
    /// initial rates at k = 0), for the actuator power `τ·θ̇`.
    pub rate: [f64; 3],
    /// Limit state of `(θ1, θ2, θ3)` at step k.
    pub limit: [LimitCode; 3],
}

/// Everything known about spatial step `k` once it is solved: row `k` of
/// `trajectory.csv`.
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialRecord {
    /// Step index k.
    pub step: usize,
    /// Time k·Δt (s).
    pub t: f64,
    /// `q[k]`: `(Rx, Ry, Rz, φx, φy, φz, θ1, θ2, θ3 per leg)` (m, rad).
    pub q: Vec<f64>,
    /// Per contact point, in the model's order (per leg: tip, knee, hip as
    /// enabled).
    pub contacts: Vec<ContactRow>,
    /// Per leg of the model, in the order of `SpatialParams::legs`.
    pub legs: Vec<LegRow>,
    /// Kinetic energy at k (J).
    pub kinetic: f64,
    /// Gravitational potential energy at k (J).
    pub potential: f64,
    /// Total linear momentum at k (kg·m/s).
    pub momentum: [f64; 3],
    /// Total angular momentum about the origin at k (kg·m²/s).
    pub angular_momentum: [f64; 3],
    /// Newton iterations spent on this step (all state trials).
    pub newton_iterations: usize,
    /// Number of solves of this step.
    pub state_trials: usize,
}

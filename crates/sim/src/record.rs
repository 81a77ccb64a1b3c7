//! What one step produces: a fixed-size, allocation-free record, and
//! contact events.

use fbd_contact::StateCode;

/// Most contact points a planar record holds (tips, knees, hips of 2 legs).
pub const MAX_CONTACTS: usize = 6;
/// Joints of the planar model (hip3, knee3, hip4, knee4).
pub const MAX_JOINTS: usize = 4;

/// Everything known about step `k` once it is solved. Row `k` of
/// `trajectory.csv` (SPEC §6).
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
    /// Kinetic energy at k, from central-difference velocities (J).
    pub kinetic: f64,
    /// Gravitational potential energy at k (J).
    pub potential: f64,
    /// Newton iterations spent on this step (all state trials).
    pub newton_iterations: usize,
    /// Number of solves of this step (1 + state switches).
    pub state_trials: usize,
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
    /// Contact point name, e.g. `tip4`.
    pub name: String,
    /// Hexapod leg number (3 or 4).
    pub leg: usize,
    /// Previous state.
    pub from: StateCode,
    /// New state.
    pub to: StateCode,
}

//! The parameters of a robot's run ([`RobotParams`]).

use super::control::RobotControl;
use fbd_contact::{ContactParams, Friction, Surface};

/// Everything a robot's run is built from besides the robot itself.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotParams {
    /// Time step Δt (s). Default 1 ms.
    pub dt: f64,
    /// Simulated time (s): `round(duration/dt) + 1` steps. Default 1 s.
    pub duration: f64,
    /// Gravity (m/s², along −Y). Default 9.81.
    pub gravity: f64,
    /// `q[0]`: base position, rotation vector, joint angles (m, rad).
    pub q0: Vec<f64>,
    /// `q̇0`, the same layout (the base's angular velocity as `φ̇`).
    pub qdot0: Vec<f64>,
    /// The ground; `None` for a run in flight (no contact points at all).
    /// Default flat ground at `y = 0`.
    pub terrain: Option<Surface>,
    /// Coulomb friction of the ground. Default μS = 0.8, μD = 0.6.
    pub friction: Friction,
    /// Contact tolerances (the hexapod's defaults).
    pub contact: ContactParams,
    /// Every `stride`-th step's record is handed out. Default 1.
    pub stride: usize,
    /// Newton's settings (`[solver]`). Default
    /// [`crate::SolverSettings::default`]: 6 chord steps, tolerance 1e-9.
    pub solver: crate::SolverSettings,
    /// The joint controller. Default passive joints.
    pub control: RobotControl,
}

impl RobotParams {
    /// The defaults (documented on the fields) for a robot with `nq`
    /// coordinates at rest at the origin.
    pub fn new(nq: usize) -> Self {
        Self {
            dt: 1e-3,
            duration: 1.0,
            gravity: 9.81,
            q0: vec![0.0; nq],
            qdot0: vec![0.0; nq],
            terrain: Some(Surface::default()),
            friction: Friction {
                mu_static: 0.8,
                mu_dynamic: 0.6,
            },
            contact: ContactParams::default(),
            stride: 1,
            solver: crate::SolverSettings::default(),
            control: RobotControl::None,
        }
    }
}

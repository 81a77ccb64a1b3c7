//! # fbd-sim
//!
//! Composes kinematics, FBD assembly, contact and the Newton solver into a
//! simulation of the paper's planar 7-DOF model.
//!
//! * [`Model`] (immutable, validated from [`PlanarParams`]) and [`Data`]
//!   (the mutable workspace built from it);
//! * [`step`] — one staged time step (kinematics → predictor → solve →
//!   contact check → accept), see [`mod@step`]; the step is one generic
//!   source for the planar and the spatial model ([`engine`]);
//! * [`run`] — the whole loop with per-row callback and a [`RunSummary`].
//! * [`simulator`] — the stepping API for controllers outside the
//!   simulator, every model: actions, state save/restore, readouts.
//! * [`robot`] — any imported robot (URDF, MJCF, D-H rows) on the generic
//!   FBD equations of `fbd_dynamics::tree`, on its terrain or in flight,
//!   with the same step, contact machinery and law audit as the hexapod.
//! * [`gait`] — the kinematic gait of the 24-DOF hexapod (gait schedule,
//!   body path, footholds, swing, IK with rates and accelerations, static
//!   stability), with its own model/workspace pair and run loop.
//!
//! ```
//! use fbd_sim::{Model, PlanarParams, run_collect};
//! let mut p = PlanarParams::default();
//! p.duration = 0.05;
//! let model = Model::planar(&p).unwrap();
//! let (rows, summary) = run_collect(&model);
//! assert!(summary.error.is_none());
//! assert_eq!(rows.len(), 6);
//! ```

pub mod control;
mod data;
pub mod energy;
pub mod engine;
mod error;
pub mod gait;
pub mod joint_inertia;
mod model;
mod params;
pub mod predictor;
pub mod record;
pub mod robot;
mod rules;
mod run;
pub mod simulator;
mod solver_settings;
pub mod spatial;
pub mod step;
mod system;

pub use control::{Control, LegTrajectory};
pub use data::Data;
pub use engine::{Engine, RunData};
pub use error::SimError;
pub use fbd_kinematics::{Joint, JointLimits, LimitSide};
pub use model::Model;
pub use params::PlanarParams;
pub use predictor::Predictor;
pub use record::{Event, LimitCode, LimitEvent, RetryEvent};
pub use robot::RobotRecord;
pub use run::{RunSummary, run, run_collect, run_until};
pub use simulator::{Action, PdTargets, Plant, Readout, SimState, Simulator};
pub use solver_settings::{
    DEFAULT_CHORD_STEPS, DEFAULT_TOLERANCE, MAX_CHORD_STEPS, MAX_TOLERANCE, MIN_TOLERANCE,
    SolverSettings,
};
pub use step::step;

//! The 3D (spatial) FBD dynamics of the 24-DOF hexapod: 13 rigid bodies
//! (the central body, and per leg the upper and the lower link), each with
//! its six Newton–Euler equations in the inertial frame, every joint
//! reaction and contact force an explicit unknown; see
//! `fbd_dynamics::spatial` for the equations and the rotation scheme. The
//! model is the hexapod's D-H instance of the generic robot model
//! ([`SpatialParams::robot_model`]) on the FBD equations of every robot
//! (`fbd_dynamics::tree`), and records every robot's record
//! ([`crate::robot::RobotRecord`]); the hexapod's parameters, controllers,
//! leg-by-leg view of the record ([`LegRow`]) and output columns are its
//! own.
//!
//! * [`SpatialParams`] → [`SpatialModel`] (immutable) and [`SpatialData`]
//!   (the workspace);
//! * [`step()`] — one staged step (kinematics at k → torques → predictor →
//!   solve → contact and limit check → accept);
//! * [`run_until`] / [`run_collect`] — the loop, one
//!   [`crate::robot::RobotRecord`] per written step, and a
//!   [`crate::RunSummary`].

pub mod control;
mod data;
mod model;
pub mod params;
pub mod record;
mod run;
pub mod step;

pub use data::SpatialData;
pub use model::{LegLimit, SpatialModel, closed_form, fastest_mode_over_poses, modes_slower_than};
pub use params::{LegTrajectory3, SpatialControl, SpatialParams, default_q0, hexagon_inertia};
pub use record::{LegIndex, LegRow, RecordIndex};
pub use run::{run_collect, run_until, run_until_written};
pub use step::step;

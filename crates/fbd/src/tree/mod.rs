//! The FBD method on any robot model ([`fbd_robot::RobotModel`]): an
//! imported URDF/MJCF robot or a D-H instance such as the paper's hexapod.
//!
//! * [`mod@inverse`] — inverse dynamics body by body (every joint's force,
//!   moment and torque explicit);
//! * [`kin`] — the kinematics at a configuration `q` (floating base with
//!   fbd's `(R, φ)`, then the joint angles) and its analytic Jacobians.

pub mod inverse;
pub mod kin;

pub use inverse::{TreeData, TreeMotion, inverse};

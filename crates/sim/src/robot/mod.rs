//! Any imported robot ([`fbd_robot::RobotModel`]: URDF, MJCF, D-H rows)
//! on the ground: the generic FBD equations of [`fbd_dynamics::tree`]
//! stepped by the staged step of every model ([`crate::engine`]) with the
//! contact machinery of every 3D model ([`crate::engine::surface`]): the
//! foot–soil state machine (free, sticking, sliding with `μS ≥ μD`), joint
//! stops at each joint's limits, retries in substeps and the law audit of
//! every written row, as for the paper's hexapod.
//!
//! * [`RobotParams`] → [`RobotSim`] (immutable, validated);
//! * [`RobotData`] (= [`crate::RunData`]`<RobotSim>`, the workspace);
//! * [`RobotRecord`]: what a step produced (row `k` of `trajectory.csv`);
//! * [`RobotControl`]: passive joints, PD to fixed angles, along a joint
//!   trajectory or along a gait plan ([`fbd_robot::gait`]), per joint,
//!   clamped to each joint's effort limit.
//!
//! The layout of `q` is `(R, φ)` of the floating base, then the joint
//! angles in model order; `q̇0` has the same layout, the base's angular
//! velocity entering as `φ̇`. A contact sphere touches the ground at its
//! lowest point (its centre minus the radius along `Y`): a sticking sphere
//! is held at that point and does not roll.

mod control;
mod data;
mod model;
mod params;
mod plant;
mod step;

pub use crate::engine::tree_record::{PLANE_ROOT, RobotContactRow, RobotRecord, plane_q_index};
pub use control::{GaitWork, JointTrajectory, RobotControl, joint_rates};
pub use data::RobotData;
pub use model::{RobotSim, gait_pose_stride, mass_matrix};
pub use params::RobotParams;
pub use step::step;

//! The FBD method on any robot model ([`fbd_robot::RobotModel`]): an
//! imported URDF/MJCF robot or a D-H instance such as the paper's hexapod.
//!
//! * [`mod@inverse`] — inverse dynamics body by body (every joint's force,
//!   moment and torque explicit);
//! * [`kin`] — the kinematics at a configuration `q` (floating base with
//!   fbd's `(R, φ)`, then the joint angles) and its analytic Jacobians;
//! * [`mechanism`] — the FBD bodies, joint reactions (a compound joint of
//!   two meeting axes as one), contact points, stops and the layout of one
//!   step's unknowns;
//! * [`mod@assemble`] — the residual and analytic Jacobian of one time step
//!   ([`crate::assembly::FbdModel`] for [`TreeMechanism`]) and the stepping
//!   entry points, as [`crate::spatial`]'s.

pub mod assemble;
pub mod inverse;
pub mod kin;
pub mod mechanism;

pub use assemble::TreeFbdData;
pub use inverse::{TreeData, TreeMotion, inverse};
pub use mechanism::{
    TreeBody, TreeContact, TreeLimit, TreeMechanism, TreeReaction, contacts_by_kind,
};

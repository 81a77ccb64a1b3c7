//! # fbd-kinematics
//!
//! Denavit–Hartenberg kinematics of the six-legged robot of the paper
//! (eqs. 1–5) and the planar 7-DOF two-leg model (docs/reference.md), with analytic
//! Jacobians.
//!
//! Conventions (docs/reference.md): inertial `Y` is vertical, up; body `y` is vertical,
//! body `−z` forward; legs are numbered 1–6 (front-left, front-right,
//! middle-left, middle-right, rear-left, rear-right) and arrays are indexed
//! by `leg number − 1`; angles in radians, lengths in metres.
//!
//! * [`dh`]: the matrices of eqs. (1)–(3) and (5) as literal 4×4 transforms,
//!   and the leg chain of eq. (4) — the reference definitions.
//! * [`leg`]: one 3-DOF leg in its base frame: fast forward kinematics and
//!   the analytic tip Jacobian.
//! * [`leg_jacobian`]: joint rates and accelerations of one leg from the
//!   analytic tip Jacobian and its time derivative.
//! * [`body`]: leg numbering, `γi`, and the body → leg-base transform.
//! * [`pose`]: the central body's pose, `Rot = Rx(φx)·Rz(φz)·Ry(φy)`.
//! * [`hexapod`]: allocation-free 24-DOF forward kinematics of every
//!   auxiliary point and rotation versor (model/data split), with point
//!   Jacobians.
//! * [`ik`]: closed-form inverse kinematics of one leg, both knee branches.
//! * [`stance`]: body pose + six inertial tip targets → 18 joint angles.
//! * [`error`]: the typed [`KinematicsError`].
//! * [`planar`]: the planar model as a generic floating-base tree whose
//!   segment angles are linear in `q`; positions, Jacobians and
//!   velocity-product terms of every auxiliary point.
//! * [`limits`]: [`JointLimits`], the `[min, max]` range of θ1, θ2, θ3.
//! * [`num`]: [`num::Num`] and [`num::Fixed`], numbers quoted in messages,
//!   short at any magnitude.
//! * [`fd`]: the shared central finite-difference checker used by every
//!   Jacobian test in the workspace.

pub mod body;
pub mod dh;
pub mod error;
pub mod fd;
pub mod hexapod;
pub mod ik;
pub mod leg;
pub mod leg_jacobian;
pub mod limits;
pub mod num;
pub mod planar;
pub mod pose;
pub mod stance;

pub use error::KinematicsError;
pub use limits::{Joint, JointLimits, LimitSide};
/// The linear-algebra crate of the public API (`Vector3`, `Matrix3`, …),
/// re-exported so users need not depend on a matching version.
pub use nalgebra;

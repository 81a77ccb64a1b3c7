//! # fbd-kinematics
//!
//! Denavit–Hartenberg kinematics of the six-legged robot of the paper
//! (eqs. 1–5) and the planar 7-DOF two-leg model (SPEC §1.4), with analytic
//! Jacobians.
//!
//! * [`planar`]: the planar model as a generic floating-base tree whose
//!   segment angles are linear in `q`; positions, Jacobians and
//!   velocity-product terms of every auxiliary point.
//! * [`fd`]: the shared central finite-difference checker used by every
//!   Jacobian test in the workspace.

pub mod fd;
pub mod planar;

//! # fbd-dynamics
//!
//! Free Body Diagram equation assembly (paper §4–§5.3, the contract).
//!
//! Every rigid body is isolated and its Newton–Euler equations are written in
//! the inertial frame with every force explicit: gravity at its centre of
//! mass, the joint force it exchanges with each neighbour (the parent exerts
//! `+F_j` on the child at the joint point, the child `−F_j` on the parent),
//! contact forces at its contact points and joint torques. Moments are taken
//! about the centre of mass and projected on the body's rotation versor
//! (eq. 10).
//!
//! ## Unknowns and equations of one time step
//! For a planar tree of `B` bodies joined by `J = B − 1` revolute joints with
//! `C` contact points, the unknowns of step `k` are
//!
//! * `q[k+1]`: `nq = 3 + J` generalised coordinates;
//! * the joint forces at `k`: `2J`;
//! * the contact forces at `k` (`Fa`, `N` in the terrain frame): `2C`;
//!
//! `3B + 2C` in all, and the equations are the `3B` Newton–Euler equations
//! (x, y, rotation) plus 2 contact equations per contact point (ST1: `N = 0,
//! Fa = 0`; ST2: the point at its anchor; ST3: the point on the surface and
//! `Fa = −dir·μD·N`). For the paper's two-leg model (`B = 5`, `J = 4`,
//! `C = 2`) that is **19 unknowns and 19 equations**: 15 dynamic and 4
//! contact. The paper counts "20 dynamic + 25 kinematic" because it writes each
//! moment `M` as an equation of its own (5 more) and counts the auxiliary
//! points and versors separately; here those kinematic relations are the
//! closed-form functions of `fbd_kinematics::planar`, evaluated and
//! differentiated analytically, not extra unknowns.
//!
//! ## Time discretisation
//! The second derivative of every body coordinate `x_b(q)` (centre of mass
//! and absolute angle) is `(x_b(q[k+1]) − 2 x_b(q[k]) + x_b(q[k−1]))/Δt²`;
//! forces, arms and versors are evaluated at `q[k]`. At `k = 0`,
//! `x_b[−1] = x_b(q[1]) − 2Δt ẋ_b(0)`. The residual is nonlinear in `q[k+1]`
//! only, linear in the forces; its Jacobian is assembled analytically,
//! directly into a sparse pattern (see [`assemble`]).
//!
//! ## One assembly, two models
//! The residual and its Jacobian are written once, in [`assembly`], over a
//! [`space::Space`] (the plane or space) and a model ([`assembly::FbdModel`]):
//! the planar mechanism ([`assemble`]) and any robot in space ([`tree`])
//! supply their kinematics, joint reactions and rotation rows; loads,
//! Newton–Euler rows, contact and stop rows ([`rows`]) and every force
//! column of the Jacobian are shared.
//!
//! ## Any robot in space
//! [`tree`] writes the per-body balances of any [`fbd_robot::RobotModel`]:
//! an imported URDF/MJCF robot, or a D-H instance such as the paper's
//! 24-DOF hexapod (`fbd_robot::dh::hexapod`, the model the 3D simulator
//! steps): inverse dynamics body by body, every joint's force, moment and
//! torque explicit ([`tree::inverse`]); the kinematics with analytic
//! Jacobians ([`tree::kin`]); and the step's residual and Jacobian as an
//! [`assembly::FbdModel`] ([`tree::mechanism`], [`tree::assemble`]).
//! [`spatial`] holds the pieces of the 3D equations (the rotation scheme,
//! the slip direction) and the hexapod in closed form, an independent
//! reference for the tests and the controller's stability check.

pub mod assemble;
pub mod assembly;
pub mod body;
pub mod check;
pub mod mechanism;
pub mod rows;
pub mod space;
pub mod spatial;
pub mod tree;

pub use assemble::{
    ContactEquation, FbdData, History, JacobianSink, LimitEquation, LimitState, NoJacobian,
    advance, evaluate_next, pattern_key, prepare_step, set_configuration,
};
pub use assembly::{eval, pattern};
pub use mechanism::{
    BodySpec, ContactPoints, ContactSpec, JointSpec, Layout, Mechanism, PointKind, TwoLegInertia,
};

//! # The spatial (3D) FBD equations of the hexapod
//!
//! The equations are assembled for every robot by [`crate::tree`] (the
//! hexapod is its D-H instance, `fbd_robot::dh::hexapod`); this module
//! holds their 3D pieces ([`equations`], [`so3`]) and the hexapod in closed
//! form ([`mechanism`], [`kin`]: the bodies of the paper's legs on the leg
//! kinematics of `fbd_kinematics::hexapod`), an independent reference for
//! the tests and the joint controller's stability check.
//!
//! The paper's method, extended from its planar two-leg model to the
//! 24-DOF hexapod: every rigid body is isolated and its six Newton–Euler
//! equations are written in the inertial frame with every force explicit.
//!
//! ## Bodies, joints, unknowns
//! 13 bodies for six legs: the central body and, per leg, the upper and the
//! lower link. The hip is two revolute joints (θ1 about `z0`, θ2 about `z1`,
//! eqs. 1–2) at one point with nothing between them: one joint of two
//! rotational degrees of freedom. Its reaction on the upper link is a force
//! `F_h` (3 unknowns) and a constraint moment `μ_h·(z0 × z1)` (1 unknown:
//! the joint transmits every moment except about its two axes), plus the
//! actuator torques `τ1·z0 + τ2·z1`. The knee (θ3 about `z2`) transmits a
//! force `F_k` (3) and the constraint moments `μ1·b1 + μ2·b2` (2, `b1`
//! along the upper link, `b2 = z2 × b1`), plus `τ3·z2`. A contact point
//! carries a force `(Ft1, N, Ft2)` (3) in its terrain frame `(t1, n, t2)`.
//! Unknowns of step `k`: `q[k+1]` (`6 + 3·legs`: `R`, `φ`, the joint
//! angles), 9 joint unknowns per leg, 3 per contact point, 1 per joint
//! limit; equations: 6 per body, 3 per contact point, 1 per limit. For six
//! legs: 24 + 54 = **78 unknowns and 78 body equations**, plus 3 per
//! contact point (96 with the six feet on the ground).
//!
//! ## Time discretisation
//! *Translation*, exactly as in the planar model: `m·(c[k+1] − 2c[k] +
//! c[k−1])/Δt² = ΣF[k]` for every centre of mass `c(q)`.
//!
//! *Rotation*: a discrete Lie-group form of Euler's equations in the
//! inertial frame. With `R[k]` the body's rotation (body → inertial) and
//! `I` its inertia tensor in its own frame, the rotation over a step is
//! `ψ[k+½] = log(R[k]ᵀ·R[k+1])` (a body-frame rotation vector) and the
//! angular momentum over the step is taken at the geodesic midpoint:
//!
//! ```text
//! L[k+½] = R[k]·exp(ψ[k+½]/2) · I · ψ[k+½]/Δt
//! (L[k+½] − L[k−½]) / Δt = ΣM[k]      (moments about the CoM at k)
//! ```
//!
//! It is (a) second order (time-symmetric and consistent), (b) conserves a
//! free body's angular momentum exactly: `L[k+½]` is the same at every
//! step to solver tolerance, and with the translation rows the total
//! `Σ m·c[k]×(c[k+1] − c[k])/Δt + L[k+½]` of the whole robot changes only
//! by the external moments (internal forces act at one point on both
//! bodies, so they cancel); (c) reduces to the paper's central difference
//! for a body turning about a fixed axis `e`: then `ψ = e·(φ[k+1] − φ[k])`
//! and `e·(L[k+½] − L[k−½])/Δt = I_ee·(φ[k+1] − 2φ[k] + φ[k−1])/Δt²`.
//! At k = 0, `L[−½] = 2·L(0) − L[½]` from the initial angular velocity,
//! as `c[−1] = c[1] − 2Δt·ċ(0)` for the translation.
//!
//! Every force, arm and direction is evaluated at `q[k]`; the residual is
//! nonlinear in `q[k+1]` only, and its Jacobian is analytic: the
//! derivative of `L[k+½]` uses the right Jacobian of SO(3) ([`so3`]).
//!
//! ## Contact rows
//! As in the planar model ([`fbd_contact::spatial`]): ST1 `F = 0`; ST2
//! `K·(p − a) + β·F = 0` (3 rows, inertial); ST3 `Ft1 + μD·ŝ1·N = 0`,
//! `K·(p_y − ϱ(p_x, p_z)) + β·N = 0`, `Ft2 + μD·ŝ2·N = 0` with `ŝ` the
//! unit direction of the point's slip over the step, an implicit function
//! of `q[k+1]` ([`equations::slip_direction`]). Joint limits as in the planar model, the stop
//! moment along the joint's axis.

pub mod equations;
pub mod kin;
pub mod mechanism;
pub mod so3;

pub use equations::{
    BodyStep3, SLIP_BIAS, STOP_SPEED, SpatialContactEquation, half_momentum,
    half_momentum_and_rotation, half_momentum_value, slip_direction,
};
pub use kin::{Columns, SpatialKin};
pub use mechanism::{
    BodyKind, SpatialBody, SpatialInertia, SpatialLayout, SpatialLimit, SpatialMechanism,
    lower_body, point_id, q_joint, upper_body,
};

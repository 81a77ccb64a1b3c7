//! Inverse kinematics of one leg at one step: closed-form angles with the
//! knee branch and angle branches kept continuous, joint rates and
//! accelerations from the analytic leg Jacobian and its time derivative
//! (never from differences of angles), and the joint-limit check.
//!
//! The foot's inertial position, velocity and acceleration `p, ṗ, p̈` are
//! carried into the leg base frame through the moving body
//! (`d = p − R`, ω and ω̇ the body's angular velocity and acceleration):
//!
//! ```text
//! d_b = Rotᵀ·d
//! ḋ_b = Rotᵀ·(ḋ − ω×d)
//! d̈_b = Rotᵀ·(d̈ − ω̇×d − 2ω×ḋ + ω×(ω×d))
//! ```
//!
//! then by the constant mount rotation `cA0i⁻¹` (eq. 5), and solved by
//! [`fbd_kinematics::ik::leg_ik_trig`] and
//! [`fbd_kinematics::leg_jacobian::joint_accelerations_trig`] (the joint
//! sines and cosines from the solution, no `sin_cos`; they are returned
//! for the forward kinematics, [`fbd_kinematics::hexapod::forward_trig`]).

use std::f64::consts::TAU;

use fbd_kinematics::KinematicsError;
use fbd_kinematics::hexapod::HexapodModel;
use fbd_kinematics::ik::{KneeBranch, leg_ik_trig};
use fbd_kinematics::leg_jacobian::{LegTrig, joint_accelerations_trig, joint_rates_trig};
use fbd_kinematics::limits::{Joint, JointLimits};
use fbd_kinematics::nalgebra::Vector3;

use super::body::BodyState;
use super::error::GaitError;

/// Joint angles, rates and accelerations of one leg (rad, rad/s, rad/s²).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LegJoints {
    /// `(θ1, θ2, θ3)`.
    pub theta: [f64; 3],
    /// `(θ̇1, θ̇2, θ̇3)`.
    pub rate: [f64; 3],
    /// `(θ̈1, θ̈2, θ̈3)`.
    pub accel: [f64; 3],
}

/// `a + 2πk` nearest `near`.
#[inline]
fn nearest(a: f64, near: f64) -> f64 {
    a + TAU * ((near - a) / TAU).round()
}

/// Solves leg `leg` (array index) for a foot at `p, v, acc` (inertial) with
/// the body in state `body` at time `t`; `previous` are the angles of the
/// previous step (the branch to stay near), `branch` the knee branch.
/// Returns the joints and the sines and cosines of their angles. With
/// `ACCEL = false` the joint accelerations are not computed (a joint
/// controller needs angles and rates): `accel` is NaN.
///
/// # Errors
/// [`GaitError::Unreachable`], [`GaitError::Singular`],
/// [`GaitError::JointLimit`], naming the leg (1–6) and `t`.
#[allow(clippy::too_many_arguments)]
#[inline]
pub fn solve_leg<const ACCEL: bool>(
    model: &HexapodModel,
    limits: &JointLimits,
    leg: usize,
    t: f64,
    body: &BodyState,
    foot: (&Vector3<f64>, &Vector3<f64>, &Vector3<f64>),
    previous: &[f64; 3],
    branch: KneeBranch,
) -> Result<(LegJoints, LegTrig), GaitError> {
    let (p, v, acc) = foot;
    let rt = body.rotation.transpose();
    let (w, wd) = (&body.omega, &body.omega_dot);
    let d = p - body.position;
    let dd = v - body.velocity;
    let ddd = acc - body.acceleration;
    let d_b = rt * d;
    let v_b = rt * (dd - w.cross(&d));
    let mount = model.mount(leg);
    let p0 = mount.body_to_base(&d_b);
    // Velocities transform by the rotation alone.
    let r0 = mount.rotation().transpose();
    let v0 = r0 * v_b;
    let number = leg + 1;
    let geom = model.leg();
    let (mut theta, trig) = leg_ik_trig(geom, &p0, branch).map_err(|e| match e {
        KinematicsError::Unreachable {
            distance,
            min_reach,
            max_reach,
        } => GaitError::Unreachable {
            leg: number,
            t,
            distance,
            by: if distance > max_reach {
                distance - max_reach
            } else {
                min_reach - distance
            },
            min: min_reach,
            max: max_reach,
        },
        other => GaitError::Singular {
            leg: number,
            t,
            what: other.to_string(),
        },
    })?;
    for k in 0..3 {
        theta[k] = nearest(theta[k], previous[k]);
    }
    let rates = if ACCEL {
        let a_b = rt * (ddd - wd.cross(&d) - 2.0 * w.cross(&dd) + w.cross(&w.cross(&d)));
        joint_accelerations_trig(geom, &trig, &v0, &(r0 * a_b))
    } else {
        joint_rates_trig(geom, &trig, &v0).map(|rate| (rate, [f64::NAN; 3]))
    };
    let (rate, accel) = rates.map_err(|s| GaitError::Singular {
        leg: number,
        t,
        what: format!(
            "the leg Jacobian is singular (det {:.3e} m³: leg stretched or folded)",
            s.det
        ),
    })?;
    for j in Joint::ALL {
        let x = theta[j.index()];
        let [lo, hi] = limits.range(j);
        if x < lo || x > hi {
            let by = if x < lo { lo - x } else { x - hi };
            return Err(GaitError::JointLimit {
                leg: number,
                t,
                joint: j.name(),
                angle_deg: x.to_degrees(),
                by_deg: by.to_degrees(),
                min_deg: lo.to_degrees(),
                max_deg: hi.to_degrees(),
            });
        }
    }
    Ok((LegJoints { theta, rate, accel }, trig))
}

//! One kinematic step of all six legs: gait phase, footholds, swing path,
//! body state, inverse kinematics with rates and accelerations, forward
//! kinematics, centre of mass and stability margin. No allocation.

use fbd_kinematics::hexapod::forward_trig;
use fbd_kinematics::leg_jacobian::LegTrig;
use fbd_kinematics::nalgebra::Vector3;
use fbd_kinematics::pose::BodyPose;

use super::error::GaitError;
use super::ik::solve_leg;
use super::model::{GaitData, GaitModel};
use super::params::LEGS;
use super::schedule::{LegPhase, phase_with};
use super::stability::{centre_of_mass, margin};
use super::swing::swing;

/// The foot of leg `leg` after swing `k` (`None`: the initial foothold).
#[inline]
pub fn anchor(model: &GaitModel, leg: usize, k: Option<usize>) -> Vector3<f64> {
    match k {
        None => model.initial_feet[leg],
        Some(k) => model.footholds[leg][k],
    }
}

/// Computes step `k` (time `k·Δt`) into `data`. `data` must hold the
/// previous step's joint angles (or the initial ones), which the angle
/// branches stay near.
///
/// # Errors
/// A [`GaitError`] naming the leg and the time when a foot target is out of
/// reach, a leg is singular or a joint passes its limit.
pub fn step(model: &GaitModel, data: &mut GaitData, k: usize) -> Result<(), GaitError> {
    let (support, n_support, trig) = targets::<true>(model, data, k)?;
    let pose = BodyPose {
        position: data.body.position,
        phi: data.body.phi,
    };
    // The IK's sines and cosines and the body's rotation: no trigonometry.
    forward_trig(&model.kin, &pose, &data.body.rotation, &trig, &mut data.fk);
    data.com = centre_of_mass(&model.masses, &data.fk);
    data.margin = margin(&support[..n_support], [data.com.x, data.com.z]);
    Ok(())
}

/// The part of [`step`] a joint controller needs: step `k`'s phases,
/// feet, body state and the legs' joint angles and rates (`data.legs`),
/// without their accelerations (`accel` is NaN), the forward kinematics,
/// centre of mass and stability margin (`data.fk`, `data.com` and
/// `data.margin` keep their previous values). The same numbers as
/// [`step`]'s.
///
/// # Errors
/// As [`step`].
pub fn step_targets(model: &GaitModel, data: &mut GaitData, k: usize) -> Result<(), GaitError> {
    targets::<false>(model, data, k).map(|_| ())
}

/// [`step_targets`] (with the joint accelerations when `ACCEL`),
/// returning the stance feet's horizontal positions (their number) and
/// each leg's sines and cosines for the forward kinematics.
#[allow(clippy::type_complexity)]
fn targets<const ACCEL: bool>(
    model: &GaitModel,
    data: &mut GaitData,
    k: usize,
) -> Result<([[f64; 2]; LEGS], usize, [LegTrig; LEGS]), GaitError> {
    let t = model.time(k);
    let p = &model.params;
    let planar = model.plan.planar_at_step(k);
    let body = model.plan.state(t, &planar);
    let zero = Vector3::zeros();
    let mut support = [[0.0; 2]; LEGS];
    let mut n_support = 0;
    let mut trig = [LegTrig {
        s1: 0.0,
        c1: 1.0,
        s2: 0.0,
        c2: 1.0,
        s23: 0.0,
        c23: 1.0,
    }; LEGS];
    for (leg, trig) in trig.iter_mut().enumerate() {
        let phase = phase_with(p, leg, model.last_swing[leg], t);
        let (foot, vel, acc) = match phase {
            LegPhase::Stance { last } => (anchor(model, leg, last), zero, zero),
            LegPhase::Swing { k: s, u } => {
                let from = anchor(model, leg, s.checked_sub(1));
                let to = anchor(model, leg, Some(s));
                swing(&from, &to, p.swing_height, p.swing_time(), u)
            }
        };
        if phase.is_stance() {
            support[n_support] = [foot.x, foot.z];
            n_support += 1;
        }
        (data.legs[leg], *trig) = solve_leg::<ACCEL>(
            &model.kin,
            &p.limits,
            leg,
            t,
            &body,
            (&foot, &vel, &acc),
            &data.legs[leg].theta,
            model.branches[leg],
        )?;
        data.phases[leg] = phase;
        data.feet[leg] = foot;
        data.foot_velocity[leg] = vel;
        data.foot_acceleration[leg] = acc;
    }
    data.body = body;
    data.step = k;
    data.t = t;
    Ok((support, n_support, trig))
}

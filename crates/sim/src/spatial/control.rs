//! Stage 2 of a spatial step: the joint torques `τ = kp·(θ* − θ[k]) +
//! kd·(θ̇* − θ̇[k])` of every joint, explicit in the state of step `k`
//! (`θ̇[k] = (θ[k] − θ[k−1])/Δt`, the initial rates at k = 0), clamped to
//! `±torque_limit`. Targets: fixed angles (`pd`, `θ̇* = 0`), a
//! piecewise-linear trajectory (`trajectory`, `θ̇*` its slope) or the
//! kinematic gait generator's angles and rates at step `k` (`gait`). A
//! positive torque drives its joint angle towards larger values.

use super::data::SpatialData;
use super::model::SpatialModel;
use super::params::SpatialControl;
use crate::SimError;
use crate::engine::tree_record::coordinate_rate;
use fbd_dynamics::spatial::q_joint;

/// The joint rates `θ̇[k]` of slot `s` (backward difference).
pub fn joint_rates(model: &SpatialModel, data: &SpatialData, s: usize) -> [f64; 3] {
    std::array::from_fn(|j| coordinate_rate(model, data, q_joint(s, j)))
}

/// Fills `data.fbd.torque` for step `data.k`. No allocation.
///
/// # Errors
/// [`SimError::Control`] when the gait generator cannot place a foot.
pub fn joint_torques(model: &SpatialModel, data: &mut SpatialData) -> Result<(), SimError> {
    if let Some(tau) = &data.external_torque {
        assert_eq!(
            3 * tau.len(),
            data.fbd.torque.len(),
            "one torque triple per leg"
        );
        for (t, v) in data.fbd.torque.iter_mut().zip(tau.iter().flatten()) {
            *t = *v;
        }
        return Ok(());
    }
    let dt = model.dt();
    let t = data.k as f64 * dt;
    let Some((kp, kd, limit)) = model.params.control.gains() else {
        data.fbd.torque.fill(0.0);
        return Ok(());
    };
    if let (SpatialControl::Gait { gait, .. }, Some(g)) = (&model.params.control, &mut data.control)
    {
        let k = data.k.min(gait.steps);
        crate::gait::step_targets(gait, g, k).map_err(|e| SimError::Control {
            step: data.k,
            t,
            message: e.to_string(),
        })?;
    }
    for s in 0..model.legs.len() {
        let rate = joint_rates(model, data, s);
        let (target, target_rate) = match &model.params.control {
            SpatialControl::Pd { target, .. } => (target[s], [0.0; 3]),
            SpatialControl::Trajectory { legs, .. } => {
                let h = 1e-6;
                let (a, b) = (legs[s].at(t - h), legs[s].at(t + h));
                (
                    legs[s].at(t),
                    std::array::from_fn(|j| (b[j] - a[j]) / (2.0 * h)),
                )
            }
            SpatialControl::Gait { .. } => {
                let g = data.control.as_ref().expect("gait workspace");
                let leg = &g.legs[model.legs[s] - 1];
                (leg.theta, leg.rate)
            }
            SpatialControl::None => unreachable!("handled above"),
        };
        for j in 0..3 {
            let theta = data.q[q_joint(s, j)];
            data.fbd.torque[3 * s + j] =
                crate::control::pd_torque(kp, kd, limit, target[j], target_rate[j], theta, rate[j]);
        }
    }
    Ok(())
}

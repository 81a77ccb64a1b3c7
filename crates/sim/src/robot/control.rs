//! Stage 2 of a robot's step: every joint's torque
//! `τ = kp·(θ* − θ[k]) + kd·(θ̇* − θ̇[k])`, explicit in the state of step
//! `k` (`θ̇[k] = (θ[k] − θ[k−1])/Δt`, the initial rates at k = 0), clamped
//! to the joint's effort limit (from the description) and to
//! `±torque_limit` when set. Targets: fixed angles (`Pd`, `θ̇* = 0`) or a
//! piecewise-linear joint trajectory (`Trajectory`, `θ̇*` its slope). A
//! positive torque drives its joint angle towards larger values. Torques
//! set from outside ([`crate::RunData::external_torque`]) replace the
//! controller's as given.

use super::data::RobotData;
use super::model::RobotSim;
use crate::SimError;
use fbd_dynamics::tree::kin::BASE_DOF;
use fbd_robot::gait::GaitPlan;

/// Joint angles over time, linear between knots.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct JointTrajectory {
    /// Strictly increasing times (s), at least one.
    pub times: Vec<f64>,
    /// The joint angles (rad) at each time, one per model joint.
    pub angles: Vec<Vec<f64>>,
}

impl JointTrajectory {
    /// Joint `j`'s target angle and rate at time `t` (constant before the
    /// first knot and after the last).
    pub fn at(&self, t: f64, j: usize) -> (f64, f64) {
        let ts = &self.times;
        let n = ts.len();
        if t <= ts[0] {
            return (self.angles[0][j], 0.0);
        }
        if t >= ts[n - 1] {
            return (self.angles[n - 1][j], 0.0);
        }
        let i = ts.partition_point(|&s| s <= t) - 1;
        let (a, b) = (self.angles[i][j], self.angles[i + 1][j]);
        let slope = (b - a) / (ts[i + 1] - ts[i]);
        (a + (t - ts[i]) * slope, slope)
    }
}

/// The joint controller of a robot's run.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum RobotControl {
    /// Passive joints (zero torque).
    #[default]
    None,
    /// PD to fixed joint angles.
    Pd {
        /// Position gain per joint (N·m/rad).
        kp: Vec<f64>,
        /// Rate gain per joint (N·m·s/rad).
        kd: Vec<f64>,
        /// The target angle per joint (rad).
        target: Vec<f64>,
        /// `|τ| ≤ torque_limit` (N·m) on every joint, besides its effort
        /// limit.
        torque_limit: Option<f64>,
    },
    /// PD along a joint trajectory.
    Trajectory {
        /// Position gain per joint (N·m/rad).
        kp: Vec<f64>,
        /// Rate gain per joint (N·m·s/rad).
        kd: Vec<f64>,
        /// The targets over time.
        trajectory: JointTrajectory,
        /// `|τ| ≤ torque_limit` (N·m) on every joint.
        torque_limit: Option<f64>,
    },
    /// PD along a gait plan's joint angles with its rates as feed-forward.
    Gait {
        /// Position gain per joint (N·m/rad).
        kp: Vec<f64>,
        /// Rate gain per joint (N·m·s/rad).
        kd: Vec<f64>,
        /// The plan at `t = 0` (each run steps its own copy).
        plan: Box<GaitPlan>,
        /// `|τ| ≤ torque_limit` (N·m) on every joint.
        torque_limit: Option<f64>,
    },
}

/// The controller's workspace of a gait run: the plan (warm-started IK)
/// and its targets of the current step.
#[derive(Clone, Debug)]
pub struct GaitWork {
    /// The run's copy of the plan.
    pub plan: GaitPlan,
    /// Joint targets `θ*` (rad).
    pub target: Vec<f64>,
    /// Joint rate targets `θ̇*` (rad/s).
    pub rate: Vec<f64>,
}

impl RobotControl {
    /// The workspace a run of this controller needs (a gait's plan).
    pub fn work(&self) -> Option<Box<GaitWork>> {
        match self {
            RobotControl::Gait { plan, .. } => {
                let n = plan.standing().len();
                Some(Box::new(GaitWork {
                    plan: (**plan).clone(),
                    target: vec![0.0; n],
                    rate: vec![0.0; n],
                }))
            }
            _ => None,
        }
    }
}

/// Joint `j`'s rate `θ̇[k]` (backward difference; `q̇0` at k = 0).
pub fn joint_rates(model: &RobotSim, data: &RobotData, j: usize) -> f64 {
    crate::engine::tree_record::coordinate_rate(model, data, BASE_DOF + j)
}

/// Fills `data.fbd.torque` for step `data.k`. No allocation.
///
/// # Errors
/// None yet (a controller that cannot compute its targets will report
/// [`SimError::Control`]).
pub fn joint_torques(model: &RobotSim, data: &mut RobotData) -> Result<(), SimError> {
    if let Some(tau) = &data.external_torque {
        assert_eq!(tau.len(), data.fbd.torque.len(), "one torque per joint");
        data.fbd.torque.copy_from_slice(tau);
        return Ok(());
    }
    let t = data.k as f64 * model.params.dt;
    let (kp, kd, limit) = match &model.params.control {
        RobotControl::None => {
            data.fbd.torque.fill(0.0);
            return Ok(());
        }
        RobotControl::Pd {
            kp,
            kd,
            torque_limit,
            ..
        }
        | RobotControl::Trajectory {
            kp,
            kd,
            torque_limit,
            ..
        }
        | RobotControl::Gait {
            kp,
            kd,
            torque_limit,
            ..
        } => (kp, kd, *torque_limit),
    };
    if let Some(work) = data.control.as_mut() {
        let GaitWork { plan, target, rate } = &mut **work;
        plan.targets(t, target, rate)
            .map_err(|e| SimError::Control {
                step: data.k,
                t,
                message: e.to_string(),
            })?;
    }
    for j in 0..model.mech.model.joints.len() {
        let (target, target_rate) = match &model.params.control {
            RobotControl::Pd { target, .. } => (target[j], 0.0),
            RobotControl::Trajectory { trajectory, .. } => trajectory.at(t, j),
            RobotControl::Gait { .. } => {
                let w = data.control.as_ref().expect("a gait run's workspace");
                (w.target[j], w.rate[j])
            }
            RobotControl::None => unreachable!("handled above"),
        };
        let theta = data.q[BASE_DOF + j];
        let rate = joint_rates(model, data, j);
        let lim = match (limit, model.effort[j]) {
            (Some(a), Some(b)) => Some(a.min(b)),
            (a, b) => a.or(b),
        };
        data.fbd.torque[j] =
            crate::control::pd_torque(kp[j], kd[j], lim, target, target_rate, theta, rate);
    }
    Ok(())
}

//! Joint controllers: the torques `FbdData::torque` applied at step `k`,
//! computed explicitly from the state of step `k`.
//!
//! `τ = kp·(θ* − θ[k]) − kd·θ̇[k]`, with the backward-difference rate
//! `θ̇[k] = (θ[k] − θ[k−1])/Δt` (the initial rate at `k = 0`), clamped to
//! `±torque_limit`. A positive torque drives its joint angle towards larger
//! values (see [`fbd_dynamics::JointSpec::axis_z`]). Joint order of the
//! two-leg model: `[hip3, knee3, hip4, knee4]`, targets per leg `(θ2, θ3)`.

use crate::{Data, Model};

/// A joint-space target trajectory of one leg: `N` joint angles (rad) at
/// `times` (s), linear in between, held before the first and after the
/// last point. The planar model's is `(θ2, θ3)` (`N = 2`), the spatial
/// model's `(θ1, θ2, θ3)` ([`crate::spatial::LegTrajectory3`]).
#[derive(Clone, Debug, PartialEq)]
pub struct LegTrajectory<const N: usize = 2> {
    /// Strictly increasing times (s), at least one.
    pub times: Vec<f64>,
    /// The joint angles (rad) at each time.
    pub targets: Vec<[f64; N]>,
}

impl<const N: usize> Default for LegTrajectory<N> {
    fn default() -> Self {
        Self {
            times: Vec::new(),
            targets: Vec::new(),
        }
    }
}

impl<const N: usize> LegTrajectory<N> {
    /// The target at time `t`.
    pub fn at(&self, t: f64) -> [f64; N] {
        let (ts, xs) = (&self.times, &self.targets);
        let n = ts.len().min(xs.len());
        if n == 0 {
            return [0.0; N];
        }
        if t <= ts[0] {
            return xs[0];
        }
        if t >= ts[n - 1] {
            return xs[n - 1];
        }
        let i = ts[..n].partition_point(|&s| s <= t) - 1;
        let u = (t - ts[i]) / (ts[i + 1] - ts[i]);
        std::array::from_fn(|j| xs[i][j] + u * (xs[i + 1][j] - xs[i][j]))
    }
}

/// The joint controller of a planar run.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Control {
    /// Passive joints: no torque.
    #[default]
    None,
    /// PD regulation to fixed joint angles.
    Pd {
        /// Stiffness (N·m/rad), ≥ 0.
        kp: f64,
        /// Damping (N·m·s/rad), ≥ 0.
        kd: f64,
        /// Saturation `|τ| ≤ limit` (N·m), > 0; `None` for no limit.
        torque_limit: Option<f64>,
        /// `(θ2, θ3)` targets (rad) of leg 3 and leg 4.
        target: [[f64; 2]; 2],
    },
    /// PD tracking of a piecewise-linear joint trajectory per leg.
    Trajectory {
        /// Stiffness (N·m/rad), ≥ 0.
        kp: f64,
        /// Damping (N·m·s/rad), ≥ 0.
        kd: f64,
        /// Saturation `|τ| ≤ limit` (N·m), > 0; `None` for no limit.
        torque_limit: Option<f64>,
        /// Trajectories of leg 3 and leg 4.
        legs: [LegTrajectory; 2],
    },
}

impl Control {
    /// `(kp, kd, limit)`, `None` for passive joints.
    fn gains(&self) -> Option<(f64, f64, Option<f64>)> {
        match self {
            Control::None => None,
            Control::Pd {
                kp,
                kd,
                torque_limit,
                ..
            }
            | Control::Trajectory {
                kp,
                kd,
                torque_limit,
                ..
            } => Some((*kp, *kd, *torque_limit)),
        }
    }

    /// `(θ2, θ3)` target (rad) of leg `leg` (0 = leg 3, 1 = leg 4) at `t`.
    pub fn target(&self, leg: usize, t: f64) -> Option<[f64; 2]> {
        match self {
            Control::None => None,
            Control::Pd { target, .. } => Some(target[leg]),
            Control::Trajectory { legs, .. } => Some(legs[leg].at(t)),
        }
    }

    /// Checks the parameters; `Err((key, what, got))` names the
    /// configuration key at fault.
    pub fn validate(&self) -> Result<(), (String, &'static str, String)> {
        let Some((kp, kd, limit)) = self.gains() else {
            return Ok(());
        };
        for (key, v) in [("control.kp", kp), ("control.kd", kd)] {
            if !(v.is_finite() && v >= 0.0) {
                return Err((key.into(), "must be finite and ≥ 0", v.to_string()));
            }
        }
        if let Some(l) = limit
            && !(l.is_finite() && l > 0.0)
        {
            return Err((
                "control.torque_limit".into(),
                "must be positive and finite",
                l.to_string(),
            ));
        }
        for (leg, name) in [(0, "leg3"), (1, "leg4")] {
            match self {
                Control::Pd { target, .. } => {
                    if !target[leg].iter().all(|v| v.is_finite()) {
                        return Err((
                            format!("control.{name}.target_deg"),
                            "must be finite",
                            format!("{:?}", target[leg]),
                        ));
                    }
                }
                Control::Trajectory { legs, .. } => {
                    let l = &legs[leg];
                    if l.times.is_empty() || l.times.len() != l.targets.len() {
                        return Err((
                            format!("control.{name}.times"),
                            "must be non-empty and as long as target_deg",
                            format!("{} times, {} targets", l.times.len(), l.targets.len()),
                        ));
                    }
                    if !l.times.iter().all(|v| v.is_finite())
                        || l.times.windows(2).any(|w| w[1] <= w[0])
                    {
                        return Err((
                            format!("control.{name}.times"),
                            "must be finite and strictly increasing",
                            format!("{:?}", l.times),
                        ));
                    }
                    if !l.targets.iter().flatten().all(|v| v.is_finite()) {
                        return Err((
                            format!("control.{name}.target_deg"),
                            "must be finite",
                            format!("{:?}", l.targets),
                        ));
                    }
                }
                Control::None => {}
            }
        }
        Ok(())
    }
}

/// The PD law of every controller (planar and spatial, configured or
/// set through [`crate::simulator`]): `τ = kp·(θ* − θ) + kd·(θ̇* − θ̇)`,
/// clamped to `±limit`.
#[inline]
pub fn pd_torque(
    kp: f64,
    kd: f64,
    limit: Option<f64>,
    target: f64,
    target_rate: f64,
    theta: f64,
    rate: f64,
) -> f64 {
    let tau = kp * (target - theta) + kd * (target_rate - rate);
    match limit {
        Some(l) => tau.clamp(-l, l),
        None => tau,
    }
}

/// Stage 2 of [`crate::step()`]: the joint torques of step `data.k` into
/// `data.fbd.torque`, from `q[k]` and `q[k−1]` (explicit): the external
/// torques [`Data::external_torque`] as given when set (no saturation),
/// else the configured controller's. No allocation.
pub fn joint_torques(model: &Model, data: &mut Data) {
    if let Some(tau) = &data.external_torque {
        let n = data.fbd.torque.len();
        assert!(
            n <= tau.len(),
            "{n} joints, external torques hold {}",
            tau.len()
        );
        data.fbd.torque.copy_from_slice(&tau[..n]);
        return;
    }
    let control = &model.params.control;
    let Some((kp, kd, limit)) = control.gains() else {
        data.fbd.torque.fill(0.0);
        return;
    };
    let dt = model.dt();
    let t = data.k as f64 * dt;
    let targets = [
        control.target(0, t).unwrap_or_default(),
        control.target(1, t).unwrap_or_default(),
    ];
    for (j, spec) in model.mech.joints.iter().enumerate() {
        let i = spec.q_index;
        // q = (Rx, Ry, φz, θ2₃, θ3₃, θ2₄, θ3₄).
        let target = targets[((i - 3) / 2).min(1)][(i - 3) % 2];
        let rate = if data.k == 0 {
            model.params.qdot0[i]
        } else {
            (data.q[i] - data.q_prev[i]) / dt
        };
        data.fbd.torque[j] = pd_torque(kp, kd, limit, target, 0.0, data.q[i], rate);
    }
}

#[cfg(test)]
mod tests {
    use crate::{Control, Data, Model, PlanarParams, step};

    fn params(control: Control) -> PlanarParams {
        PlanarParams {
            duration: 0.3,
            control,
            ..PlanarParams::default()
        }
    }

    /// External torques replace the configured controller: zero external
    /// torques on a PD-controlled model give the passive run, and the PD
    /// torques fed back from outside give the PD run, bit for bit.
    #[test]
    fn external_torques_replace_the_controller() {
        let pd = Control::Pd {
            kp: 200.0,
            // Below the stability limit of the explicit torques at the
            // default Δt (4.2 N·m·s/rad).
            kd: 3.0,
            torque_limit: Some(40.0),
            target: [[0.1, 4.3], [-0.1, 4.4]],
        };
        let passive = Model::planar(&params(Control::None)).unwrap();
        let controlled = Model::planar(&params(pd)).unwrap();
        let (mut a, mut b, mut c) = (
            Data::new(&passive),
            Data::new(&controlled),
            Data::new(&controlled),
        );
        let mut moved = false;
        for _ in 0..controlled.steps {
            let ra = step(&passive, &mut a).unwrap();
            b.external_torque = Some(vec![0.0; 4]);
            let rb = step(&controlled, &mut b).unwrap();
            assert_eq!(ra.q, rb.q, "zero external torques = passive joints");
            // The controller's own torques, computed outside and fed back.
            let mut probe = Data::new(&controlled);
            probe.k = c.k;
            probe.q.copy_from_slice(&c.q);
            probe.q_prev.copy_from_slice(&c.q_prev);
            super::joint_torques(&controlled, &mut probe);
            let tau = probe.fbd.torque.clone();
            c.external_torque = Some(tau.clone());
            let rc = step(&controlled, &mut c).unwrap();
            assert_eq!(rc.torque, tau);
            moved |= rc.q != ra.q;
        }
        let mut d = Data::new(&controlled);
        for _ in 0..controlled.steps {
            step(&controlled, &mut d).unwrap();
        }
        assert_eq!(c.q, d.q, "PD torques from outside = the built-in PD run");
        assert!(moved, "the torques changed the motion");
    }
}

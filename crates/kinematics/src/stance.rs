//! Stance inverse kinematics: body pose and six inertial tip targets → the
//! 18 joint angles.

use nalgebra::Vector3;

use crate::body::LEG_COUNT;
use crate::error::KinematicsError;
use crate::hexapod::HexapodModel;
use crate::ik::{KneeBranch, leg_ik};
use crate::pose::BodyPose;

/// Joint angles `(θ1, θ2, θ3)` (rad) of every leg placing its tip at
/// `tips[i]` (inertial frame) with the body at `pose`, knee branch
/// `branches[i]` per leg; arrays are indexed by leg number − 1.
///
/// Each target is mapped to the body frame (`Rotᵀ·(p − R)`), then to the leg
/// base frame (`cA0i⁻¹`), and solved by [`leg_ik`].
///
/// # Errors
/// [`KinematicsError::NonFinite`] if the pose is not finite;
/// [`KinematicsError::Leg`] naming the first leg (number 1–6) whose target
/// cannot be reached, with the leg's own error as its source.
pub fn stance_ik(
    model: &HexapodModel,
    pose: &BodyPose,
    tips: &[Vector3<f64>; LEG_COUNT],
    branches: &[KneeBranch; LEG_COUNT],
) -> Result<[[f64; 3]; LEG_COUNT], KinematicsError> {
    if !(pose.position.iter().all(|v| v.is_finite()) && pose.phi.iter().all(|v| v.is_finite())) {
        return Err(KinematicsError::NonFinite);
    }
    let rot_t = pose.rotation().transpose();
    let mut out = [[0.0; 3]; LEG_COUNT];
    for (i, o) in out.iter_mut().enumerate() {
        let p_body = rot_t * (tips[i] - pose.position);
        let p0 = model.mount(i).body_to_base(&p_body);
        *o = leg_ik(model.leg(), &p0, branches[i]).map_err(|e| KinematicsError::Leg {
            leg: i + 1,
            source: Box::new(e),
        })?;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::hexapod::{HexapodConfig, HexapodData, forward};

    #[test]
    fn round_trip_and_leg_named_error() {
        let model = HexapodModel::default();
        let pose = BodyPose::new([0.1, 0.5, 0.2], [0.1, -0.3, 0.2]);
        let joints = [[0.1, 0.1, 4.3]; LEG_COUNT];
        let mut d = HexapodData::new();
        forward(&model, &HexapodConfig { pose, joints }, &mut d);
        let mut tips = d.legs.map(|l| l.tip);
        let got = stance_ik(&model, &pose, &tips, &[KneeBranch::Up; LEG_COUNT]).unwrap();
        for (g, w) in got.iter().zip(&joints) {
            for k in 0..3 {
                assert!((g[k] - w[k]).abs() < 1e-9, "{g:?} vs {w:?}");
            }
        }
        tips[4].y -= 5.0;
        let e = stance_ik(&model, &pose, &tips, &[KneeBranch::Up; LEG_COUNT]).unwrap_err();
        assert!(matches!(e, KinematicsError::Leg { leg: 5, .. }), "{e}");
        assert!(
            e.to_string().starts_with("leg 5: target at distance"),
            "{e}"
        );
    }
}

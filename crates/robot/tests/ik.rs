//! Numeric inverse kinematics of contact points (`fbd_robot::ik`): targets
//! that forward kinematics reached from random joint angles are reached
//! again from other starting angles, within the joint limits; a target out
//! of reach is an error naming the point and the distance left.

use std::path::Path;

use fbd_robot::forward::base_frame;
use fbd_robot::ik::{IkParams, solve};
use fbd_robot::nalgebra::Vector3;
use fbd_robot::{ContactChoice, RobotData, RobotModel, Up, forward};
use proptest::prelude::*;

fn lab() -> RobotModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/robots/lab_hexapod.urdf");
    fbd_robot::urdf::load(&path, Up::Z, &ContactChoice::CollisionSpheres).unwrap()
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    #[test]
    fn reachable_feet_are_reached_within_the_limits(
        phi in prop::array::uniform3(-0.5f64..0.5),
        fraction in prop::collection::vec(0.05f64..0.95, 18),
        start in prop::collection::vec(0.3f64..0.7, 18),
    ) {
        let model = lab();
        // Joint angles inside the limits as fractions of each range.
        let within = |f: &[f64]| -> Vec<f64> {
            model.joints.iter().zip(f).map(|(j, x)| {
                let l = j.limits.unwrap();
                l.lower + x * (l.upper - l.lower)
            }).collect()
        };
        let goal = within(&fraction);
        let base = base_frame([0.0, 0.2, 0.0], phi);
        let mut d = RobotData::new(&model);
        forward(&model, &base, &goal, &mut d);
        let targets: Vec<(usize, Vector3<f64>)> = (0..6).map(|c| (c, d.contacts[c])).collect();
        let q = solve(&model, &base, &within(&start), &targets, &IkParams::default()).unwrap();
        forward(&model, &base, &q, &mut d);
        for (c, t) in &targets {
            prop_assert!((d.contacts[*c] - t).norm() <= 1e-10);
        }
        for (j, joint) in model.joints.iter().enumerate() {
            let l = joint.limits.unwrap();
            prop_assert!(l.lower <= q[j] && q[j] <= l.upper, "{}", joint.name);
        }
    }
}

#[test]
fn a_foot_out_of_reach_is_an_error_naming_it() {
    let model = lab();
    let base = base_frame([0.0, 0.2, 0.0], [0.0; 3]);
    let far = Vector3::new(0.0, -1.0, 0.0);
    let c = model
        .contacts
        .iter()
        .position(|c| c.name == "rm_foot_sphere")
        .unwrap();
    let err = solve(&model, &base, &[0.0; 18], &[(c, far)], &IkParams::default()).unwrap_err();
    assert_eq!(err.point, "rm_foot_sphere");
    assert!(err.distance > 0.5, "{err}");
    assert!(err.to_string().contains("rm_foot_sphere"));
}

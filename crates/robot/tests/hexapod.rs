//! The paper's hexapod built as a generic [`RobotModel`] from its D-H
//! parameters places every point and axis where the hand-expanded D-H
//! kinematics of `fbd-kinematics` does, for any pose and joint angles.

use fbd_kinematics::hexapod::{HexapodConfig, HexapodData, HexapodModel, forward as dh_forward};
use fbd_kinematics::pose::BodyPose;
use fbd_robot::dh::{HexapodLayout, HexapodMasses, hexapod};
use fbd_robot::forward::base_frame;
use fbd_robot::nalgebra::Vector3;
use fbd_robot::{RobotData, forward};
use proptest::prelude::*;

fn close(a: Vector3<f64>, b: Vector3<f64>) -> bool {
    (a - b).norm() <= 1e-12
}

proptest! {
    #[test]
    fn the_dh_instance_matches_the_hexapod_kinematics(
        position in prop::array::uniform3(-2.0f64..2.0),
        phi in prop::array::uniform3(-3.0f64..3.0),
        joints in prop::array::uniform6(prop::array::uniform3(-3.2f64..3.2)),
    ) {
        let geometry = HexapodModel::default();
        let robot = hexapod(&geometry, &HexapodMasses::default(), &HexapodLayout::default());
        let cfg = HexapodConfig { pose: BodyPose::new(position, phi), joints };
        let mut dh = HexapodData::new();
        dh_forward(&geometry, &cfg, &mut dh);

        let q: Vec<f64> = joints.iter().flatten().copied().collect();
        let mut data = RobotData::new(&robot);
        forward(&robot, &base_frame(position, phi), &q, &mut data);

        for leg in 0..6 {
            let n = leg + 1;
            let l = &dh.legs[leg];
            let at = |name: String| {
                let k = robot.contacts.iter().position(|c| c.name == name).unwrap();
                data.contacts[k]
            };
            prop_assert!(close(at(format!("tip{n}")), l.tip), "tip {n}");
            prop_assert!(close(at(format!("knee{n}")), l.knee), "knee {n}");
            prop_assert!(close(at(format!("hip{n}")), l.hip), "hip {n}");
            let body = |name: String| robot.body_index(&name).unwrap();
            let (upper, lower) = (body(format!("upper{n}")), body(format!("lower{n}")));
            prop_assert!(close(data.com(&robot, upper), l.upper_com), "upper com");
            prop_assert!(close(data.com(&robot, lower), l.lower_com), "lower com");
            let axis = |name: String| data.axes[robot.joint_index(&name).unwrap()];
            let axes = [
                (axis(format!("theta1_{n}")), l.hip_axis),
                (axis(format!("theta2_{n}")), l.upper_versor),
                (axis(format!("theta3_{n}")), l.lower_versor),
            ];
            for (k, (got, want)) in axes.into_iter().enumerate() {
                prop_assert!(close(got, want), "axis of joint {k}");
            }
        }
        prop_assert!(close(data.com(&robot, 0), dh.body_com));
    }
}

#[test]
fn the_hexapod_instance_has_the_paper_structure() {
    let m = HexapodMasses::default();
    let robot = hexapod(&HexapodModel::default(), &m, &HexapodLayout::default());
    assert_eq!(robot.bodies.len(), 1 + 6 * 3);
    assert_eq!(robot.joints.len(), 18);
    assert_eq!(robot.actuators.len(), 18);
    assert_eq!(robot.contacts.len(), 18);
    let want = m.body_mass + 6.0 * (m.upper_mass + m.lower_mass);
    assert!((robot.mass() - want).abs() < 1e-12);
    // The massless coxa between θ1 and θ2 makes one two-axis hip per leg.
    let pairs = robot.compound_joints();
    assert_eq!(pairs.len(), 6);
    for (first, second) in pairs {
        let (a, b) = (&robot.joints[first].name, &robot.joints[second].name);
        assert!(
            a.starts_with("theta1_") && b.starts_with("theta2_"),
            "{a} {b}"
        );
        assert_eq!(a[7..], b[7..]);
    }
    // The planar pair: legs 3 and 4, tips only.
    let planar = hexapod(
        &HexapodModel::default(),
        &m,
        &HexapodLayout {
            legs: vec![3, 4],
            knees: false,
            hips: false,
            ..HexapodLayout::default()
        },
    );
    let names: Vec<&str> = planar.contacts.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, ["tip3", "tip4"]);
}

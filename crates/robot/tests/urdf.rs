//! URDF import: the lab hexapod of `examples/robots` (fixed joints merged,
//! the root turned to fbd's frame, foot spheres as contact points), its
//! kinematics against the URDF chain composed independently, and one error
//! naming file, line and element per unsupported or malformed input.

use std::path::{Path, PathBuf};

use fbd_robot::forward::base_frame;
use fbd_robot::nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};
use fbd_robot::tree::RawJointKind;
use fbd_robot::urdf::{self, rpy};
use fbd_robot::{ContactChoice, RobotData, RobotError, Up, forward};
use proptest::prelude::*;

fn lab() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/robots/lab_hexapod.urdf")
}

/// ROS (z up, x forward) → fbd (y up, −z forward).
fn ros_to_fbd(v: Vector3<f64>) -> Vector3<f64> {
    Vector3::new(-v.y, v.z, -v.x)
}

fn skew_shift(m: f64, c: Vector3<f64>) -> Matrix3<f64> {
    m * (Matrix3::identity() * c.norm_squared() - c * c.transpose())
}

#[test]
fn the_lab_hexapod_imports_with_fixed_links_merged() {
    let robot = urdf::load(&lab(), Up::Z, &ContactChoice::CollisionSpheres).unwrap();
    assert_eq!(robot.name, "lab_hexapod");
    assert_eq!(robot.bodies.len(), 19, "base + 6 × (coxa, femur, tibia)");
    assert_eq!(robot.joints.len(), 18);
    assert_eq!(robot.actuators.len(), 18);
    assert!(robot.actuators.iter().all(|a| a.effort_limit == Some(3.0)));
    let want = 2.0 + 0.02 + 6.0 * (0.06 + 0.12 + 0.10 + 0.01);
    assert!((robot.mass() - want).abs() < 1e-12, "{}", robot.mass());
    // Six foot spheres, on the tibias (the feet merged into them).
    assert_eq!(robot.contacts.len(), 6);
    for c in &robot.contacts {
        assert!(c.name.ends_with("_foot_sphere"));
        assert_eq!(robot.bodies[c.body].name, format!("{}_tibia", &c.name[..2]));
        assert!((c.position - Vector3::new(0.0, 0.0, -0.12)).norm() < 1e-15);
        assert_eq!(c.radius, 0.01);
    }
    // The root: base (2 kg at 0) + IMU (0.02 kg at (−0.05, 0, 0.03)),
    // turned to fbd's frame.
    let root = &robot.bodies[0];
    let imu = ros_to_fbd(Vector3::new(-0.05, 0.0, 0.03));
    let com = 0.02 * imu / 2.02;
    assert!((root.com - com).norm() < 1e-15);
    let base_ros = Matrix3::from_diagonal(&Vector3::new(0.00468333, 0.0154167, 0.0192667));
    let turn = Up::Z.rotation().into_inner();
    let inertia = turn * base_ros * turn.transpose()
        + Matrix3::identity() * 1e-6
        + skew_shift(2.0, -com)
        + skew_shift(0.02, imu - com);
    assert!((root.inertia - inertia).norm() < 1e-15, "{}", root.inertia);
    // A tibia: 0.10 kg rod centred at (0, 0, −0.06), foot 0.01 kg at −0.12.
    let tibia = &robot.bodies[robot.body_index("lf_tibia").unwrap()];
    let c = Vector3::new(0.0, 0.0, (0.10 * -0.06 + 0.01 * -0.12) / 0.11);
    assert!((tibia.com - c).norm() < 1e-15);
    let rod = Matrix3::from_diagonal(&Vector3::new(0.0001225, 0.0001225, 5e-06));
    let i = rod
        + skew_shift(0.10, Vector3::new(0.0, 0.0, -0.06) - c)
        + Matrix3::identity() * 4e-7
        + skew_shift(0.01, Vector3::new(0.0, 0.0, -0.12) - c);
    assert!((tibia.inertia - i).norm() < 1e-15);
    // No massless body between two joints at one point here.
    assert!(robot.compound_joints().is_empty());
    let l = robot.joints[robot.joint_index("lf_tibia_joint").unwrap()]
        .limits
        .unwrap();
    assert!(
        (l.lower + 120f64.to_radians()).abs() < 1e-9 && (l.upper - 60f64.to_radians()).abs() < 1e-9
    );
}

/// The URDF chain of `joint` names composed directly from the parsed
/// joints (no merging, no turning): the foot of leg `leg` in the ROS frame.
fn ros_foot(tree: &fbd_robot::tree::RawTree, leg: &str, q: &[f64; 3]) -> Vector3<f64> {
    let mut frame = Isometry3::identity();
    let names = ["coxa_joint", "femur_joint", "tibia_joint", "ankle"];
    for (k, n) in names.iter().enumerate() {
        let j = tree
            .joints
            .iter()
            .find(|j| j.name == format!("{leg}_{n}"))
            .unwrap();
        frame *= j.origin;
        if let RawJointKind::Revolute(_) = j.kind {
            frame *= UnitQuaternion::from_scaled_axis(j.axis.normalize() * q[k]);
        }
    }
    frame.translation.vector
}

proptest! {
    #[test]
    fn lab_hexapod_feet_follow_the_urdf_chain(
        position in prop::array::uniform3(-1.0f64..1.0),
        phi in prop::array::uniform3(-3.0f64..3.0),
        q in prop::collection::vec(-2.0f64..2.0, 18),
    ) {
        let text = std::fs::read_to_string(lab()).unwrap();
        let tree = urdf::parse(&lab(), &text).unwrap();
        let robot = tree.build(Up::Z, &ContactChoice::CollisionSpheres).unwrap();
        let base = base_frame(position, phi);
        let mut data = RobotData::new(&robot);
        forward(&robot, &base, &q, &mut data);
        for (k, c) in robot.contacts.iter().enumerate() {
            let leg = &c.name[..2];
            let j = robot.joint_index(&format!("{leg}_coxa_joint")).unwrap();
            let want = base * nalgebra_point(ros_to_fbd(ros_foot(&tree, leg, &[q[j], q[j + 1], q[j + 2]])));
            prop_assert!((data.contacts[k] - want.coords).norm() < 1e-12, "{}", c.name);
        }
    }
}

fn nalgebra_point(v: Vector3<f64>) -> fbd_robot::nalgebra::Point3<f64> {
    v.into()
}

#[test]
fn zero_angles_put_the_feet_under_the_femur_ends() {
    let robot = urdf::load(&lab(), Up::Z, &ContactChoice::CollisionSpheres).unwrap();
    let mut data = RobotData::new(&robot);
    let base = Isometry3::from_parts(Translation3::new(0.0, 0.2, 0.0), UnitQuaternion::identity());
    forward(&robot, &base, &[0.0; 18], &mut data);
    let mounts = [
        ("lf", 0.12, 0.06, 45.0),
        ("rm", 0.0, -0.08, -90.0),
        ("rr", -0.12, -0.06, -135.0),
    ];
    for (leg, x, y, yaw) in mounts {
        let k = robot
            .contacts
            .iter()
            .position(|c| c.name.starts_with(leg))
            .unwrap();
        // The file writes the yaw to 10 digits.
        let (s, c) = f64::to_radians(yaw).sin_cos();
        let ros = Vector3::new(x + 0.13 * c, y + 0.13 * s, -0.12);
        let want = Vector3::new(0.0, 0.2, 0.0) + ros_to_fbd(ros);
        assert!(
            (data.contacts[k] - want).norm() < 1e-9,
            "{leg}: {} vs {want}",
            data.contacts[k]
        );
    }
}

#[test]
fn contact_points_can_be_named_links_or_spheres() {
    let choice = ContactChoice::Named(vec!["lf_foot".into(), "rr_foot_sphere".into()]);
    let robot = urdf::load(&lab(), Up::Z, &choice).unwrap();
    assert_eq!(robot.contacts.len(), 2);
    assert_eq!(robot.contacts[0].radius, 0.0, "a link is a point");
    assert_eq!(robot.contacts[1].radius, 0.01, "a sphere keeps its radius");
    let err = urdf::load(&lab(), Up::Z, &ContactChoice::Named(vec!["lf_fot".into()])).unwrap_err();
    let msg = err.to_string();
    assert!(
        msg.contains("lab_hexapod.urdf") && msg.contains("\"lf_fot\""),
        "{msg}"
    );
    assert!(msg.contains("did you mean \"lf_foot\""), "{msg}");
}

#[test]
fn rpy_is_roll_then_pitch_then_yaw_about_fixed_axes() {
    let r = rpy(0.3, -0.2, 1.1).to_rotation_matrix().into_inner();
    let (rx, ry, rz) = (
        fbd_kinematics::pose::rot_x(0.3),
        fbd_kinematics::pose::rot_y(-0.2),
        fbd_kinematics::pose::rot_z(1.1),
    );
    assert!((r - rz * ry * rx).norm() < 1e-15);
}

/// The error of `text` read as `bad.urdf`.
fn error(text: &str) -> RobotError {
    let file = Path::new("bad.urdf");
    urdf::parse(file, text)
        .and_then(|t| t.build(Up::Z, &ContactChoice::CollisionSpheres))
        .unwrap_err()
}

const HEAD: &str = "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"b\"><collision><geometry><sphere radius=\"0.01\"/></geometry></collision></link>\n";

#[test]
fn unsupported_and_malformed_descriptions_name_file_line_and_element() {
    let cases: [(String, &str); 9] = [
        (
            format!("{HEAD}<joint name=\"slide\" type=\"prismatic\">\n<parent link=\"a\"/><child link=\"b\"/></joint></robot>"),
            "bad.urdf:4: <joint name=\"slide\">: unsupported: a prismatic joint",
        ),
        (
            format!("{HEAD}<joint name=\"j\" type=\"revolute\"><parent link=\"a\"/><child link=\"b\"/></joint></robot>"),
            "bad.urdf:4: <joint name=\"j\">: missing <limit",
        ),
        (
            format!("{HEAD}<joint name=\"j\" type=\"continuous\"><parent link=\"a\"/><child link=\"b\"/>\n<origin xyz=\"0 0 zero\"/></joint></robot>"),
            "bad.urdf:5: <origin>: attribute xyz = \"0 0 zero\": 3 finite numbers",
        ),
        (
            format!("{HEAD}<link name=\"c\"/><joint name=\"j\" type=\"continuous\"><parent link=\"a\"/><child link=\"b\"/></joint>\n<joint name=\"k\" type=\"continuous\"><parent link=\"a\"/><child link=\"c\"/></joint>\n<joint name=\"m\" type=\"continuous\"><parent link=\"b\"/><child link=\"c\"/></joint></robot>"),
            "bad.urdf:6: <joint name=\"m\">: unsupported: a closed loop",
        ),
        (
            format!("{HEAD}</robot>"),
            "bad.urdf:3: <link name=\"b\">: two root links, \"a\" and \"b\"",
        ),
        (
            format!("{HEAD}<joint name=\"j\" type=\"continuous\"><parent link=\"a\"/><child link=\"c\"/></joint></robot>"),
            "bad.urdf:4: <joint name=\"j\">: child link \"c\" is not in the description",
        ),
        (
            format!("{HEAD}<joint name=\"j\" type=\"continuous\"><parent link=\"a\"/><child link=\"b\"/>\n<mimic joint=\"x\"/></joint></robot>"),
            "bad.urdf:5: <mimic>: unsupported: a mimic joint",
        ),
        (
            "<robot name=\"r\">\n<link name=\"a\"/>\n<link name=\"foot\"><collision><geometry>\n<mesh filename=\"foot.stl\"/></geometry></collision></link>\n<joint name=\"j\" type=\"continuous\"><parent link=\"a\"/><child link=\"foot\"/></joint></robot>".to_owned(),
            "bad.urdf:4: <mesh>: unsupported: a foot whose collision is a mesh",
        ),
        (
            "<robot name=\"r\">\n<link name=\"a\">\n</robot>".to_owned(),
            "bad.urdf:3: not well-formed XML",
        ),
    ];
    for (text, want) in cases {
        let msg = error(&text).to_string();
        assert!(msg.starts_with(want), "{msg}\n  wanted: {want}");
    }
    let missing = urdf::load(
        Path::new("no/such.urdf"),
        Up::Z,
        &ContactChoice::CollisionSpheres,
    )
    .unwrap_err()
    .to_string();
    assert!(
        missing.starts_with("no/such.urdf: cannot read: no such file"),
        "{missing}"
    );
}

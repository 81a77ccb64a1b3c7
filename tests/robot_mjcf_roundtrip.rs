//! The hexapod three ways: `fbd export mjcf` read back by the MJCF importer
//! (`fbd_robot::mjcf`), the D-H instance of the generic model
//! (`fbd_scenario::robot::hexapod_robot`) and the hand-expanded D-H
//! kinematics of `fbd-kinematics` agree on every body's mass, centre of
//! mass and inertia, every joint axis and every contact point, for random
//! poses and joint angles.

use std::path::Path;

use fbd_kinematics::hexapod::{HexapodConfig, HexapodData, HexapodModel, forward as dh_forward};
use fbd_kinematics::leg::LegGeometry;
use fbd_kinematics::pose::BodyPose;
use fbd_robot::forward::base_frame;
use fbd_robot::nalgebra::Vector3;
use fbd_robot::{ContactChoice, RobotData, RobotModel, Up, forward};
use fbd_sim::spatial::SpatialParams;
use proptest::prelude::*;

fn imported(p: &SpatialParams) -> RobotModel {
    let xml = fbd_scenario::mjcf::mjcf(p, "roundtrip.toml").unwrap();
    let file = Path::new("hexapod.xml");
    fbd_robot::mjcf::parse(file, &xml)
        .and_then(|t| t.build(Up::Y, &ContactChoice::CollisionSpheres))
        .unwrap()
}

fn geometry(p: &SpatialParams) -> HexapodModel {
    HexapodModel::new(
        p.side,
        LegGeometry {
            a: p.upper_length,
            c: p.lower_length,
        },
        p.upper_com,
        p.lower_com,
    )
}

#[test]
fn the_three_hexapods_have_the_same_bodies() {
    let p = SpatialParams::default();
    let mjcf = imported(&p);
    let dh = fbd_scenario::robot::hexapod_robot(&p);
    assert!((mjcf.mass() - dh.mass()).abs() < 1e-12);
    assert_eq!(mjcf.joints.len(), 18);
    for body in &dh.bodies {
        if body.mass == 0.0 {
            continue; // the massless coxa: a frame of its own in each
        }
        let b = &mjcf.bodies[mjcf.body_index(&body.name).unwrap()];
        assert!((b.mass - body.mass).abs() < 1e-12, "{}", body.name);
        // Same frames (fbd's body frame; D-H frames 2 and 3 at the hip and
        // knee), so the same centre of mass and inertia in them.
        assert!((b.com - body.com).norm() < 1e-12, "{}", body.name);
        assert!(
            (b.inertia - body.inertia).norm() < 1e-12,
            "{}: {} vs {}",
            body.name,
            b.inertia,
            body.inertia
        );
    }
    for j in &dh.joints {
        let k = &mjcf.joints[mjcf.joint_index(&j.name).unwrap()];
        assert_eq!(k.limits, j.limits, "{}", j.name);
    }
    let mut names: Vec<&str> = mjcf.contacts.iter().map(|c| c.name.as_str()).collect();
    let mut want: Vec<&str> = dh.contacts.iter().map(|c| c.name.as_str()).collect();
    names.sort_unstable();
    want.sort_unstable();
    assert_eq!(names, want);
    // Each contact point sits on the same body.
    for c in &dh.contacts {
        let k = mjcf.contacts.iter().find(|k| k.name == c.name).unwrap();
        assert_eq!(
            mjcf.bodies[k.body].name, dh.bodies[c.body].name,
            "{}",
            c.name
        );
    }
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]
    #[test]
    fn the_three_hexapods_move_alike(
        position in prop::array::uniform3(-1.0f64..1.0),
        phi in prop::array::uniform3(-3.0f64..3.0),
        joints in prop::array::uniform6(prop::array::uniform3(-3.2f64..3.2)),
    ) {
        let p = SpatialParams::default();
        let models = [imported(&p), fbd_scenario::robot::hexapod_robot(&p)];
        let mut reference = HexapodData::new();
        let cfg = HexapodConfig { pose: BodyPose::new(position, phi), joints };
        dh_forward(&geometry(&p), &cfg, &mut reference);
        for m in &models {
            let q: Vec<f64> = m
                .joints
                .iter()
                .map(|j| {
                    let (k, n) = j.name.strip_prefix("theta").unwrap().split_once('_').unwrap();
                    joints[n.parse::<usize>().unwrap() - 1][k.parse::<usize>().unwrap() - 1]
                })
                .collect();
            let mut d = RobotData::new(m);
            forward(m, &base_frame(position, phi), &q, &mut d);
            for (c, x) in m.contacts.iter().zip(&d.contacts) {
                let n: usize = c.name[c.name.len() - 1..].parse().unwrap();
                let l = &reference.legs[n - 1];
                let want = match &c.name[..c.name.len() - 1] {
                    "tip" => l.tip,
                    "knee" => l.knee,
                    _ => l.hip,
                };
                prop_assert!((x - want).norm() < 1e-12, "{}", c.name);
            }
            for (b, body) in m.bodies.iter().enumerate() {
                let want: Option<Vector3<f64>> = match body.name.as_str() {
                    "body" => Some(reference.body_com),
                    n if n.starts_with("upper") && !n.contains('/') => {
                        Some(reference.legs[n[5..].parse::<usize>().unwrap() - 1].upper_com)
                    }
                    n if n.starts_with("lower") => {
                        Some(reference.legs[n[5..].parse::<usize>().unwrap() - 1].lower_com)
                    }
                    _ => None,
                };
                if let Some(want) = want {
                    prop_assert!((d.com(m, b) - want).norm() < 1e-12, "{}", body.name);
                }
            }
            for (j, joint) in m.joints.iter().enumerate() {
                let (k, n) = joint.name.strip_prefix("theta").unwrap().split_once('_').unwrap();
                let l = &reference.legs[n.parse::<usize>().unwrap() - 1];
                let want = [l.hip_axis, l.upper_versor, l.lower_versor][k.parse::<usize>().unwrap() - 1];
                prop_assert!((d.axes[j] - want).norm() < 1e-12, "{}", joint.name);
            }
        }
    }
}

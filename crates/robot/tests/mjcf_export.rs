//! Any robot model written as MJCF (`fbd_robot::mjcf_export`) and read
//! back by the MJCF importer is the same robot: the same mass, joints and
//! limits, and the same contact points, centres of mass and joint axes at
//! random poses — for the lab hexapod (URDF) and the paper's hexapod built
//! from D-H rows (whose massless two-axis hips fold into the upper links).

use std::path::Path;

use fbd_kinematics::hexapod::HexapodModel;
use fbd_robot::dh::{HexapodLayout, HexapodMasses, hexapod};
use fbd_robot::forward::base_frame;
use fbd_robot::mjcf_export::to_mjcf;
use fbd_robot::nalgebra::Isometry3;
use fbd_robot::{ContactChoice, RobotData, RobotModel, Up, forward};
use proptest::prelude::*;

fn lab() -> RobotModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/robots/lab_hexapod.urdf");
    fbd_robot::urdf::load(&path, Up::Z, &ContactChoice::CollisionSpheres).unwrap()
}

fn paper() -> RobotModel {
    hexapod(
        &HexapodModel::default(),
        &HexapodMasses::default(),
        &HexapodLayout::default(),
    )
}

fn round_trip(m: &RobotModel) -> RobotModel {
    let xml = to_mjcf(m, 9.81, 0.001, &Isometry3::identity());
    fbd_robot::mjcf::parse(Path::new("export.xml"), &xml)
        .and_then(|t| t.build(Up::Y, &ContactChoice::CollisionSpheres))
        .unwrap_or_else(|e| panic!("{e}\n{xml}"))
}

#[test]
fn the_export_keeps_mass_joints_limits_and_actuators() {
    for m in [lab(), paper()] {
        let back = round_trip(&m);
        assert!((back.mass() - m.mass()).abs() < 1e-12);
        let names = |r: &RobotModel| {
            r.joints
                .iter()
                .map(|j| (j.name.clone(), j.limits))
                .collect::<Vec<_>>()
        };
        assert_eq!(names(&back), names(&m));
        assert_eq!(back.contacts.len(), m.contacts.len());
        assert_eq!(back.actuators.len(), m.actuators.len());
    }
    // The paper's hexapod: the massless coxa folds into the upper link,
    // which then carries two hinges, as `fbd export mjcf` writes it.
    let xml = to_mjcf(&paper(), 9.81, 0.001, &Isometry3::identity());
    assert!(!xml.contains("coxa1"), "{xml}");
    assert!(!xml.contains("1e-9"));
}

fn q_of(model: &RobotModel, reference: &RobotModel, q: &[f64]) -> Vec<f64> {
    model
        .joints
        .iter()
        .map(|j| q[reference.joint_index(&j.name).unwrap()])
        .collect()
}

fn check(
    m: &RobotModel,
    position: [f64; 3],
    phi: [f64; 3],
    q: &[f64],
) -> Result<(), TestCaseError> {
    let back = round_trip(m);
    let base = base_frame(position, phi);
    let mut a = RobotData::new(m);
    forward(m, &base, q, &mut a);
    let mut b = RobotData::new(&back);
    forward(&back, &base, &q_of(&back, m, q), &mut b);
    for (c, p) in m.contacts.iter().zip(&a.contacts) {
        let k = back.contacts.iter().position(|d| d.name == c.name).unwrap();
        prop_assert!((b.contacts[k] - p).norm() < 1e-12, "{}", c.name);
    }
    for (j, joint) in m.joints.iter().enumerate() {
        let k = back.joint_index(&joint.name).unwrap();
        prop_assert!((b.axes[k] - a.axes[j]).norm() < 1e-12, "{}", joint.name);
    }
    for (i, body) in m.bodies.iter().enumerate().filter(|(_, b)| b.mass > 0.0) {
        let k = back.body_index(&body.name).unwrap();
        prop_assert!((back.bodies[k].mass - body.mass).abs() < 1e-12);
        prop_assert!(
            (b.com(&back, k) - a.com(m, i)).norm() < 1e-12,
            "{}",
            body.name
        );
        let (ra, rb) = (
            a.frames[i].rotation.to_rotation_matrix().into_inner(),
            b.frames[k].rotation.to_rotation_matrix().into_inner(),
        );
        let (ia, ib) = (
            ra * body.inertia * ra.transpose(),
            rb * back.bodies[k].inertia * rb.transpose(),
        );
        prop_assert!((ia - ib).norm() < 1e-12, "{}", body.name);
    }
    prop_assert!((b.total_com(&back) - a.total_com(m)).norm() < 1e-12);
    Ok(())
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn lab_hexapod_round_trips(
        position in prop::array::uniform3(-1.0f64..1.0),
        phi in prop::array::uniform3(-3.0f64..3.0),
        q in prop::collection::vec(-2.0f64..2.0, 18),
    ) {
        check(&lab(), position, phi, &q)?;
    }

    #[test]
    fn paper_hexapod_round_trips(
        position in prop::array::uniform3(-1.0f64..1.0),
        phi in prop::array::uniform3(-3.0f64..3.0),
        q in prop::collection::vec(-3.0f64..3.0, 18),
    ) {
        check(&paper(), position, phi, &q)?;
    }
}

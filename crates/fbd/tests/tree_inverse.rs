//! Inverse dynamics by the FBD method on any robot ([`fbd_dynamics::tree`])
//! against finite differences of the kinematics alone: along a smooth
//! motion through the given state, every body's centre-of-mass and angular
//! accelerations are the second differences of its positions and frames,
//! and the root's external wrench is the rate of change of the whole
//! robot's linear and angular momentum less gravity (Newton–Euler for the
//! whole robot, which the body-by-body pass never writes).

use std::path::Path;

use fbd_dynamics::tree::{TreeData, TreeMotion, inverse};
use fbd_robot::dh::{HexapodLayout, HexapodMasses, hexapod};
use fbd_robot::nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};
use fbd_robot::{ContactChoice, RobotData, RobotModel, Up, forward};
use proptest::prelude::*;

/// The state along `q(t) = q + qd·t + qdd·t²/2`, the root's origin likewise
/// and its rotation `exp(ω·t + α·t²/2)·R`: velocities and accelerations at
/// t = 0 are the motion's.
fn at(motion: &TreeMotion, t: f64) -> (Isometry3<f64>, Vec<f64>) {
    let m = motion;
    let p = m.base.translation.vector + m.velocity * t + m.acceleration * t * t / 2.0;
    let turn = UnitQuaternion::from_scaled_axis(m.omega * t + m.alpha * t * t / 2.0);
    let base = Isometry3::from_parts(Translation3::from(p), turn * m.base.rotation);
    let q = (0..m.q.len())
        .map(|j| m.q[j] + m.qd[j] * t + m.qdd[j] * t * t / 2.0)
        .collect();
    (base, q)
}

/// Linear momentum and angular momentum about the inertial origin.
fn momentum(
    model: &RobotModel,
    motion: &TreeMotion,
    t: f64,
    h: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    let mut d = [
        RobotData::new(model),
        RobotData::new(model),
        RobotData::new(model),
    ];
    for (k, s) in [-1.0, 0.0, 1.0].into_iter().enumerate() {
        let (base, q) = at(motion, t + s * h);
        forward(model, &base, &q, &mut d[k]);
    }
    let (mut p, mut l) = (Vector3::zeros(), Vector3::zeros());
    for (b, body) in model.bodies.iter().enumerate() {
        let c = d[1].com(model, b);
        let v = (d[2].com(model, b) - d[0].com(model, b)) / (2.0 * h);
        // ω from the frame's change: R(t+h)·R(t−h)ᵀ ≈ exp(2h·ω).
        let r = d[2].frames[b].rotation * d[0].frames[b].rotation.inverse();
        let w = r.scaled_axis() / (2.0 * h);
        let rot = d[1].frames[b].rotation.to_rotation_matrix().into_inner();
        let inertia = rot * body.inertia * rot.transpose();
        p += body.mass * v;
        l += c.cross(&(body.mass * v)) + inertia * w;
    }
    (p, l)
}

fn check(model: &RobotModel, motion: &TreeMotion) -> Result<(), TestCaseError> {
    let g = Vector3::new(0.0, -9.81, 0.0);
    let mut data = TreeData::new(model);
    inverse(model, motion, g, &mut data);
    // Body accelerations against second differences.
    let h = 1e-4;
    let mut d = [
        RobotData::new(model),
        RobotData::new(model),
        RobotData::new(model),
    ];
    for (k, s) in [-1.0, 0.0, 1.0].into_iter().enumerate() {
        let (base, q) = at(motion, s * h);
        forward(model, &base, &q, &mut d[k]);
    }
    for b in 0..model.bodies.len() {
        let fd = (d[2].com(model, b) - 2.0 * d[1].com(model, b) + d[0].com(model, b)) / (h * h);
        let scale = 1.0 + data.com_acceleration[b].norm();
        prop_assert!(
            (fd - data.com_acceleration[b]).norm() < 1e-4 * scale,
            "body {b}: {fd} vs {}",
            data.com_acceleration[b]
        );
    }
    // The whole robot: F_ext + M·g = dP/dt, M_ext + Σ c×m·g = dL/dt (about
    // the inertial origin; the root's moment is about its frame origin).
    // Central differences at h and h/2, Richardson-extrapolated: O(h⁴).
    // (A plain central difference at h = 1e-3 errs by h²/6 times the third
    // derivative of L, about 2e-3 on the fastest motions of the strategy:
    // links turning at 20 rad/s a metre from the origin.)
    let rate = |h: f64| {
        let (p1, l1) = momentum(model, motion, h, 1e-5);
        let (p0, l0) = momentum(model, motion, -h, 1e-5);
        ((p1 - p0) / (2.0 * h), (l1 - l0) / (2.0 * h))
    };
    let h = 1e-3;
    let ((dp_h, dl_h), (dp_2, dl_2)) = (rate(h), rate(h / 2.0));
    let (dp, dl) = ((4.0 * dp_2 - dp_h) / 3.0, (4.0 * dl_2 - dl_h) / 3.0);
    let mass = model.mass();
    let o = motion.base.translation.vector;
    let force = data.base_force + mass * g;
    let torque_gravity: Vector3<f64> = (0..model.bodies.len())
        .map(|b| data.kin.com(model, b).cross(&(model.bodies[b].mass * g)))
        .sum();
    let moment = data.base_moment + o.cross(&data.base_force) + torque_gravity;
    let scale = 1.0 + dp.norm() + mass * 9.81;
    prop_assert!(
        (force - dp).norm() < 1e-4 * scale,
        "force {force} vs dP/dt {dp}"
    );
    let scale = 1.0 + dl.norm() + torque_gravity.norm();
    prop_assert!(
        (moment - dl).norm() < 1e-4 * scale,
        "moment {moment} vs dL/dt {dl}"
    );
    // Every joint: the torque is the moment's axis component.
    for j in 0..model.joints.len() {
        prop_assert!(
            data.constraint_moment(j).dot(&data.kin.axes[j]).abs()
                < 1e-9 * (1.0 + data.moment[j].norm())
        );
    }
    Ok(())
}

fn motion(
    model: &RobotModel,
    base: ([f64; 3], [f64; 3]),
    rates: ([f64; 3], [f64; 3], [f64; 3], [f64; 3]),
    joints: &[[f64; 3]],
) -> TreeMotion {
    let n = model.joints.len();
    let v = Vector3::from;
    TreeMotion {
        base: Isometry3::from_parts(
            Translation3::from(v(base.0)),
            UnitQuaternion::from_scaled_axis(v(base.1)),
        ),
        velocity: v(rates.0),
        omega: v(rates.1),
        acceleration: v(rates.2),
        alpha: v(rates.3),
        q: (0..n).map(|j| joints[j][0]).collect(),
        qd: (0..n).map(|j| joints[j][1]).collect(),
        qdd: (0..n).map(|j| joints[j][2]).collect(),
    }
}

fn lab() -> RobotModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/robots/lab_hexapod.urdf");
    fbd_robot::urdf::load(&path, Up::Z, &ContactChoice::CollisionSpheres).unwrap()
}

fn vec3(r: f64) -> impl Strategy<Value = [f64; 3]> {
    prop::array::uniform3(-r..r)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn lab_hexapod_forces_balance_the_momentum(
        base in (vec3(1.0), vec3(3.0)),
        rates in (vec3(2.0), vec3(3.0), vec3(20.0), vec3(30.0)),
        joints in prop::collection::vec(prop::array::uniform3(-2.0f64..2.0), 18),
    ) {
        let model = lab();
        let joints: Vec<[f64; 3]> = joints.iter().map(|j| [j[0], 3.0 * j[1], 20.0 * j[2]]).collect();
        check(&model, &motion(&model, base, rates, &joints))?;
    }

    #[test]
    fn dh_hexapod_forces_balance_the_momentum(
        base in (vec3(1.0), vec3(3.0)),
        rates in (vec3(2.0), vec3(3.0), vec3(20.0), vec3(30.0)),
        joints in prop::collection::vec(prop::array::uniform3(-3.0f64..3.0), 18),
    ) {
        let model = hexapod(&Default::default(), &HexapodMasses::default(), &HexapodLayout::default());
        let joints: Vec<[f64; 3]> = joints.iter().map(|j| [j[0], 3.0 * j[1], 20.0 * j[2]]).collect();
        check(&model, &motion(&model, base, rates, &joints))?;
    }
}

#[test]
fn a_robot_standing_still_needs_its_weight_and_no_moment_about_its_com() {
    let model = lab();
    let n = model.joints.len();
    let m = TreeMotion {
        base: Isometry3::identity(),
        velocity: Vector3::zeros(),
        omega: Vector3::zeros(),
        acceleration: Vector3::zeros(),
        alpha: Vector3::zeros(),
        q: vec![0.3; n],
        qd: vec![0.0; n],
        qdd: vec![0.0; n],
    };
    let mut data = TreeData::new(&model);
    inverse(&model, &m, Vector3::new(0.0, -9.81, 0.0), &mut data);
    let w = model.mass() * 9.81;
    assert!((data.base_force - Vector3::new(0.0, w, 0.0)).norm() < 1e-12 * w);
    // Held at the root's origin: the moment is the weight's about it.
    let c = data.kin.total_com(&model);
    let want = -c.cross(&Vector3::new(0.0, -w, 0.0));
    assert!((data.base_moment - want).norm() < 1e-12 * w);
    // A foot link carries 0.01 kg: its tibia's joint holds the tibia and
    // foot (0.11 kg) against gravity.
    let j = model.joint_index("lf_tibia_joint").unwrap();
    assert!((data.force[j] - Vector3::new(0.0, 0.11 * 9.81, 0.0)).norm() < 1e-12);
    let _ = Point3::<f64>::origin();
}

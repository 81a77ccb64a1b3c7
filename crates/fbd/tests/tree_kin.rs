//! The kinematics of any robot model ([`fbd_dynamics::tree::kin`]):
//!
//! * every analytic Jacobian (centres of mass, contact points, points fixed
//!   anywhere on a body, angular velocities) against central differences
//!   of `eval` through the workspace's one checker
//!   ([`fbd_kinematics::fd::check_jacobian`]), on the lab hexapod URDF,
//!   on the same robot with oblique and negative joint axes (the general
//!   rotation of the kinematics and its coordinate-axis shortcuts), and on
//!   the paper's hexapod built from D-H rows, at random configurations;
//! * the frames, axes and contact points against [`fbd_robot::forward`]
//!   with the same base pose ([`fbd_robot::forward::base_frame`]);
//! * on the D-H hexapod, equality (1e-12) with the closed-form
//!   spatial kinematics ([`fbd_dynamics::spatial::SpatialKin`]): centres of
//!   mass, tips, knees, hips, joint axes and every dense Jacobian, which
//!   share the `q` layout;
//! * the Jacobians' sparsity: exactly the base's and the ancestor joints'
//!   columns, in increasing `q` order.
//!
//! (That `eval` does not allocate is not tested here: counting
//! allocations needs a counting global allocator, a dev-dependency this
//! crate does not have.)

use std::path::Path;

use fbd_dynamics::mechanism::{ContactPoints, PointKind};
use fbd_dynamics::spatial::{SpatialInertia, SpatialKin, SpatialMechanism};
use fbd_dynamics::tree::kin::{Columns, TreeKin};
use fbd_kinematics::JointLimits;
use fbd_kinematics::fd::{FdTolerance, check_jacobian};
use fbd_kinematics::hexapod::HexapodModel;
use fbd_robot::dh::{HexapodLayout, HexapodMasses, hexapod};
use fbd_robot::forward::base_frame;
use fbd_robot::nalgebra::{Matrix3, Vector3};
use fbd_robot::{ContactChoice, RobotData, RobotModel, Up, forward};
use proptest::prelude::*;

fn lab() -> RobotModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/robots/lab_hexapod.urdf");
    fbd_robot::urdf::load(&path, Up::Z, &ContactChoice::CollisionSpheres).unwrap()
}

/// The lab hexapod with every joint's axis changed: an oblique axis (the
/// kinematics' general rotation), a negative coordinate axis, and the
/// description's own, leg joint by leg joint.
fn oblique() -> RobotModel {
    let mut model = lab();
    for (j, joint) in model.joints.iter_mut().enumerate() {
        match j % 3 {
            0 => {
                joint.axis = fbd_robot::nalgebra::Unit::new_normalize(Vector3::new(1.0, 2.0, -2.0))
            }
            1 => joint.axis = -Vector3::y_axis(),
            _ => {}
        }
    }
    model
}

fn dh_hexapod(legs: &[usize]) -> RobotModel {
    let layout = HexapodLayout {
        legs: legs.to_vec(),
        ..HexapodLayout::default()
    };
    hexapod(&HexapodModel::default(), &HexapodMasses::default(), &layout)
}

/// A point fixed in body `b`'s frame, different for every body.
fn local_point(b: usize) -> Vector3<f64> {
    let f = b as f64;
    Vector3::new(0.07 - 0.01 * f, -0.05 + 0.02 * f, 0.11 - 0.015 * f)
}

/// `vee((M − Mᵀ)/2)` of `M = R·R0ᵀ`: its derivative at `R = R0` is the
/// angular velocity `ω` (`Ṙ·R0ᵀ = [ω]×`).
fn turn(r: &Matrix3<f64>, r0: &Matrix3<f64>) -> Vector3<f64> {
    let m = r * r0.transpose();
    Vector3::new(
        m[(2, 1)] - m[(1, 2)],
        m[(0, 2)] - m[(2, 0)],
        m[(1, 0)] - m[(0, 1)],
    ) / 2.0
}

/// What row block `k` of the stacked function is (for failure messages).
fn block_name(model: &RobotModel, k: usize) -> String {
    let nb = model.bodies.len();
    let name = |b: usize| model.bodies[b].name.clone();
    match k {
        k if k < nb => format!("centre of mass of {}", name(k)),
        k if k < 2 * nb => format!("angular velocity of {}", name(k - nb)),
        k if k < 3 * nb => format!("point fixed on {}", name(k - 2 * nb)),
        k => format!("contact {}", model.contacts[k - 3 * nb].name),
    }
}

/// Every Jacobian of `model` at `q` against central differences.
fn check_fd(model: &RobotModel, q: &[f64]) -> Result<(), TestCaseError> {
    let nb = model.bodies.len();
    let nc = model.contacts.len();
    let mut kin = TreeKin::new(model);
    kin.eval(model, q);
    let nq = kin.nq();
    prop_assert_eq!(nq, q.len());
    let blocks = 3 * nb + nc;
    let m = 3 * blocks;

    // The analytic Jacobian, dense, row-major.
    let mut dense = vec![0.0; m * nq];
    let mut block = vec![0.0; 3 * nq];
    let mut put = |k: usize, cols: Columns| {
        cols.dense_into(&mut block);
        dense[3 * k * nq..3 * (k + 1) * nq].copy_from_slice(&block);
    };
    for b in 0..nb {
        put(b, kin.com_jacobian(b));
        put(nb + b, kin.angular_jacobian(b));
        put(
            2 * nb + b,
            kin.point_jacobian(b, &kin.body_point(b, &local_point(b))),
        );
    }
    for c in 0..nc {
        put(3 * nb + c, kin.contact_jacobian(c));
    }

    // The same quantities by evaluation.
    let r0 = kin.rotation.clone();
    let mut work = TreeKin::new(model);
    let f = |x: &[f64], out: &mut [f64]| {
        work.eval(model, x);
        for b in 0..nb {
            out[3 * b..3 * b + 3].copy_from_slice(work.com[b].as_slice());
            let w = turn(&work.rotation[b], &r0[b]);
            out[3 * (nb + b)..3 * (nb + b) + 3].copy_from_slice(w.as_slice());
            let p = work.body_point(b, &local_point(b));
            out[3 * (2 * nb + b)..3 * (2 * nb + b) + 3].copy_from_slice(p.as_slice());
        }
        for c in 0..nc {
            out[3 * (3 * nb + c)..3 * (3 * nb + c) + 3].copy_from_slice(work.contact[c].as_slice());
        }
    };
    let jac = |i: usize, j: usize| dense[i * nq + j];
    if let Err(e) = check_jacobian(q, m, f, jac, FdTolerance::default()) {
        return Err(TestCaseError::fail(format!(
            "{} of {}, row {} (x, y, z), q index {}: {e}",
            block_name(model, e.i / 3),
            model.name,
            e.i % 3,
            e.j
        )));
    }
    Ok(())
}

/// The frames, axes and contact points agree with `fbd_robot::forward`.
fn check_forward(model: &RobotModel, q: &[f64]) -> Result<(), TestCaseError> {
    let mut kin = TreeKin::new(model);
    kin.eval(model, q);
    let base = base_frame([q[0], q[1], q[2]], [q[3], q[4], q[5]]);
    let mut data = RobotData::new(model);
    forward(model, &base, &q[6..], &mut data);
    for b in 0..model.bodies.len() {
        let frame = data.frames[b];
        let rot = frame.rotation.to_rotation_matrix().into_inner();
        prop_assert!(
            (kin.origin[b] - frame.translation.vector).norm() < 1e-12,
            "origin {b}"
        );
        prop_assert!((kin.rotation[b] - rot).norm() < 1e-12, "rotation {b}");
        prop_assert!((kin.com[b] - data.com(model, b)).norm() < 1e-12, "com {b}");
    }
    for j in 0..model.joints.len() {
        let child = model.joints[j].child;
        prop_assert!((kin.axis[j] - data.axes[j]).norm() < 1e-12, "axis {j}");
        prop_assert!((kin.axis[j].norm() - 1.0).abs() < 1e-12, "axis {j} is unit");
        prop_assert!((kin.joint_origin[j] - data.frames[child].translation.vector).norm() < 1e-12);
    }
    for c in 0..model.contacts.len() {
        // The sphere's centre, and the point that touches level ground,
        // its radius below.
        prop_assert!(
            (kin.contact_center[c] - data.contacts[c]).norm() < 1e-12,
            "contact {c}"
        );
        let lowest = data.contacts[c] - model.contacts[c].radius * Vector3::y();
        prop_assert!((kin.contact[c] - lowest).norm() < 1e-12, "contact {c}");
    }
    Ok(())
}

/// Each Jacobian has exactly the base's and the ancestor joints' columns,
/// in increasing `q` index, and `apply` is the dense product.
fn check_sparsity(model: &RobotModel, q: &[f64]) -> Result<(), TestCaseError> {
    let mut kin = TreeKin::new(model);
    kin.eval(model, q);
    let nq = kin.nq();
    let v: Vec<f64> = (0..nq).map(|i| 0.3 - 0.07 * i as f64).collect();
    let mut depth = 0;
    for b in 0..model.bodies.len() {
        // The ancestors by walking up the parents.
        let mut up = Vec::new();
        let mut at = b;
        while let Some(j) = model.bodies[at].joint {
            up.push(j);
            at = model.joints[j].parent;
        }
        up.reverse();
        prop_assert_eq!(kin.ancestors(b), &up[..]);
        depth = depth.max(up.len());
        let mut expect_point: Vec<usize> = (0..6).collect();
        let mut expect_angle: Vec<usize> = (3..6).collect();
        expect_point.extend(up.iter().map(|j| 6 + j));
        expect_angle.extend(up.iter().map(|j| 6 + j));
        for (cols, expect) in [
            (kin.com_jacobian(b), &expect_point),
            (kin.angular_jacobian(b), &expect_angle),
        ] {
            let idx: Vec<usize> = cols.iter().map(|(i, _)| i).collect();
            prop_assert_eq!(&idx, expect);
            prop_assert_eq!(cols.len(), expect.len());
            let mut dense = vec![0.0; 3 * nq];
            cols.dense_into(&mut dense);
            let mut jv = Vector3::zeros();
            for r in 0..3 {
                jv[r] = (0..nq).map(|i| dense[r * nq + i] * v[i]).sum();
            }
            prop_assert!((cols.apply(&v) - jv).norm() < 1e-12);
        }
    }
    prop_assert_eq!(kin.max_depth(), depth);
    Ok(())
}

/// Equality with the hexapod's own spatial kinematics.
fn check_spatial(legs: &[usize], q: &[f64]) -> Result<(), TestCaseError> {
    let model = dh_hexapod(legs);
    let mut kin = TreeKin::new(&model);
    kin.eval(&model, q);
    let inertia = SpatialInertia {
        body_mass: 10.0,
        body_inertia: Matrix3::identity(),
        upper_mass: 0.3,
        upper_axial: 6e-5,
        upper_transverse: 1.0e-3,
        lower_mass: 1.1,
        lower_axial: 1.2e-4,
        lower_transverse: 1.6e-2,
    };
    let all = ContactPoints {
        tips: true,
        knees: true,
        hips: true,
    };
    let mech = SpatialMechanism::new(
        HexapodModel::default(),
        legs,
        &inertia,
        9.81,
        all,
        &JointLimits::default(),
    );
    let mut sk = SpatialKin::new(&mech);
    sk.eval(&mech, q);
    let nq = kin.nq();
    prop_assert_eq!(nq, mech.layout().nq);
    let tol = 1e-12;
    let (mut a, mut b) = (vec![0.0; 3 * nq], vec![0.0; 3 * nq]);
    let dense = |cols: &fbd_dynamics::spatial::Columns, out: &mut [f64]| {
        out.fill(0.0);
        for (i, c) in cols.iter() {
            for r in 0..3 {
                out[r * nq + i] = c[r];
            }
        }
    };
    let same = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < tol);

    // Bodies by name: body ↔ central, upper{n}, lower{n} (coxa{n} has no
    // counterpart: it is the massless frame of the two-axis hip).
    let mut matched = 0;
    for (sb, body) in mech.bodies.iter().enumerate() {
        let tb = model.body_index(&body.name).expect("same body names");
        matched += 1;
        prop_assert!(
            (kin.com[tb] - sk.com[sb]).norm() < tol,
            "com of {}",
            body.name
        );
        dense(&sk.com_jacobian(&mech, sb), &mut b);
        kin.com_jacobian(tb).dense_into(&mut a);
        prop_assert!(
            same(&a, &b),
            "com Jacobian of {}: {:?} vs {:?}",
            body.name,
            a,
            b
        );
        dense(&sk.angular_jacobian(&mech, sb), &mut b);
        kin.angular_jacobian(tb).dense_into(&mut a);
        prop_assert!(
            same(&a, &b),
            "angular Jacobian of {}: {:?} vs {:?}",
            body.name,
            a,
            b
        );
    }
    prop_assert_eq!(matched, 1 + 2 * legs.len());

    // Contact points (tips, knees, hips) by name.
    prop_assert_eq!(mech.contacts.len(), model.contacts.len());
    for spec in &mech.contacts {
        let c = model
            .contacts
            .iter()
            .position(|c| c.name == spec.name)
            .expect("same contact names");
        let s = mech.legs.iter().position(|&n| n == spec.leg).unwrap();
        let p = sk.point(&mech, s, spec.kind);
        prop_assert!((kin.contact[c] - p).norm() < tol, "{}", spec.name);
        dense(&sk.contact_jacobian(&mech, s, spec.kind), &mut b);
        kin.contact_jacobian(c).dense_into(&mut a);
        prop_assert!(
            same(&a, &b),
            "Jacobian of {}: {:?} vs {:?}",
            spec.name,
            a,
            b
        );
    }

    // Hips and knees as joint origins, and the joint axes.
    for (s, &n) in legs.iter().enumerate() {
        let joint = |k: usize| model.joint_index(&format!("theta{k}_{n}")).unwrap();
        let hip = sk.point(&mech, s, PointKind::Hip);
        let knee = sk.point(&mech, s, PointKind::Knee);
        prop_assert!((kin.joint_origin[joint(1)] - hip).norm() < tol);
        prop_assert!((kin.joint_origin[joint(2)] - hip).norm() < tol);
        prop_assert!((kin.joint_origin[joint(3)] - knee).norm() < tol);
        for (k, axis) in sk.axes(&mech, s).iter().enumerate() {
            prop_assert!(
                (kin.axis[joint(k + 1)] - axis).norm() < tol,
                "axis {k} of leg {n}"
            );
        }
    }
    for k in 0..3 {
        prop_assert!((kin.phi_axes[k] - sk.fk.phi_axes[k]).norm() < tol);
    }
    Ok(())
}

/// A random `q` for `joints` joints: the base within a metre, φ within
/// ±1.2 rad (away from the parametrisation's singularity at |φz| = π/2),
/// the joints within ±3 rad.
fn q_strategy(joints: usize) -> impl Strategy<Value = Vec<f64>> {
    (
        proptest::collection::vec(-1.0..1.0f64, 3),
        proptest::collection::vec(-1.2..1.2f64, 3),
        proptest::collection::vec(-3.0..3.0f64, joints),
    )
        .prop_map(|(r, phi, theta)| [r, phi, theta].concat())
}

const LAB_JOINTS: usize = 18;

#[test]
fn the_lab_hexapod_has_the_joints_the_strategy_draws() {
    let model = lab();
    assert_eq!(model.joints.len(), LAB_JOINTS);
    assert_eq!(dh_hexapod(&[1, 2, 3, 4, 5, 6]).joints.len(), 18);
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn lab_hexapod_jacobians_match_central_differences(q in q_strategy(LAB_JOINTS)) {
        let model = lab();
        check_fd(&model, &q)?;
    }

    #[test]
    fn dh_hexapod_jacobians_match_central_differences(q in q_strategy(18)) {
        let model = dh_hexapod(&[1, 2, 3, 4, 5, 6]);
        check_fd(&model, &q)?;
    }

    #[test]
    fn eval_matches_forward(q in q_strategy(18)) {
        check_forward(&lab(), &q)?;
        check_forward(&oblique(), &q)?;
        check_forward(&dh_hexapod(&[1, 2, 3, 4, 5, 6]), &q)?;
    }

    #[test]
    fn oblique_axes_jacobians_match_central_differences(q in q_strategy(LAB_JOINTS)) {
        check_fd(&oblique(), &q)?;
    }

    #[test]
    fn jacobians_have_the_ancestor_columns(q in q_strategy(18)) {
        check_sparsity(&lab(), &q)?;
        check_sparsity(&dh_hexapod(&[1, 2, 3, 4, 5, 6]), &q)?;
    }

    #[test]
    fn dh_hexapod_matches_the_spatial_kinematics(q in q_strategy(18)) {
        check_spatial(&[1, 2, 3, 4, 5, 6], &q)?;
    }

    #[test]
    fn dh_hexapod_with_three_legs_matches_the_spatial_kinematics(q in q_strategy(9)) {
        check_spatial(&[1, 3, 4], &q)?;
    }
}

/// Every field `eval` fills, for comparing two workspaces' evaluations.
fn frames(kin: &TreeKin) -> Vec<f64> {
    let mut v = Vec::new();
    for list in [
        &kin.origin,
        &kin.com,
        &kin.axis,
        &kin.joint_origin,
        &kin.contact,
        &kin.contact_center,
    ] {
        v.extend(list.iter().flat_map(|x| x.iter().copied()));
    }
    v.extend(kin.rotation.iter().flat_map(|r| r.iter().copied()));
    v.extend(kin.phi_axes.iter().flat_map(|x| x.iter().copied()));
    v
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]

    /// `eval` at the `q` of its last evaluation finds its frames in place:
    /// whatever the workspace evaluated before, it holds, bit for bit, a
    /// fresh workspace's evaluation at the last `q` (a `q` that differs in
    /// a single bit, a zero's sign included, is evaluated again).
    #[test]
    fn eval_again_at_the_same_q_is_a_fresh_evaluation(
        q1 in q_strategy(LAB_JOINTS),
        q2 in q_strategy(LAB_JOINTS),
        j in 6..6 + LAB_JOINTS,
    ) {
        let model = lab();
        let fresh = |q: &[f64]| {
            let mut kin = TreeKin::new(&model);
            kin.eval(&model, q);
            frames(&kin)
        };
        let mut kin = TreeKin::new(&model);
        prop_assert!(kin.evaluated_at().is_none());
        for q in [&q1, &q2, &q2, &q1, &q1] {
            kin.eval(&model, q);
            prop_assert_eq!(kin.evaluated_at(), Some(&q[..]));
            prop_assert_eq!(frames(&kin), fresh(q));
        }
        let mut signed = q1.clone();
        signed[j] = 0.0;
        kin.eval(&model, &signed);
        signed[j] = -0.0;
        kin.eval(&model, &signed);
        prop_assert_eq!(
            frames(&kin).iter().map(|x| x.to_bits()).collect::<Vec<_>>(),
            fresh(&signed).iter().map(|x| x.to_bits()).collect::<Vec<_>>()
        );
    }
}

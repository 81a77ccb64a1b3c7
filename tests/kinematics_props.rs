//! Property tests of `fbd-kinematics`: the docs/reference.md test vector through the
//! 3D model, planar ≡ hexapod restricted to the plane, FK/IK round trips,
//! proper rotations, analytic Jacobians against finite differences, errors.

mod common;

use std::f64::consts::TAU;

use common::strategies::{self as st, fixed_config};
use fbd_kinematics::KinematicsError;
use fbd_kinematics::body::LEG_COUNT;
use fbd_kinematics::dh::{a01, a12, a23, body_to_leg_base, rotation_block};
use fbd_kinematics::fd::{FdTolerance, check_jacobian};
use fbd_kinematics::hexapod::{
    HexapodConfig, HexapodData, HexapodModel, LegPoint, NQ, forward, joint_index,
};
use fbd_kinematics::ik::{KneeBranch, leg_ik, leg_ik_body};
use fbd_kinematics::leg::LegGeometry;
use fbd_kinematics::nalgebra::{Matrix3, Vector3};
use fbd_kinematics::planar::{self, PlanarChains};
use fbd_kinematics::pose::BodyPose;
use fbd_kinematics::stance::stance_ik;
use proptest::prelude::*;

/// Legs 3 and 4 as array indices.
const LEG3: usize = 2;
const LEG4: usize = 3;

fn angle_close(a: f64, b: f64, tol: f64) -> bool {
    let d = (a - b).rem_euclid(TAU);
    d.min(TAU - d) <= tol
}

fn assert_proper_rotation(r: &Matrix3<f64>) -> Result<(), TestCaseError> {
    let e = (r.transpose() * r - Matrix3::identity()).norm();
    prop_assert!(e < 1e-12, "RᵀR − I = {e:e}");
    prop_assert!(
        (r.determinant() - 1.0).abs() < 1e-12,
        "det {}",
        r.determinant()
    );
    Ok(())
}

/// Configuration of the hexapod equivalent to planar `q` (legs 3 and 4).
fn hexapod_from_planar(q: &[f64; planar::NQ]) -> HexapodConfig {
    let mut cfg = HexapodConfig {
        pose: BodyPose::new(
            [q[planar::RX], q[planar::RY], 0.0],
            [0.0, 0.0, q[planar::PHI_Z]],
        ),
        joints: [[0.0, 0.0, 4.0]; LEG_COUNT],
    };
    for (leg, idx) in [(0, LEG3), (1, LEG4)] {
        cfg.joints[idx] = [
            0.0,
            q[planar::theta2_index(leg)],
            q[planar::theta3_index(leg)],
        ];
    }
    cfg
}

/// The leg's "radial" coordinate ρ = −a·cosθ2 + c·cos(θ2+θ3) (< 0: outward).
fn rho(g: &LegGeometry, th: [f64; 3]) -> f64 {
    -g.a * th[1].cos() + g.c * (th[1] + th[2]).cos()
}

#[test]
fn spec_test_vector_through_hexapod_fk() {
    let model = HexapodModel::new(0.25, LegGeometry { a: 0.2, c: 0.42 }, 0.5, 0.5);
    let mut cfg = HexapodConfig {
        pose: BodyPose::new([0.0, 0.6, 0.0], [0.0; 3]),
        ..HexapodConfig::default()
    };
    cfg.joints[LEG3] = [0.0, 0.0, 245f64.to_radians()];
    cfg.joints[LEG4] = [0.0, 0.0, 255f64.to_radians()];
    let mut d = HexapodData::new();
    forward(&model, &cfg, &mut d);
    let want3 = Vector3::new(-0.594006, 0.219351, 0.0);
    let want4 = Vector3::new(0.525210, 0.194311, 0.0);
    assert!(
        (d.legs[LEG3].tip - want3).amax() < 1e-6,
        "{}",
        d.legs[LEG3].tip
    );
    assert!(
        (d.legs[LEG4].tip - want4).amax() < 1e-6,
        "{}",
        d.legs[LEG4].tip
    );
    // Paper §5.2: leg 3's versors along +Z, leg 4's along −Z, body's +Z.
    assert!((d.legs[LEG3].upper_versor - Vector3::z()).norm() < 1e-15);
    assert!((d.legs[LEG4].lower_versor + Vector3::z()).norm() < 1e-15);
    assert!((d.body_versor - Vector3::z()).norm() < 1e-15);
    // And IK brings the angles back.
    for (leg, th3) in [(LEG3, 245.0f64), (LEG4, 255.0)] {
        let tip_body = cfg.pose.to_body(&d.legs[leg].tip);
        let th = leg_ik_body(&model, leg, &tip_body, KneeBranch::Up).unwrap();
        assert!(th[0].abs() < 1e-12 && th[1].abs() < 1e-12, "{th:?}");
        assert!(angle_close(th[2], th3.to_radians(), 1e-12), "{th:?}");
    }
}

#[test]
fn error_cases() {
    let g = LegGeometry { a: 0.2, c: 0.42 };
    // Too far.
    let e = leg_ik(&g, &Vector3::new(-0.5, 0.3, -0.4), KneeBranch::Up).unwrap_err();
    let KinematicsError::Unreachable {
        distance,
        min_reach,
        max_reach,
    } = e
    else {
        panic!("{e:?}")
    };
    assert!((distance - (0.5f64 * 0.5 + 0.09 + 0.16).sqrt()).abs() < 1e-15);
    assert!((min_reach - 0.22).abs() < 1e-15 && (max_reach - 0.62).abs() < 1e-15);
    let msg = e.to_string();
    assert!(
        msg.contains(&format!("{distance:.6}")) && msg.contains("0.620000"),
        "{msg}"
    );
    // Too close (inside |a − c|).
    let e = leg_ik(&g, &Vector3::new(-0.1, 0.0, 0.0), KneeBranch::Down).unwrap_err();
    assert!(e.to_string().contains("distance 0.100000 m"), "{e}");
    // On the θ1 axis.
    let e = leg_ik(&g, &Vector3::new(0.0, 0.0, -0.4), KneeBranch::Up).unwrap_err();
    assert!(matches!(e, KinematicsError::SingularHip { .. }), "{e}");
    assert!(e.to_string().contains("θ1"), "{e}");
    // Stance: the failing leg is named.
    let model = HexapodModel::default();
    let pose = BodyPose::new([0.0, 0.4, 0.0], [0.0; 3]);
    let mut tips = [Vector3::new(0.0, 0.0, 0.0); LEG_COUNT];
    let mut d = HexapodData::new();
    forward(
        &model,
        &HexapodConfig {
            pose,
            joints: [[0.0, 0.2, 4.3]; LEG_COUNT],
        },
        &mut d,
    );
    for (t, l) in tips.iter_mut().zip(&d.legs) {
        *t = l.tip;
    }
    tips[1] = d.legs[1].hip + Vector3::new(0.0, -0.3, 0.0); // under the hip of leg 2
    let e = stance_ik(&model, &pose, &tips, &[KneeBranch::Up; LEG_COUNT]).unwrap_err();
    let KinematicsError::Leg { leg, source } = &e else {
        panic!("{e:?}")
    };
    assert_eq!(*leg, 2);
    assert!(matches!(**source, KinematicsError::SingularHip { .. }));
    assert!(e.to_string().starts_with("leg 2: "), "{e}");
}

proptest! {
    #![proptest_config(fixed_config(256, 0x6b69_6e65_6d61_7431))]

    /// docs/reference.md: the planar model is the hexapod restricted to legs 3 and 4,
    /// θ1 = 0, φx = φy = 0, Rz = 0 — every point, and the Jacobians.
    #[test]
    fn planar_equals_restricted_hexapod(
        side in st::length(),
        leg in st::leg_geometry(),
        fu in st::com_fraction(),
        fl in st::com_fraction(),
        q in st::planar_q(),
    ) {
        let model = HexapodModel::new(side, leg, fu, fl);
        let (chains, ix) = PlanarChains::two_leg(&model.planar_geometry());
        let mut pd = chains.new_data();
        chains.eval_positions(&q, &mut pd);
        chains.eval_jacobians(&mut pd);
        let mut hd = HexapodData::new();
        forward(&model, &hexapod_from_planar(&q), &mut hd);
        let body = pd.pos[ix.body_com];
        prop_assert!((hd.body_com - Vector3::new(body[0], body[1], 0.0)).norm() < 1e-12);
        prop_assert!((hd.body_versor - Vector3::z()).norm() < 1e-12);
        for (pl, idx) in [(0usize, LEG3), (1, LEG4)] {
            let pairs = [
                (ix.hip[pl], LegPoint::Hip),
                (ix.knee[pl], LegPoint::Knee),
                (ix.tip[pl], LegPoint::Tip),
                (ix.upper_com[pl], LegPoint::UpperCom),
                (ix.lower_com[pl], LegPoint::LowerCom),
            ];
            for (p, pt) in pairs {
                let h = hd.leg_point(idx, pt);
                let w = pd.pos[p];
                prop_assert!(h.z == 0.0, "{pt:?} z = {}", h.z);
                prop_assert!(
                    (h.x - w[0]).abs() < 1e-12 && (h.y - w[1]).abs() < 1e-12,
                    "leg {} {pt:?}: hexapod {h} vs planar {w:?}", idx + 1
                );
                // Planar Jacobian columns (Rx, Ry, φz, θ2, θ3) = hexapod's.
                let j = hd.leg_point_jacobian(idx, pt);
                let cols = [
                    (planar::RX, 0),
                    (planar::RY, 1),
                    (planar::PHI_Z, 5),
                    (planar::theta2_index(pl), 7),
                    (planar::theta3_index(pl), 8),
                ];
                for axis in 0..2 {
                    for (pc, hc) in cols {
                        let (a, b) = (pd.jac_at(p, axis, pc), j[(axis, hc)]);
                        prop_assert!((a - b).abs() < 1e-12, "{pt:?} ({axis},{pc}): {a} vs {b}");
                    }
                }
            }
            // Versors: leg 3 +Z, leg 4 −Z (paper §5.2).
            let s = planar::side_sign(pl);
            prop_assert!((hd.legs[idx].upper_versor + s * Vector3::z()).norm() < 1e-12);
            prop_assert!((hd.legs[idx].lower_versor + s * Vector3::z()).norm() < 1e-12);
        }
    }
}

proptest! {
    #![proptest_config(fixed_config(512, 0x6b69_6e65_6d61_7432))]

    /// FK(IK(p)) = p on both branches, for any reachable, non-singular p.
    #[test]
    fn fk_of_ik_is_identity(leg in st::leg_geometry(), th in st::joint_angles()) {
        let p = leg.tip(th);
        let scale = leg.max_reach();
        prop_assume!(p.xy().norm() > 1e-6 * scale);
        for branch in [KneeBranch::Up, KneeBranch::Down] {
            let sol = leg_ik(&leg, &p, branch).map_err(|e| TestCaseError::fail(e.to_string()))?;
            prop_assert_eq!(KneeBranch::of(sol[2]), branch);
            let back = leg.tip(sol);
            prop_assert!((back - p).norm() < 1e-9 * scale, "{branch:?}: {back} vs {p}");
        }
    }

    /// IK(FK(θ)) = θ (mod 2π) on θ's own branch, with the leg outward.
    #[test]
    fn ik_of_fk_is_identity(leg in st::leg_geometry(), th in st::joint_angles()) {
        let scale = leg.max_reach();
        prop_assume!(rho(&leg, th) < -1e-2 * scale && th[2].sin().abs() > 1e-2);
        let sol = leg_ik(&leg, &leg.tip(th), KneeBranch::of(th[2]))
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        for k in 0..3 {
            prop_assert!(angle_close(sol[k], th[k], 1e-7), "θ{}: {sol:?} vs {th:?}", k + 1);
        }
    }

    /// The body-frame IK inverts the 24-DOF FK of every leg; the stance
    /// helper inverts it for all six legs at once from inertial targets.
    /// Positions must come back for every leg; angles too where the leg
    /// stands outward on a well-defined branch.
    #[test]
    fn body_and_stance_ik_invert_fk(model in st::hexapod_model(), cfg in st::hexapod_config()) {
        let g = *model.leg();
        let scale = g.max_reach();
        let mut d = HexapodData::new();
        forward(&model, &cfg, &mut d);
        for (i, l) in d.legs.iter().enumerate() {
            let axis_dist = (l.tip - l.hip).cross(&l.hip_axis).norm();
            prop_assume!(axis_dist > 1e-6 * scale, "leg {} tip on its θ1 axis", i + 1);
        }
        let regular = cfg.joints.map(|th| rho(&g, th) < -1e-2 * scale && th[2].sin().abs() > 1e-2);
        let branches = cfg.joints.map(|th| KneeBranch::of(th[2]));
        let check = |i: usize, sol: [f64; 3], w: &mut HexapodData| -> Result<(), TestCaseError> {
            let mut c2 = cfg;
            c2.joints[i] = sol;
            forward(&model, &c2, w);
            let err = (w.legs[i].tip - d.legs[i].tip).norm();
            prop_assert!(err < 1e-9 * (1.0 + scale), "leg {}: tip off by {err:e}", i + 1);
            if regular[i] {
                let th = cfg.joints[i];
                for k in 0..3 {
                    prop_assert!(angle_close(sol[k], th[k], 1e-7), "leg {}: {sol:?} vs {th:?}", i + 1);
                }
            }
            Ok(())
        };
        let mut w = HexapodData::new();
        for (i, (l, &branch)) in d.legs.iter().zip(&branches).enumerate() {
            let tb = cfg.pose.to_body(&l.tip);
            let sol = leg_ik_body(&model, i, &tb, branch)
                .map_err(|e| TestCaseError::fail(format!("leg {}: {e}", i + 1)))?;
            check(i, sol, &mut w)?;
        }
        let tips = d.legs.map(|l| l.tip);
        let sol = stance_ik(&model, &cfg.pose, &tips, &branches)
            .map_err(|e| TestCaseError::fail(e.to_string()))?;
        for (i, s) in sol.iter().enumerate() {
            check(i, *s, &mut w)?;
        }
    }

    /// Targets beyond `a + c` are unreachable, with their distance reported.
    #[test]
    fn unreachable_reports_distance(
        leg in st::leg_geometry(),
        p in st::position(),
        excess in 1e-6..1.0f64,
    ) {
        let p = Vector3::from(p);
        prop_assume!(p.norm() > 1e-3);
        let target = p.normalize() * (leg.max_reach() + excess);
        let e = leg_ik(&leg, &target, KneeBranch::Up).unwrap_err();
        prop_assert!(e.to_string().contains(&format!("{:.6}", target.norm())), "{e}");
        let is_unreachable = matches!(
            e,
            KinematicsError::Unreachable { distance, .. } if (distance - target.norm()).abs() < 1e-12
        );
        prop_assert!(is_unreachable, "{e:?}");
    }
}

proptest! {
    #![proptest_config(fixed_config(256, 0x6b69_6e65_6d61_7433))]

    /// Body pose, D-H blocks and the FK's rotation are proper rotations.
    #[test]
    fn rotations_are_proper(pose in st::body_pose(), th in st::joint_angles(), g in 0.0..TAU) {
        assert_proper_rotation(&pose.rotation())?;
        assert_proper_rotation(&rotation_block(&a01(th[0])))?;
        assert_proper_rotation(&rotation_block(&a12(th[1], 0.3)))?;
        assert_proper_rotation(&rotation_block(&a23(th[2], 0.4)))?;
        assert_proper_rotation(&rotation_block(&body_to_leg_base(g, 0.2)))?;
        let mut d = HexapodData::new();
        forward(&HexapodModel::default(), &HexapodConfig { pose, ..Default::default() }, &mut d);
        assert_proper_rotation(&d.rotation)?;
        for l in &d.legs {
            prop_assert!((l.upper_versor.norm() - 1.0).abs() < 1e-12);
            prop_assert!(l.upper_versor.dot(&l.hip_axis).abs() < 1e-12);
        }
    }

    /// `∂tip/∂θ` of one leg (frame 0) against central differences, and its
    /// inertial form from the 24-DOF data.
    #[test]
    fn leg_tip_jacobian_matches_fd(leg in st::leg_geometry(), th in st::joint_angles()) {
        let j = leg.tip_jacobian(th);
        let r = check_jacobian(
            &th,
            3,
            |x, out| out.copy_from_slice(leg.tip([x[0], x[1], x[2]]).as_slice()),
            |i, k| j[(i, k)],
            FdTolerance::default(),
        );
        prop_assert!(r.is_ok(), "{}", r.unwrap_err());
    }

    /// Every point Jacobian of the 24-DOF FK against central differences over
    /// all 24 coordinates.
    #[test]
    fn hexapod_point_jacobians_match_fd(model in st::hexapod_model(), cfg in st::hexapod_config()) {
        let q = cfg.to_q();
        let mut d = HexapodData::new();
        forward(&model, &cfg, &mut d);
        let points = [LegPoint::Hip, LegPoint::Knee, LegPoint::Tip, LegPoint::UpperCom, LegPoint::LowerCom];
        let mut w = HexapodData::new();
        for leg in 0..LEG_COUNT {
            let jacs = points.map(|p| d.leg_point_jacobian(leg, p));
            let first = joint_index(leg, 0);
            let r = check_jacobian(
                &q,
                3 * points.len(),
                |x, out| {
                    let x: &[f64; NQ] = x.try_into().unwrap();
                    forward(&model, &HexapodConfig::from_q(x), &mut w);
                    for (k, &p) in points.iter().enumerate() {
                        out[3 * k..3 * k + 3].copy_from_slice(w.leg_point(leg, p).as_slice());
                    }
                },
                |i, k| {
                    let j = &jacs[i / 3];
                    match k {
                        0..6 => j[(i % 3, k)],
                        _ if (first..first + 3).contains(&k) => j[(i % 3, 6 + k - first)],
                        _ => 0.0,
                    }
                },
                FdTolerance::default(),
            );
            prop_assert!(r.is_ok(), "leg {}: {}", leg + 1, r.unwrap_err());
            // The inertial joint Jacobian is Rot·C_γ·(frame-0 Jacobian).
            let j0 = model.leg().tip_jacobian(cfg.joints[leg]);
            let want = d.rotation * model.mount(leg).rotation() * j0;
            prop_assert!((d.tip_joint_jacobian(leg) - want).norm() < 1e-12);
        }
    }
}

//! The hexapod dynamics configuration: the dispatch rule (kinematic gait vs
//! 3D dynamics), every key into the right [`SpatialParams`] field (degrees
//! to radians, the inertial angular velocity to `φ̇`), one-line errors that
//! name the key, `legs = [3, 4]`, and the `config.toml` round trip.

use std::path::Path;

use fbd_kinematics::nalgebra::{Matrix3, Vector3};
use fbd_kinematics::pose::BodyPose;
use fbd_scenario::{Config, HexapodConfig, euler_rate_matrix, load, parse_str};
use fbd_sim::spatial::{SpatialControl, SpatialParams, default_q0, hexagon_inertia};

fn hexapod(text: &str) -> HexapodConfig {
    match parse_str(text, "h.toml", &[]) {
        Ok(Config::Hexapod(h)) => *h,
        other => panic!("expected a hexapod config: {other:?}"),
    }
}

fn params(text: &str) -> SpatialParams {
    hexapod(text).spatial_params("h.toml").unwrap()
}

/// The error of `text`: one line, naming `key`.
fn error(text: &str, key: &str) -> String {
    let e = match parse_str(text, "h.toml", &[]) {
        Err(e) => e.to_string(),
        Ok(Config::Hexapod(h)) => match h.spatial_params("h.toml") {
            Err(e) => e.to_string(),
            Ok(_) => panic!("accepted: {text}"),
        },
        Ok(_) => panic!("accepted: {text}"),
    };
    assert!(!e.contains('\n'), "not one line: {e}");
    assert!(e.starts_with("h.toml"), "does not name the file: {e}");
    assert!(e.contains(key), "does not name `{key}`: {e}");
    e
}

const H: &str = "model = \"hexapod\"\n";

fn example(name: &str) -> HexapodConfig {
    let p = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../examples")
        .join(name);
    match load(&p) {
        Ok(Config::Hexapod(h)) => *h,
        other => panic!("{name}: {other:?}"),
    }
}

#[test]
fn a_bare_hexapod_is_the_default_dynamics() {
    let h = hexapod(H);
    assert!(h.is_dynamic());
    assert_eq!(
        h.spatial_params("h.toml").unwrap(),
        SpatialParams::default()
    );
}

#[test]
fn dispatch_rule() {
    let gait = "[gait]\nperiod = 1.0\n";
    let control_gait = "[control]\nkind = \"gait\"\nkp = 100.0\n";
    for (text, dynamic) in [
        (String::new(), true),
        (gait.to_owned(), false),
        (format!("{gait}{control_gait}"), true),
        ("[control]\nkind = \"pd\"\nkp = 100.0\n".to_owned(), true),
        ("dynamics = \"kinematic\"\n".to_owned(), false),
        (format!("dynamics = \"fbd\"\n{gait}{control_gait}"), true),
        (format!("dynamics = \"kinematic\"\n{gait}"), false),
    ] {
        let h = hexapod(&format!("{H}{text}"));
        assert_eq!(h.is_dynamic(), dynamic, "{text}");
        // The decision is written back, so config.toml repeats the run.
        let full = Config::Hexapod(Box::new(h.clone())).to_toml();
        let want = if dynamic { "fbd" } else { "kinematic" };
        assert!(full.contains(&format!("dynamics = \"{want}\"")), "{full}");
    }
    // The kinematic gait examples stay kinematic; the dynamics examples
    // are dynamic.
    for name in [
        "hexapod_tripod.toml",
        "hexapod_turn.toml",
        "hexapod_wave_slope.toml",
        "hexapod_pose.toml",
    ] {
        assert!(!example(name).is_dynamic(), "{name}");
    }
    for name in [
        "hexapod_drop.toml",
        "hexapod_stand.toml",
        "hexapod_walk.toml",
        "hexapod_walk_ice.toml",
        "hexapod_slope.toml",
    ] {
        let h = example(name);
        assert!(h.is_dynamic(), "{name}");
        h.spatial_params(name).unwrap();
    }
}

/// `ω` of the body from a central difference of `Rot(φ)`: `Ṙ·Rᵀ = [ω]×`.
fn omega_fd(phi: [f64; 3], phi_dot: [f64; 3]) -> Vector3<f64> {
    let h = 1e-6;
    let rot = |s: f64| {
        BodyPose::new([0.0; 3], std::array::from_fn(|k| phi[k] + s * phi_dot[k])).rotation()
    };
    let rdot: Matrix3<f64> = (rot(h) - rot(-h)) / (2.0 * h);
    let w = rdot * rot(0.0).transpose();
    Vector3::new(w[(2, 1)], w[(0, 2)], w[(1, 0)])
}

#[test]
fn every_key_reaches_its_field() {
    let text = format!(
        "{H}legs = [1, 2, 3, 4, 5, 6]
[time]
dt = 0.002
duration = 0.5
[world]
gravity = 9.7
[body]
mass = 8.0
inertia = [0.2, 0.35, 0.25, 0.01, -0.02, 0.03]
side = 0.3
[leg]
upper_length = 0.22
upper_mass = 0.4
upper_inertia = 0.003
upper_radius = 0.025
upper_com = 0.4
lower_length = 0.45
lower_mass = 1.2
lower_radius = 0.012
lower_com = 0.7
theta1_deg = [-80.0, 80.0]
theta2_deg = [-100.0, 110.0]
theta3_deg = [190.0, 320.0]
[initial]
position = [0.1, 0.7, -0.2]
velocity = [0.3, -0.4, 0.5]
phi_deg = [20.0, -35.0, 40.0]
omega_deg = [10.0, -20.0, 30.0]
[initial.leg2]
theta_deg = [5.0, -10.0, 260.0]
rate_deg = [1.0, 2.0, -3.0]
[terrain]
kind = \"slope\"
angle_deg = 5.0
height = -0.01
mu_static = 0.7
mu_dynamic = 0.5
[contact]
points = [\"tips\", \"knees\"]
[output]
stride = 5
[control]
kind = \"pd\"
kp = 300.0
kd = 8.0
torque_limit = 40.0
[control.leg5]
target_deg = [0.0, -20.0, 290.0]
"
    );
    let p = params(&text);
    let r = f64::to_radians;
    assert_eq!((p.dt, p.duration, p.gravity), (0.002, 0.5, 9.7));
    assert_eq!(p.body_mass, 8.0);
    assert_eq!(p.body_inertia, [0.2, 0.35, 0.25, 0.01, -0.02, 0.03]);
    assert_eq!(p.side, 0.3);
    assert_eq!(
        (
            p.upper_length,
            p.upper_mass,
            p.upper_inertia,
            p.upper_radius,
            p.upper_com
        ),
        (0.22, 0.4, 0.003, 0.025, 0.4)
    );
    // Omitted transverse inertia: the solid cylinder m·(3r² + c²)/12.
    let lower = 1.2 * (3.0 * 0.012 * 0.012 + 0.45 * 0.45) / 12.0;
    assert_eq!(
        (
            p.lower_length,
            p.lower_mass,
            p.lower_inertia,
            p.lower_radius,
            p.lower_com
        ),
        (0.45, 1.2, lower, 0.012, 0.7)
    );
    assert_eq!(p.joint_limits.theta1, [r(-80.0), r(80.0)]);
    assert_eq!(p.joint_limits.theta2, [r(-100.0), r(110.0)]);
    assert_eq!(p.joint_limits.theta3, [r(190.0), r(320.0)]);
    assert_eq!(p.legs, vec![1, 2, 3, 4, 5, 6]);
    assert_eq!(p.q0.len(), 24);
    assert_eq!(&p.q0[..6], &[0.1, 0.7, -0.2, r(20.0), r(-35.0), r(40.0)]);
    assert_eq!(&p.q0[9..12], &[r(5.0), r(-10.0), r(260.0)]);
    // Legs without [initial.legN]: the default (0°, 0°, 250°).
    assert_eq!(&p.q0[6..9], &default_q0()[6..9]);
    assert_eq!(&p.qdot0[..3], &[0.3, -0.4, 0.5]);
    assert_eq!(&p.qdot0[9..12], &[r(1.0), r(2.0), r(-3.0)]);
    assert!(p.qdot0[12..].iter().all(|v| *v == 0.0));
    // ω (inertial) → φ̇: E(φ)·φ̇ = ω, and the rotation matrices turn at ω.
    let phi = [r(20.0), r(-35.0), r(40.0)];
    let omega = Vector3::new(r(10.0), r(-20.0), r(30.0));
    let phi_dot = [p.qdot0[3], p.qdot0[4], p.qdot0[5]];
    let e = euler_rate_matrix(phi) * Vector3::from(phi_dot);
    assert!((e - omega).norm() < 1e-14 * omega.norm(), "{e} vs {omega}");
    let fd = omega_fd(phi, phi_dot);
    assert!((fd - omega).norm() < 1e-8, "{fd} vs {omega}");
    assert_eq!(p.terrain.height(1.0, 0.3), -0.01 + r(5.0).tan());
    assert_eq!((p.friction.mu_static, p.friction.mu_dynamic), (0.7, 0.5));
    assert!(p.contact_points.tips && p.contact_points.knees && !p.contact_points.hips);
    assert_eq!(p.stride, 5);
    let SpatialControl::Pd {
        kp,
        kd,
        torque_limit,
        target,
    } = &p.control
    else {
        panic!("{:?}", p.control)
    };
    assert_eq!((*kp, *kd, *torque_limit), (300.0, 8.0, Some(40.0)));
    // Targets default to the leg's initial angles.
    assert_eq!(target[1], [r(5.0), r(-10.0), r(260.0)]);
    assert_eq!(target[4], [0.0, r(-20.0), r(290.0)]);
    assert_eq!(target[0], [p.q0[6], p.q0[7], p.q0[8]]);
}

#[test]
fn body_inertia_forms() {
    let inertia = |v: &str| params(&format!("{H}[body]\ninertia = {v}\n")).body_inertia;
    assert_eq!(inertia("0.3"), [0.3, 0.3, 0.3, 0.0, 0.0, 0.0]);
    assert_eq!(inertia("[0.2, 0.3, 0.4]"), [0.2, 0.3, 0.4, 0.0, 0.0, 0.0]);
    // A flat body (I1 + I2 = I3) is a body.
    assert_eq!(
        inertia("[0.1, 0.2, 0.3, 0.0, 0.0, 0.0]"),
        [0.1, 0.2, 0.3, 0.0, 0.0, 0.0]
    );
    // Omitted: the hexagonal plate of the configured mass and side.
    assert_eq!(
        params(&format!("{H}[body]\nmass = 6.0\nside = 0.2\n")).body_inertia,
        hexagon_inertia(6.0, 0.2)
    );
    for bad in [
        "[0.1, 0.2]",
        "[0.1, 0.2, 0.3, 0.4]",
        "[0.1, 0.1, 0.5]",
        "[0.2, 0.2, 0.2, 0.3, 0.0, 0.0]",
        "-0.1",
        "[0.2, nan, 0.2]",
    ] {
        error(&format!("{H}[body]\ninertia = {bad}\n"), "body.inertia");
    }
    let e = error(&format!("{H}[body]\ninertia = \"big\"\n"), "body.inertia");
    assert!(e.contains("h.toml:3:"), "{e}");
    // The planar model takes one number.
    error("[body]\ninertia = [0.1, 0.2, 0.3]\n", "body.inertia");
}

#[test]
fn legs_three_and_four() {
    let text = format!(
        "{H}legs = [3, 4]\n[initial]\nposition = [0.0, 0.6, 0.0]\n[initial.leg3]\ntheta_deg = [0.0, 0.0, 245.0]\n[initial.leg4]\ntheta_deg = [0.0, 0.0, 255.0]\n[control]\nkind = \"trajectory\"\nkp = 50.0\n[control.leg3]\ntimes = [0.0, 0.5]\ntarget_deg = [[0.0, 0.0, 245.0], [0.0, 10.0, 250.0]]\n[control.leg4]\ntimes = [0.0]\ntarget_deg = [[0.0, 0.0, 255.0]]\n"
    );
    let p = params(&text);
    assert_eq!(p.legs, vec![3, 4]);
    let r = f64::to_radians;
    assert_eq!(
        p.q0,
        vec![
            0.0,
            0.6,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            0.0,
            r(245.0),
            0.0,
            0.0,
            r(255.0)
        ]
    );
    assert_eq!(p.qdot0, vec![0.0; 12]);
    let SpatialControl::Trajectory { legs, .. } = &p.control else {
        panic!("{:?}", p.control)
    };
    assert_eq!(legs.len(), 2);
    assert_eq!(legs[0].times, vec![0.0, 0.5]);
    assert_eq!(legs[0].at(0.25), [0.0, r(5.0), (r(245.0) + r(250.0)) / 2.0]);
    // config.toml leaves out the other legs' tables and reads back.
    let c = parse_str(&text, "h.toml", &[]).unwrap();
    let full = c.to_toml();
    assert!(!full.contains("[initial.leg1]"), "{full}");
    let again = parse_str(&full, "full.toml", &[]).unwrap();
    assert_eq!(c, again);
    let Config::Hexapod(h) = again else { panic!() };
    assert_eq!(h.spatial_params("full.toml").unwrap(), p);
    // A table of a leg the model does not have is an error naming it.
    error(
        &format!("{H}legs = [3, 4]\n[initial.leg1]\ntheta_deg = [0.0, 0.0, 250.0]\n"),
        "initial.leg1",
    );
    error(
        &format!(
            "{H}legs = [3, 4]\n[control]\nkind = \"pd\"\n[control.leg5]\ntarget_deg = [0.0, 0.0, 250.0]\n"
        ),
        "control.leg5",
    );
}

#[test]
fn bad_values_name_their_key() {
    let cases: &[(&str, &str)] = &[
        ("[initial]\nphi_deg = [0.0, 0.0, 90.0]\n", "initial.phi_deg"),
        (
            "[initial]\nphi_deg = [10.0, 0.0, -90.0]\n",
            "initial.phi_deg",
        ),
        ("[initial]\nphi_deg = [0.0, 0.0]\n", "initial.phi_deg"),
        (
            "[initial]\nomega_deg = [0.0, nan, 0.0]\n",
            "initial.omega_deg",
        ),
        ("[initial]\nvelocity = [0.0, 1.0]\n", "initial.velocity"),
        (
            "[initial.leg2]\ntheta_deg = [0.0, inf, 250.0]\n",
            "initial.leg2.theta_deg",
        ),
        (
            "[initial.leg6]\nrate_deg = [0.0, 1.0]\n",
            "initial.leg6.rate_deg",
        ),
        ("[leg]\nupper_radius = 0.0\n", "leg.upper_radius"),
        ("[leg]\nlower_radius = -0.01\n", "leg.lower_radius"),
        ("[leg]\nlower_mass = 0.0\n", "leg.lower_mass"),
        ("legs = [4, 3]\n", "legs"),
        ("legs = [3, 3]\n", "legs"),
        ("legs = [0, 1]\n", "legs"),
        ("legs = [7]\n", "legs"),
        ("legs = []\n", "legs"),
        ("dynamics = \"warp\"\n", "dynamics"),
        ("[time]\ndt = 0.0\n", "time.dt"),
        (
            "[terrain]\nmu_static = 0.2\nmu_dynamic = 0.3\n",
            "terrain.mu_dynamic",
        ),
        ("[output]\nstride = 0\n", "output.stride"),
        ("[control]\nkind = \"gait\"\n", "gait"),
        ("[control]\nkind = \"pd\"\nkp = -1.0\n", "control.kp"),
        ("[control]\nkind = \"pd\"\nkd = nan\n", "control.kd"),
        (
            "[control]\nkind = \"pd\"\ntorque_limit = 0.0\n",
            "control.torque_limit",
        ),
        (
            "[control]\nkind = \"pd\"\n[control.leg1]\ntarget_deg = [1.0, 2.0]\n",
            "control.leg1.target_deg",
        ),
        (
            "[control]\nkind = \"pd\"\n[control.leg1]\ntimes = [0.0]\n",
            "control.leg1.times",
        ),
        (
            "[control]\nkind = \"none\"\n[control.leg2]\ntarget_deg = [0.0, 0.0, 250.0]\n",
            "control.leg2.target_deg",
        ),
        ("[control]\nkind = \"trajectory\"\n", "control.leg1.times"),
        (
            "[control]\nkind = \"trajectory\"\n[control.leg1]\ntimes = [0.0, 1.0]\ntarget_deg = [[0.0, 0.0, 250.0]]\n",
            "control.leg1.target_deg",
        ),
        (
            "[control]\nkind = \"trajectory\"\n[control.leg1]\ntimes = [1.0, 0.0]\ntarget_deg = [[0.0, 0.0, 250.0], [0.0, 0.0, 250.0]]\n",
            "control.leg1.times",
        ),
        (
            "dynamics = \"kinematic\"\n[control]\nkind = \"gait\"\n[gait]\n",
            "control.kind",
        ),
        (
            "dynamics = \"kinematic\"\n[control]\nkind = \"pd\"\n",
            "control",
        ),
        ("dynamics = \"kinematic\"\nlegs = [3, 4]\n", "legs"),
        ("dynamics = \"fbd\"\n[gait]\n", "gait"),
        (
            "legs = [3, 4]\n[control]\nkind = \"gait\"\n[gait]\n",
            "legs",
        ),
    ];
    for (text, key) in cases {
        error(&format!("{H}{text}"), key);
    }
    // Hexapod-only keys in a planar file.
    for (text, key) in [
        ("dynamics = \"fbd\"\n", "dynamics"),
        ("legs = [3, 4]\n", "legs"),
        ("[leg]\nupper_radius = 0.02\n", "leg.upper_radius"),
        ("[control]\nkind = \"gait\"\n", "control.kind"),
        (
            "[control]\nkind = \"pd\"\n[control.leg1]\ntarget_deg = [0.0, 250.0]\n",
            "control.leg1",
        ),
    ] {
        error(text, key);
    }
}

#[test]
fn gait_control_tracks_the_gait_of_the_same_run() {
    let p = params(&format!(
        "{H}[time]\nduration = 2.0\n[control]\nkind = \"gait\"\nkp = 300.0\nkd = 6.0\n[gait]\nperiod = 1.0\n"
    ));
    let SpatialControl::Gait { kp, kd, gait, .. } = &p.control else {
        panic!("{:?}", p.control)
    };
    assert_eq!((*kp, *kd), (300.0, 6.0));
    assert_eq!(gait.dt, p.dt);
    assert_eq!(p.dt, 0.001);
    assert_eq!(gait.steps, (p.duration / p.dt).round() as usize);
    // The dynamics start from the gait's initial pose: the default stance
    // on the ground.
    assert_eq!(&p.q0[..3], &gait.initial.position);
    for (n, joints) in gait.initial.joints.iter().enumerate() {
        assert_eq!(&p.q0[6 + 3 * n..9 + 3 * n], joints);
    }
    for f in &gait.initial_feet {
        assert!(f.y.abs() < 1e-9, "{f:?}");
    }
    assert_eq!(gait.kin.leg().a, p.upper_length);
    assert_eq!(gait.kin.side(), p.side);
}

#[test]
fn config_round_trips() {
    for text in [
        H.to_owned(),
        format!(
            "{H}[control]\nkind = \"pd\"\nkp = 200.0\nkd = 5.0\n[body]\ninertia = [0.2, 0.3, 0.2]\n"
        ),
        format!("{H}[time]\nduration = 1.0\n[control]\nkind = \"gait\"\nkp = 300.0\n[gait]\n"),
        format!(
            "{H}[initial]\nomega_deg = [30.0, 0.0, -10.0]\nphi_deg = [5.0, 10.0, 15.0]\n[body]\ninertia = 0.25\n"
        ),
        format!("{H}[gait]\n"),
    ] {
        let c = parse_str(&text, "h.toml", &[]).unwrap();
        let full = c.to_toml();
        let again = parse_str(&full, "full.toml", &[]).unwrap();
        assert_eq!(c, again, "{full}");
        assert_eq!(full, again.to_toml());
        let (Config::Hexapod(a), Config::Hexapod(b)) = (&c, &again) else {
            panic!()
        };
        assert_eq!(a.is_dynamic(), b.is_dynamic());
        if a.is_dynamic() {
            assert_eq!(
                a.spatial_params("h.toml").unwrap(),
                b.spatial_params("full.toml").unwrap(),
                "{full}"
            );
        }
    }
}

//! The `[leg] theta1_deg / theta2_deg / theta3_deg` keys: defaults, values
//! in radians, and errors that name the key.

use fbd_scenario::{Config, ConfigError, parse_str};

fn planar(text: &str) -> Result<fbd_sim::PlanarParams, ConfigError> {
    match parse_str(text, "t.toml", &[])? {
        Config::Planar(p) => Ok(p.params()),
        Config::Hexapod(_) => panic!("expected a planar config"),
    }
}

#[test]
fn omitted_keys_take_the_documented_defaults() {
    let p = planar("[time]\nduration = 0.1\n").unwrap();
    assert_eq!(p.joint_limits, fbd_sim::JointLimits::default());
}

#[test]
fn keys_are_degrees_and_reach_the_model_in_radians() {
    let p = planar("[leg]\ntheta2_deg = [-90.0, 45.0]\ntheta3_deg = [190.0, 300.0]\n").unwrap();
    let close = |a: [f64; 2], b: [f64; 2]| {
        (a[0] - b[0].to_radians()).abs() < 1e-15 && (a[1] - b[1].to_radians()).abs() < 1e-15
    };
    assert!(close(p.joint_limits.theta2, [-90.0, 45.0]));
    assert!(close(p.joint_limits.theta3, [190.0, 300.0]));
    assert_eq!(
        p.joint_limits.theta1,
        fbd_sim::JointLimits::default().theta1
    );
}

#[test]
fn bad_ranges_name_the_key() {
    for (text, key) in [
        ("[leg]\ntheta3_deg = [300.0, 200.0]\n", "leg.theta3_deg"),
        ("[leg]\ntheta2_deg = [10.0, 10.0]\n", "leg.theta2_deg"),
        ("[leg]\ntheta1_deg = [-inf, 10.0]\n", "leg.theta1_deg"),
        ("[leg]\ntheta2_deg = [nan, 10.0]\n", "leg.theta2_deg"),
    ] {
        let e = planar(text).unwrap_err().to_string();
        assert!(e.starts_with("t.toml: ") && e.contains(key), "{text}: {e}");
    }
    let e = planar("[leg]\ntheta2_deg = [1.0, 2.0, 3.0]\n")
        .unwrap_err()
        .to_string();
    assert!(e.contains("theta2_deg") && e.contains("2 numbers"), "{e}");
}

#[test]
fn an_initial_angle_outside_its_limits_names_the_key_and_the_excess() {
    let c = parse_str("[initial.leg3]\ntheta_deg = [0.0, 340.0]\n", "t.toml", &[]).unwrap();
    let Config::Planar(p) = c else {
        panic!("planar")
    };
    let e = p.model("t.toml").unwrap_err().to_string();
    assert!(
        e.starts_with("t.toml: initial.leg3.theta_deg")
            && e.contains("theta3")
            && e.contains("10.000°"),
        "{e}"
    );
    // Inside wider limits the same pose is fine.
    let c = parse_str(
        "[leg]\ntheta3_deg = [180.0, 350.0]\n[initial.leg3]\ntheta_deg = [0.0, 340.0]\n",
        "t.toml",
        &[],
    )
    .unwrap();
    let Config::Planar(p) = c else {
        panic!("planar")
    };
    assert!(p.model("t.toml").is_ok());
}

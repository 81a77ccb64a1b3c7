//! `model = "robot"` on the command line: `fbd kinematics` and `fbd
//! inverse` of the lab hexapod (examples/robots), and one-line errors for
//! what does not work (yet) or is mistyped.

mod common;

use common::{example, fbd, s, stderr, write};

fn json(out: &std::process::Output) -> serde_json::Value {
    assert!(out.status.success(), "{}", stderr(out));
    serde_json::from_slice(&out.stdout).unwrap()
}

fn one_line_error(out: &std::process::Output, code: i32) -> String {
    assert_eq!(out.status.code(), Some(code), "{}", stderr(out));
    let e = stderr(out);
    assert_eq!(e.lines().count(), 1, "{e:?}");
    e
}

#[test]
fn kinematics_prints_every_body_joint_and_foot() {
    let v = json(&fbd(&["kinematics", &example("robots/lab_hexapod.toml")]));
    assert_eq!(v["robot"], "lab_hexapod");
    assert_eq!(v["bodies"].as_array().unwrap().len(), 19);
    assert_eq!(v["joints"].as_array().unwrap().len(), 18);
    let feet = v["contacts"].as_array().unwrap();
    assert_eq!(feet.len(), 6);
    // The example stands the robot with its foot spheres on y = 0.
    for f in feet {
        let y = f["position"][1].as_f64().unwrap();
        assert!((y - 0.01).abs() < 1e-6, "{f}");
    }
    let mass = v["mass"].as_f64().unwrap();
    assert!((mass - 3.76).abs() < 1e-12);
}

#[test]
fn inverse_of_a_robot_at_rest_needs_its_weight_at_the_root() {
    let dir = tempfile::tempdir().unwrap();
    let urdf = std::path::Path::new(&example("robots/lab_hexapod.urdf")).to_owned();
    let cfg = write(
        dir.path(),
        "rest.toml",
        &format!(
            "model = \"robot\"\n[robot]\nurdf = \"{}\"\n[world]\ngravity = 9.81\n",
            urdf.display()
        ),
    );
    let v = json(&fbd(&["inverse", s(&cfg)]));
    let f = &v["base_force"];
    assert!((f[1].as_f64().unwrap() - 3.76 * 9.81).abs() < 1e-9, "{f}");
    assert!(f[0].as_f64().unwrap().abs() < 1e-12 && f[2].as_f64().unwrap().abs() < 1e-12);
    // A femur holds its femur, tibia and foot: 0.23 kg.
    let joints = v["joints"].as_array().unwrap();
    let femur = joints
        .iter()
        .find(|j| j["name"] == "lf_femur_joint")
        .unwrap();
    assert!(
        (femur["force"][1].as_f64().unwrap() - 0.23 * 9.81).abs() < 1e-12,
        "{femur}"
    );
}

#[test]
fn robot_configurations_fail_on_one_line_where_they_do_not_work() {
    let cfg = example("robots/lab_hexapod.toml");
    let e = one_line_error(&fbd(&["run", &cfg]), 2);
    assert!(
        e.contains("model = \"robot\"") && e.contains("fbd kinematics"),
        "{e}"
    );
    let e = one_line_error(&fbd(&["inverse", &example("paper.toml")]), 2);
    assert!(e.contains("fbd inverse takes a model = \"robot\""), "{e}");

    let dir = tempfile::tempdir().unwrap();
    let urdf = example("robots/lab_hexapod.urdf");
    let cases = [
        (
            format!("model = \"robot\"\n[robot]\nurdf = \"{urdf}\"\ncontacts = [\"lf_fot\"]\n"),
            "did you mean \"lf_foot\"",
        ),
        (
            format!(
                "model = \"robot\"\n[robot]\nurdf = \"{urdf}\"\n[initial]\njoints_deg = {{ lf_femur = 3.0 }}\n"
            ),
            "initial.joints_deg.lf_femur: no such joint",
        ),
        (
            format!(
                "model = \"robot\"\n[robot]\nurdf = \"{urdf}\"\n[initial]\njoints_deg = {{ lf_tibia_joint = 90.0 }}\n"
            ),
            "initial.joints_deg.lf_tibia_joint: outside the joint's limits",
        ),
        (
            format!("model = \"robot\"\n[robot]\nurdf = \"{urdf}\"\nmjcf = \"x.xml\"\n"),
            "exactly one of urdf",
        ),
        (
            "model = \"robot\"\n[robot]\nurdf = \"missing.urdf\"\n".to_owned(),
            "missing.urdf: cannot read",
        ),
        (
            format!("model = \"robot\"\n[robot]\nurdf = \"{urdf}\"\nup = \"x\"\n"),
            "robot.up: unknown up axis",
        ),
    ];
    for (text, want) in cases {
        let cfg = write(dir.path(), "bad.toml", &text);
        let e = one_line_error(&fbd(&["kinematics", s(&cfg)]), 2);
        assert!(e.contains(want), "{e}\n  wanted: {want}");
    }
}

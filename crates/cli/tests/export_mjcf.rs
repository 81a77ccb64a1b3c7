//! `fbd export mjcf CONFIG [--out FILE]`: the MuJoCo model of a hexapod
//! configuration on stdout or in a file (the same bytes, every run), and
//! one-line errors for what cannot be exported. (MuJoCo itself loads the
//! model and checks its kinematics in bench/peer/test_mjcf.py.)

mod common;

use common::{fbd, s, stderr, stdout, write};

const HEXAPOD: &str = r#"
model = "hexapod"
dynamics = "fbd"
[initial]
position = [0.1, 0.5, -0.2]
phi_deg = [5.0, 30.0, -10.0]
[control]
kind = "pd"
kp = 150.0
kd = 3.0
torque_limit = 25.0
"#;

fn one_line_error(o: &std::process::Output, code: i32, needles: &[&str]) {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(code), "{e:?}");
    assert_eq!(e.lines().count(), 1, "{e:?}");
    assert!(e.starts_with("error: ") && !e.contains("panicked"), "{e:?}");
    for n in needles {
        assert!(e.contains(n), "{e:?} does not mention {n:?}");
    }
}

#[test]
fn stdout_and_file_hold_the_same_model() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "robot.toml", HEXAPOD);
    let o = fbd(&["export", "mjcf", s(&cfg)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let xml = stdout(&o);
    let dest = dir.path().join("robot.xml");
    let f = fbd(&["export", "mjcf", s(&cfg), "--out", s(&dest)]);
    assert!(f.status.success(), "{}", stderr(&f));
    assert!(stdout(&f).is_empty());
    assert_eq!(
        std::fs::read_to_string(&dest).unwrap(),
        xml,
        "deterministic"
    );
    // 13 bodies, 18 hinges and servos with the configured gains, the
    // initial state as a keyframe.
    assert_eq!(xml.matches("<body ").count(), 13);
    assert_eq!(xml.matches("type=\"hinge\"").count(), 18);
    assert_eq!(xml.matches("<position ").count(), 18);
    assert!(xml.contains("kp=\"150\" kv=\"3\" forcerange=\"-25 25\""));
    assert!(xml.contains("<key name=\"initial\" qpos=\"0.1 0.5 -0.2 "));
    assert!(xml.trim_end().ends_with("</mujoco>"));
}

#[test]
fn what_cannot_be_exported_is_a_one_line_error() {
    let dir = tempfile::tempdir().unwrap();
    let planar = write(dir.path(), "planar.toml", "model = \"planar\"\n");
    one_line_error(
        &fbd(&["export", "mjcf", s(&planar)]),
        2,
        &["planar.toml", "model", "hexapod"],
    );
    let slope = write(
        dir.path(),
        "slope.toml",
        &format!("{HEXAPOD}[terrain]\nkind = \"sine\"\namplitude = 0.01\nwavelength = 1.0\n"),
    );
    one_line_error(
        &fbd(&["export", "mjcf", s(&slope)]),
        2,
        &["slope.toml", "terrain.kind", "\"sine\""],
    );
    let cfg = write(dir.path(), "robot.toml", HEXAPOD);
    let missing = dir.path().join("no/such/dir/robot.xml");
    one_line_error(
        &fbd(&["export", "mjcf", s(&cfg), "--out", s(&missing)]),
        4,
        &["no/such/dir"],
    );
    assert!(!missing.exists());
    one_line_error(
        &fbd(&["export", "mjcf", "absent.toml"]),
        2,
        &["absent.toml"],
    );
}

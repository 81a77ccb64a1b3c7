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

/// A motion CSV of the lab hexapod: every joint `0.4·sin(2t + j)`, the
/// base rising `ry = 0.2 + 0.1·t²`, sampled every `dt` for 0.5 s.
fn lab_motion(dt: f64) -> String {
    let model = fbd_robot::urdf::load(
        std::path::Path::new(&example("robots/lab_hexapod.urdf")),
        fbd_robot::Up::Z,
        &fbd_robot::ContactChoice::CollisionSpheres,
    )
    .unwrap();
    let mut csv = String::from("t,ry");
    for j in &model.joints {
        csv.push(',');
        csv.push_str(&j.name);
    }
    csv.push('\n');
    let n = (0.5 / dt).round() as usize;
    for k in 0..=n {
        let t = k as f64 * dt;
        csv.push_str(&format!("{t},{}", 0.2 + 0.1 * t * t));
        for j in 0..model.joints.len() {
            csv.push_str(&format!(",{}", 0.4 * (2.0 * t + j as f64).sin()));
        }
        csv.push('\n');
    }
    csv
}

#[test]
fn inverse_along_a_motion_converges_at_second_order() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = example("robots/lab_hexapod.toml");
    // The femur torque of leg lf at t = 0.25 s, with Δt and Δt/2.
    let torque_at = |dt: f64| {
        let motion = write(dir.path(), "motion.csv", &lab_motion(dt));
        let out = fbd(&["inverse", &cfg, "--motion", s(&motion)]);
        assert!(out.status.success(), "{}", stderr(&out));
        let text = String::from_utf8(out.stdout).unwrap();
        let mut lines = text.lines();
        let header: Vec<&str> = lines.next().unwrap().split(',').collect();
        let col = header
            .iter()
            .position(|c| *c == "tau_lf_femur_joint")
            .unwrap();
        let rows: Vec<Vec<f64>> = lines
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect();
        assert_eq!(
            rows.len(),
            (0.5 / dt).round() as usize - 1,
            "interior samples"
        );
        let row = rows.iter().find(|r| (r[0] - 0.25).abs() < 1e-9).unwrap();
        row[col]
    };
    let (coarse, fine, finest) = (torque_at(0.01), torque_at(0.005), torque_at(0.0025));
    let ratio = (coarse - fine) / (fine - finest);
    assert!(
        (3.5..4.5).contains(&ratio),
        "error ratio {ratio}: not second order"
    );
}

#[test]
fn a_bad_motion_is_one_line_naming_the_file_and_line() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = example("robots/lab_hexapod.toml");
    let good = lab_motion(0.01);
    let lines: Vec<String> = good.lines().map(str::to_owned).collect();
    let cases = [
        (
            {
                let mut l = lines.clone();
                l[0] = l[0].replace(",lf_coxa_joint", ",lf_coxa");
                l
            },
            "motion.csv:1:1: no column for joint `lf_coxa_joint`",
        ),
        (
            {
                let mut l = lines.clone();
                l[5] = l[5].replacen("0.04", "0.045", 1);
                l
            },
            "motion.csv:6:1: t = 0.045: samples must be uniformly spaced",
        ),
        (
            {
                let mut l = lines.clone();
                l[3] = l[3].replacen(',', ",x", 1);
                l
            },
            "motion.csv:4:1: column `ry`",
        ),
        (
            lines[..3].to_vec(),
            "motion.csv:1:1: 2 rows: central differences need at least 3",
        ),
    ];
    for (text, want) in cases {
        let motion = write(dir.path(), "motion.csv", &(text.join("\n") + "\n"));
        let e = one_line_error(&fbd(&["inverse", &cfg, "--motion", s(&motion)]), 2);
        assert!(e.contains(want), "{e}\n  wanted: {want}");
    }
    let e = one_line_error(&fbd(&["inverse", &cfg, "--out", "x.csv"]), 2);
    assert!(e.contains("--motion"), "{e}");
}

#[test]
fn export_mjcf_writes_an_imported_robot_all_or_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let dest = dir.path().join("lab.xml");
    let out = fbd(&[
        "export",
        "mjcf",
        &example("robots/lab_hexapod.toml"),
        "--out",
        s(&dest),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let xml = std::fs::read_to_string(&dest).unwrap();
    // Read back, it is the robot the configuration names.
    let model = fbd_robot::mjcf::parse(&dest, &xml)
        .and_then(|t| {
            t.build(
                fbd_robot::Up::Y,
                &fbd_robot::ContactChoice::CollisionSpheres,
            )
        })
        .unwrap();
    assert_eq!(model.joints.len(), 18);
    assert!((model.mass() - 3.76).abs() < 1e-12);
    assert_eq!(model.contacts.len(), 6);
    // Nothing but the file in the directory (no temporary left).
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn contacts_at_places_the_feet_by_inverse_kinematics() {
    let v = json(&fbd(&[
        "kinematics",
        &example("robots/lab_hexapod_stand.toml"),
    ]));
    let text = std::fs::read_to_string(example("robots/lab_hexapod_stand.toml")).unwrap();
    let table: toml::Table = toml::from_str(&text).unwrap();
    let targets = table["initial"]["contacts_at"].as_table().unwrap();
    for f in v["contacts"].as_array().unwrap() {
        let want = targets[f["name"].as_str().unwrap()].as_array().unwrap();
        for k in 0..3 {
            let (got, want) = (
                f["position"][k].as_f64().unwrap(),
                want[k].as_float().unwrap(),
            );
            assert!((got - want).abs() <= 1e-10, "{f}");
        }
    }
    // Every joint inside its limits.
    for j in v["joints"].as_array().unwrap() {
        let (a, l) = (j["angle"].as_f64().unwrap(), &j["limits"]);
        assert!(
            l[0].as_f64().unwrap() <= a && a <= l[1].as_f64().unwrap(),
            "{j}"
        );
    }
    // A foot out of reach names itself and the distance left.
    let dir = tempfile::tempdir().unwrap();
    let far = text.replace(
        "rm_foot_sphere = [0.23, 0.01, 0.0]",
        "rm_foot_sphere = [0.9, 0.01, 0.0]",
    );
    let cfg = write(
        dir.path(),
        "far.toml",
        &far.replace(
            "\"lab_hexapod.urdf\"",
            &format!("\"{}\"", example("robots/lab_hexapod.urdf")),
        ),
    );
    let e = one_line_error(&fbd(&["kinematics", s(&cfg)]), 2);
    assert!(
        e.contains("initial.contacts_at.rm_foot_sphere: out of reach")
            && e.contains(" m from its target"),
        "{e}"
    );
}

//! End-to-end tests of the `fbd` binary (docs/reference.md).

mod common;

use common::{FAIL_DT, FAIL_STEP, FAILS, example, fail_prefix, fbd, s, stderr, stdout, write};
use std::path::Path;
use std::process::Output;

const FILES: [&str; 10] = [
    "trajectory.csv",
    "events.csv",
    "summary.json",
    "config.toml",
    "tips.svg",
    "forces.svg",
    "stance.svg",
    "joints.svg",
    "energy.svg",
    "viewer.html",
];

const SPEC_COLUMNS: &str = "t,rx,ry,phi_z,theta2_3,theta3_3,theta2_4,theta3_4,tip3_x,tip3_y,tip4_x,tip4_y,state3,state4,fa3,n3,fa4,n4,hip3_fx,hip3_fy,knee3_fx,knee3_fy,hip4_fx,hip4_fy,knee4_fx,knee4_fy";

/// The one-line error message, checked to be exactly one line.
fn one_line_error(o: &Output) -> String {
    let e = stderr(o);
    assert_eq!(e.lines().count(), 1, "stderr is not one line: {e:?}");
    assert!(e.starts_with("error: "), "{e:?}");
    e
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn kinematics_reproduces_the_spec_test_vector() {
    let o = fbd(&["kinematics", &example("paper.toml")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let legs = v["legs"].as_array().unwrap();
    assert_eq!(legs.len(), 2);
    let expect = [
        (3, [-0.594006, 0.219351, 0.0]),
        (4, [0.525210, 0.194311, 0.0]),
    ];
    for (leg, (n, tip)) in legs.iter().zip(expect) {
        assert_eq!(leg["leg"], n);
        for k in 0..3 {
            let got = leg["tip"][k].as_f64().unwrap();
            assert!(
                (got - tip[k]).abs() < 1e-6,
                "leg {n} tip[{k}] = {got}, expected {}",
                tip[k]
            );
        }
        let hip = &leg["hip"];
        let d = 0.25 * (std::f64::consts::PI / 6.0).cos();
        assert!((hip[0].as_f64().unwrap().abs() - d).abs() < 1e-12);
        assert!((hip[1].as_f64().unwrap() - 0.6).abs() < 1e-12);
        assert!(leg["knee"].as_array().unwrap().len() == 3);
    }
}

#[test]
fn kinematics_of_the_standing_hexapod_has_six_level_tips() {
    let o = fbd(&["kinematics", &example("hexapod_pose.toml")]);
    assert!(o.status.success(), "{}", stderr(&o));
    let v: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    let legs = v["legs"].as_array().unwrap();
    assert_eq!(
        legs.iter()
            .map(|l| l["leg"].as_u64().unwrap())
            .collect::<Vec<_>>(),
        [1, 2, 3, 4, 5, 6]
    );
    let heights: Vec<f64> = legs.iter().map(|l| l["tip"][1].as_f64().unwrap()).collect();
    for h in &heights {
        assert!(
            (h - heights[0]).abs() < 1e-12 && *h > 0.0 && *h < 0.02,
            "{heights:?}"
        );
    }
    // Front legs (1, 2) are forward: body −z.
    assert!(legs[0]["tip"][2].as_f64().unwrap() < 0.0 && legs[5]["tip"][2].as_f64().unwrap() > 0.0);
}

#[test]
fn default_run_writes_every_file() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = fbd(&["run", "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    for f in FILES {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    // No temporary files left behind.
    assert_eq!(std::fs::read_dir(&out).unwrap().count(), FILES.len());

    let text = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let header = text.lines().next().unwrap();
    assert!(header.starts_with(SPEC_COLUMNS), "{header}");
    for extra in [
        "tau_hip3",
        "kinetic",
        "potential",
        "energy",
        "newton_iterations",
    ] {
        assert!(header.split(',').any(|c| c == extra), "{extra} missing");
    }
    let mut rdr = csv::Reader::from_path(out.join("trajectory.csv")).unwrap();
    let cols = rdr.headers().unwrap().clone();
    let rows: Vec<csv::StringRecord> = rdr.records().map(Result::unwrap).collect();
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "ok");
    assert!(summary["error"].is_null());
    let steps = summary["steps"].as_u64().unwrap() as usize;
    assert_eq!(rows.len(), steps);
    for key in [
        "newton_iterations",
        "wall_seconds",
        "steps_per_second",
        "symbolic_factorizations",
        "evicted_patterns",
        "reference_lu_retries",
        "dt",
        "duration",
        "first_touchdown",
        "first_slip",
        "peak_contact_force",
        "peak_joint_force",
        "final_energy",
    ] {
        assert!(!summary[key].is_null(), "summary.{key} is null");
    }
    // Row 0 is t = 0 at the initial configuration; states are ST1|ST2|ST3.
    let col = |name: &str| cols.iter().position(|c| c == name).unwrap();
    assert_eq!(rows[0][col("t")].parse::<f64>().unwrap(), 0.0);
    assert_eq!(rows[0][col("ry")].parse::<f64>().unwrap(), 0.6);
    for r in &rows {
        assert!(["ST1", "ST2", "ST3"].contains(&&r[col("state3")]));
        assert_eq!(r.len(), cols.len());
    }

    // events.csv and summary.events agree.
    let events = std::fs::read_to_string(out.join("events.csv")).unwrap();
    let mut lines = events.lines();
    assert_eq!(lines.next(), Some("t,leg,from,to,point"));
    let ev = summary["events"].as_array().unwrap();
    assert_eq!(lines.count(), ev.len());
    for e in ev {
        // Tip events name the leg alone; knee and hip events add the point.
        let point = match e["point"].as_str().unwrap() {
            "tip" => String::new(),
            other => format!("{other}  "),
        };
        // The time as written in events.csv: the decimal of k·Δt.
        let line = format!(
            "t={:?} s  leg {}  {point}{} -> {}",
            e["t"].as_f64().unwrap(),
            e["leg"],
            e["from"].as_str().unwrap(),
            e["to"].as_str().unwrap()
        );
        assert!(
            stdout(&o).contains(&line),
            "stdout lacks {line:?}:\n{}",
            stdout(&o)
        );
    }
    assert!(
        stdout(&o).contains(s(&out)),
        "stdout does not say where the files went"
    );
    for svg in ["tips.svg", "forces.svg", "stance.svg"] {
        let t = std::fs::read_to_string(out.join(svg)).unwrap();
        assert!(
            t.starts_with("<svg") && t.trim_end().ends_with("</svg>"),
            "{svg}"
        );
    }
    let tips = std::fs::read_to_string(out.join("tips.svg")).unwrap();
    assert!(tips.contains("time (s)") && tips.contains("position (m)"));
}

#[test]
fn rerunning_the_written_config_is_byte_identical() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b, c) = (
        dir.path().join("a"),
        dir.path().join("b"),
        dir.path().join("c"),
    );
    let cfg = write(
        dir.path(),
        "cfg.toml",
        "[time]\nduration = 0.3\n[initial]\nphi_z_deg = 1.7\n[initial.leg4]\ntheta_deg = [3.3, 251.1]\n[leg]\nupper_mass = 0.35\n[output]\nstride = 2\n",
    );
    let o = fbd(&["run", s(&cfg), "--out", s(&a)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = fbd(&["run", s(&a.join("config.toml")), "--out", s(&b)]);
    assert!(o.status.success(), "{}", stderr(&o));
    // Running the config in place (read, then overwritten) works too.
    let o = fbd(&["run", s(&b.join("config.toml")), "--out", s(&b)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let o = fbd(&["run", s(&cfg), "--out", s(&c)]);
    assert!(o.status.success(), "{}", stderr(&o));
    for f in ["trajectory.csv", "events.csv", "config.toml"] {
        let fa = std::fs::read(a.join(f)).unwrap();
        assert_eq!(
            fa,
            std::fs::read(b.join(f)).unwrap(),
            "{f} differs after re-running config.toml"
        );
        assert_eq!(
            fa,
            std::fs::read(c.join(f)).unwrap(),
            "{f} differs between identical runs"
        );
    }
    // stride 2 over 31 steps: rows 0, 2, …, 30.
    let rows = std::fs::read_to_string(a.join("trajectory.csv"))
        .unwrap()
        .lines()
        .count()
        - 1;
    assert_eq!(rows, 16);
    assert_eq!(json(&a.join("summary.json"))["rows_written"], 16);
}

#[test]
fn paper_example_equals_the_default_run() {
    let dir = tempfile::tempdir().unwrap();
    let (a, b) = (dir.path().join("a"), dir.path().join("b"));
    assert!(fbd(&["run", "--out", s(&a)]).status.success());
    let o = fbd(&["run", &example("paper.toml"), "--out", s(&b)]);
    assert!(o.status.success(), "{}", stderr(&o));
    for f in ["trajectory.csv", "events.csv", "config.toml"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{f}"
        );
    }
}

#[test]
fn extra_contact_points_add_columns() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(
        dir.path(),
        "k.toml",
        "[time]\nduration = 0.05\n[contact]\npoints = [\"tips\", \"knees\", \"hips\"]\n",
    );
    let out = dir.path().join("o");
    let o = fbd(&["run", s(&cfg), "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let header = text.lines().next().unwrap();
    let tail = "knee3_state,knee3_fa,knee3_n,knee4_state,knee4_fa,knee4_n,hip3_state,hip3_fa,hip3_n,hip4_state,hip4_fa,hip4_n,tau_hip3,tau_knee3,tau_hip4,tau_knee4,kinetic,potential,energy,newton_iterations,stop_hip3,stop_knee3,stop_hip4,stop_knee4";
    assert_eq!(header, format!("{SPEC_COLUMNS},{tail}"));
}

#[test]
fn unknown_key_names_file_line_column_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(
        dir.path(),
        "bad.toml",
        "model = \"planar\"\n[time]\ndt = 0.01\n\n[body]\nmass = 6.0\nmasss = 3.0\n",
    );
    let out = dir.path().join("o");
    let o = fbd(&["run", s(&cfg), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2));
    let e = one_line_error(&o);
    assert!(e.contains(&format!("{}:7:1:", s(&cfg))), "{e}");
    assert!(e.contains("masss"), "{e}");
    assert!(!out.exists(), "nothing is written for a bad configuration");
    let o = fbd(&["kinematics", s(&cfg)]);
    assert_eq!(o.status.code(), Some(2));

    let cfg = write(dir.path(), "type.toml", "[terrain]\nmu_static = \"high\"\n");
    let o = fbd(&["run", s(&cfg), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2));
    let e = one_line_error(&o);
    assert!(e.contains(":2:13: terrain.mu_static: invalid type"), "{e}");

    let cfg = write(dir.path(), "syntax.toml", "[time\ndt = 0.01\n");
    let o = fbd(&["run", s(&cfg), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2));
    assert!(one_line_error(&o).contains("syntax.toml:1:"));
}

#[test]
fn semantic_errors_name_table_and_key() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    for (text, key) in [
        ("[leg]\nlower_mass = -2.0\n", "leg.lower_mass"),
        (
            "[terrain]\nmu_static = 0.2\nmu_dynamic = 0.3\n",
            "terrain.mu_dynamic",
        ),
        ("[time]\ndt = 0.0\n", "time.dt"),
        (
            "[initial.leg3]\ntheta_deg = [nan, 245.0]\n",
            "initial.leg3.theta_deg",
        ),
        ("[initial]\nposition = [0.0, 0.1]\n", "initial.leg"),
        ("[contact]\npoints = [\"knees\"]\n", "contact.points"),
    ] {
        let cfg = write(dir.path(), "sem.toml", text);
        let o = fbd(&["run", s(&cfg), "--out", s(&out)]);
        assert_eq!(o.status.code(), Some(2), "{text}");
        let e = one_line_error(&o);
        assert!(
            e.starts_with(&format!("error: {}: {key}", s(&cfg))),
            "{text} → {e}"
        );
        assert!(e.contains("(got ") && e.contains("expected"), "{e}");
    }
}

#[test]
fn unreadable_configurations_are_usage_errors() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let missing = dir.path().join("missing.toml");
    for (path, what) in [
        (missing.as_path(), "no such file"),
        (dir.path(), "directory"),
    ] {
        let o = fbd(&["run", s(path), "--out", s(&out)]);
        assert_eq!(o.status.code(), Some(2));
        let e = one_line_error(&o);
        assert!(e.contains(s(path)) && e.contains(what), "{e}");
    }
}

#[test]
fn output_directory_problems_are_io_errors() {
    let dir = tempfile::tempdir().unwrap();
    let file = write(dir.path(), "afile", "x");
    let o = fbd(&["run", "--out", s(&file)]);
    assert_eq!(o.status.code(), Some(4));
    assert!(one_line_error(&o).contains("not a directory"));
    let o = fbd(&["run", "--out", s(&file.join("sub"))]);
    assert_eq!(o.status.code(), Some(4));
    one_line_error(&o);
}

#[test]
fn hexapod_run_writes_its_files() {
    // A kinematic hexapod run (`dynamics = "kinematic"`; the gait's own
    // tests are in tests/gait_*.rs); here only the command's contract: exit 0, the files
    // in DIR, summary.json ok.
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("hex");
    let o = fbd(&["run", &example("hexapod_pose.toml"), "--out", s(&out)]);
    assert!(o.status.success(), "{}", stderr(&o));
    for f in [
        "trajectory.csv",
        "events.csv",
        "summary.json",
        "config.toml",
    ] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    assert_eq!(json(&out.join("summary.json"))["status"], "ok");
}

#[test]
fn a_failed_simulation_still_writes_everything() {
    // A run that succeeds here is a regression of this test.
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "fail.toml", FAILS);
    let out = dir.path().join("o");
    let o = fbd(&["run", s(&cfg), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let e = one_line_error(&o);
    assert!(e.starts_with(&format!("error: {}", fail_prefix())), "{e}");
    assert!(e.contains("residual") && e.contains(s(&cfg)), "{e}");
    assert!(!e.contains("panicked"), "{e}");
    for f in FILES {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "error");
    assert!(
        summary["error"]
            .as_str()
            .unwrap()
            .starts_with(&fail_prefix()),
        "{summary}"
    );
    assert_eq!(summary["steps"], FAIL_STEP);
    assert_eq!(summary["rows_written"], FAIL_STEP);
    let text = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let t: Vec<f64> = text
        .lines()
        .skip(1)
        .map(|l| l.split(',').next().unwrap().parse().unwrap())
        .collect();
    assert_eq!(t.len(), FAIL_STEP, "rows for t = 0 … 0.25");
    for (k, t) in t.iter().enumerate() {
        assert!((t - k as f64 * FAIL_DT).abs() < 1e-12, "row {k}: t = {t}");
    }
}

#[test]
fn help_lists_the_commands() {
    let o = fbd(&["--help"]);
    assert!(o.status.success());
    let h = stdout(&o);
    assert!(h.contains("run") && h.contains("kinematics"), "{h}");
    for cmd in ["run", "kinematics"] {
        let o = fbd(&[cmd, "--help"]);
        assert!(o.status.success());
        assert!(stdout(&o).contains("CONFIG"));
    }
    let o = fbd(&["frobnicate"]);
    assert_eq!(o.status.code(), Some(2));
    one_line_error(&o);
    let o = fbd(&["kinematics"]);
    assert_eq!(o.status.code(), Some(2));
    one_line_error(&o);
}

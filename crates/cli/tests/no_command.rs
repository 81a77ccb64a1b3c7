//! `fbd` without a command is `fbd run` of the built-in experiment: what
//! `cargo run --release` does on a fresh clone.

mod common;

use common::{fbd_in, s};
use fbd_cli::output::FILES;

fn check_out(out: &std::path::Path, stdout: &str) {
    for f in FILES {
        assert!(out.join(f).is_file(), "{f} missing in {}", out.display());
    }
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "ok", "{summary}");
    assert_eq!(summary["steps"], summary["steps_planned"]);
    // The paper's first event: leg 4 touches down in the step from 0.19 s.
    assert!(stdout.contains("t=0.19 s  leg 4  ST1 -> ST2"), "{stdout}");
    // Times are the decimal of k·Δt: row k of the 0.01 s run is k/100
    // (`0.35`, never `0.35000000000000003`), in events.csv too.
    let traj = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    for (k, row) in traj.lines().skip(1).enumerate() {
        let t = row.split(',').next().unwrap();
        assert_eq!(t, format!("{:?}", k as f64 / 100.0), "row {k}");
    }
    let events = std::fs::read_to_string(out.join("events.csv")).unwrap();
    for row in events.lines().skip(1) {
        let t = row.split(',').next().unwrap();
        let hundredths = (t.parse::<f64>().unwrap() * 100.0).round();
        assert_eq!(t, format!("{:?}", hundredths / 100.0), "{row}");
    }
    let leftovers: Vec<_> = std::fs::read_dir(out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
}

#[test]
fn no_arguments_runs_the_default_experiment_into_out() {
    let dir = tempfile::tempdir().unwrap();
    let o = fbd_in(dir.path(), &[]);
    let stdout = String::from_utf8_lossy(&o.stdout);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    check_out(&dir.path().join("out"), &stdout);
    // Nothing else is created in the working directory.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
}

#[test]
fn out_without_a_command_names_the_directory() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("elsewhere");
    let o = fbd_in(dir.path(), &["--out", s(&out)]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    check_out(&out, &String::from_utf8_lossy(&o.stdout));
    assert!(!dir.path().join("out").exists());
}

#[test]
fn help_still_lists_the_commands() {
    let dir = tempfile::tempdir().unwrap();
    let o = fbd_in(dir.path(), &["--help"]);
    assert!(o.status.success());
    let h = String::from_utf8_lossy(&o.stdout);
    for cmd in ["run", "kinematics", "sweep"] {
        assert!(h.contains(cmd), "{h}");
    }
    assert!(
        !dir.path().join("out").exists(),
        "--help ran the experiment"
    );
}

#[test]
fn a_configuration_without_a_command_points_to_fbd_run() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("my.toml"), "").unwrap();
    let o = fbd_in(dir.path(), &["my.toml"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(err.lines().count(), 1, "{err}");
    assert!(err.contains("`fbd run my.toml`"), "{err}");
    assert!(!dir.path().join("out").exists());
}

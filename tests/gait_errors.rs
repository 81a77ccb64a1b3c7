//! Bad walks stop with a one-line error naming the leg, the time and by how
//! much, and the steps computed so far are written; a kinematic hexapod
//! without `[gait]` stands.

use std::path::Path;

fn run(dir: &Path, text: &str) -> (Result<(), String>, String) {
    let cfg = dir.join("c.toml");
    std::fs::write(&cfg, text).unwrap();
    let out = dir.join("out");
    let mut sink = Vec::new();
    let r = fbd_cli::run::run_command(Some(&cfg), &out, &mut sink).map_err(|e| e.to_string());
    let summary = std::fs::read_to_string(out.join("summary.json")).unwrap_or_default();
    (r, summary)
}

const BASE: &str = "model = \"hexapod\"\n[time]\ndt = 0.01\nduration = 4.0\n[initial]\nposition = [0.0, 0.38, 0.0]\n";

#[test]
fn foothold_beyond_reach_names_the_leg() {
    let dir = tempfile::tempdir().unwrap();
    // A 0.9 m stride: the first footholds are 0.45 m ahead of neutral.
    let (r, summary) = run(
        dir.path(),
        &format!("{BASE}[gait]\nperiod = 2.0\nforward_speed = 0.45\nramp = 0.0\n"),
    );
    let e = r.unwrap_err();
    assert!(
        e.contains("leg ")
            && e.contains("out of reach by")
            && e.contains(" m ")
            && e.contains("t = "),
        "{e}"
    );
    assert!(!e.contains('\n'), "one line: {e}");
    let s: serde_json::Value = serde_json::from_str(&summary).unwrap();
    assert_eq!(s["status"], "error");
    let rows = s["rows_written"].as_u64().unwrap();
    assert!(rows > 0, "the steps before the error are written");
    let csv = std::fs::read_to_string(dir.path().join("out/trajectory.csv")).unwrap();
    assert_eq!(csv.lines().count() as u64, rows + 1);
}

#[test]
fn joint_limit_names_the_joint_and_degrees() {
    let dir = tempfile::tempdir().unwrap();
    let (r, _) = run(
        dir.path(),
        &format!("{BASE}[leg]\ntheta1_deg = [-3.0, 3.0]\n[gait]\nyaw_rate_deg = 20.0\n"),
    );
    let e = r.unwrap_err();
    assert!(
        e.contains("theta1")
            && e.contains("past its limit by")
            && e.contains('°')
            && e.contains("leg "),
        "{e}"
    );
}

#[test]
fn kinematic_hexapod_without_gait_stands() {
    let dir = tempfile::tempdir().unwrap();
    // (Without `dynamics = "kinematic"` it would run the 3D dynamics.)
    let text = BASE.replacen('\n', "\ndynamics = \"kinematic\"\n", 1);
    let (r, summary) = run(dir.path(), &text);
    r.unwrap();
    let s: serde_json::Value = serde_json::from_str(&summary).unwrap();
    assert_eq!(s["status"], "ok");
    assert_eq!(s["run"], "standing");
    assert_eq!(s["rows_written"], 401);
    assert_eq!(s["distance"], 0.0);
    let csv = std::fs::read_to_string(dir.path().join("out/trajectory.csv")).unwrap();
    let mut lines = csv.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let first = lines.next().unwrap();
    assert!(
        lines.all(|l| l.split(',').skip(1).eq(first.split(',').skip(1))),
        "the pose is held"
    );
    for c in [
        "t", "rx", "phi_z", "theta3_6", "omega1_1", "alpha2_4", "foot5_y", "stance6", "com_z",
        "margin",
    ] {
        assert!(header.contains(&c), "column {c}");
    }
}

#[test]
fn require_stable_stops_an_unstable_gait() {
    let dir = tempfile::tempdir().unwrap();
    // β = 0.45: between the two tripods' swings every foot is in the air.
    let (r, summary) = run(
        dir.path(),
        &format!(
            "{BASE}[gait]\nkind = \"custom\"\nduty_factor = 0.45\nphases = [0.0, 0.5, 0.5, 0.0, 0.0, 0.5]\nforward_speed = 0.05\nrequire_stable = true\n"
        ),
    );
    let e = r.unwrap_err();
    assert!(
        e.contains("statically unstable") && e.contains("t = 0.5 s"),
        "{e}"
    );
    let s: serde_json::Value = serde_json::from_str(&summary).unwrap();
    assert_eq!(s["status"], "error");
    let low = s["events"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["event"] == "margin_low")
        .expect("a margin_low event");
    assert_eq!(low["t"], 0.5);
}

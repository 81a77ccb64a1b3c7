//! The figures README.md quotes from runs of the examples are those the
//! runs produce: this test runs each example and fails, naming the README
//! line it expected, when the README disagrees (a stale figure). Timings
//! are not checked (they are quoted as ranges with the machine and the
//! command); every other figure below is.
//!
//! Checked: the default experiment's events table (touchdowns, slips, the
//! event count at 10 ms); the tripod gait's printed report; the dynamic
//! walk's printed report (steps, Newton iterations, distance, height) and
//! its first slips; the walk on ice's distance against the walk's and the
//! difference in per cent and millimetres.

use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn readme() -> String {
    std::fs::read_to_string(root().join("README.md")).unwrap()
}

/// Runs `fbd run CONFIG` (the built-in default without one) into a
/// temporary folder: the printed report and `summary.json`.
fn run(config: Option<&str>) -> (String, serde_json::Value) {
    let tmp = tempfile::tempdir().unwrap();
    let path = config.map(|c| root().join(c));
    let mut out = Vec::new();
    fbd_cli::run::run_command(path.as_deref(), tmp.path(), &mut out).unwrap();
    let summary = std::fs::read_to_string(tmp.path().join("summary.json")).unwrap();
    (
        String::from_utf8(out).unwrap(),
        serde_json::from_str(&summary).unwrap(),
    )
}

/// Fails unless README.md contains `want`, showing the README's nearest
/// line (the one starting like `want`).
fn has(readme: &str, want: &str, what: &str) {
    if readme.contains(want) {
        return;
    }
    let key: String = want.chars().take(24).collect();
    let near: Vec<&str> = readme.lines().filter(|l| l.contains(key.trim())).collect();
    panic!(
        "README.md is stale ({what}): expected\n  {want}\nREADME lines starting alike:\n  {}",
        near.join("\n  ")
    );
}

/// The printed report's line starting with `prefix`.
fn line<'a>(report: &'a str, prefix: &str) -> &'a str {
    report
        .lines()
        .find(|l| l.starts_with(prefix))
        .unwrap_or_else(|| panic!("no line `{prefix}…` in\n{report}"))
}

/// `solved 3001 steps, 3124 Newton iterations, 0.089 s` without the time.
fn without_time(l: &str) -> &str {
    l.rsplit_once(", ").map_or(l, |(a, _)| a)
}

#[test]
fn default_experiment_events_table() {
    let r = readme();
    let (_, s) = run(None);
    let t = |k: &str, leg: &str| s[k][leg].as_f64().unwrap();
    let (td4, td3) = (t("first_touchdown", "leg4"), t("first_touchdown", "leg3"));
    let dt = s["dt"].as_f64().unwrap();
    has(
        &r,
        &format!(
            "| leg 4 reaches the soil | 0.20 s | step {td4} → tip on the ground at **{:.2} s** |",
            td4 + dt
        ),
        "leg 4 touchdown",
    );
    has(
        &r,
        &format!(
            "| leg 3 reaches the soil | 0.02 s after leg 4 | step {td3} → on the ground at **{:.2} s** |",
            td3 + dt
        ),
        "leg 3 touchdown",
    );
    let (s3, s4) = (t("first_slip", "leg3"), t("first_slip", "leg4"));
    assert_eq!(s3, s4, "the README says both legs slip at once");
    has(
        &r,
        &format!("| both legs start slipping | around 0.24 s | **{s3:.2} s** (both) |"),
        "slips",
    );
    let events = s["events"].as_array().unwrap().len();
    has(
        &r,
        &format!("| 10 ms | 0.19–0.20 s | 0.21–0.22 s | {s3:.2} s | {s4:.2} s | {events} |"),
        "events at 10 ms",
    );
}

#[test]
fn tripod_gait_report() {
    let r = readme();
    let (report, _) = run(Some("examples/hexapod_tripod.toml"));
    has(
        &r,
        without_time(line(&report, "computed ")),
        "tripod: steps",
    );
    has(&r, line(&report, "distance walked "), "tripod: distance");
    has(
        &r,
        line(&report, "minimum stability margin "),
        "tripod: margin",
    );
}

#[test]
fn dynamic_walk_and_walk_on_ice() {
    let r = readme();
    let (report, s) = run(Some("examples/hexapod_walk.toml"));
    has(
        &r,
        without_time(line(&report, "solved ")),
        "walk: steps and Newton iterations",
    );
    has(
        &r,
        line(&report, "body moved "),
        "walk: distance and height",
    );
    // The first ST3 of each foot that slips: the README names them.
    let slips: Vec<String> = s["first_slip"]
        .as_object()
        .unwrap()
        .iter()
        .filter_map(|(leg, t)| Some(format!("{leg} {}", t.as_f64()?)))
        .collect();
    has(
        &r,
        &format!("`first_slip`: {}", slips.join(", ")),
        "walk: first slips",
    );

    let (_, ice) = run(Some("examples/hexapod_walk_ice.toml"));
    let d = |s: &serde_json::Value| s["displacement"][0].as_f64().unwrap();
    let (walk, on_ice) = (d(&s), d(&ice));
    let figures = format!("{on_ice:.3} m against {walk:.3} m");
    has(
        &r,
        &format!("the robot ends {on_ice:.3} m up it against {walk:.3} m"),
        "walk on ice: distances",
    );
    has(
        &r,
        &format!(
            "walks {:.0} % less far ({figures})",
            (1.0 - on_ice / walk) * 100.0
        ),
        "walk on ice: per cent",
    );
    has(
        &r,
        &format!("the {:.0} mm lost", (walk - on_ice) * 1e3),
        "walk on ice: millimetres",
    );
}

#[test]
fn the_readme_is_where_this_test_looks() {
    assert!(Path::new(&root().join("README.md")).exists());
}

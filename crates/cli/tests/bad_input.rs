//! Issue 4: every bad input gets a clear one-line error and a documented
//! exit status (2 usage/configuration, 3 simulation failed, 4 I/O), no
//! panic reaches the user, and no computed result is lost or half-written.
//!
//! Each test runs the real binary. Pre-simulation errors must leave no
//! `trajectory.csv` in the `--out` directory. The last tests feed arbitrary
//! bytes and mutations of `examples/paper.toml` to the loader.

mod common;

use common::{FAIL_STEP, FAILS, fail_prefix, fbd, s};
use std::path::{Path, PathBuf};
use std::process::Output;

use fbd_cli::Config;
use fbd_cli::config::parse_str;
use proptest::prelude::*;
use proptest::test_runner::{Config as PtConfig, RngAlgorithm, TestRng, TestRunner};

const USAGE: i32 = 2;
const SIMULATION: i32 = 3;
const IO: i32 = 4;

fn paper_toml() -> String {
    std::fs::read_to_string(common::examples().join("paper.toml")).unwrap()
}

/// Checks the exit status and that stderr is one `error:` line without a
/// panic that contains every needle; returns the line.
fn check_error(o: &Output, code: i32, needles: &[&str]) -> String {
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert_eq!(o.status.code(), Some(code), "stderr: {e:?}");
    assert_eq!(e.lines().count(), 1, "stderr is not one line: {e:?}");
    assert!(e.starts_with("error: "), "{e:?}");
    assert!(
        !e.contains("panicked") && !e.contains("internal error"),
        "{e:?}"
    );
    for n in needles {
        assert!(e.contains(n), "{e:?} does not mention {n:?}");
    }
    e
}

/// A temporary directory with `cfg.toml` holding `text`.
struct Case {
    dir: tempfile::TempDir,
    cfg: PathBuf,
}

impl Case {
    fn new(text: &str) -> Self {
        let dir = tempfile::tempdir().unwrap();
        let cfg = dir.path().join("cfg.toml");
        std::fs::write(&cfg, text).unwrap();
        Self { dir, cfg }
    }

    fn out(&self) -> PathBuf {
        self.dir.path().join("out")
    }

    /// `fbd run cfg.toml --out out`.
    fn run(&self) -> Output {
        fbd(&["run", s(&self.cfg), "--out", s(&self.out())])
    }

    /// Runs, expects a configuration error (exit 2) naming the file and
    /// every needle, and checks nothing was simulated or written.
    fn rejected(&self, needles: &[&str]) -> String {
        let o = self.run();
        let mut all = vec![s(&self.cfg)];
        all.extend_from_slice(needles);
        let e = check_error(&o, USAGE, &all);
        assert!(
            !self.out().join("trajectory.csv").exists(),
            "trajectory.csv written for a bad configuration"
        );
        assert!(o.stdout.is_empty(), "something was simulated: {o:?}");
        e
    }
}

/// `error: <file>: <table>.<key>: <what> (got X, expected Y)`.
fn semantic(text: &str, key: &str, got: &str) {
    let c = Case::new(text);
    let e = c.rejected(&[key, "(got ", got, "expected "]);
    assert!(
        e.starts_with(&format!("error: {}: {key}: ", s(&c.cfg))),
        "{text:?} → {e}"
    );
}

// ---- TOML syntax, types, unknown keys: `file:line:col: key: what` ----

#[test]
fn toml_syntax_error_has_line_and_column() {
    let c = Case::new("[time]\ndt = 0.01\nduration = = 0.5\n");
    let e = c.rejected(&[":3:"]);
    assert!(e.starts_with(&format!("error: {}:3:", s(&c.cfg))), "{e}");
}

#[test]
fn wrong_type_names_the_key() {
    let c = Case::new("[body]\nmass = \"heavy\"\n");
    let e = c.rejected(&["body.mass", "invalid type", "expected a number"]);
    assert!(
        e.starts_with(&format!("error: {}:2:8: body.mass:", s(&c.cfg))),
        "{e}"
    );
    Case::new("[output]\nstride = 1.5\n").rejected(&[
        ":2:10:",
        "output.stride",
        "expected a whole number",
    ]);
    Case::new("[initial]\nposition = [0.0]\n").rejected(&["initial.position", "2 numbers"]);
}

#[test]
fn unknown_key_names_the_key() {
    let c = Case::new("[leg]\nupper_mass = 0.3\nupper_mas = 0.3\n");
    c.rejected(&[":3:1:", "upper_mas", "unknown field"]);
    Case::new("colour = \"red\"\n").rejected(&[":1:1:", "colour"]);
}

#[test]
fn duplicate_key_quotes_the_key() {
    Case::new("[time]\ndt = 0.01\ndt = 0.02\n").rejected(&[":3:", "duplicate key", "dt"]);
}

// ---- values out of their domain ----

#[test]
fn masses_lengths_inertias_must_be_positive_and_finite() {
    for key in [
        "body.mass",
        "body.inertia",
        "body.side",
        "leg.upper_length",
        "leg.upper_mass",
        "leg.upper_inertia",
        "leg.lower_length",
        "leg.lower_mass",
        "leg.lower_inertia",
    ] {
        let (table, name) = key.split_once('.').unwrap();
        for (v, got) in [
            ("0.0", "got 0"),
            ("-1.0", "got -1"),
            ("nan", "NaN"),
            ("inf", "got inf"),
        ] {
            semantic(&format!("[{table}]\n{name} = {v}\n"), key, got);
        }
    }
}

#[test]
fn dt_must_be_positive_and_not_exceed_duration() {
    semantic("[time]\ndt = 0.0\n", "time.dt", "got 0");
    semantic("[time]\ndt = -0.01\n", "time.dt", "got -0.01");
    semantic("[time]\ndt = nan\n", "time.dt", "NaN");
    semantic("[time]\ndt = 0.5\nduration = 0.1\n", "time.dt", "got 0.5");
    semantic("[time]\nduration = -inf\n", "time.duration", "got -inf");
    semantic(
        "[time]\ndt = 1e-300\nduration = 1e300\n",
        "time.duration",
        "too many steps",
    );
}

#[test]
fn gravity_must_be_finite() {
    semantic("[world]\ngravity = nan\n", "world.gravity", "NaN");
    semantic("[world]\ngravity = -inf\n", "world.gravity", "got -inf");
}

#[test]
fn friction_must_satisfy_zero_le_mu_dynamic_le_mu_static() {
    semantic(
        "[terrain]\nmu_static = 0.2\nmu_dynamic = 0.3\n",
        "terrain.mu_dynamic",
        "got 0.3",
    );
    semantic(
        "[terrain]\nmu_dynamic = -0.1\n",
        "terrain.mu_dynamic",
        "got -0.1",
    );
    semantic(
        "[terrain]\nmu_static = -1.0\n",
        "terrain.mu_static",
        "got -1",
    );
    semantic("[terrain]\nmu_static = nan\n", "terrain.mu_static", "NaN");
    semantic(
        "[terrain]\nmu_dynamic = inf\nmu_static = inf\n",
        "terrain.mu_static",
        "inf",
    );
}

#[test]
fn com_fractions_and_terrain_height_must_be_finite() {
    semantic("[leg]\nupper_com = 1.5\n", "leg.upper_com", "got 1.5");
    semantic("[leg]\nlower_com = nan\n", "leg.lower_com", "NaN");
    semantic("[terrain]\nheight = inf\n", "terrain.height", "got inf");
    // Rejected even where unused: nan/inf never reach config.toml.
    semantic(
        "[terrain]\nkind = \"none\"\nheight = nan\n",
        "terrain.height",
        "NaN",
    );
}

#[test]
fn angles_and_velocities_must_be_finite_planar() {
    for (table, key, value) in [
        ("initial", "position", "[nan, 0.6]"),
        ("initial", "position", "[0.0, inf]"),
        ("initial", "velocity", "[0.0, -inf]"),
        ("initial", "phi_z_deg", "nan"),
        ("initial", "omega_z_deg", "inf"),
        ("initial.leg3", "theta_deg", "[nan, 245.0]"),
        ("initial.leg3", "rate_deg", "[0.0, inf]"),
        ("initial.leg4", "theta_deg", "[0.0, -inf]"),
        ("initial.leg4", "rate_deg", "[nan, 0.0]"),
    ] {
        semantic(
            &format!("[{table}]\n{key} = {value}\n"),
            &format!("{table}.{key}"),
            "must be finite",
        );
    }
}

#[test]
fn angles_and_velocities_must_be_finite_hexapod() {
    for (table, key) in [
        ("initial", "position"),
        ("initial", "velocity"),
        ("initial", "phi_deg"),
        ("initial", "omega_deg"),
        ("initial.leg1", "theta_deg"),
        ("initial.leg6", "rate_deg"),
    ] {
        let c = Case::new(&format!(
            "model = \"hexapod\"\n[{table}]\n{key} = [0.0, nan, 0.0]\n"
        ));
        let o = fbd(&["kinematics", s(&c.cfg)]);
        check_error(
            &o,
            USAGE,
            &[s(&c.cfg), &format!("{table}.{key}"), "must be finite"],
        );
        assert!(o.stdout.is_empty());
    }
}

#[test]
fn initial_tip_below_the_terrain_names_leg_and_depth() {
    // Ry = 0.3: both tips start below y = 0; leg 3 is checked first.
    let c = Case::new("[initial]\nposition = [0.0, 0.3]\n");
    let e = c.rejected(&["initial.leg3", "tip3", "0.080649 m below the terrain"]);
    assert!(e.contains("got depth 0.080649 m"), "{e}");
    // Only leg 4 below: raise the ground until tip 4 is under it.
    let c = Case::new("[initial.leg3]\ntheta_deg = [0.0, 180.0]\n[terrain]\nheight = 0.3\n");
    c.rejected(&["initial.leg4", "tip4", "below the terrain"]);
}

#[test]
fn stride_must_be_at_least_one() {
    semantic("[output]\nstride = 0\n", "output.stride", "got 0");
    Case::new("[output]\nstride = -1\n").rejected(&[":2:10:", "output.stride"]);
}

#[test]
fn unknown_model_lists_the_valid_ones() {
    let c = Case::new("model = \"quadruped\"\n");
    c.rejected(&[":1:9:", "model", "quadruped", "`planar`", "`hexapod`"]);
    let o = fbd(&["kinematics", s(&c.cfg)]);
    check_error(&o, USAGE, &["quadruped", "`planar`"]);
}

#[test]
fn unknown_terrain_kind_lists_the_valid_ones() {
    Case::new("[terrain]\nkind = \"lava\"\n").rejected(&[
        ":2:8:",
        "terrain.kind",
        "lava",
        "expected",
        "`flat`",
        "`none`",
    ]);
}

#[test]
fn empty_file_is_the_default_experiment() {
    // As a file with one key is filled from the defaults, an empty one (or
    // one of blanks and comments) is all defaults.
    let default = Case::new("");
    let o = fbd(&["run", "--out", s(&default.out())]);
    assert!(o.status.success(), "{o:?}");
    let expected = std::fs::read(default.out().join("config.toml")).unwrap();
    for text in ["", "  \n\t\n", "# nothing but a comment\n"] {
        let c = Case::new(text);
        let o = c.run();
        assert!(o.status.success(), "{text:?}: {o:?}");
        let got = std::fs::read(c.out().join("config.toml")).unwrap();
        assert_eq!(got, expected, "{text:?}");
    }
}

#[test]
fn negative_gravity_is_rejected_as_a_magnitude() {
    let e = Case::new("[world]\ngravity = -9.81\n").rejected(&["world.gravity", "magnitude"]);
    assert!(e.contains("got -9.81"), "{e}");
    // Zero gravity is allowed (a robot floating in space).
    let c = Case::new("[world]\ngravity = 0.0\n[time]\nduration = 0.05\n");
    assert!(c.run().status.success());
}

/// The longest run of consecutive digits in `text`.
fn longest_digit_run(text: &str) -> usize {
    text.split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0)
}

#[test]
fn huge_and_tiny_values_are_quoted_short() {
    // Rust's `{}` writes 1e300 with all its 301 digits: every quoted
    // number goes through `fbd_kinematics::num`.
    let hexapod = "model = \"hexapod\"\n[time]\nduration = 0.01\n";
    for (text, needles) in [
        (
            "[leg]\nlower_com = 1e300\n".to_owned(),
            vec!["leg.lower_com", "got 1e300"],
        ),
        (
            "[leg]\ntheta1_deg = 1e300\n".to_owned(),
            vec!["leg.theta1_deg", "invalid type: floating point `1e300`"],
        ),
        (
            format!("{hexapod}[initial.leg4]\ntheta_deg = [0.0, 0.0, 1e300]\n"),
            vec![
                "initial.leg4.theta_deg",
                "theta3 = 1.000e300°",
                "by 1.000e300°",
            ],
        ),
        (
            format!("{hexapod}[control]\nkind = \"pd\"\nkp = 1000.0\nkd = 1e300\n"),
            vec!["control.kd", "got 1e300 N·m·s/rad"],
        ),
        (
            "[terrain]\nmu_static = 0.5\nmu_dynamic = 1e300\n".to_owned(),
            vec!["terrain.mu_dynamic", "got 1e300"],
        ),
        (
            "[time]\ndt = 1e-300\nduration = 1e-301\n".to_owned(),
            vec!["time.dt", "got 1e-300"],
        ),
    ] {
        let e = Case::new(&text).rejected(&needles);
        assert!(longest_digit_run(&e) < 20, "{text:?} → {e}");
    }
    // A run-time advice: the time scale of a robot under 1e300 m/s² of
    // gravity and the step it asks for, as numbers, not as zeros.
    let c = Case::new("[world]\ngravity = 1e300\n[time]\nduration = 0.01\n");
    let o = c.run();
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("√(c/g) = 6.481e-151 s"), "{e}");
    assert!(e.contains("try time.dt = 2e-152"), "{e}");
    assert!(longest_digit_run(&e) < 20, "{e}");
}

#[test]
fn a_swing_shorter_than_two_steps_is_rejected() {
    // `period = 1e-9` asked the gait's plan for a foothold per period:
    // 3e8 of them in a 0.3 s run, and the run was killed for memory.
    // The tripod's swing is half the period: two steps of 1 ms need 4 ms.
    let walk = |period: &str| {
        format!(
            "model = \"hexapod\"\n[time]\ndt = 0.001\nduration = 0.3\n\
             [gait]\nkind = \"tripod\"\nperiod = {period}\n[control]\nkind = \"gait\"\n"
        )
    };
    semantic(&walk("1e-9"), "gait.period", "1e-9");
    let e = Case::new(&walk("0.0039")).rejected(&[
        "gait.period",
        "spans fewer than 2 steps of time.dt = 0.001 s",
        "a period ≥ 0.004 s",
    ]);
    assert!(e.contains("(got 0.0039, "), "{e}");
    assert!(parse_str(&walk("0.004"), "w.toml", &[]).is_ok());
    // An imported robot's gait keeps the same rule.
    let robots = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/robots");
    let text = std::fs::read_to_string(robots.join("lab_hexapod_walk.toml"))
        .unwrap()
        .replace(
            "urdf = \"lab_hexapod.urdf\"",
            &format!("urdf = {:?}", s(&robots.join("lab_hexapod.urdf"))),
        )
        .replace(
            "pattern = \"tripod\"",
            "pattern = \"tripod\"\nperiod = 1e-9",
        );
    Case::new(&text).rejected(&[
        "gait.period: the swing (1 − duty_factor)·period = ",
        "spans fewer than 2 steps of time.dt = 0.001 s (got 1e-9, expected a period ≥ 0.005 s",
    ]);
}

#[test]
fn a_typo_in_a_key_suggests_the_key() {
    let e = Case::new("[terrain]\nmu_statc = 0.5\n").rejected(&["cfg.toml:2:1"]);
    assert!(e.contains("did you mean `mu_static`?"), "{e}");
    let e = Case::new("[tme]\ndt = 0.01\n").rejected(&["cfg.toml:1:"]);
    assert!(e.contains("did you mean `time`?"), "{e}");
    // No suggestion when nothing is close.
    let e = Case::new("[body]\nwingspan = 2.0\n").rejected(&["wingspan"]);
    assert!(!e.contains("did you mean"), "{e}");
}

#[test]
fn a_failure_at_a_large_step_suggests_a_smaller_one() {
    // The reference failing experiment at Δt = 0.05 s, above a twentieth of
    // the lower links' time scale √(c/g) = 0.21 s: the error says so and
    // suggests 0.01 s.
    let c = Case::new(&FAILS.replace("[time]\n", "[time]\ndt = 0.05\n"));
    let o = c.run();
    let e = check_error(&o, SIMULATION, &["time.dt = 0.05 s is likely too large"]);
    assert!(e.trim_end().ends_with("try time.dt = 0.01"), "{e}");
    // At Δt = 0.01 s the same kind of failure gets no such advice.
    let c = Case::new(FAILS);
    let e = check_error(&c.run(), SIMULATION, &[&fail_prefix()]);
    assert!(!e.contains("too large"), "{e}");
}

#[test]
fn a_missing_file_reads_the_same_in_every_command() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nope.toml");
    let out = dir.path().join("out");
    let want = format!("error: {}: no such file\n", missing.display());
    for args in [
        vec!["run", s(&missing), "--out", s(&out)],
        vec!["kinematics", s(&missing)],
        vec!["sweep", s(&missing), "--out", s(&out)],
    ] {
        let o = fbd(&args);
        check_error(&o, USAGE, &[]);
        assert_eq!(String::from_utf8_lossy(&o.stderr), want, "{args:?}");
    }
    // A sweep whose base is missing names the base and the sweep.
    let sweep = dir.path().join("sweep.toml");
    std::fs::write(
        &sweep,
        "base = \"nope.toml\"\n[vary]\n\"time.dt\" = [0.01]\n",
    )
    .unwrap();
    let o = fbd(&["sweep", s(&sweep), "--out", s(&out)]);
    check_error(
        &o,
        USAGE,
        &[&format!("{}: no such file (the base of", missing.display())],
    );
    // merge: a missing directory, and a directory that is not a sweep's.
    let nodir = dir.path().join("nodir");
    let o = fbd(&["sweep", "merge", s(&nodir), "--out", s(&out)]);
    check_error(
        &o,
        USAGE,
        &[&format!("{}: no such directory", nodir.display())],
    );
    let o = fbd(&["sweep", "merge", s(dir.path()), "--out", s(&out)]);
    check_error(&o, USAGE, &["sweep.json: no such file"]);
}

#[test]
fn missing_file_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("nope.toml");
    let out = dir.path().join("out");
    let o = fbd(&["run", s(&missing), "--out", s(&out)]);
    check_error(&o, USAGE, &[s(&missing), "no such file"]);
    assert!(!out.exists());
    let o = fbd(&["kinematics", s(&missing)]);
    check_error(&o, USAGE, &[s(&missing), "no such file"]);
}

#[test]
fn directory_as_config_is_rejected() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = fbd(&["run", s(dir.path()), "--out", s(&out)]);
    check_error(&o, USAGE, &[s(dir.path()), "is a directory"]);
    assert!(!out.exists());
}

#[test]
fn non_utf8_file_is_rejected() {
    let c = Case::new("");
    std::fs::write(&c.cfg, b"[time]\ndt = 0.01 # \xff\xfe\n").unwrap();
    c.rejected(&["not UTF-8"]);
}

// ---- output directory: fails before simulating (exit 4) ----

#[test]
fn output_dir_that_cannot_be_created_fails_before_simulating() {
    let c = Case::new(FAILS);
    let file = c.dir.path().join("plain_file");
    std::fs::write(&file, "x").unwrap();
    let under_file = file.join("sub");
    let o = fbd(&["run", s(&c.cfg), "--out", s(&under_file)]);
    let e = check_error(
        &o,
        IO,
        &[s(&under_file), "cannot create the output directory"],
    );
    assert!(!e.contains("step"), "{e}");
    assert!(o.stdout.is_empty(), "simulated anyway");
    let o = fbd(&["run", s(&c.cfg), "--out", s(&file)]);
    check_error(&o, IO, &[s(&file), "not a directory"]);
    assert!(o.stdout.is_empty(), "simulated anyway");
}

#[cfg(unix)]
#[test]
fn runtime_failure_names_step_time_and_residual() {
    let c = Case::new(FAILS);
    let o = c.run();
    let e = check_error(&o, SIMULATION, &["residual", s(&c.cfg)]);
    assert!(e.starts_with(&format!("error: {}", fail_prefix())), "{e}");
    let out = c.out();
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert_eq!(summary["status"], "error");
    let msg = summary["error"].as_str().unwrap();
    assert!(
        msg.starts_with(&fail_prefix()) && msg.contains("residual"),
        "{msg}"
    );
    let rows = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let last = rows.lines().last().unwrap();
    assert_eq!(rows.lines().count(), 1 + FAIL_STEP);
    // Times are the decimal of k·Δt.
    assert!(last.starts_with("0.25,"), "{last}");
    assert_no_temp_files(&out);
}

// ---- nothing half-written ----

fn assert_no_temp_files(dir: &Path) {
    for f in std::fs::read_dir(dir).unwrap() {
        let name = f.unwrap().file_name().to_string_lossy().into_owned();
        assert!(!name.ends_with(".tmp"), "temporary file left: {name}");
    }
}

#[test]
fn rerunning_into_an_existing_dir_replaces_every_file_whole() {
    let long = Case::new("[time]\nduration = 0.4\n");
    let out = long.out();
    assert!(long.run().status.success());
    let before: Vec<Vec<u8>> = fbd_cli::output::FILES
        .iter()
        .map(|f| std::fs::read(out.join(f)).unwrap())
        .collect();
    // A shorter run into the same directory: every file is the new one.
    std::fs::write(&long.cfg, "[time]\nduration = 0.1\n").unwrap();
    assert!(long.run().status.success());
    let traj = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    assert_eq!(traj.lines().count(), 1 + 11, "stale rows left behind");
    for (f, old) in fbd_cli::output::FILES.iter().zip(&before) {
        let new = std::fs::read(out.join(f)).unwrap();
        assert_ne!(&new, old, "{f} was not replaced");
    }
    assert!(
        std::fs::read_to_string(out.join("config.toml"))
            .unwrap()
            .contains("duration = 0.1")
    );
    assert_no_temp_files(&out);
}

// ---- the loader never panics ----

fn runner(cases: u32) -> TestRunner {
    let config = PtConfig {
        cases,
        failure_persistence: None,
        ..PtConfig::default()
    };
    TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha))
}

/// Loads `text`; an accepted configuration must also build its model and
/// survive a round trip through `config.toml`.
fn load_checked(text: &str) -> Result<(), TestCaseError> {
    match parse_str(text, "fuzz.toml", &[]) {
        Err(e) => {
            let msg = e.to_string();
            prop_assert!(!msg.contains('\n'), "multi-line error: {msg:?}");
            prop_assert!(msg.starts_with("fuzz.toml"), "{msg}");
            // 1e308 quoted as itself, not as its 309 digits (the longest
            // replacement is a 20-digit integer).
            prop_assert!(longest_digit_run(&msg) <= 20, "{msg}");
        }
        Ok(c) => {
            let written = c.to_toml();
            let again = parse_str(&written, "config.toml", &[]);
            prop_assert_eq!(again.as_ref().ok(), Some(&c), "{:?}\n{}", again, written);
            if let Config::Planar(p) = &c {
                let _ = p.model("fuzz.toml");
            }
        }
    }
    Ok(())
}

const REPLACEMENTS: [&str; 16] = [
    "nan",
    "-nan",
    "inf",
    "-inf",
    "-1",
    "0",
    "-0.0",
    "1e308",
    "-1e308",
    "1e-320",
    "\"str\"",
    "[]",
    "{}",
    "true",
    "18446744073709551616",
    "[1, 2, 3]",
];

/// Spans of the numbers in `line` (runs of number characters that parse).
fn numbers(line: &str) -> Vec<(usize, usize)> {
    let is_num = |c: char| c.is_ascii_digit() || "+-.eE".contains(c);
    let mut spans = Vec::new();
    let mut start = None;
    for (i, c) in line.char_indices().chain([(line.len(), ' ')]) {
        match (start, is_num(c)) {
            (None, true) => start = Some(i),
            (Some(s), false) => {
                if line[s..i].parse::<f64>().is_ok() {
                    spans.push((s, i));
                }
                start = None;
            }
            _ => {}
        }
    }
    spans
}

/// Applies one mutation `(kind, a, b)` to `lines`.
fn mutate(lines: &mut Vec<String>, (kind, a, b): (u8, usize, usize)) {
    if lines.is_empty() {
        lines.push(String::new());
    }
    let i = a % lines.len();
    match kind % 5 {
        0 => {
            lines.remove(i);
        }
        1 => {
            let l = lines[i].clone();
            lines.insert(i, l);
        }
        2 => {
            let j = b % lines.len();
            lines[i] = lines[j].clone();
        }
        3 => {
            let spans = numbers(&lines[i]);
            if !spans.is_empty() {
                let (s, e) = spans[b % spans.len()];
                let r = REPLACEMENTS[(b / 7) % REPLACEMENTS.len()];
                lines[i].replace_range(s..e, r);
            }
        }
        _ => {
            // Replace the value after `=` wholesale.
            if let Some(eq) = lines[i].find('=') {
                let r = REPLACEMENTS[b % REPLACEMENTS.len()];
                lines[i].replace_range(eq + 1.., &format!(" {r}"));
            }
        }
    }
}

/// `cases` random mutations (1 to 7 each) of `text` through the loader.
fn mutations_load(text: &str, cases: u32) {
    load_checked(text).unwrap();
    let base: Vec<String> = text.lines().map(str::to_owned).collect();
    let ops = prop::collection::vec((any::<u8>(), any::<usize>(), any::<usize>()), 1..8);
    runner(cases)
        .run(&ops, |ops| {
            let mut lines = base.clone();
            for op in ops {
                mutate(&mut lines, op);
            }
            load_checked(&lines.join("\n"))
        })
        .unwrap();
}

#[test]
fn loader_never_panics_on_mutations_of_the_paper_example() {
    mutations_load(&paper_toml(), 500);
}

#[test]
fn loader_never_panics_on_mutations_of_the_hexapod_walk() {
    // The 3D keys: `[gait]`, `[control]`, the six legs' initial angles.
    let walk = std::fs::read_to_string(common::examples().join("hexapod_walk.toml")).unwrap();
    mutations_load(&walk, 300);
}

#[test]
fn loader_never_panics_on_arbitrary_bytes() {
    let bytes = prop::collection::vec(any::<u8>(), 0..400);
    runner(500)
        .run(&bytes, |b| load_checked(&String::from_utf8_lossy(&b)))
        .unwrap();
    // TOML-shaped text hits more of the loader than random bytes.
    let tomlish = "[a-z\\[\\]\\.=\" 0-9\n-]{0,200}";
    runner(500).run(&tomlish, |t| load_checked(&t)).unwrap();
}

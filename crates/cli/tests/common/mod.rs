//! Helpers shared by the end-to-end tests of the `fbd` binary.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs the real `fbd` binary with `args`.
pub fn fbd(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fbd"))
        .args(args)
        .output()
        .expect("the fbd binary runs")
}

/// Runs the real `fbd` binary with `args` in the working directory `dir`.
pub fn fbd_in(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_fbd"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the fbd binary runs")
}

/// The repository's `examples/` directory.
pub fn examples() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples")
}

/// `examples/<name>` as a string argument.
pub fn example(name: &str) -> String {
    examples().join(name).display().to_string()
}

/// A path as a command-line argument.
pub fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

/// Standard error as text.
pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Standard output as text.
pub fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Writes `text` to `dir/name` and returns the path.
pub fn write(dir: &Path, name: &str, text: &str) -> PathBuf {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p
}

/// The reference failing experiment, away from the contact model: the robot
/// in space (no terrain, joint stops out of reach) whose trajectory
/// controller (kp = 10 N·m/rad, stable) is told to turn both hips by 10⁶°
/// between t = 0.25 s and 0.26 s: a torque of 1.7e5 N·m in one step, which
/// Newton's method cannot solve, deterministically at step [`FAIL_STEP`]
/// (t = 0.26 s). (It was a stiff PD controller in space, which is now
/// refused before the run: its explicit torques were unstable.) A run that
/// succeeds here is a regression of the tests that use it: pick another
/// failing experiment.
pub const FAILS: &str = "[time]\nduration = 1.0\n[leg]\ntheta2_deg = [-1e6, 1e6]\ntheta3_deg = [-1e6, 1e6]\n[terrain]\nkind = \"none\"\n[control]\nkind = \"trajectory\"\nkp = 10.0\n[control.leg3]\ntimes = [0.0, 0.25, 0.26]\ntarget_deg = [[0.0, 245.0], [0.0, 245.0], [1e6, 245.0]]\n[control.leg4]\ntimes = [0.0, 0.25, 0.26]\ntarget_deg = [[0.0, 255.0], [0.0, 255.0], [1e6, 255.0]]\n";

/// The step at which [`FAILS`] stops.
pub const FAIL_STEP: usize = 26;

/// Δt of [`FAILS`] (s).
pub const FAIL_DT: f64 = 0.01;

/// `"step 26 (t = 0.26"`: how the error of [`FAILS`] starts.
pub fn fail_prefix() -> String {
    format!("step {FAIL_STEP} (t = {:.2}", FAIL_STEP as f64 * FAIL_DT)
}

/// The figures README.md and docs/*.md quote, checked against runs (one
/// module for the workspace's and the CLI's tests).
#[path = "../../../../tests/common/readme.rs"]
pub mod readme;

/// The header and the rows of fields of `dir/trajectory.csv`.
pub fn trajectory_fields(dir: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let text = std::fs::read_to_string(dir.join("trajectory.csv")).unwrap();
    let split = |l: &str| l.split(',').map(str::to_owned).collect::<Vec<_>>();
    let mut lines = text.lines();
    let header = split(lines.next().unwrap());
    (header, lines.map(split).collect())
}

/// The header and the rows of `dir/trajectory.csv`, every cell a number
/// (a contact state, `ST1`–`ST3`, as NaN).
pub fn trajectory(dir: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let (header, rows) = trajectory_fields(dir);
    let rows = rows
        .iter()
        .map(|r| r.iter().map(|v| v.parse().unwrap_or(f64::NAN)).collect())
        .collect();
    (header, rows)
}

/// The scene JSON embedded in `dir/viewer.html`.
pub fn scene(dir: &Path) -> serde_json::Value {
    let page = std::fs::read_to_string(dir.join("viewer.html")).unwrap();
    let start = r#"<script id="fbd-scene" type="application/json">"#;
    let a = page.find(start).expect("the scene element") + start.len();
    let b = a + page[a..].find("</script>").unwrap();
    serde_json::from_str(&page[a..b].replace("<\\/", "</")).unwrap()
}

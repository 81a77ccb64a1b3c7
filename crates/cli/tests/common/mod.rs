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
/// in space (no terrain, joint stops out of reach) driven by a stiff PD
/// controller. Newton's method fails, deterministically at step
/// [`FAIL_STEP`] (t = 0.26 s). A run that succeeds here is a regression of
/// the tests that use it: pick another failing experiment.
pub const FAILS: &str = "[time]\nduration = 1.0\n[leg]\ntheta2_deg = [-1e6, 1e6]\ntheta3_deg = [-1e6, 1e6]\n[terrain]\nkind = \"none\"\n[control]\nkind = \"pd\"\nkp = 300.0\n[control.leg3]\ntarget_deg = [30.0, 200.0]\n[control.leg4]\ntarget_deg = [30.0, 200.0]\n";

/// The step at which [`FAILS`] stops.
pub const FAIL_STEP: usize = 26;

/// Δt of [`FAILS`] (s).
pub const FAIL_DT: f64 = 0.01;

/// `"step 26 (t = 0.26"`: how the error of [`FAILS`] starts.
pub fn fail_prefix() -> String {
    format!("step {FAIL_STEP} (t = {:.2}", FAIL_STEP as f64 * FAIL_DT)
}

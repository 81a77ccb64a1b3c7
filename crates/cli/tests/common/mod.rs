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

/// The reference failing experiment: the robot dropped from 20 m with a
/// time step of 0.2 s, far too large for its links (they swing on a time
/// scale of 0.21 s). It falls freely, and the step of the landing cannot be
/// solved: deterministically at step [`FAIL_STEP`] (t = 2.2 s).
pub const FAILS: &str = "[time]\ndt = 0.2\nduration = 4.0\n[initial]\nposition = [0.0, 20.0]\n";

/// The step at which [`FAILS`] stops.
pub const FAIL_STEP: usize = 11;

/// `"step 11 (t = 2.2"`: how the error of [`FAILS`] starts.
pub fn fail_prefix() -> String {
    format!("step {FAIL_STEP} (t = {:.1}", FAIL_STEP as f64 * 0.2)
}

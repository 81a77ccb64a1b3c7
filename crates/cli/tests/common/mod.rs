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

/// The reference failing experiment: the paper's model (contact at the feet
/// only) run to 1 s. Its body falls through the floor, a leg straightens and
/// Newton diverges, deterministically at step 49 (t = 0.49 s).
pub const FAILS_AT_STEP_49: &str = "[time]\nduration = 1.0\n[contact]\npoints = [\"tips\"]\n";

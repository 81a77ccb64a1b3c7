//! What `fbd` says, end to end through the binary (issue 27, "Messages"):
//! a Δt far too large for a passive fall warns before the run with the
//! value to use (and a fine Δt does not); printed numbers never read
//! `-0.0000`; a sweep that will write more than
//! `fbd_cli::output::LARGE_SWEEP` warns once before its first run, saying
//! what would shrink it, and every sweep ends by saying how much it wrote.

mod common;

use common::{example, fbd, s, stderr, stdout, write};

#[test]
fn a_far_too_large_step_on_a_passive_fall_warns_with_a_suggested_value() {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "coarse.toml", "[time]\ndt = 0.5\n");
    let o = fbd(&["run", s(&cfg), "--out", s(&dir.path().join("coarse"))]);
    let e = stderr(&o);
    assert_eq!(
        e.matches("far too large").count(),
        1,
        "one warning before the run:\n{e}"
    );
    let w = e.lines().find(|l| l.contains("far too large")).unwrap();
    assert!(w.starts_with("warning: time.dt = 0.5 s"), "{w}");
    assert!(w.contains("(the run solves 3 steps)"), "{w}");
    assert!(w.ends_with("try time.dt = 0.01"), "{w}");

    // The built-in experiment's Δt (the suggested one) runs without it.
    let o = fbd(&["run", "--out", s(&dir.path().join("fine"))]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
}

/// The first `-0.000…` (a negative zero printed with decimals) of `text`.
fn negative_zero(text: &str) -> Option<&str> {
    text.match_indices("-0.").find_map(|(i, _)| {
        let digits: &str = &text[i + 3..];
        let n = digits.bytes().take_while(u8::is_ascii_digit).count();
        (n > 0 && digits[..n].bytes().all(|b| b == b'0')).then(|| {
            let end = text[i..].find('\n').map_or(text.len(), |j| i + j);
            &text[i..end]
        })
    })
}

#[test]
fn printed_numbers_are_never_negative_zero() {
    assert_eq!(negative_zero("z -0.0000 m"), Some("-0.0000 m"));
    assert_eq!(negative_zero("x -0.0010 m, -0.5"), None);
    let dir = tempfile::tempdir().unwrap();
    // A hexapod floating just below the origin without gravity: every
    // figure of its report rounds to zero from below.
    let floating = write(
        dir.path(),
        "floating.toml",
        "model = \"hexapod\"\n[world]\ngravity = 0.0\n[terrain]\nkind = \"none\"\n[time]\ndt = 0.001\nduration = 0.01\n[initial]\nposition = [-1e-6, -1e-6, -1e-6]\n",
    );
    // The kinematic gait turning a hair to the right.
    let turn = write(
        dir.path(),
        "turn.toml",
        "model = \"hexapod\"\ndynamics = \"kinematic\"\n[time]\nduration = 1.0\n[gait]\nforward_speed = -1e-7\nyaw_rate_deg = -1e-5\n",
    );
    for (cfg, name) in [
        (s(&floating).to_owned(), "floating"),
        (s(&turn).to_owned(), "turn"),
        (example("hexapod_turn.toml"), "hexapod_turn"),
        (example("paper.toml"), "paper"),
    ] {
        let o = fbd(&["run", &cfg, "--out", s(&dir.path().join(name))]);
        assert!(o.status.success(), "{name}: {}", stderr(&o));
        let out = stdout(&o);
        assert!(out.contains(" m"), "{name}: {out}");
        if let Some(z) = negative_zero(&out) {
            panic!("{name} prints a negative zero: {z}\n{out}");
        }
    }
}

/// A sweep file of `runs` runs of `base` (written to `dir`).
fn sweep_file(dir: &std::path::Path, base: &str, runs: usize) -> std::path::PathBuf {
    write(dir, "base.toml", base);
    let mus: Vec<String> = (0..runs)
        .map(|i| format!("{}", 0.4 + 0.001 * i as f64))
        .collect();
    write(
        dir,
        "sweep.toml",
        &format!(
            "base = \"base.toml\"\n[vary]\n\"terrain.mu_static\" = [{}]\n",
            mus.join(", ")
        ),
    )
}

#[test]
fn a_sweep_too_large_warns_once_with_what_would_shrink_it() {
    let dir = tempfile::tempdir().unwrap();
    // Two runs planned for 2e6 s at Δt = 10 ms (4e8 rows in all, some
    // 380 GB of CSV), which fail at their step 26 (the reference failing
    // experiment): the warning comes before the first run, from the plan.
    let base = common::FAILS.replace("duration = 1.0", "duration = 2e6");
    let sweep = sweep_file(dir.path(), &base, 2);
    let out = dir.path().join("big");
    let o = fbd(&["sweep", s(&sweep), "--out", s(&out), "--jobs", "1"]);
    assert_eq!(o.status.code(), Some(3), "the runs fail: {}", stderr(&o));
    let e = stderr(&o);
    let warnings: Vec<&str> = e
        .lines()
        .filter(|l| l.starts_with("warning: this sweep will write about"))
        .collect();
    assert_eq!(warnings.len(), 1, "one warning:\n{e}");
    let w = warnings[0];
    assert!(w.contains("GB (2 runs: trajectory files"), "{w}");
    assert!(w.contains("`[output] stride = "), "{w}");
    assert!(w.contains("`format = \"parquet\"`"), "{w}");
    // Nothing near that was written, and the sweep says what it wrote.
    assert!(
        stdout(&o).contains("files in ") && stdout(&o).contains(" kB"),
        "{}",
        stdout(&o)
    );

    // The stride it suggests is enough: no sweep warning with it.
    let stride: usize = w
        .split("`[output] stride = ")
        .nth(1)
        .and_then(|r| r.split('`').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no stride in {w}"));
    let strided = format!("{base}[output]\nstride = {stride}\n");
    let sweep = sweep_file(dir.path(), &strided, 2);
    let o = fbd(&["sweep", s(&sweep), "--out", s(&dir.path().join("strided"))]);
    assert!(
        !stderr(&o).contains("this sweep will write"),
        "{}",
        stderr(&o)
    );
}

#[test]
fn a_small_sweep_does_not_warn_and_says_what_it_wrote() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = sweep_file(dir.path(), "[time]\nduration = 0.1\n", 2);
    let o = fbd(&["sweep", s(&sweep), "--out", s(&dir.path().join("small"))]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!stderr(&o).contains("warning"), "{}", stderr(&o));
    let out = stdout(&o);
    let wrote = out
        .lines()
        .find(|l| l.starts_with("files in "))
        .unwrap_or_else(|| panic!("{out}"));
    // `(12 kB; per-run viewers and plots with --viewer, --plots)`: the
    // bytes the directory holds.
    let kb: f64 = wrote
        .split('(')
        .nth(1)
        .and_then(|r| r.split(" kB").next())
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("{wrote}"));
    let real = fbd_cli::sweep::dir_bytes(&dir.path().join("small")) as f64 / 1e3;
    assert!(
        (kb - real).abs() <= 0.5,
        "{wrote}: the folder holds {real} kB"
    );
}

//! A PD gain that makes the explicit joint torques unstable is a
//! configuration error before the run: one line naming the file, the key,
//! the limit and the remedy, the exit status of every invalid parameter
//! (2), and no output written.

mod common;

use common::{example, fbd, s, stderr};

/// `examples/hexapod_walk.toml` with `control.kd` set to `kd`, in a
/// temporary directory.
fn walk_with_kd(kd: &str) -> (tempfile::TempDir, std::path::PathBuf) {
    let text = std::fs::read_to_string(example("hexapod_walk.toml")).unwrap();
    let line = "kd = 15.0                       # N·m·s/rad";
    assert!(text.contains(line), "the walk's damping line moved");
    let dir = tempfile::tempdir().unwrap();
    let cfg = common::write(
        dir.path(),
        "walk.toml",
        &text.replace(line, &format!("kd = {kd}")),
    );
    (dir, cfg)
}

#[test]
fn an_unstable_kd_is_one_line_before_the_run() {
    let (dir, cfg) = walk_with_kd("30.0");
    let out = dir.path().join("out");
    let o = fbd(&["run", s(&cfg), "--out", s(&out)]);
    let e = stderr(&o);
    assert_eq!(o.status.code(), Some(2), "{e}");
    assert_eq!(e.lines().count(), 1, "{e}");
    for needle in [
        "error: ",
        "walk.toml",
        "control.kd",
        "got 30 N·m·s/rad",
        "control.kd < 19.7",
        "time.dt below",
    ] {
        assert!(e.contains(needle), "{e:?} lacks {needle:?}");
    }
    assert!(!e.contains("panicked"), "{e}");
    assert!(!out.exists(), "nothing is written before the run");
}

#[test]
fn kd_22_is_refused_too() {
    // Engineer's observation: kd = 22 launched the walking robot into the
    // air; the limit of its tripod stance is 19.74 N·m·s/rad.
    let (dir, cfg) = walk_with_kd("22.0");
    let out = dir.path().join("out");
    let o = fbd(&["run", s(&cfg), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    assert!(stderr(&o).contains("control.kd"), "{}", stderr(&o));
    assert!(!out.exists());
}

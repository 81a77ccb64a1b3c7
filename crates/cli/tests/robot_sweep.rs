//! `fbd sweep` of an imported robot: every run is `fbd run` of its
//! `config.toml`, `index.csv` has the dynamic hexapod's columns, `--resume`
//! skips what finished, and an override the robot cannot take is one line
//! naming the key.

mod common;

use common::{example, fbd, s, stderr, write};

/// A 2 × 2 sweep over friction and drop height of the lab hexapod's drop
/// (0.3 s, every 5th row), written next to a copy of its base.
fn sweep_file(dir: &std::path::Path, extra: &str) -> std::path::PathBuf {
    let base = std::fs::read_to_string(example("robots/lab_hexapod_drop.toml"))
        .unwrap()
        .replace(
            "urdf = \"lab_hexapod.urdf\"",
            &format!("urdf = \"{}\"", example("robots/lab_hexapod.urdf")),
        );
    write(dir, "drop.toml", &base);
    write(
        dir,
        "sweep.toml",
        &format!(
            "base = \"drop.toml\"\nmode = \"grid\"\n[vary]\n\"terrain.mu_static\" = [0.3, 0.9]\n\
             \"initial.position\" = [[0.0, 0.16, 0.0], [0.0, 0.2, 0.0]]\n[derive]\n\
             \"terrain.mu_dynamic\" = {{ from = \"terrain.mu_static\", scale = 0.75 }}\n\
             [set]\n\"time.duration\" = 0.3\n\"output.stride\" = 5\n{extra}"
        ),
    )
}

#[test]
fn a_robot_sweep_runs_every_combination_and_resumes() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = sweep_file(dir.path(), "");
    let out = dir.path().join("out");
    let o = fbd(&["sweep", s(&sweep), "--out", s(&out), "--jobs", "2"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let index = std::fs::read_to_string(out.join("index.csv")).unwrap();
    let mut lines = index.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    for c in [
        "run",
        "status",
        "terrain.mu_static",
        "distance",
        "final_height",
        "peak_foot_n",
        "first_touchdown",
        "events",
        "max_law_violation",
        "error",
    ] {
        assert!(header.contains(&c), "no column {c} in {header:?}");
    }
    let rows: Vec<&str> = lines.collect();
    assert_eq!(rows.len(), 4);
    assert!(rows.iter().all(|r| r.contains(",ok,")), "{index}");
    // Every run is `fbd run` of its config.toml: the same files, and the
    // varied values in it.
    for i in 0..4 {
        let rd = out.join("runs").join(i.to_string());
        for f in [
            "trajectory.csv",
            "events.csv",
            "summary.json",
            "config.toml",
        ] {
            assert!(rd.join(f).is_file(), "run {i}: {f}");
        }
        assert!(
            !rd.join("viewer.html").exists(),
            "no viewer without --viewer"
        );
        let again = dir.path().join(format!("again{i}"));
        let o = fbd(&["run", s(&rd.join("config.toml")), "--out", s(&again)]);
        assert!(o.status.success(), "{}", stderr(&o));
        assert_eq!(
            std::fs::read(rd.join("trajectory.csv")).unwrap(),
            std::fs::read(again.join("trajectory.csv")).unwrap(),
            "run {i} repeats byte for byte"
        );
    }
    let cfg0 = std::fs::read_to_string(out.join("runs/0/config.toml")).unwrap();
    assert!(cfg0.contains("mu_static = 0.3"), "{cfg0}");
    // The higher drop touches down later.
    let touchdown = |i: usize| -> f64 {
        let cols: Vec<&str> = rows[i].split(',').collect();
        let at = header.iter().position(|h| *h == "first_touchdown").unwrap();
        // The quoted arrays of initial.position hold commas: count from the
        // end of the row instead.
        let from_end = header.len() - at;
        cols[cols.len() - from_end].parse().unwrap()
    };
    assert!(touchdown(1) > touchdown(0), "{index}");
    // --resume: every run finished, none is run again.
    let o = fbd(&["sweep", s(&sweep), "--out", s(&out), "--resume"]);
    assert!(o.status.success(), "{}", stderr(&o));
    let said = String::from_utf8_lossy(&o.stdout).to_string();
    assert!(said.contains("ran 0, skipped 4"), "{said}");
}

#[test]
fn a_key_the_robot_does_not_have_is_one_line() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = sweep_file(dir.path(), "\"leg.upper_length\" = 0.3\n");
    let o = fbd(&["sweep", s(&sweep), "--out", s(&dir.path().join("out"))]);
    assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
    let e = stderr(&o);
    assert_eq!(e.trim().lines().count(), 1, "{e}");
    assert!(e.contains("set.\"leg.upper_length\""), "{e}");
}

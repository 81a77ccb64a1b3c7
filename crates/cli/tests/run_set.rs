//! `fbd run [CONFIG] --set KEY=VALUE`: keys of the configuration set on the
//! command line, in order, for the built-in default, a hexapod and an
//! imported robot; the written config.toml repeats the run; a bad key or
//! value is one line naming it, with nothing written.

mod common;

use common::{example, fbd, s, stderr};

fn config(dir: &std::path::Path) -> toml::Table {
    toml::from_str(&std::fs::read_to_string(dir.join("config.toml")).unwrap()).unwrap()
}

fn summary(dir: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(dir.join("summary.json")).unwrap()).unwrap()
}

#[test]
fn set_changes_the_default_and_its_written_configuration_repeats_the_run() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("a");
    let o = fbd(&[
        "run",
        "--set",
        "time.duration=0.3",
        "--set",
        "time.dt = 0.005",
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let c = config(&out);
    assert_eq!(c["time"]["dt"].as_float(), Some(0.005));
    assert_eq!(c["time"]["duration"].as_float(), Some(0.3));
    // 0.3 s at 5 ms: steps 0..=60.
    assert_eq!(summary(&out)["steps"], 61);
    // The later of two settings of one key wins.
    let twice = tmp.path().join("twice");
    let o = fbd(&[
        "run",
        "--set",
        "time.duration=1",
        "--set",
        "time.duration=0.2",
        "--out",
        s(&twice),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(config(&twice)["time"]["duration"].as_float(), Some(0.2));
    // The written configuration repeats the run, byte for byte.
    let again = tmp.path().join("b");
    let o = fbd(&["run", s(&out.join("config.toml")), "--out", s(&again)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let read = |d: &std::path::Path| std::fs::read(d.join("trajectory.csv")).unwrap();
    assert_eq!(read(&out), read(&again));
}

#[test]
fn set_changes_a_hexapod_and_a_robot_configuration() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("walk");
    let o = fbd(&[
        "run",
        &example("hexapod_walk.toml"),
        "--set",
        "time.dt=0.0005",
        "--set",
        "time.duration=0.05",
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let sm = summary(&out);
    assert_eq!(sm["dt"], 0.0005);
    assert_eq!(sm["steps"], 101);
    let out = tmp.path().join("robot");
    let o = fbd(&[
        "run",
        &example("robots/lab_hexapod_stand.toml"),
        "--set",
        "time.duration=0.02",
        "--out",
        s(&out),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(config(&out)["time"]["duration"].as_float(), Some(0.02));
    assert_eq!(summary(&out)["steps"], 21);
}

#[test]
fn a_bad_setting_is_one_line_naming_the_key_and_writes_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let walk = example("hexapod_walk.toml");
    let robot = example("robots/lab_hexapod_stand.toml");
    let cases: [(&[&str], &str); 5] = [
        (&["run", "--set", "time"], "expected KEY=VALUE"),
        (&["run", "--set", "time.dtt=0.1"], "override `time.dtt`"),
        (
            &["run", &walk, "--set", "control.kind=gaitt"],
            "override `control.kind`",
        ),
        (&["run", &walk, "--set", "time.dt=-1"], "time.dt"),
        (
            &["run", &robot, "--set", "time.duraton=0.1"],
            "override `time.duraton`",
        ),
    ];
    for (i, (args, want)) in cases.iter().enumerate() {
        let out = tmp.path().join(format!("bad{i}"));
        let mut args = args.to_vec();
        args.extend(["--out", s(&out)]);
        let o = fbd(&args);
        assert_eq!(o.status.code(), Some(2), "{args:?}");
        let e = stderr(&o);
        assert_eq!(e.lines().count(), 1, "{e:?}");
        assert!(
            e.starts_with("error: ") && e.contains(want),
            "{args:?}: {e}"
        );
        // A line of the robot's re-written text is no line of its file.
        let at_line = e
            .match_indices(".toml:")
            .any(|(i, m)| e[i + m.len()..].starts_with(|c: char| c.is_ascii_digit()));
        assert!(!at_line, "{e}");
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
    }
}

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

/// `fbd run [CONFIG] --set S…  --out DIR`, which must succeed.
fn run_ok(config: Option<&str>, sets: &[&str], out: &std::path::Path) {
    let mut args = vec!["run"];
    args.extend(config);
    for set in sets {
        args.extend(["--set", set]);
    }
    args.extend(["--out", s(out)]);
    let o = fbd(&args);
    assert!(o.status.success(), "{args:?}: {}", stderr(&o));
}

#[test]
fn set_changes_the_default_and_its_written_configuration_repeats_the_run() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("a");
    run_ok(None, &["time.duration=0.3", "time.dt = 0.005"], &out);
    let c = config(&out);
    assert_eq!(c["time"]["dt"].as_float(), Some(0.005));
    assert_eq!(c["time"]["duration"].as_float(), Some(0.3));
    // 0.3 s at 5 ms: steps 0..=60.
    assert_eq!(summary(&out)["steps"], 61);
    // The later of two settings of one key wins.
    let twice = tmp.path().join("twice");
    run_ok(None, &["time.duration=1", "time.duration=0.2"], &twice);
    assert_eq!(config(&twice)["time"]["duration"].as_float(), Some(0.2));
    // The written configuration repeats the run, byte for byte.
    let again = tmp.path().join("b");
    run_ok(Some(s(&out.join("config.toml"))), &[], &again);
    let read = |d: &std::path::Path| std::fs::read(d.join("trajectory.csv")).unwrap();
    assert_eq!(read(&out), read(&again));
}

#[test]
fn set_changes_a_hexapod_and_a_robot_configuration() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("walk");
    let walk = example("hexapod_walk.toml");
    run_ok(Some(&walk), &["time.dt=0.0005", "time.duration=0.05"], &out);
    let sm = summary(&out);
    assert_eq!(sm["dt"], 0.0005);
    assert_eq!(sm["steps"], 101);
    let out = tmp.path().join("robot");
    let robot = example("robots/lab_hexapod_stand.toml");
    run_ok(Some(&robot), &["time.duration=0.02"], &out);
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

//! A run into a directory that holds an earlier run's files leaves no file
//! of that run behind looking current: `torques.svg` of an actuated run,
//! the planar plots after a hexapod run, the hexapod's plots after a planar
//! run.

mod common;

use common::{example, fbd, s, stdout};

fn names(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

fn sorted(files: &[&str]) -> Vec<String> {
    let mut v: Vec<String> = files.iter().map(|f| f.to_string()).collect();
    v.sort();
    v
}

#[test]
fn each_run_leaves_exactly_its_own_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let planar = fbd_cli::output::FILES;
    let hexapod = fbd_cli::hexapod::FILES;

    // An actuated run writes torques.svg too, and lists it.
    let o = fbd(&["run", &example("squat.toml"), "--out", s(&out)]);
    assert!(o.status.success(), "{o:?}");
    let mut with_torques = planar.to_vec();
    with_torques.push("torques.svg");
    assert_eq!(names(&out), sorted(&with_torques));
    assert!(stdout(&o).contains("torques.svg"), "{}", stdout(&o));

    // The passive default: the earlier torques.svg is gone.
    let o = fbd(&["run", "--out", s(&out)]);
    assert!(o.status.success(), "{o:?}");
    assert_eq!(names(&out), sorted(&planar));
    assert!(!stdout(&o).contains("torques.svg"), "{}", stdout(&o));

    // A hexapod run: no planar plot is left.
    let o = fbd(&["run", &example("hexapod_pose.toml"), "--out", s(&out)]);
    assert!(o.status.success(), "{o:?}");
    assert_eq!(names(&out), sorted(&hexapod));

    // And back: no hexapod plot is left.
    let o = fbd(&["run", "--out", s(&out)]);
    assert!(o.status.success(), "{o:?}");
    assert_eq!(names(&out), sorted(&planar));
}

#[test]
fn a_configuration_error_keeps_the_earlier_files() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    let o = fbd(&["run", &example("squat.toml"), "--out", s(&out)]);
    assert!(o.status.success(), "{o:?}");
    let before = names(&out);
    let bad = common::write(dir.path(), "bad.toml", "[time]\ndtt = 0.01\n");
    let o = fbd(&["run", s(&bad), "--out", s(&out)]);
    assert_eq!(o.status.code(), Some(2), "{o:?}");
    assert_eq!(
        names(&out),
        before,
        "a failed load must not touch the files"
    );
}

#[test]
fn a_smaller_sweep_removes_the_runs_of_a_larger_one() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("sweep");
    let sweep = |values: &str| {
        let f = common::write(
            dir.path(),
            "s.toml",
            &format!(
                "mode = \"grid\"\n[vary]\n\"time.duration\" = {values}\n\"time.dt\" = [0.01]\n"
            ),
        );
        let o = fbd(&["sweep", s(&f), "--out", s(&out), "--jobs", "1"]);
        assert!(o.status.success(), "{o:?}");
    };
    sweep("[0.05, 0.06, 0.07]");
    let runs = out.join("runs");
    assert_eq!(names(&runs), ["0", "1", "2"]);
    sweep("[0.05]");
    assert_eq!(names(&runs), ["0"], "runs of the earlier sweep left");
    let index = std::fs::read_to_string(out.join("index.csv")).unwrap();
    assert_eq!(index.lines().count(), 2, "{index}");
}

//! End-to-end tests of `fbd sweep` and `fbd sweep merge` (the real binary,
//! short runs in temporary directories).

use std::collections::BTreeSet;
mod common;

use common::{examples, fbd, s};
use std::path::{Path, PathBuf};
use std::process::Output;

fn text(o: &Output) -> String {
    format!(
        "stdout: {}\nstderr: {}",
        String::from_utf8_lossy(&o.stdout),
        String::from_utf8_lossy(&o.stderr)
    )
}

/// A sweep file in `dir` with the paper's base and `body` after it.
fn sweep_file(dir: &Path, name: &str, body: &str) -> PathBuf {
    let base = examples().join("paper.toml");
    let p = dir.join(name);
    std::fs::write(
        &p,
        format!("base = {:?}\n{body}", base.display().to_string()),
    )
    .unwrap();
    p
}

/// index.csv as (header, rows).
fn index(dir: &Path) -> (Vec<String>, Vec<Vec<String>>) {
    let mut r = csv::Reader::from_path(dir.join("index.csv")).unwrap();
    let h = r.headers().unwrap().iter().map(str::to_owned).collect();
    let rows = r
        .records()
        .map(|x| x.unwrap().iter().map(str::to_owned).collect())
        .collect();
    (h, rows)
}

fn runs_of(dir: &Path) -> BTreeSet<usize> {
    index(dir).1.iter().map(|r| r[0].parse().unwrap()).collect()
}

fn run_ok(args: &[&str]) -> Output {
    let o = fbd(args);
    assert!(o.status.success(), "{args:?}: {}", text(&o));
    o
}

const SHORT_GRID: &str = r#"mode = "grid"
[vary]
"time.duration" = [0.2, 0.3]
"terrain.mu_static" = [0.3, 0.5, 0.7]
"#;

#[test]
fn grid_size_columns_and_files() {
    let t = tempfile::tempdir().unwrap();
    let f = sweep_file(t.path(), "g.toml", SHORT_GRID);
    let out = t.path().join("out");
    run_ok(&["sweep", s(&f), "--out", s(&out), "--jobs", "2"]);
    let (h, rows) = index(&out);
    assert_eq!(
        h.join(","),
        "run,status,time.duration,terrain.mu_static,touchdown3,touchdown4,slip3,slip4,\
         peak_n3,peak_n4,peak_fa3,peak_fa4,peak_joint_force,steps,wall_seconds,error"
    );
    assert_eq!(rows.len(), 6);
    // First key slowest.
    let vals: Vec<(String, String)> = rows.iter().map(|r| (r[2].clone(), r[3].clone())).collect();
    assert_eq!(vals[0], ("0.2".into(), "0.3".into()));
    assert_eq!(vals[1], ("0.2".into(), "0.5".into()));
    assert_eq!(vals[3], ("0.3".into(), "0.3".into()));
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r[0], i.to_string());
        assert_eq!(r[1], "ok", "{r:?}");
        let d = out.join("runs").join(i.to_string());
        for f in [
            "trajectory.csv",
            "events.csv",
            "summary.json",
            "config.toml",
        ] {
            assert!(d.join(f).is_file(), "{}", d.join(f).display());
        }
        // The viewer and the plots only with --viewer, --plots.
        for f in ["tips.svg", "forces.svg", "stance.svg", "viewer.html"] {
            assert!(!d.join(f).exists(), "{}", d.join(f).display());
        }
        let cfg = std::fs::read_to_string(d.join("config.toml")).unwrap();
        assert!(cfg.contains(&format!("mu_static = {}", r[3])), "{cfg}");
    }
    assert!(out.join("sweep.svg").is_file());
    let j: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("sweep.json")).unwrap()).unwrap();
    assert_eq!(j["total_runs"], 6);
}

#[test]
fn zip_size_and_array_values() {
    let t = tempfile::tempdir().unwrap();
    let f = sweep_file(
        t.path(),
        "z.toml",
        r#"mode = "zip"
[vary]
"time.duration" = [0.2, 0.2, 0.3]
"initial.position" = [[0.0, 0.6], [0.0, 0.65], [0.0, 0.7]]
"#,
    );
    let out = t.path().join("out");
    run_ok(&["sweep", s(&f), "--out", s(&out), "--plot", "steps"]);
    let (_, rows) = index(&out);
    assert_eq!(rows.len(), 3);
    assert_eq!(rows[1][3], "[0.0, 0.65]");
    assert_eq!(rows[2][13], "31");
    let raw = std::fs::read_to_string(out.join("index.csv")).unwrap();
    assert!(raw.contains("\"[0.0, 0.65]\""), "{raw}");
    // Unequal lengths: an error before anything runs.
    let bad = sweep_file(
        t.path(),
        "bad.toml",
        "mode = \"zip\"\n[vary]\n\"time.duration\" = [0.2]\n\"terrain.mu_static\" = [0.3, 0.4]\n",
    );
    let o = fbd(&["sweep", s(&bad), "--out", s(&t.path().join("bad"))]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(!t.path().join("bad").exists());
}

#[test]
fn unknown_key_or_wrong_type_fails_up_front_naming_run_and_key() {
    let t = tempfile::tempdir().unwrap();
    for (body, key) in [
        (
            "[vary]\n\"terrain.mu_statc\" = [0.3, 0.4]\n",
            "terrain.mu_statc",
        ),
        (
            "[vary]\n\"terrain.mu_static\" = [0.4, \"high\"]\n",
            "terrain.mu_static",
        ),
        // mu_static < mu_dynamic (0.3) only in run 1.
        ("[vary]\n\"terrain.mu_static\" = [0.4, 0.2]\n", "run 1"),
    ] {
        let f = sweep_file(t.path(), "u.toml", body);
        let out = t.path().join("u");
        let o = fbd(&["sweep", s(&f), "--out", s(&out)]);
        assert_eq!(o.status.code(), Some(2), "{}", text(&o));
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(e.contains(key) && e.contains("run "), "{e}");
        assert!(!out.exists(), "nothing may run");
    }
}

#[test]
fn a_sweep_too_large_to_plan_is_a_one_line_error() {
    // A grid of five 200-value lists (3.2e11 runs) and samples = 1e9 asked
    // for more memory than the machine has and aborted; samples = 0 ran
    // nothing and exited 0.
    let t = tempfile::tempdir().unwrap();
    let list = |x0: f64| {
        let v: Vec<String> = (0..200)
            .map(|i| format!("{}", x0 + 0.001 * f64::from(i)))
            .collect();
        format!("[{}]", v.join(", "))
    };
    let grid = format!(
        "mode = \"grid\"\n[vary]\n\"terrain.mu_static\" = {}\n\"time.duration\" = {}\n\"initial.position\" = [[0.0, 0.5]]\n\"world.gravity\" = {}\n\"body.mass\" = {}\n\"leg.upper_mass\" = {}\n",
        list(0.3),
        list(0.2),
        list(9.0),
        list(5.0),
        list(0.5)
    );
    for (body, needles) in [
        (
            grid.as_str(),
            vec![
                "mode = \"grid\" of 200 × 200 × 1 × 200 × 200 × 200 values",
                "(1000000)",
            ],
        ),
        (
            "mode = \"random\"\nsamples = 1000000000\n[vary]\n\"terrain.mu_static\" = { min = 0.3, max = 0.8 }\n",
            vec!["samples = 1000000000: more runs than one sweep file may plan"],
        ),
        (
            "mode = \"random\"\nsamples = 0\n[vary]\n\"terrain.mu_static\" = { min = 0.3, max = 0.8 }\n",
            vec!["samples = 0: mode = \"random\" needs at least 1"],
        ),
    ] {
        let f = sweep_file(t.path(), "big.toml", body);
        let out = t.path().join("big");
        let o = fbd(&["sweep", s(&f), "--out", s(&out)]);
        assert_eq!(o.status.code(), Some(2), "{}", text(&o));
        let e = String::from_utf8_lossy(&o.stderr);
        assert_eq!(e.lines().count(), 1, "{e}");
        for n in needles {
            assert!(e.contains(n), "{n:?} not in {e}");
        }
        assert!(!out.exists(), "nothing may run");
    }
    // One run past the cap (a grid of 1000 × 1001, whose size is known
    // before anything is planned) is refused.
    let values = |n: usize| {
        let v: Vec<String> = (0..n)
            .map(|i| format!("{}", 0.2 + 1e-6 * i as f64))
            .collect();
        format!("[{}]", v.join(", "))
    };
    let f = sweep_file(
        t.path(),
        "cap.toml",
        &format!(
            "mode = \"grid\"\n[vary]\n\"terrain.mu_static\" = {}\n\"time.duration\" = {}\n",
            values(1000),
            values(1001)
        ),
    );
    let o = fbd(&["sweep", s(&f), "--out", s(&t.path().join("cap"))]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    assert!(
        String::from_utf8_lossy(&o.stderr).contains("1000 × 1001 values"),
        "{}",
        text(&o)
    );
}

#[test]
fn a_sweep_file_error_is_said_as_a_configuration_error() {
    // The loader's wording (the key, a whole number, a close key), not
    // serde's Rust types.
    let t = tempfile::tempdir().unwrap();
    for (body, needles) in [
        (
            "mode = \"random\"\nsamples = -3\n[vary]\n\"terrain.mu_static\" = { min = 0.3, max = 0.8 }\n",
            vec![":3:11: samples: invalid value: integer `-3`, expected a whole number"],
        ),
        (
            "mod = \"grid\"\n[vary]\n\"terrain.mu_static\" = [0.3]\n",
            vec![":2:1: unknown field `mod`, did you mean `mode`?"],
        ),
    ] {
        let f = sweep_file(t.path(), "e.toml", body);
        let o = fbd(&["sweep", s(&f), "--out", s(&t.path().join("e"))]);
        assert_eq!(o.status.code(), Some(2), "{}", text(&o));
        let e = String::from_utf8_lossy(&o.stderr);
        for n in needles {
            assert!(e.contains(n) && !e.contains("usize"), "{n:?} not in {e}");
        }
    }
}

#[test]
fn random_is_reproducible_by_seed() {
    let t = tempfile::tempdir().unwrap();
    let body = |seed: u64| {
        format!(
            "mode = \"random\"\nsamples = 4\nseed = {seed}\n[vary]\n\"time.duration\" = {{ min = 0.1, max = 0.2 }}\n\"terrain.mu_static\" = {{ min = 0.3, max = 0.8 }}\n"
        )
    };
    let mut cols = Vec::new();
    for (name, seed) in [("a", 1), ("b", 1), ("c", 2)] {
        let f = sweep_file(t.path(), &format!("{name}.toml"), &body(seed));
        let out = t.path().join(name);
        run_ok(&["sweep", s(&f), "--out", s(&out)]);
        let (_, rows) = index(&out);
        assert_eq!(rows.len(), 4);
        for r in &rows {
            let d: f64 = r[2].parse().unwrap();
            let m: f64 = r[3].parse().unwrap();
            assert!(
                (0.1..=0.2).contains(&d) && (0.3..=0.8).contains(&m),
                "{r:?}"
            );
        }
        cols.push(
            rows.iter()
                .map(|r| (r[2].clone(), r[3].clone()))
                .collect::<Vec<_>>(),
        );
    }
    assert_eq!(cols[0], cols[1]);
    assert_ne!(cols[0], cols[2]);
}

/// Every file of a run directory except summary.json byte-identical;
/// summary.json identical but for the timings.
fn assert_same_run(a: &Path, b: &Path) {
    for f in [
        "trajectory.csv",
        "events.csv",
        "config.toml",
        "tips.svg",
        "forces.svg",
        "stance.svg",
    ] {
        // (the plots only where the sweep was asked for them: in both or
        // in neither)
        assert_eq!(a.join(f).exists(), b.join(f).exists(), "{f}");
        if !a.join(f).exists() && f.ends_with(".svg") {
            continue;
        }
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(b.join(f)).unwrap(),
            "{} vs {}",
            a.join(f).display(),
            b.join(f).display()
        );
    }
    let strip = |p: &Path| {
        let mut j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(p.join("summary.json")).unwrap())
                .unwrap();
        j["wall_seconds"] = serde_json::Value::Null;
        j["steps_per_second"] = serde_json::Value::Null;
        j["stability_check_seconds"] = serde_json::Value::Null;
        j
    };
    assert_eq!(strip(a), strip(b));
}

#[test]
fn jobs_1_and_2_give_identical_runs_equal_to_fbd_run() {
    let t = tempfile::tempdir().unwrap();
    let f = sweep_file(t.path(), "g.toml", SHORT_GRID);
    let (o1, o2) = (t.path().join("j1"), t.path().join("j2"));
    run_ok(&["sweep", s(&f), "--out", s(&o1), "--jobs", "1"]);
    run_ok(&["sweep", s(&f), "--out", s(&o2), "--jobs", "2"]);
    let strip_wall = |d: &Path| -> Vec<Vec<String>> {
        index(d)
            .1
            .into_iter()
            .map(|mut r| {
                r[14].clear();
                r
            })
            .collect()
    };
    assert_eq!(strip_wall(&o1), strip_wall(&o2));
    for i in 0..6 {
        let (a, b) = (o1.join(format!("runs/{i}")), o2.join(format!("runs/{i}")));
        assert_same_run(&a, &b);
        let alone = t.path().join(format!("alone{i}"));
        run_ok(&["run", s(&a.join("config.toml")), "--out", s(&alone)]);
        assert_same_run(&a, &alone);
    }
}

#[test]
fn a_failing_run_is_isolated() {
    let t = tempfile::tempdir().unwrap();
    // The reference failing experiment stops at step 26; stopped earlier,
    // it does not fail.
    std::fs::write(t.path().join("fail.toml"), common::FAILS).unwrap();
    let f = t.path().join("f.toml");
    std::fs::write(
        &f,
        "base = \"fail.toml\"\nmode = \"zip\"\n[vary]\n\"time.duration\" = [0.1, 1.0, 0.2]\n",
    )
    .unwrap();
    let out = t.path().join("out");
    let o = fbd(&["sweep", s(&f), "--out", s(&out), "--jobs", "2"]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    assert!(String::from_utf8_lossy(&o.stderr).contains("1 of 3 runs failed"));
    let (head, rows) = index(&out);
    let error = head.iter().position(|h| h == "error").unwrap();
    assert_eq!(rows.len(), 3);
    assert_eq!(rows[0][1], "ok");
    assert_eq!(rows[2][1], "ok");
    assert_eq!(rows[1][1], "error");
    assert!(!rows[1][error].is_empty(), "{:?}", rows[1]);
    assert!(
        rows[1][error].contains(&common::fail_prefix()),
        "{:?}",
        rows[1]
    );
    let sum = std::fs::read_to_string(out.join("runs/1/summary.json")).unwrap();
    assert!(sum.contains("\"status\": \"error\""));
}

#[test]
fn resume_reruns_only_missing_runs() {
    let t = tempfile::tempdir().unwrap();
    let f = sweep_file(t.path(), "g.toml", SHORT_GRID);
    let out = t.path().join("out");
    run_ok(&["sweep", s(&f), "--out", s(&out), "--jobs", "2"]);
    let mtime = |i: usize| {
        std::fs::metadata(out.join(format!("runs/{i}/trajectory.csv")))
            .unwrap()
            .modified()
            .unwrap()
    };
    let before: Vec<_> = (0..6).map(mtime).collect();
    std::fs::remove_dir_all(out.join("runs/4")).unwrap();
    // A half-written run (no .done marker) is not taken as finished.
    std::fs::remove_file(out.join("runs/2/.done")).unwrap();
    let o = run_ok(&["sweep", s(&f), "--out", s(&out), "--resume"]);
    let so = String::from_utf8_lossy(&o.stdout);
    assert!(so.contains("ran 2, skipped 4"), "{so}");
    for i in [0, 1, 3, 5] {
        assert_eq!(mtime(i), before[i], "run {i} was rerun");
    }
    assert_eq!(runs_of(&out), (0..6).collect());
    assert!(out.join("runs/4/.done").is_file());
    // A changed definition reruns the runs whose configuration changed.
    let f2 = sweep_file(t.path(), "g2.toml", &SHORT_GRID.replace("0.7]", "0.75]"));
    let o = run_ok(&["sweep", s(&f2), "--out", s(&out), "--resume"]);
    let so = String::from_utf8_lossy(&o.stdout);
    assert!(so.contains("ran 2, skipped 4"), "{so}");
    assert_eq!(index(&out).1[5][3], "0.75");
}

#[test]
fn shards_partition_and_merge() {
    let t = tempfile::tempdir().unwrap();
    let f = sweep_file(t.path(), "g.toml", SHORT_GRID);
    let mut sets = Vec::new();
    let mut dirs = Vec::new();
    for i in 0..4 {
        let d = t.path().join(format!("shard{i}"));
        run_ok(&["sweep", s(&f), "--out", s(&d), "--shard", &format!("{i}/4")]);
        let runs = runs_of(&d);
        assert!(runs.iter().all(|r| r % 4 == i), "{runs:?}");
        sets.push(runs);
        dirs.push(d);
    }
    let union: BTreeSet<usize> = sets.iter().flatten().copied().collect();
    assert_eq!(union, (0..6).collect());
    assert_eq!(sets.iter().map(BTreeSet::len).sum::<usize>(), 6, "disjoint");

    let merged = t.path().join("merged");
    let mut args = vec!["sweep", "merge"];
    args.extend(dirs.iter().map(|d| s(d)));
    args.extend(["--out", s(&merged)]);
    let o = run_ok(&args);
    assert!(String::from_utf8_lossy(&o.stdout).contains("merged 6 of 6 runs"));
    let whole = t.path().join("whole");
    run_ok(&["sweep", s(&f), "--out", s(&whole)]);
    for i in 0..6 {
        assert_same_run(
            &merged.join(format!("runs/{i}")),
            &whole.join(format!("runs/{i}")),
        );
    }
    assert_eq!(index(&merged).1.len(), 6);
    assert!(merged.join("sweep.svg").is_file());

    // A missing shard is reported (exit 3) with the missing indices.
    let partial = t.path().join("partial");
    let o = fbd(&[
        "sweep",
        "merge",
        s(&dirs[0]),
        s(&dirs[1]),
        "--out",
        s(&partial),
    ]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("2 of 6 runs missing: 2, 3"), "{e}");
    assert_eq!(runs_of(&partial), [0, 1, 4, 5].into_iter().collect());
}

#[test]
fn bad_arguments_are_usage_errors() {
    let t = tempfile::tempdir().unwrap();
    let f = sweep_file(t.path(), "g.toml", SHORT_GRID);
    for extra in [
        vec!["--shard", "4/4"],
        vec!["--shard", "x"],
        vec!["--jobs", "0"],
        vec!["--plot", "nope"],
    ] {
        let mut args = vec!["sweep", s(&f), "--out", "unused"];
        args.extend(extra.iter().copied());
        let o = fbd(&args);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {}", text(&o));
    }
}

#[test]
fn counts_agree_with_their_nouns() {
    let t = tempfile::tempdir().unwrap();
    let f = sweep_file(t.path(), "one.toml", "[vary]\n\"time.duration\" = [0.2]\n");
    let out = t.path().join("one");
    let o = run_ok(&["sweep", s(&f), "--out", s(&out)]);
    let so = String::from_utf8_lossy(&o.stdout);
    assert!(so.starts_with("sweep: 1 run; ran 1,"), "{so}");
    let merged = t.path().join("merged");
    let o = run_ok(&["sweep", "merge", s(&out), "--out", s(&merged)]);
    let so = String::from_utf8_lossy(&o.stdout);
    assert!(
        so.contains(&format!(
            "merged 1 of 1 run from 1 directory into {}",
            merged.display()
        )),
        "{so}"
    );
    // One failure among one run: "1 of 1 run failed (run 0)".
    std::fs::write(t.path().join("fail.toml"), common::FAILS).unwrap();
    let f = t.path().join("f.toml");
    std::fs::write(
        &f,
        "base = \"fail.toml\"\n[vary]\n\"time.duration\" = [1.0]\n",
    )
    .unwrap();
    let o = fbd(&["sweep", s(&f), "--out", s(&t.path().join("f"))]);
    assert_eq!(o.status.code(), Some(3), "{}", text(&o));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(e.contains("1 of 1 run failed (run 0)"), "{e}");
}

/// A sweep of the hexapod's 3D dynamics: the standing example, 0.2 s (the
/// feet touch down at 0.1 s), friction × PD stiffness.
#[test]
fn a_dynamic_hexapod_sweep_runs_the_dynamics_with_its_columns() {
    let t = tempfile::tempdir().unwrap();
    let stand = std::fs::read_to_string(examples().join("hexapod_stand.toml")).unwrap();
    assert!(stand.contains("\nduration = 1.0\n"));
    let base = stand.replace("\nduration = 1.0\n", "\nduration = 0.2\n");
    std::fs::write(t.path().join("stand.toml"), base).unwrap();
    let f = t.path().join("s.toml");
    // μS = 0.1 is below the stance's |Ft|/N = 0.13: the feet slip.
    std::fs::write(
        &f,
        r#"base = "stand.toml"
mode = "grid"
[vary]
"terrain.mu_static" = [0.1, 0.8]
"control.kp" = [200.0, 300.0]
[derive]
"terrain.mu_dynamic" = { from = "terrain.mu_static", scale = 0.75 }
"#,
    )
    .unwrap();
    let out = t.path().join("out");
    run_ok(&["sweep", s(&f), "--out", s(&out), "--jobs", "2"]);
    let (h, rows) = index(&out);
    assert_eq!(
        h.join(","),
        "run,status,terrain.mu_static,control.kp,terrain.mu_dynamic,distance,final_height,\
         peak_torque,peak_foot_n,first_touchdown,foot_slips,events,newton_iterations,\
         steps_per_second,steps,wall_seconds,max_law_violation,retried_steps,substeps,error"
    );
    assert_eq!(rows.len(), 4);
    let col = |r: &[String], name: &str| -> String {
        r[h.iter().position(|c| c == name).unwrap()].clone()
    };
    let num = |r: &[String], name: &str| -> f64 { col(r, name).parse().unwrap() };
    let weight = 18.4 * 9.81;
    for (i, r) in rows.iter().enumerate() {
        assert_eq!(r[1], "ok", "{r:?}");
        let d = out.join("runs").join(i.to_string());
        // The files of a dynamic run, not of the kinematic gait (its plots
        // only with --plots).
        assert!(d.join("trajectory.csv").is_file());
        for f in ["feet.svg", "torques.svg", "body.svg"] {
            assert!(!d.join(f).exists(), "{}", d.join(f).display());
        }
        assert!(!d.join("gait.svg").exists());
        let j: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("summary.json")).unwrap())
                .unwrap();
        assert_eq!(j["run"], "dynamic");
        assert_eq!(col(r, "steps"), "201");
        assert_eq!(col(r, "steps"), j["steps"].to_string());
        assert_eq!(
            num(r, "newton_iterations"),
            j["newton_iterations"].as_f64().unwrap()
        );
        assert_eq!(num(r, "distance"), j["distance"].as_f64().unwrap());
        assert_eq!(num(r, "final_height"), j["final_height"].as_f64().unwrap());
        assert_eq!(
            num(r, "peak_torque"),
            j["peak_torque_max"].as_f64().unwrap()
        );
        let events = j["events"].as_array().unwrap();
        assert_eq!(num(r, "events"), events.len() as f64);
        // The run's audit of every step, as summary.json counts it.
        for c in ["max_law_violation", "retried_steps", "substeps"] {
            assert_eq!(num(r, c), j[c].as_f64().unwrap(), "{c}");
        }
        assert!(num(r, "max_law_violation") < 1e-6 * weight, "{r:?}");
        assert!(num(r, "steps_per_second") > 0.0);
        // Touchdown of the six feet together after the 5 cm drop,
        // √(2·0.05/g) = 0.101 s: the step from 0.1 s puts them down.
        assert_eq!(num(r, "first_touchdown"), 0.1, "{r:?}");
        // Standing, the feet carry the weight: the impact's peak is above
        // a sixth of it; the body stays up (touchdown height 0.3516 m).
        assert!(num(r, "peak_foot_n") > weight / 6.0, "{r:?}");
        let y = num(r, "final_height");
        assert!((0.33..0.36).contains(&y), "{r:?}");
        // No sideways push: the body does not travel.
        assert!(num(r, "distance") < 1e-6, "{r:?}");
        // The feet slip on μS = 0.1 (each foot at least once), never on 0.8.
        let slips = num(r, "foot_slips");
        let counted = events
            .iter()
            .filter(|e| e["point"] == "tip" && e["to"] == "ST3" && e["from"] != "ST3")
            .count() as f64;
        assert_eq!(slips, counted);
        if col(r, "terrain.mu_static") == "0.1" {
            assert!(slips >= 6.0, "{r:?}");
        } else {
            assert_eq!(slips, 0.0, "{r:?}");
        }
    }
    // Same run alone: the same files (the dynamics, not the gait).
    let a = out.join("runs/1");
    let alone = t.path().join("alone");
    run_ok(&["run", s(&a.join("config.toml")), "--out", s(&alone)]);
    for f in ["trajectory.csv", "events.csv", "config.toml"] {
        assert_eq!(
            std::fs::read(a.join(f)).unwrap(),
            std::fs::read(alone.join(f)).unwrap(),
            "{f}"
        );
    }
    // merge reads the dynamic index back with its columns.
    let merged = t.path().join("merged");
    run_ok(&["sweep", "merge", s(&out), "--out", s(&merged)]);
    assert_eq!(index(&merged).0, h);
    assert_eq!(index(&merged).1.len(), 4);
    // An invalid run of a dynamic base fails up front, naming run and key.
    std::fs::write(
        &f,
        "base = \"stand.toml\"\n[vary]\n\"control.kp\" = [300.0, -1.0]\n",
    )
    .unwrap();
    let o = fbd(&["sweep", s(&f), "--out", s(&t.path().join("bad"))]);
    assert_eq!(o.status.code(), Some(2), "{}", text(&o));
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("run 1 (control.kp = -1.0)") && e.contains("kp"),
        "{e}"
    );
}

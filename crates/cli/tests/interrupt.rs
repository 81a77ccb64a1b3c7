//! SIGINT and SIGTERM during `fbd run` and `fbd sweep`: the stepping loop
//! stops, the steps computed so far and every file are written,
//! `summary.json` says `"interrupted"`, no temporary file is left, and the
//! exit status is 130.

mod common;

use std::path::Path;
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::{s, write};
use fbd_cli::output::FILES;

/// The built-in experiment run for a very long time (it is at rest from
/// 0.78 s): 10⁷ steps, far more than a test waits for.
const LONG: &str = "[time]\nduration = 100000.0\n[output]\nstride = 1000\n";

fn spawn(args: &[&str]) -> Child {
    Command::new(env!("CARGO_BIN_EXE_fbd"))
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("the fbd binary starts")
}

/// Waits until `ready` holds (the run is stepping), then sends `signal`.
fn signal_when(child: &Child, signal: &str, ready: impl Fn() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the run never started"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    // Let it solve some steps.
    std::thread::sleep(Duration::from_millis(300));
    let ok = Command::new("kill")
        .args([format!("-{signal}"), child.id().to_string()])
        .status()
        .expect("kill runs")
        .success();
    assert!(ok, "kill -{signal} failed");
}

fn wait(child: Child) -> Output {
    // A stopped run finishes its files in well under a minute; a run that
    // ignored the signal would go on for hours, so bound the wait.
    let id = child.id();
    let done = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
    let flag = done.clone();
    std::thread::spawn(move || {
        std::thread::sleep(Duration::from_secs(120));
        if !flag.load(std::sync::atomic::Ordering::SeqCst) {
            let _ = Command::new("kill")
                .args(["-KILL", &id.to_string()])
                .status();
        }
    });
    let o = child.wait_with_output().unwrap();
    done.store(true, std::sync::atomic::Ordering::SeqCst);
    o
}

fn temporaries(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect()
}

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

/// Checks an interrupted run directory; returns the steps solved.
fn check_interrupted_run(out: &Path) -> u64 {
    for f in FILES {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    assert!(temporaries(out).is_empty(), "{:?}", temporaries(out));
    let summary = json(&out.join("summary.json"));
    assert_eq!(summary["status"], "interrupted", "{summary}");
    assert!(summary["error"].as_str().unwrap().contains("interrupted"));
    let steps = summary["steps"].as_u64().unwrap();
    let planned = summary["steps_planned"].as_u64().unwrap();
    assert!(steps > 0 && steps < planned, "{steps} of {planned}");
    // Every written row is there, complete; the last one is before the
    // step the signal stopped.
    let text = std::fs::read_to_string(out.join("trajectory.csv")).unwrap();
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert_eq!(rows.len() as u64, summary["rows_written"].as_u64().unwrap());
    assert_eq!(rows.len() as u64, (steps - 1) / 1000 + 1);
    let header_cols = text.lines().next().unwrap().split(',').count();
    assert!(rows.iter().all(|r| r.split(',').count() == header_cols));
    let last_t: f64 = rows
        .last()
        .unwrap()
        .split(',')
        .next()
        .unwrap()
        .parse()
        .unwrap();
    assert!(last_t < steps as f64 * 0.01 + 1e-9, "{last_t}");
    // The configuration is complete: rerunning it is possible.
    assert!(out.join("config.toml").is_file());
    steps
}

fn run_and_signal(signal: &str) {
    let dir = tempfile::tempdir().unwrap();
    let cfg = write(dir.path(), "long.toml", LONG);
    let out = dir.path().join("out");
    // A previous, finished run in the same directory must not survive.
    std::fs::create_dir_all(&out).unwrap();
    std::fs::write(out.join("summary.json"), "{\"status\": \"ok\"}\n").unwrap();
    let child = spawn(&["run", s(&cfg), "--out", s(&out)]);
    let o = {
        let out = out.clone();
        signal_when(&child, signal, move || !temporaries(&out).is_empty());
        wait(child)
    };
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{stderr}");
    let last = stderr.lines().last().unwrap_or_default();
    assert!(
        last.starts_with("error: interrupted after ") && last.contains(s(&out)),
        "{stderr}"
    );
    check_interrupted_run(&out);
    assert!(String::from_utf8_lossy(&o.stdout).contains("stopped after"));
}

#[test]
fn sigint_stops_a_run_and_writes_everything() {
    run_and_signal("INT");
}

#[test]
fn sigterm_stops_a_run_and_writes_everything() {
    run_and_signal("TERM");
}

#[test]
fn sigint_stops_a_sweep_and_the_index_says_which_runs() {
    let dir = tempfile::tempdir().unwrap();
    write(dir.path(), "long.toml", LONG);
    let sweep = write(
        dir.path(),
        "sweep.toml",
        "base = \"long.toml\"\n[vary]\n\"terrain.mu_static\" = [0.4, 0.5, 0.6]\n",
    );
    let out = dir.path().join("sweep");
    let child = spawn(&[
        "sweep",
        s(&sweep),
        "--out",
        s(&out),
        "--jobs",
        "1",
        "--viewer",
        "--plots",
    ]);
    let run0 = out.join("runs/0");
    let o = {
        let run0 = run0.clone();
        signal_when(&child, "INT", move || {
            run0.is_dir() && !temporaries(&run0).is_empty()
        });
        wait(child)
    };
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(130), "{stderr}");
    assert!(stderr.contains("`--resume` continues"), "{stderr}");
    check_interrupted_run(&run0);
    // Runs 1 and 2 never started.
    assert!(!out.join("runs/1").exists() && !out.join("runs/2").exists());
    let index = std::fs::read_to_string(out.join("index.csv")).unwrap();
    let rows: Vec<&str> = index.lines().skip(1).collect();
    assert_eq!(rows.len(), 1, "{index}");
    assert!(rows[0].starts_with("0,interrupted,"), "{index}");
    assert!(temporaries(&out).is_empty());
}

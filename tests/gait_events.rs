//! The duty factor and the phases read back from `events.csv` of
//! `fbd run`: for every leg, touchdown − lift-off = (1 − β)·T, lift-offs
//! one period apart, and lift-off times modulo T equal the gait's phases.

use std::path::Path;

use fbd_sim::gait::GaitKind;

fn run(dir: &Path, gait: &str) -> String {
    let cfg = dir.join("c.toml");
    std::fs::write(
        &cfg,
        format!(
            "model = \"hexapod\"\n[time]\ndt = 0.01\nduration = 6.0\n[initial]\nposition = [0.0, 0.38, 0.0]\n[gait]\n{gait}\nperiod = 1.2\nforward_speed = 0.05\n"
        ),
    )
    .unwrap();
    let out = dir.join("out");
    let mut sink = Vec::new();
    fbd_cli::run::run_command(Some(&cfg), &out, &mut sink).unwrap();
    std::fs::read_to_string(out.join("events.csv")).unwrap()
}

fn check(csv: &str, duty: f64, phases: [f64; 6], period: f64) {
    let mut lift: [Vec<f64>; 6] = Default::default();
    let mut down: [Vec<f64>; 6] = Default::default();
    let mut lines = csv.lines();
    assert_eq!(lines.next(), Some("t,leg,event,margin"));
    for l in lines {
        let f: Vec<&str> = l.split(',').collect();
        let t: f64 = f[0].parse().unwrap();
        match f[2] {
            "liftoff" => lift[f[1].parse::<usize>().unwrap() - 1].push(t),
            "touchdown" => down[f[1].parse::<usize>().unwrap() - 1].push(t),
            _ => {}
        }
    }
    for leg in 0..6 {
        let (l, d) = (&lift[leg], &down[leg]);
        assert!(l.len() >= 3, "leg {}: {} lift-offs", leg + 1, l.len());
        assert_eq!(l.len(), d.len(), "leg {}: every swing lands", leg + 1);
        for (a, b) in l.iter().zip(d) {
            let beta = 1.0 - (b - a) / period;
            assert!((beta - duty).abs() < 1e-9, "leg {}: β = {beta}", leg + 1);
        }
        for w in l.windows(2) {
            assert!((w[1] - w[0] - period).abs() < 1e-9);
        }
        let phase = (l[0] / period).rem_euclid(1.0);
        assert!(
            (phase - phases[leg]).abs() < 1e-9,
            "leg {}: phase {phase} vs {}",
            leg + 1,
            phases[leg]
        );
    }
}

#[test]
fn presets_read_back() {
    for (name, kind) in [
        ("tripod", GaitKind::Tripod),
        ("ripple", GaitKind::Ripple),
        ("wave", GaitKind::Wave),
    ] {
        let dir = tempfile::tempdir().unwrap();
        let csv = run(dir.path(), &format!("kind = \"{name}\""));
        let (duty, phases) = kind.preset().unwrap();
        check(&csv, duty, phases, 1.2);
    }
}

#[test]
fn custom_reads_back() {
    let dir = tempfile::tempdir().unwrap();
    let phases = [0.1, 0.6, 0.35, 0.85, 0.2, 0.7];
    let csv = run(
        dir.path(),
        &format!("kind = \"custom\"\nduty_factor = 0.7\nphases = {phases:?}"),
    );
    check(&csv, 0.7, phases, 1.2);
}

//! The compiled LU (fbd-solver's default, `NewtonParams::compiled_lu`)
//! against faer's pivoting LU (the reference path) on whole runs: the
//! planar passive fall and moving flight of `bench/peer`, the hexapod
//! standing and walking, and the contact-rich landing of
//! `examples/hexapod_drop.toml` (six feet, then six hips). Each run is
//! solved twice, once per path: the events (contact states, joint limits,
//! retried steps) must be identical, and every row's coordinates and
//! forces equal to the Newton tolerance's round-off (the two paths sum the
//! same products in different orders).

use std::path::Path;

use fbd_scenario::Config;
use fbd_sim::spatial::{SpatialModel, run_collect as spatial_run};
use fbd_sim::{Model, run_collect as planar_run};

fn load(rel: &str) -> Config {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join(rel);
    fbd_scenario::load(&path).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

/// Largest `|a − b|` over two equally long sequences.
fn worst<'a>(a: impl Iterator<Item = &'a f64>, b: impl Iterator<Item = &'a f64>) -> f64 {
    a.zip(b).map(|(x, y)| (x - y).abs()).fold(0.0, f64::max)
}

fn spatial(rel: &str, duration: Option<f64>, q_tol: f64, force_tol: f64) {
    let Config::Hexapod(h) = load(rel) else {
        panic!("{rel} is a hexapod file")
    };
    let mut params = h.spatial_params(rel).expect("parameters");
    if let Some(d) = duration {
        params.duration = d;
    }
    let compiled = SpatialModel::new(&params).expect("model");
    assert!(
        compiled.newton.compiled_lu,
        "the compiled LU is the default"
    );
    let mut reference = compiled.clone();
    reference.newton.compiled_lu = false;
    let (a, sa) = spatial_run(&compiled);
    let (b, sb) = spatial_run(&reference);
    assert!(sa.error.is_none() && sb.error.is_none(), "{rel}: {sa:?}");
    assert_eq!(sa.steps, sb.steps, "{rel}");
    assert_eq!(sa.events, sb.events, "{rel}: contact events");
    assert_eq!(sa.limit_events, sb.limit_events, "{rel}: limit events");
    assert_eq!(sa.retries, sb.retries, "{rel}: retried steps");
    let (mut dq, mut df) = (0.0f64, 0.0f64);
    for (ra, rb) in a.iter().zip(&b) {
        dq = dq.max(worst(ra.q.iter(), rb.q.iter()));
        for (ca, cb) in ra.contacts.iter().zip(&rb.contacts) {
            assert_eq!(ca.state, cb.state, "{rel}: step {}", ra.step);
            df = df.max(worst(ca.force.iter(), cb.force.iter()));
        }
        // Every joint reaction (the hips' and knees').
        for (fa, fb) in ra.reaction_force.iter().zip(&rb.reaction_force) {
            df = df.max(worst(fa.iter(), fb.iter()));
        }
    }
    println!("{rel}: |Δq| ≤ {dq:.2e}, |ΔF| ≤ {df:.2e} N");
    assert!(dq <= q_tol, "{rel}: coordinates differ by {dq:e}");
    assert!(df <= force_tol, "{rel}: forces differ by {df:e} N");
}

fn planar(rel: &str, q_tol: f64, force_tol: f64) {
    let Config::Planar(p) = load(rel) else {
        panic!("{rel} is a planar file")
    };
    let compiled = Model::planar(&p.params()).expect("model");
    assert!(
        compiled.newton.compiled_lu,
        "the compiled LU is the default"
    );
    let mut reference = compiled.clone();
    reference.newton.compiled_lu = false;
    let (a, sa) = planar_run(&compiled);
    let (b, sb) = planar_run(&reference);
    assert!(sa.error.is_none() && sb.error.is_none(), "{rel}: {sa:?}");
    assert_eq!(sa.steps, sb.steps, "{rel}");
    assert_eq!(sa.events, sb.events, "{rel}: contact events");
    assert_eq!(sa.limit_events, sb.limit_events, "{rel}: limit events");
    assert_eq!(sa.retries, sb.retries, "{rel}: retried steps");
    let (mut dq, mut df) = (0.0f64, 0.0f64);
    for (ra, rb) in a.iter().zip(&b) {
        let states =
            |r: &fbd_sim::RobotRecord| r.contacts.iter().map(|c| c.state).collect::<Vec<_>>();
        assert_eq!(states(ra), states(rb), "{rel}: step {}", ra.step);
        dq = dq.max(worst(ra.q.iter(), rb.q.iter()));
        let fa = |r: &fbd_sim::RobotRecord| {
            r.contacts
                .iter()
                .map(|c| c.tangential[0])
                .collect::<Vec<_>>()
        };
        df = df.max(worst(fa(ra).iter(), fa(rb).iter()));
        let n = |r: &fbd_sim::RobotRecord| r.contacts.iter().map(|c| c.normal).collect::<Vec<_>>();
        df = df.max(worst(n(ra).iter(), n(rb).iter()));
    }
    println!("{rel}: |Δq| ≤ {dq:.2e}, |ΔF| ≤ {df:.2e} N");
    assert!(dq <= q_tol, "{rel}: coordinates differ by {dq:e}");
    assert!(df <= force_tol, "{rel}: forces differ by {df:e} N");
}

#[test]
fn planar_passive_fall_matches_faer() {
    planar("bench/peer/passive_fall.toml", 1e-8, 1e-4);
}

#[test]
fn planar_moving_flight_matches_faer() {
    // 2 s of the 100 s flight: the spinning flight is chaotic, a
    // round-off difference grows (2.7e-6 rad by 10 s).
    let Config::Planar(mut p) = load("bench/peer/moving_flight.toml") else {
        panic!("planar")
    };
    p.time.duration = 2.0;
    let compiled = Model::planar(&p.params()).expect("model");
    let mut reference = compiled.clone();
    reference.newton.compiled_lu = false;
    let (a, _) = planar_run(&compiled);
    let (b, _) = planar_run(&reference);
    let dq = a
        .iter()
        .zip(&b)
        .map(|(ra, rb)| worst(ra.q.iter(), rb.q.iter()))
        .fold(0.0, f64::max);
    println!("moving flight, 2 s: |Δq| ≤ {dq:.2e}");
    assert!(dq <= 5e-8, "coordinates differ by {dq:e}");
}

#[test]
fn hexapod_stand_matches_faer() {
    spatial("bench/peer/hexapod_stand.toml", Some(2.0), 1e-9, 1e-4);
}

#[test]
fn hexapod_walk_matches_faer() {
    spatial("bench/peer/hexapod_walk.toml", Some(2.0), 1e-8, 1e-3);
}

#[test]
fn hexapod_landing_matches_faer() {
    spatial("examples/hexapod_drop.toml", None, 1e-8, 1e-3);
}

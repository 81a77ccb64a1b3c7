//! Stage "run": a whole 10 s simulated run at Δt = 1 ms (10 001 steps) of
//! the default experiment's robot with no terrain, no output (`fbd_sim::run`
//! with an empty row callback).
//!
//! `cargo bench -p fbd-suite --bench run`

mod common;

use std::hint::black_box;
use std::time::Duration;

use common::Case;
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    let model = Case::Flight.model();
    assert_eq!(model.steps, 10_001);
    let summary = fbd_sim::run(&model, |_| {});
    assert!(summary.error.is_none(), "{:?}", summary.error);
    eprintln!(
        "run/flight_10s: {} steps, {} Newton iterations",
        summary.steps, summary.newton_iterations
    );
    c.bench_function("run/flight_10s", |b| {
        b.iter(|| {
            let s = fbd_sim::run(black_box(&model), |r| {
                black_box(r);
            });
            black_box(s.steps)
        })
    });
    // The whole default experiment (the paper's §6 fall), no output.
    let paper = fbd_sim::Model::planar(&fbd_sim::PlanarParams::default()).unwrap();
    c.bench_function("run/default_experiment", |b| {
        b.iter(|| {
            let s = fbd_sim::run(black_box(&paper), |r| {
                black_box(r);
            });
            assert!(s.error.is_none());
            black_box(s.steps)
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(10).measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    targets = bench
}
criterion_main!(benches);

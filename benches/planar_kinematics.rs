//! Stage "kinematics": positions and analytic point Jacobians of the planar
//! two-leg model (7 angles, 6 distinct, 11 points), as evaluated at every
//! Newton iterate: `planar_eval_positions` at an iterate next to the last
//! evaluation (the sines and cosines from their series, as at a step's
//! later iterates), `planar_eval_positions_new_step` alternating two
//! configurations 0.01 rad apart (every `sin_cos` evaluated, as at a
//! step's first iterate).
//!
//! `cargo bench -p fbd-suite --bench planar_kinematics`

use std::hint::black_box;
use std::time::Duration;

use criterion::{Criterion, criterion_group, criterion_main};
use fbd_kinematics::planar::{PlanarChains, PlanarGeometry};

fn bench(c: &mut Criterion) {
    let (chains, _) = PlanarChains::two_leg(&PlanarGeometry::default());
    let mut data = chains.new_data();
    let q = [
        0.01,
        0.6,
        0.02,
        0.05,
        245f64.to_radians(),
        -0.03,
        255f64.to_radians(),
    ];

    c.bench_function("planar_eval_positions", |b| {
        b.iter(|| chains.eval_positions(black_box(&q), &mut data))
    });
    let far = q.map(|v| v + 0.01);
    let mut flip = false;
    c.bench_function("planar_eval_positions_new_step", |b| {
        b.iter(|| {
            flip = !flip;
            let x = if flip { &far } else { &q };
            chains.eval_positions(black_box(x), &mut data)
        })
    });
    chains.eval_positions(&q, &mut data);
    c.bench_function("planar_eval_jacobians", |b| {
        b.iter(|| chains.eval_jacobians(black_box(&mut data)))
    });
    c.bench_function("planar_positions_and_jacobians", |b| {
        b.iter(|| {
            chains.eval_positions(black_box(&q), &mut data);
            chains.eval_jacobians(&mut data);
        })
    });
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(2)).warm_up_time(Duration::from_secs(1));
    targets = bench
}
criterion_main!(benches);

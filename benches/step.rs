//! Stage "step": one whole `fbd_sim::step` (prepare, predictor, Newton,
//! contact check, accept) per contact-state combination — flight (ST1/ST1),
//! both sticking (ST2/ST2), both sliding (ST3/ST3) — at Δt = 1 ms. Each
//! measured step is one of the first 0.5 s after a warm start (restarts are
//! not timed; see `common::time_steps`).
//!
//! `cargo bench -p fbd-suite --bench step`

mod common;

use std::time::Duration;

use common::{Case, fixtures_hold, time_steps};
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    fixtures_hold();
    for case in Case::ALL {
        let model = case.model();
        c.bench_function(&format!("step/{}", case.name()), |b| {
            b.iter_custom(|iters| time_steps(&model, case, iters))
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(2)).warm_up_time(Duration::from_secs(1));
    targets = bench
}
criterion_main!(benches);

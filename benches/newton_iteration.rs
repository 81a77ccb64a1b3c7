//! Stage "Newton": one full Newton iteration of a step (residual + analytic
//! Jacobian, numeric LU, triangular solves) at the predictor of a warm step,
//! and a whole `NewtonSolver::solve` of the step from the predictor (the
//! iteration count it takes is printed once).
//!
//! `cargo bench -p fbd-suite --bench newton_iteration`

mod common;

use std::hint::black_box;
use std::time::Duration;

use common::{Case, prepared};
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    for case in Case::ALL {
        let (model, mut data) = prepared(case);
        let (mut sys, solver, z) = fbd_sim::step::system(&model, &mut data);
        let z0 = z.to_vec();
        let mut dx = vec![0.0; z0.len()];

        c.bench_function(&format!("newton_iteration/{}", case.name()), |b| {
            b.iter(|| {
                solver.load_jacobian(&mut sys, black_box(&z0));
                solver.factorize_loaded(Some(&mut dx)).expect("nonsingular");
                black_box(&dx);
            })
        });

        let mut z = z0.clone();
        let report = solver.solve(&mut sys, &mut z).expect("converges");
        eprintln!(
            "newton_solve/{}: {} iteration(s) from the predictor",
            case.name(),
            report.iterations
        );
        c.bench_function(&format!("newton_solve/{}", case.name()), |b| {
            b.iter(|| {
                z.copy_from_slice(&z0);
                black_box(solver.solve(&mut sys, &mut z).expect("converges"));
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(2)).warm_up_time(Duration::from_secs(1));
    targets = bench
}
criterion_main!(benches);

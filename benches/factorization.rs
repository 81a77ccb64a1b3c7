//! Stage "factorisation": faer's numeric sparse LU of one step's Jacobian
//! (19 × 19), the symbolic analysis cached per pattern and the storage
//! reused, exactly as each Newton iteration does (through the solver's
//! `load_jacobian` / `factorize_loaded` hooks); the LU plus the
//! triangular solves of the Newton step; and the triangular solves alone
//! (a chord step's solve, `solve_loaded`).
//!
//! `cargo bench -p fbd-suite --bench factorization`

mod common;

use std::hint::black_box;
use std::time::Duration;

use common::{Case, prepared};
use criterion::{Criterion, criterion_group, criterion_main};

fn bench(c: &mut Criterion) {
    for case in Case::ALL {
        let (model, mut data) = prepared(case);
        let (mut sys, solver, z) = fbd_sim::step::system(&model, &mut data);
        let z = z.to_vec();
        solver.load_jacobian(&mut sys, &z);
        let mut dx = vec![0.0; z.len()];

        c.bench_function(&format!("numeric_lu/{}", case.name()), |b| {
            b.iter(|| solver.factorize_loaded(None).expect("nonsingular"))
        });
        c.bench_function(&format!("numeric_lu_and_solve/{}", case.name()), |b| {
            b.iter(|| {
                solver.factorize_loaded(Some(&mut dx)).expect("nonsingular");
                black_box(&dx);
            })
        });
        // The solve of a chord step: the kept factorisation's triangular
        // sweeps alone.
        c.bench_function(&format!("chord_solve/{}", case.name()), |b| {
            b.iter(|| {
                solver.solve_loaded(&mut dx);
                black_box(&dx);
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

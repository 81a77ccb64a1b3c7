//! Stage "assembly": the FBD residual of one step, alone and with the
//! analytic Jacobian written through a sink into CSC values (a slot map, as
//! the Newton solver does), at the predictor of a warm step of each
//! contact-state case.
//!
//! `cargo bench -p fbd-suite --bench assembly`

mod common;

use std::hint::black_box;
use std::time::Duration;

use common::{Case, prepared};
use criterion::{Criterion, criterion_group, criterion_main};
use fbd_dynamics::{JacobianSink, NoJacobian, eval, pattern};

/// Adds into CSC values through a dense `(row, col) → slot` map.
struct SlotSink<'a> {
    n: usize,
    slot: &'a [u32],
    values: &'a mut [f64],
}

impl JacobianSink for SlotSink<'_> {
    const ACTIVE: bool = true;
    #[inline]
    fn add(&mut self, row: usize, col: usize, v: f64) {
        self.values[self.slot[row * self.n + col] as usize] += v;
    }
}

fn bench(c: &mut Criterion) {
    for case in Case::ALL {
        let (model, mut data) = prepared(case);
        // Building the system sets the contact equations.
        let _ = fbd_sim::step::system(&model, &mut data);
        let mech = &model.mech;
        let terrain = &model.params.terrain;
        let n = mech.layout().dim();
        let z = data.z.clone();
        let mut r = vec![0.0; n];
        let mut entries = Vec::new();
        pattern(mech, terrain, &data.fbd, &mut entries);
        entries.sort_unstable_by_key(|&(i, j)| (j, i));
        entries.dedup();
        let mut slot = vec![u32::MAX; n * n];
        for (k, &(i, j)) in entries.iter().enumerate() {
            slot[i * n + j] = k as u32;
        }
        let mut values = vec![0.0; entries.len()];
        let fbd = &mut data.fbd;

        c.bench_function(&format!("assembly_residual/{}", case.name()), |b| {
            b.iter(|| {
                eval(mech, terrain, fbd, black_box(&z), &mut r, &mut NoJacobian);
                black_box(&r);
            })
        });
        c.bench_function(
            &format!("assembly_residual_jacobian/{}", case.name()),
            |b| {
                b.iter(|| {
                    values.fill(0.0);
                    let mut sink = SlotSink {
                        n,
                        slot: &slot,
                        values: &mut values,
                    };
                    eval(mech, terrain, fbd, black_box(&z), &mut r, &mut sink);
                    black_box((&r, &values));
                })
            },
        );
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(2)).warm_up_time(Duration::from_secs(1));
    targets = bench
}
criterion_main!(benches);

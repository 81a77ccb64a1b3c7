//! faer's sparse LU variants on the Jacobians of our steps (issue 14): the
//! numeric factorisation with the symbolic analysis done once, as each
//! refactorisation of the Newton solver does, for
//!
//! * `simplicial_colamd` — the solver's choice: simplicial (left-looking,
//!   Gilbert–Peierls) LU, COLAMD column ordering;
//! * `simplicial_natural` — the same without a fill-reducing ordering;
//! * `supernodal_colamd` — faer's supernodal LU (it allocates its work
//!   vectors on every call, so the allocation-free solver cannot use it);
//!
//! on the planar step's Jacobian in flight (19 + 4 unknowns), both feet
//! sticking, both sliding, the default fall's robot lying on its feet,
//! knees and hips (31), and the hexapod's 3D step standing on six feet.
//! The fill of `L + U` of each is printed once.
//!
//! `cargo bench -p fbd-suite --bench lu_variants`

mod common;

use std::hint::black_box;
use std::time::Duration;

use common::{Case, prepared};
use criterion::{Criterion, criterion_group, criterion_main};
use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::perm::PermRef;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::lu::simplicial::{
    SimplicialLu, factorize_simplicial_numeric_lu, factorize_simplicial_numeric_lu_scratch,
};
use faer::sparse::linalg::lu::{LuSymbolicParams, NumericLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Par, Spec};
use fbd_sim::spatial::{SpatialData, SpatialModel, SpatialParams};
use fbd_sim::{Data, Model, PlanarParams};
use fbd_solver::{NewtonSolver, NewtonSystem};

/// A Jacobian in CSC form.
struct Csc {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    values: Vec<f64>,
}

impl Csc {
    fn of<S: NewtonSystem>(sys: &mut S, z: &[f64]) -> Self {
        let n = z.len();
        let mut r = vec![0.0; n];
        let dense = NewtonSolver::dense_jacobian(sys, z, &mut r);
        let mut entries = Vec::new();
        sys.pattern(&mut entries);
        entries.sort_unstable_by_key(|&(i, j)| (j, i));
        entries.dedup();
        let mut col_ptr = vec![0; n + 1];
        let mut row_idx = Vec::new();
        let mut values = Vec::new();
        for &(i, j) in &entries {
            col_ptr[j + 1] += 1;
            row_idx.push(i);
            values.push(dense[i * n + j]);
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }
        Self {
            n,
            col_ptr,
            row_idx,
            values,
        }
    }

    fn symbolic(&self) -> SymbolicSparseColMatRef<'_, usize> {
        SymbolicSparseColMatRef::new_checked(self.n, self.n, &self.col_ptr, None, &self.row_idx)
    }

    fn matrix(&self) -> SparseColMatRef<'_, usize, f64> {
        SparseColMatRef::new(self.symbolic(), &self.values)
    }
}

/// The planar step of a fixture case at its predictor.
fn planar_case(case: Case) -> Csc {
    let (model, mut data) = prepared(case);
    let (mut sys, _, z) = fbd_sim::step::system(&model, &mut data);
    let z = z.to_vec();
    Csc::of(&mut sys, &z)
}

/// The default fall at Δt = 1 ms, lying on its feet, knees and hips at
/// 1.5 s (31 unknowns).
fn lying() -> Csc {
    let p = PlanarParams {
        dt: 1e-3,
        duration: 2.0,
        ..PlanarParams::default()
    };
    let model = Model::planar(&p).expect("valid");
    let mut data = Data::new(&model);
    for _ in 0..1500 {
        fbd_sim::step(&model, &mut data).expect("step");
    }
    fbd_sim::engine::step::prepare(&model, &mut data).expect("prepare");
    let (mut sys, _, z) = fbd_sim::step::system(&model, &mut data);
    let z = z.to_vec();
    Csc::of(&mut sys, &z)
}

/// The hexapod standing on its six feet (the 3D engine's default
/// configuration after 50 steps).
fn hexapod() -> Csc {
    let model = SpatialModel::new(&SpatialParams::default()).expect("valid");
    let mut data = SpatialData::new(&model);
    for _ in 0..50 {
        fbd_sim::spatial::step(&model, &mut data).expect("step");
    }
    fbd_sim::engine::step::prepare(&model, &mut data).expect("prepare");
    let z = data.z.clone();
    let mut sys = fbd_sim::spatial::step::system_for_bench(&model, &mut data);
    Csc::of(&mut sys, &z)
}

fn bench(c: &mut Criterion) {
    let cases = [
        ("flight", planar_case(Case::Flight)),
        ("stick", planar_case(Case::Stick)),
        ("slide", planar_case(Case::Slide)),
        ("lying", lying()),
        ("hexapod", hexapod()),
    ];
    for (name, a) in &cases {
        let n = a.n;
        let identity: Vec<usize> = (0..n).collect();
        let natural = PermRef::new_checked(&identity, &identity, n);
        let simplicial = factorize_symbolic_lu(
            a.symbolic(),
            LuSymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
                ..Default::default()
            },
        )
        .expect("symbolic");
        let supernodal = factorize_symbolic_lu(
            a.symbolic(),
            LuSymbolicParams {
                supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SUPERNODAL,
                ..Default::default()
            },
        )
        .expect("symbolic");
        let mut mem = MemBuffer::new(StackReq::any_of(&[
            factorize_simplicial_numeric_lu_scratch::<usize, f64>(n, n),
            supernodal.factorize_numeric_lu_scratch::<f64>(Par::Seq, Spec::default()),
        ]));
        let (mut fwd, mut inv) = (vec![0; n], vec![0; n]);
        let mut lu = SimplicialLu::new();
        for (variant, perm) in [
            ("simplicial_colamd", simplicial.col_perm()),
            ("simplicial_natural", natural),
        ] {
            factorize_simplicial_numeric_lu(
                &mut fwd,
                &mut inv,
                &mut lu,
                a.matrix(),
                perm,
                MemStack::new(&mut mem),
            )
            .expect("nonsingular");
            let fill = lu.l_factor_unsorted().compute_nnz() + lu.u_factor_unsorted().compute_nnz();
            eprintln!(
                "lu/{name}/{variant}: n = {n}, nnz(A) = {}, nnz(L + U) = {fill}",
                a.row_idx.len()
            );
            c.bench_function(&format!("lu/{name}/{variant}"), |b| {
                b.iter(|| {
                    factorize_simplicial_numeric_lu(
                        &mut fwd,
                        &mut inv,
                        &mut lu,
                        black_box(a.matrix()),
                        perm,
                        MemStack::new(&mut mem),
                    )
                    .expect("nonsingular")
                })
            });
        }
        let mut numeric = NumericLu::new();
        c.bench_function(&format!("lu/{name}/supernodal_colamd"), |b| {
            b.iter(|| {
                supernodal
                    .factorize_numeric_lu(
                        &mut numeric,
                        black_box(a.matrix()),
                        Par::Seq,
                        MemStack::new(&mut mem),
                        Spec::default(),
                    )
                    .map(|_| ())
                    .expect("nonsingular")
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(1)).warm_up_time(Duration::from_millis(300));
    targets = bench
}
criterion_main!(benches);

//! After the first solve of a pattern, `NewtonSolver::solve` must not touch
//! the heap: not in the Newton loop, not in faer's numeric refactorisation,
//! not in the triangular solves (faer's storage is grown at its first use,
//! and a pattern's program for a new set of exact zeros is compiled like
//! a new pattern; one compiled again, once, after failing its pivots twice
//! in a row reuses its storage unless it outgrows it).
//!
//! The global allocator is `System` wrapped by `stats_alloc`'s `StatsAlloc`,
//! which counts every allocation, reallocation and deallocation in atomic
//! counters. (The wrapper lives in a dev-dependency because the workspace
//! forbids `unsafe_code`, and implementing `GlobalAlloc` needs `unsafe impl`.)
//!
//! The counters are process-global, so this file runs as a plain `main`
//! without libtest's harness: no other thread of this binary can allocate
//! inside the measured region. Anything counted there is a real allocation (never hidden).

mod common;

use std::alloc::System;

use common::{Cubic, Pivoting, TrigChain};
use fbd_solver::{NewtonParams, NewtonSolver, SolverError};
use stats_alloc::{INSTRUMENTED_SYSTEM, Region, Stats, StatsAlloc};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

fn assert_no_heap(what: &str, stats: Stats) {
    assert!(
        stats.allocations == 0 && stats.reallocations == 0 && stats.deallocations == 0,
        "{what}: heap traffic during a solve of a cached pattern: {stats:?}"
    );
}

fn second_solve_of_a_pattern_does_not_allocate() {
    let root_a: Vec<f64> = (0..10)
        .map(|i| 0.8 * ((i as f64) * 0.7 + 0.3).sin())
        .collect();
    let root_b: Vec<f64> = root_a.iter().map(|r| -0.5 * r + 0.2).collect();
    let mut chain = TrigChain::with_root(&root_a, 1);
    let mut cubic = Cubic {
        c: vec![1.0, -2.0, 0.5, 3.0, 0.0, -1.0, 2.0],
        key: 2,
    };
    let mut x = vec![0.0; 10];
    let mut y = vec![0.0; 7];
    let mut solver = NewtonSolver::default();

    // First solves: register both patterns (allocation expected here).
    let first = Region::new(GLOBAL);
    solver.solve(&mut chain, &mut x).expect("chain converges");
    solver.solve(&mut cubic, &mut y).expect("cubic converges");
    assert!(
        first.change().allocations > 0,
        "the first solve builds the cache"
    );
    assert_eq!(solver.symbolic_factorizations(), 2);

    // Second solve of the same pattern, from a fresh start and towards a
    // different root (different values, several refactorisations).
    chain.retarget(&root_b);
    x.fill(0.0);
    let region = Region::new(GLOBAL);
    let report = solver.solve(&mut chain, &mut x);
    let stats = region.change();
    let report = report.expect("converges");
    assert_no_heap("second solve", stats);
    assert!(report.factorizations >= 3, "{report:?}");
    for (xi, ri) in x.iter().zip(&root_b) {
        assert!((xi - ri).abs() < 1e-9);
    }

    // Switching back and forth between cached patterns (different
    // dimensions) does not allocate either, over many solves.
    let region = Region::new(GLOBAL);
    let mut ok = true;
    for k in 0..50 {
        chain.retarget(if k % 2 == 0 { &root_a } else { &root_b });
        x.fill(0.0);
        ok &= solver.solve(&mut chain, &mut x).is_ok();
        cubic.c[0] = 1.0 + 0.01 * k as f64;
        y.fill(0.0);
        ok &= solver.solve(&mut cubic, &mut y).is_ok();
    }
    let stats = region.change();
    assert!(ok);
    assert_no_heap("alternating cached patterns", stats);

    // Error paths of a cached pattern are allocation-free too (an error is
    // a plain `Copy` value).
    x.fill(f64::NAN);
    let region = Region::new(GLOBAL);
    let err = solver.solve(&mut chain, &mut x);
    let stats = region.change();
    assert_eq!(err, Err(SolverError::NonFinite { iter: 0 }));
    assert_no_heap("error path", stats);
    assert_eq!(solver.symbolic_factorizations(), 2);

    // Same pattern, values that force a different pivot sequence (and so a
    // different fill of L/U) than the first solve: the compiled program
    // fails its pivots and faer's LU factors instead. faer's L/U vectors
    // are sized for the worst case at its first use, a set of exact zeros
    // that falls back twice gets a program of its own, and a program that
    // falls back twice in a row is compiled again on those values, once,
    // in its own storage (these allocate, as a new pattern does, or may:
    // the first two rounds); from then on the same cases never touch the
    // heap.
    let mut piv = Pivoting::new(40);
    let mut z = vec![0.0; 40];
    solver
        .solve(&mut piv, &mut z)
        .expect("diagonally dominant case converges");
    for round in 0..4 {
        for weak in [true, false, true] {
            piv.weak_diagonal = weak;
            z.fill(0.0);
            let region = Region::new(GLOBAL);
            let res = solver.solve(&mut piv, &mut z);
            let stats = region.change();
            let rep = res.expect("converges");
            // Ill-conditioned when the diagonal is weak: may end on the step
            // test (round-off floor), see `NewtonParams`.
            assert!(rep.residual <= 1e-6, "{rep:?}");
            if round > 1 {
                assert_no_heap("re-pivoted refactorisation", stats);
            }
        }
    }
    assert_eq!(solver.symbolic_factorizations(), 3);

    // Chord steps with a kept factorisation, refactorisations when they
    // contract too little, the renewal rule across solves, and patterns of
    // one dimension sharing their numeric storage: a sequence of nearby
    // solves as a simulation makes them.
    let mut solver = NewtonSolver::new(NewtonParams {
        chord_steps: 6,
        refactor_cost: 4.0,
        ..NewtonParams::default()
    });
    let mut other = TrigChain::with_root(&root_a, 3);
    let mut x = vec![0.0; 10];
    solver.solve(&mut chain, &mut x).expect("first solve");
    solver.solve(&mut other, &mut x).expect("second pattern");
    let targets: Vec<Vec<f64>> = (0..200)
        .map(|k| {
            root_a
                .iter()
                .map(|r| r + 0.3 * (0.05 * k as f64).sin())
                .collect()
        })
        .collect();
    let region = Region::new(GLOBAL);
    let mut chords = 0;
    let mut ok = true;
    for (k, target) in targets.iter().enumerate() {
        let sys = if k % 50 == 49 { &mut other } else { &mut chain };
        sys.retarget(target);
        match solver.solve(sys, &mut x) {
            Ok(rep) => chords += rep.chord_iterations,
            Err(_) => ok = false,
        }
    }
    let stats = region.change();
    assert!(ok);
    assert!(chords > 100, "chord steps taken: {chords}");
    assert_no_heap("chord steps and refactorisations", stats);
}

// The workspace's runner of harness-less tests (one source for the
// allocation tests of every crate).
#[path = "../../../tests/common/harness.rs"]
mod harness;

/// Runs without libtest's harness (`harness = false` in `Cargo.toml`): the
/// allocation counters are process-global, and the harness's main thread
/// allocates while it waits for a test to finish, at a moment no test
/// controls (a rare false failure).
fn main() {
    harness::run_alone(
        "second_solve_of_a_pattern_does_not_allocate",
        second_solve_of_a_pattern_does_not_allocate,
    );
}

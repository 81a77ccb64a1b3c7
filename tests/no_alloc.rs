//! The stepping loop does not touch the heap once every contact pattern it
//! meets has been solved once (issue 5).
//!
//! The global allocator of this test binary is `System` wrapped by
//! `stats_alloc`'s `StatsAlloc`, which counts allocations, reallocations and
//! deallocations in atomic counters (a dev-dependency: implementing
//! `GlobalAlloc` needs `unsafe impl`, which the workspace lints forbid). The
//! counters are process-global, so this file runs as a plain `main`
//! without libtest's harness (no other thread allocates).
//!
//! Cases: the benchmarks' fixtures (`benches/common/mod.rs`), the default
//! experiment's robot at Δt = 1 ms with its feet in flight (ST1), sticking
//! (ST2; its knees reach their joint limits during the measured pass and
//! stay there) or sliding (ST3).
//!
//! Each case builds a `Model`, runs 2010 steps once so that the solver has
//! met every contact pattern of the run (the first solve of a pattern builds
//! its CSC structure and symbolic LU: allocation expected there), then
//! restarts from a fresh `Data` with that warm solver, steps 10 times
//! (the first step uses the initial velocities) and counts the heap traffic
//! of the next 2000 `fbd_sim::step` calls, which must be zero.
//! (Contact *events* are outside this guarantee: the event list grows, in
//! amortised steps, past its initial capacity of 64.)
//!
//! The retry path: runs 0 and 19 of `examples/sweep_landing_1000.toml`
//! (`tests/landing_retry.rs`, Δt = 10 ms), hard landings whose touchdown
//! step is solved again in substeps (run 19's state search still cycles at
//! Δt/64 and is closed by its least inconsistent combination). A first pass meets every pattern of
//! the run; the measured pass steps the whole run again from a fresh `Data`
//! with the warm solver, its event, limit-event and retry lists reserved to
//! the first pass's lengths (so that their pushes are preallocated, not
//! amortised), and must not touch the heap at all — substeps, restores of
//! the step's start and the state search's fallbacks included.

use std::alloc::System;

use fbd_sim::{Data, Model, step};

mod common;
use common::physics::landing;
use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};

/// The benchmarks' fixtures: the same three cases.
#[path = "../benches/common/mod.rs"]
mod fixtures;
use fixtures::Case;

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

fn steady_stepping_does_not_allocate() {
    retried_steps_do_not_allocate();
    for case in Case::ALL {
        let model = case.model();
        // A first pass registers every contact pattern the run meets (the
        // state search may try a pattern for one trial without an event:
        // its first solve builds its structure and symbolic LU).
        let mut warm = Data::new(&model);
        for _ in 0..2010 {
            step(&model, &mut warm).expect("warm-up pass");
        }
        // The measured pass: a fresh state, stepping with the warm solver.
        let mut data = Data::new(&model);
        std::mem::swap(&mut data.solver, &mut warm.solver);
        drop(warm);
        for _ in 0..10 {
            step(&model, &mut data).expect("warm-up step");
        }
        assert!(case.holds(&data.states), "{case:?}: {:?}", data.states);
        let events = data.events.len();
        let patterns = data.symbolic_factorizations();

        let region = Region::new(GLOBAL);
        for _ in 0..2000 {
            std::hint::black_box(step(&model, &mut data).expect("step"));
        }
        let stats = region.change();

        assert!(case.holds(&data.states), "{case:?}: {:?}", data.states);
        assert_eq!(
            data.events.len(),
            events,
            "{case:?}: no events in a steady state"
        );
        assert_eq!(
            data.symbolic_factorizations(),
            patterns,
            "{case:?}: a new contact pattern in the measured pass"
        );
        assert!(
            stats.allocations == 0 && stats.reallocations == 0 && stats.deallocations == 0,
            "{case:?}: heap traffic in 2000 steady steps: {stats:?}"
        );
        if let Case::Stick = case {
            // The collapsing robot straightens its knees onto their limits
            // during the measured pass: the joint-limit rows (a limit
            // reached, then held) are covered too.
            assert!(
                data.limit_states.iter().filter(|l| l.is_at()).count() == 2,
                "{case:?}: both knees at their limits, {:?}",
                data.limit_states
            );
        }
        eprintln!("{case:?}: 2000 steps, {stats:?}");
    }
}

/// The retry path (see the module docs): landings with substeps.
fn retried_steps_do_not_allocate() {
    let run0 = landing(
        3.6307028881198846,
        -68.17923482210148,
        0.42541363101410046,
        [16.450618133873157, 256.5144904354054],
        [10.676025180807866, 248.8771949134427],
        0.9801527659718492,
    );
    let run19 = landing(
        -15.611146718503639,
        114.58431493462297,
        0.9249770876982062,
        [7.09621971089739, 261.08032973878665],
        [-4.899273363481299, 271.1942274223952],
        0.2546993914186943,
    );
    let last_resort = retried_run_does_not_allocate("run 0", &run0);
    assert_eq!(last_resort, 0, "run 0 needs no least-inconsistent closure");
    let last_resort = retried_run_does_not_allocate("run 19", &run19);
    assert!(
        last_resort > 0,
        "run 19 covers the least-inconsistent closure"
    );
}

/// Steps the whole run twice (see the module docs) and returns the state
/// searches closed by their least inconsistent combination.
fn retried_run_does_not_allocate(what: &str, p: &fbd_sim::PlanarParams) -> usize {
    let model = Model::planar(p).expect("valid parameters");
    let mut warm = Data::new(&model);
    for _ in 0..model.steps {
        step(&model, &mut warm).expect("first pass");
    }
    assert!(
        !warm.retries.is_empty(),
        "{what}: the landing is retried in substeps"
    );
    let mut data = Data::new(&model);
    std::mem::swap(&mut data.solver, &mut warm.solver);
    data.events.reserve(warm.events.len());
    data.limit_events.reserve(warm.limit_events.len());
    data.retries.reserve(warm.retries.len());
    let patterns = data.symbolic_factorizations();

    let region = Region::new(GLOBAL);
    for _ in 0..model.steps {
        std::hint::black_box(step(&model, &mut data).expect("step"));
    }
    let stats = region.change();

    assert_eq!(
        data.retries.len(),
        warm.retries.len(),
        "{what}: the same retries"
    );
    assert_eq!(
        data.events.len(),
        warm.events.len(),
        "{what}: the same events"
    );
    assert_eq!(
        data.symbolic_factorizations(),
        patterns,
        "{what}: a new contact pattern in the measured pass"
    );
    assert!(
        stats.allocations == 0 && stats.reallocations == 0 && stats.deallocations == 0,
        "{what}: heap traffic in {} steps with {} retried: {stats:?}",
        model.steps,
        data.retries.len()
    );
    eprintln!(
        "{what}: {} steps, {} retried ({:?}), {stats:?}",
        model.steps,
        data.retries.len(),
        data.retries
    );
    data.resolved_cycles
}

/// Without libtest's harness (see [`common::harness`]).
fn main() {
    common::harness::run_alone(
        "steady_stepping_does_not_allocate",
        steady_stepping_does_not_allocate,
    );
}

//! The stepping loop does not touch the heap once every contact pattern it
//! meets has been solved once (issue 5).
//!
//! The global allocator of this test binary is `System` wrapped by
//! `stats_alloc`'s `StatsAlloc`, which counts allocations, reallocations and
//! deallocations in atomic counters (a dev-dependency: implementing
//! `GlobalAlloc` needs `unsafe impl`, which the workspace lints forbid). The
//! counters are process-global, so this file holds a single `#[test]`.
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

use std::alloc::System;

use fbd_sim::{Data, step};
use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};

/// The benchmarks' fixtures: the same three cases.
#[path = "../benches/common/mod.rs"]
mod fixtures;
use fixtures::Case;

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

#[test]
fn steady_stepping_does_not_allocate() {
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

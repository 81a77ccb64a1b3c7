//! One kinematic gait step does not touch the heap (the footholds and the
//! body path are computed when the model is built).
//!
//! The global allocator of this test binary is `System` wrapped by
//! `stats_alloc`'s counting `StatsAlloc`; the counters are process-global,
//! so this file runs as a plain `main` without libtest's harness (no other
//! thread allocates).

mod common;

use std::alloc::System;

use common::gait::model;
use fbd_sim::gait::{Command, GaitData, GaitKind, GaitParams, step};
use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

fn gait_steps_do_not_allocate() {
    let params = GaitParams {
        forward: Command::Profile(vec![[0.0, 0.02], [2.0, 0.08]]),
        yaw_rate: Command::Constant(4f64.to_radians()),
        sway: 0.01,
        walk_time: 4.0,
        ..GaitParams::preset(GaitKind::Wave)
    };
    let m = model(params, 0.005, 5.0);
    let mut data = GaitData::new(&m);
    // A first step outside the count (one-time lazy initialisations of the
    // process, if any).
    step(&m, &mut data, 0).expect("reachable");
    // The counters are process-global: an allocation by another thread of
    // the test harness during the measurement would count too. A step that
    // allocates does so in every pass (1001 steps), so the best of three
    // passes is the gait's own count.
    let mut best = None;
    for _ in 0..3 {
        let region = Region::new(GLOBAL);
        for k in 0..=m.steps {
            step(&m, &mut data, k).expect("reachable");
        }
        let stats = region.change();
        let counts = (stats.allocations, stats.reallocations, stats.deallocations);
        if best.is_none_or(|(b, _)| counts < b) {
            best = Some((counts, stats));
        }
        if counts == (0, 0, 0) {
            break;
        }
    }
    let (counts, stats) = best.expect("three passes");
    assert_eq!(counts, (0, 0, 0), "{} steps: {stats:?}", m.steps + 1);
}

/// Without libtest's harness (see [`common::harness`]).
fn main() {
    common::harness::run_alone("gait_steps_do_not_allocate", gait_steps_do_not_allocate);
}

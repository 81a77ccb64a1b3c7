//! The spatial stepping loop does not touch the heap once every contact
//! pattern it meets has been solved once: the same measurement as
//! `tests/no_alloc.rs` (a counting global allocator, a harness-less
//! `main`) on 3D runs — a tumbling flight, the PD stance settling on its
//! six feet, and a stance sliding down a slope (feet in ST3, slip
//! directions updated) — with the event lists reserved to the first pass's
//! lengths.

use std::alloc::System;

use fbd_contact::{Friction, Surface, Terrain};
use fbd_sim::spatial::{SpatialData, SpatialModel, SpatialParams, step};
use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};

mod common;

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

fn cases() -> Vec<(&'static str, SpatialParams)> {
    let stance = common::spatial::stance();
    let mut flight = SpatialParams {
        terrain: Surface::new(Terrain::None, 0.0),
        ..SpatialParams::default()
    };
    flight.qdot0[3..6].copy_from_slice(&[1.0, -2.0, 0.5]);
    for s in 0..6 {
        flight.qdot0[7 + 3 * s] = 1.0 - 0.3 * s as f64;
    }
    let mut slope = stance.clone();
    slope.terrain = Surface::new(
        Terrain::Slope {
            slope: 0.3,
            height: -0.2,
        },
        0.4,
    );
    slope.friction = Friction {
        mu_static: 0.1,
        mu_dynamic: 0.1,
    };
    slope.q0[1] += 0.25;
    vec![("flight", flight), ("stance", stance), ("slope", slope)]
}

fn spatial_stepping_does_not_allocate() {
    for (name, mut p) in cases() {
        p.duration = 2.0;
        let model = SpatialModel::new(&p).unwrap();
        let mut warm = SpatialData::new(&model);
        for _ in 0..model.steps {
            step(&model, &mut warm).unwrap_or_else(|e| panic!("{name}: {e}"));
        }
        let mut data = SpatialData::new(&model);
        std::mem::swap(&mut data.solver, &mut warm.solver);
        data.events.reserve(warm.events.len() + 1);
        data.limit_events.reserve(warm.limit_events.len() + 1);
        data.retries.reserve(warm.retries.len() + 1);
        let events = warm.events.len();
        drop(warm);
        let region = Region::new(GLOBAL);
        for _ in 0..model.steps {
            step(&model, &mut data).expect("step");
            std::hint::black_box(&data.record);
        }
        let stats = region.change();
        println!("{name}: {events} events, {stats:?}");
        assert_eq!(
            (stats.allocations, stats.reallocations),
            (0, 0),
            "{name}: the stepping loop allocated"
        );
    }
}

/// Without libtest's harness (see [`common::harness`]).
fn main() {
    common::harness::run_alone(
        "spatial_stepping_does_not_allocate",
        spatial_stepping_does_not_allocate,
    );
}

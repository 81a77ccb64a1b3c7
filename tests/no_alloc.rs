//! The stepping loop does not touch the heap once every contact pattern it
//! meets has been solved once (issue 5).
//!
//! The global allocator of this test binary is `System` wrapped by
//! `stats_alloc`'s `StatsAlloc`, which counts allocations, reallocations and
//! deallocations in atomic counters (a dev-dependency: implementing
//! `GlobalAlloc` needs `unsafe impl`, which the workspace lints forbid). The
//! counters are process-global, so this file holds a single `#[test]`.
//!
//! Cases, at Δt = 1 ms with the default experiment's robot:
//! * flight — no terrain, both tips ST1;
//! * stick — both tips on flat ground, μS huge: both ST2;
//! * slide — both tips on the ground, μS = μD = 0, body moving at 0.5 m/s:
//!   both ST3.
//!
//! Each case builds a `Model`, runs 2010 steps once so that the solver has
//! met every contact pattern of the run (the first solve of a pattern builds
//! its CSC structure and symbolic LU: allocation expected there), then
//! restarts from a fresh `Data` with that warm solver, steps 10 times
//! (the first step uses the initial velocities) and counts the heap traffic
//! of the next 2000 `fbd_sim::step` calls, which must be zero.
//! (Contact *events* are outside this guarantee: an `Event` carries the
//! point's name as a `String`.)

use std::alloc::System;

use fbd_contact::{ContactState, Friction, Terrain};
use fbd_dynamics::ContactPoints;
use fbd_sim::{Data, Model, PlanarParams, step};
use stats_alloc::{INSTRUMENTED_SYSTEM, Region, StatsAlloc};

#[global_allocator]
static GLOBAL: &StatsAlloc<System> = &INSTRUMENTED_SYSTEM;

fn params(case: &str) -> PlanarParams {
    let mut p = PlanarParams {
        dt: 1e-3,
        duration: 10.0,
        // The paper's model: the states named are those of the feet.
        contact_points: ContactPoints {
            tips: true,
            knees: false,
            hips: false,
        },
        ..PlanarParams::default()
    };
    if case == "flight" {
        p.terrain = Terrain::None;
        return p;
    }
    let th3 = 250f64.to_radians();
    p.q0 = [0.0, -p.lower_length * th3.sin(), 0.0, 0.0, th3, 0.0, th3];
    if case == "stick" {
        p.friction = Friction {
            mu_static: 1e6,
            mu_dynamic: 0.3,
        };
    } else {
        p.friction = Friction {
            mu_static: 0.0,
            mu_dynamic: 0.0,
        };
        p.qdot0[0] = 0.5;
    }
    p
}

fn in_state(case: &str, s: &ContactState) -> bool {
    match case {
        "flight" => matches!(s, ContactState::Free),
        "stick" => matches!(s, ContactState::Stick { .. }),
        _ => matches!(s, ContactState::Slide { .. }),
    }
}

#[test]
fn steady_stepping_does_not_allocate() {
    for case in ["flight", "stick", "slide"] {
        let model = Model::planar(&params(case)).expect("valid parameters");
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
        assert!(
            data.states.iter().all(|s| in_state(case, s)),
            "{case}: {:?}",
            data.states
        );
        let events = data.events.len();
        let patterns = data.symbolic_factorizations();

        let region = Region::new(GLOBAL);
        for _ in 0..2000 {
            std::hint::black_box(step(&model, &mut data).expect("step"));
        }
        let stats = region.change();

        assert!(
            data.states.iter().all(|s| in_state(case, s)),
            "{case}: {:?}",
            data.states
        );
        assert_eq!(
            data.events.len(),
            events,
            "{case}: no events in a steady state"
        );
        assert_eq!(
            data.symbolic_factorizations(),
            patterns,
            "{case}: a new contact pattern in the measured pass"
        );
        assert!(
            stats.allocations == 0 && stats.reallocations == 0 && stats.deallocations == 0,
            "{case}: heap traffic in 2000 steady steps: {stats:?}"
        );
        eprintln!("{case}: 2000 steps, {stats:?}");
    }
}

//! A crawl given up at a certain touchdown (`docs/reference.md`, *Contact
//! in 3D*): in the 3D drop of `bench/peer` (feet, knees and hips, Δt =
//! 1 ms) the solve of the impact step in the states before the hips and
//! knees strike crawled at a kink of the sliding feet's rows for all its
//! iterations, then its fallbacks ran. Given up at its kept iterate, where
//! those points are already below the ground, the search touches them down
//! at once. The run completes with every row within the contact laws (from
//! the records alone), as it does when no crawl is given up, with fewer
//! factorisations; the walk, which never crawls, gives none up.

mod common;

use common::spatial::assert_rows_within_laws;
use fbd_scenario::{Config, load};
use fbd_sim::RunSummary;
use fbd_sim::simulator::{Action, Simulator};
use fbd_sim::spatial::{SpatialModel, run_collect};
use std::path::Path;

fn model(case: &str, give_up: bool) -> SpatialModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("bench/peer")
        .join(format!("{case}.toml"));
    let Config::Hexapod(c) = load(&path).expect("the configuration loads") else {
        panic!("a hexapod configuration")
    };
    let mut p = c.spatial_params(case).expect("valid");
    p.stride = 1;
    let mut m = SpatialModel::new(&p).expect("a valid model");
    m.newton.give_up_crawls = give_up;
    m
}

/// Runs `model` to its end; fails unless every row obeys the contact laws
/// to 1e-6 of the weight.
fn exact(model: &SpatialModel) -> RunSummary {
    let (rows, summary) = run_collect(model);
    if let Some(e) = &summary.error {
        panic!("{e}");
    }
    assert_eq!(rows.len(), model.steps);
    assert_rows_within_laws(model, &rows, &summary, "the run");
    let weight = model.mech.total_mass() * model.params.gravity;
    assert!(summary.max_law_violation <= 1e-6 * weight);
    summary
}

#[test]
fn the_drop_gives_up_the_crawl_before_its_hips_and_knees_strike() {
    let given_up = exact(&model("hexapod_drop", true));
    let kept = exact(&model("hexapod_drop", false));
    assert!(given_up.abandoned_crawls >= 1, "{given_up:?}");
    assert_eq!(kept.abandoned_crawls, 0);
    // The hips and knees strike: touchdowns of points other than feet.
    let strikes = given_up
        .events
        .iter()
        .filter(|e| {
            e.from == fbd_contact::StateCode::St1 && e.point != fbd_dynamics::PointKind::Tip
        })
        .count();
    assert!(strikes >= 6, "{strikes} hip and knee touchdowns");
    println!(
        "factorisations: {} giving up crawls, {} without",
        given_up.numeric_factorizations, kept.numeric_factorizations
    );
    assert!(given_up.numeric_factorizations < kept.numeric_factorizations);
}

#[test]
fn the_walk_never_gives_up_a_solve() {
    let s = exact(&model("hexapod_walk", true));
    assert_eq!(s.abandoned_crawls, 0);
}

/// Every Newton step the solver takes is counted (`docs/reference.md`,
/// *Speed*): stepped to its end, the drop — whose given-up crawls are
/// failed solves, their steps in no report — has counted exactly the
/// steps its solver took, chord steps included, and its rows hold them
/// step by step (the given-up crawl's steps in the step that gave it up).
#[test]
fn every_step_of_every_solve_counts_the_given_up_ones_too() {
    let model = model("hexapod_drop", true);
    let steps = model.steps;
    let mut sim = Simulator::new(model.clone());
    let mut rows_sum = 0;
    for _ in 1..steps {
        sim.step(&Action::Controller).expect("the drop steps");
        rows_sum += sim.data().record.newton_iterations;
    }
    let data = sim.data();
    assert!(data.abandoned_crawls >= 1, "a crawl was given up");
    assert_eq!(data.newton_iterations as u64, data.solver.steps_taken());
    assert_eq!(
        data.chord_iterations as u64,
        data.solver.chord_steps_taken()
    );
    assert_eq!(rows_sum, data.newton_iterations);
    // The same as a run writes.
    let (rows, summary) = run_collect(&model);
    assert_eq!(summary.newton_iterations, data.newton_iterations);
    assert_eq!(
        rows.iter().map(|r| r.newton_iterations).sum::<usize>(),
        rows_sum
    );
}

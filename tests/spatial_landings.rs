//! Contact-rich 3D landings complete exactly: runs of
//! `examples/sweep_hexapod_landing_1000.toml` (the default hexapod dropped
//! onto its feet, knees and hips; Δt = 2 ms, 1.5 s) that the fixed-state
//! search could not close — a foot landing while it slides fast (runs 2,
//! 49, 77, 79, 81: no exact combination even at Δt/64), a body coming down
//! on knees and hips with several points sliding and reversing (runs 0, 1,
//! 3) — each complete with complementarity contact rows, obey every
//! contact law on every row (checked from the records alone, the slip's
//! direction to its documented resolution; `tests/csv_balance.rs` checks
//! the bodies' balances from the output columns) and come to rest: no
//! event in their last 0.1 s. Runs 522, 570, 872 and 246 needed the
//! fallbacks of the state search and of the step (below) before Newton's
//! watchdog crossed the contact rows' kinks
//! (`fbd_solver::NewtonParams::watchdog`): they are solved here without
//! it too, so that those fallbacks keep being exercised on the steps that
//! needed them, and with it.

mod common;

use common::spatial::{LawReport, assert_rows_within_laws, landing_config};
use fbd_sim::RunSummary;
use fbd_sim::spatial::{SpatialModel, run_collect};

fn landing(run: usize) -> SpatialModel {
    with_watchdog(run, true)
}

/// Landing `run`, with Newton's watchdog (the default) or without it.
fn with_watchdog(run: usize, watchdog: bool) -> SpatialModel {
    let mut params = landing_config(run)
        .spatial_params("landing")
        .expect("a valid run");
    // Every row (the sweep file's `[set]` writes every 50th).
    params.stride = 1;
    let mut model = SpatialModel::new(&params).expect("a valid model");
    if !watchdog {
        model.newton.watchdog = 0;
    }
    model
}

/// Runs landing `run` to its end; fails unless it completes with every
/// row within the contact laws (1e-6 of the weight). Its summary and the
/// law report.
fn complete_exactly(run: usize) -> (SpatialModel, RunSummary, LawReport) {
    complete_exactly_with(run, true)
}

/// [`complete_exactly`] with or without Newton's watchdog.
fn complete_exactly_with(run: usize, watchdog: bool) -> (SpatialModel, RunSummary, LawReport) {
    let model = with_watchdog(run, watchdog);
    let (rows, summary) = run_collect(&model);
    if let Some(e) = &summary.error {
        panic!("run {run}: {e}");
    }
    assert_eq!(rows.len(), model.steps, "run {run}");
    let laws = assert_rows_within_laws(&model, &rows, &summary, &format!("run {run}"));
    (model, summary, laws)
}

#[test]
fn landings_that_had_no_exact_solution_complete_exactly() {
    for run in [0, 1, 2, 3, 49, 77, 79, 81] {
        let (model, summary, laws) = complete_exactly(run);
        assert!(laws.sliding > 0 && laws.directions > 0, "run {run} slides");
        // Calm at rest: no contact event in the last 0.1 s (they come to
        // rest between 0.6 s and 1.38 s).
        let late = summary
            .events
            .iter()
            .filter(|e| e.t > model.params.duration - 0.1)
            .count();
        assert_eq!(late, 0, "run {run}: {late} events in the last 0.1 s");
    }
}

/// Runs whose active-set fallback found no solution from the failed
/// iterate (without the watchdog, runs 522, 570 and 872 stopped with "no
/// exact solution down to Δt/64", 997 of 1000 landings completing): the
/// same frozen branches solved again from the step's start close the step
/// (without that second attempt these runs fail); every row obeys the
/// contact laws. With the watchdog, they complete exactly too.
#[test]
fn landings_that_needed_the_second_active_set_attempt_complete_exactly() {
    for run in [522, 570, 872] {
        let (_, summary, _) = complete_exactly_with(run, false);
        assert!(summary.newton_fallbacks > 0, "run {run}: no fallback used");
        complete_exactly(run);
    }
}

/// A landing on many points at once (run 246: at t = 0.928 s the robot,
/// lying on its hips and knees, rocks on them: within the step feet lift
/// off, feet and knees turn from sliding to sticking and a hip touches
/// down) whose step has no exact solution down to Δt/32 closes at Δt/64:
/// every row obeys the contact laws and the retry is reported. With the
/// ladder of substeps cut at Δt/32 (`max_substeps`, 256 by default) the
/// run stops at that step with the error naming it, the point and the law
/// its best solution breaks, the rows before it kept. (Which step of a
/// chaotic landing needs Δt/64 or Δt/128 moves with the round-off: run 522
/// at step 722 in the build before the 3D models renewed their kept
/// factorisation, runs 468, 522, 782 and 839 at Δt/128 in earlier ones;
/// run 352 at Δt/128 before Newton's watchdog. The reference-LU rung,
/// after the substeps, is kept for steps that only faer's pivoting LU
/// closes; no run of the sweep needs it now.)
///
/// That is without Newton's watchdog (the scenario of the ladder); with
/// it, the run retries one step, in 2 substeps (of the 1000 landings'
/// 142 retried steps, 124 close at Δt/2, and run 522's step at 1.444 s
/// alone needs Δt/64).
#[test]
fn a_landing_closed_at_dt_over_64_completes_exactly_and_stops_without() {
    let (_, summary, _) = complete_exactly(246);
    assert!(
        summary.retries.iter().all(|r| r.substeps <= 2),
        "{:?}",
        summary.retries
    );
    let (model, summary, _) = complete_exactly_with(246, false);
    assert_eq!(model.max_substeps, 256);
    let deep: Vec<_> = summary.retries.iter().filter(|r| r.substeps > 32).collect();
    assert_eq!(deep.len(), 1, "{:?}", summary.retries);
    assert_eq!((deep[0].step, deep[0].substeps), (464, 64));
    assert!(!deep[0].reference_lu);
    let mut cut = with_watchdog(246, false);
    cut.max_substeps = 32;
    let (rows, summary) = run_collect(&cut);
    let error = summary.error.expect("stops at step 464").to_string();
    assert!(
        error.starts_with("step 464 (t = 0.928000 s): no exact solution down to Δt/32: "),
        "{error}"
    );
    assert_eq!(rows.len(), 464);
}

/// A robot on its knees with feet braced against the ground (run 0,
/// 0.636–0.65 s: feet 1, 5 and 6 slide at μD·N with slips below 1 nm a
/// step while the body tips over). Sticking them needs more than μS·N,
/// tried alone or together; a foot that could not stick slides on without
/// being tried again while its slip runs forwards, so each of these steps
/// is one or two solves (it took about 12 solves and 90 Newton iterations
/// a step when every stopped slide was tried sticking again in every
/// step), and every row obeys the contact laws (`complete_exactly`).
#[test]
fn a_foot_that_could_not_stick_is_not_tried_again_every_step() {
    let model = landing(0);
    let (rows, summary) = run_collect(&model);
    assert!(summary.error.is_none(), "{:?}", summary.error);
    for row in &rows[319..=325] {
        assert!(
            row.newton_iterations <= 6 && row.state_trials <= 2,
            "step {}: {} iterations, {} solves",
            row.step,
            row.newton_iterations,
            row.state_trials
        );
    }
    complete_exactly(0);
}

//! The stepping loop of a spatial run.

use super::data::SpatialData;
use super::model::SpatialModel;
use super::record::SpatialRecord;
use super::step::step;
use crate::RunSummary;
use crate::rules::step_loop;
use std::sync::atomic::AtomicBool;

/// Runs `model` from its initial state to the end (or the first error, or
/// until `stop` is set), handing every `stride`-th record to `on_row`.
pub fn run_until(
    model: &SpatialModel,
    stop: &AtomicBool,
    mut on_row: impl FnMut(&SpatialRecord),
) -> RunSummary {
    let mut data = SpatialData::new(model);
    let end = step_loop(
        &mut data,
        model.steps,
        model.params.stride,
        stop,
        |d| step(model, d),
        |(), d| on_row(&d.record),
    );
    summary(data, end.wall, end.error, end.interrupted)
}

fn summary(
    data: SpatialData,
    wall: f64,
    error: Option<crate::SimError>,
    interrupted: bool,
) -> RunSummary {
    RunSummary {
        steps: data.k,
        newton_iterations: data.newton_iterations,
        max_newton_iterations: data.max_step_iterations,
        chord_iterations: data.chord_iterations,
        numeric_factorizations: data.solver.numeric_factorizations(),
        wall_seconds: wall,
        symbolic_factorizations: data.symbolic_factorizations(),
        events: data.events,
        error,
        limit_events: data.limit_events,
        retries: data.retries,
        resolved_cycles: data.resolved_cycles,
        interrupted,
    }
}

/// [`run_until`] keeping every written record in memory.
pub fn run_collect(model: &SpatialModel) -> (Vec<SpatialRecord>, RunSummary) {
    let mut rows = Vec::with_capacity(model.steps / model.params.stride.max(1) + 1);
    let summary = run_until(model, &AtomicBool::new(false), |r| rows.push(r.clone()));
    (rows, summary)
}

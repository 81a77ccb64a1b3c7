//! The stepping loop of a spatial run.

use super::data::SpatialData;
use super::model::SpatialModel;
use super::record::SpatialRecord;
use super::step::step;
use crate::RunSummary;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// Runs `model` from its initial state to the end (or the first error, or
/// until `stop` is set), handing every `stride`-th record to `on_row`.
pub fn run_until(
    model: &SpatialModel,
    stop: &AtomicBool,
    mut on_row: impl FnMut(&SpatialRecord),
) -> RunSummary {
    let mut data = SpatialData::new(model);
    let stride = model.params.stride.max(1);
    let mut wall = 0.0;
    let mut error = None;
    let mut interrupted = false;
    for k in 0..model.steps {
        if stop.load(Ordering::Relaxed) {
            interrupted = true;
            break;
        }
        let start = Instant::now();
        let result = step(model, &mut data);
        wall += start.elapsed().as_secs_f64();
        match result {
            Ok(()) => {
                if k % stride == 0 {
                    on_row(&data.record);
                }
            }
            Err(e) => {
                error = Some(e);
                break;
            }
        }
    }
    summary(data, wall, error, interrupted)
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
        numeric_factorizations: data.solver.numeric_factorizations(),
        wall_seconds: wall,
        symbolic_factorizations: data.symbolic_factorizations(),
        events: data.events,
        error,
        limit_events: data.limit_events,
        retries: data.retries,
        resolved_cycles: data.resolved_cycles,
        interrupted,
        ..RunSummary::default()
    }
}

/// [`run_until`] keeping every written record in memory.
pub fn run_collect(model: &SpatialModel) -> (Vec<SpatialRecord>, RunSummary) {
    let mut rows = Vec::with_capacity(model.steps / model.params.stride.max(1) + 1);
    let summary = run_until(model, &AtomicBool::new(false), |r| rows.push(r.clone()));
    (rows, summary)
}

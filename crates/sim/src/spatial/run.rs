//! The stepping loop of a spatial run.

use super::data::SpatialData;
use super::model::SpatialModel;
use crate::RunSummary;
use crate::engine::tree_record::RobotRecord;
use std::sync::atomic::AtomicBool;

/// Runs `model` to its last step (or the first error or `stop`), handing
/// every `stride`-th record to `on_row`
/// ([`crate::engine::run::run_until`]).
pub fn run_until(
    model: &SpatialModel,
    stop: &AtomicBool,
    on_row: impl FnMut(&RobotRecord),
) -> RunSummary {
    crate::engine::run::run_until(model, SpatialData::new(model), stop, on_row)
}

/// [`run_until`] for a caller that writes every `written`-th record and
/// only observes the others ([`crate::engine::run::run_in_written`]).
pub fn run_until_written(
    model: &SpatialModel,
    stop: &AtomicBool,
    written: usize,
    on_row: impl FnMut(&RobotRecord),
) -> RunSummary {
    let mut data = SpatialData::new(model);
    crate::engine::run::run_in_written(model, &mut data, stop, written, on_row)
}

/// [`run_until`] keeping every written record in memory.
pub fn run_collect(model: &SpatialModel) -> (Vec<RobotRecord>, RunSummary) {
    let mut rows = Vec::with_capacity(model.steps / model.params.stride.max(1) + 1);
    let summary = run_until(model, &AtomicBool::new(false), |r| rows.push(r.clone()));
    (rows, summary)
}

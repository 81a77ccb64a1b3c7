//! The stepping loop of a whole run, for every model.

use super::{Engine, RunData};
use crate::{RunSummary, SimError};
use std::sync::atomic::{AtomicBool, Ordering};

/// Runs `model` from its initial state to its last step (or the first
/// error), handing the record of every `stride`-th step to `on_row`, and
/// stopping before the next step once `stop` is set (e.g. by a signal
/// handler; the summary then says `interrupted`).
///
/// The records of the other steps are not made (a strided run does not pay
/// for rows it does not write). The wall time is the loop's minus the
/// observer's: the clock is read around the loop and around each handed
/// row only, not around every step.
pub fn run_until<M: Engine>(
    model: &M,
    data: RunData<M>,
    stop: &AtomicBool,
    on_row: impl FnMut(&M::Record),
) -> RunSummary {
    let mut data = data;
    run_in(model, &mut data, stop, on_row)
}

/// [`run_until`] on a workspace the caller keeps: after the run, `data`
/// holds the last state (`q[k]`, the contact states); its event lists
/// have moved into the summary.
pub fn run_in<M: Engine>(
    model: &M,
    data: &mut RunData<M>,
    stop: &AtomicBool,
    on_row: impl FnMut(&M::Record),
) -> RunSummary {
    run_in_written(model, data, stop, 1, on_row)
}

/// [`run_in`] for a caller that writes only every `written`-th of the
/// records it is handed (step `k` with `k % written == 0`) and observes
/// the others (`fbd run`'s plots and peaks, which want every step): those
/// are made without what only a written row reads (a tree model's
/// reaction moments, joint stops, momenta and centre of mass:
/// [`super::tree_record::RobotRecord`]). `written = 1` is [`run_in`].
pub fn run_in_written<M: Engine>(
    model: &M,
    data: &mut RunData<M>,
    stop: &AtomicBool,
    written: usize,
    mut on_row: impl FnMut(&M::Record),
) -> RunSummary {
    let written = written.max(1);
    let settings = model.settings();
    let stride = settings.stride.max(1);
    let mut error: Option<SimError> = None;
    let mut interrupted = false;
    let mut observer = std::time::Duration::ZERO;
    // Steps to the next handed-out record and to the next written one
    // (counted down: no division a step).
    let (mut to_wanted, mut to_written) = (0, 0);
    let start = std::time::Instant::now();
    for _ in 0..settings.steps {
        if stop.load(Ordering::Relaxed) {
            interrupted = true;
            break;
        }
        let wanted = countdown(&mut to_wanted, stride);
        data.want_record = wanted;
        data.whole_record = countdown(&mut to_written, written);
        match super::step::step(model, data) {
            Ok(()) if wanted => {
                let t = std::time::Instant::now();
                on_row(&data.record);
                observer += t.elapsed();
            }
            Ok(()) => {}
            Err(e) => {
                error = Some(e);
                break;
            }
        }
    }
    let wall = start.elapsed().saturating_sub(observer).as_secs_f64();
    data.want_record = true;
    data.whole_record = true;
    summary(data, wall, error, interrupted)
}

/// Whether this is a step of a period of `period` steps (`left` counts
/// the steps to the next one down, from 0 at the first).
#[inline]
fn countdown(left: &mut usize, period: usize) -> bool {
    let now = *left == 0;
    *left = if now { period - 1 } else { *left - 1 };
    now
}

/// The summary of a run that ended with `data` (its event lists move
/// into it).
fn summary<M: Engine>(
    data: &mut RunData<M>,
    wall: f64,
    error: Option<SimError>,
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
        evicted_patterns: data.solver.evicted_patterns(),
        events: std::mem::take(&mut data.events),
        error,
        limit_events: std::mem::take(&mut data.limit_events),
        retries: std::mem::take(&mut data.retries),
        resolved_cycles: data.resolved_cycles,
        enumerated_cycles: data.enumerated_cycles,
        rejected_solutions: data.rejected_solutions,
        newton_fallbacks: data.newton_fallbacks,
        abandoned_crawls: data.abandoned_crawls,
        substeps: data.substeps,
        direction_refinements: data.direction_refinements,
        backward_slides: data.backward_slides,
        max_law_violation: data.max_law_violation,
        interrupted,
    }
}

//! The staged step (see [`super`]) and its retry in substeps.
//!
//! **Retry in substeps.** A step that Newton cannot solve, or whose state
//! search finds no consistent combination (a cycle after the fallbacks),
//! is solved again from `q[k]` as 2, 4, 8, … substeps of `Δt/n`, down to
//! `Δt/max_substeps`, before the run fails. The substeps start from the
//! velocity of the last step (the previous configuration is taken at
//! `t_k − Δt/n` on the line `q[k−1] → q[k]`), keep the step's joint
//! torques, and the next full step continues from `q[k]` and `q[k+1]`: rows
//! stay on the Δt grid. Each retried step is a [`RetryEvent`]; its record
//! is the first substep's (forces at `t_k`) with the iterations and solves
//! of all of them. A step that cannot be solved exactly even at
//! `Δt/max_substeps` (its best solution breaks a contact or limit law,
//! [`super::search`]) ends the run with [`SimError::Inexact`], naming the
//! point and the law; the rows before it are kept. Before that, when the
//! solver runs the compiled LU (`NewtonParams::compiled_lu`), the same
//! ladder — the whole step, then 2, 4, … substeps — is tried once more
//! with faer's pivoting LU, the reference path
//! ([`RetryEvent::reference_lu`]): both solve the same systems to
//! round-off, and a hard step's state search can turn on round-off.

use super::search::{describe_states, solve, start_search, stick_failed_in_search};
use super::{Engine, RunData};
use crate::SimError;
use crate::record::{Event, LimitCode, LimitEvent, RetryEvent};
use crate::rules::Failure;
use fbd_contact::{ContactMode, StateCode};
use fbd_dynamics::History;

/// Solves step `data.k` (its record in `data.record`) and advances the
/// state to `k + 1`, retrying in substeps when the whole step cannot be
/// solved.
///
/// # Errors
/// A [`SimError`] naming the step and time: the controller's, or the
/// solver's or the state search's when every retry has failed.
pub fn step<M: Engine>(model: &M, data: &mut RunData<M>) -> Result<(), SimError> {
    let k = data.k;
    let t = k as f64 * model.dt();
    prepare(model, data)?;
    let steps_before = data.solver.steps_taken();
    let chords_before = data.solver.chord_steps_taken();
    let first = match solve(model, data) {
        Ok((iterations, trials)) => {
            count_iterations(data, steps_before, chords_before);
            record(model, data, iterations, trials, model.dt());
            let same = accept(model, data, t);
            model.accepted_whole(data);
            data.predictor.record(&data.z, same);
            data.k += 1;
            return Ok(());
        }
        Err(f) => f,
    };
    // Stages 1–5 leave the accepted state as it was: it is kept for the
    // retry only when one is needed.
    save_grid(data);
    data.failed_trial.copy_from_slice(&data.trial);
    data.failed_limits.copy_from_slice(&data.limit_trial);
    let mut last = first;
    let mut finest = 1;
    // The compiled LU's attempts, then (when every one failed) the same
    // ladder from the whole step with faer's reference LU: the two solve
    // the same systems to round-off, to which a hard step's state search
    // can be sensitive (see the module docs).
    let compiled = data.solver.params().compiled_lu;
    for (reference, start) in [(false, 2), (true, 1)] {
        if reference {
            if !compiled {
                break;
            }
            data.solver.params_mut().compiled_lu = false;
        }
        let mut n = start;
        while n <= model.max_substeps() {
            // Without exact rows, at the finest subdivision a cycling state
            // search is closed by its least inconsistent trial, whatever its
            // violation.
            data.last_resort = !model.exact() && n == model.max_substeps();
            let result = substeps(model, data, n);
            data.last_resort = false;
            finest = n;
            data.substeps += n;
            match result {
                Ok(iterations) => {
                    data.solver.params_mut().compiled_lu = compiled;
                    // The record holds the substeps' searches; the
                    // attempts that failed before them count too.
                    let all = count_iterations(data, steps_before, chords_before);
                    M::add_to_record(&mut data.record, all - iterations, 0);
                    data.retries.push(RetryEvent {
                        t,
                        step: k,
                        substeps: n,
                        cause: first.cause(),
                        reference_lu: reference,
                    });
                    data.k += 1;
                    return Ok(());
                }
                Err(f) => {
                    last = f;
                    restore_grid(model, data);
                    n *= 2;
                }
            }
        }
    }
    data.solver.params_mut().compiled_lu = compiled;
    // The run's totals hold the failed step's iterations too.
    count_iterations(data, steps_before, chords_before);
    // A step with no exact solution names the law its finest attempt
    // breaks; otherwise the whole step's failure is the error.
    let (failure, states, limits) = match last {
        Failure::Inexact { .. } => (last, &data.best_trial, &data.best_limits),
        _ => (first, &data.failed_trial, &data.failed_limits),
    };
    Err(failure.error(
        k,
        t,
        finest,
        || describe_states(model, states, limits),
        |i, limit| {
            if limit {
                model.limit_name(i)
            } else {
                model.contact_name(i).to_string()
            }
        },
    ))
}

/// Adds the Newton iterations the solver took since `steps_before`
/// (chord steps since `chords_before`) — every solve of the step, failed
/// attempts included — to the run's totals and its largest step; returns
/// them.
fn count_iterations<M: Engine>(
    data: &mut RunData<M>,
    steps_before: u64,
    chords_before: u64,
) -> usize {
    let steps = (data.solver.steps_taken() - steps_before) as usize;
    data.newton_iterations += steps;
    data.chord_iterations += (data.solver.chord_steps_taken() - chords_before) as usize;
    data.max_step_iterations = data.max_step_iterations.max(steps);
    steps
}

/// Stages 1–3 of [`step`]: the constants of step `data.k`, the joint
/// torques and the predictor of the unknowns in `data.z`; the trial states
/// start from the accepted ones. Public for benchmarks, which time the
/// stages one by one.
///
/// # Errors
/// A controller failure.
pub fn prepare<M: Engine>(model: &M, data: &mut RunData<M>) -> Result<(), SimError> {
    let dt = model.dt();
    let k = data.k;
    let history = if k == 0 {
        History::Initial {
            qdot: model.qdot0(),
        }
    } else {
        History::Previous
    };
    model.kinematics(data, history, dt);
    model.torques(data)?;
    if k == 0 {
        for ((z, &q), &v) in data.z.iter_mut().zip(&data.q).zip(model.qdot0()) {
            *z = q + dt * v;
        }
    } else {
        data.predictor.predict(&mut data.z);
    }
    start_search(data);
    Ok(())
}

/// The record of the solved (sub)step of length `h` when it is wanted.
fn record<M: Engine>(model: &M, data: &mut RunData<M>, iterations: usize, trials: usize, h: f64) {
    if data.want_record {
        model.make_record(data, iterations, trials, h);
    } else {
        model.skip_record(data, h);
    }
}

/// Stage 6: events (at time `t`, attributed to step `data.k`), the trial
/// states become the accepted ones and `q[k+1]` the current configuration.
/// `true` when every point and joint keeps its equations
/// ([`ContactMode::same_law`]): the predictor's history goes on.
fn accept<M: Engine>(model: &M, data: &mut RunData<M>, t: f64) -> bool {
    let k = data.k;
    for c in 0..model.contacts() {
        let (from, to) = (data.states[c].code(), data.trial[c].code());
        if from != to {
            let (leg, point) = model.contact_identity(c);
            data.events.push(Event {
                t,
                step: k,
                contact: c,
                point,
                leg,
                from,
                to,
            });
        }
    }
    for l in 0..model.limits() {
        let (from, to) = (
            LimitCode::of(&data.limit_states[l]),
            LimitCode::of(&data.limit_trial[l]),
        );
        if from != to {
            let info = model.limit(l);
            data.limit_events.push(LimitEvent {
                t,
                step: k,
                joint_index: info.joint_index,
                joint: info.joint,
                leg: info.leg,
                from,
                to,
            });
        }
    }
    // A point that slides on after its search tried sticking it (and
    // sticking needed more than μS·N), or that has slid on since, is not
    // tried again while its slip runs forward ([`super::search`]; the
    // exact models only).
    if model.exact() {
        for c in 0..model.contacts() {
            let slides = data.trial[c].code() == StateCode::St3;
            let failed = stick_failed_in_search(data.seen[c]);
            let kept = data.stick_refused[c] && data.states[c].code() == StateCode::St3;
            data.stick_refused[c] = slides && (failed || kept);
        }
    }
    let same = data
        .states
        .iter()
        .zip(&data.trial)
        .all(|(a, b)| a.same_law(b))
        && data.limit_states == data.limit_trial;
    data.states.copy_from_slice(&data.trial);
    data.limit_states.copy_from_slice(&data.limit_trial);
    // q[k−1] → q[k−2], q[k] → q[k−1] by swaps, then q[k+1].
    std::mem::swap(&mut data.q_prev2, &mut data.q_prev);
    std::mem::swap(&mut data.q_prev, &mut data.q);
    let nq = model.nq();
    data.q.copy_from_slice(&data.z[..nq]);
    model.advance(data);
    same
}

/// Keeps what an attempt in substeps may change (the accepted state, left
/// unchanged by the failed whole step), to start the next retry from it.
fn save_grid<M: Engine>(data: &mut RunData<M>) {
    data.grid_q.copy_from_slice(&data.q);
    data.grid_q_prev.copy_from_slice(&data.q_prev);
    data.grid_q_prev2.copy_from_slice(&data.q_prev2);
    data.grid_states.copy_from_slice(&data.states);
    data.grid_limits.copy_from_slice(&data.limit_states);
    data.grid_stick_refused.copy_from_slice(&data.stick_refused);
    data.grid_events = [data.events.len(), data.limit_events.len()];
}

/// Back to the start of the step after a failed attempt in substeps.
fn restore_grid<M: Engine>(model: &M, data: &mut RunData<M>) {
    data.q.copy_from_slice(&data.grid_q);
    data.q_prev.copy_from_slice(&data.grid_q_prev);
    data.q_prev2.copy_from_slice(&data.grid_q_prev2);
    data.states.copy_from_slice(&data.grid_states);
    data.limit_states.copy_from_slice(&data.grid_limits);
    data.stick_refused.copy_from_slice(&data.grid_stick_refused);
    data.events.truncate(data.grid_events[0]);
    data.limit_events.truncate(data.grid_events[1]);
    model.reset_kinematics(data);
}

/// Step `data.k` as `n` substeps of `Δt/n` (see the module docs); the
/// Newton iterations of all of them.
fn substeps<M: Engine>(model: &M, data: &mut RunData<M>, n: usize) -> Result<usize, Failure> {
    let nq = model.nq();
    let h = model.dt() / n as f64;
    let k = data.k;
    let t = k as f64 * model.dt();
    let mut total = 0;
    for i in 0..n {
        let history = if k == 0 && i == 0 {
            History::Initial {
                qdot: model.qdot0(),
            }
        } else {
            History::Previous
        };
        if i == 0 && k > 0 {
            // The previous configuration at t_k − h, on the line q[k−1] → q[k].
            for j in 0..nq {
                data.q_prev[j] = data.q[j] - (data.q[j] - data.grid_q_prev[j]) / n as f64;
            }
            model.set_previous(data);
        }
        model.kinematics(data, history, h);
        let z = data.z[..nq].iter_mut().zip(&data.q);
        if k == 0 && i == 0 {
            for ((z, &q), &v) in z.zip(model.qdot0()) {
                *z = q + h * v;
            }
        } else {
            for ((z, &q), &p) in z.zip(&data.q_prev) {
                *z = 2.0 * q - p;
            }
        }
        start_search(data);
        let (iterations, trials) = solve(model, data)?;
        total += iterations;
        if i == 0 {
            record(model, data, iterations, trials, h);
        } else {
            M::add_to_record(&mut data.record, iterations, trials);
        }
        let _ = accept(model, data, t + i as f64 * h);
    }
    // Back on the grid: the next full step continues from q[k] and q[k+1];
    // the predictor records the step (not its substeps) as a break of its
    // history.
    data.q_prev.copy_from_slice(&data.grid_q);
    data.q_prev2.copy_from_slice(&data.grid_q_prev);
    data.predictor.record(&data.z, false);
    model.set_previous(data);
    Ok(total)
}

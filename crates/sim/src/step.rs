//! One time step, in stages:
//!
//! 1. **kinematics at k**: the per-body constants of the second differences;
//! 2. **joint torques at k**: the controller's torques from `q[k]`, `q[k−1]`
//!    ([`crate::control`]);
//! 3. **predictor**: a starting guess for `q[k+1]` (forces from the last step);
//! 4. **solve**: Newton on the FBD equations with the current contact and
//!    joint-limit states;
//! 5. **state check**: every contact point's switching rule and every joint
//!    limit's on the trial solution (touchdowns and limit arrivals all at
//!    once, other switches one at a time, see [`check_states`]); any switch
//!    → back to 4. A repeated state combination means no combination the
//!    rules reach is consistent; before giving up, a point that flip-flopped
//!    between ST1 (it penetrates when free) and ST2 (it would pull on the
//!    ground when stuck) is tried in ST3, sliding opposite to the friction
//!    sticking needed — the remaining candidate of Coulomb's law
//!    ([`slide_flip_flops`]). If it still cycles, every combination of
//!    the few points and joint limits involved is solved in turn and the
//!    first consistent one is taken ([`enumerate_states`]): the greedy
//!    rules, one switch at a time, can miss a consistent combination that
//!    is two switches away (a foot that slides *and* a knee that leaves its
//!    stop);
//! 6. **accept**: record, events, and `q[k+1]` becomes the current state.
//!
//! **Retry in substeps.** A step that Newton cannot solve, or whose state
//! search finds no consistent combination (a cycle after the fallback), is
//! solved again from `q[k]` as 2, 4, 8, … substeps of `Δt/n`, down to
//! `Δt/`[`Model::max_substeps`], before the run fails. The substeps start
//! from the velocity of the last step (the previous configuration is taken
//! at `t_k − Δt/n` on the line `q[k−1] → q[k]`), keep the step's joint
//! torques, and the next full step continues from `q[k]` and `q[k+1]`: rows
//! stay on the Δt grid. Each retried step is a [`RetryEvent`].
//!
//! **Joint limits** are one-sided, plastic stops (`fbd_dynamics::assemble`):
//! a free joint whose trial angle crosses an end of its range is held at
//! that end; a joint at an end is released when the stop's moment would
//! pull it there instead of pushing it away.

use crate::energy;
use crate::record::{
    Event, LimitCode, LimitEvent, MAX_CONTACTS, MAX_JOINTS, RetryEvent, StepRecord,
};
use crate::rules::{Failure, MAX_STATE_TRIALS, limit_arrival, limit_release, regularization};
pub use crate::system::StepSystem;
use crate::system::row_scales;
use crate::{Data, Model, SimError};
use fbd_contact::{ContactState, Trial, transition};
use fbd_dynamics::{
    ContactEquation, History, LimitEquation, LimitState, advance, evaluate_next, prepare_step,
};
use fbd_solver::NewtonSolver;

/// Solves step `data.k` and advances the state to `k + 1`, retrying in
/// substeps when the whole step cannot be solved (see the module docs).
pub fn step(model: &Model, data: &mut Data) -> Result<StepRecord, SimError> {
    let k = data.k;
    let t = k as f64 * model.dt();
    save_grid(data);
    prepare(model, data);
    let first = match solve(model, data) {
        Ok((iterations, trials)) => {
            data.max_step_iterations = data.max_step_iterations.max(iterations);
            let record = make_record(model, data, iterations, trials, model.dt());
            let same = accept(model, data, t);
            data.predictor.record(&data.z, same);
            data.k += 1;
            return Ok(record);
        }
        Err(f) => f,
    };
    data.failed_trial.copy_from_slice(&data.trial);
    data.failed_limits.copy_from_slice(&data.limit_trial);
    let mut n = 2;
    while n <= model.max_substeps {
        // At the finest subdivision a cycling state search is closed by
        // its least inconsistent trial, whatever its violation.
        data.last_resort = n == model.max_substeps;
        let result = substeps(model, data, n);
        data.last_resort = false;
        match result {
            Ok(record) => {
                data.max_step_iterations = data.max_step_iterations.max(record.newton_iterations);
                data.retries.push(RetryEvent {
                    t,
                    step: k,
                    substeps: n,
                    cause: first.cause(),
                });
                data.k += 1;
                return Ok(record);
            }
            Err(_) => {
                restore_grid(model, data);
                n *= 2;
            }
        }
    }
    Err(first.error(k, t, || {
        describe_states(model, &data.failed_trial, &data.failed_limits)
    }))
}

/// Stages 4–5: solves the current (sub)step until its contact and limit
/// states are consistent. Returns the Newton iterations and the number of
/// solves.
fn solve(model: &Model, data: &mut Data) -> Result<(usize, usize), Failure> {
    let nq = model.mech.layout().nq;
    let mut fallback_used = false;
    let mut newton_iterations = 0;
    let mut trials = 0;
    loop {
        trials += 1;
        let (mut sys, solver, z) = system(model, data);
        let report = solver.solve(&mut sys, z).map_err(Failure::Newton)?;
        newton_iterations += report.iterations;
        data.chord_iterations += report.chord_iterations;
        if data.z.iter().any(|v| !v.is_finite()) {
            return Err(Failure::NonFinite {
                residual: report.residual,
            });
        }
        evaluate_next(&model.mech, &mut data.fbd, &data.z[..nq]);
        let v = violation(model, data);
        if v < data.best_violation {
            data.best_violation = v;
            data.best_z.copy_from_slice(&data.z);
            data.best_trial.copy_from_slice(&data.trial);
            data.best_limits.copy_from_slice(&data.limit_trial);
        }
        if !check_states(model, data) {
            break;
        }
        let mut key = states_key(data);
        if data.visited.contains(&key) && !fallback_used {
            fallback_used = true;
            if slide_flip_flops(data) {
                data.visited.clear();
                key = states_key(data);
            }
        }
        if data.visited.contains(&key) || trials >= MAX_STATE_TRIALS {
            // No combination the rules reach is consistent: every
            // combination of the points and limits involved is tried
            // (when they are few), then the one that violates the contact
            // and limit laws least is accepted when its violation is
            // negligible.
            if enumerate_states(model, data, &mut newton_iterations, &mut trials) {
                data.enumerated_cycles += 1;
                break;
            }
            if data.best_violation <= model.cycle_tolerance || data.last_resort {
                data.z.copy_from_slice(&data.best_z);
                data.trial.copy_from_slice(&data.best_trial);
                data.limit_trial.copy_from_slice(&data.best_limits);
                evaluate_next(&model.mech, &mut data.fbd, &data.z[..nq]);
                data.resolved_cycles += 1;
                break;
            }
            return Err(Failure::Cycle {
                residual: report.residual,
            });
        }
        data.visited.push(key);
    }
    data.newton_iterations += newton_iterations;
    Ok((newton_iterations, trials))
}

/// Stage 6: events (at time `t`, attributed to step `data.k`), the trial
/// states become the accepted ones and `q[k+1]` the current configuration.
/// `true` when the states did not change.
fn accept(model: &Model, data: &mut Data, t: f64) -> bool {
    let mech = &model.mech;
    let k = data.k;
    for c in 0..mech.contacts.len() {
        let (from, to) = (data.states[c].code(), data.trial[c].code());
        if from != to {
            data.events.push(Event {
                t,
                step: k,
                contact: c,
                point: model.contact_point[c],
                leg: model.contact_leg[c],
                from,
                to,
            });
        }
    }
    for (l, &j) in mech.limits.iter().enumerate() {
        let (from, to) = (
            LimitCode::of(&data.limit_states[l]),
            LimitCode::of(&data.limit_trial[l]),
        );
        if from != to {
            data.limit_events.push(LimitEvent {
                t,
                step: k,
                joint_index: j,
                joint: model.limit_joint[l],
                leg: model.limit_leg[l],
                from,
                to,
            });
        }
    }
    let same = data.states == data.trial && data.limit_states == data.limit_trial;
    data.states.copy_from_slice(&data.trial);
    data.limit_states.copy_from_slice(&data.limit_trial);
    std::mem::swap(&mut data.q_prev2, &mut data.q_prev);
    data.q_prev.copy_from_slice(&data.q);
    let nq = mech.layout().nq;
    data.q.copy_from_slice(&data.z[..nq]);
    advance(mech, &mut data.fbd);
    same
}

/// Keeps what a failed attempt may change, to start the retry from it.
fn save_grid(data: &mut Data) {
    data.grid_q.copy_from_slice(&data.q);
    data.grid_q_prev.copy_from_slice(&data.q_prev);
    data.grid_q_prev2.copy_from_slice(&data.q_prev2);
    data.grid_states.copy_from_slice(&data.states);
    data.grid_limits.copy_from_slice(&data.limit_states);
    data.grid_events = [data.events.len(), data.limit_events.len()];
}

/// Back to the start of the step after a failed attempt in substeps.
fn restore_grid(model: &Model, data: &mut Data) {
    let chains = &model.mech.chains;
    data.q.copy_from_slice(&data.grid_q);
    data.q_prev.copy_from_slice(&data.grid_q_prev);
    data.q_prev2.copy_from_slice(&data.grid_q_prev2);
    data.states.copy_from_slice(&data.grid_states);
    data.limit_states.copy_from_slice(&data.grid_limits);
    data.events.truncate(data.grid_events[0]);
    data.limit_events.truncate(data.grid_events[1]);
    chains.eval_positions(&data.grid_q, &mut data.fbd.kin);
    chains.eval_jacobians(&mut data.fbd.kin);
    chains.eval_positions(&data.grid_q_prev, &mut data.fbd.kin_prev);
}

/// Step `data.k` as `n` substeps of `Δt/n` (see the module docs). The
/// record is that of the first substep (forces at `t_k`), with the
/// iterations and solves of all of them.
fn substeps(model: &Model, data: &mut Data, n: usize) -> Result<StepRecord, Failure> {
    let mech = &model.mech;
    let nq = mech.layout().nq;
    let h = model.dt() / n as f64;
    let k = data.k;
    let t = k as f64 * model.dt();
    let mut record = None;
    for i in 0..n {
        let history = if k == 0 && i == 0 {
            History::Initial {
                qdot: &model.params.qdot0,
            }
        } else {
            History::Previous
        };
        if i == 0 && k > 0 {
            // The previous configuration at t_k − h, on the line q[k−1] → q[k].
            for j in 0..nq {
                data.q_prev[j] = data.q[j] - (data.q[j] - data.grid_q_prev[j]) / n as f64;
            }
            mech.chains
                .eval_positions(&data.q_prev, &mut data.fbd.kin_prev);
        }
        prepare_step(mech, &mut data.fbd, history, h);
        for j in 0..nq {
            data.z[j] = if k == 0 && i == 0 {
                data.q[j] + h * model.params.qdot0[j]
            } else {
                2.0 * data.q[j] - data.q_prev[j]
            };
        }
        start_search(data);
        let (iterations, trials) = solve(model, data)?;
        match record.as_mut() {
            None => record = Some(make_record(model, data, iterations, trials, h)),
            Some(r) => {
                r.newton_iterations += iterations;
                r.state_trials += trials;
            }
        }
        let _ = accept(model, data, t + i as f64 * h);
    }
    // Back on the grid: the next full step continues from q[k] and q[k+1];
    // the predictor records the step (not its substeps) as a break of its
    // history.
    data.q_prev.copy_from_slice(&data.grid_q);
    data.q_prev2.copy_from_slice(&data.grid_q_prev);
    data.predictor.record(&data.z, false);
    mech.chains
        .eval_positions(&data.grid_q, &mut data.fbd.kin_prev);
    Ok(record.expect("at least two substeps"))
}

/// The cycle fallback of stage 5: every point that was solved in both ST1
/// and ST2 during this step's search (and is not sliding) is set to ST3,
/// sliding opposite to the friction its last sticking trial needed. `true`
/// if any point was changed.
fn slide_flip_flops(data: &mut Data) -> bool {
    let mut forced = false;
    for (c, state) in data.trial.iter_mut().enumerate() {
        if data.seen[c] & 0b11 == 0b11 && !matches!(state, ContactState::Slide { .. }) {
            *state = ContactState::Slide {
                dir: -data.stick_fa[c].signum(),
            };
            forced = true;
        }
    }
    forced
}

/// Most contact points and joint limits [`enumerate_states`] combines.
const MAX_INVOLVED: usize = 4;

/// Most combinations (one solve each) [`enumerate_states`] tries: 4 states
/// of 3 points, or of 2 points and 2 stops on/off.
const MAX_ENUMERATED: usize = 64;

/// The cycle's exhaustive fallback (stage 5): the points involved in this
/// step's search (solved in more than one state, or not free in the
/// accepted or least inconsistent combination) each take ST1, ST2 (at the
/// anchor of its last sticking trial, if it had one), ST3 forwards and
/// ST3 backwards; the joint limits involved (at a stop in the accepted,
/// least inconsistent or current combination) are free or at that stop;
/// every other point is free and every other joint limit free. The
/// combinations are solved in a fixed order and the first whose violation
/// of the contact and limit laws ([`violation`]) is at most
/// [`Model::cycle_tolerance`] is kept in `data` (`true`). `false` when none
/// is, or when there are too many to try ([`MAX_ENUMERATED`]); the least
/// inconsistent trial is updated either way. No allocation.
fn enumerate_states(
    model: &Model,
    data: &mut Data,
    newton_iterations: &mut usize,
    trials: &mut usize,
) -> bool {
    let nq = model.mech.layout().nq;
    let mut points = [0usize; MAX_INVOLVED];
    let mut np = 0;
    for c in 0..data.trial.len() {
        let involved = data.seen[c].count_ones() >= 2
            || !matches!(data.states[c], ContactState::Free)
            || !matches!(data.best_trial[c], ContactState::Free);
        if involved {
            if np == MAX_INVOLVED {
                return false;
            }
            points[np] = c;
            np += 1;
        }
    }
    let mut stops = [(0usize, LimitState::Free); MAX_INVOLVED];
    let mut ns = 0;
    for l in 0..data.limit_trial.len() {
        let at = [
            data.best_limits[l],
            data.limit_trial[l],
            data.limit_states[l],
        ]
        .into_iter()
        .find(LimitState::is_at);
        if let Some(at) = at {
            if ns == MAX_INVOLVED {
                return false;
            }
            stops[ns] = (l, at);
            ns += 1;
        }
    }
    let combinations = 4usize.pow(np as u32) << ns;
    if combinations > MAX_ENUMERATED {
        return false;
    }
    for combo in 0..combinations {
        let mut m = combo;
        data.trial.fill(ContactState::Free);
        data.limit_trial.fill(LimitState::Free);
        let mut possible = true;
        for &c in &points[..np] {
            data.trial[c] = match m % 4 {
                0 => ContactState::Free,
                1 if data.seen[c] & 0b10 != 0 => ContactState::Stick {
                    anchor: data.stick_anchor[c],
                },
                1 => {
                    possible = false;
                    ContactState::Free
                }
                2 => ContactState::Slide { dir: 1.0 },
                _ => ContactState::Slide { dir: -1.0 },
            };
            m /= 4;
        }
        for &(l, at) in &stops[..ns] {
            if m % 2 == 1 {
                data.limit_trial[l] = at;
            }
            m /= 2;
        }
        if !possible {
            continue;
        }
        data.z.copy_from_slice(&data.best_z);
        *trials += 1;
        let (mut sys, solver, z) = system(model, data);
        let Ok(report) = solver.solve(&mut sys, z) else {
            continue;
        };
        *newton_iterations += report.iterations;
        data.chord_iterations += report.chord_iterations;
        if data.z.iter().any(|v| !v.is_finite()) {
            continue;
        }
        evaluate_next(&model.mech, &mut data.fbd, &data.z[..nq]);
        let v = violation(model, data);
        if v < data.best_violation {
            data.best_violation = v;
            data.best_z.copy_from_slice(&data.z);
            data.best_trial.copy_from_slice(&data.trial);
            data.best_limits.copy_from_slice(&data.limit_trial);
        }
        if v <= model.cycle_tolerance {
            return true;
        }
    }
    false
}

/// Stages 1–3 of [`step`]: the per-body constants of step `data.k` and the
/// predictor of the unknowns in `data.z`; the trial contact and limit
/// states start from the accepted ones. Public for benchmarks, which time
/// the stages one by one.
pub fn prepare(model: &Model, data: &mut Data) {
    let mech = &model.mech;
    let dt = model.dt();
    let k = data.k;
    let history = if k == 0 {
        History::Initial {
            qdot: &model.params.qdot0,
        }
    } else {
        History::Previous
    };
    prepare_step(mech, &mut data.fbd, history, dt);

    // 2. Joint torques at k (explicit, from q[k] and q[k−1]).
    crate::control::joint_torques(model, data);

    // 3. Predictor ([`crate::predictor`]); the initial velocity at k = 0.
    if k == 0 {
        let nq = mech.layout().nq;
        for i in 0..nq {
            data.z[i] = data.q[i] + dt * model.params.qdot0[i];
        }
    } else {
        data.predictor.predict(&mut data.z);
    }
    start_search(data);
}

/// The state search starts from the accepted states.
fn start_search(data: &mut Data) {
    data.best_violation = f64::INFINITY;
    data.trial.copy_from_slice(&data.states);
    data.limit_trial.copy_from_slice(&data.limit_states);
    data.visited.clear();
    let key = states_key(data);
    data.visited.push(key);
    data.seen.fill(0);
}

/// Stage 4's inputs for the current trial states (contact and limit
/// equations, row scales), split from `data`: the step's
/// [`NewtonSystem`](fbd_solver::NewtonSystem), the solver and the unknowns
/// `z`. Public for benchmarks.
pub fn system<'a>(
    model: &'a Model,
    data: &'a mut Data,
) -> (StepSystem<'a>, &'a mut NewtonSolver, &'a mut [f64]) {
    set_contact_equations(model, data);
    for (eq, &state) in data.fbd.limit.iter_mut().zip(&data.limit_trial) {
        *eq = LimitEquation {
            state,
            regularization: beta(model, data.fbd.dt),
        };
    }
    row_scales(
        &model.mech,
        &data.fbd,
        data.q[0].abs().max(data.q[1].abs()),
        &mut data.scales,
        &mut data.weights,
    );
    let sys = StepSystem {
        mech: &model.mech,
        terrain: &model.params.terrain,
        fbd: &mut data.fbd,
        scales: &data.scales,
        weights: &data.weights,
    };
    (sys, &mut data.solver, &mut data.z)
}

/// The equations of each contact point for its trial state: the terrain
/// frame at the anchor (ST2), under the point at k (ST1, ST3).
fn set_contact_equations(model: &Model, data: &mut Data) {
    let terrain = &model.params.terrain;
    let beta = beta(model, data.fbd.dt);
    for (c, spec) in model.mech.contacts.iter().enumerate() {
        let state = data.trial[c];
        let x = match state {
            ContactState::Stick { anchor } => anchor[0],
            _ => data.fbd.kin.pos[spec.point][0],
        };
        let (tangent, normal) = terrain.frame(x);
        data.fbd.contact[c] = ContactEquation {
            state,
            tangent,
            normal,
            mu_dynamic: model.params.friction.mu_dynamic,
            regularization: beta + model.contact_bumper[c],
        };
    }
}

/// The regularisation β of the contact and stop rows for a (sub)step of
/// length `h` ([`crate::rules::regularization`]).
fn beta(model: &Model, h: f64) -> f64 {
    regularization(model.contact.regularization, h)
}

/// Applies the switching rules to the trial solution; `true` if any point
/// or joint limit switched. Every touchdown (ST1 → ST2) and every joint
/// reaching a limit is applied at once: a point that penetrates must carry
/// a force, a joint past its end must be stopped. Of the other switches —
/// lift-off, limit release, the start or end of a slide — only the most
/// violated one is applied before re-solving, since one of them changes
/// the forces on all the others (at an impact of several points, switching
/// them all together chases its tail): lift-offs and releases first (most
/// negative `N`, or stop moment over the length scale), then slips
/// (largest `|Fa| − μS·N`), then slide reversals.
fn check_states(model: &Model, data: &mut Data) -> bool {
    let lay = model.mech.layout();
    let dt = data.fbd.dt;
    let mut touchdown = false;
    let mut best: Option<(usize, ContactState, f64)> = None;
    for (c, spec) in model.mech.contacts.iter().enumerate() {
        let eq = &data.fbd.contact[c];
        let trial = Trial {
            p_k: data.fbd.kin.pos[spec.point],
            p_next: data.fbd.kin_next.pos[spec.point],
            fa: data.z[lay.contact_fa(c)],
            n: data.z[lay.contact_n(c)],
            tangent: eq.tangent,
            dt,
        };
        data.seen[c] |= 1 << data.trial[c].key().min(2);
        if let ContactState::Stick { anchor } = data.trial[c] {
            data.stick_fa[c] = trial.fa;
            data.stick_anchor[c] = anchor;
        }
        let Some(next) = transition(
            &data.trial[c],
            &trial,
            &model.params.terrain,
            &model.params.friction,
            &model.contact,
        ) else {
            continue;
        };
        // docs/reference.md: ST3 → ST2 needs the reversal *and* |Fa| ≤ μS·N; a point
        // that already tried sticking in this search and had to slide again
        // stays sliding at the friction limit.
        let stick_failed = data.seen[c] & 0b110 == 0b110;
        if stick_failed
            && matches!(data.trial[c], ContactState::Slide { .. })
            && matches!(next, ContactState::Stick { .. })
        {
            continue;
        }
        // Priority: lift-off > slip > slide reversal, then the violation.
        let priority = match (data.trial[c], next) {
            (ContactState::Free, _) => {
                data.trial[c] = next;
                touchdown = true;
                continue;
            }
            (_, ContactState::Free) => 2e12 - trial.n,
            (ContactState::Stick { .. }, _) => {
                1e12 + trial.fa.abs() - model.params.friction.mu_static * trial.n
            }
            _ => 0.0,
        };
        if best.is_none_or(|b| priority > b.2) {
            best = Some((c, next, priority));
        }
    }
    // Joint limits: arrivals at once, a release competes with lift-offs.
    let length = data.fbd.length_scale;
    let mut release: Option<(usize, f64)> = None;
    for (l, &j) in model.mech.limits.iter().enumerate() {
        let angle = data.z[model.mech.joints[j].q_index];
        let joint = model.limit_joint[l];
        let state = data.limit_trial[l];
        if !state.is_at() {
            if let Some(at) = limit_arrival(&model.params.joint_limits, joint, angle) {
                data.limit_trial[l] = at;
                touchdown = true;
            }
        } else if let Some(priority) = limit_release(
            &state,
            data.z[lay.limit_moment(l)],
            length,
            model.contact.force_tol,
        ) && best.is_none_or(|b| priority > b.2)
            && release.is_none_or(|r| priority > r.1)
        {
            release = Some((l, priority));
        }
    }
    if !touchdown {
        if let Some((l, priority)) = release
            && best.is_none_or(|b| priority > b.2)
        {
            data.limit_trial[l] = LimitState::Free;
            return true;
        }
        let Some((c, next, _)) = best else {
            return false;
        };
        // A point that slid, tried sticking and must slide again is locked in
        // ST3 from now on (see above): the search has learnt something, and
        // returning to an earlier combination is no longer a cycle.
        if data.seen[c] & 0b100 != 0
            && matches!(data.trial[c], ContactState::Stick { .. })
            && matches!(next, ContactState::Slide { .. })
        {
            data.visited.clear();
        }
        data.trial[c] = next;
    }
    rigid_anchors(model, data);
    true
}

/// Anchors of points that share a rigid body. docs/reference.md anchors a touchdown
/// where the point's straight path `p[k] → p[k+1]` crosses the terrain; for
/// two points of one body (a knee and a foot of one link, both hips) two
/// such anchors are not a rigid placement — their distance differs from the
/// points' by the body's motion during the step — and sticking at both
/// would tear the body apart. So on each body, the first point to stick
/// keeps its anchor (an already sticking point, or else the first point
/// anchored now, which keeps the contract's crossing), and every other point
/// anchored now is placed on the terrain at its rigid distance from that
/// reference, on its side. A point alone on its body — every foot of the
/// paper's model — is untouched.
fn rigid_anchors(model: &Model, data: &mut Data) {
    let mech = &model.mech;
    for body in 0..mech.bodies.len() {
        let on_body = || (0..mech.contacts.len()).filter(move |&c| mech.contacts[c].body == body);
        let fresh = |data: &Data, c: usize| {
            matches!(data.trial[c], ContactState::Stick { .. })
                && !matches!(data.states[c], ContactState::Stick { .. })
        };
        let kept = on_body()
            .find(|&c| matches!(data.trial[c], ContactState::Stick { .. }) && !fresh(data, c));
        let Some(reference) = kept.or_else(|| on_body().find(|&c| fresh(data, c))) else {
            continue;
        };
        let ContactState::Stick { anchor: from } = data.trial[reference] else {
            unreachable!("the reference sticks")
        };
        let p_ref = data.fbd.kin.pos[mech.contacts[reference].point];
        for c in on_body() {
            if c == reference || !fresh(data, c) {
                continue;
            }
            let p = data.fbd.kin.pos[mech.contacts[c].point];
            let dist = (p[0] - p_ref[0]).hypot(p[1] - p_ref[1]);
            let anchor = model
                .params
                .terrain
                .point_at_distance(from, dist, p[0] - p_ref[0]);
            data.trial[c] = ContactState::Stick { anchor };
        }
    }
}

/// How far the trial solution is from satisfying the law of the state it
/// was solved in, as a force (N): penetration of a free point or crossing
/// of a free joint (times the position gain), a pulling contact or stop,
/// friction beyond μS·N when sticking, a slide running backwards. The
/// largest over all points and limits; 0 for a consistent solution.
fn violation(model: &Model, data: &Data) -> f64 {
    let mech = &model.mech;
    let lay = mech.layout();
    let k = data.fbd.position_gain;
    let length = data.fbd.length_scale;
    let mu = model.params.friction.mu_static;
    let mut worst: f64 = 0.0;
    for (c, spec) in mech.contacts.iter().enumerate() {
        let (fa, n) = (data.z[lay.contact_fa(c)], data.z[lay.contact_n(c)]);
        let p_k = data.fbd.kin.pos[spec.point];
        let p_next = data.fbd.kin_next.pos[spec.point];
        let v = match data.trial[c] {
            ContactState::Free => k * (-model.params.terrain.clearance(p_next)).max(0.0),
            ContactState::Stick { .. } => (-n).max(0.0) + (fa.abs() - mu * n).max(0.0),
            ContactState::Slide { dir } => {
                let t = data.fbd.contact[c].tangent;
                let along = (p_next[0] - p_k[0]) * t[0] + (p_next[1] - p_k[1]) * t[1];
                (-n).max(0.0) + k * (-along * dir).max(0.0)
            }
        };
        worst = worst.max(v);
    }
    for (l, &j) in mech.limits.iter().enumerate() {
        let angle = data.z[mech.joints[j].q_index];
        let v = match data.limit_trial[l] {
            LimitState::Free => {
                let [lo, hi] = model.params.joint_limits.range(model.limit_joint[l]);
                data.fbd.limit_gain / length * (lo - angle).max(angle - hi).max(0.0)
            }
            LimitState::At { side, .. } => {
                (-side.sign() * data.z[lay.limit_moment(l)] / length).max(0.0)
            }
        };
        worst = worst.max(v);
    }
    worst
}

/// The trial states of contacts (4 each, with the slide direction) and
/// joint limits (3 each) as one number, for cycle detection.
fn states_key(data: &Data) -> u64 {
    let k = data.trial.iter().fold(0, |k, s| k * 4 + s.key());
    data.limit_trial.iter().fold(k, |k, s| k * 3 + s.key())
}

fn describe_states(model: &Model, states: &[ContactState], limits: &[LimitState]) -> String {
    let mut parts: Vec<String> = model
        .mech
        .contacts
        .iter()
        .zip(states)
        .map(|(c, s)| format!("{}={}", c.name, s.code()))
        .collect();
    for (l, s) in limits.iter().enumerate() {
        if s.is_at() {
            let j = &model.mech.joints[model.mech.limits[l]];
            parts.push(format!("{}={}", j.name, LimitCode::of(s).as_str()));
        }
    }
    parts.join(" ")
}

fn make_record(
    model: &Model,
    data: &Data,
    newton_iterations: usize,
    state_trials: usize,
    h: f64,
) -> StepRecord {
    let mech = &model.mech;
    let lay = mech.layout();
    let nc = mech.contacts.len().min(MAX_CONTACTS);
    let mut r = StepRecord::zeroed(data.k, data.k as f64 * model.dt(), nc);
    r.potential = energy::potential(mech, &data.fbd.kin);
    r.newton_iterations = newton_iterations;
    r.state_trials = state_trials;
    r.q.copy_from_slice(&data.q[..7]);
    for c in 0..nc {
        r.point[c] = data.fbd.kin.pos[mech.contacts[c].point];
        r.state[c] = data.trial[c].code();
        r.fa[c] = data.z[lay.contact_fa(c)];
        r.n[c] = data.z[lay.contact_n(c)];
    }
    for j in 0..lay.joints.min(MAX_JOINTS) {
        r.joint_force[j] = [data.z[lay.joint_force(j, 0)], data.z[lay.joint_force(j, 1)]];
        r.torque[j] = data.fbd.torque[j];
    }
    for (l, &j) in mech.limits.iter().enumerate() {
        if j < MAX_JOINTS {
            r.limit[j] = LimitCode::of(&data.limit_trial[l]);
            r.limit_moment[j] = data.z[lay.limit_moment(l)];
        }
    }
    r.kinetic = if data.k == 0 {
        energy::kinetic_exact(mech, &data.fbd.kin, &model.params.qdot0)
    } else {
        energy::kinetic_central(mech, &data.fbd.kin_prev, &data.fbd.kin_next, h)
    };
    r
}

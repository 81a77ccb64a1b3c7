//! One spatial time step, in the stages of the planar step
//! ([`crate::step`]), with the same rules:
//!
//! 1. **kinematics at k** — every body's constants, the constraint
//!    directions ([`fbd_dynamics::spatial::prepare_step`]);
//! 2. **joint torques at k** ([`super::control`]);
//! 3. **predictor** — [`crate::predictor`] (the initial velocity at k = 0);
//! 4. **solve** — Newton on the FBD equations with the trial contact and
//!    limit states;
//! 5. **state check** — every touchdown and limit arrival at once, the most
//!    violated other switch (lift-off/release, then slip, then the end of a
//!    slide) one at a time ([`fbd_contact::spatial`]); back to 4 until no
//!    point switches. A repeated combination is a cycle: a point that
//!    flip-flopped between ST1 and ST2 is tried in ST3, then the least
//!    inconsistent combination is taken if its violation is negligible;
//! 6. **accept** — record, events, `q[k+1]` becomes the current state; a
//!    sliding point's reference direction becomes the step's slip
//!    direction.
//!
//! A step that cannot be solved is retried as 2, 4, … substeps down to
//! `Δt/max_substeps`, exactly as in the planar model.

use super::control::{joint_rates, joint_torques};
use super::data::SpatialData;
use super::model::SpatialModel;
use crate::SimError;
use crate::record::{Event, LimitCode, LimitEvent, RetryEvent};
use crate::rules::{Failure, MAX_STATE_TRIALS, Sink, limit_arrival, limit_release, regularization};
use fbd_contact::spatial::{clearance, frame, point_at_distance, project};
use fbd_contact::{SpatialState, SpatialTrial, transition_spatial};
use fbd_dynamics::spatial::{
    SpatialContactEquation, SpatialFbdData, SpatialMechanism, advance, eval, evaluate_next,
    half_momentum_and_rotation, pattern, pattern_key, prepare_step, set_previous,
};
use fbd_dynamics::{History, LimitEquation, LimitState, NoJacobian};
use fbd_kinematics::nalgebra::Vector3;
use fbd_solver::{NewtonSolver, NewtonSystem};

/// One spatial step's equations as a [`NewtonSystem`].
pub struct SpatialSystem<'a> {
    mech: &'a SpatialMechanism,
    surface: &'a fbd_contact::Surface,
    fbd: &'a mut SpatialFbdData,
    scales: &'a [f64],
}

impl NewtonSystem for SpatialSystem<'_> {
    fn dim(&self) -> usize {
        self.mech.layout().dim()
    }
    fn pattern_key(&self) -> u64 {
        pattern_key(self.fbd)
    }
    fn pattern(&self, entries: &mut Vec<(usize, usize)>) {
        pattern(self.mech, self.fbd, entries);
    }
    fn eval(&mut self, x: &[f64], r: &mut [f64], jac: Option<&mut fbd_solver::JacobianSink<'_>>) {
        match jac {
            Some(j) => eval(self.mech, self.surface, self.fbd, x, r, &mut Sink(j)),
            None => eval(self.mech, self.surface, self.fbd, x, r, &mut NoJacobian),
        }
    }
    fn residual_scale(&self, row: usize) -> f64 {
        self.scales[row]
    }
}

/// Solves step `data.k` (its record in `data.record`) and advances to
/// `k + 1`, retrying in substeps when the whole step cannot be solved.
///
/// # Errors
/// A [`SimError`] naming the step and time.
pub fn step(model: &SpatialModel, data: &mut SpatialData) -> Result<(), SimError> {
    let k = data.k;
    let t = k as f64 * model.dt();
    save_grid(data);
    prepare(model, data)?;
    let first = match solve(model, data) {
        Ok((iterations, trials)) => {
            make_record(model, data, iterations, trials, model.dt());
            let same = accept(model, data, t);
            data.fbd.l_carry_valid = true;
            data.predictor.record(&data.z, same);
            data.k += 1;
            return Ok(());
        }
        Err(f) => f,
    };
    data.failed_trial.copy_from_slice(&data.trial);
    let mut n = 2;
    while n <= model.max_substeps {
        data.last_resort = n == model.max_substeps;
        let result = substeps(model, data, n);
        data.last_resort = false;
        match result {
            Ok(()) => {
                data.retries.push(RetryEvent {
                    t,
                    step: k,
                    substeps: n,
                    cause: first.cause(),
                });
                data.k += 1;
                return Ok(());
            }
            Err(_) => {
                restore_grid(model, data);
                n *= 2;
            }
        }
    }
    Err(first.error(k, t, || describe_states(model, &data.failed_trial)))
}

/// Stages 1–3: constants, torques, predictor; the search starts from the
/// accepted states.
///
/// # Errors
/// A controller failure.
pub fn prepare(model: &SpatialModel, data: &mut SpatialData) -> Result<(), SimError> {
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
    joint_torques(model, data)?;
    // The initial velocity at k = 0, then the shared predictor.
    if k == 0 {
        for i in 0..model.nq() {
            data.z[i] = data.q[i] + dt * model.params.qdot0[i];
        }
    } else {
        data.predictor.predict(&mut data.z);
    }
    start_search(data);
    Ok(())
}

fn start_search(data: &mut SpatialData) {
    data.start_z.copy_from_slice(&data.z);
    data.fbd.fixed_direction.fill(false);
    data.best_violation = f64::INFINITY;
    data.trial.copy_from_slice(&data.states);
    data.limit_trial.copy_from_slice(&data.limit_states);
    data.visited.clear();
    let key = states_key(data);
    data.visited.push(key);
    data.seen.fill(0);
}

/// The regularisation β for a (sub)step of length `h` (as the planar one).
fn beta(model: &SpatialModel, h: f64) -> f64 {
    regularization(model.params.contact.regularization, h)
}

/// Stage 4's system for the current trial states.
fn system<'a>(
    model: &'a SpatialModel,
    data: &'a mut SpatialData,
) -> (SpatialSystem<'a>, &'a mut NewtonSolver, &'a mut [f64]) {
    let surface = &model.params.terrain;
    let b = beta(model, data.fbd.dt);
    for (c, spec) in model.mech.contacts.iter().enumerate() {
        let state = data.trial[c];
        let (x, z) = match state {
            SpatialState::Stick { anchor } => (anchor[0], anchor[2]),
            _ => {
                let p = data.fbd.kin.point(&model.mech, spec.point / 3, spec.kind);
                (p.x, p.z)
            }
        };
        data.fbd.contact[c] = SpatialContactEquation {
            state,
            frame: frame(surface, x, z),
            mu_dynamic: model.params.friction.mu_dynamic,
            regularization: b + model.contact_bumper[c],
        };
    }
    for (eq, &state) in data.fbd.limit.iter_mut().zip(&data.limit_trial) {
        *eq = LimitEquation {
            state,
            regularization: b,
        };
    }
    row_scales(model, data);
    let sys = SpatialSystem {
        mech: &model.mech,
        surface,
        fbd: &mut data.fbd,
        scales: &data.scales,
    };
    (sys, &mut data.solver, &mut data.z)
}

/// Stage 4's system for the accepted states of `data` (for benchmarks,
/// which time the assembly and the factorisation apart).
pub fn system_for_bench<'a>(
    model: &'a SpatialModel,
    data: &'a mut SpatialData,
) -> SpatialSystem<'a> {
    data.trial.copy_from_slice(&data.states);
    data.limit_trial.copy_from_slice(&data.limit_states);
    system(model, data).0
}

/// Convergence scales: forces to `1e-9 ×` the weight with a round-off
/// floor, moments times the length scale, positions to `1e-12 m`-ish (as
/// the planar model's).
fn row_scales(model: &SpatialModel, data: &mut SpatialData) {
    let mech = &model.mech;
    let lay = mech.layout();
    let k = data.fbd.position_gain;
    let extent = data.q[0].abs().max(data.q[1].abs()).max(data.q[2].abs());
    let force = mech.total_mass() * mech.gravity.abs().max(1.0) + 1e-6 * k * (1.0 + extent);
    let moment = force * mech.length_scale();
    for b in 0..lay.bodies {
        let row = lay.body_row(b);
        data.scales[row..row + 3].fill(force);
        data.scales[row + 3..row + 6].fill(moment);
    }
    let position = 1e-3 * k * (1.0 + extent);
    for c in 0..lay.contacts {
        let row = lay.contact_row(c);
        let s = match data.trial[c] {
            SpatialState::Free => [force; 3],
            SpatialState::Stick { .. } => [position; 3],
            SpatialState::Slide { .. } => [force, position, force],
        };
        data.scales[row..row + 3].copy_from_slice(&s);
    }
    for l in 0..lay.limits {
        data.scales[lay.limit_row(l)] = moment;
    }
}

/// Stages 4–5 for the current (sub)step.
fn solve(model: &SpatialModel, data: &mut SpatialData) -> Result<(usize, usize), Failure> {
    let nq = model.nq();
    let mut fallback_used = false;
    let mut newton_iterations = 0;
    let mut trials = 0;
    loop {
        trials += 1;
        let (mut sys, solver, z) = system(model, data);
        let report = match solver.solve(&mut sys, z) {
            Ok(report) => report,
            Err(e) => {
                // A slide about to stop can leave the implicit friction
                // direction without a solution (the direction of a
                // vanishing slip is undefined): the slides keep their
                // reference direction (the planar rule); if that fails too
                // the slowest sliding point sticks (under p[k]) and the
                // search goes on; without one, the step fails.
                if trials < MAX_STATE_TRIALS
                    && (fix_slides(data) || stop_slowest_slide(model, data))
                {
                    data.z.copy_from_slice(&data.start_z);
                    continue;
                }
                return Err(Failure::Newton(e));
            }
        };
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
    data.max_step_iterations = data.max_step_iterations.max(newton_iterations);
    Ok((newton_iterations, trials))
}

/// Fixes the friction direction of every sliding point of the trial at
/// its reference direction; `false` if there was none to fix.
fn fix_slides(data: &mut SpatialData) -> bool {
    let mut any = false;
    for (c, state) in data.trial.iter().enumerate() {
        if matches!(state, SpatialState::Slide { .. }) && !data.fbd.fixed_direction[c] {
            data.fbd.fixed_direction[c] = true;
            any = true;
        }
    }
    any
}

/// Sticks the sliding point of the trial whose slip at the last evaluated
/// iterate is the smallest; `false` without sliding points.
fn stop_slowest_slide(model: &SpatialModel, data: &mut SpatialData) -> bool {
    let slowest = (0..data.trial.len())
        .filter(|&c| matches!(data.trial[c], SpatialState::Slide { .. }))
        .min_by(|&a, &b| data.fbd.slip_len[a].total_cmp(&data.fbd.slip_len[b]));
    let Some(c) = slowest else {
        return false;
    };
    let spec = &model.mech.contacts[c];
    let p = data.fbd.kin.point(&model.mech, spec.point / 3, spec.kind);
    data.trial[c] = SpatialState::Stick {
        anchor: project(&model.params.terrain, [p.x, p.y, p.z]),
    };
    true
}

/// The trial of contact `c` from the last solution.
fn trial_of(model: &SpatialModel, data: &SpatialData, c: usize) -> SpatialTrial {
    let mech = &model.mech;
    let lay = mech.layout();
    let spec = &mech.contacts[c];
    let (s, kind) = (spec.point / 3, spec.kind);
    let p_k = data.fbd.kin.point(mech, s, kind);
    let p_next = data.fbd.kin_next.point(mech, s, kind);
    SpatialTrial {
        p_k: [p_k.x, p_k.y, p_k.z],
        p_next: [p_next.x, p_next.y, p_next.z],
        ft: [
            data.z[lay.contact_force(c, 0)],
            data.z[lay.contact_force(c, 2)],
        ],
        n: data.z[lay.contact_force(c, 1)],
        frame: data.fbd.contact[c].frame,
        dt: data.fbd.dt,
    }
}

/// Applies the switching rules to the trial solution (see the module
/// docs); `true` if any point or limit switched.
fn check_states(model: &SpatialModel, data: &mut SpatialData) -> bool {
    let mech = &model.mech;
    let lay = mech.layout();
    let mu_s = model.params.friction.mu_static;
    let mut touchdown = false;
    let mut best: Option<(usize, SpatialState, f64)> = None;
    for c in 0..mech.contacts.len() {
        let trial = trial_of(model, data, c);
        let code = data.trial[c].code() as u8;
        data.seen[c] |= 1 << code;
        if matches!(data.trial[c], SpatialState::Stick { .. }) {
            data.stick_ft[c] = trial.ft;
        }
        let Some(next) = transition_spatial(
            &data.trial[c],
            &trial,
            &model.params.terrain,
            &model.params.friction,
            &model.params.contact,
        ) else {
            continue;
        };
        let stick_failed = data.seen[c] & 0b110 == 0b110;
        match (data.trial[c], next) {
            (SpatialState::Free, _) => {
                data.trial[c] = next;
                touchdown = true;
            }
            (SpatialState::Slide { .. }, SpatialState::Stick { .. }) if stick_failed => {}
            (_, SpatialState::Free) => {
                let priority = 2e12 - trial.n;
                if best.is_none_or(|b| priority > b.2) {
                    best = Some((c, next, priority));
                }
            }
            (SpatialState::Stick { .. }, _) => {
                let priority = 1e12 + trial.ft[0].hypot(trial.ft[1]) - mu_s * trial.n;
                if best.is_none_or(|b| priority > b.2) {
                    best = Some((c, next, priority));
                }
            }
            _ => {
                if best.is_none_or(|b| 0.0 > b.2) {
                    best = Some((c, next, 0.0));
                }
            }
        }
    }
    let length = mech.length_scale();
    let limits = &model.params.joint_limits;
    let mut release: Option<(usize, f64)> = None;
    for (l, lim) in mech.limits.iter().enumerate() {
        let state = data.limit_trial[l];
        if !state.is_at() {
            if let Some(at) = limit_arrival(limits, lim.joint, data.z[lim.q_index]) {
                data.limit_trial[l] = at;
                touchdown = true;
            }
        } else if let Some(priority) = limit_release(
            &state,
            data.z[lay.limit_moment(l)],
            length,
            model.params.contact.force_tol,
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
        if data.seen[c] & 0b100 != 0
            && matches!(data.trial[c], SpatialState::Stick { .. })
            && matches!(next, SpatialState::Slide { .. })
        {
            data.visited.clear();
        }
        data.trial[c] = next;
    }
    rigid_anchors(model, data);
    true
}

/// Anchors of points that share a rigid body (as in the planar model): on
/// each body the first point to stick keeps its anchor; every other point
/// anchored now is placed on the surface at its rigid distance from that
/// reference, in the horizontal direction it lies in.
fn rigid_anchors(model: &SpatialModel, data: &mut SpatialData) {
    let mech = &model.mech;
    for body in 0..mech.bodies.len() {
        let on_body = || (0..mech.contacts.len()).filter(move |&c| mech.contacts[c].body == body);
        let fresh = |data: &SpatialData, c: usize| {
            matches!(data.trial[c], SpatialState::Stick { .. })
                && !matches!(data.states[c], SpatialState::Stick { .. })
        };
        let kept = on_body()
            .find(|&c| matches!(data.trial[c], SpatialState::Stick { .. }) && !fresh(data, c));
        let Some(reference) = kept.or_else(|| on_body().find(|&c| fresh(data, c))) else {
            continue;
        };
        let SpatialState::Stick { anchor: from } = data.trial[reference] else {
            unreachable!("the reference sticks")
        };
        let spec = &mech.contacts[reference];
        let p_ref = data.fbd.kin.point(mech, spec.point / 3, spec.kind);
        for c in on_body() {
            if c == reference || !fresh(data, c) {
                continue;
            }
            let sc = &mech.contacts[c];
            let p = data.fbd.kin.point(mech, sc.point / 3, sc.kind);
            let d = p - p_ref;
            let horizontal = d.x.hypot(d.z);
            let anchor = if horizontal > 1e-12 {
                point_at_distance(
                    &model.params.terrain,
                    from,
                    d.norm(),
                    [d.x / horizontal, d.z / horizontal],
                )
            } else {
                project(&model.params.terrain, [from[0], from[1], from[2]])
            };
            data.trial[c] = SpatialState::Stick { anchor };
        }
    }
}

/// The cycle fallback: points solved in both ST1 and ST2 slide, opposite
/// to the friction their last sticking trial needed.
fn slide_flip_flops(data: &mut SpatialData) -> bool {
    let mut forced = false;
    for (c, state) in data.trial.iter_mut().enumerate() {
        if data.seen[c] & 0b11 == 0b11 && !matches!(state, SpatialState::Slide { .. }) {
            let ft = data.stick_ft[c];
            let len = ft[0].hypot(ft[1]);
            let dir = if len > 0.0 {
                [-ft[0] / len, -ft[1] / len]
            } else {
                [1.0, 0.0]
            };
            *state = SpatialState::Slide { dir };
            forced = true;
        }
    }
    forced
}

/// How far the trial is from its state's law, as a force (N).
fn violation(model: &SpatialModel, data: &SpatialData) -> f64 {
    let mech = &model.mech;
    let lay = mech.layout();
    let k = data.fbd.position_gain;
    let length = mech.length_scale();
    let mu = model.params.friction.mu_static;
    let mut worst: f64 = 0.0;
    for c in 0..mech.contacts.len() {
        let t = trial_of(model, data, c);
        let v = match data.trial[c] {
            SpatialState::Free => k * (-clearance(&model.params.terrain, t.p_next)).max(0.0),
            SpatialState::Stick { .. } => {
                (-t.n).max(0.0) + (t.ft[0].hypot(t.ft[1]) - mu * t.n).max(0.0)
            }
            SpatialState::Slide { dir } => {
                // A slide slower than the stop speed carries less than μD·N
                // (regularised direction): that deficit is a violation too.
                let s = t.slip();
                let deficit = model.params.friction.mu_dynamic * t.n - t.ft[0].hypot(t.ft[1]);
                (-t.n).max(0.0) + k * (-(s[0] * dir[0] + s[1] * dir[1])).max(0.0) + deficit.max(0.0)
            }
        };
        worst = worst.max(v);
    }
    for (l, lim) in mech.limits.iter().enumerate() {
        let angle = data.z[lim.q_index];
        let v = match data.limit_trial[l] {
            LimitState::Free => {
                let [lo, hi] = model.params.joint_limits.range(lim.joint);
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

/// Contact codes (3 each) and limit states (3 each) as one number; the
/// slip direction is not part of it (turning is not a switch).
fn states_key(data: &SpatialData) -> u64 {
    let k = data
        .trial
        .iter()
        .fold(0u64, |k, s| k.wrapping_mul(3).wrapping_add(s.code() as u64));
    data.limit_trial
        .iter()
        .fold(k, |k, s| k.wrapping_mul(3).wrapping_add(s.key()))
}

fn describe_states(model: &SpatialModel, states: &[SpatialState]) -> String {
    model
        .mech
        .contacts
        .iter()
        .zip(states)
        .filter(|(_, s)| !matches!(s, SpatialState::Free))
        .map(|(c, s)| format!("{}={}", c.name, s.code()))
        .collect::<Vec<_>>()
        .join(" ")
}

/// Stage 6; `true` when no contact or limit state changed.
fn accept(model: &SpatialModel, data: &mut SpatialData, t: f64) -> bool {
    let (events, limit_events) = (data.events.len(), data.limit_events.len());
    let mech = &model.mech;
    let k = data.k;
    for (c, spec) in mech.contacts.iter().enumerate() {
        let (from, to) = (data.states[c].code(), data.trial[c].code());
        if from != to {
            data.events.push(Event {
                t,
                step: k,
                contact: c,
                point: spec.kind.as_str(),
                leg: spec.leg,
                from,
                to,
            });
        }
    }
    for (l, lim) in mech.limits.iter().enumerate() {
        let (from, to) = (
            LimitCode::of(&data.limit_states[l]),
            LimitCode::of(&data.limit_trial[l]),
        );
        if from != to {
            data.limit_events.push(LimitEvent {
                t,
                step: k,
                joint_index: lim.q_index,
                joint: lim.joint,
                leg: mech.legs[lim.slot],
                from,
                to,
            });
        }
    }
    data.states.copy_from_slice(&data.trial);
    // A slide's reference direction follows its slip.
    for (c, state) in data.states.iter_mut().enumerate() {
        if let SpatialState::Slide { dir } = state {
            *dir = data.fbd.slip_hat[c];
        }
    }
    data.limit_states.copy_from_slice(&data.limit_trial);
    std::mem::swap(&mut data.q_prev2, &mut data.q_prev);
    data.q_prev.copy_from_slice(&data.q);
    let nq = model.nq();
    data.q.copy_from_slice(&data.z[..nq]);
    advance(&mut data.fbd);
    data.events.len() == events && data.limit_events.len() == limit_events
}

fn save_grid(data: &mut SpatialData) {
    data.grid_q.copy_from_slice(&data.q);
    data.grid_q_prev.copy_from_slice(&data.q_prev);
    data.grid_q_prev2.copy_from_slice(&data.q_prev2);
    data.grid_states.copy_from_slice(&data.states);
    data.grid_limits.copy_from_slice(&data.limit_states);
    data.grid_events = [data.events.len(), data.limit_events.len()];
}

fn restore_grid(model: &SpatialModel, data: &mut SpatialData) {
    let mech = &model.mech;
    data.q.copy_from_slice(&data.grid_q);
    data.q_prev.copy_from_slice(&data.grid_q_prev);
    data.q_prev2.copy_from_slice(&data.grid_q_prev2);
    data.states.copy_from_slice(&data.grid_states);
    data.limit_states.copy_from_slice(&data.grid_limits);
    data.events.truncate(data.grid_events[0]);
    data.limit_events.truncate(data.grid_events[1]);
    data.fbd.kin.eval(mech, &data.grid_q);
    set_previous(mech, &mut data.fbd, &data.grid_q_prev);
}

/// Step `data.k` as `n` substeps of `Δt/n` (the planar scheme): the record
/// is the first substep's.
fn substeps(model: &SpatialModel, data: &mut SpatialData, n: usize) -> Result<(), Failure> {
    let mech = &model.mech;
    let nq = model.nq();
    let h = model.dt() / n as f64;
    let k = data.k;
    let t = k as f64 * model.dt();
    let mut first = true;
    for i in 0..n {
        let history = if k == 0 && i == 0 {
            History::Initial {
                qdot: &model.params.qdot0,
            }
        } else {
            History::Previous
        };
        if i == 0 && k > 0 {
            for j in 0..nq {
                data.q_prev[j] = data.q[j] - (data.q[j] - data.grid_q_prev[j]) / n as f64;
            }
            set_previous(mech, &mut data.fbd, &data.q_prev);
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
        if first {
            make_record(model, data, iterations, trials, h);
            first = false;
        } else {
            data.record.newton_iterations += iterations;
            data.record.state_trials += trials;
        }
        let _ = accept(model, data, t + i as f64 * h);
    }
    data.q_prev.copy_from_slice(&data.grid_q);
    data.q_prev2.copy_from_slice(&data.grid_q_prev);
    data.predictor.record(&data.z, false);
    set_previous(mech, &mut data.fbd, &data.grid_q);
    Ok(())
}

/// Fills `data.record` for the solved (sub)step of length `h`.
fn make_record(
    model: &SpatialModel,
    data: &mut SpatialData,
    newton_iterations: usize,
    state_trials: usize,
    h: f64,
) {
    let mech = &model.mech;
    let lay = mech.layout();
    let fbd = &data.fbd;
    let z = &data.z;
    let rec = &mut data.record;
    rec.step = data.k;
    rec.t = data.k as f64 * model.dt();
    rec.q.copy_from_slice(&data.q);
    rec.newton_iterations = newton_iterations;
    rec.state_trials = state_trials;
    for (c, spec) in mech.contacts.iter().enumerate() {
        let p = fbd.kin.point(mech, spec.point / 3, spec.kind);
        let eq = &fbd.contact[c];
        let fl = [
            z[lay.contact_force(c, 0)],
            z[lay.contact_force(c, 1)],
            z[lay.contact_force(c, 2)],
        ];
        let [t1, n, t2] = eq.frame;
        let row = &mut rec.contacts[c];
        row.point = [p.x, p.y, p.z];
        row.state = data.trial[c].code();
        row.force = std::array::from_fn(|i| fl[0] * t1[i] + fl[1] * n[i] + fl[2] * t2[i]);
        row.normal = fl[1];
    }
    for s in 0..lay.legs {
        let [z0, z1, z2] = fbd.axes[s];
        let tau = fbd.torque[s];
        let mut stop = [0.0; 3];
        let mut limit = [LimitCode::Free; 3];
        for (l, lim) in mech.limits.iter().enumerate() {
            if lim.slot == s {
                let j = lim.joint.index();
                stop[j] = z[lay.limit_moment(l)];
                limit[j] = LimitCode::of(&data.limit_trial[l]);
            }
        }
        let v = |i: usize| Vector3::new(z[i], z[i + 1], z[i + 2]);
        let hip_m = z[lay.hip_moment(s)] * fbd.hip_dir[s]
            + (tau[0] + stop[0]) * z0
            + (tau[1] + stop[1]) * z1;
        let [b1, b2] = fbd.knee_dir[s];
        let knee_m =
            z[lay.knee_moment(s, 0)] * b1 + z[lay.knee_moment(s, 1)] * b2 + (tau[2] + stop[2]) * z2;
        let row = &mut rec.legs[s];
        row.hip_force = v(lay.hip_force(s, 0)).into();
        row.hip_moment = hip_m.into();
        row.knee_force = v(lay.knee_force(s, 0)).into();
        row.knee_moment = knee_m.into();
        row.torque = tau;
        row.limit = limit;
    }
    // Rates need `data` immutably: a second pass.
    for s in 0..lay.legs {
        let r = joint_rates(model, data, s);
        data.record.legs[s].rate = r;
    }
    // Energies and momenta over the step k → k+1 (the scheme's own); the
    // momenta are the next step's L[k−½] when this step is accepted whole.
    let fbd = &mut data.fbd;
    let mut carry = std::mem::take(&mut fbd.l_carry);
    let g = model.params.gravity;
    let (mut kinetic, mut potential) = (0.0, 0.0);
    let (mut p, mut hmom) = (Vector3::zeros(), Vector3::zeros());
    for (b, body) in mech.bodies.iter().enumerate() {
        let (c0, c1) = (fbd.kin.com[b], fbd.kin_next.com[b]);
        let v = (c1 - c0) / h;
        let (l, psi) =
            half_momentum_and_rotation(&fbd.kin.rot[b], &fbd.kin_next.rot[b], &body.inertia, h);
        carry[b] = l;
        kinetic +=
            0.5 * body.mass * v.norm_squared() + 0.5 * psi.dot(&(body.inertia * psi)) / (h * h);
        potential += body.mass * g * 0.5 * (c0.y + c1.y);
        p += body.mass * v;
        hmom += body.mass * c0.cross(&v) + l;
    }
    fbd.l_carry = carry;
    fbd.l_carry_dt = h;
    let rec = &mut data.record;
    rec.kinetic = kinetic;
    rec.potential = potential;
    rec.momentum = p.into();
    rec.angular_momentum = hmom.into();
}

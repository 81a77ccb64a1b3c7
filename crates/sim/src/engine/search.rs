//! Stages 4–5 of the step: solve with the trial contact and joint-limit
//! states, check every switching rule on the solution, and solve again
//! until no point or joint switches.
//!
//! Every touchdown (ST1 → ST2) and every joint reaching a limit is applied
//! at once: a point that penetrates must carry a force, a joint past its
//! end must be stopped. Of the other switches — lift-off, limit release,
//! the start or end of a slide — only the most violated one is applied
//! before re-solving, since one of them changes the forces on all the
//! others (at an impact of several points, switching them all together
//! chases its tail): lift-offs and releases first (most negative `N`, or
//! stop moment over the length scale), then slips (largest `|Ft| − μS·N`),
//! then the ends of slides — which the exact models (the 3D ones,
//! [`super::Settings::exact`]) apply together, every slide whose slip has
//! stopped at once: tried one at a time, a foot that stops while the
//! others still slide at μD·N can need more than μS·N alone where all of
//! them together stick inside their cones (the complementarity rows then
//! return any that must slide to ST3 at once).
//!
//! **Touchdowns during a crawl** (3D models). A solve whose Newton
//! iteration crawls (its watchdog returns to the kept iterate,
//! `fbd_solver::NewtonParams::watchdog`) is given up
//! (`fbd_solver::SolverError::Abandoned`) when that kept iterate is near
//! a solution and a free point is clearly below the ground there
//! ([`super::surface::ABANDON_RESIDUAL`], [`super::surface::ABANDON_DEPTH`]:
//! a scaled residual of at most 1e-3, positions within a micrometre, and
//! a point more than 10 µm deep): converging those states would only
//! confirm a touchdown the rules above apply anyway, and at an impact — a
//! body whose hips and knees strike while its feet slide — the states
//! before it are the hard ones (their semismooth solve crawled for all its
//! 50 iterations, then its fallbacks ran). The search touches the points
//! down there, anchored where the kept iterate's path crosses the ground,
//! and solves again ([`RunData::abandoned_crawls`]). A step that does not
//! crawl, or whose crawl has no such point, is solved as before; the
//! solution accepted is checked by the law audit below like every other.
//!
//! **A slide that could not stop** (exact models). A sliding point whose slip stops is
//! tried sticking; when sticking needs more than μS·N it slides on at
//! μD·N, and the search does not try it again in that step. It keeps that
//! mark across steps while it keeps sliding forwards
//! ([`RunData::stick_refused`]): it is tried sticking again only when its
//! slip reverses (or when its complementarity rows find it inside its μD
//! disc, a stop that needs no trial). A slide at μD·N whose slip is
//! (almost) zero obeys Coulomb's law either way (`μD·N ≤ μS·N`); tried
//! every step, it cost two to a dozen solves a step and wrote an ST3 → ST2
//! → ST3 pair of events whenever one of them went through (a robot on its
//! knees with its feet braced against the ground). The planar model keeps
//! the paper's machine, every end of a slide tried one at a time in each
//! step.
//!
//! **Cycles.** A repeated state combination means no combination the
//! rules reach is consistent. Before giving up, a point that flip-flopped
//! between ST1 (it penetrates when free) and ST2 (it would pull on the
//! ground when stuck) is tried in ST3, sliding opposite to the friction
//! sticking needed — the remaining candidate of Coulomb's law
//! ([`slide_flip_flops`]). If it still cycles, every combination of the
//! few points and joint limits involved is solved in turn and the first
//! consistent one is taken ([`enumerate_states`]): the greedy rules, one
//! switch at a time, can miss a consistent combination that is two
//! switches away (a foot that slides *and* a knee that leaves its stop).
//! Then the least inconsistent trial of the search is accepted when its
//! violation of the contact and limit laws ([`violation`]) is negligible
//! (at most the model's cycle tolerance, 1e-7 of the weight); otherwise the
//! step is retried in substeps, and at the finest substeps the run stops
//! with an error naming the point and the law ([`Failure::Inexact`]):
//! an inexact trial is never accepted. (The planar model, whose
//! [`super::Settings::exact`] is `false`, keeps the earlier rule: at the
//! finest substeps the least inconsistent trial is accepted.)
//!
//! **Law audit** (models with [`super::Settings::exact`]: the spatial
//! one). Every solution the search accepts — consistent by the
//! switching rules, or closed as above — is checked against every law of
//! the states it was solved in ([`worst_violation`]): no penetration of a
//! free point beyond the penetration tolerance, `N ≥ 0`, `|Ft| ≤ μS·N`
//! when sticking, and when sliding `Ft = −μD·N·ŝ` with `ŝ` the unit slip
//! of the step itself (magnitude *and* direction), every joint within its
//! range and every stop pushing. A solution that breaks one by more than
//! 1e-6 of the weight ([`LAW_TOLERANCE`]) is rejected like an unclosable cycle (counted in
//! [`RunData::rejected_solutions`]); the largest violation of the accepted
//! ones is [`RunData::max_law_violation`].
//!
//! **Joint limits** are one-sided, plastic stops: a free joint whose trial
//! angle crosses an end of its range is held at that end; a joint at an
//! end is released when the stop's moment would pull it there instead of
//! pushing it away ([`crate::rules`]).

use super::{Engine, Law, RunData};
use crate::rules::{Failure, LIMIT_ANGLE_TOL, MAX_STATE_TRIALS, limit_arrival, limit_release};
use fbd_contact::{ContactMode, ContactTrial, StateCode, switch};
use fbd_dynamics::LimitState;

/// The state search starts from the accepted states (and the unknowns in
/// `data.z`, kept to start again from after a failed solve).
pub(crate) fn start_search<M: Engine>(data: &mut RunData<M>) {
    data.start_z.copy_from_slice(&data.z);
    data.origin_z.copy_from_slice(&data.z);
    data.best_violation = f64::INFINITY;
    data.trial.copy_from_slice(&data.states);
    data.limit_trial.copy_from_slice(&data.limit_states);
    data.visited.clear();
    let key = states_key(data);
    data.visited.push(key);
    data.seen.fill(0);
}

/// Stages 4–5: solves the current (sub)step until its contact and limit
/// states are consistent. Returns the Newton iterations — every step
/// every solve of the search applied, those of failed and given-up
/// solves included ([`fbd_solver::NewtonSolver::steps_taken`]) —
/// and the number of solves.
pub(crate) fn solve<M: Engine>(
    model: &M,
    data: &mut RunData<M>,
) -> Result<(usize, usize), Failure> {
    let mut fallback_used = false;
    let mut refinements = 0;
    let steps_before = data.solver.steps_taken();
    let mut trials = 0;
    loop {
        trials += 1;
        let report = match model.solve(data) {
            Ok(report) => report,
            Err(e) => {
                let retry = trials < MAX_STATE_TRIALS;
                if retry
                    && matches!(e, fbd_solver::SolverError::Abandoned { .. })
                    && touch_down_after_crawl(model, data)
                {
                    continue;
                }
                if retry && model.newton_fallback(data) {
                    data.newton_fallbacks += 1;
                    data.z.copy_from_slice(&data.start_z);
                    continue;
                }
                return Err(Failure::Newton(e));
            }
        };
        if !all_finite(&data.z) {
            return Err(Failure::NonFinite {
                residual: report.residual,
            });
        }
        model.evaluate_next(data);
        if trials < MAX_STATE_TRIALS && model.complementarity_switches(data) {
            continue;
        }
        if refinements < MAX_DIRECTION_REFINEMENTS && model.refine_directions(data) {
            refinements += 1;
            data.direction_refinements += 1;
            continue;
        }
        data.checked_trial.copy_from_slice(&data.trial);
        data.checked_limits.copy_from_slice(&data.limit_trial);
        if !check_states(model, data) {
            // Consistent by the switching rules: the law audit.
            if !model.exact() {
                break;
            }
            let worst = worst_violation(model, data, &data.trial, &data.limit_trial);
            if worst.amount > LAW_TOLERANCE * model.cycle_tolerance() {
                data.rejected_solutions += 1;
                return Err(worst.failure());
            }
            data.max_law_violation = data.max_law_violation.max(worst.amount);
            count_backward(model, data);
            break;
        }
        // An inconsistent solution: kept if it is the least inconsistent
        // so far.
        keep_if_best(model, data);
        let mut key = states_key(data);
        if data.visited.contains(&key) && !fallback_used {
            fallback_used = true;
            if slide_flip_flops(data) {
                data.visited.clear();
                key = states_key(data);
            }
        }
        if data.visited.contains(&key) || trials >= MAX_STATE_TRIALS {
            if enumerate_states(model, data, &mut trials) {
                data.enumerated_cycles += 1;
                break;
            }
            if data.best_violation <= model.cycle_tolerance() || data.last_resort {
                data.z.copy_from_slice(&data.best_z);
                data.trial.copy_from_slice(&data.best_trial);
                data.limit_trial.copy_from_slice(&data.best_limits);
                model.evaluate_next(data);
                data.max_law_violation = data.max_law_violation.max(data.best_violation);
                count_backward(model, data);
                data.resolved_cycles += 1;
                break;
            }
            if data.best_violation.is_finite() {
                // Name the point and the law of the least inconsistent trial.
                data.z.copy_from_slice(&data.best_z);
                model.evaluate_next(data);
                let worst = worst_violation(model, data, &data.best_trial, &data.best_limits);
                return Err(worst.failure());
            }
            return Err(Failure::Cycle {
                residual: report.residual,
            });
        }
        data.visited.push(key);
    }
    Ok(((data.solver.steps_taken() - steps_before) as usize, trials))
}

/// After a crawl given up at its kept iterate (module docs): the
/// touchdowns certain there, made by the switching rules, when they lead
/// to states not yet tried in this search (`true`: solve again).
fn touch_down_after_crawl<M: Engine>(model: &M, data: &mut RunData<M>) -> bool {
    model.evaluate_next(data);
    if !check_states(model, data) {
        return false;
    }
    let key = states_key(data);
    if data.visited.contains(&key) {
        return false;
    }
    data.visited.push(key);
    data.abandoned_crawls += 1;
    true
}

/// Counts the accepted slides whose slip runs against their reference
/// direction ([`RunData::backward_slides`]).
fn count_backward<M: Engine>(model: &M, data: &mut RunData<M>) {
    for c in 0..data.trial.len() {
        if data.trial[c].code() == StateCode::St3 {
            let trial = model.trial(data, c);
            if trial.slip_speed(&data.trial[c]) < 0.0 {
                data.backward_slides += 1;
            }
        }
    }
}

/// The law audit's tolerance in units of the cycle tolerance: 10, i.e.
/// 1e-6 of the robot's weight (0.18 mN on the default hexapod). The
/// solver's convergence scale of a friction row grows with the position
/// gain at small substeps (a few 1e-5 N at Δt/64), above the cycle
/// tolerance, far below any physical force.
const LAW_TOLERANCE: f64 = 10.0;

/// Most re-solves of one search that move fixed friction directions to
/// the slip found ([`Engine::refine_directions`]).
const MAX_DIRECTION_REFINEMENTS: usize = 40;

/// Keeps the solution in `data.z`, solved in the states
/// `data.checked_trial` and `data.checked_limits`, as the search's least
/// inconsistent one when it is (judged in those states); returns its
/// violation.
fn keep_if_best<M: Engine>(model: &M, data: &mut RunData<M>) -> f64 {
    let v = violation(model, data, &data.checked_trial, &data.checked_limits);
    if v < data.best_violation {
        data.best_violation = v;
        data.best_z.copy_from_slice(&data.z);
        data.best_trial.copy_from_slice(&data.checked_trial);
        data.best_limits.copy_from_slice(&data.checked_limits);
    }
    v
}

/// Applies the switching rules to the trial solution (see the module
/// docs); `true` if any point or joint limit switched.
fn check_states<M: Engine>(model: &M, data: &mut RunData<M>) -> bool {
    let mut touchdown = false;
    let mut best: Option<(usize, M::State, f64)> = None;
    for c in 0..model.contacts() {
        let trial = model.trial(data, c);
        let friction = model.friction_at(trial.location());
        let mu_s = friction.mu_static;
        let state = data.trial[c];
        data.seen[c] |= 1 << (state.code() as u8);
        if let Some(anchor) = state.anchor() {
            data.stick_ft[c] = trial.tangential();
            data.stick_anchor[c] = anchor;
        }
        data.stops[c] = None;
        let Some(next) = switch(
            &state,
            &trial,
            model.ground(),
            &friction,
            model.contact_params(),
        ) else {
            continue;
        };
        // ST3 → ST2 needs the slip to stop *and* |Ft| ≤ μS·N: a point that
        // already tried sticking in this search and had to slide again
        // stays sliding at the friction limit, as does one that could not
        // stick in an earlier step and slides on forwards (module docs).
        let stick_failed = stick_failed_in_search(data.seen[c])
            || model.exact() && data.stick_refused[c] && trial.slip_speed(&state) > 0.0;
        // Priority: lift-off > slip > end of a slide, then the violation.
        let priority = match (state.code(), next.code()) {
            (StateCode::St1, _) => {
                data.trial[c] = next;
                touchdown = true;
                continue;
            }
            (StateCode::St3, StateCode::St2) if stick_failed => continue,
            (StateCode::St3, StateCode::St2) => {
                data.stops[c] = Some(next);
                0.0
            }
            (_, StateCode::St1) => 2e12 - trial.normal(),
            (StateCode::St2, _) => {
                1e12 + M::State::tangent_norm(trial.tangential()) - mu_s * trial.normal()
            }
            _ => 0.0,
        };
        if best.is_none_or(|b| priority > b.2) {
            best = Some((c, next, priority));
        }
    }
    // Joint limits: arrivals at once, a release competes with lift-offs.
    let length = model.length_scale(data);
    let force_tol = model.contact_params().force_tol;
    let mut release: Option<(usize, f64)> = None;
    for l in 0..model.limits() {
        let info = model.limit(l);
        let state = data.limit_trial[l];
        if !state.is_at() {
            if let Some(at) = limit_arrival(info.range, data.z[info.q_index]) {
                data.limit_trial[l] = at;
                touchdown = true;
            }
        } else if let Some(priority) = limit_release(
            &state,
            data.z[model.limit_moment_index(l)],
            length,
            force_tol,
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
        // A point that slid, tried sticking and must slide again is locked
        // in ST3 from now on (see above): the search has learnt something,
        // and returning to an earlier combination is no longer a cycle.
        if data.seen[c] & 0b100 != 0
            && data.trial[c].code() == StateCode::St2
            && next.code() == StateCode::St3
        {
            data.visited.clear();
        }
        data.trial[c] = next;
        if data.stops[c].is_some() && model.exact() {
            // An end of a slide: every slide that has stopped sticks
            // together (module docs).
            for (state, stop) in data.trial.iter_mut().zip(&data.stops) {
                if let Some(stop) = stop {
                    *state = *stop;
                }
            }
        }
    }
    rigid_anchors(model, data);
    true
}

/// Whether a point's search solved it both sticking and sliding (`seen`
/// bits of ST2 and ST3): it tried sticking and had to slide.
pub(crate) fn stick_failed_in_search(seen: u8) -> bool {
    seen & 0b110 == 0b110
}

/// Anchors of points that share a rigid body. A touchdown is anchored
/// where the point's straight path `p[k] → p[k+1]` crosses the ground; for
/// two points of one body (a knee and a foot of one link, both hips) two
/// such anchors are not a rigid placement — their distance differs from the
/// points' by the body's motion during the step — and sticking at both
/// would tear the body apart. So on each body, the first point to stick
/// keeps its anchor (an already sticking point, or else the first point
/// anchored now, which keeps the crossing), and every other point anchored
/// now is placed on the ground at its rigid distance from that reference,
/// on its side ([`Engine::anchor_at_distance`]). A point alone on its body
/// — every foot — is untouched.
fn rigid_anchors<M: Engine>(model: &M, data: &mut RunData<M>) {
    let sticks = |s: &M::State| s.code() == StateCode::St2;
    for body in 0..model.bodies() {
        let on_body = || (0..model.contacts()).filter(move |&c| model.contact_body(c) == body);
        let fresh =
            |data: &RunData<M>, c: usize| sticks(&data.trial[c]) && !sticks(&data.states[c]);
        let kept = on_body().find(|&c| sticks(&data.trial[c]) && !fresh(data, c));
        let Some(reference) = kept.or_else(|| on_body().find(|&c| fresh(data, c))) else {
            continue;
        };
        let from = data.trial[reference]
            .anchor()
            .expect("the reference sticks");
        for c in on_body() {
            if c == reference || !fresh(data, c) {
                continue;
            }
            let anchor = model.anchor_at_distance(data, reference, from, c);
            data.trial[c] = M::State::stick(anchor);
        }
    }
}

/// The cycle fallback: every point that was solved in both ST1 and ST2
/// during this step's search (and is not sliding) is set to ST3, sliding
/// opposite to the friction its last sticking trial needed. `true` if any
/// point was changed.
fn slide_flip_flops<M: Engine>(data: &mut RunData<M>) -> bool {
    let mut forced = false;
    for (c, state) in data.trial.iter_mut().enumerate() {
        if data.seen[c] & 0b11 == 0b11 && state.code() != StateCode::St3 {
            *state = M::State::slide_against(data.stick_ft[c]);
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

/// The cycle's exhaustive fallback: the points involved in this step's
/// search (solved in more than one state, or not free in the accepted or
/// least inconsistent combination) each take ST1, ST2 (at the anchor of its
/// last sticking trial, if it had one), ST3 forwards and ST3 backwards
/// along the first tangent; the joint limits involved (at a stop in the
/// accepted, least inconsistent or current combination) are free or at
/// that stop; every other point is free and every other joint limit free.
/// The combinations are solved in a fixed order and the first whose
/// violation ([`violation`]) is at most the model's cycle tolerance is
/// kept in `data` (`true`). `false` when none is, or when there are too
/// many to try ([`MAX_ENUMERATED`]); the least inconsistent trial is
/// updated either way. No allocation.
fn enumerate_states<M: Engine>(model: &M, data: &mut RunData<M>, trials: &mut usize) -> bool {
    let mut points = [0usize; MAX_INVOLVED];
    let mut np = 0;
    for c in 0..data.trial.len() {
        let involved = data.seen[c].count_ones() >= 2
            || data.states[c].code() != StateCode::St1
            || data.best_trial[c].code() != StateCode::St1;
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
        data.trial.fill(M::State::FREE);
        data.limit_trial.fill(LimitState::Free);
        let mut possible = true;
        for &c in &points[..np] {
            data.trial[c] = match m % 4 {
                0 => M::State::FREE,
                1 if data.seen[c] & 0b10 != 0 => M::State::stick(data.stick_anchor[c]),
                1 => {
                    possible = false;
                    M::State::FREE
                }
                2 => M::State::slide_along_first(1.0),
                _ => M::State::slide_along_first(-1.0),
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
        if model.solve(data).is_err() {
            continue;
        }
        if !all_finite(&data.z) {
            continue;
        }
        model.evaluate_next(data);
        data.checked_trial.copy_from_slice(&data.trial);
        data.checked_limits.copy_from_slice(&data.limit_trial);
        if keep_if_best(model, data) <= model.cycle_tolerance() {
            return true;
        }
    }
    false
}

/// The worst law violation of a trial solution: how much (N), which law,
/// and where (a contact point, or a joint limit when `limit`).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Worst {
    pub amount: f64,
    pub law: Law,
    pub index: usize,
    pub limit: bool,
}

impl Worst {
    /// The failure of a step whose best solution breaks this law.
    pub(crate) fn failure(self) -> Failure {
        Failure::Inexact {
            index: self.index,
            limit: self.limit,
            law: self.law,
            amount: self.amount,
        }
    }
}

/// How far the trial solution is from satisfying the law of the state it
/// was solved in, as a force (N): penetration of a free point or crossing
/// of a free joint beyond the switching tolerances (times the position
/// gain), a pulling contact or stop, friction beyond μS·N when sticking, a
/// slide running backwards or whose friction is not `−μD·N·ŝ`
/// ([`Engine::contact_violation`]). The largest over all points and
/// limits, with its law and place; 0 for a consistent solution.
pub(crate) fn worst_violation<M: Engine>(
    model: &M,
    data: &RunData<M>,
    states: &[M::State],
    limits: &[LimitState],
) -> Worst {
    let mut worst = Worst {
        amount: 0.0,
        law: Law::None,
        index: 0,
        limit: false,
    };
    for (c, state) in states.iter().enumerate() {
        let trial = model.trial(data, c);
        let (v, law) = model.contact_violation(data, state, &trial);
        if v > worst.amount {
            worst = Worst {
                amount: v,
                law,
                index: c,
                limit: false,
            };
        }
    }
    let length = model.length_scale(data);
    let gain = model.limit_gain(data);
    for (l, state) in limits.iter().enumerate() {
        let info = model.limit(l);
        let angle = data.z[info.q_index];
        let (v, law) = match *state {
            LimitState::Free => {
                let [lo, hi] = info.range;
                let tol = if model.exact() { LIMIT_ANGLE_TOL } else { 0.0 };
                let beyond = (lo - angle).max(angle - hi) - tol;
                (gain / length * beyond.max(0.0), Law::LimitCrossing)
            }
            LimitState::At { side, .. } => (
                (-side.sign() * data.z[model.limit_moment_index(l)] / length).max(0.0),
                Law::LimitPull,
            ),
        };
        if v > worst.amount {
            worst = Worst {
                amount: v,
                law,
                index: l,
                limit: true,
            };
        }
    }
    worst
}

/// The amount of [`worst_violation`] (N).
pub(crate) fn violation<M: Engine>(
    model: &M,
    data: &RunData<M>,
    states: &[M::State],
    limits: &[LimitState],
) -> f64 {
    worst_violation(model, data, states, limits).amount
}

/// `true` when every value is finite: one pass without an exit per value
/// (a reduction the compiler vectorises; the solution is finite all but
/// never).
fn all_finite(z: &[f64]) -> bool {
    z.iter().fold(true, |ok, v| ok & v.is_finite())
}

/// The trial states of contacts and joint limits as one number, for cycle
/// detection.
fn states_key<M: Engine>(data: &RunData<M>) -> u64 {
    let k = data.trial.iter().fold(0u64, |k, s| {
        k.wrapping_mul(M::State::KEY_BASE)
            .wrapping_add(s.search_key())
    });
    data.limit_trial
        .iter()
        .fold(k, |k, s| k.wrapping_mul(3).wrapping_add(s.key()))
}

/// The state combination of a failed step, for its error: every point in
/// contact and every joint at a stop, `name=code`.
pub(crate) fn describe_states<M: Engine>(
    model: &M,
    states: &[M::State],
    limits: &[LimitState],
) -> String {
    let mut parts: Vec<String> = states
        .iter()
        .enumerate()
        .filter(|(_, s)| s.code() != StateCode::St1)
        .map(|(c, s)| format!("{}={}", model.contact_name(c), s.code()))
        .collect();
    for (l, s) in limits.iter().enumerate() {
        if s.is_at() {
            parts.push(format!(
                "{}={}",
                model.limit_name(l),
                crate::record::LimitCode::of(s).as_str()
            ));
        }
    }
    if parts.is_empty() {
        "every point free".into()
    } else {
        parts.join(" ")
    }
}

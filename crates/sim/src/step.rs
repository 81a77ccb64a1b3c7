//! One time step, in stages:
//!
//! 1. **kinematics at k**: the per-body constants of the second differences;
//! 2. **joint torques at k**: the controller's torques from `q[k]`, `q[k−1]`
//!    ([`crate::control`]);
//! 3. **predictor**: a starting guess for `q[k+1]` (forces from the last step);
//! 4. **solve**: Newton on the FBD equations with the current contact states;
//! 5. **contact check**: every point's switching rule on the trial solution
//!    (touchdowns all at once, other switches one at a time, see
//!    [`check_contacts`]); any switch → back to 4. A repeated state combination means no
//!    combination the rules reach is consistent; before giving up, a point
//!    that flip-flopped between ST1 (it penetrates when free) and ST2 (it
//!    would pull on the ground when stuck) is tried in ST3, sliding opposite
//!    to the friction sticking needed — the remaining candidate of Coulomb's
//!    law ([`slide_flip_flops`]). A cycle after that is an error;
//! 6. **accept**: record, events, and `q[k+1]` becomes the current state.

use crate::energy;
use crate::record::{Event, MAX_CONTACTS, MAX_JOINTS, StepRecord};
pub use crate::system::StepSystem;
use crate::system::row_scales;
use crate::{Data, Model, SimError};
use fbd_contact::{ContactState, Trial, transition};
use fbd_dynamics::{ContactEquation, History, advance, evaluate_next, prepare_step};
use fbd_solver::NewtonSolver;

/// Solves step `data.k` and advances the state to `k + 1`.
pub fn step(model: &Model, data: &mut Data) -> Result<StepRecord, SimError> {
    let mech = &model.mech;
    let dt = model.dt();
    let k = data.k;
    let t = k as f64 * dt;
    let nq = mech.layout().nq;

    // 1–3. Kinematics and torques at k, predictor.
    prepare(model, data);
    let mut fallback_used = false;
    let mut newton_iterations = 0;
    let mut trials = 0;
    loop {
        trials += 1;
        let (mut sys, solver, z) = system(model, data);
        let report = solver
            .solve(&mut sys, z)
            .map_err(|source| SimError::Newton { step: k, t, source })?;
        newton_iterations += report.iterations;
        if data.z.iter().any(|v| !v.is_finite()) {
            return Err(SimError::NonFinite {
                step: k,
                t,
                residual: report.residual,
            });
        }
        evaluate_next(mech, &mut data.fbd, &data.z[..nq]);
        if !check_contacts(model, data) {
            break;
        }
        let mut key = states_key(&data.trial);
        if data.visited.contains(&key) && !fallback_used {
            fallback_used = true;
            if slide_flip_flops(data) {
                data.visited.clear();
                key = states_key(&data.trial);
            }
        }
        if data.visited.contains(&key) {
            return Err(SimError::Cycling {
                step: k,
                t,
                states: describe_states(model, &data.trial),
                residual: report.residual,
            });
        }
        data.visited.push(key);
    }
    data.newton_iterations += newton_iterations;

    // 6. Accept.
    let record = make_record(model, data, newton_iterations, trials);
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
    data.states.copy_from_slice(&data.trial);
    std::mem::swap(&mut data.q_prev2, &mut data.q_prev);
    data.q_prev.copy_from_slice(&data.q);
    data.q.copy_from_slice(&data.z[..nq]);
    advance(mech, &mut data.fbd);
    data.k += 1;
    Ok(record)
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

/// Stages 1–3 of [`step`]: the per-body constants of step `data.k` and the
/// predictor of `q[k+1]` in `data.z` (the forces keep the last solution);
/// the trial contact states start from the accepted ones. Public for
/// benchmarks, which time the stages one by one.
pub fn prepare(model: &Model, data: &mut Data) {
    let mech = &model.mech;
    let dt = model.dt();
    let k = data.k;
    let nq = mech.layout().nq;
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

    // 3. Predictor: quadratic extrapolation of q through the last three
    // configurations (exact for the discrete free fall), linear at k = 1,
    // the initial velocity at k = 0.
    for i in 0..nq {
        data.z[i] = match k {
            0 => data.q[i] + dt * model.params.qdot0[i],
            1 => 2.0 * data.q[i] - data.q_prev[i],
            _ => 3.0 * (data.q[i] - data.q_prev[i]) + data.q_prev2[i],
        };
    }
    data.trial.copy_from_slice(&data.states);
    data.visited.clear();
    data.visited.push(states_key(&data.trial));
    data.seen.fill(0);
}

/// Stage 4's inputs for the current trial states (contact equations, row
/// scales), split from `data`: the step's [`NewtonSystem`](fbd_solver::NewtonSystem),
/// the solver and the unknowns `z`. Public for benchmarks.
pub fn system<'a>(
    model: &'a Model,
    data: &'a mut Data,
) -> (StepSystem<'a>, &'a mut NewtonSolver, &'a mut [f64]) {
    set_contact_equations(model, data);
    row_scales(
        &model.mech,
        &data.fbd,
        data.q[0].abs().max(data.q[1].abs()),
        &mut data.scales,
    );
    let sys = StepSystem {
        mech: &model.mech,
        terrain: &model.params.terrain,
        fbd: &mut data.fbd,
        scales: &data.scales,
    };
    (sys, &mut data.solver, &mut data.z)
}

/// The equations of each contact point for its trial state: the terrain
/// frame at the anchor (ST2), under the point at k (ST1, ST3).
fn set_contact_equations(model: &Model, data: &mut Data) {
    let terrain = &model.params.terrain;
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
            regularization: model.contact.regularization
                + model.contact_compliance[c] * data.fbd.position_gain,
        };
    }
}

/// Applies the switching rules to the trial solution; `true` if any point
/// switched. Every touchdown (ST1 → ST2) is applied at once: a point that
/// penetrates must carry a force. Of the other switches — lift-off, the
/// start or end of a slide — only the most violated one is applied before
/// re-solving, since one of them changes the forces on all the others (at an
/// impact of several points, switching them all together chases its tail):
/// lift-offs first (most negative `N`), then slips (largest `|Fa| − μS·N`),
/// then slide reversals.
fn check_contacts(model: &Model, data: &mut Data) -> bool {
    let lay = model.mech.layout();
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
            dt: model.dt(),
        };
        data.seen[c] |= 1 << data.trial[c].key().min(2);
        if matches!(data.trial[c], ContactState::Stick { .. }) {
            data.stick_fa[c] = trial.fa;
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
        // SPEC §3: ST3 → ST2 needs the reversal *and* |Fa| ≤ μS·N; a point
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
    if !touchdown {
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

/// Anchors of points that share a rigid body. SPEC §3 anchors a touchdown
/// where the point's straight path `p[k] → p[k+1]` crosses the terrain; for
/// two points of one body (a knee and a foot of one link, both hips) two
/// such anchors are not a rigid placement — their distance differs from the
/// points' by the body's motion during the step — and sticking at both
/// would tear the body apart. So on each body, the first point to stick
/// keeps its anchor (an already sticking point, or else the first point
/// anchored now, which keeps the SPEC's crossing), and every other point
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

fn states_key(states: &[ContactState]) -> u64 {
    states.iter().fold(0, |k, s| k * 4 + s.key())
}

fn describe_states(model: &Model, states: &[ContactState]) -> String {
    model
        .mech
        .contacts
        .iter()
        .zip(states)
        .map(|(c, s)| format!("{}={}", c.name, s.code()))
        .collect::<Vec<_>>()
        .join(" ")
}

fn make_record(
    model: &Model,
    data: &Data,
    newton_iterations: usize,
    state_trials: usize,
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
    r.kinetic = if data.k == 0 {
        energy::kinetic_exact(mech, &data.fbd.kin, &model.params.qdot0)
    } else {
        energy::kinetic_central(mech, &data.fbd.kin_prev, &data.fbd.kin_next, model.dt())
    };
    r
}

//! A landing that chattered (run 685 of `examples/sweep_landing_1000_1ms.toml`,
//! Δt = 1 ms): the hip of leg 3 slides while the foot of leg 4 lands sliding
//! at 0.7 m/s with its knee at the stop. The state search, one switch at a
//! time, found no consistent combination — the foot sliding with its knee
//! at the stop needs a pulling normal force, lifted it penetrates — and
//! every step from 0.516 s to 0.56 s was closed at Δt/64 by its least
//! inconsistent combination, the hip and the foot alternating between
//! sliding and lifting off: 1824 events. A consistent combination exists
//! two switches away (both points sliding forwards, the knee off its stop);
//! the search now tries every combination of the few points and stops
//! involved before giving up. The run writes a few dozen events, needs no
//! closure by the least inconsistent combination, and obeys Coulomb's law
//! and every body's force balance on every row.

mod common;

use common::physics::{landing, worst_body_imbalance};
use fbd_contact::StateCode;
use fbd_sim::{Data, Model, step};

#[test]
fn a_sliding_foot_whose_knee_leaves_its_stop_does_not_chatter() {
    let mut p = landing(
        -22.831102871279604,
        -58.98216613395488,
        0.4802801828580012,
        [-17.926821135182628, 245.8094977048047],
        [7.655920206361195, 251.676009983331],
        0.6085022338236266,
    );
    p.dt = 0.001;
    let model = Model::planar(&p).expect("valid parameters");
    assert_eq!(model.mech.contacts.len(), 6, "feet, knees and hips");
    let mut data = Data::new(&model);
    let mut rows = Vec::with_capacity(model.steps);
    for _ in 0..model.steps {
        rows.push(
            step(&model, &mut data)
                .expect("the landing completes")
                .clone(),
        );
    }

    let events = data.events.len() + data.limit_events.len();
    assert!(
        events <= 60,
        "{events} events: chatter ({} contact, {} limit)",
        data.events.len(),
        data.limit_events.len()
    );
    assert!(
        data.enumerated_cycles > 0,
        "the landing exercises the search over every combination"
    );
    assert_eq!(
        data.resolved_cycles, 0,
        "no step is closed by an inconsistent combination"
    );
    assert!(
        data.retries.iter().all(|r| r.substeps < model.max_substeps),
        "{:?}",
        data.retries
    );

    // Coulomb's law on every row (forces of the step's first (sub)step).
    let (mus, mud) = (p.friction.mu_static, p.friction.mu_dynamic);
    for r in &rows {
        for c in 0..r.contacts.len() {
            let (fa, n, name) = (
                r.contacts[c].tangential[0],
                r.contacts[c].normal,
                &model.mech.contacts[c].name,
            );
            let tol = 1e-6 * (1.0 + n.abs());
            match r.contacts[c].state {
                StateCode::St1 => assert!(fa.abs() < 1e-9 && n.abs() < 1e-9, "t = {}: {name}", r.t),
                StateCode::St2 => assert!(
                    n >= -1e-6 && fa.abs() <= mus * n + tol,
                    "t = {}: {name} sticking with fa = {fa}, n = {n}",
                    r.t
                ),
                StateCode::St3 => assert!(
                    n >= -1e-6 && (fa.abs() - mud * n).abs() <= tol,
                    "t = {}: {name} sliding with fa = {fa}, n = {n}",
                    r.t
                ),
            }
        }
    }

    // Every body balances on every row whose central difference spans no
    // retried step (a retried step's record holds its first substep's
    // forces).
    let retried = |k: usize| data.retries.iter().any(|r| r.step == k);
    for chunk in rows
        .split(|r| retried(r.step) || retried(r.step + 1))
        .filter(|c| c.len() >= 3)
    {
        let (worst, at) = worst_body_imbalance(&model, chunk);
        assert!(worst < 1e-6, "{at}");
    }
}

//! The contact-rich 3D landing at every Δt (issue 22, item 5): the passive
//! hexapod of `bench/peer/hexapod_drop.toml`, dropped tilted and spinning
//! onto its feet, knees and hips, at Δt = 4, 2, 1, 0.5 and 0.25 ms. Every
//! run completes with every row exact (the law audit); the first touchdown
//! and the first slip come at the same time to within two steps; the robot
//! comes to rest (no kinetic energy) at a place and height that
//! converges as Δt shrinks: within 3·Δt m (Δt in s) of the finest run's,
//! and closer at 1 ms than at 4 ms; and at a time that converges too
//! (closer to the finest run's at 1 and 0.5 ms than at 4 ms, within 20 ms
//! at 0.5 ms).
//!
//! The events: those of the touchdown (before 0.5 s) are the same number
//! at every Δt, to within five. The robot then settles by rocking on the
//! ring of its six hip points, each rock about a tenth of the tilt and a
//! third of the time of the one before (18.5, 1.39, 0.11, 0.011 mrad), to
//! rest at a finite time: infinitely many rocks in finite time, as a plate
//! dropped almost flat (Zeno), each a round of hip touchdowns, lift-offs
//! and the slips they jolt. A finer Δt resolves more rocks, about one more
//! for every threefold finer step, so the events grow by a roughly
//! constant number per halving (logarithmically; which rocks a step
//! resolves moves with the round-off), where a chatter at the step rate
//! would double them with every halving: from 4 to 0.25 ms they must grow
//! less than 8-fold (3.6-fold here; a chatter would be 16-fold). They are
//! printed, and checked against the README's "about 130 at 4 ms, 450 at
//! 0.25 ms", rounded to tens.

mod common;

use fbd_scenario::{Config, load};
use fbd_sim::spatial::{SpatialModel, run_collect};
use std::path::Path;

struct Landing {
    dt: f64,
    touchdown: f64,
    first_slip: f64,
    rest: [f64; 3],
    /// When the robot has come to rest: the end of the last step with
    /// kinetic energy above 1e-9 J (s).
    rest_from: f64,
    events: usize,
    /// Events before 0.5 s: the touchdown and its bounces and slips.
    touchdown_events: usize,
}

fn land(dt: f64) -> Landing {
    let path = Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/bench/peer/hexapod_drop.toml"
    ));
    let Config::Hexapod(c) = load(path).expect("the configuration loads") else {
        panic!("a hexapod configuration")
    };
    let mut p = c.spatial_params("hexapod_drop").expect("valid");
    p.dt = dt;
    let model = SpatialModel::new(&p).expect("a valid model");
    let (rows, summary) = run_collect(&model);
    if let Some(e) = &summary.error {
        panic!("Δt = {dt}: {e}");
    }
    assert_eq!(rows.len(), model.steps);
    let weight = model.mech.total_mass() * model.params.gravity;
    assert!(
        summary.max_law_violation <= 1e-6 * weight,
        "Δt = {dt}: a row breaks a law by {} N",
        summary.max_law_violation
    );
    let touchdown = summary
        .events
        .iter()
        .find(|e| e.from == fbd_contact::StateCode::St1)
        .expect("a touchdown")
        .t;
    let first_slip = summary
        .events
        .iter()
        .find(|e| e.to == fbd_contact::StateCode::St3)
        .expect("a slip")
        .t;
    let last = rows.last().unwrap();
    assert!(
        last.kinetic < 1e-9,
        "Δt = {dt}: still moving at the end ({} J)",
        last.kinetic
    );
    let rest = [last.q[0], last.q[1], last.q[2]];
    let rest_from = rows
        .iter()
        .rev()
        .find(|r| r.kinetic > 1e-9)
        .map_or(0.0, |r| r.t + dt);
    let times = summary
        .events
        .iter()
        .map(|e| e.t)
        .chain(summary.limit_events.iter().map(|e| e.t));
    Landing {
        dt,
        touchdown,
        first_slip,
        rest,
        rest_from,
        events: summary.events.len() + summary.limit_events.len(),
        touchdown_events: times.filter(|&t| t < 0.5).count(),
    }
}

#[test]
fn the_landing_converges_as_dt_shrinks() {
    let runs: Vec<Landing> = [0.004, 0.002, 0.001, 0.0005, 0.00025]
        .into_iter()
        .map(land)
        .collect();
    let fine = runs.last().unwrap();
    let mut errors = Vec::new();
    for r in &runs {
        println!(
            "Δt = {:6.2} ms: touchdown {:.4} s, first slip {:.4} s, rest at ({:+.4}, {:+.4}, {:+.4}) m from {:.4} s, {} events ({} before 0.5 s)",
            r.dt * 1e3,
            r.touchdown,
            r.first_slip,
            r.rest[0],
            r.rest[1],
            r.rest[2],
            r.rest_from,
            r.events,
            r.touchdown_events
        );
        assert!(
            r.touchdown_events.abs_diff(fine.touchdown_events) <= 5,
            "Δt = {}: {} events before 0.5 s, {} at the finest",
            r.dt,
            r.touchdown_events,
            fine.touchdown_events
        );
        // Within two steps of the finest run's time.
        let within_two_steps = |what: &str, t: f64, finest: f64| {
            assert!(
                (t - finest).abs() <= 2.0 * r.dt + 1e-12,
                "Δt = {}: {what} at {t} s, {finest} s at the finest",
                r.dt
            );
        };
        within_two_steps("touchdown", r.touchdown, fine.touchdown);
        within_two_steps("first slip", r.first_slip, fine.first_slip);
        let e = (r.rest[0] - fine.rest[0]).hypot(r.rest[2] - fine.rest[2]);
        assert!(
            e <= 3.0 * r.dt,
            "Δt = {}: rests {e:.4} m from the finest run's place",
            r.dt
        );
        assert!(
            (r.rest[1] - fine.rest[1]).abs() < 1e-3,
            "Δt = {}: rests at another height",
            r.dt
        );
        errors.push(e);
    }
    assert!(
        errors[2] < errors[0],
        "the rest place does not converge: {errors:?}"
    );
    // The time of rest converges: the settling's last rocks are resolved
    // as Δt shrinks, and they are ever shorter.
    let late: Vec<f64> = runs
        .iter()
        .map(|r| (r.rest_from - fine.rest_from).abs())
        .collect();
    assert!(
        late[2] < late[0] && late[3] < late[0] && late[3] < 0.02,
        "the time of rest does not converge: {late:?} s from the finest run's"
    );
    // The events grow far slower than the steps (the rocks of a settling
    // resolved one by one, not a chatter at the step rate).
    let (coarse, finest) = (&runs[0], &runs[4]);
    assert!(
        finest.events < 8 * coarse.events,
        "{} events at Δt = {}, {} at Δt = {}: chatter at the step rate",
        coarse.events,
        coarse.dt,
        finest.events,
        finest.dt
    );
    // The README's "about 130 at 4 ms, 450 at 0.25 ms": the events rounded
    // to tens.
    let readme = common::readme::doc("README.md");
    let tens = |n: usize| (n as f64 / 10.0).round() * 10.0;
    readme.figure(
        "grow as Δt shrinks (about ",
        " at 4 ms, ",
        tens(runs[0].events),
        "events of the landing at 4 ms",
    );
    readme.figure(
        " at 4 ms, ",
        " at 0.25 ms on that landing",
        tens(runs[4].events),
        "events of the landing at 0.25 ms",
    );
}

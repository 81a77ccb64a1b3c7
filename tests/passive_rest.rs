//! The paper's passive robot with knee and hip contacts (the default): it
//! falls, lands on its feet, slips, lands on its body and knees, and comes
//! to rest on the ground — and on frictionless ground its energy never grows
//! beyond the scheme's O(Δt²) oscillation.

mod common;

use common::physics::{plane, run_ok, worst_body_imbalance};
use fbd_contact::StateCode;
use fbd_sim::PlanarParams;

#[test]
fn the_passive_experiment_runs_to_rest() {
    let p = PlanarParams::default();
    assert!(p.contact_points.knees && p.contact_points.hips);
    let (model, rows, summary) = run_ok(&p);
    let last = rows.last().unwrap();
    assert!((last.t - p.duration).abs() < 1e-9);
    // At rest on the ground: every point in contact sticks and pushes, the
    // others are clear of it, and together they carry the weight.
    assert_eq!(last.contacts.len(), 6);
    for c in 0..6 {
        match last.contacts[c].state {
            StateCode::St2 => assert!(
                last.contacts[c].normal > 0.0,
                "point {c}: n = {}",
                last.contacts[c].normal
            ),
            StateCode::St1 => assert!(p.terrain.clearance(plane(last.contacts[c].point)) > 0.0),
            StateCode::St3 => panic!("point {c} still slides at the end"),
        }
    }
    let resting = last.contacts[..6]
        .iter()
        .filter(|c| c.state == StateCode::St2)
        .count();
    assert!(resting >= 4, "resting on {resting} points");
    let w = model.mech.total_mass() * p.gravity;
    let n: f64 = last.contacts[..6].iter().map(|c| c.normal).sum();
    let fa: f64 = last.contacts[..6].iter().map(|c| c.tangential[0]).sum();
    assert!((n - w).abs() < 1e-6 * w, "Σn = {n}, weight {w}");
    assert!(fa.abs() < 1e-6 * w, "Σfa = {fa}");
    assert!(
        last.kinetic < 1e-12,
        "kinetic energy at the end {}",
        last.kinetic
    );
    // The body landed on both hips and at least one knee touched down.
    let touched = |name: &str| {
        summary
            .events
            .iter()
            .any(|e| format!("{}{}", e.point, e.leg) == name && e.from == StateCode::St1)
    };
    assert!(touched("hip3") && touched("hip4"), "the body never landed");
    // The joint limits keep the legs from folding flat: a hip stops at its
    // limit, no knee reaches the ground, every angle stays in its range.
    assert!(!summary.limit_events.is_empty(), "no joint reached a limit");
    assert!(
        !touched("knee3") && !touched("knee4"),
        "a knee touched down"
    );
    let l = &p.joint_limits;
    for r in &rows {
        for (i, range) in [l.theta2, l.theta3, l.theta2, l.theta3].iter().enumerate() {
            let a = r.q[6 + i];
            assert!(
                a >= range[0] - 1e-9 && a <= range[1] + 1e-9,
                "t = {}: joint angle q[{}] = {a} outside {range:?}",
                r.t,
                3 + i
            );
        }
    }
    let (worst, at) = worst_body_imbalance(&model, &rows);
    assert!(worst < 1e-6, "{at}");
}

#[test]
fn energy_never_grows_beyond_second_order_on_frictionless_ground() {
    // A thrown, spinning robot with moving legs lands on frictionless ground:
    // impacts dissipate, sliding does not, nothing may create energy. The
    // discrete energy (central-difference velocities) may exceed its start
    // only by the scheme's O(Δt²) oscillation.
    let excess = |dt: f64| {
        let mut p = PlanarParams {
            dt,
            duration: 1.5,
            ..PlanarParams::default()
        };
        p.friction.mu_static = 0.0;
        p.friction.mu_dynamic = 0.0;
        p.qdot0 = [0.7, 1.5, 2.0, -3.0, 4.0, 2.5, -1.0];
        let (_, rows, summary) = run_ok(&p);
        assert!(
            summary.events.iter().any(|e| e.to == StateCode::St3),
            "the run must slide"
        );
        let e0 = rows[0].kinetic + rows[0].potential;
        let last = rows.last().unwrap();
        assert!(
            last.kinetic + last.potential < 0.5 * e0,
            "impacts must dissipate"
        );
        rows.iter()
            .map(|r| r.kinetic + r.potential - e0)
            .fold(f64::MIN, f64::max)
            / e0
    };
    let (e1, e2, e3) = (excess(0.005), excess(0.0025), excess(0.00125));
    eprintln!("relative energy excess {e1:e} {e2:e} {e3:e}");
    assert!(e1 < 1e-6, "energy grew by {e1} of its start");
    for (a, b) in [(e1, e2), (e2, e3)] {
        let ratio = a / b;
        assert!(
            (3.0..5.5).contains(&ratio),
            "halving Δt divided the excess by {ratio} (relative excesses {e1:e}, {e2:e}, {e3:e}); O(Δt²) expects ≈ 4"
        );
    }
}

//! Flight (`terrain.kind = "none"`): free fall, conservation of momentum
//! and angular momentum, second-order convergence.

mod common;

use common::physics::{angular_momentum, momentum, run_ok, system_com};
use fbd_contact::Terrain;
use fbd_sim::PlanarParams;

fn flight(dt: f64, duration: f64, tumbling: bool) -> PlanarParams {
    let mut p = PlanarParams {
        dt,
        duration,
        terrain: Terrain::None,
        // Free joints: the conservation laws of the scheme itself (a stop
        // at a joint limit is a plastic impact and takes energy out; it
        // conserves momentum, tested below with the limits on).
        joint_limits: fbd_sim::JointLimits::none(),
        ..PlanarParams::default()
    };
    if tumbling {
        // A thrown, spinning robot with moving legs.
        p.qdot0 = [0.7, 1.5, 2.0, -3.0, 4.0, 2.5, -1.0];
    }
    p
}

#[test]
fn centre_of_mass_falls_exactly_g_t2_over_2_from_rest() {
    let (model, rows, _) = run_ok(&flight(0.01, 1.0, false));
    let c0 = system_com(&model, &rows[0].plane_q());
    for r in &rows {
        let c = system_com(&model, &r.plane_q());
        let expect = c0[1] - 0.5 * 9.81 * r.t * r.t;
        assert!(
            (c[1] - expect).abs() < 1e-9,
            "t = {}: y_cm = {}, g t²/2 predicts {}",
            r.t,
            c[1],
            expect
        );
        assert!(
            (c[0] - c0[0]).abs() < 1e-12,
            "t = {}: x_cm drifted to {}",
            r.t,
            c[0]
        );
        // From rest, a uniform field exerts no internal forces.
        for f in &r.reaction_force {
            assert!(
                f[0].abs() < 1e-6 && f[1].abs() < 1e-6,
                "t = {}: joint force {f:?} in free fall",
                r.t
            );
        }
    }
}

#[test]
fn momentum_and_angular_momentum_are_conserved_while_tumbling() {
    // With the default joint limits: the stops act on the legs and their
    // moments are internal, equal and opposite on the two bodies of a joint.
    let mut p = flight(0.005, 1.0, true);
    p.joint_limits = fbd_sim::JointLimits::default();
    let (model, rows, summary) = run_ok(&p);
    assert!(
        !summary.limit_events.is_empty(),
        "the tumbling legs must reach a joint limit"
    );
    let dt = p.dt;
    let p0 = momentum(&model, &rows[0].plane_q(), &rows[1].plane_q(), dt);
    let l0 = angular_momentum(&model, &rows[0].plane_q(), &rows[1].plane_q(), dt);
    assert!(l0.abs() > 0.1, "the test needs a spinning robot (L = {l0})");
    let m = model.mech.total_mass();
    for w in rows.windows(2) {
        let pk = momentum(&model, &w[0].plane_q(), &w[1].plane_q(), dt);
        let lk = angular_momentum(&model, &w[0].plane_q(), &w[1].plane_q(), dt);
        assert!(
            (pk[0] - p0[0]).abs() < 1e-8 * m,
            "t = {}: horizontal momentum {} vs {}",
            w[0].t,
            pk[0],
            p0[0]
        );
        // Vertical momentum changes by exactly −M g Δt per step.
        let expect_y = p0[1] - m * 9.81 * w[0].t;
        assert!(
            (pk[1] - expect_y).abs() < 1e-7 * m,
            "t = {}: vertical momentum {} vs {}",
            w[0].t,
            pk[1],
            expect_y
        );
        assert!(
            (lk - l0).abs() < 1e-8 * l0.abs().max(1.0),
            "t = {}: angular momentum {} vs {}",
            w[0].t,
            lk,
            l0
        );
    }
}

#[test]
fn trajectory_error_is_second_order() {
    let t_end = 0.3;
    let final_q = |dt: f64| {
        // Solved to round-off, so that only the discretisation error shows.
        let mut model = fbd_sim::Model::planar(&flight(dt, t_end, true)).unwrap();
        model.newton.residual_tol = 3e-11;
        model.newton.step_residual_factor = 10.0;
        let (rows, summary) = fbd_sim::run_collect(&model);
        assert!(summary.error.is_none(), "{:?}", summary.error);
        let last = rows.last().unwrap();
        assert!((last.t - t_end).abs() < 1e-9);
        last.plane_q()
    };
    let reference = final_q(0.004 / 64.0);
    let err = |dt: f64| {
        let q = final_q(dt);
        q.iter()
            .zip(&reference)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max)
    };
    let (e1, e2, e3) = (err(0.004), err(0.002), err(0.001));
    eprintln!("errors {e1:e} {e2:e} {e3:e} ratios {} {}", e1 / e2, e2 / e3);
    for (a, b) in [(e1, e2), (e2, e3)] {
        let ratio = a / b;
        assert!(
            (3.2..5.0).contains(&ratio),
            "halving Δt divided the error by {ratio} (errors {e1:e}, {e2:e}, {e3:e}); second order expects ≈ 4"
        );
    }
    // The README quotes both ratios.
    let readme = common::readme::doc("README.md");
    readme.figure(
        "(halving Δt from 4 ms divides it by ",
        ", then ",
        e1 / e2,
        "flight: order of convergence",
    );
    let first = readme.quoted("(halving Δt from 4 ms divides it by ", ", then ");
    readme.figure(
        &format!("divides it by {first}, then "),
        "; `tests/flight.rs`)",
        e2 / e3,
        "flight: order of convergence",
    );
}

#[test]
fn energy_is_conserved_in_flight_up_to_second_order_oscillation() {
    let (_, rows, _) = run_ok(&flight(0.002, 1.0, true));
    let e0 = rows[1].kinetic + rows[1].potential;
    let worst = rows[1..]
        .iter()
        .map(|r| (r.kinetic + r.potential - e0).abs())
        .fold(0.0, f64::max);
    // O(Δt²) oscillation of the mixed-time-level energy, no drift.
    assert!(
        worst < 1e-3 * e0.abs(),
        "energy deviates by {worst} J of {e0} J"
    );
}

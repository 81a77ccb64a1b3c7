//! The whole 3D robot in flight, tumbling with its legs swinging (passive
//! joints, no ground, no joint limits): the centre of mass falls exactly
//! `g·t²/2`, the linear momentum is exact, the angular momentum conserved
//! to 1e-9 relative, no energy drift over 1e5 steps, and the scheme is of
//! second order in Δt.

use fbd_contact::{Surface, Terrain};
use fbd_dynamics::spatial::SpatialKin;
use fbd_kinematics::JointLimits;
use fbd_kinematics::nalgebra::Vector3;
use fbd_sim::spatial::{SpatialModel, SpatialParams, closed_form, run_collect, run_until};
use std::sync::atomic::AtomicBool;

mod common;

/// A tumbling robot: tilted body spinning about all three axes, every
/// joint moving.
fn tumbling(dt: f64, duration: f64, gravity: f64) -> SpatialParams {
    let mut p = SpatialParams {
        dt,
        duration,
        gravity,
        terrain: Surface::new(Terrain::None, 0.0),
        joint_limits: JointLimits::none(),
        ..SpatialParams::default()
    };
    p.q0[3..6].copy_from_slice(&[0.2, -0.3, 0.25]);
    p.qdot0[..6].copy_from_slice(&[0.3, 1.0, -0.2, 1.2, -2.0, 0.8]);
    for s in 0..6 {
        let f = s as f64;
        p.q0[6 + 3 * s] = 0.1 * (f - 2.5);
        p.q0[7 + 3 * s] = -0.2 + 0.05 * f;
        p.qdot0[6 + 3 * s] = 1.5 - 0.5 * f;
        p.qdot0[7 + 3 * s] = -1.0 + 0.4 * f;
        p.qdot0[8 + 3 * s] = 2.4 - 0.7 * f;
    }
    p
}

/// The centre of mass from the closed-form hexapod (an independent
/// reference for the generic tree kinematics the model steps on).
fn com(model: &SpatialModel, q: &[f64]) -> Vector3<f64> {
    let mech = closed_form(&model.params);
    let mut kin = SpatialKin::new(&mech);
    kin.eval(&mech, q);
    let m = mech.total_mass();
    mech.bodies
        .iter()
        .zip(&kin.com)
        .map(|(b, c)| b.mass * c)
        .sum::<Vector3<f64>>()
        / m
}

#[test]
fn the_centre_of_mass_falls_exactly_and_momentum_is_exact() {
    let p = tumbling(0.001, 1.0, 9.81);
    let model = SpatialModel::new(&p).unwrap();
    let (rows, summary) = run_collect(&model);
    assert!(summary.error.is_none(), "{:?}", summary.error);
    let c0 = com(&model, &rows[0].q);
    // Initial CoM velocity from the momentum of the first half step.
    let m = model.mech.total_mass();
    let p_half = Vector3::from(rows[0].momentum);
    let v0 = p_half / m + Vector3::new(0.0, 0.5 * 9.81 * p.dt, 0.0);
    let mut worst: f64 = 0.0;
    for r in &rows {
        let t = r.t;
        let want = c0 + v0 * t + Vector3::new(0.0, -0.5 * 9.81 * t * t, 0.0);
        worst = worst.max((com(&model, &r.q) - want).norm());
        // p[k+½] = p[½] − M·g·k·Δt, exactly.
        let want_p = p_half + Vector3::new(0.0, -m * 9.81 * t, 0.0);
        let dp = (Vector3::from(r.momentum) - want_p).norm();
        assert!(dp < 1e-9 * m * 9.81, "t = {t}: momentum off by {dp:e}");
    }
    println!("CoM vs g·t²/2: max deviation {worst:.2e} m over 1 s");
    let b = bounds("free fall of the tumbling robot's centre of mass vs `g·t²/2` over 1 s");
    assert!(
        worst <= b[0],
        "README.md is stale: {worst:e} m, bound {}",
        b[0]
    );
    // Exact up to the solver's tolerance on the force rows (1e-9 of the
    // weight): 5 nm after a 4.9 m fall would be that tolerance everywhere.
    assert!(worst < 1e-8, "the centre of mass deviates by {worst:e} m");
}

/// Runs the weightless tumbling robot for `n` steps; returns the largest
/// relative change of the angular momentum, the kinetic energy's mean over
/// the first and the last 1000 steps and its range.
fn weightless(n: usize) -> (f64, f64, f64, f64, f64) {
    let p = tumbling(0.001, (n - 1) as f64 * 0.001, 0.0);
    let mut model = SpatialModel::new(&p).unwrap();
    // Conservation is to the solver's tolerance: a tenth of the default.
    model.newton.residual_tol = 1e-10;
    let (mut h0, mut e_first, mut e_last) = (None, 0.0, 0.0);
    let (mut worst_h, mut e_min, mut e_max): (f64, f64, f64) = (0.0, f64::INFINITY, 0.0);
    let mut k = 0;
    let window = 1000.min(n);
    let summary = run_until(&model, &AtomicBool::new(false), |r| {
        let h = Vector3::from(r.angular_momentum);
        let h0 = *h0.get_or_insert(h);
        worst_h = worst_h.max((h - h0).norm() / h0.norm());
        let e = r.kinetic;
        e_min = e_min.min(e);
        e_max = e_max.max(e);
        if k < window {
            e_first += e / window as f64;
        }
        if k >= n - window {
            e_last += e / window as f64;
        }
        k += 1;
    });
    assert!(summary.error.is_none(), "{:?}", summary.error);
    assert_eq!(summary.steps, n);
    println!(
        "{n} steps: |ΔH|/|H| ≤ {worst_h:.2e}; kinetic energy {e_min:.6}..{e_max:.6} J, means of the first and last 1000 steps {e_first:.9} {e_last:.9}; {:.0} steps/s",
        summary.steps_per_second()
    );
    (worst_h, e_first, e_last, e_min, e_max)
}

/// The README's row of the momentum figures.
const MOMENTUM_ROW: &str = "angular momentum of the weightless tumbling robot, 2000 steps / 1e5 steps (solver tolerance 1e-10)";

/// The bounds `below X` quoted in the README's row `first` (round-off
/// figures are quoted as bounds: any change of the arithmetic moves them).
fn bounds(first: &str) -> Vec<f64> {
    let row = common::readme::doc("README.md").row(first);
    row[1]
        .split("below ")
        .skip(1)
        .map(|b| common::readme::parse(b.split([' ', ')']).next().unwrap()))
        .collect()
}

#[test]
fn angular_momentum_is_conserved_to_1e_9() {
    let (worst_h, ..) = weightless(2000);
    let b = bounds(MOMENTUM_ROW);
    assert!(
        worst_h <= b[0],
        "README.md is stale: {worst_h:e}, bound {}",
        b[0]
    );
    assert!(
        worst_h < 1e-9,
        "angular momentum drifts by {worst_h:e} (relative)"
    );
}

#[test]
fn no_energy_drift_over_1e5_steps() {
    let (worst_h, e_first, e_last, e_min, e_max) = weightless(100_000);
    let drift = (e_last - e_first).abs() / e_first;
    let b = bounds(MOMENTUM_ROW);
    assert!(
        worst_h <= b[1],
        "README.md is stale: {worst_h:e}, bound {}",
        b[1]
    );
    let e = bounds("kinetic energy, mean of the first vs the last 1000 of 1e5 steps");
    let range = (e_max - e_min) / e_first;
    assert!(
        drift <= e[0] && range <= e[1],
        "README.md is stale: drift {drift:e}, range {range:e}, bounds {e:?}"
    );
    assert!(drift < 1e-5, "energy drifts by {drift:e} (relative)");
    assert!(
        (e_max - e_min) / e_first < 1e-3,
        "energy oscillates by more than 0.1 %"
    );
    assert!(
        worst_h < 2e-6,
        "angular momentum drifts by {worst_h:e} over 1e5 steps"
    );
}

#[test]
fn the_scheme_is_second_order() {
    let t = 0.25;
    // The configuration every 10 ms over [0, t].
    let samples = |dt: f64| {
        let p = tumbling(dt, t, 9.81);
        let model = SpatialModel::new(&p).unwrap();
        let (rows, s) = run_collect(&model);
        assert!(s.error.is_none(), "{:?}", s.error);
        let every = (0.01 / dt).round() as usize;
        rows.iter()
            .step_by(every)
            .map(|r| r.q.clone())
            .collect::<Vec<_>>()
    };
    let reference = samples(1e-3 / 16.0);
    let err = |dt: f64| {
        let s = samples(dt);
        assert_eq!(s.len(), reference.len());
        s.iter()
            .zip(&reference)
            .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
            .fold(0.0, f64::max)
    };
    let (e1, e2, e3) = (err(2e-3), err(1e-3), err(0.5e-3));
    let (p1, p2) = ((e1 / e2).log2(), (e2 / e3).log2());
    println!("max |q − q_ref| over [0, {t}] s: {e1:.3e} {e2:.3e} {e3:.3e}; orders {p1:.3} {p2:.3}");
    let row = common::readme::doc("README.md")
        .row("order of convergence (whole robot; single free body)");
    assert!(
        row[1].starts_with(&format!("{p1:.3}, {p2:.3};")),
        "README.md is stale: quotes {}, the runs give {p1:.3}, {p2:.3}",
        row[1]
    );
    assert!(
        (1.8..2.2).contains(&p1) && (1.8..2.2).contains(&p2),
        "orders {p1} {p2}"
    );
}

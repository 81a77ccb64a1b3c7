//! Static stability of the tripod gait.
//!
//! * The symmetric tripod stance (legs 1, 4, 5 at the neutral pose, every
//!   leg alike) is an equilateral triangle of circumradius
//!   `ρ = d + a·cosθ2 − c·cos(θ2 + θ3)` around the body centre, and the
//!   centre of mass is on the body's vertical axis: the margin is the
//!   inradius `ρ/2` (0.297 m for the paper's robot at θ = (0°, 0°, 245°)).
//! * Walking straight at β = ½ with stride `s`, the centre of mass moves
//!   `±s/2` along the heading relative to each support triangle, whose
//!   slanted edges face it at 60°: the smallest margin is
//!   `ρ/2 − (s/2)·sin 60°`, up to the shift of the centre of mass by the
//!   swinging legs. What the test shows: β = ½ is statically stable
//!   throughout (three feet always down, margin ≥ 0.25 m at s = 0.1 m); β
//!   = 0.45 is not (all six feet are in the air between the tripods'
//!   swings, margin −∞); β = 0.55 (the tripods overlap) is stable with at
//!   least β = ½'s margin.

mod common;

use common::gait::{model, run, run_ok};
use fbd_sim::gait::{Command, GaitKind, GaitParams};

fn walk(duty: f64, stride: f64) -> GaitParams {
    GaitParams {
        duty,
        forward: Command::Constant(stride),
        ramp: 0.0,
        walk_time: 4.0,
        ..GaitParams::preset(GaitKind::Tripod)
    }
}

#[test]
fn symmetric_tripod_stance_margin_is_the_inradius() {
    let m = model(walk(0.5, 0.0), 0.01, 0.2);
    let (rows, _) = run_ok(&m);
    let (a, c) = (0.2, 0.42);
    let d = 0.25 * (30f64).to_radians().cos();
    let th3 = 245f64.to_radians();
    let rho = d + a - c * th3.cos();
    // At t = 0.1 legs 1, 4, 5 swing: legs 2, 3, 6 stand.
    let r = &rows[10];
    assert_eq!(r.stance(), [false, true, true, false, false, true]);
    assert!(
        (r.margin - rho / 2.0).abs() < 1e-3,
        "margin {} vs ρ/2 = {}",
        r.margin,
        rho / 2.0
    );
    // The centre of mass is on the body's axis when every leg is alike.
    assert!(
        (rows[0].margin - rho / 2.0).abs() < 1e-12,
        "{}",
        rows[0].margin
    );
}

#[test]
fn tripod_is_stable_at_half_duty_and_not_below() {
    let rho = 0.25 * 30f64.to_radians().cos() + 0.2 - 0.42 * 245f64.to_radians().cos();
    let s = 0.1;
    let (rows, sum) = run_ok(&model(walk(0.5, s), 0.01, 5.0));
    let min = sum.min_margin.unwrap().0;
    let hand = rho / 2.0 - 0.5 * s * 60f64.to_radians().sin();
    assert!(
        rows.iter()
            .all(|r| r.stance().iter().filter(|x| **x).count() >= 3)
    );
    assert!(
        (min - hand).abs() < 0.01,
        "β = ½: min margin {min} vs hand {hand}"
    );
    let (_, under) = run(&model(walk(0.45, s), 0.01, 5.0));
    assert_eq!(under.min_margin.unwrap().0, f64::NEG_INFINITY, "β = 0.45");
    let (_, over) = run_ok(&model(walk(0.55, s), 0.01, 5.0));
    assert!(over.min_margin.unwrap().0 >= min - 1e-9, "β = 0.55");
}

//! Joint rates (from the analytic leg Jacobian, not from differences) equal
//! the central differences of the joint angles to O(Δt²): halving Δt
//! divides the largest difference by about 4. Accelerations likewise match
//! the central differences of the rates. The joint controller's targets
//! are the gait's angles and rates, bit for bit, without accelerations.

mod common;

use common::gait::{model, run_ok};
use fbd_sim::gait::{Command, GaitKind, GaitParams};

fn worst(dt: f64) -> (f64, f64) {
    let params = GaitParams {
        forward: Command::Constant(0.07),
        lateral: Command::Constant(-0.02),
        yaw_rate: Command::Constant(6f64.to_radians()),
        sway: 0.01,
        height: 0.01,
        pitch: 2f64.to_radians(),
        walk_time: 3.0,
        ..GaitParams::preset(GaitKind::Ripple)
    };
    let m = model(params, dt, 3.5);
    let (rows, _) = run_ok(&m);
    let (mut rate_err, mut acc_err) = (0.0f64, 0.0f64);
    // Central differences of the rates are O(Δt²) only where the jerk is
    // continuous: skip the windows that straddle a lift-off or touchdown
    // (the swing curve's jerk starts and stops there) and the ends of the
    // start-up and stop blends (0.5 s, 2.5 s, 3 s).
    let kinks = [0.5, 2.5, 3.0];
    for w in rows.windows(3) {
        let straddles =
            w[0].stance() != w[2].stance() || kinks.iter().any(|k| (w[1].t - k).abs() < 1.5 * dt);
        for leg in 0..6 {
            if straddles {
                continue;
            }
            for j in 0..3 {
                let fd = (w[2].legs[leg].theta[j] - w[0].legs[leg].theta[j]) / (2.0 * dt);
                rate_err = rate_err.max((fd - w[1].legs[leg].rate[j]).abs());
                let fa = (w[2].legs[leg].rate[j] - w[0].legs[leg].rate[j]) / (2.0 * dt);
                acc_err = acc_err.max((fa - w[1].legs[leg].accel[j]).abs());
            }
        }
    }
    (rate_err, acc_err)
}

#[test]
fn rates_and_accelerations_are_second_order_consistent() {
    let (r1, a1) = worst(0.004);
    let (r2, a2) = worst(0.002);
    // The swing's jerk (≈ 10³ rad/s³ with a third-of-a-second swing) sets
    // the size: Δt²/6·jerk ≈ 3e-3 rad/s at Δt = 4 ms.
    assert!(
        r1 < 2e-2 && a1 < 1.0,
        "Δt = 0.004: rate error {r1:e}, acceleration error {a1:e}"
    );
    let (rr, ra) = (r1 / r2, a1 / a2);
    assert!(
        (3.5..4.5).contains(&rr),
        "rate error ratio {rr} ({r1:e} → {r2:e}), expected ≈ 4"
    );
    assert!(
        (3.0..5.0).contains(&ra),
        "acceleration error ratio {ra} ({a1:e} → {a2:e}), expected ≈ 4"
    );
}

/// The joint controller's targets (`step_targets`, without the joint
/// accelerations) are the kinematic gait's (`step`) angles and rates bit
/// for bit, on a turning, swaying, pitching walk; their accelerations are
/// NaN (not computed), the gait's finite.
#[test]
fn controller_targets_are_the_gaits_angles_and_rates() {
    let params = GaitParams {
        forward: Command::Constant(0.07),
        yaw_rate: Command::Constant(6f64.to_radians()),
        sway: 0.01,
        pitch: 2f64.to_radians(),
        walk_time: 1.5,
        ..GaitParams::preset(GaitKind::Tripod)
    };
    let m = model(params, 0.002, 2.0);
    let (rows, _) = run_ok(&m);
    let mut targets = fbd_sim::gait::GaitData::new(&m);
    for (k, row) in rows.iter().enumerate() {
        fbd_sim::gait::step_targets(&m, &mut targets, k).unwrap();
        for (leg, (a, b)) in targets.legs.iter().zip(&row.legs).enumerate() {
            let bits = |v: [f64; 3]| v.map(f64::to_bits);
            assert_eq!(bits(a.theta), bits(b.theta), "step {k}, leg {leg}");
            assert_eq!(bits(a.rate), bits(b.rate), "step {k}, leg {leg}");
            assert!(a.accel.iter().all(|x| x.is_nan()), "step {k}, leg {leg}");
            assert!(b.accel.iter().all(|x| x.is_finite()), "step {k}, leg {leg}");
        }
    }
}

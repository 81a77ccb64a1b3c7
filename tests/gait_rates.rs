//! Joint rates (from the analytic leg Jacobian, not from differences) equal
//! the central differences of the joint angles to O(Δt²): halving Δt
//! divides the largest difference by about 4. Accelerations likewise match
//! the central differences of the rates.

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
    for w in rows.windows(3) {
        for leg in 0..6 {
            for j in 0..3 {
                let fd = (w[2].legs[leg].theta[j] - w[0].legs[leg].theta[j]) / (2.0 * dt);
                let e = (fd - w[1].legs[leg].rate[j]).abs();
                if e > rate_err && std::env::var("GAIT_DEBUG").is_ok() {
                    eprintln!("t {} leg {} j {} err {e:e} phase {:?}", w[1].t, leg + 1, j + 1, w[1].phases[leg]);
                }
                rate_err = rate_err.max(e);
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
    assert!(r1 < 1e-3 && a1 < 0.05, "Δt = 0.004: rate error {r1:e}, acceleration error {a1:e}");
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

//! The body follows the commanded twist: over one period its displacement
//! and heading change equal the twist integrated in closed form (an arc),
//! and the body velocity the trajectory reports is its derivative.

mod common;

use common::gait::{model, run_ok};
use fbd_sim::gait::{Command, GaitParams};

#[test]
fn displacement_over_a_period_is_the_integrated_twist() {
    let (vf, vl, w) = (0.06f64, 0.02f64, 8f64.to_radians());
    let params = GaitParams {
        forward: Command::Constant(vf),
        lateral: Command::Constant(vl),
        yaw_rate: Command::Constant(w),
        ramp: 0.0,
        walk_time: 10.0,
        ..GaitParams::default()
    };
    let dt = 0.01;
    let m = model(params, dt, 4.0);
    let (rows, _) = run_ok(&m);
    // One period T = 1 s from t = 1 s: rows 100 and 200.
    let (a, b) = (&rows[100], &rows[200]);
    let (psi0, psi1) = (a.body.phi.y, b.body.phi.y);
    assert!(
        (psi1 - psi0 - w).abs() < 1e-12,
        "heading change {}",
        psi1 - psi0
    );
    // ẋ = −v_f·sinψ + v_l·cosψ, ż = −v_f·cosψ − v_l·sinψ integrated.
    let dx = (vf * (psi1.cos() - psi0.cos()) + vl * (psi1.sin() - psi0.sin())) / w;
    let dz = (-vf * (psi1.sin() - psi0.sin()) + vl * (psi1.cos() - psi0.cos())) / w;
    let gx = b.body.position.x - a.body.position.x;
    let gz = b.body.position.z - a.body.position.z;
    assert!(
        (gx - dx).abs() < 1e-10 && (gz - dz).abs() < 1e-10,
        "displacement ({gx}, {gz}) vs integrated twist ({dx}, {dz})"
    );
    assert!((b.body.position.y - a.body.position.y).abs() < 1e-15);
    // The reported body velocity is the derivative of the position.
    for k in [50, 150, 250] {
        let v = (rows[k + 1].body.position - rows[k - 1].body.position) / (2.0 * dt);
        assert!(
            (v - rows[k].body.velocity).norm() < 1e-6,
            "t {}: {v} vs {}",
            rows[k].t,
            rows[k].body.velocity
        );
    }
}

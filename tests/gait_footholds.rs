//! Footholds: at mid-stance every foot is at its neutral position relative
//! to the body (the initial stance carried by the body's heading), and on
//! the terrain.

mod common;

use common::gait::{model, run_ok};
use fbd_sim::gait::{Command, GaitParams};

#[test]
fn feet_are_neutral_at_mid_stance() {
    let params = GaitParams {
        forward: Command::Constant(0.08),
        yaw_rate: Command::Constant(5f64.to_radians()),
        walk_time: 10.0,
        ..GaitParams::default()
    };
    let m = model(params, 0.01, 4.0);
    let psi0 = m.initial.phi[1];
    let (rows, _) = run_ok(&m);
    let mut checked = 0;
    // Tripod, T = 1 s: leg 1 stands over [0.5, 1), mid-stance 0.75, 1.75, …
    // leg 2 over [0, 0.5) + k, mid-stance 1.25, 2.25, …
    for (leg, mids) in [(0usize, [0.75, 1.75, 2.75]), (1, [1.25, 2.25, 3.25])] {
        for t in mids {
            let d = &rows[(t / 0.01f64).round() as usize];
            assert!(d.stance()[leg]);
            let (s, c) = (d.body.phi.y - psi0).sin_cos();
            let f = d.feet[leg] - d.body.position;
            // Rotate the offset back by the heading change.
            let back = [c * f.x - s * f.z, s * f.x + c * f.z];
            let n = m.neutral[leg];
            assert!(
                (back[0] - n[0]).abs() < 1e-9 && (back[1] - n[1]).abs() < 1e-9,
                "leg {} at t {t}: {back:?} vs neutral {n:?}",
                leg + 1
            );
            assert!(d.feet[leg].y.abs() < 1e-15, "foot on the ground");
            checked += 1;
        }
    }
    assert_eq!(checked, 6);
}

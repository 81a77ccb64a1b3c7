//! Both tips start on the ground with very high friction: they stay in
//! ST2, and the contact forces carry the robot — the whole system's
//! momentum balance `Σ contact forces − M g = M a_cm` holds at every step.

mod common;

use common::physics::{run_ok, standing_q, system_com, worst_body_imbalance};
use fbd_contact::StateCode;
use fbd_sim::PlanarParams;

#[test]
fn high_friction_stance_sticks_and_supports_the_robot() {
    let mut p = PlanarParams::default();
    p.q0 = standing_q(&p, 250.0);
    p.friction.mu_static = 50.0;
    p.friction.mu_dynamic = 40.0;
    p.duration = 0.15;
    let (model, rows, summary) = run_ok(&p);
    assert!(
        summary.events.is_empty(),
        "unexpected events {:?}",
        summary.events
    );
    let m = model.mech.total_mass();
    let dt = p.dt;
    for w in rows.windows(3) {
        let r = &w[1];
        assert_eq!(
            &[r.contacts[0].state, r.contacts[1].state],
            &[StateCode::St2, StateCode::St2],
            "t = {}",
            r.t
        );
        assert!(
            r.contacts[0].normal > 0.0 && r.contacts[1].normal > 0.0,
            "t = {}: n = {:?}",
            r.t,
            [r.contacts[0].normal, r.contacts[1].normal]
        );
        let c: Vec<[f64; 2]> = w.iter().map(|x| system_com(&model, &x.plane_q())).collect();
        let a = [
            (c[2][0] - 2.0 * c[1][0] + c[0][0]) / (dt * dt),
            (c[2][1] - 2.0 * c[1][1] + c[0][1]) / (dt * dt),
        ];
        let fy = r.contacts[0].normal + r.contacts[1].normal;
        let fx = r.contacts[0].tangential[0] + r.contacts[1].tangential[0];
        assert!(
            (fy - m * (9.81 + a[1])).abs() < 1e-6 * m,
            "t = {}: Σn = {fy}, M(g + a) = {}",
            r.t,
            m * (9.81 + a[1])
        );
        assert!(
            (fx - m * a[0]).abs() < 1e-6 * m,
            "t = {}: Σfa = {fx}, M a_x = {}",
            r.t,
            m * a[0]
        );
    }
    let (worst, at) = worst_body_imbalance(&model, &rows);
    assert!(worst < 1e-6, "{at}");
}

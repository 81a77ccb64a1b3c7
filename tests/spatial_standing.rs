//! The 3D robot standing on its six feet, held by PD joints: once at rest
//! the normal forces carry the weight, and every joint torque equals its
//! static value `−a·[(tip − o) × F + Σ (c − o) × m·g]` from the foot force
//! `F` and the weights of the links beyond the joint (axis `a` through the
//! joint point `o`) — the reported forces and torques agree with statics.

use fbd_dynamics::spatial::{SpatialKin, lower_body, upper_body};
use fbd_kinematics::nalgebra::Vector3;
use fbd_sim::spatial::{SpatialModel, closed_form, run_collect};

mod common;
use common::spatial::stance;

#[test]
fn at_rest_the_forces_and_torques_are_the_static_ones() {
    let p = stance();
    let model = SpatialModel::new(&p).unwrap();
    let (rows, summary) = run_collect(&model);
    assert!(summary.error.is_none(), "{:?}", summary.error);
    let last = rows.last().unwrap();
    // The closed-form hexapod: an independent reference for the statics.
    let hexapod = closed_form(&model.params);
    let mech = &hexapod;
    let weight = mech.total_mass() * p.gravity;
    let normal: f64 = last.contacts.iter().map(|c| c.force[1]).sum();
    println!(
        "Σ N = {normal:.9} N, weight {weight:.9} N, events {}",
        summary.events.len()
    );
    assert!(
        (normal - weight).abs() < 1e-6 * weight,
        "Σ N = {normal}, weight {weight}"
    );
    for (c, spec) in last.contacts.iter().zip(&model.contacts) {
        assert_eq!(
            c.state.as_str(),
            if spec.kind.as_str() == "tip" {
                "ST2"
            } else {
                "ST1"
            }
        );
    }
    let mut kin = SpatialKin::new(mech);
    kin.eval(mech, &last.q);
    let g = Vector3::new(0.0, -p.gravity, 0.0);
    let mut worst: f64 = 0.0;
    for s in 0..model.legs.len() {
        let leg = model.leg_row(last, s);
        let foot = model
            .contacts
            .iter()
            .position(|c| c.leg == leg.leg && c.kind.as_str() == "tip")
            .map(|c| &last.contacts[c])
            .unwrap();
        let f = Vector3::from(foot.force);
        let l = &kin.fk.legs[leg.leg - 1];
        let (u, lo) = (upper_body(s), lower_body(s));
        let w = |b: usize, o: &Vector3<f64>| (kin.com[b] - o).cross(&(mech.bodies[b].mass * g));
        let outboard_hip = (l.tip - l.hip).cross(&f) + w(u, &l.hip) + w(lo, &l.hip);
        let outboard_knee = (l.tip - l.knee).cross(&f) + w(lo, &l.knee);
        let want = [
            -l.hip_axis.dot(&outboard_hip),
            -l.upper_versor.dot(&outboard_hip),
            -l.lower_versor.dot(&outboard_knee),
        ];
        for (j, (&tau, &want)) in leg.torque.iter().zip(&want).enumerate() {
            let d = (tau - want).abs();
            worst = worst.max(d);
            assert!(
                d < 1e-5 * (1.0 + want.abs()),
                "leg {} θ{}: torque {tau} vs static {want}",
                leg.leg,
                j + 1,
            );
        }
    }
    println!("max |τ − τ_static| = {worst:.2e} N·m");
    // The README's bounds (round-off: any change of the arithmetic moves
    // the figures themselves).
    let readme = common::readme::doc("README.md");
    let row = readme.row("standing: Σ N vs weight; joint torques vs statics `Jᵀ F` + gravity");
    let bounds: Vec<f64> = row[1]
        .split(';')
        .map(|b| {
            let b = b.trim().trim_start_matches("below ");
            common::readme::parse(b.split_whitespace().next().unwrap())
        })
        .collect();
    let rel = (normal - weight).abs() / weight;
    assert!(
        rel <= bounds[0] && worst <= bounds[1],
        "README.md is stale (standing): Σ N off by {rel:e} relative, torques by {worst:e} N·m, the README bounds them by {bounds:?}"
    );
}

//! On every row of several runs, the friction law of the row's state holds,
//! the normal force is non-negative and no tip is below the terrain.

mod common;

use common::physics::{plane, run_ok};
use fbd_contact::StateCode;
use fbd_sim::PlanarParams;

/// Checks every row; returns the number of (sticking, sliding) rows of each
/// contact point.
fn check_rows(p: &PlanarParams) -> (Vec<usize>, Vec<usize>) {
    let (model, rows, summary) = run_ok(p);
    let retried = |k: usize| summary.retries.iter().any(|r| r.step == k);
    let (mus, mud) = (p.friction.mu_static, p.friction.mu_dynamic);
    let nc = model.mech.contacts.len();
    let (mut stick, mut slide) = (vec![0; nc], vec![0; nc]);
    for (k, r) in rows.iter().enumerate() {
        for c in 0..r.contacts.len() {
            let (fa, n, name) = (
                r.contacts[c].tangential[0],
                r.contacts[c].normal,
                &model.mech.contacts[c].name,
            );
            let tol = 1e-6 * (1.0 + n.abs());
            // Feet are rigid; knees and hips are bumpers of documented
            // compliance c, sinking c·N under load. The position of row k is
            // the outcome of step k − 1, so it carries that step's force.
            let depth = -model.params.terrain.clearance(plane(r.contacts[c].point));
            // A step solved in substeps ends with the last substep's force,
            // not recorded: bounded by the larger of its neighbours' here.
            let n_before = if k == 0 {
                0.0
            } else if retried(k - 1) {
                rows[k - 1].contacts[c]
                    .normal
                    .max(r.contacts[c].normal)
                    .max(0.0)
            } else {
                rows[k - 1].contacts[c].normal.max(0.0)
            };
            let allowed = 1e-9 + model.contact_compliance[c] * n_before;
            assert!(
                depth < allowed,
                "t = {}: {name} is {depth} m below the terrain (allowed {allowed})",
                r.t
            );
            match r.contacts[c].state {
                // Zero to the solver's force tolerance (1e-9 of the weight).
                StateCode::St1 => assert!(
                    fa.abs() < 1e-9 && n.abs() < 1e-9,
                    "t = {}: {name} in ST1 with fa = {fa}, n = {n}",
                    r.t
                ),
                StateCode::St2 => {
                    stick[c] += 1;
                    assert!(n >= -1e-6, "t = {}: {name} sticking with n = {n}", r.t);
                    assert!(
                        fa.abs() <= mus * n + tol,
                        "t = {}: {name} sticking with |fa| = {} > μS·n = {}",
                        r.t,
                        fa.abs(),
                        mus * n
                    );
                }
                StateCode::St3 => {
                    slide[c] += 1;
                    assert!(n >= -1e-6, "t = {}: {name} sliding with n = {n}", r.t);
                    assert!(
                        (fa.abs() - mud * n).abs() <= tol,
                        "t = {}: {name} sliding with |fa| = {} ≠ μD·n = {}",
                        r.t,
                        fa.abs(),
                        mud * n
                    );
                }
            }
        }
    }
    (stick, slide)
}

#[test]
fn default_run_obeys_coulomb_on_every_row() {
    // The feet stick and slide in the paper's experiment itself.
    let (stick, slide) = check_rows(&PlanarParams::default());
    assert_eq!(stick.len(), 6);
    for c in [0, 1] {
        assert!(
            stick[c] > 0 && slide[c] > 0,
            "foot {c} must exercise both laws ({} sticking rows, {} sliding rows)",
            stick[c],
            slide[c]
        );
    }
}

#[test]
fn friction_variants_obey_coulomb_on_every_row() {
    // Across the friction variants, run until the robot lies on the ground,
    // every point — feet, knees and hips — both sticks and slides.
    let (mut stick, mut slide) = (vec![0; 6], vec![0; 6]);
    let variants = [
        (0.2, 0.1, 0.0),
        (0.6, 0.6, 0.0),
        (1.0, 0.5, 0.0),
        (0.05, 0.0, 0.0),
        (0.4, 0.3, 8.0),
        (0.4, 0.3, -8.0),
    ];
    // With the default joint limits the legs do not fold flat and the
    // knees rarely reach the ground; without limits they lie on it.
    let limits = [
        fbd_sim::JointLimits::default(),
        fbd_sim::JointLimits::none(),
    ];
    for ((mus, mud, tilt_deg), limits) in variants.into_iter().flat_map(|v| limits.map(|l| (v, l)))
    {
        let mut p = PlanarParams::default();
        p.friction.mu_static = mus;
        p.friction.mu_dynamic = mud;
        p.q0[2] = f64::to_radians(tilt_deg);
        p.joint_limits = limits;
        let (st, sl) = check_rows(&p);
        eprintln!("{mus} {mud} {tilt_deg} {limits:?}: stick {st:?} slide {sl:?}");
        for c in 0..6 {
            stick[c] += st[c];
            slide[c] += sl[c];
        }
    }
    for c in 0..6 {
        assert!(
            stick[c] > 0 && slide[c] > 0,
            "contact {c} must exercise both laws ({} sticking rows, {} sliding rows)",
            stick[c],
            slide[c]
        );
    }
}

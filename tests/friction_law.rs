//! On every row of several runs, the friction law of the row's state holds,
//! the normal force is non-negative and no tip is below the terrain.

mod common;

use common::physics::run_ok;
use fbd_contact::StateCode;
use fbd_sim::PlanarParams;

/// Checks every row; returns the number of (sticking, sliding) rows of each
/// contact point.
fn check_rows(p: &PlanarParams) -> (Vec<usize>, Vec<usize>) {
    let (model, rows, _) = run_ok(p);
    let (mus, mud) = (p.friction.mu_static, p.friction.mu_dynamic);
    let nc = model.mech.contacts.len();
    let (mut stick, mut slide) = (vec![0; nc], vec![0; nc]);
    for r in &rows {
        for c in 0..r.contacts {
            let (fa, n, name) = (r.fa[c], r.n[c], &model.mech.contacts[c].name);
            let tol = 1e-6 * (1.0 + n.abs());
            let depth = -model.params.terrain.clearance(r.point[c]);
            assert!(
                depth < 1e-9,
                "t = {}: {name} is {depth} m below the terrain",
                r.t
            );
            match r.state[c] {
                StateCode::St1 => assert!(
                    fa == 0.0 && n == 0.0,
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
    // Tips, knees and hips alike: every point sticks and slides at some time.
    let (stick, slide) = check_rows(&PlanarParams::default());
    assert_eq!(stick.len(), 6);
    for c in 0..6 {
        assert!(
            stick[c] > 0 && slide[c] > 0,
            "contact {c} must exercise both laws ({} sticking rows, {} sliding rows)",
            stick[c],
            slide[c]
        );
    }
}

#[test]
fn friction_variants_obey_coulomb_on_every_row() {
    for (mus, mud) in [(0.2, 0.1), (0.6, 0.6), (1.0, 0.5), (0.05, 0.0)] {
        let mut p = PlanarParams::default();
        p.friction.mu_static = mus;
        p.friction.mu_dynamic = mud;
        p.duration = 0.4;
        check_rows(&p);
    }
}

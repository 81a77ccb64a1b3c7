//! Coulomb's law on every foot row of 3D runs where feet stick, slide in
//! changing directions and lift off: a free point carries no force; a
//! sticking point's force lies in the static cone `|Ft| ≤ μS·N`; a sliding
//! point's tangential force is `μD·N` exactly and opposes its slip over
//! the step. And the slope: on 10° the stance sticks with μS = 0.4
//! and slides down with μS = μD = 0.1.

mod common;

use common::spatial::stance;
use fbd_contact::spatial::{clearance, frame};
use fbd_contact::{Friction, Surface, Terrain};
use fbd_dynamics::spatial::SpatialKin;
use fbd_sim::robot::RobotRecord;
use fbd_sim::spatial::{SpatialModel, closed_form, run_collect};

/// Checks the law on every contact row; returns (sticking, sliding) rows.
/// `(sticking rows, sliding rows, sliding rows aligned with their slip,
/// sliding rows checked)`.
fn check_law(model: &SpatialModel, rows: &[RobotRecord]) -> (usize, usize, usize, usize) {
    let p = &model.params;
    let (mu_s, mu_d) = (p.friction.mu_static, p.friction.mu_dynamic);
    let (mut sticking, mut sliding) = (0, 0);
    let (mut aligned, mut checked) = (0usize, 0usize);
    for (i, (r, next)) in rows.iter().zip(rows.iter().skip(1)).enumerate() {
        for (j, (c, nc)) in r.contacts.iter().zip(&next.contacts).enumerate() {
            // At a touchdown step the point is above the ground at k: its
            // "slip over the step" starts in flight; the direction is
            // checked from the next step on.
            let touchdown = i == 0 || rows[i - 1].contacts[j].state.as_str() == "ST1";
            let f = c.force;
            let fnorm = (f[0] * f[0] + f[1] * f[1] + f[2] * f[2]).sqrt();
            let tol = 1e-6 * (1.0 + fnorm);
            match c.state.as_str() {
                "ST1" => assert!(fnorm < 1e-9, "t = {}: free point carries {fnorm} N", r.t),
                state => {
                    let n = c.normal;
                    assert!(n > -tol, "t = {}: pulling contact N = {n}", r.t);
                    // Tangential part: F minus its normal component, the
                    // normal taken where the equations took it.
                    let [_, nv, _] = frame(&p.terrain, c.point[0], c.point[2]);
                    let ft: Vec<f64> = (0..3).map(|i| f[i] - n * nv[i]).collect();
                    let ftn = ft.iter().map(|v| v * v).sum::<f64>().sqrt();
                    if state == "ST2" {
                        sticking += 1;
                        assert!(
                            ftn <= mu_s * n + tol,
                            "t = {}: |Ft| {ftn} > μS·N {}",
                            r.t,
                            mu_s * n
                        );
                    } else {
                        sliding += 1;
                        assert!(
                            (ftn - mu_d * n).abs() < tol,
                            "t = {}: |Ft| {ftn} ≠ μD·N {}",
                            r.t,
                            mu_d * n
                        );
                        let slip: Vec<f64> = (0..3).map(|i| nc.point[i] - c.point[i]).collect();
                        let dot: f64 = ft.iter().zip(&slip).map(|(a, b)| a * b).sum();
                        let sn = slip.iter().map(|v| v * v).sum::<f64>().sqrt();
                        if sn > 1e-9 && ftn > 1e-9 {
                            let cos = dot / (ftn * sn);
                            if !touchdown {
                                aligned += usize::from(cos < -0.999_999);
                                checked += 1;
                            }
                            // A slide about to stop whose implicit direction
                            // has no solution keeps its last direction (the
                            // planar rule): within a few degrees.
                            assert!(
                                touchdown || cos < -0.99,
                                "t = {} leg {} {}: friction not against the slip (cos {cos})",
                                r.t,
                                model.contacts[j].leg,
                                model.contacts[j].kind.as_str()
                            );
                        }
                    }
                }
            }
        }
    }
    println!("{aligned} of {checked} sliding rows with friction within 0.08° of the slip");
    assert!(
        aligned * 100 >= checked * 95,
        "{aligned} of {checked} aligned"
    );
    (sticking, sliding, aligned, checked)
}

/// A throw: the robot lands moving sideways and spinning, feet sliding in
/// turning directions, then sticking.
#[test]
fn a_spinning_landing_obeys_coulomb_on_every_row() {
    let mut p = stance();
    p.duration = 1.0;
    p.q0[1] += 0.05;
    p.qdot0[0] = 0.8;
    p.qdot0[2] = -0.5;
    p.qdot0[4] = 2.0;
    p.friction = Friction {
        mu_static: 0.5,
        mu_dynamic: 0.35,
    };
    let model = SpatialModel::new(&p).unwrap();
    let (rows, summary) = run_collect(&model);
    assert!(summary.error.is_none(), "{:?}", summary.error);
    let (stick, slide, aligned, checked) = check_law(&model, &rows);
    // The README's figure.
    let row = common::readme::doc("README.md")
        .row("sliding rows whose friction is within 0.08° of the slip, spinning landing");
    assert_eq!(
        row[1],
        format!("{aligned} of {checked}"),
        "README.md is stale (the spinning landing's aligned sliding rows)"
    );
    println!(
        "{stick} sticking and {slide} sliding rows, {} events",
        summary.events.len()
    );
    assert!(
        stick > 100 && slide > 20,
        "the run should both stick and slide"
    );
}

fn on_slope(mu: f64) -> (SpatialModel, Vec<RobotRecord>) {
    let mut p = stance();
    p.duration = 1.0;
    let slope = 10f64.to_radians().tan();
    p.terrain = Surface::new(Terrain::Slope { slope, height: 0.0 }, 0.0);
    p.friction = Friction {
        mu_static: mu,
        mu_dynamic: mu,
    };
    // The body parallel to the slope (rolled about Z by the slope angle).
    p.q0[5] = 10f64.to_radians();
    // … until its lowest foot is 1 mm above the slope.
    let hexapod = closed_form(&p);
    let mut kin = SpatialKin::new(&hexapod);
    kin.eval(&hexapod, &p.q0);
    let lowest = kin
        .fk
        .legs
        .iter()
        .map(|l| clearance(&p.terrain, [l.tip.x, l.tip.y, l.tip.z]))
        .fold(f64::INFINITY, f64::min);
    p.q0[1] += 0.001 - lowest;
    let model = SpatialModel::new(&p).unwrap();
    let (rows, summary) = run_collect(&model);
    assert!(summary.error.is_none(), "μ = {mu}: {:?}", summary.error);
    check_law(&model, &rows);
    (model, rows)
}

#[test]
fn on_a_10_degree_slope_it_sticks_with_04_and_slides_with_01() {
    let (_, rows) = on_slope(0.4);
    let (first, last) = (&rows[0], rows.last().unwrap());
    let moved = last.q[0] - first.q[0];
    println!("μ 0.4: body moved {moved:.6} m along x");
    assert!(moved.abs() < 0.005, "sticks: moved {moved}");
    assert!(
        last.contacts.iter().all(|c| c.state.as_str() != "ST3"),
        "every foot sticks at the end"
    );
    let (_, rows) = on_slope(0.1);
    let last = rows.last().unwrap();
    let moved = last.q[0] - rows[0].q[0];
    println!("μ 0.1: body moved {moved:.6} m along x");
    assert!(moved < -0.05, "slides downhill (−x): moved {moved}");
}

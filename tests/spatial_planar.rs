//! Planar consistency: the 3D engine with legs 3 and 4 only and a planar
//! initial state (`SpatialParams::planar_twin`) reproduces the planar
//! engine's run of the same parameters — the same configuration at every
//! step to 1e-8 and the same contact and joint-limit events. The two
//! engines, written apart, check each other: the rotation scheme reduces
//! to the paper's central difference about Z, the 3D contact rules to the
//! planar ones.
//!
//! Up to the first step whose planar solution breaks a law (e.g. a slide
//! locked in ST3 creeping backwards with its friction along the slip: the
//! spatial engine solves that step exactly, with its complementarity rows
//! or again in substeps; the planar engine is not audited): from there the
//! two runs differ by design.

mod common;

use common::readme::{doc, parse};
use fbd_sim::spatial::{SpatialModel, SpatialParams, run_collect as run3};
use fbd_sim::{Control, Model, PlanarParams, run_collect};

/// Compares the twins; returns the last step compared, the events up to it
/// and the largest difference of `q`.
fn compare(p: &PlanarParams) -> (usize, usize, f64) {
    let model = Model::planar(p).unwrap();
    let (rows, summary) = run_collect(&model);
    assert!(summary.error.is_none(), "planar: {:?}", summary.error);
    let twin = SpatialParams::planar_twin(p);
    let model3 = SpatialModel::new(&twin).unwrap();
    let (rows3, summary3) = run3(&model3);
    assert!(summary3.error.is_none(), "spatial: {:?}", summary3.error);
    assert_eq!(rows.len(), rows3.len());
    // The first step the 3D engine's audit rejected, or whose planar row
    // breaks the sliding law (a slide creeping backwards, its friction
    // along its slip to the next row: the 3D engine's complementarity rows
    // solve that step exactly, differently).
    let backwards = rows
        .windows(2)
        .find(|w| {
            (0..w[0].contacts.len()).any(|c| {
                let (a, b) = (&w[0].contacts[c], &w[1].contacts[c]);
                a.state == fbd_contact::StateCode::St3
                    && a.tangential[0] * (b.point[0] - a.point[0]) > 0.0
            })
        })
        .map_or(usize::MAX, |w| w[0].step);
    let cut = summary3
        .retries
        .iter()
        .filter(|r| r.cause == "inexact")
        .map(|r| r.step)
        .min()
        .unwrap_or(usize::MAX)
        .min(backwards);
    let map = [(0, 0), (1, 1), (2, 5), (3, 7), (4, 8), (5, 10), (6, 11)];
    let mut worst: f64 = 0.0;
    for (a, b) in rows.iter().zip(&rows3).take_while(|(a, _)| a.step <= cut) {
        let aq = a.plane_q();
        for (i, j) in map {
            let d = (aq[i] - b.q[j]).abs();
            worst = worst.max(d);
            assert!(
                d < 1e-8,
                "t = {}: planar q[{i}] = {} vs spatial q[{j}] = {}",
                a.t,
                aq[i],
                b.q[j]
            );
        }
        // Out of the plane: nothing moves.
        for j in [2, 3, 4, 6, 9] {
            assert!(
                b.q[j].abs() < 1e-9,
                "t = {}: out-of-plane q[{j}] = {}",
                b.t,
                b.q[j]
            );
        }
    }
    let ev = |e: &fbd_sim::Event| (e.step, e.leg, e.point, e.from, e.to);
    let planar: Vec<_> = summary
        .events
        .iter()
        .filter(|e| e.step < cut)
        .map(ev)
        .collect();
    let spatial: Vec<_> = summary3
        .events
        .iter()
        .filter(|e| e.step < cut)
        .map(ev)
        .collect();
    assert_eq!(planar, spatial, "contact events differ");
    let lev = |e: &fbd_sim::LimitEvent| (e.step, e.leg, e.joint, e.from, e.to);
    let before = |e: &&fbd_sim::LimitEvent| e.step < cut;
    assert_eq!(
        summary
            .limit_events
            .iter()
            .filter(before)
            .map(lev)
            .collect::<Vec<_>>(),
        summary3
            .limit_events
            .iter()
            .filter(before)
            .map(lev)
            .collect::<Vec<_>>(),
        "limit events differ"
    );
    let compared = rows.iter().take_while(|a| a.step <= cut).count();
    println!(
        "{} rows ({compared} compared), {} events, max |Δq| = {worst:.2e}",
        rows.len(),
        planar.len()
    );
    (compared - 1, planar.len(), worst)
}

/// The README's figures of the planar twin: the events, the bound on `q`,
/// and where the fall's comparison ends.
fn check_readme(before: &str, (last, events, worst): (usize, usize, f64), dt: f64, fall: bool) {
    let readme = doc("README.md");
    if fall {
        readme.figure(
            "10 ms up to t = ",
            " s (the same",
            last as f64 * dt,
            "planar twin: end of the fall's comparison",
        );
    }
    readme.count(before, " events,", events, "planar twin: events");
    let bound = parse(&readme.quoted(&format!("{before}{events} events, `q` within "), ")"));
    assert!(
        worst <= bound,
        "README.md: the planar twin's `q` within {bound:e}, the run gives {worst:e}"
    );
}

#[test]
fn the_default_fall_is_the_planar_fall() {
    let p = PlanarParams::default();
    check_readme("0.41 s (the same ", compare(&p), p.dt, true);
}

#[test]
fn a_pd_squat_at_1ms_is_the_planar_squat() {
    let mut p = PlanarParams {
        dt: 0.001,
        duration: 0.6,
        control: Control::Pd {
            kp: 300.0,
            kd: 8.0,
            torque_limit: Some(60.0),
            target: [[0.2, 4.3], [-0.1, 4.5]],
        },
        ..PlanarParams::default()
    };
    p.qdot0[0] = 0.3;
    check_readme("squat at 1 ms (the same ", compare(&p), p.dt, false);
}

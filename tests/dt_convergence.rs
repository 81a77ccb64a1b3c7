//! The same physics at every Δt: the built-in fall (the paper's §6
//! experiment with knee and hip contacts and the default joint limits) at
//! Δt = 10, 5, 2, 1, 0.5, 0.2 and 0.1 ms.
//!
//! * the tips touch down when free fall says they do (the touchdown step
//!   brackets √(2h/g));
//! * the first slips converge: leg 3's first slip and leg 4's sustained
//!   slip (a slide lasting at least 5 ms) move by at most about one step
//!   from their value at the finest Δt;
//! * the number of events stays bounded (impacts are plastic at every Δt:
//!   no hip or knee bounces again and again);
//! * the robot comes to rest.

mod common;

use common::physics::{run_ok, worst_body_imbalance};
use fbd_contact::StateCode::{St1, St3};
use fbd_sim::{Event, PlanarParams, RunSummary};

const DTS: [f64; 7] = [0.01, 0.005, 0.002, 0.001, 0.0005, 0.0002, 0.0001];

struct Outcome {
    dt: f64,
    touchdown: [f64; 2],
    first_slip3: f64,
    sustained_slip4: f64,
    events: usize,
    final_kinetic: f64,
}

fn tip_events(s: &RunSummary, leg: usize) -> impl Iterator<Item = &Event> {
    s.events
        .iter()
        .filter(move |e| e.point == fbd_dynamics::PointKind::Tip && e.leg == leg)
}

fn run(dt: f64) -> Outcome {
    let p = PlanarParams {
        dt,
        ..PlanarParams::default()
    };
    let (model, rows, s) = run_ok(&p);
    assert!(
        s.retries.is_empty(),
        "Δt = {dt}: retried steps {:?}",
        s.retries
    );
    let g = p.gravity;
    let mut touchdown = [0.0; 2];
    for (i, leg) in [3, 4].into_iter().enumerate() {
        let e = tip_events(&s, leg)
            .find(|e| e.from == St1)
            .expect("the tip lands");
        // Free fall from rest: the tip at height h reaches the ground after
        // √(2h/g); the touchdown step [t, t + Δt] must contain that time.
        let h = rows[0].contacts[i].point[1];
        let t_ff = (2.0 * h / g).sqrt();
        assert!(
            e.t - 1e-9 <= t_ff && t_ff <= e.t + dt + 1e-9,
            "Δt = {dt}: tip {leg} lands in step [{}, {}], free fall says {t_ff}",
            e.t,
            e.t + dt
        );
        touchdown[i] = e.t;
    }
    let first_slip3 = tip_events(&s, 3)
        .find(|e| e.to == St3)
        .expect("leg 3 slips")
        .t;
    // Leg 4's sustained slip: the first ST3 whose next event comes ≥ 5 ms
    // later (a short slide can be the jolt of leg 3's impact, resolved only
    // at small Δt).
    let e4: Vec<&Event> = tip_events(&s, 4).collect();
    let sustained_slip4 = e4
        .iter()
        .enumerate()
        .find(|(i, e)| e.to == St3 && e4.get(i + 1).is_none_or(|n| n.t - e.t >= 0.005))
        .expect("leg 4 slips")
        .1
        .t;
    let last = rows.last().unwrap();
    assert!(
        !last.contacts.iter().any(|c| c.state == St3),
        "Δt = {dt}: a point still slides at the end"
    );
    // Every body balances from the recorded forces, stop moments included.
    let (worst, at) = worst_body_imbalance(&model, &rows);
    // (the accelerations are second differences of the recorded q: their
    // round-off grows as 1/Δt²).
    let tol = 1e-6 + 1e-13 * model.mech.total_mass() / (dt * dt);
    assert!(worst < tol, "Δt = {dt}: {at}");
    Outcome {
        dt,
        touchdown,
        first_slip3,
        sustained_slip4,
        events: s.events.len() + s.limit_events.len(),
        final_kinetic: last.kinetic,
    }
}

#[test]
fn touchdown_slip_events_and_rest_converge_as_dt_goes_to_zero() {
    let runs: Vec<Outcome> = DTS.iter().map(|&dt| run(dt)).collect();
    for r in &runs {
        eprintln!(
            "Δt = {:>6} s: touchdown {:?}, first slip 3 {}, sustained slip 4 {}, {} events, final kinetic {:e} J",
            r.dt, r.touchdown, r.first_slip3, r.sustained_slip4, r.events, r.final_kinetic
        );
    }
    let finest = runs.last().unwrap();
    for r in &runs {
        // Converging slips: within about a step of the finest Δt.
        for (what, a, b) in [
            ("leg 3's first slip", r.first_slip3, finest.first_slip3),
            (
                "leg 4's sustained slip",
                r.sustained_slip4,
                finest.sustained_slip4,
            ),
        ] {
            assert!(
                (a - b).abs() <= r.dt + 5e-4,
                "Δt = {}: {what} at {a} s, {b} s at Δt = {}",
                r.dt,
                finest.dt
            );
        }
        // No chatter: the number of events does not grow as Δt shrinks.
        assert!(
            r.events <= 40,
            "Δt = {}: {} events (chatter?)",
            r.dt,
            r.events
        );
        // At rest at 1.0 s.
        assert!(
            r.final_kinetic < 1e-9,
            "Δt = {}: kinetic energy {} J at the end",
            r.dt,
            r.final_kinetic
        );
    }
    // The check has teeth: at the finest Δt the touchdowns are within
    // 0.1 ms of free fall, not just within the coarse steps.
    assert!((finest.touchdown[1] - 0.199).abs() < 2e-4);
    readme_table(&runs);
}

/// README.md's table ("The same physics at every Δt") quotes these runs:
/// each cell is read from the README and compared with the run (to its
/// last quoted digit); a stale cell fails naming the row.
fn readme_table(runs: &[Outcome]) {
    let readme = common::readme::doc("README.md");
    let unit = |q: &str| {
        let n: String = q.chars().take_while(|c| !c.is_whitespace()).collect();
        common::readme::last_digit_unit(&n)
    };
    let close = |q: &str, v: f64, what: &str, row: &str| {
        let got = common::readme::parse(q);
        assert!(
            (got - v).abs() <= 0.5 * unit(q) * (1.0 + 1e-9),
            "README.md is stale (Δt table, row {row}, {what}): quotes {q}, the run gives {v}"
        );
    };
    for r in runs {
        let name = format!("{} ms", r.dt * 1e3);
        let cells = readme.row(&name);
        assert_eq!(cells.len(), 7, "row {name}: {cells:?}");
        // Tips 4 and 3 on the ground: the step [t, t + Δt] of the touchdown.
        for (cell, td, what) in [
            (&cells[1], r.touchdown[1], "tip 4"),
            (&cells[2], r.touchdown[0], "tip 3"),
        ] {
            let (a, b) = cell
                .split_once('–')
                .unwrap_or_else(|| panic!("row {name}: `{cell}` is not a range"));
            close(a, td, what, &name);
            close(b, td + r.dt, what, &name);
        }
        close(&cells[3], r.first_slip3, "leg 3 slips", &name);
        close(&cells[4], r.sustained_slip4, "leg 4 slips", &name);
        assert_eq!(
            common::readme::parse(&cells[5]) as usize,
            r.events,
            "README.md is stale (Δt table, row {name}): events"
        );
        // The kinetic energy at rest is round-off: the README quotes a
        // bound (`< 1e-15 J`).
        let bound = cells[6]
            .strip_prefix("< ")
            .map(common::readme::parse)
            .unwrap_or_else(|| panic!("row {name}: `{}` is not a bound", cells[6]));
        assert!(
            r.final_kinetic < bound,
            "README.md is stale (Δt table, row {name}): kinetic energy {}, the run gives {:e} J",
            cells[6],
            r.final_kinetic
        );
    }
    let finest = runs.last().unwrap();
    readme.figure(
        "the slips converge to ",
        " s (leg 3)",
        finest.first_slip3,
        "converged slip of leg 3",
    );
    readme.figure(
        " s (leg 3) and ",
        " s (leg 4)",
        finest.sustained_slip4,
        "converged slip of leg 4",
    );
    let lo = runs.iter().map(|r| r.events).min().unwrap();
    let hi = runs.iter().map(|r| r.events).max().unwrap();
    readme.count(
        "The number of events stays between ",
        " and ",
        lo,
        "fewest events",
    );
    readme.count(" and ", " and the robot is at rest", hi, "most events");
}

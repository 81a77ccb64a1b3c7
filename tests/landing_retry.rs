//! Hard landings that the whole step cannot close (run 0 and run 19 of
//! `examples/sweep_landing_1000.toml`, Δt = 10 ms): before substeps and
//! joint limits they stopped with "the contact-state search cycles". They
//! now complete, the retried step is recorded, every joint stays in its
//! range, and every body balances on every row the retry did not touch.

mod common;

use common::physics::{landing, run_ok, worst_body_imbalance};
use fbd_contact::StateCode;
use fbd_sim::{Model, PlanarParams, RobotRecord};

fn check(p: &PlanarParams, what: &str) -> (Model, Vec<RobotRecord>, fbd_sim::RunSummary) {
    assert!(
        p.lowest_clearance() > 0.4,
        "{what}: a drop from above 0.4 m"
    );
    let (model, rows, summary) = run_ok(p);
    assert_eq!(rows.len(), model.steps, "{what}: the run completes");
    assert!(!summary.retries.is_empty(), "{what}: a step was retried");
    for r in &summary.retries {
        assert!(r.substeps >= 2 && r.substeps <= model.max_substeps, "{r:?}");
    }
    let l = &p.joint_limits;
    for r in &rows {
        for (i, range) in [l.theta2, l.theta3, l.theta2, l.theta3].iter().enumerate() {
            let a = r.q[6 + i];
            assert!(
                a >= range[0] - 1e-9 && a <= range[1] + 1e-9,
                "{what}: t = {}: q[{}] = {a} outside {range:?}",
                r.t,
                3 + i
            );
        }
    }
    // Force balance on the rows whose central difference spans no retried
    // step (the retried step's own record holds its first substep's forces).
    let retried: Vec<usize> = summary.retries.iter().map(|r| r.step).collect();
    let mut chunk: Vec<RobotRecord> = Vec::new();
    let mut chunks = Vec::new();
    for r in &rows {
        if retried.contains(&r.step) || retried.contains(&(r.step + 1)) {
            chunks.push(std::mem::take(&mut chunk));
        } else {
            chunk.push(r.clone());
        }
    }
    chunks.push(chunk);
    for c in chunks.iter().filter(|c| c.len() >= 3) {
        let (worst, at) = worst_body_imbalance(&model, c);
        assert!(worst < 1e-6, "{what}: {at}");
    }
    (model, rows, summary)
}

#[test]
fn a_landing_that_newton_could_not_close_completes_in_substeps() {
    let p = landing(
        3.6307028881198846,
        -68.17923482210148,
        0.42541363101410046,
        [16.450618133873157, 256.5144904354054],
        [10.676025180807866, 248.8771949134427],
        0.9801527659718492,
    );
    let (_, rows, _) = check(&p, "run 0");
    // It ends at rest on the ground.
    let last = rows.last().unwrap();
    assert!(
        last.kinetic < 1e-9,
        "kinetic energy {} at the end",
        last.kinetic
    );
    assert!(!last.contacts.iter().any(|c| c.state == StateCode::St3));
}

#[test]
fn a_landing_whose_state_search_cycles_completes() {
    let p = landing(
        -15.611146718503639,
        114.58431493462297,
        0.9249770876982062,
        [7.09621971089739, 261.08032973878665],
        [-4.899273363481299, 271.1942274223952],
        0.2546993914186943,
    );
    let (_, _, summary) = check(&p, "run 19");
    assert!(
        summary.resolved_cycles > 0,
        "the search cycles even at Δt/64 and is closed by its least inconsistent combination"
    );
}

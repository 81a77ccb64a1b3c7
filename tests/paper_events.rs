//! The paper's §6 experiment (the built-in default): "leg 4 touches the
//! ground 0.02 s before leg 3. The first one reaches the soil 0.20 s after the
//! start of motion. Around moment 0.24 s both legs start slipping."

mod common;

use common::physics::{run_ok, worst_body_imbalance};
use fbd_contact::StateCode::{St1, St2, St3};
use fbd_sim::PlanarParams;

#[test]
fn default_run_reproduces_the_papers_events() {
    let (_, rows, summary) = run_ok(&PlanarParams::default());
    let first = |name: &str, to| {
        summary
            .events
            .iter()
            .find(|e| format!("{}{}", e.point, e.leg) == name && e.to == to)
            .map(|e| (e.t, e.from))
    };
    let near = |a: f64, b: f64| (a - b).abs() < 1e-9;
    // A touchdown event at t puts the tip on the ground at t + Δt.
    let (t4, from4) = first("tip4", St2).expect("leg 4 touches down");
    let (t3, from3) = first("tip3", St2).expect("leg 3 touches down");
    assert_eq!((from3, from4), (St1, St1));
    assert!(
        near(t4 + 0.01, 0.20),
        "leg 4 reaches the soil at {} s, the paper says 0.20 s",
        t4 + 0.01
    );
    assert!(
        near(t3 - t4, 0.02),
        "leg 4 lands {} s before leg 3, the paper says 0.02 s",
        t3 - t4
    );
    let (s3, _) = first("tip3", St3).expect("leg 3 slips");
    let (s4, _) = first("tip4", St3).expect("leg 4 slips");
    assert!(
        near(s3, 0.24) && near(s4, 0.24),
        "slipping starts at {s3} s (leg 3) and {s4} s (leg 4); the paper says around 0.24 s"
    );
    // The tip on the ground one step after touchdown, and still there while sticking.
    let row = |t: f64| rows.iter().find(|r| near(r.t, t)).unwrap();
    assert!(row(0.20).contacts[1].point[1].abs() < 1e-9 && row(0.19).contacts[1].point[1] > 0.0);
    assert!(row(0.22).contacts[0].point[1].abs() < 1e-9 && row(0.21).contacts[0].point[1] > 0.0);
    // Every body balances with the recorded forces throughout.
    let (worst, at) =
        worst_body_imbalance(&common::physics::run_ok(&PlanarParams::default()).0, &rows);
    assert!(worst < 1e-6, "{at}");
}

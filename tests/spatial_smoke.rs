//! Temporary smoke runs of the spatial engine (prints).
use fbd_sim::spatial::{SpatialModel, SpatialParams, run_collect};

#[test]
fn drop_smoke() {
    let p = SpatialParams {
        duration: 1.0,
        ..SpatialParams::default()
    };
    let model = SpatialModel::new(&p).unwrap();
    let t0 = std::time::Instant::now();
    let (rows, summary) = run_collect(&model);
    println!(
        "steps {} err {:?} iters {} wall {:.3}s events {}",
        summary.steps,
        summary.error,
        summary.newton_iterations,
        t0.elapsed().as_secs_f64(),
        summary.events.len()
    );
    for e in summary.events.iter().take(40) {
        println!(
            "{:.4} leg{} {} {:?}->{:?}",
            e.t, e.leg, e.point, e.from, e.to
        );
    }
    for r in rows.iter().step_by(100) {
        println!(
            "t {:.3} y {:.4} phi {:.4} {:.4} {:.4} E {:.4} tips {:?}",
            r.t,
            r.q[1],
            r.q[3],
            r.q[4],
            r.q[5],
            r.kinetic + r.potential,
            r.contacts
                .iter()
                .map(|c| c.state.as_str())
                .collect::<Vec<_>>()
        );
    }
}

//! The kinematic hexapod gait: one kinematic step of all six legs (gait
//! phase, footholds, swing path, body state, IK with rates and
//! accelerations, forward kinematics, centre of mass, stability margin),
//! measured over the steps of a walking tripod (target < 1 µs); and a 60 s
//! walk at 1 kHz end to end (60 001 steps, no output).
//!
//! `cargo bench -p fbd-suite --bench gait`

use std::hint::black_box;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};
use fbd_contact::Surface;
use fbd_kinematics::hexapod::HexapodModel;
use fbd_sim::gait::{
    Command, GaitData, GaitKind, GaitModel, GaitParams, InitialPose, Masses, run_gait, step,
};

fn walk(duration: f64) -> GaitModel {
    let params = GaitParams {
        forward: Command::Constant(0.1),
        lateral: Command::Constant(0.01),
        yaw_rate: Command::Constant(3f64.to_radians()),
        walk_time: duration - 1.0,
        ..GaitParams::preset(GaitKind::Tripod)
    };
    GaitModel::new(
        HexapodModel::default(),
        params,
        Surface::default(),
        Masses::default(),
        1e-3,
        duration,
        InitialPose::default(),
    )
    .expect("valid gait")
}

fn bench(c: &mut Criterion) {
    let model = walk(60.0);
    let mut data = GaitData::new(&model);
    c.bench_function("gait/step", |b| {
        b.iter_custom(|iters| {
            // Cycle through the first 10 s (stance, swing, start-up).
            let start = Instant::now();
            for i in 0..iters {
                let k = (i % 10_000) as usize;
                step(&model, &mut data, black_box(k)).expect("reachable");
            }
            start.elapsed()
        })
    });
    let mut g = c.benchmark_group("gait");
    g.sample_size(10);
    g.bench_function("walk_60s_1khz", |b| {
        b.iter(|| {
            let s = run_gait(&model, &AtomicBool::new(false), |d| {
                black_box(d.margin);
            });
            assert!(s.error.is_none());
            s.steps
        })
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    targets = bench
}
criterion_main!(benches);

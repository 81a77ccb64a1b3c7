//! Criterion benchmarks of `fbd-kinematics`: the full 24-DOF forward
//! kinematics (every auxiliary point and versor), one leg's closed-form IK,
//! the stance IK, and the floor they are bounded by (21 `sin_cos` pairs).
//!
//! `cargo bench -p fbd-suite --bench kinematics -- --warm-up-time 1 --measurement-time 3`

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use fbd_kinematics::body::LEG_COUNT;
use fbd_kinematics::hexapod::{HexapodConfig, HexapodData, HexapodModel, forward};
use fbd_kinematics::ik::{KneeBranch, leg_ik, leg_ik_body};
use fbd_kinematics::nalgebra::Vector3;
use fbd_kinematics::pose::BodyPose;
use fbd_kinematics::stance::stance_ik;

fn config() -> HexapodConfig {
    HexapodConfig {
        pose: BodyPose::new([0.1, 0.55, -0.2], [0.1, -0.2, 0.15]),
        joints: [
            [0.1, 0.2, 4.3],
            [-0.3, -0.1, 4.4],
            [0.2, 0.3, 4.2],
            [0.0, 0.0, 4.3],
            [-0.2, 0.1, 4.1],
            [0.3, -0.2, 4.5],
        ],
    }
}

fn bench(c: &mut Criterion) {
    let model = HexapodModel::default();
    let cfg = config();
    let mut data = HexapodData::new();

    c.bench_function("hexapod_forward_24dof", |b| {
        b.iter(|| {
            forward(black_box(&model), black_box(&cfg), &mut data);
            black_box(&data);
        })
    });

    // The lower bound: the same 21 sin/cos pairs FK evaluates (φx, φy, φz,
    // then θ1, θ2, θ2+θ3 of each leg).
    let mut angles = [0.0; 21];
    angles[..3].copy_from_slice(cfg.pose.phi.as_slice());
    for (k, th) in cfg.joints.iter().enumerate() {
        angles[3 + 3 * k..6 + 3 * k].copy_from_slice(&[th[0], th[1], th[1] + th[2]]);
    }
    c.bench_function("sin_cos_x21_floor", |b| {
        b.iter(|| {
            let a = black_box(&angles);
            let mut acc = 0.0;
            for &x in a {
                let (s, c) = x.sin_cos();
                acc += s * c;
            }
            black_box(acc)
        })
    });

    forward(&model, &cfg, &mut data);
    let tip_body = cfg.pose.to_body(&data.legs[3].tip);
    let tip0 = model.mount(3).body_to_base(&tip_body);
    c.bench_function("leg_ik_frame0", |b| {
        b.iter(|| leg_ik(black_box(model.leg()), black_box(&tip0), KneeBranch::Up))
    });
    c.bench_function("leg_ik_body", |b| {
        b.iter(|| leg_ik_body(black_box(&model), 3, black_box(&tip_body), KneeBranch::Up))
    });

    let tips: [Vector3<f64>; LEG_COUNT] = data.legs.map(|l| l.tip);
    let branches = [KneeBranch::Up; LEG_COUNT];
    c.bench_function("stance_ik_18", |b| {
        b.iter(|| {
            stance_ik(
                black_box(&model),
                black_box(&cfg.pose),
                black_box(&tips),
                &branches,
            )
        })
    });
}

criterion_group!(benches, bench);
criterion_main!(benches);

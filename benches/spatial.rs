//! The 3D (spatial) engine, stage by stage, on the six-legged robot at
//! Δt = 1 ms: the assembly of the residual and analytic Jacobian
//! (standing on six feet: 96 unknowns), its sparse LU (faer, symbolic
//! factorisation cached per contact pattern) and one whole step standing
//! (PD stance on six sticking feet) and walking (the tripod gait tracked by
//! PD, `examples/hexapod_walk.toml`, steps 0.5–2.5 s) and landing
//! (`examples/hexapod_drop.toml`, steps 0.3–1 s: touchdown of the feet,
//! then of the hips); the numeric LU both compiled (the default) and by
//! faer's pivoting LU (the reference path). Walking (step 1000: three
//! feet down) and landing (step 700: resting on its feet and hips, twelve
//! sticking points) also have their assembly (residual and Jacobian into
//! the solver's pattern) and numeric LU; the start-up of the walk's model
//! (`SpatialModel::new`, whose stability check of the joint controller
//! visits 189 poses of the gait) and that check alone.
//!
//! `cargo bench -p fbd-suite --bench spatial`

use std::hint::black_box;
use std::path::Path;
use std::time::{Duration, Instant};

use criterion::{Criterion, criterion_group, criterion_main};

use fbd_dynamics::{JacobianSink, NoJacobian, eval, pattern};
use fbd_scenario::Config;
use fbd_sim::spatial::{SpatialData, SpatialModel, step};
use fbd_solver::NewtonSolver;

fn example(name: &str) -> SpatialModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name);
    let file = path.display().to_string();
    let Config::Hexapod(h) = fbd_scenario::load(&path).expect("example loads") else {
        panic!("{file} is a hexapod file")
    };
    SpatialModel::new(&h.spatial_params(&file).expect("parameters")).expect("model")
}

/// A model and a workspace after `warm` steps.
fn warmed(model: &SpatialModel, warm: usize) -> SpatialData {
    let mut data = SpatialData::new(model);
    for _ in 0..warm {
        step(model, &mut data).expect("warm-up step");
    }
    data
}

struct Dense<'a>(&'a mut [f64], usize);
impl JacobianSink for Dense<'_> {
    const ACTIVE: bool = true;
    fn add(&mut self, r: usize, c: usize, v: f64) {
        self.0[r * self.1 + c] += v;
    }
}

fn bench(c: &mut Criterion) {
    let stand = example("hexapod_stand.toml");
    let walk = example("hexapod_walk.toml");

    // Assembly at a standing state (all feet sticking).
    let mut data = warmed(&stand, 500);
    let n = stand.mech.dims().dim();
    let z = data.z.clone();
    // Two iterates, alternated, so that every evaluation computes the
    // kinematics (an evaluation at the same q reuses them).
    let mut z2 = z.clone();
    z2[0] += 1e-9;
    let zs = [z.clone(), z2];
    let mut flip = 0usize;
    let mut r = vec![0.0; n];
    c.bench_function("spatial/assembly_residual", |b| {
        b.iter(|| {
            flip ^= 1;
            eval(
                &stand.mech,
                &stand.params.terrain,
                &mut data.fbd,
                black_box(&zs[flip]),
                &mut r,
                &mut NoJacobian,
            )
        })
    });
    let mut dense = vec![0.0; n * n];
    c.bench_function("spatial/assembly_residual_and_jacobian_dense", |b| {
        b.iter(|| {
            dense.fill(0.0);
            flip ^= 1;
            eval(
                &stand.mech,
                &stand.params.terrain,
                &mut data.fbd,
                black_box(&zs[flip]),
                &mut r,
                &mut Dense(&mut dense, n),
            )
        })
    });
    let mut entries = Vec::new();
    pattern(&stand.mech, &stand.params.terrain, &data.fbd, &mut entries);
    println!(
        "standing: {n} unknowns, {} structural entries",
        entries.len()
    );

    // Factorisation: load the Jacobian into the solver's cached pattern
    // and factor it (numeric LU), as one full Newton iteration does.
    let mut solver = NewtonSolver::new(stand.newton);
    {
        let mut sys = fbd_sim::spatial::step::system_for_bench(&stand, &mut data);
        solver.load_jacobian(&mut sys, &z);
    }
    c.bench_function("spatial/numeric_lu", |b| {
        b.iter(|| solver.factorize_loaded(None).expect("factorisation"))
    });
    // The same by faer's pivoting LU, the reference path (the compiled LU
    // off).
    let mut faer_solver = NewtonSolver::new(fbd_solver::NewtonParams {
        compiled_lu: false,
        ..stand.newton
    });
    {
        let mut sys = fbd_sim::spatial::step::system_for_bench(&stand, &mut data);
        faer_solver.load_jacobian(&mut sys, &z);
    }
    c.bench_function("spatial/numeric_lu_faer", |b| {
        b.iter(|| faer_solver.factorize_loaded(None).expect("factorisation"))
    });

    // Assembly (residual and analytic Jacobian into the solver's pattern,
    // as each full Newton iteration loads it) and the compiled numeric LU
    // while walking and after landing.
    let drop = example("hexapod_drop.toml");
    for (name, model, at) in [("walk", &walk, 1000usize), ("landing", &drop, 700usize)] {
        let mut data = warmed(model, at);
        let z = data.z.clone();
        let mut z2 = z.clone();
        z2[0] += 1e-9;
        let zs = [z.clone(), z2];
        let mut solver = NewtonSolver::new(model.newton);
        c.bench_function(&format!("spatial/assembly_{name}"), |b| {
            b.iter(|| {
                flip ^= 1;
                let mut sys = fbd_sim::spatial::step::system_for_bench(model, &mut data);
                solver.load_jacobian(&mut sys, black_box(&zs[flip]));
            })
        });
        {
            let mut sys = fbd_sim::spatial::step::system_for_bench(model, &mut data);
            solver.load_jacobian(&mut sys, &z);
        }
        println!("{name}: {} unknowns", model.mech.dims().dim());
        c.bench_function(&format!("spatial/numeric_lu_{name}"), |b| {
            b.iter(|| solver.factorize_loaded(None).expect("factorisation"))
        });
    }

    // Start-up: the walk's model, its stability check of the joint
    // controller included (every pose decided by Cholesky tests, no cache
    // involved when the gains pass), and that check alone.
    let walk_params = walk.params.clone();
    c.bench_function("spatial/model_new_walk", |b| {
        b.iter(|| SpatialModel::new(black_box(&walk_params)).expect("model"))
    });
    // The inertia limit of the walk's gains, (kp·Δt² + 2·kd·Δt)/4.
    let limit = 0.25 * (1000.0 * 1e-6 + 2.0 * 15.0 * 1e-3);
    c.bench_function("spatial/stability_check_walk", |b| {
        b.iter(|| {
            fbd_sim::spatial::modes_slower_than(
                black_box(&walk_params),
                &walk_params.robot_model(),
                limit,
            )
        })
    });

    // One whole step, standing, walking, and landing (the passive drop:
    // the six feet touch down at 0.321 s, the hips at 0.417 s, then rest
    // on twelve sticking points).
    for (name, model, from) in [
        ("stand", &stand, 500usize),
        ("walk", &walk, 500usize),
        ("landing", &drop, 300usize),
    ] {
        c.bench_function(&format!("spatial/step_{name}"), |b| {
            b.iter_custom(|iters| {
                let mut total = Duration::ZERO;
                let mut data = warmed(model, from);
                let mut k = from;
                for _ in 0..iters {
                    if k >= (from + 2000).min(model.steps - 1) {
                        data = warmed(model, from);
                        k = from;
                    }
                    let t = Instant::now();
                    step(model, &mut data).expect("step");
                    total += t.elapsed();
                    k += 1;
                }
                total
            })
        });
    }
}

criterion_group! {
    name = benches;
    config = Criterion::default().measurement_time(Duration::from_secs(2)).warm_up_time(Duration::from_secs(1));
    targets = bench
}
criterion_main!(benches);

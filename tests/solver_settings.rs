//! `[solver]`: Newton's settings of a run. Full Newton (`chord_steps = 0`,
//! a factorisation at every iteration) solves the same steps as the
//! default chord steps: a contact-rich 3D landing takes no chord step,
//! touches down at the same step and obeys every contact law on every row;
//! a tighter `tolerance` balances every body tighter, recomputed from the
//! records alone.

mod common;

use common::physics::{run_ok, worst_body_imbalance};
use common::spatial::{assert_rows_within_laws, landing_config};
use fbd_sim::spatial::{SpatialModel, run_collect};
use fbd_sim::{PlanarParams, SolverSettings};

/// Landing `run` of `examples/sweep_hexapod_landing_1000.toml`, every row
/// written, with `chord_steps` set in its configuration (`None`: the
/// default).
fn landing(run: usize, chord_steps: Option<usize>) -> SpatialModel {
    let mut c = landing_config(run);
    c.solver.chord_steps = chord_steps;
    let mut params = c.spatial_params("landing").expect("a valid run");
    params.stride = 1;
    SpatialModel::new(&params).expect("a valid model")
}

#[test]
fn full_newton_lands_the_same_without_a_chord_step() {
    let chord = landing(0, None);
    let full = landing(0, Some(0));
    assert_eq!(chord.newton.chord_steps, fbd_sim::DEFAULT_CHORD_STEPS);
    assert_eq!(full.newton.chord_steps, 0);
    let mut first = Vec::new();
    for (name, model) in [("chord steps", &chord), ("full Newton", &full)] {
        let (rows, summary) = run_collect(model);
        if let Some(e) = &summary.error {
            panic!("{name}: {e}");
        }
        assert_eq!(rows.len(), model.steps, "{name}");
        assert_rows_within_laws(model, &rows, &summary, name);
        let e = &summary.events[0];
        first.push((e.step, e.leg, e.point, e.to));
        if model.newton.chord_steps == 0 {
            assert_eq!(summary.chord_iterations, 0, "{name}");
            assert!(summary.newton_iterations > 0);
            assert!(
                summary.numeric_factorizations >= summary.newton_iterations as u64,
                "{name}: every iteration factors"
            );
        } else {
            assert!(summary.chord_iterations > 0, "{name}");
        }
    }
    // The touchdown is the same step, point and state: the two solve the
    // same equations to the same tolerance (the impact after it is
    // chaotic: later events may differ).
    assert_eq!(first[0], first[1]);
}

#[test]
fn a_tighter_tolerance_balances_every_body_tighter() {
    let worst = |tolerance: f64| {
        let p = PlanarParams {
            solver: SolverSettings {
                tolerance,
                ..SolverSettings::default()
            },
            ..PlanarParams::default()
        };
        let (model, rows, _) = run_ok(&p);
        assert_eq!(model.newton.residual_tol, tolerance);
        worst_body_imbalance(&model, &rows).0
    };
    let (default, tight) = (worst(fbd_sim::DEFAULT_TOLERANCE), worst(1e-12));
    // The paper's fall: every body balances to 1.9e-8 N at the default
    // tolerance, to 8.3e-11 N at 1e-12 (its heaviest body, the 10 kg
    // trunk, weighs 98 N).
    assert!(default < 1e-6, "{default} N");
    assert!(tight < default / 100.0, "{tight} N against {default} N");
}

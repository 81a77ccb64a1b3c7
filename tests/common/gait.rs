//! Helpers of the kinematic-gait tests: the paper's robot in its default
//! stance on flat ground, and a run collecting every step.

use std::sync::atomic::AtomicBool;

use fbd_contact::Surface;
use fbd_kinematics::hexapod::HexapodModel;
use fbd_sim::gait::{GaitData, GaitModel, GaitParams, GaitSummary, InitialPose, Masses, run_gait};

/// The paper's geometry, default masses, flat ground, the default stance.
pub fn model(params: GaitParams, dt: f64, duration: f64) -> GaitModel {
    GaitModel::new(
        HexapodModel::default(),
        params,
        Surface::default(),
        Masses::default(),
        dt,
        duration,
        InitialPose::default(),
    )
    .expect("valid gait model")
}

/// Every step of a run and its summary.
pub fn run(model: &GaitModel) -> (Vec<GaitData>, GaitSummary) {
    let mut rows = Vec::with_capacity(model.steps + 1);
    let s = run_gait(model, &AtomicBool::new(false), |d| rows.push(d.clone()));
    (rows, s)
}

/// [`run`] that must reach the end without error.
pub fn run_ok(model: &GaitModel) -> (Vec<GaitData>, GaitSummary) {
    let (rows, s) = run(model);
    if let Some(e) = &s.error {
        panic!("gait run failed: {e}");
    }
    assert_eq!(rows.len(), model.steps + 1);
    (rows, s)
}

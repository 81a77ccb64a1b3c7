//! A run with `stride > 1` makes only the records it hands out
//! (`fbd_sim::engine::run::run_until`); the steps in between must not
//! change: every handed record equals, to the bit, the same step's record
//! of the run with stride 1. The spatial step carries each body's
//! momentum `L[k+½]` from the record's making to the next step, so this
//! checks that a skipped record still carries it (`skip_record`).

use fbd_sim::spatial::{SpatialModel, SpatialParams};
use fbd_sim::{Control, Model, PlanarParams};

mod common;

/// Stride of the strided runs: not a divisor of anything in particular.
const STRIDE: usize = 7;

#[test]
fn strided_planar_records_are_those_of_every_step() {
    // The default fall (contacts, slides, retries) with a PD controller.
    let mut p = PlanarParams {
        duration: 0.6,
        dt: 0.002,
        ..PlanarParams::default()
    };
    p.control = Control::Pd {
        kp: 20.0,
        kd: 0.5,
        torque_limit: None,
        target: [[0.0, 250f64.to_radians()]; 2],
    };
    let every = fbd_sim::run_collect(&Model::planar(&p).unwrap()).0;
    p.stride = STRIDE;
    let (strided, summary) = fbd_sim::run_collect(&Model::planar(&p).unwrap());
    assert!(summary.error.is_none(), "{:?}", summary.error);
    assert_eq!(strided.len(), every.len().div_ceil(STRIDE));
    for (i, r) in strided.iter().enumerate() {
        assert_eq!(*r, every[i * STRIDE], "step {}", i * STRIDE);
    }
}

#[test]
fn strided_spatial_records_are_those_of_every_step() {
    // The PD stance dropped onto its feet, tumbling a little.
    let mut p: SpatialParams = common::spatial::stance();
    p.duration = 0.4;
    p.dt = 0.001;
    p.q0[1] += 0.02;
    p.qdot0[3..6].copy_from_slice(&[0.5, -0.8, 0.3]);
    let every = fbd_sim::spatial::run_collect(&SpatialModel::new(&p).unwrap()).0;
    p.stride = STRIDE;
    let (strided, summary) = fbd_sim::spatial::run_collect(&SpatialModel::new(&p).unwrap());
    assert!(summary.error.is_none(), "{:?}", summary.error);
    assert_eq!(strided.len(), every.len().div_ceil(STRIDE));
    for (i, r) in strided.iter().enumerate() {
        assert_eq!(*r, every[i * STRIDE], "step {}", i * STRIDE);
    }
}

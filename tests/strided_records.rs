//! A run with `stride > 1` makes only the records it hands out
//! (`fbd_sim::engine::run::run_until`); the steps in between must not
//! change: every handed record equals, to the bit, the same step's record
//! of the run with stride 1. The spatial step carries each body's
//! momentum `L[k+½]` from the record's making to the next step, so this
//! checks that a skipped record still carries it (`skip_record`).
//!
//! A run that writes every `STRIDE`-th record and observes the others
//! (`fbd run`'s plots and peaks, `fbd_sim::engine::run::run_in_written`)
//! makes those without what only a written row reads: their observed
//! fields, and every written record whole, must be those of the run that
//! makes every record whole, to the bit.

use fbd_sim::robot::RobotRecord;
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

/// The PD stance dropped onto its feet, tumbling a little, for 0.4 s.
fn tumbling_stance() -> SpatialParams {
    let mut p: SpatialParams = common::spatial::stance();
    p.duration = 0.4;
    p.dt = 0.001;
    p.q0[1] += 0.02;
    p.qdot0[3..6].copy_from_slice(&[0.5, -0.8, 0.3]);
    p
}

#[test]
fn strided_spatial_records_are_those_of_every_step() {
    let mut p = tumbling_stance();
    let every = fbd_sim::spatial::run_collect(&SpatialModel::new(&p).unwrap()).0;
    p.stride = STRIDE;
    let (strided, summary) = fbd_sim::spatial::run_collect(&SpatialModel::new(&p).unwrap());
    assert!(summary.error.is_none(), "{:?}", summary.error);
    assert_eq!(strided.len(), every.len().div_ceil(STRIDE));
    for (i, r) in strided.iter().enumerate() {
        assert_eq!(*r, every[i * STRIDE], "step {}", i * STRIDE);
    }
}

#[test]
fn observed_spatial_records_are_those_of_every_step() {
    // Every record handed out, every `STRIDE`-th whole.
    let model = SpatialModel::new(&tumbling_stance()).unwrap();
    let every = fbd_sim::spatial::run_collect(&model).0;
    let mut observed = Vec::new();
    let stop = std::sync::atomic::AtomicBool::new(false);
    let summary =
        fbd_sim::spatial::run_until_written(&model, &stop, STRIDE, |r| observed.push(r.clone()));
    assert!(summary.error.is_none(), "{:?}", summary.error);
    assert_eq!(observed.len(), every.len());
    let mut partial = 0;
    for (k, (o, e)) in observed.iter().zip(&every).enumerate() {
        if k % STRIDE == 0 {
            assert_eq!(o, e, "written step {k}");
            continue;
        }
        // What the plots and the peaks read, to the bit.
        let seen = |r: &RobotRecord| {
            (
                (r.step, r.t.to_bits(), r.newton_iterations),
                (r.q.clone(), r.contacts.clone(), r.reaction_force.clone()),
                (r.torque.clone(), r.rate.clone()),
                (r.kinetic.to_bits(), r.potential.to_bits()),
            )
        };
        assert_eq!(seen(o), seen(e), "observed fields, step {k}");
        // What they do not: left as the last whole record's.
        partial += (o.reaction_moment != e.reaction_moment || o.momentum != e.momentum) as usize;
    }
    assert!(partial > 0, "the observed records left something out");
}

//! `summary.json` of a dynamic hexapod run: the summary of every model on
//! the tree equations ([`crate::tree::summary`]) in the hexapod's keys —
//! its contact points `tip4`, `knee4`, `hip4`, its feet `leg4`, its joint
//! reactions `hip4` and `knee4`, its joints `theta1`–`theta3` of each leg —
//! with its `run`, `control` and `legs`, its stability check and its
//! events with legs.

use fbd_sim::RunSummary;
use fbd_sim::spatial::{SpatialControl, SpatialParams};

use super::Layout;
use super::csv::Slots;
use crate::output::{self, EventJson};
use crate::steptime::StepTimes;
use crate::tree::summary::{Collector, Facts, HexapodRun, Keys, TreeSummary};

pub use crate::tree::summary::JointPeak;

/// `summary.json` of a dynamic hexapod run.
pub type SpatialSummary = TreeSummary<EventJson>;

/// The hexapod's keys of its figures, found in its records by `slots`.
pub fn keys(layout: &Layout, slots: &Slots) -> Keys {
    let mut keys = Keys {
        contacts: slots
            .contacts
            .iter()
            .map(|&(leg, kind)| format!("{}{leg}", kind.as_str()))
            .collect(),
        ..Keys::default()
    };
    for (i, &n) in layout.legs.iter().enumerate() {
        keys.feet.push((format!("leg{n}"), slots.tips[i]));
        let leg = slots.legs[i];
        keys.reactions.push((format!("hip{n}"), leg.map(|l| l.hip)));
        keys.reactions
            .push((format!("knee{n}"), leg.map(|l| l.knee)));
        for j in 0..3 {
            keys.joints
                .push((Some(n), format!("theta{}", j + 1), leg.map(|l| l.joint + j)));
        }
    }
    keys
}

/// The collector of a hexapod run's summary.
pub(crate) fn collector(layout: &Layout, slots: &Slots, params: &SpatialParams) -> Collector {
    Collector::new(keys(layout, slots), &params.terrain)
}

/// The summary of a run of `params` planned for `steps_planned` steps, of
/// which `rows` rows were written, from what `collect` gathered.
pub(crate) fn finish(
    collect: Collector,
    params: &SpatialParams,
    steps_planned: usize,
    layout: &Layout,
    run: &RunSummary,
    rows: usize,
    stability_check_seconds: f64,
) -> SpatialSummary {
    let times = StepTimes::new(params.dt);
    let facts = Facts {
        model: "hexapod",
        robot: None,
        hexapod: Some(HexapodRun {
            run: "dynamic",
            control: match params.control {
                SpatialControl::None => "none",
                SpatialControl::Pd { .. } => "pd",
                SpatialControl::Trajectory { .. } => "trajectory",
                SpatialControl::Gait { .. } => "gait",
            },
            legs: layout.legs.clone(),
        }),
        dt: params.dt,
        duration: params.duration,
        steps_planned,
        stride: params.stride,
        contact_points: layout.point_names(params),
        stability_check_seconds: Some(stability_check_seconds),
        peak_normal_force: false,
    };
    let events = output::run_events(run, &times)
        .into_iter()
        .map(|e| e.2)
        .collect();
    collect.finish(facts, run, rows, events)
}

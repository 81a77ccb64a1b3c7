//! Shared fixtures of the stage benchmarks (`planar_kinematics`, `assembly`,
//! `factorization`, `newton_iteration`, `step`, `run`): the default
//! experiment's robot (`PlanarParams::default()`) at Δt = 1 ms in each
//! contact-state combination.
//!
//! * **flight** — no terrain (every tip ST1), falling from the default pose;
//! * **stick** — both tips on flat ground at t = 0 (legs θ = (0°, 250°), Ry
//!   chosen so that both tips are at y = 0 within 1e-9, docs/reference.md), μS huge:
//!   both tips ST2 while the passive robot collapses;
//! * **slide** — the same pose with μS = μD = 0 and a horizontal body
//!   velocity of 0.5 m/s: both tips ST3.
#![allow(dead_code)]

use std::hint::black_box;
use std::time::{Duration, Instant};

use fbd_contact::{ContactState, Friction, Terrain};
use fbd_dynamics::ContactPoints;
use fbd_sim::{Data, Model, PlanarParams, step};

/// Time step of every fixture (s).
pub const DT: f64 = 1e-3;

/// The contact-state combinations benchmarked.
#[derive(Clone, Copy, Debug)]
pub enum Case {
    /// Both tips ST1 (no terrain).
    Flight,
    /// Both tips ST2.
    Stick,
    /// Both tips ST3.
    Slide,
}

impl Case {
    /// All cases.
    pub const ALL: [Case; 3] = [Case::Flight, Case::Stick, Case::Slide];

    /// Short name for benchmark ids.
    pub fn name(self) -> &'static str {
        match self {
            Case::Flight => "flight",
            Case::Stick => "stick",
            Case::Slide => "slide",
        }
    }

    /// The parameters of this case.
    pub fn params(self) -> PlanarParams {
        let mut p = PlanarParams {
            dt: DT,
            duration: 10.0,
            // The paper's model: the states named are those of the feet.
            contact_points: ContactPoints {
                tips: true,
                knees: false,
                hips: false,
            },
            ..PlanarParams::default()
        };
        if let Case::Flight = self {
            p.terrain = Terrain::None;
            return p;
        }
        // Symmetric legs, tips on the ground: tip y − Ry = c·sin(θ2 + θ3).
        let th3 = 250f64.to_radians();
        p.q0 = [0.0, 0.0, 0.0, 0.0, th3, 0.0, th3];
        p.q0[1] = -p.lower_length * th3.sin();
        p.terrain = Terrain::Flat { height: 0.0 };
        match self {
            Case::Stick => {
                p.friction = Friction {
                    mu_static: 1e6,
                    mu_dynamic: 0.3,
                }
            }
            _ => {
                p.friction = Friction {
                    mu_static: 0.0,
                    mu_dynamic: 0.0,
                };
                p.qdot0[0] = 0.5;
                // Without joint limits the frictionless robot collapses
                // onto its sliding feet and stays there; with them a stop
                // lifts a foot off the ground.
                p.joint_limits = fbd_sim::JointLimits::none();
            }
        }
        p
    }

    /// The model of this case.
    pub fn model(self) -> Model {
        Model::planar(&self.params()).expect("valid fixture")
    }

    /// Whether `s` is this case's state for every tip.
    pub fn holds(self, states: &[ContactState]) -> bool {
        states.iter().all(|s| match self {
            Case::Flight => matches!(s, ContactState::Free),
            Case::Stick => matches!(s, ContactState::Stick { .. }),
            Case::Slide => matches!(s, ContactState::Slide { .. }),
        })
    }
}

/// Steps solved from the initial state before a fixture is used: past the
/// first step (k = 0 uses the initial velocities) and, for `Slide`, past the
/// ST2 → ST3 switch of the first step.
pub const WARMUP: usize = 5;

/// Steps timed per fresh state in [`time_steps`] (0.5 s of simulated time:
/// each case stays in its state combination, see the `fixtures_hold` check).
pub const CHUNK: u64 = 500;

/// A workspace at step [`WARMUP`] of `model`, in the case's state.
pub fn warm_data(model: &Model, case: Case) -> Data {
    let mut data = Data::new(model);
    for _ in 0..WARMUP {
        step(model, &mut data).expect("warm-up step");
    }
    assert!(
        case.holds(&data.states),
        "{case:?} fixture left its state: {:?}",
        data.states
    );
    data
}

/// The case's model and a warm workspace whose next step is prepared
/// (kinematics at k, torques, predictor): what the per-stage benches time.
pub fn prepared(case: Case) -> (Model, Data) {
    let model = case.model();
    let mut data = warm_data(&model, case);
    fbd_sim::engine::step::prepare(&model, &mut data).expect("prepare");
    (model, data)
}

/// `iters` calls of [`step`], restarting from a fresh warm state every
/// [`CHUNK`] steps (the restart is not timed). For `iter_custom`.
pub fn time_steps(model: &Model, case: Case, iters: u64) -> Duration {
    let mut total = Duration::ZERO;
    let mut left = iters;
    while left > 0 {
        let mut data = warm_data(model, case);
        let n = left.min(CHUNK);
        let start = Instant::now();
        for _ in 0..n {
            black_box(step(model, &mut data).expect("step"));
        }
        total += start.elapsed();
        debug_assert!(case.holds(&data.states));
        left -= n;
    }
    total
}

/// Checks once that every case stays in its state combination for
/// `WARMUP + CHUNK` steps (so that [`time_steps`] measures what it says).
pub fn fixtures_hold() {
    for case in Case::ALL {
        let model = case.model();
        let mut data = warm_data(&model, case);
        for _ in 0..CHUNK {
            step(&model, &mut data).expect("step");
            assert!(
                case.holds(&data.states),
                "{case:?} left its state at step {}: {:?}",
                data.k,
                data.states
            );
        }
    }
}

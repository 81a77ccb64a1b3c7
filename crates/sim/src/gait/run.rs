//! The loop of a kinematic run: every step, the lift-off, touchdown and
//! stability events, and the figures of the summary.

use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use super::error::GaitError;
use super::model::{GaitData, GaitModel};
use super::params::LEGS;
use super::schedule::{LegPhase, liftoff_time, touchdown_time};
use super::step::step;

/// What happened.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GaitEventKind {
    /// A foot leaves the ground.
    Liftoff,
    /// A foot lands.
    Touchdown,
    /// The stability margin dropped below `margin_warning`.
    MarginLow,
    /// The stability margin is back at or above `margin_warning`.
    MarginRecovered,
}

impl GaitEventKind {
    /// `liftoff`, `touchdown`, `margin_low` or `margin_recovered`.
    pub fn as_str(self) -> &'static str {
        match self {
            GaitEventKind::Liftoff => "liftoff",
            GaitEventKind::Touchdown => "touchdown",
            GaitEventKind::MarginLow => "margin_low",
            GaitEventKind::MarginRecovered => "margin_recovered",
        }
    }
}

/// One event of a kinematic run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GaitEvent {
    /// Time (s): the scheduled instant for lift-off and touchdown (not
    /// rounded to the grid), the step's time for margin events.
    pub t: f64,
    /// Leg number 1–6 (`None` for margin events).
    pub leg: Option<usize>,
    /// What happened.
    pub kind: GaitEventKind,
    /// The stability margin at the event (m).
    pub margin: f64,
}

/// The figures of a kinematic run.
#[derive(Clone, Debug, PartialEq)]
pub struct GaitSummary {
    /// Steps computed (rows).
    pub steps: usize,
    /// Wall time of the stepping loop alone (s).
    pub wall_seconds: f64,
    /// Events in time order.
    pub events: Vec<GaitEvent>,
    /// Why the run stopped early.
    pub error: Option<GaitError>,
    /// The stop flag ended the run early.
    pub interrupted: bool,
    /// Horizontal path length of the body centre (m).
    pub distance: f64,
    /// Net horizontal displacement of the body centre (m).
    pub displacement: f64,
    /// Body heading change (rad).
    pub heading_change: f64,
    /// Simulated time covered (s).
    pub time: f64,
    /// Smallest stability margin (m) and its time (s).
    pub min_margin: Option<(f64, f64)>,
    /// Largest |θ̇| per leg and joint (rad/s).
    pub peak_rate: [[f64; 3]; LEGS],
    /// Largest |θ̈| per leg and joint (rad/s²).
    pub peak_accel: [[f64; 3]; LEGS],
}

impl GaitSummary {
    /// Mean horizontal speed, path length over time (m/s).
    pub fn mean_speed(&self) -> f64 {
        if self.time > 0.0 {
            self.distance / self.time
        } else {
            0.0
        }
    }
}

/// Runs `model` to the end, the first error or until `stop` is set, handing
/// every computed step to `on_step`.
pub fn run_gait(
    model: &GaitModel,
    stop: &AtomicBool,
    mut on_step: impl FnMut(&GaitData),
) -> GaitSummary {
    let mut data = GaitData::new(model);
    let p = &model.params;
    let cycles = if p.walking {
        (model.steps as f64 * model.dt / p.period).ceil() as usize + 1
    } else {
        0
    };
    let mut s = GaitSummary {
        steps: 0,
        wall_seconds: 0.0,
        events: Vec::with_capacity(2 * LEGS * cycles + 16),
        error: None,
        interrupted: false,
        distance: 0.0,
        displacement: 0.0,
        heading_change: 0.0,
        time: 0.0,
        min_margin: None,
        peak_rate: [[0.0; 3]; LEGS],
        peak_accel: [[0.0; 3]; LEGS],
    };
    let mut prev_phase = [LegPhase::Stance { last: None }; LEGS];
    let mut low = false;
    let (mut x0, mut z0, mut psi0) = (0.0, 0.0, 0.0);
    let (mut px, mut pz) = (0.0, 0.0);
    for k in 0..=model.steps {
        if stop.load(Ordering::Relaxed) {
            s.interrupted = true;
            break;
        }
        let start = Instant::now();
        let r = step(model, &mut data, k);
        s.wall_seconds += start.elapsed().as_secs_f64();
        if let Err(e) = r {
            s.error = Some(e);
            break;
        }
        s.steps += 1;
        s.time = data.t;
        let (x, z) = (data.body.position.x, data.body.position.z);
        if k == 0 {
            (x0, z0, psi0) = (x, z, data.body.phi.y);
        } else {
            s.distance += (x - px).hypot(z - pz);
        }
        (px, pz) = (x, z);
        s.displacement = (x - x0).hypot(z - z0);
        s.heading_change = data.body.phi.y - psi0;
        for (leg, ph) in data.phases.iter().enumerate() {
            let ev = |t, kind| GaitEvent {
                t,
                leg: Some(leg + 1),
                kind,
                margin: data.margin,
            };
            match (prev_phase[leg], *ph) {
                (LegPhase::Stance { .. }, LegPhase::Swing { k: c, .. }) => {
                    s.events
                        .push(ev(liftoff_time(p, leg, c), GaitEventKind::Liftoff));
                }
                (LegPhase::Swing { k: c, .. }, LegPhase::Stance { .. }) => {
                    s.events
                        .push(ev(touchdown_time(p, leg, c), GaitEventKind::Touchdown));
                }
                (LegPhase::Swing { k: a, .. }, LegPhase::Swing { k: b, .. }) if a != b => {
                    s.events
                        .push(ev(touchdown_time(p, leg, a), GaitEventKind::Touchdown));
                    s.events
                        .push(ev(liftoff_time(p, leg, b), GaitEventKind::Liftoff));
                }
                _ => {}
            }
            for j in 0..3 {
                let l = &data.legs[leg];
                s.peak_rate[leg][j] = s.peak_rate[leg][j].max(l.rate[j].abs());
                s.peak_accel[leg][j] = s.peak_accel[leg][j].max(l.accel[j].abs());
            }
        }
        prev_phase = data.phases;
        let m = data.margin;
        if s.min_margin.is_none_or(|(v, _)| m < v) {
            s.min_margin = Some((m, data.t));
        }
        let below = m < p.margin_warning;
        if below != low {
            s.events.push(GaitEvent {
                t: data.t,
                leg: None,
                kind: if below {
                    GaitEventKind::MarginLow
                } else {
                    GaitEventKind::MarginRecovered
                },
                margin: m,
            });
            low = below;
        }
        on_step(&data);
        if below && p.require_stable {
            s.error = Some(GaitError::Unstable {
                t: data.t,
                margin: m,
                threshold: p.margin_warning,
            });
            break;
        }
    }
    s
}

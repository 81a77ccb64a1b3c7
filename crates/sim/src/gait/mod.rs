//! The kinematic gait of the 24-DOF hexapod: gait generation and kinematic
//! stepping (no forces).
//!
//! A periodic gait (duty factor β, one lift-off phase per leg; presets
//! tripod, ripple, wave, or custom) moves the body along a commanded planar
//! twist; stance feet stay where they landed, swing feet travel to the next
//! foothold, and every step the closed-form leg inverse kinematics gives
//! the 18 joint angles, the analytic leg Jacobian their rates and
//! accelerations, and the support polygon the static stability margin.
//!
//! One stage per file:
//!
//! * [`params`] — [`GaitParams`] (documented defaults), presets, profiles;
//! * [`schedule`] — phase → stance/swing, lift-off and touchdown times;
//! * [`body`] — the commanded twist integrated, start-up and stop, offsets,
//!   sway, terrain following;
//! * [`foothold`] — where a swing lands;
//! * [`swing`] — the swing path (quintic + bump; why in its docs);
//! * [`ik`] — leg IK, rates and accelerations, joint limits;
//! * [`stability`] — support polygon, whole-robot centre of mass, margin;
//! * [`model`] — [`GaitModel`] (immutable) and [`GaitData`] (workspace);
//! * [`mod@step`] — one kinematic step of all six legs;
//! * [`mod@run`] — the loop, events and summary.

pub mod body;
pub mod error;
pub mod foothold;
pub mod ik;
pub mod model;
pub mod params;
pub mod run;
pub mod schedule;
pub mod stability;
pub mod step;
pub mod swing;

pub use error::GaitError;
pub use model::{GaitData, GaitModel, InitialPose};
pub use params::{Command, GaitKind, GaitParams, LEGS};
pub use run::{GaitEvent, GaitEventKind, GaitSummary, run_gait};
pub use stability::Masses;
pub use step::{step, step_targets};

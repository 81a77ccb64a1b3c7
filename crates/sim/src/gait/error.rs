//! Why a gait could not be built or a kinematic run stopped.

use fbd_kinematics::num::Fixed;
use thiserror::Error;

/// `t` as a short decimal: up to 6 decimals, trailing zeros removed.
pub fn fmt_time(t: f64) -> String {
    let s = Fixed(t, 6).to_string();
    if s.contains('e') {
        return s;
    }
    let s = s.trim_end_matches('0');
    if s.ends_with('.') {
        format!("{s}0")
    } else {
        s.to_owned()
    }
}

/// Errors of the kinematic gait (one line each, naming the leg, the time
/// and by how much).
#[derive(Clone, Debug, PartialEq, Error)]
pub enum GaitError {
    /// A gait parameter is out of its domain.
    #[error("gait.{0}")]
    Invalid(String),
    /// A foot target is farther from (or closer to) the hip than the leg
    /// reaches.
    #[error(
        "leg {leg} at t = {} s: foot target out of reach by {} m (hip–foot distance {} m, the leg reaches [{}, {}] m)",
        fmt_time(*t), Fixed(*by, 6), Fixed(*distance, 6), Fixed(*min, 6), Fixed(*max, 6)
    )]
    Unreachable {
        /// Leg number 1–6.
        leg: usize,
        /// Time (s).
        t: f64,
        /// Hip–target distance (m).
        distance: f64,
        /// By how much it is outside the reach (m).
        by: f64,
        /// Smallest reach `|a − c|` (m).
        min: f64,
        /// Largest reach `a + c` (m).
        max: f64,
    },
    /// A foot target on the hip's vertical axis (θ1 undetermined), or a
    /// singular leg Jacobian (stretched or folded leg).
    #[error("leg {leg} at t = {} s: {what}", fmt_time(*t))]
    Singular {
        /// Leg number 1–6.
        leg: usize,
        /// Time (s).
        t: f64,
        /// What is singular.
        what: String,
    },
    /// A joint angle past its limit.
    #[error(
        "leg {leg} at t = {} s: {joint} = {}° is past its limit by {}° (range [{}°, {}°])",
        fmt_time(*t), Fixed(*angle_deg, 3), Fixed(*by_deg, 3), Fixed(*min_deg, 3), Fixed(*max_deg, 3)
    )]
    JointLimit {
        /// Leg number 1–6.
        leg: usize,
        /// Time (s).
        t: f64,
        /// `theta1`, `theta2` or `theta3`.
        joint: &'static str,
        /// The angle (deg).
        angle_deg: f64,
        /// By how much past the limit (deg).
        by_deg: f64,
        /// Lower limit (deg).
        min_deg: f64,
        /// Upper limit (deg).
        max_deg: f64,
    },
    /// The stability margin fell below the threshold with
    /// `require_stable = true`.
    #[error(
        "t = {} s: statically unstable: stability margin {} m below the required {} m",
        fmt_time(*t), Fixed(*margin, 6), Fixed(*threshold, 6)
    )]
    Unstable {
        /// Time (s).
        t: f64,
        /// The margin (m).
        margin: f64,
        /// The threshold (m).
        threshold: f64,
    },
}

impl GaitError {
    /// The time the error happened, if it is a run error.
    pub fn time(&self) -> Option<f64> {
        match self {
            GaitError::Invalid(_) => None,
            GaitError::Unreachable { t, .. }
            | GaitError::Singular { t, .. }
            | GaitError::JointLimit { t, .. }
            | GaitError::Unstable { t, .. } => Some(*t),
        }
    }
}

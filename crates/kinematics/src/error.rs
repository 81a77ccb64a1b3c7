//! Typed errors of the kinematics crate.

use thiserror::Error;

use crate::num::Fixed;

/// Why an inverse-kinematics problem has no (unique) solution.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum KinematicsError {
    /// The target is farther from the hip than `a + c`, or closer than
    /// `|a − c|`: no knee angle reaches it.
    #[error(
        "target at distance {distance:.6} m from the hip is out of reach: \
         the leg reaches distances in [{min_reach:.6}, {max_reach:.6}] m"
    )]
    Unreachable {
        /// Distance from the hip (origin of the leg's frame 0) to the target (m).
        distance: f64,
        /// Smallest reachable distance, `|a − c|` (m).
        min_reach: f64,
        /// Largest reachable distance, `a + c` (m).
        max_reach: f64,
    },
    /// The target lies on the θ1 axis (the hip's vertical axis, `z0` of the
    /// leg base frame), so θ1 is undetermined.
    #[error(
        "target lies on the θ1 axis (radial distance {radial:.3e} m ≤ {tolerance:.3e} m): \
         θ1 is undetermined"
    )]
    SingularHip {
        /// Distance of the target from the θ1 axis (m).
        radial: f64,
        /// The tolerance it fell below (m).
        tolerance: f64,
    },
    /// A coordinate of the target (or of the body pose) is NaN or infinite.
    #[error("non-finite target coordinate")]
    NonFinite,
    /// A joint angle lies outside its [`crate::limits::JointLimits`] range.
    #[error(
        "{joint} = {}° is outside its limits [{}°, {}°] by {}°",
        Fixed(value.to_degrees(), 3), Fixed(min.to_degrees(), 3),
        Fixed(max.to_degrees(), 3), Fixed(outside_by.to_degrees(), 3)
    )]
    JointLimit {
        /// `"theta1"`, `"theta2"` or `"theta3"`.
        joint: &'static str,
        /// The angle (rad).
        value: f64,
        /// Lower end of the range (rad).
        min: f64,
        /// Upper end of the range (rad).
        max: f64,
        /// How far outside the range the angle is (rad).
        outside_by: f64,
    },
    /// The inverse kinematics of one leg of a stance failed.
    #[error("leg {leg}: {source}")]
    Leg {
        /// Leg number, 1–6 (docs/reference.md numbering).
        leg: usize,
        /// Why this leg failed.
        #[source]
        source: Box<KinematicsError>,
    },
}

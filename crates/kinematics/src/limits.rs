//! Joint limits of one leg: a `[min, max]` range (radians) for each of
//! θ1, θ2 and θ3, the same for every leg.
//!
//! The planar model uses θ2 and θ3 (its legs have no θ1); the hexapod uses
//! all three. The dynamics treat a limit as a one-sided constraint: a joint
//! is free inside its range, and a joint that reaches an end stays there
//! (a plastic stop) while the stop pushes it back into the range, leaving
//! it when the stop would have to pull.
//!
//! Angle conventions are the D-H ones of [`crate::dh`]: θ2 = 0 points the
//! upper link outward, horizontally, positive θ2 lowers the knee; θ3 = 180°
//! is a straight leg and θ3 = 360° the lower link folded back onto the upper
//! one.

use crate::KinematicsError;

/// One of the three joints of a leg.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Joint {
    /// θ1, the hip's vertical axis (hexapod only).
    Theta1,
    /// θ2, the hip's horizontal axis.
    Theta2,
    /// θ3, the knee.
    Theta3,
}

impl Joint {
    /// The three joints, in order.
    pub const ALL: [Joint; 3] = [Joint::Theta1, Joint::Theta2, Joint::Theta3];

    /// `"theta1"`, `"theta2"` or `"theta3"`, as in configuration keys and
    /// output columns.
    pub fn name(self) -> &'static str {
        match self {
            Joint::Theta1 => "theta1",
            Joint::Theta2 => "theta2",
            Joint::Theta3 => "theta3",
        }
    }

    /// 0, 1 or 2.
    pub fn index(self) -> usize {
        self as usize
    }
}

/// Which end of its range a joint is at.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LimitSide {
    /// At `min`: the stop pushes towards larger angles.
    Lower,
    /// At `max`: the stop pushes towards smaller angles.
    Upper,
}

impl LimitSide {
    /// +1 at the lower end (the stop's moment acts towards larger angles),
    /// −1 at the upper end.
    pub fn sign(self) -> f64 {
        match self {
            LimitSide::Lower => 1.0,
            LimitSide::Upper => -1.0,
        }
    }
}

/// `[min, max]` of every joint of a leg (radians), `min < max`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLimits {
    /// θ1 range. Default `[−90°, 90°]`: the leg may swing a quarter turn
    /// forward or back from its radial direction, never into the body.
    pub theta1: [f64; 2],
    /// θ2 range. Default `[−120°, 120°]`: the upper link may rise or drop
    /// two thirds of a half turn from horizontal. At −180° it would lie
    /// along the body, the "folded flat" pose in which a collapsing passive
    /// robot lies on one line on the ground and its sticking constraints
    /// become singular.
    pub theta2: [f64; 2],
    /// θ3 range. Default `[180°, 330°]`: from the straight leg (180°, the
    /// knee cannot over-extend) to the lower link 30° from the upper one.
    /// 360° is the folded-flat knee. The paper's initial pose (245°, 255°),
    /// the standing pose of the examples (250°) and the squat (265°) lie
    /// well inside.
    pub theta3: [f64; 2],
}

impl Default for JointLimits {
    fn default() -> Self {
        let rad = |[lo, hi]: [f64; 2]| [lo.to_radians(), hi.to_radians()];
        let [t1, t2, t3] = Self::DEFAULT_DEG;
        Self {
            theta1: rad(t1),
            theta2: rad(t2),
            theta3: rad(t3),
        }
    }
}

impl JointLimits {
    /// The default ranges of θ1, θ2, θ3 in degrees (see the fields).
    pub const DEFAULT_DEG: [[f64; 2]; 3] = [[-90.0, 90.0], [-120.0, 120.0], [180.0, 330.0]];

    /// Limits so wide that they never act (`±∞`).
    pub fn none() -> Self {
        let all = [f64::NEG_INFINITY, f64::INFINITY];
        Self {
            theta1: all,
            theta2: all,
            theta3: all,
        }
    }

    /// The range of `joint` (rad).
    pub fn range(&self, joint: Joint) -> [f64; 2] {
        match joint {
            Joint::Theta1 => self.theta1,
            Joint::Theta2 => self.theta2,
            Joint::Theta3 => self.theta3,
        }
    }

    /// `true` when every range is `min < max` and neither end is NaN
    /// (infinite ends mean "no limit").
    pub fn is_valid(&self) -> bool {
        Joint::ALL.iter().all(|&j| {
            let [lo, hi] = self.range(j);
            !lo.is_nan() && !hi.is_nan() && lo < hi
        })
    }

    /// Which end `theta` of `joint` lies beyond, if any (rad).
    pub fn violated(&self, joint: Joint, theta: f64) -> Option<LimitSide> {
        let [lo, hi] = self.range(joint);
        if theta < lo {
            Some(LimitSide::Lower)
        } else if theta > hi {
            Some(LimitSide::Upper)
        } else {
            None
        }
    }

    /// The angle of `joint`'s `side` end (rad).
    pub fn end(&self, joint: Joint, side: LimitSide) -> f64 {
        let [lo, hi] = self.range(joint);
        match side {
            LimitSide::Lower => lo,
            LimitSide::Upper => hi,
        }
    }

    /// Checks one joint angle (rad); the error names the joint and by how
    /// much the angle is outside its range.
    pub fn check(&self, joint: Joint, theta: f64) -> Result<(), KinematicsError> {
        let [min, max] = self.range(joint);
        let outside_by = if theta < min {
            min - theta
        } else if theta > max {
            theta - max
        } else if theta.is_nan() {
            f64::NAN
        } else {
            return Ok(());
        };
        Err(KinematicsError::JointLimit {
            joint: joint.name(),
            value: theta,
            min,
            max,
            outside_by,
        })
    }

    /// Checks `(θ1, θ2, θ3)` of one leg (rad).
    pub fn check_leg(&self, theta: [f64; 3]) -> Result<(), KinematicsError> {
        for j in Joint::ALL {
            self.check(j, theta[j.index()])?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_hold_the_paper_pose_and_exclude_the_folded_flat_leg() {
        let l = JointLimits::default();
        assert!(l.is_valid());
        for t3 in [245.0f64, 250.0, 255.0, 265.0, 290.0] {
            assert!(l.check(Joint::Theta3, t3.to_radians()).is_ok(), "{t3}");
        }
        assert!(l.check(Joint::Theta2, 0.0).is_ok());
        assert!(l.check(Joint::Theta2, -180f64.to_radians()).is_err());
        assert!(l.check(Joint::Theta3, 360f64.to_radians()).is_err());
    }

    #[test]
    fn check_names_the_joint_and_the_excess() {
        let l = JointLimits::default();
        let e = l.check(Joint::Theta3, 340f64.to_radians()).unwrap_err();
        let KinematicsError::JointLimit {
            joint, outside_by, ..
        } = e.clone()
        else {
            panic!("{e:?}")
        };
        assert_eq!(joint, "theta3");
        assert!((outside_by - 10f64.to_radians()).abs() < 1e-12);
        let msg = e.to_string();
        assert!(msg.contains("theta3") && msg.contains("10.000°"), "{msg}");
        assert!(l.check(Joint::Theta1, f64::NAN).is_err());
        assert_eq!(
            l.violated(Joint::Theta2, -2.5),
            Some(LimitSide::Lower),
            "−143° is below −120°"
        );
        assert_eq!(l.violated(Joint::Theta2, 0.0), None);
        assert!(
            l.check_leg([0.0, 0.0, 250f64.to_radians()]).is_ok()
                && JointLimits::none().check_leg([9.0, -9.0, 9.0]).is_ok()
        );
    }
}

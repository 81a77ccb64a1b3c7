//! Gait parameters ([`GaitParams`]) with documented defaults, the named
//! presets ([`GaitKind`]) and commanded speed profiles ([`Command`]).

use fbd_kinematics::JointLimits;
use fbd_kinematics::num::Num;

/// Number of legs.
pub const LEGS: usize = 6;

/// A named gait: duty factor β and one lift-off phase per leg (fraction of
/// the period at which the leg lifts off, legs 1–6).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GaitKind {
    /// β = ½, legs {1, 4, 5} lift off together at phase 0 and {2, 3, 6} at
    /// phase ½: always three feet on the ground.
    Tripod,
    /// β = ⅔: on each side the legs swing rear to front (5, 3, 1 and 6, 4,
    /// 2) a third of a period apart, the right side half a period after
    /// the left: always four feet on the ground.
    Ripple,
    /// β = ⅚: one leg swings at a time, rear to front, left side first
    /// (5, 3, 1, 6, 4, 2): always five feet on the ground.
    Wave,
    /// β and the six phases given explicitly.
    Custom,
}

impl GaitKind {
    /// `(β, phases)` of a named gait (`None` for [`GaitKind::Custom`]).
    pub fn preset(self) -> Option<(f64, [f64; LEGS])> {
        match self {
            GaitKind::Tripod => Some((0.5, [0.0, 0.5, 0.5, 0.0, 0.0, 0.5])),
            GaitKind::Ripple => Some((
                2.0 / 3.0,
                [2.0 / 3.0, 1.0 / 6.0, 1.0 / 3.0, 5.0 / 6.0, 0.0, 0.5],
            )),
            GaitKind::Wave => Some((
                5.0 / 6.0,
                [2.0 / 6.0, 5.0 / 6.0, 1.0 / 6.0, 4.0 / 6.0, 0.0, 3.0 / 6.0],
            )),
            GaitKind::Custom => None,
        }
    }

    /// `"tripod"`, `"ripple"`, `"wave"` or `"custom"`.
    pub fn as_str(self) -> &'static str {
        match self {
            GaitKind::Tripod => "tripod",
            GaitKind::Ripple => "ripple",
            GaitKind::Wave => "wave",
            GaitKind::Custom => "custom",
        }
    }
}

/// A commanded quantity: constant, or piecewise linear in time through
/// `(t, value)` points (t strictly increasing), constant beyond the ends.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    /// The same value at every time.
    Constant(f64),
    /// Piecewise-linear profile through `[t, value]` points.
    Profile(Vec<[f64; 2]>),
}

impl Default for Command {
    /// `Constant(0)`.
    fn default() -> Self {
        Command::Constant(0.0)
    }
}

impl Command {
    /// Value and time derivative at `t` (the derivative of a profile is
    /// that of the segment containing `t`, zero beyond the ends).
    #[inline]
    pub fn eval(&self, t: f64) -> (f64, f64) {
        match self {
            Command::Constant(v) => (*v, 0.0),
            Command::Profile(p) => {
                let last = p.len() - 1;
                if t <= p[0][0] {
                    return (p[0][1], 0.0);
                }
                if t >= p[last][0] {
                    return (p[last][1], 0.0);
                }
                let i = p
                    .partition_point(|q| q[0] <= t)
                    .saturating_sub(1)
                    .min(last - 1);
                let (a, b) = (p[i], p[i + 1]);
                let k = (b[1] - a[1]) / (b[0] - a[0]);
                (a[1] + k * (t - a[0]), k)
            }
        }
    }

    /// `true` when the value is zero at every time.
    pub fn is_zero(&self) -> bool {
        match self {
            Command::Constant(v) => *v == 0.0,
            Command::Profile(p) => p.iter().all(|q| q[1] == 0.0),
        }
    }
}

/// Everything that defines a kinematic gait. Lengths m, times s, angles
/// rad, speeds m/s and rad/s.
#[derive(Clone, Debug, PartialEq)]
pub struct GaitParams {
    /// Duty factor β ∈ (0, 1): the fraction of the period a leg is in
    /// stance. Default ½ (tripod).
    pub duty: f64,
    /// Lift-off phase of each leg, fraction of the period in `[0, 1)`
    /// (legs 1–6). Default: the tripod's `[0, ½, ½, 0, 0, ½]`.
    pub phases: [f64; LEGS],
    /// Gait period T (s). Default 1 s.
    pub period: f64,
    /// Height of the swing foot above the straight line from lift-off to
    /// touchdown at mid-swing (m). Default 0.05 m.
    pub swing_height: f64,
    /// Forward speed along the body's heading (body −z), m/s. Default 0.
    pub forward: Command,
    /// Lateral speed to the body's right (body +x), m/s. Default 0.
    pub lateral: Command,
    /// Yaw rate about the vertical +Y (rad/s; positive turns left).
    /// Default 0.
    pub yaw_rate: Command,
    /// Start-up and stop time (s): the commanded speeds, the sway and the
    /// body offsets are blended in over `[0, ramp]` and the speeds and
    /// sway out over `[walk_time − ramp, walk_time]` with the quintic
    /// smoothstep `10u³ − 15u⁴ + 6u⁵` (velocity and acceleration
    /// continuous). Default 0.5 s.
    pub ramp: f64,
    /// No leg lifts off at or after this time (s); the body stops here.
    /// Default `f64::INFINITY` (set by the loader to `duration − period`, so
    /// that every foot is down at the end).
    pub walk_time: f64,
    /// Body height offset (m, up). Default 0.
    pub height: f64,
    /// Body roll offset (rad, about the forward axis; positive lowers the
    /// right side). Default 0.
    pub roll: f64,
    /// Body pitch offset (rad, about the body's lateral axis; positive
    /// raises the front). Default 0.
    pub pitch: f64,
    /// Lateral body sway amplitude (m): the body moves `sway·sin(2πt/T)`
    /// to its right. Default 0.
    pub sway: f64,
    /// The body height follows the terrain under the body centre (for
    /// `steps`, the staircase's mean line). Default `true`.
    pub follow_terrain: bool,
    /// A warning event is recorded when the stability margin drops below
    /// this (m). Default 0.02 m.
    pub margin_warning: f64,
    /// Stop the run with an error when the margin drops below
    /// `margin_warning`. Default `false`.
    pub require_stable: bool,
    /// Joint limits checked at every step. Default: none (`±∞`).
    pub limits: JointLimits,
    /// `false` for a standing run: no leg lifts off, the body keeps its
    /// pose and the feet stay where the initial joint angles put them.
    /// Default `true`.
    pub walking: bool,
}

impl Default for GaitParams {
    fn default() -> Self {
        let (duty, phases) = GaitKind::Tripod.preset().unwrap_or((0.5, [0.0; LEGS]));
        Self {
            duty,
            phases,
            period: 1.0,
            swing_height: 0.05,
            forward: Command::default(),
            lateral: Command::default(),
            yaw_rate: Command::default(),
            ramp: 0.5,
            walk_time: f64::INFINITY,
            height: 0.0,
            roll: 0.0,
            pitch: 0.0,
            sway: 0.0,
            follow_terrain: true,
            margin_warning: 0.02,
            require_stable: false,
            limits: JointLimits::none(),
            walking: true,
        }
    }
}

impl GaitParams {
    /// A standing run: the initial pose held (see [`GaitParams::walking`]).
    pub fn standing() -> Self {
        Self {
            walking: false,
            ..Self::default()
        }
    }

    /// The parameters of a named gait (β and phases), other fields default.
    pub fn preset(kind: GaitKind) -> Self {
        let mut p = Self::default();
        if let Some((duty, phases)) = kind.preset() {
            p.duty = duty;
            p.phases = phases;
        }
        p
    }

    /// Swing duration `(1 − β)·T` (s).
    pub fn swing_time(&self) -> f64 {
        (1.0 - self.duty) * self.period
    }

    /// Checks the domains; the error names the field.
    pub fn check(&self) -> Result<(), String> {
        let pos = |name: &str, v: f64| {
            if v.is_finite() && v > 0.0 {
                Ok(())
            } else {
                Err(format!(
                    "{name} must be positive and finite (got {})",
                    Num(v)
                ))
            }
        };
        pos("period", self.period)?;
        if !(self.duty > 0.0 && self.duty < 1.0) {
            return Err(format!(
                "duty_factor must lie in (0, 1) (got {})",
                Num(self.duty)
            ));
        }
        if let Some(p) = self.phases.iter().find(|p| !(0.0..1.0).contains(*p)) {
            return Err(format!("phases must lie in [0, 1) (got {})", Num(*p)));
        }
        for (name, v) in [
            ("swing_height", self.swing_height),
            ("ramp", self.ramp),
            ("sway", self.sway),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(format!("{name} must be finite and ≥ 0 (got {})", Num(v)));
            }
        }
        for (name, v) in [
            ("height", self.height),
            ("roll", self.roll),
            ("pitch", self.pitch),
            ("margin_warning", self.margin_warning),
        ] {
            if !v.is_finite() {
                return Err(format!("{name} must be finite (got {v})"));
            }
        }
        if self.walk_time.is_nan() {
            return Err("walk_time must not be NaN".into());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_keep_enough_feet_down() {
        // At any phase, the number of legs in swing is at most
        // ⌈6·(1 − β)⌉: 3 for the tripod, 2 ripple, 1 wave.
        for (kind, most) in [
            (GaitKind::Tripod, 3),
            (GaitKind::Ripple, 2),
            (GaitKind::Wave, 1),
        ] {
            let (duty, phases) = kind.preset().unwrap();
            for i in 0..240 {
                let t = (i as f64 + 0.5) / 240.0;
                let swinging = phases
                    .iter()
                    .filter(|&&o| (t - o).rem_euclid(1.0) < 1.0 - duty)
                    .count();
                assert_eq!(swinging, most, "{kind:?} at phase {t}");
            }
        }
    }

    #[test]
    fn profile_is_piecewise_linear() {
        let c = Command::Profile(vec![[0.0, 0.0], [1.0, 2.0], [3.0, 2.0]]);
        assert_eq!(c.eval(-1.0), (0.0, 0.0));
        assert_eq!(c.eval(0.5), (1.0, 2.0));
        assert_eq!(c.eval(2.0), (2.0, 0.0));
        assert_eq!(c.eval(5.0), (2.0, 0.0));
        assert!(!c.is_zero() && Command::default().is_zero());
    }
}

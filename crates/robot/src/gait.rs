//! A kinematic gait generator for any legged robot: the joint angles (and
//! rates) that walk a [`RobotModel`] at a commanded horizontal velocity and
//! yaw rate, with its feet stepping in a periodic pattern. It plans targets
//! only; a PD tracking controller elsewhere applies them
//! (`τ = kp·(θ* − θ) + kd·(θ̇* − θ̇)`), and the plan assumes the body
//! follows the planned base pose [`GaitPlan::base`] — **the joint targets
//! are relative to that planned base pose**: forward kinematics of the
//! planned pose and the targets puts every foot on its planned place.
//!
//! # Frames and units
//!
//! * Inertial frame: `Y` up, the ground is the plane `y = 0`. Lengths m,
//!   times s, angles rad.
//! * The base pose is fbd's `(R, φ)` with `Rot = Rx(φx)·Rz(φz)·Ry(φy)`
//!   ([`crate::forward::base_frame`]). The body frame is `+y` up, `−z`
//!   forward, `+x` to the robot's right ([`crate::Up`]: a `z`-up
//!   description's forward `+x` becomes the body's `−z`), so **at φ = 0 the
//!   robot faces the inertial `−Z`**.
//! * The planned body keeps φx, φz of the start pose (a level start keeps
//!   it level) and yaws about its own up axis: `φy(t) = φy₀ + ∫ yaw_rate`.
//! * [`GaitParams::velocity`] `[vx, vz]` is in the **heading frame**: the
//!   inertial `X`, `Z` axes turned by `Ry(φy(t))`. At heading 0 it is the
//!   inertial velocity; walking forward at `s` m/s is `[0, −s]`
//!   ([`GaitParams::with_forward_speed`]). With a yaw rate the body runs on
//!   a circle, the velocity turning with it.
//!
//! # Timeline
//!
//! * `0 ≤ t < startup`: the robot stands; its body height goes smoothly
//!   (`3u² − 2u³`) from the start pose's to [`GaitParams::body_height`].
//! * From `startup` the feet step; the body's velocity and yaw rate ramp
//!   up smoothly (`3u² − 2u³`) over [`GaitParams::ramp`] seconds to the
//!   commanded ones, then stay constant (the body's path is the constant
//!   command's path, entered at `ramp/2` later: after the ramp the body is
//!   where it would be had it started at full speed at `startup + ramp/2`).
//! * Leg `i` lifts off at `startup + (phases[i] + k)·period`, `k = 0, 1, …`,
//!   swings for `(1 − duty)·period` and stands for `duty·period`. Before its
//!   first lift-off it stands on its start foothold.
//!
//! # Feet
//!
//! A leg is a contact point (its foot) and the joints above it that no
//! other foot shares (joints shared by several feet — a spine — are held at
//! the standing pose's angles). Its **nominal foothold** is the foot's place
//! in the body frame at the standing pose (`q0`), moved outwards by
//! [`GaitParams::stance_width`] along the body's `x`, and projected
//! vertically onto the ground: `y = radius` of the contact sphere (0 for a
//! point), so that the sphere touches `y = 0`.
//!
//! * **Stance**: the foot stays fixed in the inertial frame at its
//!   touchdown foothold.
//! * **Footholds** (Raibert): the foothold of each stance is the nominal
//!   foothold carried by the planned body at **mid-stance**; with a constant
//!   command that is, at touchdown, the nominal foothold plus
//!   `velocity·duty·period/2` relative to the body (and turned by half the
//!   stance's yaw). Consecutive footholds of a leg are `velocity·period`
//!   apart when walking straight.
//! * **Swing**: from the lift-off foothold to the next one; horizontally a
//!   quintic `10u³ − 15u⁴ + 6u⁵` (zero velocity and acceleration at both
//!   ends), vertically `step_height·64u³(1 − u)³` (apex `step_height` at
//!   mid-swing, zero velocity at both ends), `u` the swing's progress.
//!
//! # Inverse kinematics
//!
//! Each leg's joint angles come from a small damped least-squares (Newton)
//! search on the leg's own chain with the planned base, warm-started from
//! the previous call's targets (the first from `q0`) moved on at their
//! rates (to second order) when the call is at most 10 ms later (at a
//! controller's Δt one Newton iteration then reaches the tolerance), the
//! search stopping at a hundredth of the tolerance, joint
//! limits held by clamping with an active set (a trial step that does not
//! bring the foot closer is retried with more damping from the angles
//! kept and their Jacobian); a foot left farther than
//! [`GaitParams::ik_tolerance`] from its target is
//! [`GaitError::OutOfReach`]. The rates solve `J·θ̇ = ṗ_foot − (v_b + ω_b ×
//! (p − R))` with the leg's Jacobian `J` at the solution (exact for a leg of
//! three joints, the least-norm rates for more). All buffers are allocated
//! in [`GaitPlan::new`]; [`GaitPlan::targets`] does not allocate (except an
//! error's foot name).

use nalgebra::{Isometry3, Matrix3, Point3, Unit, UnitQuaternion, Vector3};

use fbd_kinematics::num::Num;

use crate::forward::{RobotData, base_frame, forward};
use crate::model::{JointLimits, RobotModel};

/// Why a gait cannot be planned or followed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum GaitError {
    /// The IK left a foot farther than the tolerance from its planned place.
    #[error(
        "foot \"{foot}\" is out of reach at t = {time} s: it stays {residual:.3e} m from its planned place (the closest its joints reach within their limits)"
    )]
    OutOfReach {
        /// The foot's contact point name.
        foot: String,
        /// The time (s).
        time: f64,
        /// Distance left (m).
        residual: f64,
    },
    /// A foot index that is not one of the model's contact points.
    #[error("contact point {index} is not in the model (it has {count})")]
    NoSuchContact {
        /// The index given.
        index: usize,
        /// How many contact points the model has.
        count: usize,
    },
    /// A foot name that is not one of the model's contact points.
    #[error("no contact point named \"{name}\"{suggestion}")]
    UnknownFoot {
        /// The name given.
        name: String,
        /// ` (did you mean "x"?)` or a list of the names, possibly empty.
        suggestion: String,
    },
    /// The same contact point given twice.
    #[error("contact point \"{foot}\" is given twice as a foot")]
    DuplicateFoot {
        /// Its name.
        foot: String,
    },
    /// No feet at all.
    #[error("a gait needs at least one foot")]
    NoFeet,
    /// A foot with no joint of its own (on the root, or only on joints
    /// shared with other feet).
    #[error("foot \"{foot}\" has no joint of its own to move")]
    NoJoints {
        /// Its name.
        foot: String,
    },
    /// Not one phase offset per foot.
    #[error("{phases} phase offsets for {feet} feet (one per foot)")]
    PhaseCount {
        /// Offsets given.
        phases: usize,
        /// Feet given.
        feet: usize,
    },
    /// A phase offset outside `[0, 1)`.
    #[error("phase offset {} of leg {leg} is not in [0, 1)", Num(*value))]
    Phase {
        /// The leg (index into the feet).
        leg: usize,
        /// The offset.
        value: f64,
    },
    /// A duty factor outside `(0, 1)`.
    #[error("duty factor {} is not in (0, 1)", Num(*.0))]
    Duty(f64),
    /// Another parameter out of its range.
    #[error("gait parameter {name} = {} must be {rule}", Num(*value))]
    Parameter {
        /// The field of [`GaitParams`].
        name: &'static str,
        /// Its value.
        value: f64,
        /// What it must be.
        rule: &'static str,
    },
    /// A swing shorter than [`MIN_SWING_STEPS`] steps ([`check_swing`]).
    #[error(
        "the swing (1 − duty factor)·period = {} s spans fewer than {MIN_SWING_STEPS} steps of Δt = {} s: the period must be at least {} s at this duty factor (or Δt smaller)",
        Num(*swing), Num(*dt), Num(*min_period)
    )]
    ShortSwing {
        /// `(1 − duty)·period` (s).
        swing: f64,
        /// The time step (s).
        dt: f64,
        /// The shortest period that passes (s).
        min_period: f64,
    },
    /// A joint vector of the wrong length.
    #[error("{what} has {got} values, the model has {expected} joints")]
    JointCount {
        /// Which vector.
        what: &'static str,
        /// Its length.
        got: usize,
        /// The model's joint count.
        expected: usize,
    },
}

/// The fewest steps of Δt that a swing, `(1 − duty)·period`, may span:
/// in fewer a foot would lift off and land with no step in the air, and a
/// period of nanoseconds asked a plan for a foothold every period —
/// hundreds of millions of them in a run of a second. The rule of every
/// gait (the hexapod's and an imported robot's).
pub const MIN_SWING_STEPS: f64 = 2.0;

/// Checks that the swing `(1 − duty)·period` spans at least
/// [`MIN_SWING_STEPS`] steps of `dt` ([`GaitError::ShortSwing`] names the
/// shortest period that does). Values out of their own domains pass: each
/// has its own check.
pub fn check_swing(period: f64, duty: f64, dt: f64) -> Result<(), GaitError> {
    let swing = (1.0 - duty) * period;
    if swing < MIN_SWING_STEPS * dt {
        return Err(GaitError::ShortSwing {
            swing,
            dt,
            min_period: MIN_SWING_STEPS * dt / (1.0 - duty),
        });
    }
    Ok(())
}

/// The gait's parameters: plain fields (a configuration table maps onto
/// them one to one). [`Default`] is [`GaitParams::trot`].
#[derive(Clone, Debug, PartialEq)]
pub struct GaitParams {
    /// Each leg's phase offset in `[0, 1)` (fraction of the period), in the
    /// order of the feet given to [`GaitPlan::new`]: leg `i` lifts off at
    /// `startup + (phases[i] + k)·period`.
    pub phases: Vec<f64>,
    /// Period of one stride (s), > 0. Default 0.5.
    pub period: f64,
    /// Duty factor: the fraction of the period a foot stands, in `(0, 1)`.
    pub duty: f64,
    /// Apex of the swing above the ground (m), ≥ 0. Default 0.04.
    pub step_height: f64,
    /// Body velocity `[vx, vz]` in the heading frame (m/s); forward is
    /// `−z` (see the module docs). Default `[0, 0]` (stepping in place).
    pub velocity: [f64; 2],
    /// Yaw rate about the vertical (rad/s, counter-clockwise seen from
    /// above). Default 0.
    pub yaw_rate: f64,
    /// The body's height (the base origin's `y`, m) while walking; `None`
    /// keeps the start pose's. Default `None`.
    pub body_height: Option<f64>,
    /// Nominal footholds moved outwards (away from the body's `x = 0`
    /// plane, along the body's `x`) by this much (m; negative narrows).
    /// Default 0.
    pub stance_width: f64,
    /// Time standing still before the first step (s), ≥ 0; the body height
    /// moves to `body_height` during it. Default 0.5.
    pub startup: f64,
    /// Time over which velocity and yaw rate ramp up after `startup` (s),
    /// ≥ 0. Default 0.5.
    pub ramp: f64,
    /// Largest distance of a foot from its planned place that the IK
    /// accepts (m), > 0. Default 1e-10.
    pub ik_tolerance: f64,
    /// Most Newton iterations per leg and call, ≥ 1. Default 50.
    pub ik_max_iterations: usize,
}

impl Default for GaitParams {
    fn default() -> Self {
        Self::trot()
    }
}

impl GaitParams {
    /// Common defaults with the given phase offsets and duty factor.
    fn with(phases: Vec<f64>, period: f64, duty: f64) -> Self {
        Self {
            phases,
            period,
            duty,
            step_height: 0.04,
            velocity: [0.0, 0.0],
            yaw_rate: 0.0,
            body_height: None,
            stance_width: 0.0,
            startup: 0.5,
            ramp: 0.5,
            ik_tolerance: 1e-10,
            ik_max_iterations: 50,
        }
    }

    /// Trot of a quadruped, feet ordered `[front-left, front-right,
    /// hind-left, hind-right]`: diagonal pairs together, phases
    /// `[0, ½, ½, 0]`, period 0.5 s, duty 0.6 (two feet or more always
    /// stand).
    pub fn trot() -> Self {
        Self::with(vec![0.0, 0.5, 0.5, 0.0], 0.5, 0.6)
    }

    /// Lateral-sequence walk of a quadruped, feet ordered `[front-left,
    /// front-right, hind-left, hind-right]`: lift-offs FL, HR, FR, HL a
    /// quarter period apart, phases `[0, ½, ¾, ¼]`, period 0.8 s, duty 0.75
    /// (one foot in the air at a time).
    pub fn walk() -> Self {
        Self::with(vec![0.0, 0.5, 0.75, 0.25], 0.8, 0.75)
    }

    /// Alternating tripod of a hexapod, feet ordered `[left-front,
    /// left-middle, left-rear, right-front, right-middle, right-rear]`:
    /// {LF, LR, RM} and {LM, RF, RR} alternate, phases
    /// `[0, ½, 0, ½, 0, ½]`, period 0.8 s, duty 0.6.
    pub fn tripod() -> Self {
        Self::with(vec![0.0, 0.5, 0.0, 0.5, 0.0, 0.5], 0.8, 0.6)
    }

    /// These parameters with any phase offsets (one per foot, in `[0, 1)`).
    pub fn with_phases(mut self, phases: Vec<f64>) -> Self {
        self.phases = phases;
        self
    }

    /// These parameters walking straight forward (the body's `−z`) at
    /// `speed` m/s: `velocity = [0, −speed]`.
    pub fn with_forward_speed(mut self, speed: f64) -> Self {
        self.velocity = [0.0, -speed];
        self
    }

    /// Checks the ranges (not the phase count, which needs the feet).
    fn check(&self) -> Result<(), GaitError> {
        let bad = |name, value, rule| Err(GaitError::Parameter { name, value, rule });
        if !(self.period.is_finite() && self.period > 0.0) {
            return bad("period", self.period, "finite and > 0");
        }
        if !(self.duty > 0.0 && self.duty < 1.0) {
            return Err(GaitError::Duty(self.duty));
        }
        for (leg, &value) in self.phases.iter().enumerate() {
            if !(0.0..1.0).contains(&value) {
                return Err(GaitError::Phase { leg, value });
            }
        }
        if !(self.step_height.is_finite() && self.step_height >= 0.0) {
            return bad("step_height", self.step_height, "finite and ≥ 0");
        }
        for (name, v) in [
            ("velocity[0]", self.velocity[0]),
            ("velocity[1]", self.velocity[1]),
            ("yaw_rate", self.yaw_rate),
            ("stance_width", self.stance_width),
        ] {
            if !v.is_finite() {
                return bad(name, v, "finite");
            }
        }
        if let Some(h) = self.body_height
            && !h.is_finite()
        {
            return bad("body_height", h, "finite");
        }
        if !(self.startup.is_finite() && self.startup >= 0.0) {
            return bad("startup", self.startup, "finite and ≥ 0");
        }
        if !(self.ramp.is_finite() && self.ramp >= 0.0) {
            return bad("ramp", self.ramp, "finite and ≥ 0");
        }
        if !(self.ik_tolerance.is_finite() && self.ik_tolerance > 0.0) {
            return bad("ik_tolerance", self.ik_tolerance, "finite and > 0");
        }
        if self.ik_max_iterations == 0 {
            return bad("ik_max_iterations", 0.0, "≥ 1");
        }
        Ok(())
    }
}

/// The planned base pose and its rates at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BasePose {
    /// The base origin `R` in the inertial frame (m).
    pub position: [f64; 3],
    /// fbd's angles `(φx, φy, φz)` (rad).
    pub phi: [f64; 3],
    /// `Ṙ` (m/s).
    pub velocity: [f64; 3],
    /// `φ̇` (rad/s); only `φ̇y` is non-zero.
    pub phi_rate: [f64; 3],
}

impl BasePose {
    /// The base's frame ([`base_frame`]).
    pub fn frame(&self) -> Isometry3<f64> {
        base_frame(self.position, self.phi)
    }
}

/// A foot's planned place at one time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FootTarget {
    /// The contact point (sphere centre) in the inertial frame (m).
    pub position: [f64; 3],
    /// Its velocity (m/s); zero in stance.
    pub velocity: [f64; 3],
    /// Whether the foot stands (else it swings).
    pub stance: bool,
}

/// One joint of a leg's path from the root, copied from the model.
#[derive(Clone, Debug, PartialEq)]
struct PathJoint {
    index: usize,
    origin: Isometry3<f64>,
    axis: Unit<Vector3<f64>>,
    limits: Option<JointLimits>,
    /// Moved by this leg's IK (else held at `q0`).
    moved: bool,
}

/// One leg: its foot, its path of joints, its footholds and IK buffers.
#[derive(Clone, Debug, PartialEq)]
struct Leg {
    name: String,
    /// Its foot: the index of the contact point in the model.
    contact: usize,
    radius: f64,
    /// The contact point in its body's frame.
    local: Vector3<f64>,
    path: Vec<PathJoint>,
    /// Nominal foot position in the base frame (before projection).
    nominal: Vector3<f64>,
    /// The start foothold (inertial).
    start: Vector3<f64>,
    phase: f64,
    // Buffers, one entry per moved joint.
    axes: Vec<Vector3<f64>>,
    origins: Vec<Vector3<f64>>,
    cols: Vec<Vector3<f64>>,
    /// `cols` at the angles kept while a trial step is evaluated.
    saved_cols: Vec<Vector3<f64>>,
    dq: Vec<f64>,
    saved: Vec<f64>,
    held: Vec<bool>,
}

impl Leg {
    /// The foot in the inertial frame for `q`; with `jacobian` the
    /// columns `∂p/∂θ` of the moved joints go to `self.cols`.
    fn foot(&mut self, base: &Isometry3<f64>, q: &[f64], jacobian: bool) -> Vector3<f64> {
        let mut frame = *base;
        let mut k = 0;
        for pj in &self.path {
            frame = frame * pj.origin * UnitQuaternion::from_axis_angle(&pj.axis, q[pj.index]);
            if pj.moved {
                self.axes[k] = frame.rotation * pj.axis.into_inner();
                self.origins[k] = frame.translation.vector;
                k += 1;
            }
        }
        let p = (frame * Point3::from(self.local)).coords;
        if jacobian {
            for k in 0..self.cols.len() {
                self.cols[k] = self.axes[k].cross(&(p - self.origins[k]));
            }
        }
        p
    }

    /// `Jᵀ·(J·Jᵀ + λ²·1)⁻¹·e` over the joints not held, into `self.dq`.
    fn dls(&mut self, e: &Vector3<f64>, lambda: f64) -> bool {
        let mut a = Matrix3::identity() * (lambda * lambda);
        for (c, &h) in self.cols.iter().zip(&self.held) {
            if !h {
                a += c * c.transpose();
            }
        }
        let y = match a.cholesky() {
            Some(ch) => ch.solve(e),
            None => match a.try_inverse() {
                Some(inv) => inv * e,
                None => return false,
            },
        };
        for (k, c) in self.cols.iter().enumerate() {
            self.dq[k] = if self.held[k] { 0.0 } else { c.dot(&y) };
        }
        true
    }

    /// Moves the leg's joints in `q` so that the foot reaches `target` (to
    /// [`IK_STOP`] of `tolerance`, or as near as it gets); returns the foot
    /// at the final angles (`cols` its Jacobian there:
    /// a rejected trial step restores the columns of the angles kept, so
    /// that the retry with more damping, and the rates after the solve,
    /// use the Jacobian at the angles they start from).
    fn solve(
        &mut self,
        base: &Isometry3<f64>,
        q: &mut [f64],
        target: &Vector3<f64>,
        tolerance: f64,
        max_iterations: usize,
    ) -> Vector3<f64> {
        let clamp = |l: Option<JointLimits>, x: f64| match l {
            Some(l) => x.clamp(l.lower, l.upper),
            None => x,
        };
        for pj in self.path.iter().filter(|p| p.moved) {
            q[pj.index] = clamp(pj.limits, q[pj.index]);
        }
        let mut lambda = 1e-4;
        let mut p = self.foot(base, q, true);
        let mut e = target - p;
        for _ in 0..max_iterations {
            if e.norm() <= IK_STOP * tolerance {
                break;
            }
            let mut improved = false;
            for _ in 0..30 {
                // Active set: joints at a limit that the step pushes past
                // it are held, and the step solved again without them.
                self.held.fill(false);
                let mut ok = self.dls(&e, lambda);
                for _ in 0..self.held.len() {
                    if !ok {
                        break;
                    }
                    let mut changed = false;
                    for (k, pj) in self.path.iter().filter(|p| p.moved).enumerate() {
                        if let Some(l) = pj.limits {
                            let x = q[pj.index];
                            let out = (x <= l.lower && self.dq[k] < 0.0)
                                || (x >= l.upper && self.dq[k] > 0.0);
                            if out && !self.held[k] {
                                self.held[k] = true;
                                changed = true;
                            }
                        }
                    }
                    if !changed {
                        break;
                    }
                    ok = self.dls(&e, lambda);
                }
                if !ok {
                    lambda *= 10.0;
                    continue;
                }
                for (k, pj) in self.path.iter().filter(|p| p.moved).enumerate() {
                    self.saved[k] = q[pj.index];
                    q[pj.index] = clamp(pj.limits, q[pj.index] + self.dq[k]);
                }
                self.saved_cols.copy_from_slice(&self.cols);
                let foot = self.foot(base, q, true);
                let trial = target - foot;
                if trial.norm() < e.norm() {
                    (p, e) = (foot, trial);
                    lambda = (lambda / 10.0).max(1e-12);
                    improved = true;
                    break;
                }
                for (k, pj) in self.path.iter().filter(|p| p.moved).enumerate() {
                    q[pj.index] = self.saved[k];
                }
                self.cols.copy_from_slice(&self.saved_cols);
                lambda *= 10.0;
            }
            if !improved {
                break;
            }
        }
        p
    }

    /// The rates of the moved joints for the foot's velocity `rhs` relative
    /// to the base's rigid motion (`cols` at the solution `q`), into `qd`;
    /// a joint at a limit that the rates would push past it is held (rate
    /// 0) and the others solved again.
    fn rates(&mut self, q: &[f64], rhs: &Vector3<f64>, qd: &mut [f64]) {
        self.held.fill(false);
        for _ in 0..=self.held.len() {
            if !self.dls(rhs, 0.0) {
                self.dls(rhs, 1e-9);
            }
            let mut changed = false;
            for (k, pj) in self.path.iter().filter(|p| p.moved).enumerate() {
                if let Some(l) = pj.limits {
                    let x = q[pj.index];
                    let out =
                        (x <= l.lower && self.dq[k] < 0.0) || (x >= l.upper && self.dq[k] > 0.0);
                    if out && !self.held[k] {
                        self.held[k] = true;
                        changed = true;
                    }
                }
            }
            if !changed {
                break;
            }
        }
        for (k, pj) in self.path.iter().filter(|p| p.moved).enumerate() {
            qd[pj.index] = self.dq[k];
        }
    }
}

/// Where a leg is in its cycle.
enum Phase {
    /// Standing on foothold `k` (−1: the start foothold).
    Stance(i64),
    /// Swinging from foothold `k − 1` to `k`, progress `u ∈ [0, 1)`.
    Swing(i64, f64),
}

/// A gait planned for one robot: the body's path, each foot's footholds
/// and swings, and the joint targets that follow them (see the module
/// docs).
#[derive(Clone, Debug, PartialEq)]
pub struct GaitPlan {
    params: GaitParams,
    legs: Vec<Leg>,
    /// The standing pose (joints of no leg keep these angles).
    q0: Vec<f64>,
    /// The last targets (the IK's warm start).
    q: Vec<f64>,
    /// The last targets' rates and time: the warm start of a call at most
    /// `WARM_RATE_SPAN` later is `q + h·qd + h²/2·qdd`, `h = t − t_last`.
    qd: Vec<f64>,
    /// The change of the rates over the last call's step forward divided
    /// by its length (rad/s², zero after a longer step), for the warm
    /// start's second-order term.
    qdd: Vec<f64>,
    t_last: f64,
    position0: [f64; 3],
    phi0: [f64; 3],
    height: f64,
    /// Targets recorded along a run's steps ([`GaitPlan::record_samples`]),
    /// shared by the plan's clones.
    samples: Option<std::sync::Arc<SampledTargets>>,
}

/// Joint targets of a plan stepped from `t = 0` at every step `dt` of a
/// run, kept at every `stride`-th step (`targets[i]` at `t = i·stride·dt`):
/// what the run's controller will command there, bit for bit, recorded
/// once by a caller that steps the plan anyway (the configuration's reach
/// check) for a later one that samples poses (the start-up stability
/// check), which then needs no inverse kinematics of its own.
#[derive(Clone, Debug, PartialEq)]
pub struct SampledTargets {
    /// The run's step (s).
    pub dt: f64,
    /// Steps between two samples.
    pub stride: usize,
    /// The targets (rad, in the order of the model's joints).
    pub targets: Vec<Vec<f64>>,
}

/// Events (lift-off, touchdown) within this fraction of a period of a time
/// count as at that time.
const EVENT_SNAP: f64 = 1e-9;

/// Where a leg's inverse kinematics stops, as a fraction of
/// [`GaitParams::ik_tolerance`] (a foot farther than the tolerance itself is
/// out of reach): a hundredth, so that the joint targets are smooth from
/// step to step to well below the tolerance. Stopped at the tolerance
/// itself, the warm start moved on at the rates often leaves the search
/// nothing to do, the targets then jitter by up to the tolerance, and the
/// lab hexapod's walk (`examples/robots/lab_hexapod_walk.toml`) took 8 %
/// more Newton iterations in its dynamics (5,921 instead of 5,460).
const IK_STOP: f64 = 0.01;

/// The longest step forward in time (s) over which [`GaitPlan::targets`]
/// starts the IK from the last targets moved on at their rates, to second
/// order (a joint then off by about `θ⃛·Δt³/6`, one Newton iteration from
/// the tolerance at a controller's Δt), rather than from the last targets
/// themselves: longer steps, and steps back, start from those.
const WARM_RATE_SPAN: f64 = 0.01;

/// `sin x / x`.
fn sinc(x: f64) -> f64 {
    if x.abs() < 1e-4 {
        1.0 - x * x / 6.0
    } else {
        x.sin() / x
    }
}

/// `(3u² − 2u³, 6u − 6u²)` for `u` clamped to `[0, 1]`.
fn smoothstep(u: f64) -> (f64, f64) {
    let u = u.clamp(0.0, 1.0);
    (u * u * (3.0 - 2.0 * u), 6.0 * u * (1.0 - u))
}

/// `Ry(a)·(x, 0, z)` as `(x', z')`.
fn turn(a: f64, x: f64, z: f64) -> (f64, f64) {
    let (s, c) = a.sin_cos();
    (c * x + s * z, -s * x + c * z)
}

impl GaitPlan {
    /// Plans a gait for `model` stepping on the contact points `feet`
    /// (indices into `model.contacts`, in the order of
    /// [`GaitParams::phases`]), starting from the base pose `(position,
    /// phi)` (fbd's `R`, φ) and the standing joint angles `q0` (rad, in the
    /// order of `model.joints`), which define the nominal footholds. The
    /// targets at `t = 0` are solved here (the IK's first warm start).
    ///
    /// # Errors
    /// [`GaitError`]: no feet, a foot not in the model or given twice, a
    /// foot without joints of its own, `q0` of the wrong length, phases
    /// not one per foot or out of `[0, 1)`, duty or another parameter out
    /// of range, or a foot out of reach at `t = 0`.
    pub fn new(
        model: &RobotModel,
        feet: &[usize],
        position: [f64; 3],
        phi: [f64; 3],
        q0: &[f64],
        params: GaitParams,
    ) -> Result<Self, GaitError> {
        params.check()?;
        if feet.is_empty() {
            return Err(GaitError::NoFeet);
        }
        if params.phases.len() != feet.len() {
            return Err(GaitError::PhaseCount {
                phases: params.phases.len(),
                feet: feet.len(),
            });
        }
        let count = model.contacts.len();
        for (i, &f) in feet.iter().enumerate() {
            if f >= count {
                return Err(GaitError::NoSuchContact { index: f, count });
            }
            if feet[..i].contains(&f) {
                return Err(GaitError::DuplicateFoot {
                    foot: model.contacts[f].name.clone(),
                });
            }
        }
        if q0.len() != model.joints.len() {
            return Err(GaitError::JointCount {
                what: "q0",
                got: q0.len(),
                expected: model.joints.len(),
            });
        }
        if q0.iter().any(|x| !x.is_finite()) || position.iter().chain(&phi).any(|x| !x.is_finite())
        {
            return Err(GaitError::Parameter {
                name: "q0/position/phi",
                value: f64::NAN,
                rule: "finite",
            });
        }
        // Each foot's joints, root side first; a joint above two feet is
        // shared (held).
        let chains: Vec<Vec<usize>> = feet
            .iter()
            .map(|&f| {
                let mut out = Vec::new();
                let mut b = model.contacts[f].body;
                while let Some(j) = model.bodies[b].joint {
                    out.push(j);
                    b = model.joints[j].parent;
                }
                out.reverse();
                out
            })
            .collect();
        let base = base_frame(position, phi);
        let mut data = RobotData::new(model);
        forward(model, &base, q0, &mut data);
        let mut legs = Vec::with_capacity(feet.len());
        for (i, &f) in feet.iter().enumerate() {
            let contact = &model.contacts[f];
            let path: Vec<PathJoint> = chains[i]
                .iter()
                .map(|&j| PathJoint {
                    index: j,
                    origin: model.joints[j].origin,
                    axis: model.joints[j].axis,
                    limits: model.joints[j].limits,
                    moved: !chains
                        .iter()
                        .enumerate()
                        .any(|(o, c)| o != i && c.contains(&j)),
                })
                .collect();
            let n = path.iter().filter(|p| p.moved).count();
            if n == 0 {
                return Err(GaitError::NoJoints {
                    foot: contact.name.clone(),
                });
            }
            let mut nominal = base
                .inverse_transform_point(&Point3::from(data.contacts[f]))
                .coords;
            if nominal.x != 0.0 {
                nominal.x += params.stance_width * nominal.x.signum();
            }
            let mut start = (base * Point3::from(nominal)).coords;
            start.y = contact.radius;
            legs.push(Leg {
                name: contact.name.clone(),
                contact: f,
                radius: contact.radius,
                local: contact.position,
                path,
                nominal,
                start,
                phase: params.phases[i],
                axes: vec![Vector3::zeros(); n],
                origins: vec![Vector3::zeros(); n],
                cols: vec![Vector3::zeros(); n],
                saved_cols: vec![Vector3::zeros(); n],
                dq: vec![0.0; n],
                saved: vec![0.0; n],
                held: vec![false; n],
            });
        }
        let height = params.body_height.unwrap_or(position[1]);
        let mut plan = Self {
            params,
            legs,
            q0: q0.to_vec(),
            q: q0.to_vec(),
            qd: vec![0.0; q0.len()],
            qdd: vec![0.0; q0.len()],
            t_last: f64::NAN,
            position0: position,
            phi0: phi,
            height,
            samples: None,
        };
        let mut q = q0.to_vec();
        let mut qd = vec![0.0; q0.len()];
        plan.targets(0.0, &mut q, &mut qd)?;
        Ok(plan)
    }

    /// Keeps `samples` with the plan and its clones (see
    /// [`SampledTargets`]).
    pub fn record_samples(&mut self, samples: SampledTargets) {
        self.samples = Some(std::sync::Arc::new(samples));
    }

    /// Drops the recorded targets: a stability check then solves the
    /// poses it samples itself (`tests/gait_samples.rs` compares the two).
    pub fn forget_samples(&mut self) {
        self.samples = None;
    }

    /// The targets recorded by [`GaitPlan::record_samples`], if any.
    pub fn samples(&self) -> Option<&SampledTargets> {
        self.samples.as_deref()
    }

    /// The contact indices of the named contact points, in order (for
    /// [`GaitPlan::new`]'s `feet`).
    ///
    /// # Errors
    /// [`GaitError::UnknownFoot`] for a name that is no contact point.
    pub fn feet_by_name(model: &RobotModel, names: &[&str]) -> Result<Vec<usize>, GaitError> {
        names
            .iter()
            .map(|name| {
                model
                    .contacts
                    .iter()
                    .position(|c| c.name == *name)
                    .ok_or_else(|| {
                        let known: Vec<&str> =
                            model.contacts.iter().map(|c| c.name.as_str()).collect();
                        GaitError::UnknownFoot {
                            name: (*name).to_string(),
                            suggestion: crate::suggest(name, &known),
                        }
                    })
            })
            .collect()
    }

    /// The parameters.
    pub fn params(&self) -> &GaitParams {
        &self.params
    }

    /// Number of legs (feet).
    pub fn leg_count(&self) -> usize {
        self.legs.len()
    }

    /// Leg `leg`'s foot: the index of its contact point in the model
    /// (`feet[leg]` of [`GaitPlan::new`]).
    ///
    /// # Panics
    /// For a leg index out of range.
    pub fn foot_contact(&self, leg: usize) -> usize {
        self.legs[leg].contact
    }

    /// The standing pose's joint angles `q0`.
    pub fn standing(&self) -> &[f64] {
        &self.q0
    }

    /// `(σ, σ̇)`: the time along the constant command's path (0 until
    /// `startup`, then ramped in).
    fn path_time(&self, t: f64) -> (f64, f64) {
        let tau = t - self.params.startup;
        let r = self.params.ramp;
        if tau <= 0.0 {
            (0.0, 0.0)
        } else if tau < r {
            let u = tau / r;
            (r * u * u * u * (1.0 - 0.5 * u), u * u * (3.0 - 2.0 * u))
        } else {
            (tau - 0.5 * r, 1.0)
        }
    }

    /// The planned base pose and rates at `t` (s; times before 0 are 0).
    pub fn base(&self, t: f64) -> BasePose {
        let t = t.max(0.0);
        let p = &self.params;
        let [x0, y0, z0] = self.position0;
        let psi0 = self.phi0[1];
        let w = p.yaw_rate;
        let [vx, vz] = p.velocity;
        let (y, ydot) = if p.startup > 0.0 {
            let (s, ds) = smoothstep(t / p.startup);
            (
                y0 + (self.height - y0) * s,
                (self.height - y0) * ds / p.startup,
            )
        } else {
            (self.height, 0.0)
        };
        let (sigma, sdot) = self.path_time(t);
        // ∫₀^σ Ry(ψ₀ + w·s)·v ds = σ·sinc(wσ/2)·Ry(ψ₀ + wσ/2)·v.
        let (dx, dz) = turn(psi0 + 0.5 * w * sigma, vx, vz);
        let k = sigma * sinc(0.5 * w * sigma);
        let psi = psi0 + w * sigma;
        let (ux, uz) = turn(psi, vx, vz);
        BasePose {
            position: [x0 + k * dx, y, z0 + k * dz],
            phi: [self.phi0[0], psi, self.phi0[2]],
            velocity: [sdot * ux, ydot, sdot * uz],
            phi_rate: [0.0, w * sdot, 0.0],
        }
    }

    /// Leg `leg`'s place in its cycle at `t`.
    fn phase(&self, leg: usize, t: f64) -> Phase {
        let p = &self.params;
        // In periods; events closer than EVENT_SNAP periods to a time are
        // at that time (a touchdown and a lift-off planned for one instant
        // stay one instant despite rounding).
        let s = (t.max(0.0) - p.startup) / p.period - self.legs[leg].phase;
        if s < -EVENT_SNAP {
            return Phase::Stance(-1);
        }
        let mut k = s.floor();
        let mut f = s - k;
        if f > 1.0 - EVENT_SNAP {
            k += 1.0;
            f = 0.0;
        }
        let f = f.max(0.0);
        let swing = 1.0 - p.duty;
        if f < swing - EVENT_SNAP {
            Phase::Swing(k as i64, f / swing)
        } else {
            Phase::Stance(k as i64)
        }
    }

    /// Foothold `k` of leg `leg` (inertial; `k = −1`: the start foothold):
    /// the nominal foothold carried by the planned body at mid-stance.
    fn foothold(&self, leg: usize, k: i64) -> Vector3<f64> {
        let l = &self.legs[leg];
        if k < 0 {
            return l.start;
        }
        let p = &self.params;
        let t = p.startup + (l.phase + k as f64 + 1.0 - 0.5 * p.duty) * p.period;
        let mut f = (self.base(t).frame() * Point3::from(l.nominal)).coords;
        f.y = l.radius;
        f
    }

    /// Whether leg `leg` stands at `t` (false for a leg index out of
    /// range).
    pub fn stance(&self, leg: usize, t: f64) -> bool {
        leg < self.legs.len() && matches!(self.phase(leg, t), Phase::Stance(_))
    }

    /// Leg `leg`'s planned foot place and velocity at `t` (`None` for a leg
    /// index out of range).
    pub fn foot(&self, leg: usize, t: f64) -> Option<FootTarget> {
        if leg >= self.legs.len() {
            return None;
        }
        let (pos, vel, stance) = self.foot_vec(leg, t);
        Some(FootTarget {
            position: pos.into(),
            velocity: vel.into(),
            stance,
        })
    }

    fn foot_vec(&self, leg: usize, t: f64) -> (Vector3<f64>, Vector3<f64>, bool) {
        match self.phase(leg, t) {
            Phase::Stance(k) => (self.foothold(leg, k), Vector3::zeros(), true),
            Phase::Swing(k, u) => {
                let a = self.foothold(leg, k - 1);
                let b = self.foothold(leg, k);
                let ts = (1.0 - self.params.duty) * self.params.period;
                let h = self.params.step_height;
                let m = u * u * u * (10.0 + u * (-15.0 + 6.0 * u));
                let dm = 30.0 * u * u * (1.0 - u) * (1.0 - u);
                let v = 1.0 - u;
                let bump = 64.0 * u * u * u * v * v * v;
                let dbump = 192.0 * u * u * v * v * (1.0 - 2.0 * u);
                let mut pos = a + (b - a) * m;
                pos.y += h * bump;
                let mut vel = (b - a) * (dm / ts);
                vel.y += h * dbump / ts;
                (pos, vel, false)
            }
        }
    }

    /// The joint targets at `t` (s): `q` gets the angles (rad), `qd` the
    /// rates (rad/s), both in the order of the model's joints (joints of no
    /// leg: `q0` and 0); returns the planned base pose they assume. A PD
    /// tracking controller applies them; they put the feet on their
    /// planned places only with the base at the returned pose. The IK
    /// starts from the previous call's angles, moved on at their rates for
    /// a call at most 10 ms later (smooth, small steps in `t`
    /// keep one branch of each knee). Allocates nothing but an error's
    /// name.
    ///
    /// # Errors
    /// [`GaitError::JointCount`] for buffers of the wrong length;
    /// [`GaitError::OutOfReach`] naming the first foot left farther than
    /// [`GaitParams::ik_tolerance`] (`q`, `qd` then hold the closest angles
    /// found for it and its rates).
    pub fn targets(
        &mut self,
        t: f64,
        q: &mut [f64],
        qd: &mut [f64],
    ) -> Result<BasePose, GaitError> {
        let n = self.q0.len();
        for (what, got) in [("q", q.len()), ("qd", qd.len())] {
            if got != n {
                return Err(GaitError::JointCount {
                    what,
                    got,
                    expected: n,
                });
            }
        }
        let pose = self.base(t);
        let frame = pose.frame();
        let origin = Vector3::from(pose.position);
        let v_base = Vector3::from(pose.velocity);
        let omega = frame.rotation * Vector3::y() * pose.phi_rate[1];
        q.copy_from_slice(&self.q0);
        qd.fill(0.0);
        let mut failure = None;
        // Warm start from the previous targets, moved on at their rates
        // over a short step forward.
        let h = t - self.t_last;
        let h = if h > 0.0 && h <= WARM_RATE_SPAN {
            h
        } else {
            0.0
        };
        for leg in 0..self.legs.len() {
            let (target, velocity, _) = self.foot_vec(leg, t);
            for pj in self.legs[leg].path.iter().filter(|p| p.moved) {
                let i = pj.index;
                q[i] = self.q[i] + h * (self.qd[i] + 0.5 * h * self.qdd[i]);
            }
            let tol = self.params.ik_tolerance;
            let iters = self.params.ik_max_iterations;
            let l = &mut self.legs[leg];
            let p = l.solve(&frame, q, &target, tol, iters);
            let residual = (target - p).norm();
            let rhs = velocity - v_base - omega.cross(&(p - origin));
            l.rates(q, &rhs, qd);
            if residual > tol && failure.is_none() {
                failure = Some((leg, residual));
            }
        }
        self.q.copy_from_slice(q);
        for ((a, &v), v0) in self.qdd.iter_mut().zip(qd.iter()).zip(&mut self.qd) {
            *a = if h > 0.0 { (v - *v0) / h } else { 0.0 };
            *v0 = v;
        }
        self.t_last = t;
        match failure {
            Some((leg, residual)) => Err(GaitError::OutOfReach {
                foot: self.legs[leg].name.clone(),
                time: t,
                residual,
            }),
            None => Ok(pose),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{ContactChoice, Up};

    /// The lab hexapod standing (`examples/robots/lab_hexapod.toml`) and
    /// its tripod plan.
    fn lab_plan() -> (RobotModel, GaitPlan) {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../examples/robots/lab_hexapod.urdf");
        let model = crate::urdf::load(&path, Up::Z, &ContactChoice::CollisionSpheres).unwrap();
        // Femurs 20° up, tibias 20° down, the rest at zero.
        let degrees = |name: &str| match name.rsplit('_').nth(1) {
            Some("femur") => 20.0,
            Some("tibia") => -20.0,
            _ => 0.0f64,
        };
        let q: Vec<f64> = model
            .joints
            .iter()
            .map(|joint| degrees(&joint.name).to_radians())
            .collect();
        let feet: Vec<usize> = (0..model.contacts.len())
            .filter(|&c| model.contacts[c].name.ends_with("_foot_sphere"))
            .collect();
        let plan = GaitPlan::new(
            &model,
            &feet,
            [0.0, 0.102638, 0.0],
            [0.0; 3],
            &q,
            GaitParams::tripod(),
        )
        .unwrap();
        (model, plan)
    }

    /// The foot and the Jacobian columns `solve` leaves equal those of a
    /// fresh evaluation at the angles it returns, also after trial steps
    /// it rejected (a target out of reach: the search stops on the angles
    /// kept) — the retry with more damping and the rates use the Jacobian
    /// of the angles they start from.
    #[test]
    fn solve_leaves_the_jacobian_of_its_angles() {
        let (_, mut plan) = lab_plan();
        let base = plan.base(0.0).frame();
        let mut q = plan.q.clone();
        let leg = &mut plan.legs[0];
        let here = leg.foot(&base, &q, false);
        for (target, reachable) in [
            (here + Vector3::new(0.01, -0.005, 0.02), true),
            (here + Vector3::new(2.0, 1.0, 0.0), false),
        ] {
            let p = leg.solve(&base, &mut q, &target, 1e-10, 50);
            assert_eq!((target - p).norm() <= 1e-10, reachable, "{p} for {target}");
            let cols = leg.cols.clone();
            let again = leg.foot(&base, &q, true);
            assert_eq!(p, again, "the foot returned is the foot at the angles");
            assert_eq!(cols, leg.cols, "the columns are those of the angles");
        }
    }

    /// Along a tripod walk on a 1 ms grid, the warm start moved on at the
    /// rates (to second order) leaves every leg at most one Newton
    /// iteration from the tolerance, where the last targets alone leave a
    /// third of the legs two; the targets and rates agree with those of
    /// the unmoved warm start to well within the tolerance's angles.
    #[test]
    fn the_warm_start_moved_at_the_rates_takes_one_iteration() {
        let (model, plan) = lab_plan();
        let n = model.joint_count();
        let (mut moved, mut still) = (plan.clone(), plan);
        let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
        let (mut q2, mut qd2) = (vec![0.0; n], vec![0.0; n]);
        // How many legs take 0, 1, 2, more iterations from the warm start
        // of a call at `t` made `h` after the last (counted on a copy).
        let count = |plan: &GaitPlan, t: f64, h: f64, tally: &mut [usize; 4]| {
            let mut copy = plan.clone();
            let frame = copy.base(t).frame();
            for leg in 0..copy.legs.len() {
                let (target, _, _) = copy.foot_vec(leg, t);
                let mut k = 0;
                loop {
                    let mut qq = copy.q.clone();
                    for pj in copy.legs[leg].path.iter().filter(|p| p.moved) {
                        let i = pj.index;
                        qq[i] += h * (copy.qd[i] + 0.5 * h * copy.qdd[i]);
                    }
                    let p = copy.legs[leg].solve(&frame, &mut qq, &target, 1e-10, k);
                    if (target - p).norm() <= 1e-10 || k == 3 {
                        break;
                    }
                    k += 1;
                }
                tally[k] += 1;
            }
        };
        let (mut with_rates, mut without) = ([0usize; 4], [0usize; 4]);
        for k in 1..=3000 {
            let t = k as f64 * 1e-3;
            count(&moved, t, 1e-3, &mut with_rates);
            count(&still, t, 0.0, &mut without);
            moved.targets(t, &mut q, &mut qd).unwrap();
            // As if the last call were long ago: the unmoved warm start.
            still.t_last = f64::NAN;
            still.targets(t, &mut q2, &mut qd2).unwrap();
            for j in 0..n {
                assert!((q[j] - q2[j]).abs() < 1e-8, "joint {j} at t = {t}");
                assert!((qd[j] - qd2[j]).abs() < 1e-6, "rate {j} at t = {t}");
            }
        }
        assert_eq!(with_rates[2] + with_rates[3], 0, "{with_rates:?}");
        assert!(without[2] > without[1], "{without:?}");
        assert_eq!(without[3], 0, "{without:?}");
    }
}

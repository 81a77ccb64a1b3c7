//! The immutable [`GaitModel`] and the mutable [`GaitData`] workspace of a
//! kinematic hexapod run.

use fbd_contact::Surface;
use fbd_kinematics::hexapod::{HexapodConfig, HexapodData, HexapodModel, forward};
use fbd_kinematics::ik::KneeBranch;
use fbd_kinematics::nalgebra::Vector3;
use fbd_kinematics::num::Num;
use fbd_kinematics::pose::BodyPose;

use super::body::{BodyPlan, BodyState};
use super::error::GaitError;
use super::foothold::foothold;
use super::ik::LegJoints;
use super::params::{GaitParams, LEGS};
use super::schedule::{LegPhase, last_swing};
use super::stability::Masses;

/// The initial state of a kinematic run: body pose and joint angles (rad).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct InitialPose {
    /// `(Rx, Ry, Rz)` (m).
    pub position: [f64; 3],
    /// `(φx, φy, φz)` (rad).
    pub phi: [f64; 3],
    /// `(θ1, θ2, θ3)` of each leg (rad).
    pub joints: [[f64; 3]; LEGS],
}

impl Default for InitialPose {
    /// Body at 0.38 m, level, every leg at `(0°, 0°, 245°)` (the paper's
    /// leg-3 pose): the feet are then 0.0006 m above `y = 0`.
    fn default() -> Self {
        Self {
            position: [0.0, 0.38, 0.0],
            phi: [0.0; 3],
            joints: [[0.0, 0.0, 245f64.to_radians()]; LEGS],
        }
    }
}

/// Everything fixed during a kinematic run.
#[derive(Clone, Debug, PartialEq)]
pub struct GaitModel {
    /// Geometry of the robot.
    pub kin: HexapodModel,
    /// The gait.
    pub params: GaitParams,
    /// The terrain.
    pub surface: Surface,
    /// Body and link masses (for the centre of mass).
    pub masses: Masses,
    /// Time step Δt (s).
    pub dt: f64,
    /// Number of steps: rows are written at `k·Δt`, `k = 0..=steps`.
    pub steps: usize,
    /// The initial pose.
    pub initial: InitialPose,
    /// The planned body motion.
    pub plan: BodyPlan,
    /// Initial feet (inertial; dropped onto the terrain when walking).
    pub initial_feet: [Vector3<f64>; LEGS],
    /// Neutral horizontal foot offsets from the body centre, initial
    /// heading frame, `(dx, dz)` (m).
    pub neutral: [[f64; 2]; LEGS],
    /// Knee branch of every leg (that of its initial θ3), kept throughout.
    pub branches: [KneeBranch; LEGS],
    /// Index of the last swing of every leg (cached from the schedule).
    pub last_swing: [Option<usize>; LEGS],
    /// The foothold of every swing of every leg within the run
    /// ([`super::foothold::foothold`], computed once).
    pub footholds: [Vec<Vector3<f64>>; LEGS],
}

impl GaitModel {
    /// Builds a run of `duration` s at step `dt` from `initial`.
    ///
    /// When walking, the initial feet (where the initial joint angles put
    /// them) are dropped vertically onto the terrain: these are the neutral
    /// footholds and the feet at `t = 0`. A standing run keeps them where
    /// they are.
    ///
    /// # Errors
    /// [`GaitError::Invalid`] for out-of-domain parameters, or a walking
    /// gait without ground.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        kin: HexapodModel,
        params: GaitParams,
        surface: Surface,
        masses: Masses,
        dt: f64,
        duration: f64,
        initial: InitialPose,
    ) -> Result<Self, GaitError> {
        params.check().map_err(GaitError::Invalid)?;
        if !(dt.is_finite() && dt > 0.0 && duration.is_finite() && duration >= 0.0) {
            return Err(GaitError::Invalid(format!(
                "time: dt and duration must be positive (got dt = {}, duration = {})",
                Num(dt),
                Num(duration)
            )));
        }
        if params.walking {
            fbd_robot::gait::check_swing(params.period, params.duty, dt)
                .map_err(|e| GaitError::Invalid(format!("period: {e}")))?;
        }
        if params.walking && !surface.exists() {
            return Err(GaitError::Invalid(
                "kind: a walking robot needs ground (terrain.kind = \"none\")".into(),
            ));
        }
        let steps = (duration / dt).round() as usize;
        let pose = BodyPose::new(initial.position, initial.phi);
        let mut fk = HexapodData::new();
        forward(
            &kin,
            &HexapodConfig {
                pose,
                joints: initial.joints,
            },
            &mut fk,
        );
        let mut initial_feet = fk.legs.map(|l| l.tip);
        if params.walking {
            for f in &mut initial_feet {
                f.y = surface.height(f.x, f.z);
            }
        }
        let r0 = pose.position;
        let neutral = initial_feet.map(|f| [f.x - r0.x, f.z - r0.z]);
        let branches = initial.joints.map(|j| KneeBranch::of(j[2]));
        let until = params.walk_time.min(duration + params.period) + 2.0 * dt;
        let plan = BodyPlan::new(&params, &surface, r0, pose.phi, dt, until);
        let last_swing: [Option<usize>; LEGS] = std::array::from_fn(|i| last_swing(&params, i));
        let swings_in_run = (duration / params.period).ceil() as usize + 2;
        let footholds = std::array::from_fn(|leg| {
            let n = last_swing[leg].map_or(0, |l| l.saturating_add(1).min(swings_in_run));
            (0..n)
                .map(|k| {
                    foothold(
                        &params,
                        &plan,
                        &surface,
                        initial.phi[1],
                        neutral[leg],
                        leg,
                        k,
                    )
                })
                .collect()
        });
        Ok(Self {
            kin,
            params,
            surface,
            masses,
            dt,
            steps,
            initial,
            plan,
            initial_feet,
            neutral,
            branches,
            last_swing,
            footholds,
        })
    }

    /// Time of step `k` (s).
    pub fn time(&self, k: usize) -> f64 {
        k as f64 * self.dt
    }
}

/// The state of one step, filled by [`super::step::step`]. Fixed size: no
/// allocation while stepping.
#[derive(Clone, Debug, PartialEq)]
pub struct GaitData {
    /// Step index k.
    pub step: usize,
    /// Time k·Δt (s).
    pub t: f64,
    /// The body's pose, velocity and acceleration.
    pub body: BodyState,
    /// Joint angles, rates and accelerations of every leg.
    pub legs: [LegJoints; LEGS],
    /// Commanded foot positions (inertial, m).
    pub feet: [Vector3<f64>; LEGS],
    /// Commanded foot velocities (m/s).
    pub foot_velocity: [Vector3<f64>; LEGS],
    /// Commanded foot accelerations (m/s²).
    pub foot_acceleration: [Vector3<f64>; LEGS],
    /// Stance or swing of every leg.
    pub phases: [LegPhase; LEGS],
    /// Forward kinematics of the solved joint angles.
    pub fk: HexapodData,
    /// Centre of mass of the whole robot (m).
    pub com: Vector3<f64>,
    /// Stability margin (m).
    pub margin: f64,
}

impl GaitData {
    /// A workspace for `model`, holding the initial joint angles (the
    /// branch the first step stays near).
    pub fn new(model: &GaitModel) -> Self {
        let z = Vector3::zeros();
        Self {
            step: 0,
            t: 0.0,
            body: BodyState::default(),
            legs: model.initial.joints.map(|theta| LegJoints {
                theta,
                ..LegJoints::default()
            }),
            feet: model.initial_feet,
            foot_velocity: [z; LEGS],
            foot_acceleration: [z; LEGS],
            phases: [LegPhase::Stance { last: None }; LEGS],
            fk: HexapodData::new(),
            com: z,
            margin: 0.0,
        }
    }

    /// `true` for every leg in stance.
    pub fn stance(&self) -> [bool; LEGS] {
        self.phases.map(|p| p.is_stance())
    }
}

//! `model = "robot"`: a robot imported from a URDF or MJCF description.
//!
//! ```toml
//! model = "robot"
//! [robot]
//! urdf = "solo12.urdf"        # or mjcf = "robot.xml"; relative to this file
//! up = "z"                    # optional: the description's up axis, "z" | "y"
//! contacts = ["FL_FOOT"]      # optional: links, sites or collision spheres;
//!                             #   default every collision sphere
//! [initial]
//! position = [0.0, 0.4, 0.0]  # optional: the root frame's origin (m)
//! phi_deg = [0.0, 0.0, 0.0]   # optional: φx, φy, φz of the root frame
//! joints_deg = { FL_KFE = -60.0 }  # optional: joint angles, others 0
//! [time]
//! dt = 0.001                  # optional: the step (s)
//! duration = 1.0              # optional (s)
//! [terrain]
//! kind = "flat"               # or "none" (flight), a height map, …
//! [output]
//! stride = 1                  # optional: every stride-th step is written
//! ```
//!
//! `fbd kinematics`, `fbd inverse`, `fbd export mjcf` take such a
//! configuration, and `fbd run` simulates it on its terrain or in flight
//! ([`LoadedRobot::run`]).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use fbd_robot::nalgebra::Isometry3;
use fbd_robot::{ContactChoice, RobotModel, Up};
use serde::{Deserialize, Serialize};

use crate::{ConfigError, Num};

/// The `model` value of an imported robot.
pub const MODEL: &str = "robot";

/// `[robot]`.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RobotSection {
    /// A URDF file, relative to the configuration's directory.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub urdf: Option<String>,
    /// An MJCF file, relative to the configuration's directory.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub mjcf: Option<String>,
    /// The description's up axis, `"z"` (default: ROS and MuJoCo) or
    /// `"y"` (fbd's own exports).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub up: Option<String>,
    /// The contact points by name (links, sites, collision spheres);
    /// default every collision sphere.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub contacts: Option<Vec<String>>,
}

/// `[initial]` of an imported robot.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RobotInitial {
    /// The root frame's origin in the inertial frame (m). Default 0.
    #[serde(default)]
    pub position: [f64; 3],
    /// `(φx, φy, φz)` of the root frame (deg). Default 0.
    #[serde(default)]
    pub phi_deg: [f64; 3],
    /// Joint angles by joint name (deg); joints not named are at 0.
    #[serde(default)]
    pub joints_deg: BTreeMap<String, f64>,
    /// Velocity of the root frame's origin (m/s, inertial). Default 0.
    #[serde(default)]
    pub velocity: [f64; 3],
    /// Angular velocity of the root (deg/s, inertial). Default 0.
    #[serde(default)]
    pub omega_deg: [f64; 3],
    /// Joint rates by joint name (deg/s); others 0.
    #[serde(default)]
    pub rates_deg: BTreeMap<String, f64>,
    /// Lowers (or raises) the root so that the lowest contact point touches
    /// the terrain (after `contacts_at`). Default false.
    #[serde(default)]
    pub rest_on_ground: bool,
    /// Contact points placed at inertial positions (m) by numeric inverse
    /// kinematics of their chains ([`fbd_robot::ik`]), starting from
    /// `joints_deg`; the root stays at `position`, `phi_deg`.
    #[serde(default)]
    pub contacts_at: BTreeMap<String, [f64; 3]>,
}

/// `[world]` of an imported robot.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RobotWorld {
    /// Gravitational acceleration along −Y (m/s²). Default 9.81.
    #[serde(default = "default_gravity")]
    pub gravity: f64,
}

fn default_gravity() -> f64 {
    9.81
}

impl Default for RobotWorld {
    fn default() -> Self {
        Self {
            gravity: default_gravity(),
        }
    }
}

/// `[inverse]`: the accelerations of `fbd inverse`.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RobotInverse {
    /// Acceleration of the root frame's origin (m/s², inertial). Default 0.
    #[serde(default)]
    pub acceleration: [f64; 3],
    /// Angular acceleration of the root (deg/s², inertial). Default 0.
    #[serde(default)]
    pub alpha_deg: [f64; 3],
    /// Joint accelerations by joint name (deg/s²); others 0.
    #[serde(default)]
    pub joints_deg: BTreeMap<String, f64>,
}

/// `[time]` of an imported robot.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RobotTime {
    /// The time step Δt (s). Default 0.001.
    #[serde(default = "default_dt")]
    pub dt: f64,
    /// The simulated time (s). Default 1.0.
    #[serde(default = "default_duration")]
    pub duration: f64,
}

fn default_dt() -> f64 {
    0.001
}

fn default_duration() -> f64 {
    1.0
}

impl Default for RobotTime {
    fn default() -> Self {
        Self {
            dt: default_dt(),
            duration: default_duration(),
        }
    }
}

/// How the joints of an imported robot are driven (`[control] kind`).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum RobotControlKind {
    /// Passive joints (zero torque).
    #[default]
    None,
    /// PD to fixed joint angles.
    Pd,
    /// PD along piecewise-linear joint trajectories.
    Trajectory,
    /// PD along the joint angles and rates of the `[gait]` plan.
    Gait,
}

/// A gait's stepping pattern (`[gait] pattern`).
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq)]
#[serde(rename_all = "lowercase")]
pub enum GaitPattern {
    /// Four legs, diagonal pairs: phases `[0, ½, ½, 0]` (feet FL, FR, HL,
    /// HR), period 0.5 s, duty factor 0.6.
    #[default]
    Trot,
    /// Four legs, one at a time (FL, HR, FR, HL): phases `[0, ½, ¾, ¼]`,
    /// period 0.8 s, duty factor 0.75.
    Walk,
    /// Six legs in two tripods: phases `[0, ½, 0, ½, 0, ½]` (LF, LM, LR,
    /// RF, RM, RR), period 0.8 s, duty factor 0.6.
    Tripod,
    /// `phases` given, period 0.5 s and duty factor 0.6 unless given.
    Custom,
}

/// `[gait]` of an imported robot (`[control] kind = "gait"`): the plan of
/// [`fbd_robot::gait`]. Every key but `pattern` is optional; the complete
/// configuration (`config.toml`) holds the values used.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RobotGaitConfig {
    /// The pattern; its phases, period and duty factor are the defaults.
    #[serde(default)]
    pub pattern: GaitPattern,
    /// The feet (contact points by name), in the order of `phases`;
    /// default every contact point in the model's order.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feet: Option<Vec<String>>,
    /// Per foot, the lift-off's phase in `[0, 1)`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub phases: Option<Vec<f64>>,
    /// Gait period (s).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub period: Option<f64>,
    /// Duty factor: the stance's share of the period, in (0, 1).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub duty_factor: Option<f64>,
    /// Swing apex above the ground (m). Default 0.04.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub step_height: Option<f64>,
    /// Forward speed (m/s, along the body's `−z`); or `velocity`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub speed: Option<f64>,
    /// Horizontal velocity `[vx, vz]` (m/s) in the heading frame; default
    /// `[0, −speed]`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub velocity: Option<[f64; 2]>,
    /// Yaw rate (deg/s, counter-clockwise seen from above). Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub yaw_rate_deg: Option<f64>,
    /// Body height while walking (m); default the initial one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub body_height: Option<f64>,
    /// Footholds moved outwards along the body's `x` (m). Default 0.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub stance_width: Option<f64>,
    /// Standing time before the first step (s). Default 0.5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub startup: Option<f64>,
    /// The velocity's smooth ramp after `startup` (s). Default 0.5.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ramp: Option<f64>,
}

/// `[control]` of an imported robot: `τ = kp·(θ* − θ[k]) + kd·(θ̇* −
/// θ̇[k])` on every joint, clamped to the joint's effort limit and to
/// `torque_limit`.
#[derive(Clone, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RobotControlConfig {
    /// `"none"` (default), `"pd"` or `"trajectory"`.
    #[serde(default)]
    pub kind: RobotControlKind,
    /// Position gain of every joint (N·m/rad). Default 0.
    #[serde(default)]
    pub kp: f64,
    /// Rate gain of every joint (N·m·s/rad). Default 0.
    #[serde(default)]
    pub kd: f64,
    /// Per-joint gains `{ joint = [kp, kd] }` replacing `kp`, `kd`.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub gains: BTreeMap<String, [f64; 2]>,
    /// `|τ| ≤ torque_limit` (N·m) on every joint, besides each joint's
    /// effort limit from the description.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub torque_limit: Option<f64>,
    /// `pd`: target angles by joint (deg); joints not named hold their
    /// initial angle.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub target_deg: BTreeMap<String, f64>,
    /// `trajectory`: the knots' times (s), strictly increasing.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub times: Vec<f64>,
    /// `trajectory`: per knot, joint angles by name (deg); joints not
    /// named hold their initial angle.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub targets_deg: Vec<BTreeMap<String, f64>>,
}

/// `[output]` of an imported robot: every model's (`stride`, `format`,
/// `viewer`, `plots`).
pub type RobotOutput = crate::OutputConfig;

/// A `model = "robot"` configuration file.
#[derive(Clone, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct RobotConfig {
    /// `"robot"`.
    pub model: String,
    /// `[robot]`.
    pub robot: RobotSection,
    /// `[initial]`.
    #[serde(default)]
    pub initial: RobotInitial,
    /// `[world]`.
    #[serde(default)]
    pub world: RobotWorld,
    /// `[inverse]`.
    #[serde(default)]
    pub inverse: RobotInverse,
    /// `[time]`.
    #[serde(default)]
    pub time: RobotTime,
    /// `[terrain]`: the hexapod's table (every kind; `"none"` for a run
    /// in flight). Default flat ground at `y = 0`.
    #[serde(default)]
    pub terrain: crate::TerrainConfig,
    /// `[control]`.
    #[serde(default)]
    pub control: RobotControlConfig,
    /// `[gait]` (with `[control] kind = "gait"`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gait: Option<RobotGaitConfig>,
    /// `[output]`.
    #[serde(default)]
    pub output: RobotOutput,
    /// `[solver]`: Newton's settings (the hexapod's table).
    #[serde(default)]
    pub solver: crate::SolverConfig,
}

impl RobotConfig {
    /// The configuration as TOML (every key, defaults filled when it comes
    /// from [`LoadedRobot::config`]).
    pub fn to_toml(&self) -> String {
        toml::to_string(self).expect("a robot configuration serializes to TOML")
    }
}

/// A loaded robot and its initial state.
#[derive(Clone, Debug, PartialEq)]
pub struct LoadedRobot {
    /// The description file, as resolved.
    pub description: PathBuf,
    /// The model.
    pub model: RobotModel,
    /// The root frame's initial pose.
    pub base: Isometry3<f64>,
    /// The initial joint angles (rad), in the model's joint order.
    pub q: Vec<f64>,
    /// The initial joint rates (rad/s).
    pub qd: Vec<f64>,
    /// The root origin's initial velocity (m/s, inertial).
    pub velocity: [f64; 3],
    /// The root's initial angular velocity (rad/s, inertial).
    pub omega: [f64; 3],
    /// The root's initial `(φx, φy, φz)` (rad).
    pub initial_phi: [f64; 3],
    /// Gravity along −Y (m/s²).
    pub gravity: f64,
    /// `[inverse]`: root acceleration (m/s²), angular acceleration
    /// (rad/s²), joint accelerations (rad/s²).
    pub acceleration: ([f64; 3], [f64; 3], Vec<f64>),
    /// The joint controller of `[control]`, per joint in radians.
    pub control: fbd_sim::robot::RobotControl,
    /// The complete configuration: every default filled, the description
    /// given by its canonical path (`config.toml` of a run repeats it).
    pub config: RobotConfig,
}

/// Whether the TOML `text` says `model = "robot"`.
pub fn is_robot(text: &str) -> bool {
    toml::from_str::<toml::Table>(text)
        .ok()
        .and_then(|t| t.get("model").and_then(|m| m.as_str().map(|s| s == MODEL)))
        .unwrap_or(false)
}

fn semantic(file: &str, message: String) -> ConfigError {
    ConfigError::Semantic {
        file: file.to_owned(),
        message,
    }
}

/// Parses the configuration `text` of `path` and loads its robot.
pub fn load_str(text: &str, path: &Path) -> Result<LoadedRobot, ConfigError> {
    let file = path.display().to_string();
    let mut config: RobotConfig =
        toml::from_str(text).map_err(|e| crate::syntax_error(&file, text, &e))?;
    config.terrain.resolve_kind();
    config.terrain.load_profile_file(&file)?;
    config.terrain.load_map(&file)?;
    if !config.terrain.height.is_finite() {
        return Err(ConfigError::semantic(
            &file,
            "terrain.height",
            "must be finite",
            config.terrain.height,
            "a finite value",
        ));
    }
    config.terrain.validate_kind(&file)?;
    config.terrain.patches(&file)?;
    let r = &config.robot;
    let (rel, is_urdf) = match (&r.urdf, &r.mjcf) {
        (Some(u), None) => (u, true),
        (None, Some(m)) => (m, false),
        _ => {
            return Err(semantic(
                &file,
                "robot: give exactly one of urdf = \"FILE\" or mjcf = \"FILE\"".to_owned(),
            ));
        }
    };
    let up = match r.up.as_deref() {
        None | Some("z") => Up::Z,
        Some("y") => Up::Y,
        Some(other) => {
            return Err(ConfigError::semantic(
                &file,
                "robot.up",
                "unknown up axis",
                format!("\"{other}\""),
                "\"z\" or \"y\"",
            ));
        }
    };
    let contacts = match &r.contacts {
        None => ContactChoice::CollisionSpheres,
        Some(names) => ContactChoice::Named(names.clone()),
    };
    let base_dir = path.parent().unwrap_or(Path::new(""));
    let key = if is_urdf { "robot.urdf" } else { "robot.mjcf" };
    let description = resolve_description(rel, base_dir, &file, key)?;
    let model = if is_urdf {
        fbd_robot::urdf::load(&description, up, &contacts)?
    } else {
        fbd_robot::mjcf::load(&description, up, &contacts)?
    };
    let init = &config.initial;
    let joints = |table: &str, values: &BTreeMap<String, f64>, limits: bool| {
        let mut out = vec![0.0; model.joints.len()];
        for (name, &deg) in values {
            let Some(j) = model.joint_index(name) else {
                let known: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
                return Err(semantic(
                    &file,
                    format!(
                        "{table}.{name}: no such joint in {}{}",
                        description.display(),
                        suggest_name(name, &known)
                    ),
                ));
            };
            if !deg.is_finite() {
                return Err(semantic(&file, format!("{table}.{name}: must be finite")));
            }
            let rad = deg.to_radians();
            if limits
                && let Some(l) = model.joints[j].limits
                && !(l.lower <= rad && rad <= l.upper)
            {
                return Err(ConfigError::semantic(
                    &file,
                    &format!("{table}.{name}"),
                    "outside the joint's limits",
                    format!("{}°", Num(deg)),
                    &format!(
                        "[{}°, {}°]",
                        Num(l.lower.to_degrees()),
                        Num(l.upper.to_degrees())
                    ),
                ));
            }
            out[j] = rad;
        }
        Ok(out)
    };
    let mut q = joints("initial.joints_deg", &init.joints_deg, true)?;
    let qd = joints("initial.rates_deg", &init.rates_deg, false)?;
    let inv = &config.inverse;
    let qdd = joints("inverse.joints_deg", &inv.joints_deg, false)?;
    let vectors = [
        ("initial.position", init.position),
        ("initial.phi_deg", init.phi_deg),
        ("initial.velocity", init.velocity),
        ("initial.omega_deg", init.omega_deg),
        ("inverse.acceleration", inv.acceleration),
        ("inverse.alpha_deg", inv.alpha_deg),
    ];
    if let Some((key, _)) = vectors
        .iter()
        .find(|(_, v)| v.iter().any(|x| !x.is_finite()))
    {
        return Err(semantic(&file, format!("{key}: must be finite")));
    }
    let g = config.world.gravity;
    if !(g.is_finite() && g >= 0.0) {
        return Err(ConfigError::semantic(
            &file,
            "world.gravity",
            "out of range",
            g,
            "≥ 0 m/s²",
        ));
    }
    let t = &config.time;
    if !(t.dt.is_finite() && t.dt > 0.0) {
        return Err(ConfigError::semantic(
            &file,
            "time.dt",
            "out of range",
            t.dt,
            "> 0 s, finite",
        ));
    }
    if !(t.duration.is_finite() && t.duration >= 0.0) {
        return Err(ConfigError::semantic(
            &file,
            "time.duration",
            "out of range",
            t.duration,
            "≥ 0 s, finite",
        ));
    }
    if config.output.stride < 1 {
        return Err(ConfigError::semantic(
            &file,
            "output.stride",
            "out of range",
            config.output.stride,
            "≥ 1",
        ));
    }
    let base = fbd_robot::forward::base_frame(init.position, init.phi_deg.map(f64::to_radians));
    if !init.contacts_at.is_empty() {
        let mut targets = Vec::with_capacity(init.contacts_at.len());
        for (name, p) in &init.contacts_at {
            let Some(c) = model.contacts.iter().position(|c| &c.name == name) else {
                let known: Vec<&str> = model.contacts.iter().map(|c| c.name.as_str()).collect();
                return Err(semantic(
                    &file,
                    format!(
                        "initial.contacts_at.{name}: no such contact point{}",
                        suggest_name(name, &known)
                    ),
                ));
            };
            if p.iter().any(|x| !x.is_finite()) {
                return Err(semantic(
                    &file,
                    format!("initial.contacts_at.{name}: must be finite"),
                ));
            }
            targets.push((c, fbd_robot::nalgebra::Vector3::from(*p)));
        }
        q = fbd_robot::ik::solve(&model, &base, &q, &targets, &Default::default()).map_err(
            |e| {
                semantic(
                    &file,
                    format!("initial.contacts_at.{}: out of reach: {e}", e.point),
                )
            },
        )?;
    }
    let mut base = base;
    if init.rest_on_ground {
        if config.terrain.kind == crate::TerrainKind::None || model.contacts.is_empty() {
            return Err(semantic(
                &file,
                "initial.rest_on_ground: needs a terrain (not kind = \"none\") and contact points"
                    .to_owned(),
            ));
        }
        let surface = config.terrain.surface();
        let mut d = fbd_robot::forward::RobotData::new(&model);
        fbd_robot::forward::forward(&model, &base, &q, &mut d);
        let lowest = model
            .contacts
            .iter()
            .zip(&d.contacts)
            .map(|(c, p)| p.y - c.radius - surface.height(p.x, p.z))
            .fold(f64::INFINITY, f64::min);
        base.translation.vector.y -= lowest;
    }
    let plan = if config.control.kind == RobotControlKind::Gait {
        if config.terrain.kind == crate::TerrainKind::None {
            return Err(semantic(
                &file,
                "control.kind = \"gait\": a gait walks on a terrain (not kind = \"none\")"
                    .to_owned(),
            ));
        }
        let time = config.time.clone();
        let gait = config.gait.get_or_insert_with(Default::default);
        let mut plan = resolve_gait(gait, &model, &base, init.phi_deg, &q, time.dt, &file)?;
        check_reach(&mut plan, &time, &file)?;
        Some(plan)
    } else if config.gait.is_some() {
        return Err(semantic(
            &file,
            "gait: a [gait] table needs [control] kind = \"gait\"".to_owned(),
        ));
    } else {
        None
    };
    let control = resolve_control(&config.control, &model, &q, &file, &description, plan)?;
    let config = complete(&config, &description);
    Ok(LoadedRobot {
        description,
        model,
        base,
        q,
        qd,
        velocity: init.velocity,
        omega: init.omega_deg.map(f64::to_radians),
        initial_phi: init.phi_deg.map(f64::to_radians),
        gravity: g,
        acceleration: (inv.acceleration, inv.alpha_deg.map(f64::to_radians), qdd),
        control,
        config,
    })
}

/// The environment variable listing the folders that `package://NAME/…`
/// paths are looked up in (`:`-separated, as ROS and Pinocchio use it).
pub const PACKAGE_PATH_VAR: &str = "ROS_PACKAGE_PATH";

/// A description's path: `package://NAME/REST` is `DIR/NAME/REST` for the
/// first folder `DIR` of `ROS_PACKAGE_PATH` that holds it (or `DIR/REST`
/// when `DIR` is itself named `NAME`); any other path is relative to the
/// configuration's folder `base_dir`.
fn resolve_description(
    rel: &str,
    base_dir: &Path,
    file: &str,
    key: &str,
) -> Result<PathBuf, ConfigError> {
    let Some(uri) = rel.strip_prefix("package://") else {
        return Ok(base_dir.join(rel));
    };
    let (name, rest) = uri.split_once('/').unwrap_or((uri, ""));
    let dirs = std::env::var(PACKAGE_PATH_VAR).unwrap_or_default();
    for dir in dirs.split(':').filter(|d| !d.is_empty()) {
        let dir = Path::new(dir);
        let mut candidates = vec![dir.join(name).join(rest)];
        if dir.file_name().is_some_and(|n| n == name) {
            candidates.push(dir.join(rest));
        }
        if let Some(found) = candidates.into_iter().find(|c| c.is_file()) {
            return Ok(found);
        }
    }
    Err(semantic(
        file,
        format!(
            "{key}: \"{rel}\" not found: no folder {name} holding {rest} in {PACKAGE_PATH_VAR} ({}); \
             set {PACKAGE_PATH_VAR} to the folder that holds {name} (for example-robot-data: \
             pip install example-robot-data, then {PACKAGE_PATH_VAR}=<site-packages>/cmeel.prefix/share/example-robot-data/robots)",
            if dirs.is_empty() {
                "unset".to_owned()
            } else {
                format!("\"{dirs}\"")
            }
        ),
    ))
}

/// Every target of `plan` over the run's first steps is within reach: up to
/// the start-up, the ramp and two periods (after the ramp the plan repeats
/// itself in the body's frame every period) or the run's end, every step.
/// The first foot out of reach is an error naming it and the time. The
/// targets at the poses the start-up stability check samples over those
/// steps ([`fbd_sim::robot::gait_pose_stride`]) are kept with `plan`
/// ([`fbd_robot::gait::GaitPlan::record_samples`]): they are the run's
/// own, and the check needs no inverse kinematics of its own.
fn check_reach(
    plan: &mut fbd_robot::gait::GaitPlan,
    time: &RobotTime,
    file: &str,
) -> Result<(), ConfigError> {
    let p = plan.params();
    let horizon = time.duration.min(p.startup + p.ramp + 2.0 * p.period);
    let steps = (horizon / time.dt).round() as usize + 1;
    let stride = fbd_sim::robot::gait_pose_stride(steps);
    let mut stepped = plan.clone();
    let n = stepped.standing().len();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    let mut targets = Vec::with_capacity(steps / stride + 1);
    for k in 0..steps {
        stepped
            .targets(k as f64 * time.dt, &mut q, &mut qd)
            .map_err(|e| semantic(file, format!("gait: {e}")))?;
        if k % stride == 0 {
            targets.push(q.clone());
        }
    }
    plan.record_samples(fbd_robot::gait::SampledTargets {
        dt: time.dt,
        stride,
        targets,
    });
    Ok(())
}

/// `[gait]` into a plan from the initial pose (`base`, `phi_deg`, joint
/// angles `q`); fills every key of `gait` with the value used. Errors name
/// `gait.<key>`.
fn resolve_gait(
    gait: &mut RobotGaitConfig,
    model: &RobotModel,
    base: &Isometry3<f64>,
    phi_deg: [f64; 3],
    q: &[f64],
    dt: f64,
    file: &str,
) -> Result<fbd_robot::gait::GaitPlan, ConfigError> {
    use fbd_robot::gait::{GaitParams, GaitPlan};
    let mut p = match gait.pattern {
        GaitPattern::Trot | GaitPattern::Custom => GaitParams::trot(),
        GaitPattern::Walk => GaitParams::walk(),
        GaitPattern::Tripod => GaitParams::tripod(),
    };
    let names: Vec<String> = match &gait.feet {
        Some(f) => f.clone(),
        None => model.contacts.iter().map(|c| c.name.clone()).collect(),
    };
    let refs: Vec<&str> = names.iter().map(String::as_str).collect();
    let feet = GaitPlan::feet_by_name(model, &refs)
        .map_err(|e| semantic(file, format!("gait.feet: {e}")))?;
    if let Some(ph) = &gait.phases {
        p.phases = ph.clone();
    } else if gait.pattern == GaitPattern::Custom {
        return Err(semantic(
            file,
            "gait.phases: pattern = \"custom\" needs phases, one per foot".to_owned(),
        ));
    } else if p.phases.len() != feet.len() {
        return Err(semantic(
            file,
            format!(
                "gait.pattern: {:?} has {} legs, the robot {} feet ({}); give gait.feet or gait.phases",
                gait.pattern,
                p.phases.len(),
                feet.len(),
                names.join(", ")
            )
            .to_lowercase(),
        ));
    }
    let finite = |key: &str, v: f64| {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(semantic(
                file,
                format!("gait.{key}: must be finite (got {v})"),
            ))
        }
    };
    if let Some(v) = gait.period {
        p.period = finite("period", v)?;
    }
    if let Some(v) = gait.duty_factor {
        p.duty = finite("duty_factor", v)?;
    }
    if let Some(v) = gait.step_height {
        p.step_height = finite("step_height", v)?;
    }
    match (gait.velocity, gait.speed) {
        (Some(_), Some(_)) => {
            return Err(semantic(
                file,
                "gait.velocity: give speed or velocity, not both".to_owned(),
            ));
        }
        (Some(v), None) => p.velocity = [finite("velocity", v[0])?, finite("velocity", v[1])?],
        (None, Some(s)) => p.velocity = [0.0, -finite("speed", s)?],
        (None, None) => p.velocity = [0.0, 0.0],
    }
    if let Some(v) = gait.yaw_rate_deg {
        p.yaw_rate = finite("yaw_rate_deg", v)?.to_radians();
    }
    if let Some(v) = gait.body_height {
        p.body_height = Some(finite("body_height", v)?);
    }
    if let Some(v) = gait.stance_width {
        p.stance_width = finite("stance_width", v)?;
    }
    if let Some(v) = gait.startup {
        p.startup = finite("startup", v)?;
    }
    if let Some(v) = gait.ramp {
        p.ramp = finite("ramp", v)?;
    }
    crate::gait::swing_fits(file, p.period, p.duty, dt)?;
    let position = base.translation.vector;
    let plan = GaitPlan::new(
        model,
        &feet,
        [position.x, position.y, position.z],
        phi_deg.map(f64::to_radians),
        q,
        p.clone(),
    )
    .map_err(|e| semantic(file, format!("gait: {e}")))?;
    gait.feet = Some(names);
    gait.phases = Some(p.phases);
    gait.period.get_or_insert(p.period);
    gait.duty_factor.get_or_insert(p.duty);
    gait.step_height.get_or_insert(p.step_height);
    if gait.speed.is_none() {
        gait.velocity.get_or_insert(p.velocity);
    }
    gait.yaw_rate_deg.get_or_insert(0.0);
    gait.stance_width.get_or_insert(p.stance_width);
    gait.startup.get_or_insert(p.startup);
    gait.ramp.get_or_insert(p.ramp);
    Ok(plan)
}

/// `[control]` per joint in radians: gains (`kp`, `kd`, `gains`), targets
/// (`pd`: `target_deg`, others at `q`; `trajectory`: `times`,
/// `targets_deg`; `gait`: `plan`, built from `[gait]`). Errors name the
/// key.
fn resolve_control(
    c: &RobotControlConfig,
    model: &RobotModel,
    q: &[f64],
    file: &str,
    description: &Path,
    plan: Option<fbd_robot::gait::GaitPlan>,
) -> Result<fbd_sim::robot::RobotControl, ConfigError> {
    use fbd_sim::robot::{JointTrajectory, RobotControl};
    let nj = model.joints.len();
    let joint = |key: &str, name: &str| {
        model.joint_index(name).ok_or_else(|| {
            let known: Vec<&str> = model.joints.iter().map(|j| j.name.as_str()).collect();
            semantic(
                file,
                format!(
                    "{key}.{name}: no such joint in {}{}",
                    description.display(),
                    suggest_name(name, &known)
                ),
            )
        })
    };
    let finite = |key: String, v: f64| {
        if v.is_finite() {
            Ok(v)
        } else {
            Err(semantic(file, format!("{key}: must be finite (got {v})")))
        }
    };
    let mut kp = vec![c.kp; nj];
    let mut kd = vec![c.kd; nj];
    for (name, [p, d]) in &c.gains {
        let j = joint("control.gains", name)?;
        kp[j] = *p;
        kd[j] = *d;
    }
    let angles = |key: &str, table: &BTreeMap<String, f64>| {
        let mut out = q.to_vec();
        for (name, &deg) in table {
            let j = joint(key, name)?;
            out[j] = finite(format!("{key}.{name}"), deg)?.to_radians();
        }
        Ok::<_, ConfigError>(out)
    };
    let unused = |key: &str, used: bool| {
        if used {
            Err(semantic(
                file,
                format!(
                    "control.{key}: not used by kind = \"{}\"",
                    match c.kind {
                        RobotControlKind::None => "none",
                        RobotControlKind::Pd => "pd",
                        RobotControlKind::Trajectory => "trajectory",
                        RobotControlKind::Gait => "gait",
                    }
                ),
            ))
        } else {
            Ok(())
        }
    };
    Ok(match c.kind {
        RobotControlKind::Gait => {
            unused("target_deg", !c.target_deg.is_empty())?;
            unused("times", !c.times.is_empty())?;
            unused("targets_deg", !c.targets_deg.is_empty())?;
            RobotControl::Gait {
                kp,
                kd,
                plan: Box::new(plan.expect("the caller builds the plan of kind = \"gait\"")),
                torque_limit: c.torque_limit,
            }
        }
        RobotControlKind::None => {
            unused("target_deg", !c.target_deg.is_empty())?;
            unused("times", !c.times.is_empty())?;
            RobotControl::None
        }
        RobotControlKind::Pd => {
            unused("times", !c.times.is_empty())?;
            unused("targets_deg", !c.targets_deg.is_empty())?;
            RobotControl::Pd {
                kp,
                kd,
                target: angles("control.target_deg", &c.target_deg)?,
                torque_limit: c.torque_limit,
            }
        }
        RobotControlKind::Trajectory => {
            unused("target_deg", !c.target_deg.is_empty())?;
            if c.times.is_empty() || c.times.len() != c.targets_deg.len() {
                return Err(semantic(
                    file,
                    format!(
                        "control.times: one time per entry of control.targets_deg, at least one (got {} times, {} targets)",
                        c.times.len(),
                        c.targets_deg.len()
                    ),
                ));
            }
            for (i, &t) in c.times.iter().enumerate() {
                finite(format!("control.times[{i}]"), t)?;
            }
            if let Some(i) = c.times.windows(2).position(|w| w[0] >= w[1]) {
                return Err(semantic(
                    file,
                    format!(
                        "control.times: must increase strictly (times[{i}] = {} ≥ times[{}] = {})",
                        c.times[i],
                        i + 1,
                        c.times[i + 1]
                    ),
                ));
            }
            let mut knots = Vec::with_capacity(c.times.len());
            for (i, t) in c.targets_deg.iter().enumerate() {
                knots.push(angles(&format!("control.targets_deg[{i}]"), t)?);
            }
            RobotControl::Trajectory {
                kp,
                kd,
                trajectory: JointTrajectory {
                    times: c.times.clone(),
                    angles: knots,
                },
                torque_limit: c.torque_limit,
            }
        }
    })
}

/// `config` with every default filled and its description given by its
/// canonical (absolute) path.
fn complete(config: &RobotConfig, description: &Path) -> RobotConfig {
    let mut c = config.clone();
    let path = std::fs::canonicalize(description)
        .unwrap_or_else(|_| description.to_path_buf())
        .display()
        .to_string();
    if c.robot.urdf.is_some() {
        c.robot.urdf = Some(path);
    } else {
        c.robot.mjcf = Some(path);
    }
    c.robot.up.get_or_insert_with(|| "z".to_owned());
    c.solver.resolve();
    c
}

/// [`load_str`] after `overrides` (dotted keys, e.g. a sweep's) are set in
/// the configuration's table; an override that cannot be set is a
/// [`ConfigError::Override`] naming its key.
pub fn load_with_overrides(
    text: &str,
    path: &Path,
    overrides: &[crate::Override],
) -> Result<LoadedRobot, ConfigError> {
    if overrides.is_empty() {
        return load_str(text, path);
    }
    let file = path.display().to_string();
    let mut table: toml::Table =
        toml::from_str(text).map_err(|e| crate::syntax_error(&file, text, &e))?;
    for o in overrides {
        crate::apply_override(&mut table, &o.key, o.value.clone()).map_err(|message| {
            ConfigError::Override {
                file: file.clone(),
                key: o.key.clone(),
                message,
            }
        })?;
    }
    let text = toml::to_string(&table).map_err(|e| semantic(&file, e.to_string()))?;
    load_str(&text, path).map_err(|e| match e {
        // A line of the text the overrides made is no line of the file:
        // the error names the override instead.
        ConfigError::Syntax { message, .. } => ConfigError::Override {
            key: override_of(&message, overrides),
            file,
            message,
        },
        other => other,
    })
}

/// The key of the override a message (`table.key: what`) is about: the
/// last override in the table it names, or every override's key.
fn override_of(message: &str, overrides: &[crate::Override]) -> String {
    let table = message.split([':', ' ']).next().unwrap_or_default();
    let named = overrides
        .iter()
        .rev()
        .find(|o| o.key == table || o.key.starts_with(&format!("{table}.")));
    match named {
        Some(o) => o.key.clone(),
        None => overrides
            .iter()
            .map(|o| o.key.as_str())
            .collect::<Vec<_>>()
            .join("`, `"),
    }
}

/// Reads `path` and loads its robot ([`load_str`]).
pub fn load(path: &Path) -> Result<LoadedRobot, ConfigError> {
    let text = crate::read_text(path)?;
    load_str(&text, path)
}

/// ` (did you mean "x"?)` for the closest known name, if close.
fn suggest_name(name: &str, known: &[&str]) -> String {
    known
        .iter()
        .map(|k| (strsim::damerau_levenshtein(name, k), *k))
        .filter(|(d, _)| *d <= 3)
        .min()
        .map(|(_, k)| format!(" (did you mean \"{k}\"?)"))
        .unwrap_or_default()
}

/// One body at the initial state (`fbd kinematics`).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct BodyKinematics {
    /// The body's name.
    pub name: String,
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the body's frame (m).
    pub com: [f64; 3],
    /// Inertia about the centre of mass, body axes, rows (kg·m²).
    pub inertia: [[f64; 3]; 3],
    /// The body frame's origin, inertial (m).
    pub position: [f64; 3],
    /// The body frame's axes in the inertial frame, rows of the rotation
    /// matrix (`rotation[i][k]`: inertial component i of body axis k).
    pub rotation: [[f64; 3]; 3],
}

/// One joint at the initial state.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct JointKinematics {
    /// The joint's name.
    pub name: String,
    /// The parent body's name.
    pub parent: String,
    /// The child body's name.
    pub child: String,
    /// The angle (rad).
    pub angle: f64,
    /// A point of the axis: the child frame's origin, inertial (m).
    pub position: [f64; 3],
    /// The axis, inertial (unit).
    pub axis: [f64; 3],
    /// `[lower, upper]` (rad), or null for a continuous joint.
    pub limits: Option<[f64; 2]>,
    /// The effort limit (N·m), or null.
    pub effort: Option<f64>,
}

/// One contact point at the initial state.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ContactKinematics {
    /// The point's name.
    pub name: String,
    /// The body carrying it.
    pub body: String,
    /// The sphere's centre, inertial (m).
    pub position: [f64; 3],
    /// The sphere's radius (m), 0 for a point.
    pub radius: f64,
}

/// `fbd kinematics` of an imported robot.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RobotKinematics {
    /// The robot's name.
    pub robot: String,
    /// The description file.
    pub description: String,
    /// Total mass (kg).
    pub mass: f64,
    /// The whole robot's centre of mass, inertial (m).
    pub com: [f64; 3],
    /// Every body, root first.
    pub bodies: Vec<BodyKinematics>,
    /// Every revolute joint.
    pub joints: Vec<JointKinematics>,
    /// Every contact point.
    pub contacts: Vec<ContactKinematics>,
}

fn rows(m: &fbd_robot::nalgebra::Matrix3<f64>) -> [[f64; 3]; 3] {
    [0, 1, 2].map(|i| [m[(i, 0)], m[(i, 1)], m[(i, 2)]])
}

impl LoadedRobot {
    /// The robot as a MuJoCo model in fbd's frames, its root at the initial
    /// pose (`fbd export mjcf`, [`fbd_robot::mjcf_export`]).
    pub fn mjcf(&self) -> String {
        fbd_robot::mjcf_export::to_mjcf(
            &self.model,
            self.gravity,
            fbd_robot::mjcf_export::TIMESTEP,
            &self.base,
        )
    }

    /// Every body, joint and contact point at the initial state.
    pub fn kinematics(&self) -> RobotKinematics {
        let m = &self.model;
        let mut data = fbd_robot::RobotData::new(m);
        fbd_robot::forward(m, &self.base, &self.q, &mut data);
        let v = |x: fbd_robot::nalgebra::Vector3<f64>| [x.x, x.y, x.z];
        RobotKinematics {
            robot: m.name.clone(),
            description: self.description.display().to_string(),
            mass: m.mass(),
            com: v(data.total_com(m)),
            bodies: m
                .bodies
                .iter()
                .zip(&data.frames)
                .map(|(b, f)| BodyKinematics {
                    name: b.name.clone(),
                    mass: b.mass,
                    com: v(b.com),
                    inertia: rows(&b.inertia),
                    position: v(f.translation.vector),
                    rotation: rows(f.rotation.to_rotation_matrix().matrix()),
                })
                .collect(),
            joints: m
                .joints
                .iter()
                .enumerate()
                .map(|(j, joint)| JointKinematics {
                    name: joint.name.clone(),
                    parent: m.bodies[joint.parent].name.clone(),
                    child: m.bodies[joint.child].name.clone(),
                    angle: self.q[j],
                    position: v(data.frames[joint.child].translation.vector),
                    axis: v(data.axes[j]),
                    limits: joint.limits.map(|l| [l.lower, l.upper]),
                    effort: joint.effort,
                })
                .collect(),
            contacts: m
                .contacts
                .iter()
                .zip(&data.contacts)
                .map(|(c, p)| ContactKinematics {
                    name: c.name.clone(),
                    body: m.bodies[c.body].name.clone(),
                    position: v(*p),
                    radius: c.radius,
                })
                .collect(),
        }
    }
}

/// One joint's share of `fbd inverse`.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct JointInverse {
    /// The joint's name.
    pub name: String,
    /// Force of the parent body on the child at the joint (N, inertial).
    pub force: [f64; 3],
    /// Moment of the parent on the child about the joint's origin (N·m,
    /// inertial): `torque·axis + constraint_moment`.
    pub moment: [f64; 3],
    /// The torque along the joint's axis (N·m).
    pub torque: f64,
    /// The moment across the axis, carried by the joint's structure (N·m).
    pub constraint_moment: [f64; 3],
}

/// `fbd inverse`: the forces the state and `[inverse]` accelerations need.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct RobotInverseReport {
    /// The robot's name.
    pub robot: String,
    /// External force the root needs (N, inertial); zero for a motion the
    /// robot makes on its own in flight.
    pub base_force: [f64; 3],
    /// External moment the root needs about its frame's origin (N·m).
    pub base_moment: [f64; 3],
    /// Every joint's force, moment and torque.
    pub joints: Vec<JointInverse>,
}

impl LoadedRobot {
    /// Inverse dynamics by the FBD method ([`fbd_dynamics::tree`]).
    pub fn inverse(&self) -> RobotInverseReport {
        use fbd_robot::nalgebra::Vector3;
        let v = |x: Vector3<f64>| [x.x, x.y, x.z];
        let (acc, alpha, qdd) = &self.acceleration;
        let motion = fbd_dynamics::tree::TreeMotion {
            base: self.base,
            velocity: Vector3::from(self.velocity),
            omega: Vector3::from(self.omega),
            acceleration: Vector3::from(*acc),
            alpha: Vector3::from(*alpha),
            q: self.q.clone(),
            qd: self.qd.clone(),
            qdd: qdd.clone(),
        };
        let mut data = fbd_dynamics::tree::TreeData::new(&self.model);
        fbd_dynamics::tree::inverse(
            &self.model,
            &motion,
            Vector3::new(0.0, -self.gravity, 0.0),
            &mut data,
        );
        RobotInverseReport {
            robot: self.model.name.clone(),
            base_force: v(data.base_force),
            base_moment: v(data.base_moment),
            joints: (0..self.model.joints.len())
                .map(|j| JointInverse {
                    name: self.model.joints[j].name.clone(),
                    force: v(data.force[j]),
                    moment: v(data.moment[j]),
                    torque: data.torque[j],
                    constraint_moment: v(data.constraint_moment(j)),
                })
                .collect(),
        }
    }
}

/// The hexapod of `p` as a generic [`RobotModel`], built from its D-H
/// parameters ([`fbd_robot::dh::hexapod`]): the same geometry, masses,
/// inertias, legs, joint limits and contact points.
pub fn hexapod_robot(p: &fbd_sim::spatial::SpatialParams) -> RobotModel {
    p.robot_model()
}

/// A recorded motion of an imported robot (`fbd inverse --motion`): times,
/// root poses and joint angles, one row per sample.
#[derive(Clone, Debug, PartialEq)]
pub struct Motion {
    /// Sample times (s), uniformly spaced.
    pub t: Vec<f64>,
    /// The root's `(position, φ)` per sample (m, rad).
    pub base: Vec<([f64; 3], [f64; 3])>,
    /// Joint angles per sample (rad), the model's joint order.
    pub q: Vec<Vec<f64>>,
}

/// The base columns a motion may have (`trajectory.csv`'s names): `rx, ry,
/// rz` (m) and `phi_x, phi_y, phi_z` (rad).
pub const MOTION_BASE_COLUMNS: [&str; 6] = ["rx", "ry", "rz", "phi_x", "phi_y", "phi_z"];

impl LoadedRobot {
    /// Reads a motion from CSV `text` (named `file` in errors): a header
    /// with `t` and one column per joint (rad, by joint name), and
    /// optionally the base columns [`MOTION_BASE_COLUMNS`] (absent ones
    /// stay at the configuration's `[initial]` values); other columns are
    /// ignored. At least three rows, times increasing with one spacing.
    pub fn read_motion(&self, text: &str, file: &str) -> Result<Motion, ConfigError> {
        let bad = |line: usize, message: String| ConfigError::Syntax {
            file: file.to_owned(),
            line,
            col: 1,
            message,
        };
        let mut lines = text
            .lines()
            .enumerate()
            .filter(|(_, l)| !l.trim().is_empty());
        let Some((_, header)) = lines.next() else {
            return Err(bad(1, "an empty motion: expected a header row".to_owned()));
        };
        let names: Vec<&str> = header.split(',').map(str::trim).collect();
        let column = |name: &str| names.iter().position(|n| *n == name);
        let Some(t_col) = column("t") else {
            return Err(bad(1, "no column `t`".to_owned()));
        };
        let mut joint_cols = Vec::with_capacity(self.model.joints.len());
        for joint in &self.model.joints {
            match column(&joint.name) {
                Some(c) => joint_cols.push(c),
                None => {
                    return Err(bad(
                        1,
                        format!(
                            "no column for joint `{}` (one column per joint, rad)",
                            joint.name
                        ),
                    ));
                }
            }
        }
        let base_cols: Vec<Option<usize>> = MOTION_BASE_COLUMNS.iter().map(|n| column(n)).collect();
        let pose0 = {
            let p = self.base.translation.vector;
            let phi = self.initial_phi;
            [p.x, p.y, p.z, phi[0], phi[1], phi[2]]
        };
        let mut m = Motion {
            t: Vec::new(),
            base: Vec::new(),
            q: Vec::new(),
        };
        for (i, line) in lines {
            let values: Vec<&str> = line.split(',').map(str::trim).collect();
            if values.len() != names.len() {
                return Err(bad(
                    i + 1,
                    format!("{} values for {} columns", values.len(), names.len()),
                ));
            }
            let num = |c: usize| {
                values[c]
                    .parse::<f64>()
                    .ok()
                    .filter(|x| x.is_finite())
                    .ok_or_else(|| {
                        bad(
                            i + 1,
                            format!(
                                "column `{}`: `{}` is not a finite number",
                                names[c], values[c]
                            ),
                        )
                    })
            };
            m.t.push(num(t_col)?);
            let mut pose = pose0;
            for (k, c) in base_cols.iter().enumerate() {
                if let Some(c) = c {
                    pose[k] = num(*c)?;
                }
            }
            m.base
                .push(([pose[0], pose[1], pose[2]], [pose[3], pose[4], pose[5]]));
            m.q.push(
                joint_cols
                    .iter()
                    .map(|&c| num(c))
                    .collect::<Result<_, _>>()?,
            );
            let n = m.t.len();
            if n >= 2 {
                let dt = m.t[1] - m.t[0];
                let step = m.t[n - 1] - m.t[n - 2];
                if dt <= 0.0 || dt.is_nan() || (step - dt).abs() > 1e-9 * dt.max(m.t[n - 1].abs()) {
                    return Err(bad(
                        i + 1,
                        format!(
                            "t = {}: samples must be uniformly spaced in time (Δt = {dt} from the first two rows, here {step})",
                            m.t[n - 1]
                        ),
                    ));
                }
            }
        }
        if m.t.len() < 3 {
            return Err(bad(
                1,
                format!("{} rows: central differences need at least 3", m.t.len()),
            ));
        }
        Ok(m)
    }

    /// Inverse dynamics along `motion`: for each interior sample `k`, the
    /// velocities and accelerations by central differences (joint angles
    /// and the root's position: `(x[k+1] − x[k−1])/2Δt`,
    /// `(x[k+1] − 2x[k] + x[k−1])/Δt²`; the root's rotation: `ω` at the
    /// half steps from `log(R[k+1]·R[k]ᵀ)/Δt`, their mean and difference),
    /// then [`fbd_dynamics::tree::inverse`]. The table's columns are
    /// [`Self::inverse_columns`].
    pub fn inverse_along(&self, motion: &Motion) -> Vec<Vec<f64>> {
        use fbd_robot::nalgebra::{Rotation3, Vector3};
        let n = self.model.joints.len();
        let dt = motion.t[1] - motion.t[0];
        let g = Vector3::new(0.0, -self.gravity, 0.0);
        let frame = |k: usize| fbd_robot::forward::base_frame(motion.base[k].0, motion.base[k].1);
        let mut data = fbd_dynamics::tree::TreeData::new(&self.model);
        let mut rows = Vec::with_capacity(motion.t.len().saturating_sub(2));
        for k in 1..motion.t.len() - 1 {
            let (f0, f1, f2) = (frame(k - 1), frame(k), frame(k + 1));
            let (p0, p1, p2) = (
                f0.translation.vector,
                f1.translation.vector,
                f2.translation.vector,
            );
            let half = |a: &fbd_robot::nalgebra::Isometry3<f64>,
                        b: &fbd_robot::nalgebra::Isometry3<f64>| {
                let r: Rotation3<f64> = (b.rotation * a.rotation.inverse()).to_rotation_matrix();
                r.scaled_axis() / dt
            };
            let (w_minus, w_plus) = (half(&f0, &f1), half(&f1, &f2));
            let motion_k = fbd_dynamics::tree::TreeMotion {
                base: f1,
                velocity: (p2 - p0) / (2.0 * dt),
                omega: (w_minus + w_plus) / 2.0,
                acceleration: (p2 - 2.0 * p1 + p0) / (dt * dt),
                alpha: (w_plus - w_minus) / dt,
                q: motion.q[k].clone(),
                qd: (0..n)
                    .map(|j| (motion.q[k + 1][j] - motion.q[k - 1][j]) / (2.0 * dt))
                    .collect(),
                qdd: (0..n)
                    .map(|j| {
                        (motion.q[k + 1][j] - 2.0 * motion.q[k][j] + motion.q[k - 1][j]) / (dt * dt)
                    })
                    .collect(),
            };
            fbd_dynamics::tree::inverse(&self.model, &motion_k, g, &mut data);
            let mut row = Vec::with_capacity(7 + 7 * n);
            row.push(motion.t[k]);
            row.extend(data.base_force.iter());
            row.extend(data.base_moment.iter());
            for j in 0..n {
                row.push(data.torque[j]);
                row.extend(data.force[j].iter());
                row.extend(data.moment[j].iter());
            }
            rows.push(row);
        }
        rows
    }

    /// The columns of [`Self::inverse_along`]: `t`, `base_fx … base_mz`,
    /// then per joint `tau_<joint>`, `<joint>_fx, _fy, _fz` (the parent's
    /// force on the child) and `<joint>_mx, _my, _mz` (its moment about the
    /// joint's origin); inertial frame.
    pub fn inverse_columns(&self) -> Vec<String> {
        let mut c: Vec<String> = [
            "t", "base_fx", "base_fy", "base_fz", "base_mx", "base_my", "base_mz",
        ]
        .iter()
        .map(|s| (*s).to_owned())
        .collect();
        for j in &self.model.joints {
            c.push(format!("tau_{}", j.name));
            for s in ["fx", "fy", "fz", "mx", "my", "mz"] {
                c.push(format!("{}_{s}", j.name));
            }
        }
        c
    }
}

/// How a run of an imported robot ended ([`LoadedRobot::run`]).
#[derive(Clone, Debug)]
pub struct RobotRun {
    /// The engine's summary: steps, Newton iterations, events, retries,
    /// the error (naming the step, time, point or joint and law) if any.
    pub summary: fbd_sim::RunSummary,
    /// Steps planned: `round(duration/Δt) + 1`.
    pub steps_planned: usize,
    /// `q` after the last solved step (m, rad).
    pub final_q: Vec<f64>,
}

impl LoadedRobot {
    /// `q0` and `q̇0` of a run ([`fbd_sim::robot`]): the root's
    /// position and `φ`, then the joint angles; the root's velocity, `φ̇ =
    /// E(φ)⁻¹·ω` ([`crate::spatial::euler_rate_matrix`]; 0 at the
    /// singularity), then the joint rates.
    pub fn flight_state(&self) -> (Vec<f64>, Vec<f64>) {
        use fbd_robot::nalgebra::Vector3;
        let p = self.base.translation.vector;
        let phi = self.initial_phi;
        let phi_dot = crate::spatial::euler_rate_matrix(phi)
            .try_inverse()
            .map(|e| e * Vector3::from(self.omega))
            .unwrap_or_else(Vector3::zeros);
        let mut q0 = vec![p.x, p.y, p.z, phi[0], phi[1], phi[2]];
        q0.extend(&self.q);
        let mut qd0 = self.velocity.to_vec();
        qd0.extend(phi_dot.iter());
        qd0.extend(&self.qd);
        (q0, qd0)
    }

    /// The simulator's parameters of this configuration.
    pub fn params(&self) -> fbd_sim::robot::RobotParams {
        let (q0, qdot0) = self.flight_state();
        let c = &self.config;
        fbd_sim::robot::RobotParams {
            dt: c.time.dt,
            duration: c.time.duration,
            gravity: self.gravity,
            q0,
            qdot0,
            terrain: (c.terrain.kind != crate::TerrainKind::None).then(|| c.terrain.surface()),
            friction: c.terrain.friction(),
            contact: fbd_contact::ContactParams::default(),
            stride: c.output.stride,
            control: self.control.clone(),
            solver: c.solver.settings(),
        }
    }

    /// The simulator of this configuration: the robot on its terrain (no
    /// contact points with `[terrain] kind = "none"`).
    ///
    /// # Errors
    /// A parameter out of its domain, a contact point starting below the
    /// ground ([`fbd_sim::SimError`], naming the key or point).
    pub fn sim(&self) -> Result<fbd_sim::robot::RobotSim, fbd_sim::SimError> {
        fbd_sim::robot::RobotSim::new(&self.model, &self.params())
    }

    /// Simulates the robot from its initial state over `[time]`, handing
    /// every `[output] stride`-th step's record to `on_record`; stops
    /// before the next step once `stop` is set. A failing step ends the
    /// run with its error in the summary; the steps before were handed on.
    ///
    /// # Errors
    /// A parameter out of its domain or a point starting below the ground
    /// ([`Self::sim`]).
    pub fn run(
        &self,
        stop: &std::sync::atomic::AtomicBool,
        on_record: &mut dyn FnMut(&fbd_sim::robot::RobotRecord),
    ) -> Result<RobotRun, fbd_sim::SimError> {
        let sim = self.sim()?;
        Ok(self.run_sim(&sim, stop, on_record))
    }

    /// [`Self::run`] with the simulator built already.
    pub fn run_sim(
        &self,
        sim: &fbd_sim::robot::RobotSim,
        stop: &std::sync::atomic::AtomicBool,
        on_record: &mut dyn FnMut(&fbd_sim::robot::RobotRecord),
    ) -> RobotRun {
        self.run_sim_written(sim, stop, 1, on_record)
    }

    /// [`Self::run_sim`] for a caller that writes every `written`-th record
    /// and only observes the others, which are then made without what
    /// only a written row reads ([`fbd_sim::engine::run::run_in_written`]).
    pub fn run_sim_written(
        &self,
        sim: &fbd_sim::robot::RobotSim,
        stop: &std::sync::atomic::AtomicBool,
        written: usize,
        on_record: &mut dyn FnMut(&fbd_sim::robot::RobotRecord),
    ) -> RobotRun {
        let mut data = fbd_sim::robot::RobotData::new(sim);
        let summary =
            fbd_sim::engine::run::run_in_written(sim, &mut data, stop, written, on_record);
        RobotRun {
            summary,
            steps_planned: sim.steps,
            final_q: data.q,
        }
    }
}

//! # fbd-scenario
//!
//! The TOML configuration of a run (schema, defaults, loading, validation),
//! shared by the `fbd` command line, the Python package and Rust programs.
//!
//! * Every table and key is optional; omitted keys take the built-in default
//!   experiment ([`fbd_sim::PlanarParams::default`], the paper's §6 falling
//!   experiment). Omitted link inertias default to the uniform rod `m·l²/12`
//!   of the configured mass and length.
//! * Unknown keys are errors (`deny_unknown_fields` everywhere).
//! * Angles are degrees in the file and stay degrees in these structs, so
//!   that [`Config::to_toml`] writes back exactly the numbers that were read;
//!   they are converted to radians only by [`PlanarConfig::params`] and
//!   [`HexapodConfig::joints_rad`].
//!
//! ## The API (for the CLI, the Python package and Rust programs)
//!
//! Every entry point returns a complete, validated [`Config`] (defaults
//! filled in by [`Config::resolve`], every key checked by
//! [`Config::validate`]) or one [`ConfigError`]:
//!
//! * [`load`]`(path)` — a file; [`load_with_overrides`]`(path, overrides)`
//!   with dotted-key [`Override`]s applied on top (what a sweep does);
//! * [`parse_str`]`(text, name, overrides)` — TOML text, `name` standing for
//!   the file in errors; an empty text is the built-in default experiment;
//! * [`parse_table`]`(table, name, overrides)` — an in-memory
//!   [`toml::Table`] (e.g. a Python dict converted key by key); errors carry
//!   the key but no line;
//! * [`read_text`]`(path)` — the file reading of [`load`], with the one
//!   wording of a missing file every command uses (`FILE: no such file`).
//!
//! Then [`PlanarConfig::model`] builds the simulator's [`fbd_sim::Model`]
//! (errors: the same [`ConfigError`]), [`PlanarConfig::params`] gives the
//! raw [`fbd_sim::PlanarParams`], [`Config::to_toml`] the complete file
//! (`config.toml`), and [`PlanarConfig::advice`] a hint for a failed run
//! (a time step too large).
//!
//! ## One source of each rule
//!
//! The physical domain of every parameter (positive masses, lengths and
//! Δt, gravity a magnitude, `0 ≤ μD ≤ μS`, stride ≥ 1, terrain values,
//! controller gains) is checked by the simulator, [`fbd_sim::PlanarParams::validate`],
//! whose errors name the `table.key`; this crate calls it (for either model)
//! and adds the file. This crate checks what only the file knows: which keys
//! a terrain kind or controller kind uses, the contact-point list, array
//! lengths, joint ranges per key, and the hexapod's initial state.
//!
//! ## Errors point at the file
//!
//! Loading happens in two phases: the text is deserialized as written
//! (errors carry `file:line:col`, and an unknown key suggests the closest
//! known one), then optional dotted-key [`Override`]s are applied to the
//! parsed [`toml::Table`] one at a time and the result deserialized again
//! (errors name the override).

use std::path::Path;

use fbd_contact::{Friction, Terrain};
use fbd_dynamics::ContactPoints;
pub(crate) use fbd_kinematics::num::{Num, Quote};
use fbd_sim::{Model, PlanarParams, SimError};
use serde::{Deserialize, Serialize};

mod actuation;
mod gait;
pub use gait::{
    DEFAULT_FORWARD_SPEED, DEFAULT_WALK_PERIODS, GaitConfig, GaitKindConfig, STANCE_THETA_DEG,
    SpeedConfig, default_stance,
};
mod advice;
pub mod mjcf;
pub mod robot;
mod terrain_map;
pub use terrain_map::{PatchConfig, read_heights};
mod spatial;
pub use actuation::{ControlConfig, ControlKind, ControlLegConfig, TargetDeg};
pub use spatial::{DynamicsKind, InertiaConfig, PHI_Z_SINGULAR, euler_rate_matrix};

/// Fixed-length arrays of numbers: serde's `[f64; N]` would silently
/// ignore extra elements of a TOML array, so the length is checked here.
mod fixed {
    use serde::de::{Deserialize, Deserializer, Error};

    fn check<E: Error, const N: usize>(v: Vec<f64>) -> Result<[f64; N], E> {
        let len = v.len();
        v.try_into()
            .map_err(|_| E::invalid_length(len, &format!("an array of {N} numbers").as_str()))
    }

    pub fn de<'de, D: Deserializer<'de>, const N: usize>(d: D) -> Result<[f64; N], D::Error> {
        check(Vec::<f64>::deserialize(d)?)
    }

    pub fn opt<'de, D: Deserializer<'de>, const N: usize>(
        d: D,
    ) -> Result<Option<[f64; N]>, D::Error> {
        Option::<Vec<f64>>::deserialize(d)?.map(check).transpose()
    }
}

/// Why a configuration could not be used. Every variant displays as one
/// line that names the file, and where possible the line, column and key.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ConfigError {
    /// The file could not be read as text (missing, a directory, empty, not
    /// UTF-8).
    #[error("{file}: {what}")]
    Unreadable {
        /// The file as given.
        file: String,
        /// What is wrong.
        what: String,
    },
    /// The file exists but reading it failed (permissions, I/O).
    #[error("{file}: cannot read: {what}")]
    Io {
        /// The file as given.
        file: String,
        /// The operating system's message.
        what: String,
    },
    /// TOML syntax, a value of the wrong type, or an unknown key.
    #[error("{file}:{line}:{col}: {message}")]
    Syntax {
        /// The file as given.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column (characters).
        col: usize,
        /// What is wrong, prefixed with the dotted key when known.
        message: String,
    },
    /// A value out of its domain: `message` reads
    /// `<table>.<key>: <what> (got X, expected Y)`.
    #[error("{file}: {message}")]
    Semantic {
        /// The file as given.
        file: String,
        /// `table.key: what (got X, expected Y)`.
        message: String,
    },
    /// A dotted-key override is malformed or does not fit the schema.
    #[error("{file}: override `{key}`: {message}")]
    Override {
        /// The file the override applies to.
        file: String,
        /// The dotted key, e.g. `terrain.mu_static`.
        key: String,
        /// What is wrong.
        message: String,
    },
    /// A robot description (`[robot] urdf` / `mjcf`) cannot be loaded: the
    /// message names its file, line and element.
    #[error(transparent)]
    Robot(Box<fbd_robot::RobotError>),
}

impl From<fbd_robot::RobotError> for ConfigError {
    fn from(e: fbd_robot::RobotError) -> Self {
        ConfigError::Robot(Box::new(e))
    }
}

impl ConfigError {
    /// `true` for operating-system read failures (exit status 4 rather
    /// than 2).
    pub fn is_io(&self) -> bool {
        matches!(self, ConfigError::Io { .. })
    }

    /// `file: key: what (got …, expected …)`, the value quoted through
    /// [`Quote`] (numbers short at any magnitude).
    pub(crate) fn semantic(
        file: &str,
        key: &str,
        what: &str,
        got: impl Quote,
        expected: &str,
    ) -> Self {
        ConfigError::Semantic {
            file: file.to_owned(),
            message: format!("{key}: {what} (got {}, expected {expected})", got.quote()),
        }
    }
}

/// Which model a configuration describes (`model = "planar" | "hexapod"`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ModelKind {
    /// The 7-DOF planar two-leg model (legs 3 and 4 in the X–Y plane).
    #[default]
    Planar,
    /// The 24-DOF hexapod.
    Hexapod,
}

impl ModelKind {
    /// `"planar"` or `"hexapod"`.
    pub fn as_str(self) -> &'static str {
        match self {
            ModelKind::Planar => "planar",
            ModelKind::Hexapod => "hexapod",
        }
    }
}

/// `[time]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TimeConfig {
    /// Time step Δt (s).
    pub dt: f64,
    /// Simulated duration (s).
    pub duration: f64,
}

impl Default for TimeConfig {
    fn default() -> Self {
        let p = PlanarParams::default();
        Self {
            dt: p.dt,
            duration: p.duration,
        }
    }
}

/// `[world]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct WorldConfig {
    /// Gravitational acceleration (m/s²), acting along −Y.
    pub gravity: f64,
}

impl Default for WorldConfig {
    fn default() -> Self {
        Self {
            gravity: PlanarParams::default().gravity,
        }
    }
}

/// `[body]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BodyConfig {
    /// Central body mass (kg).
    pub mass: f64,
    /// Central body inertia (kg·m²): for the planar model one number, the
    /// inertia about Z through the centre of mass; for the hexapod a number
    /// (isotropic) or the tensor ([`InertiaConfig`]). `None` until
    /// [`Config::resolve`]d (planar 0.3; hexapod dynamics the hexagonal
    /// plate of [`fbd_sim::spatial::hexagon_inertia`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub inertia: Option<InertiaConfig>,
    /// Side `L` of the hexagonal body (m); hips at `d = L·cos(π/6)`.
    pub side: f64,
}

impl Default for BodyConfig {
    fn default() -> Self {
        let p = PlanarParams::default();
        Self {
            mass: p.body_mass,
            inertia: None,
            side: p.side,
        }
    }
}

/// `[leg]`: all legs alike.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct LegConfig {
    /// Upper link length `a` (m).
    pub upper_length: f64,
    /// Upper link mass (kg).
    pub upper_mass: f64,
    /// Upper link inertia about its centre of mass (kg·m²); `None` until
    /// [`Config::resolve`]d to the uniform rod `m·a²/12`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub upper_inertia: Option<f64>,
    /// Upper link radius (m, hexapod dynamics): inertia about the link's
    /// own axis `m·r²/2`; `None` until resolved to the default of
    /// [`fbd_sim::spatial::SpatialParams`] there (0.02).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub upper_radius: Option<f64>,
    /// Upper link centre of mass, fraction of `a` from the hip.
    pub upper_com: f64,
    /// Lower link length `c` (m).
    pub lower_length: f64,
    /// Lower link mass (kg).
    pub lower_mass: f64,
    /// Lower link inertia about its centre of mass (kg·m²); `None` until
    /// resolved to `m·c²/12`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lower_inertia: Option<f64>,
    /// Lower link radius (m, hexapod dynamics); `None` until resolved to
    /// the default of [`fbd_sim::spatial::SpatialParams`] there (0.015).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub lower_radius: Option<f64>,
    /// Lower link centre of mass, fraction of `c` from the knee.
    pub lower_com: f64,
    /// θ1 range `[min, max]` (deg, hexapod); `None` until resolved to the
    /// default of [`fbd_sim::JointLimits`], `[−90, 90]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[serde(deserialize_with = "fixed::opt")]
    pub theta1_deg: Option<[f64; 2]>,
    /// θ2 range `[min, max]` (deg); default `[−120, 120]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[serde(deserialize_with = "fixed::opt")]
    pub theta2_deg: Option<[f64; 2]>,
    /// θ3 range `[min, max]` (deg); default `[180, 330]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[serde(deserialize_with = "fixed::opt")]
    pub theta3_deg: Option<[f64; 2]>,
}

impl Default for LegConfig {
    fn default() -> Self {
        let p = PlanarParams::default();
        Self {
            upper_length: p.upper_length,
            upper_mass: p.upper_mass,
            upper_inertia: None,
            upper_radius: None,
            upper_com: p.upper_com,
            lower_length: p.lower_length,
            lower_mass: p.lower_mass,
            lower_inertia: None,
            lower_radius: None,
            lower_com: p.lower_com,
            theta1_deg: None,
            theta2_deg: None,
            theta3_deg: None,
        }
    }
}

impl LegConfig {
    /// The joint-limit keys with their values (deg), defaults filled in.
    pub fn limits_deg(&self) -> [(&'static str, [f64; 2]); 3] {
        let [d1, d2, d3] = fbd_sim::JointLimits::DEFAULT_DEG;
        [
            ("leg.theta1_deg", self.theta1_deg.unwrap_or(d1)),
            ("leg.theta2_deg", self.theta2_deg.unwrap_or(d2)),
            ("leg.theta3_deg", self.theta3_deg.unwrap_or(d3)),
        ]
    }

    /// The joint limits (rad).
    pub fn joint_limits(&self) -> fbd_sim::JointLimits {
        let [t1, t2, t3] = self
            .limits_deg()
            .map(|(_, r)| [r[0].to_radians(), r[1].to_radians()]);
        fbd_sim::JointLimits {
            theta1: t1,
            theta2: t2,
            theta3: t3,
        }
    }

    /// Upper link inertia, the rod default when omitted (kg·m²).
    pub fn upper_inertia(&self) -> f64 {
        self.upper_inertia
            .unwrap_or(self.upper_mass * self.upper_length * self.upper_length / 12.0)
    }

    /// Lower link inertia, the rod default when omitted (kg·m²).
    pub fn lower_inertia(&self) -> f64 {
        self.lower_inertia
            .unwrap_or(self.lower_mass * self.lower_length * self.lower_length / 12.0)
    }
}

/// Ground kinds of `[terrain] kind`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum TerrainKind {
    /// Horizontal ground `y = height`.
    #[default]
    Flat,
    /// No ground: every contact point stays in ST1.
    None,
    /// Inclined plane `y = height + tan(angle_deg)·x`.
    Slope,
    /// Piecewise-linear `points` (or a CSV `file`), flat beyond the ends.
    Profile,
    /// `y = height + amplitude·sin(360°·x/wavelength + phase_deg)`.
    Sine,
    /// Staircase `y = height + step_height·floor(x/step_width)` (risers
    /// smoothed over `fbd_contact::STEP_RAMP`).
    Steps,
    /// A height map read from `file` (PNG, NumPy, CSV or MuJoCo binary)
    /// over `size` centred on `center`.
    Heightfield,
    /// Smooth random ground (`amplitude`, `wavelength`, `seed`).
    Random,
    /// A staircase (`tread`, `riser`, `heading_deg`, `count`, `origin`).
    Stairs,
    /// Stepping stones (`stone`, `gap`, `depth`, `amplitude`, `seed`).
    Stones,
    /// Square pyramids (`amplitude`, `wavelength`).
    Pyramids,
    /// `amplitude·sin(2πx/λ)·sin(2πz/λ)` (`wavelength` λ).
    Sines,
}

/// `[terrain]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct TerrainConfig {
    /// Ground kind.
    pub kind: TerrainKind,
    /// Ground height for `kind = "flat"`, and the reference height of
    /// `slope` (at x = 0), `sine` (mean) and `steps` (step at x = 0) (m).
    pub height: f64,
    /// Slope inclination (degrees, positive rising towards +X).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub angle_deg: Option<f64>,
    /// Profile vertices `[[x, y], ...]` (m), x strictly increasing.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub points: Option<Vec<Vec<f64>>>,
    /// Profile CSV file (`x,y` lines), relative to the configuration file;
    /// replaced by `points` once loaded.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<String>,
    /// Sine amplitude (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub amplitude: Option<f64>,
    /// Sine wavelength (m), > 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub wavelength: Option<f64>,
    /// Sine phase (degrees), default 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub phase_deg: Option<f64>,
    /// Step rise (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub step_height: Option<f64>,
    /// Step run (m), > 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub step_width: Option<f64>,
    /// Static friction coefficient μS.
    pub mu_static: f64,
    /// Dynamic friction coefficient μD (`0 ≤ μD ≤ μS`).
    pub mu_dynamic: f64,
    /// Height map extent `[x, z]` (m): required by `heightfield`, default
    /// `[3, 3]` for the generated kinds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub size: Option<Vec<f64>>,
    /// Height map centre `[x, z]` (m), default `[0, 0]`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub center: Option<Vec<f64>>,
    /// Heights `[min, max]` (m) of black and white (PNG) or of the lowest
    /// and highest sample (MuJoCo binary).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub elevation: Option<Vec<f64>>,
    /// Grid spacing of a generated terrain (m), default 0.01.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub resolution: Option<f64>,
    /// Rounding radius of a generated terrain's edges (m), default 0.01.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub edge_radius: Option<f64>,
    /// Seed of `random` and `stones`, default 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub seed: Option<u64>,
    /// Stair run (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tread: Option<f64>,
    /// Stair rise (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub riser: Option<f64>,
    /// Direction the stairs climb (degrees from +X towards −Z, as a yaw),
    /// default 0.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heading_deg: Option<f64>,
    /// Number of stairs, default 3.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub count: Option<u32>,
    /// A point `[x, z]` of the first riser, default `center`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub origin: Option<Vec<f64>>,
    /// Stepping stone side (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stone: Option<f64>,
    /// Gap between stepping stones (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gap: Option<f64>,
    /// Depth of the gaps between stepping stones (m).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub depth: Option<f64>,
    /// Friction patches `[[terrain.patch]]` (the last listed wins).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub patch: Vec<PatchConfig>,
    /// The height map built from the keys above ([`TerrainConfig::load_map`]).
    #[serde(skip)]
    pub map: Option<fbd_contact::Surface>,
}

impl Default for TerrainConfig {
    fn default() -> Self {
        let p = PlanarParams::default();
        let (kind, height) = match p.terrain {
            Terrain::Flat { height } => (TerrainKind::Flat, height),
            _ => (TerrainKind::None, 0.0),
        };
        Self {
            kind,
            height,
            angle_deg: None,
            points: None,
            file: None,
            amplitude: None,
            wavelength: None,
            phase_deg: None,
            step_height: None,
            step_width: None,
            mu_static: p.friction.mu_static,
            mu_dynamic: p.friction.mu_dynamic,
            size: None,
            center: None,
            elevation: None,
            resolution: None,
            edge_radius: None,
            seed: None,
            tread: None,
            riser: None,
            heading_deg: None,
            count: None,
            origin: None,
            stone: None,
            gap: None,
            depth: None,
            patch: Vec::new(),
            map: None,
        }
    }
}

impl TerrainConfig {
    /// The terrain of the simulator.
    pub fn terrain(&self) -> Terrain {
        if terrain_map::is_map(self.kind) {
            return self.map_section().unwrap_or(Terrain::Flat {
                height: self.height,
            });
        }
        self.terrain_kind()
    }

    /// The friction coefficients of the simulator.
    pub fn friction(&self) -> Friction {
        Friction {
            mu_static: self.mu_static,
            mu_dynamic: self.mu_dynamic,
        }
    }
}

/// A kind of point of every leg that can touch the terrain.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PointKind {
    /// The feet (always on in the paper).
    Tips,
    /// The knees.
    Knees,
    /// The hips.
    Hips,
}

/// `[contact]` (an extension of the paper's model).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ContactConfig {
    /// Which points of every leg can touch the terrain; must include
    /// `"tips"`. Default `["tips", "knees", "hips"]`
    /// (`ContactPoints::default()`).
    pub points: Vec<PointKind>,
}

impl Default for ContactConfig {
    fn default() -> Self {
        let d = ContactPoints::default();
        let kinds = [
            (d.tips, PointKind::Tips),
            (d.knees, PointKind::Knees),
            (d.hips, PointKind::Hips),
        ];
        Self {
            points: kinds.into_iter().filter(|k| k.0).map(|k| k.1).collect(),
        }
    }
}

impl ContactConfig {
    /// The simulator's contact-point switches.
    pub fn contact_points(&self) -> ContactPoints {
        ContactPoints {
            tips: self.points.contains(&PointKind::Tips),
            knees: self.points.contains(&PointKind::Knees),
            hips: self.points.contains(&PointKind::Hips),
        }
    }
}

/// `[solver]`: Newton's settings, for every model (`config.toml` writes
/// both, filled in). An extension of the paper's method, which solves
/// each step by Newton's method without saying how.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverConfig {
    /// How many chord steps in a row may reuse a kept factorisation of
    /// the Jacobian (simplified Newton: a residual and a solve each, where
    /// a full Newton step also factors the Jacobian); `0` is full Newton.
    /// Default 6 (`fbd_sim::DEFAULT_CHORD_STEPS`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub chord_steps: Option<usize>,
    /// The convergence tolerance: every row's residual at most this
    /// fraction of its scale (a force row's: the robot's weight), from
    /// 1e-12 to 1e-9. Default 1e-9 (`fbd_sim::DEFAULT_TOLERANCE`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tolerance: Option<f64>,
}

impl SolverConfig {
    /// The simulator's settings (the defaults where a key is not given).
    pub fn settings(&self) -> fbd_sim::SolverSettings {
        let d = fbd_sim::SolverSettings::default();
        fbd_sim::SolverSettings {
            chord_steps: self.chord_steps.unwrap_or(d.chord_steps),
            tolerance: self.tolerance.unwrap_or(d.tolerance),
        }
    }

    /// Every key filled in with its default.
    pub fn resolve(&mut self) {
        let s = self.settings();
        self.chord_steps = Some(s.chord_steps);
        self.tolerance = Some(s.tolerance);
    }
}

/// `[output]`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct OutputConfig {
    /// Write every `stride`-th step to `trajectory.csv`.
    pub stride: usize,
    /// The trajectory's file format: `"csv"` (default, `trajectory.csv`)
    /// or `"parquet"` (`trajectory.parquet`, the same columns).
    pub format: OutputFormat,
    /// Write `viewer.html` (default true; `fbd sweep` sets it false in its
    /// runs unless `--viewer`).
    pub viewer: bool,
    /// Write the plots (`*.svg`; default true; `fbd sweep` sets it false in
    /// its runs unless `--plots`).
    pub plots: bool,
}

impl Default for OutputConfig {
    fn default() -> Self {
        Self {
            stride: PlanarParams::default().stride,
            format: OutputFormat::Csv,
            viewer: true,
            plots: true,
        }
    }
}

/// `[output] format`: the file the trajectory is written to.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum OutputFormat {
    /// `trajectory.csv`: text, one row per written step (the contract's
    /// file; default).
    #[default]
    Csv,
    /// `trajectory.parquet`: the same columns in Apache Parquet (numbers
    /// as float64, states as strings, `newton_iterations` as int64).
    Parquet,
}

impl OutputFormat {
    /// The trajectory's file name in this format.
    pub fn trajectory_file(self) -> &'static str {
        match self {
            Self::Csv => "trajectory.csv",
            Self::Parquet => "trajectory.parquet",
        }
    }
}

/// `[initial.leg3]` / `[initial.leg4]` of the planar model.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlanarLegInitial {
    /// `(θ2, θ3)` (deg); `None` until resolved to the leg's default.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[serde(deserialize_with = "fixed::opt")]
    pub theta_deg: Option<[f64; 2]>,
    /// `(θ̇2, θ̇3)` (deg/s); `None` until resolved to zero.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[serde(deserialize_with = "fixed::opt")]
    pub rate_deg: Option<[f64; 2]>,
}

/// Default `(θ2, θ3)` of legs 3 and 4 (deg): the paper's §6 table.
pub const PLANAR_THETA_DEG: [[f64; 2]; 2] = [[0.0, 245.0], [0.0, 255.0]];

/// `[initial]` of the planar model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct PlanarInitial {
    /// `(Rx, Ry)` (m).
    #[serde(deserialize_with = "fixed::de")]
    pub position: [f64; 2],
    /// `(Ṙx, Ṙy)` (m/s).
    #[serde(deserialize_with = "fixed::de")]
    pub velocity: [f64; 2],
    /// φz (deg).
    pub phi_z_deg: f64,
    /// φ̇z (deg/s).
    pub omega_z_deg: f64,
    /// Drop height (m, optional): when given, `Ry` (`position[1]`) is
    /// replaced by the height that puts the lowest contact point this far
    /// above the terrain, whatever the pose.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub drop_height: Option<f64>,
    /// Leg 3 (middle-left).
    pub leg3: PlanarLegInitial,
    /// Leg 4 (middle-right).
    pub leg4: PlanarLegInitial,
}

impl Default for PlanarInitial {
    fn default() -> Self {
        let p = PlanarParams::default();
        Self {
            position: [p.q0[0], p.q0[1]],
            velocity: [p.qdot0[0], p.qdot0[1]],
            phi_z_deg: 0.0,
            omega_z_deg: 0.0,
            drop_height: None,
            leg3: PlanarLegInitial::default(),
            leg4: PlanarLegInitial::default(),
        }
    }
}

impl PlanarInitial {
    /// `(θ2, θ3)` of leg 3 (`leg = 0`) or leg 4 (`leg = 1`), deg.
    pub fn theta_deg(&self, leg: usize) -> [f64; 2] {
        let l = if leg == 0 { &self.leg3 } else { &self.leg4 };
        l.theta_deg.unwrap_or(PLANAR_THETA_DEG[leg])
    }

    /// `(θ̇2, θ̇3)` of leg 3 (`leg = 0`) or leg 4 (`leg = 1`), deg/s.
    pub fn rate_deg(&self, leg: usize) -> [f64; 2] {
        let l = if leg == 0 { &self.leg3 } else { &self.leg4 };
        l.rate_deg.unwrap_or([0.0; 2])
    }
}

/// `[initial.legN]` of the hexapod model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HexapodLegInitial {
    /// `(θ1, θ2, θ3)` (deg).
    #[serde(deserialize_with = "fixed::de")]
    pub theta_deg: [f64; 3],
    /// `(θ̇1, θ̇2, θ̇3)` (deg/s).
    #[serde(deserialize_with = "fixed::de")]
    pub rate_deg: [f64; 3],
}

impl Default for HexapodLegInitial {
    /// The paper's leg-3 pose: `(0°, 0°, 245°)`, at rest.
    fn default() -> Self {
        Self {
            theta_deg: [0.0, 0.0, 245.0],
            rate_deg: [0.0; 3],
        }
    }
}

/// `[initial]` of the hexapod model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct HexapodInitial {
    /// `(Rx, Ry, Rz)` (m).
    #[serde(deserialize_with = "fixed::de")]
    pub position: [f64; 3],
    /// `(Ṙx, Ṙy, Ṙz)` (m/s).
    #[serde(deserialize_with = "fixed::de")]
    pub velocity: [f64; 3],
    /// `(φx, φy, φz)` (deg).
    #[serde(deserialize_with = "fixed::de")]
    pub phi_deg: [f64; 3],
    /// `(ωx, ωy, ωz)` (deg/s): the body's angular velocity in the
    /// inertial frame (3D dynamics; `φ̇ = E(φ)⁻¹·ω`, [`euler_rate_matrix`]).
    #[serde(deserialize_with = "fixed::de")]
    pub omega_deg: [f64; 3],
    /// Leg 1 (front-left).
    pub leg1: HexapodLegInitial,
    /// Leg 2 (front-right).
    pub leg2: HexapodLegInitial,
    /// Leg 3 (middle-left).
    pub leg3: HexapodLegInitial,
    /// Leg 4 (middle-right).
    pub leg4: HexapodLegInitial,
    /// Leg 5 (rear-left).
    pub leg5: HexapodLegInitial,
    /// Leg 6 (rear-right).
    pub leg6: HexapodLegInitial,
}

impl Default for HexapodInitial {
    fn default() -> Self {
        Self {
            position: [0.0, 0.6, 0.0],
            velocity: [0.0; 3],
            phi_deg: [0.0; 3],
            omega_deg: [0.0; 3],
            leg1: HexapodLegInitial::default(),
            leg2: HexapodLegInitial::default(),
            leg3: HexapodLegInitial::default(),
            leg4: HexapodLegInitial::default(),
            leg5: HexapodLegInitial::default(),
            leg6: HexapodLegInitial::default(),
        }
    }
}

impl HexapodInitial {
    /// The six leg tables, indexed by leg number − 1.
    pub fn legs(&self) -> [&HexapodLegInitial; 6] {
        [
            &self.leg1, &self.leg2, &self.leg3, &self.leg4, &self.leg5, &self.leg6,
        ]
    }
}

/// A whole configuration file; `I` is the model's `[initial]` table.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ConfigFile<I> {
    /// `"planar"` or `"hexapod"`.
    #[serde(default)]
    pub model: ModelKind,
    /// `dynamics = "fbd" | "kinematic"` (hexapod): overrides the dispatch
    /// rule of [`HexapodConfig::is_dynamic`]; resolved for every hexapod.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub dynamics: Option<DynamicsKind>,
    /// `legs = [3, 4]` (hexapod dynamics): the leg numbers of the model,
    /// increasing; all six by default.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub legs: Option<Vec<usize>>,
    /// `[time]`.
    #[serde(default)]
    pub time: TimeConfig,
    /// `[world]`.
    #[serde(default)]
    pub world: WorldConfig,
    /// `[body]`.
    #[serde(default)]
    pub body: BodyConfig,
    /// `[leg]`.
    #[serde(default)]
    pub leg: LegConfig,
    /// `[initial]`.
    #[serde(default)]
    pub initial: I,
    /// `[terrain]`.
    #[serde(default)]
    pub terrain: TerrainConfig,
    /// `[contact]`.
    #[serde(default)]
    pub contact: ContactConfig,
    /// `[output]`.
    #[serde(default)]
    pub output: OutputConfig,
    /// `[solver]`: Newton's settings.
    #[serde(default)]
    pub solver: SolverConfig,
    /// `[control]`: the joint controller (planar model, hexapod dynamics).
    #[serde(default)]
    pub control: ControlConfig,
    /// `[gait]` (hexapod model): the kinematic gait, run kinematically, or
    /// tracked by the dynamics with `[control] kind = "gait"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub gait: Option<GaitConfig>,
}

/// A planar configuration.
pub type PlanarConfig = ConfigFile<PlanarInitial>;
/// A hexapod configuration.
pub type HexapodConfig = ConfigFile<HexapodInitial>;

impl Default for PlanarConfig {
    /// The built-in default experiment, every key filled in.
    fn default() -> Self {
        let mut c = Self {
            model: ModelKind::Planar,
            dynamics: None,
            legs: None,
            time: TimeConfig::default(),
            world: WorldConfig::default(),
            body: BodyConfig::default(),
            leg: LegConfig::default(),
            initial: PlanarInitial::default(),
            terrain: TerrainConfig::default(),
            contact: ContactConfig::default(),
            output: OutputConfig::default(),
            solver: SolverConfig::default(),
            control: ControlConfig::default(),
            gait: None,
        };
        c.resolve_common();
        c.resolve_initial();
        c
    }
}

impl<I> ConfigFile<I> {
    fn resolve_common(&mut self) {
        self.body
            .inertia
            .get_or_insert(InertiaConfig::Scalar(PlanarParams::default().body_inertia));
        self.leg.upper_inertia = Some(self.leg.upper_inertia());
        self.leg.lower_inertia = Some(self.leg.lower_inertia());
        let [t1, t2, t3] = self.leg.limits_deg().map(|(_, r)| Some(r));
        self.leg.theta1_deg = t1;
        self.leg.theta2_deg = t2;
        self.leg.theta3_deg = t3;
        let mut points = self.contact.points.clone();
        points.sort();
        points.dedup();
        self.contact.points = points;
        self.terrain.resolve_kind();
        self.solver.resolve();
    }

    /// The simulator's parameters of the tables every model shares
    /// (`[time]`, `[world]`, `[body]`, `[leg]`, `[terrain]`, `[contact]`,
    /// `[output]`), with the default initial state and no control.
    pub fn shared_params(&self) -> PlanarParams {
        PlanarParams {
            dt: self.time.dt,
            duration: self.time.duration,
            gravity: self.world.gravity,
            body_mass: self.body.mass,
            body_inertia: self
                .body
                .inertia
                .as_ref()
                .map_or(PlanarParams::default().body_inertia, InertiaConfig::about_z),
            side: self.body.side,
            upper_length: self.leg.upper_length,
            upper_mass: self.leg.upper_mass,
            upper_inertia: self.leg.upper_inertia(),
            upper_com: self.leg.upper_com,
            lower_length: self.leg.lower_length,
            lower_mass: self.leg.lower_mass,
            lower_inertia: self.leg.lower_inertia(),
            lower_com: self.leg.lower_com,
            joint_limits: self.leg.joint_limits(),
            terrain: self.terrain.terrain(),
            friction: self.terrain.friction(),
            patches: self.terrain.patches("").unwrap_or_default(),
            contact_points: self.contact.contact_points(),
            stride: self.output.stride,
            solver: self.solver.settings(),
            ..PlanarParams::default()
        }
    }

    /// Checks the keys every model shares; errors name `table.key`.
    pub fn validate_common(&self, file: &str) -> Result<(), ConfigError> {
        let err = |key: &str, what: &str, got: &dyn Quote, expected: &str| {
            Err(ConfigError::semantic(file, key, what, got, expected))
        };
        for (key, [lo, hi]) in self.leg.limits_deg() {
            if !(lo.is_finite() && hi.is_finite() && lo < hi) {
                return err(
                    key,
                    "must be a finite range [min, max] with min < max",
                    &format!("[{}, {}]", Num(lo), Num(hi)),
                    "finite degrees, min < max",
                );
            }
        }
        // Checked for every kind: `nan`/`inf` are rejected everywhere, even
        // where the value is unused (it is written back to config.toml).
        if !self.terrain.height.is_finite() {
            return err(
                "terrain.height",
                "must be finite",
                &self.terrain.height,
                "a finite value",
            );
        }
        self.terrain.validate_kind(file)?;
        self.terrain.patches(file)?;
        // The physical domains (positive masses, lengths and time step,
        // gravity a magnitude, 0 ≤ μD ≤ μS, stride ≥ 1, …) have one source,
        // the simulator's parameter check; the file is added here.
        self.shared_params()
            .validate()
            .map_err(|e| ConfigError::Semantic {
                file: file.to_owned(),
                message: e.to_string(),
            })?;
        if !self.contact.points.contains(&PointKind::Tips) {
            let got = format!(
                "{:?}",
                self.contact
                    .points
                    .iter()
                    .map(|p| point_name(*p))
                    .collect::<Vec<_>>()
            );
            return err(
                "contact.points",
                "must include the tips",
                &got,
                "a list containing \"tips\"",
            );
        }
        Ok(())
    }
}

fn point_name(p: PointKind) -> &'static str {
    match p {
        PointKind::Tips => "tips",
        PointKind::Knees => "knees",
        PointKind::Hips => "hips",
    }
}

fn check_finite(file: &str, key: &str, values: &[f64]) -> Result<(), ConfigError> {
    for v in values {
        if !v.is_finite() {
            let got = if values.len() == 1 {
                v.to_string()
            } else {
                format!("{values:?}")
            };
            return Err(ConfigError::semantic(
                file,
                key,
                "must be finite",
                got,
                "finite values",
            ));
        }
    }
    Ok(())
}

impl PlanarConfig {
    fn resolve_initial(&mut self) {
        for leg in 0..2 {
            let (theta, rate) = (self.initial.theta_deg(leg), self.initial.rate_deg(leg));
            let l = if leg == 0 {
                &mut self.initial.leg3
            } else {
                &mut self.initial.leg4
            };
            l.theta_deg = Some(theta);
            l.rate_deg = Some(rate);
        }
        let initial = [self.initial.theta_deg(0), self.initial.theta_deg(1)];
        self.control.resolve(initial);
        if let Some(h) = self.initial.drop_height {
            let mut p = self.params();
            p.set_drop_height(h);
            self.initial.position[1] = p.q0[1];
        }
    }

    /// Checks every key, in the file's units (degrees for `*_deg` keys).
    /// The dynamic model may still reject the configuration (e.g. a tip
    /// below the terrain): see [`PlanarConfig::model`].
    pub fn validate(&self, file: &str) -> Result<(), ConfigError> {
        spatial::reject_hexapod_keys(self, file)?;
        self.validate_common(file)?;
        let i = &self.initial;
        check_finite(file, "initial.position", &i.position)?;
        check_finite(file, "initial.velocity", &i.velocity)?;
        check_finite(file, "initial.phi_z_deg", &[i.phi_z_deg])?;
        check_finite(file, "initial.omega_z_deg", &[i.omega_z_deg])?;
        if let Some(h) = i.drop_height
            && !(h.is_finite() && h >= 0.0)
        {
            return Err(ConfigError::semantic(
                file,
                "initial.drop_height",
                "must be finite and ≥ 0",
                h,
                "a height ≥ 0 (m)",
            ));
        }
        if self.gait.is_some() {
            return Err(ConfigError::semantic(
                file,
                "gait",
                "the kinematic gait is for the hexapod",
                "a [gait] table",
                "model = \"hexapod\"",
            ));
        }
        for (leg, name) in [(0, "leg3"), (1, "leg4")] {
            check_finite(
                file,
                &format!("initial.{name}.theta_deg"),
                &i.theta_deg(leg),
            )?;
            check_finite(file, &format!("initial.{name}.rate_deg"), &i.rate_deg(leg))?;
        }
        self.control.control(file)?;
        Ok(())
    }

    /// The simulator's parameters (SI units, radians).
    pub fn params(&self) -> PlanarParams {
        let i = &self.initial;
        let [t3, t4] = [i.theta_deg(0), i.theta_deg(1)];
        let [r3, r4] = [i.rate_deg(0), i.rate_deg(1)];
        PlanarParams {
            q0: [
                i.position[0],
                i.position[1],
                i.phi_z_deg.to_radians(),
                t3[0].to_radians(),
                t3[1].to_radians(),
                t4[0].to_radians(),
                t4[1].to_radians(),
            ],
            qdot0: [
                i.velocity[0],
                i.velocity[1],
                i.omega_z_deg.to_radians(),
                r3[0].to_radians(),
                r3[1].to_radians(),
                r4[0].to_radians(),
                r4[1].to_radians(),
            ],
            control: self.control.control("").unwrap_or_default(),
            ..self.shared_params()
        }
    }

    /// Validates and builds the dynamic model; errors name `table.key`
    /// (prefixed with `file`).
    pub fn model(&self, file: &str) -> Result<Model, ConfigError> {
        self.validate(file)?;
        Model::planar(&self.params()).map_err(|e: SimError| ConfigError::Semantic {
            file: file.to_owned(),
            message: e.to_string(),
        })
    }
}

impl HexapodConfig {
    /// Checks every key, in the file's units, for the run the dispatch
    /// rule chooses ([`HexapodConfig::is_dynamic`]).
    pub fn validate(&self, file: &str) -> Result<(), ConfigError> {
        self.validate_dispatch(file)?;
        self.validate_common(file)?;
        let i = &self.initial;
        check_finite(file, "initial.position", &i.position)?;
        check_finite(file, "initial.velocity", &i.velocity)?;
        check_finite(file, "initial.phi_deg", &i.phi_deg)?;
        check_finite(file, "initial.omega_deg", &i.omega_deg)?;
        for (n, l) in i.legs().iter().enumerate() {
            check_finite(
                file,
                &format!("initial.leg{}.theta_deg", n + 1),
                &l.theta_deg,
            )?;
            check_finite(file, &format!("initial.leg{}.rate_deg", n + 1), &l.rate_deg)?;
        }
        if let Some(g) = &self.gait {
            g.validate(file)?;
            g.validate_swing(file, self.time.dt)?;
        }
        Ok(())
    }

    /// `(θ1, θ2, θ3)` of every leg in radians, indexed by leg number − 1.
    pub fn joints_rad(&self) -> [[f64; 3]; 6] {
        self.initial
            .legs()
            .map(|l| l.theta_deg.map(f64::to_radians))
    }

    /// `(φx, φy, φz)` in radians.
    pub fn phi_rad(&self) -> [f64; 3] {
        self.initial.phi_deg.map(f64::to_radians)
    }
}

/// A configuration of either model.
#[derive(Clone, Debug, PartialEq)]
pub enum Config {
    /// `model = "planar"` (or no `model` key).
    Planar(Box<PlanarConfig>),
    /// `model = "hexapod"`.
    Hexapod(Box<HexapodConfig>),
}

impl Default for Config {
    /// The built-in default experiment.
    fn default() -> Self {
        Config::Planar(Box::default())
    }
}

const HEADER: &str = "\
# The complete configuration of an fbd run: every key with the value used.
# `fbd run` of this file repeats the run exactly.
";

impl Config {
    /// The model kind.
    pub fn model(&self) -> ModelKind {
        match self {
            Config::Planar(_) => ModelKind::Planar,
            Config::Hexapod(_) => ModelKind::Hexapod,
        }
    }

    /// Fills every omitted key with its default value (inertias, leg
    /// angles) and normalises the contact-point list.
    pub fn resolve(&mut self) {
        match self {
            Config::Planar(c) => {
                c.model = ModelKind::Planar;
                c.resolve_common();
                c.resolve_initial();
            }
            Config::Hexapod(c) => {
                c.model = ModelKind::Hexapod;
                c.resolve_dynamics();
                c.resolve_common();
                let duration = c.time.duration;
                if let Some(g) = &mut c.gait {
                    g.resolve(duration);
                }
            }
        }
    }

    /// Checks every key; errors name the file and `table.key`.
    pub fn validate(&self, file: &str) -> Result<(), ConfigError> {
        match self {
            Config::Planar(c) => c.validate(file),
            Config::Hexapod(c) => c.validate(file),
        }
    }

    /// The complete configuration as TOML: every key with its value, floats
    /// written so that they read back bit-identical.
    pub fn to_toml(&self) -> String {
        let mut c = self.clone();
        c.resolve();
        let body = match &c {
            Config::Planar(p) => toml::to_string(p),
            Config::Hexapod(h) => toml::to_string(h),
        };
        // Serializing plain structs of numbers, strings and arrays cannot
        // fail; keep a readable fallback rather than a panic.
        let body = body.unwrap_or_else(|e| format!("# serialization failed: {e}\n"));
        let body = spatial::drop_absent_legs(&c, body);
        format!("{HEADER}{body}")
    }
}

/// One dotted-key override, e.g. `terrain.mu_static = 0.5`, applied on top
/// of a file by [`load_with_overrides`] / [`parse_str`].
#[derive(Clone, Debug, PartialEq)]
pub struct Override {
    /// Dotted key, e.g. `initial.leg3.theta_deg`.
    pub key: String,
    /// The TOML value to set.
    pub value: toml::Value,
}

impl Override {
    /// An override of `key` with `value`.
    pub fn new(key: impl Into<String>, value: impl Into<toml::Value>) -> Self {
        Self {
            key: key.into(),
            value: value.into(),
        }
    }

    /// Parses `KEY=VALUE` where VALUE is a TOML value (`0.5`, `[0.0, 0.6]`,
    /// `"flat"`); a VALUE that is not valid TOML is taken as a string.
    pub fn parse(spec: &str) -> Result<Self, String> {
        let (key, value) = spec
            .split_once('=')
            .ok_or_else(|| format!("`{spec}`: expected KEY=VALUE"))?;
        let key = key.trim();
        if key.is_empty() || key.split('.').any(|s| s.trim().is_empty()) {
            return Err(format!(
                "`{spec}`: expected a dotted key such as terrain.mu_static"
            ));
        }
        let value = value.trim();
        let value = match format!("v = {value}").parse::<toml::Table>() {
            Ok(mut t) => t
                .remove("v")
                .unwrap_or_else(|| toml::Value::String(value.to_owned())),
            Err(_) => toml::Value::String(value.to_owned()),
        };
        Ok(Self {
            key: key.split('.').map(str::trim).collect::<Vec<_>>().join("."),
            value,
        })
    }
}

/// Sets the dotted `key` of `table` to `value`, creating intermediate
/// tables. Fails when an intermediate key holds a non-table value.
pub fn apply_override(
    table: &mut toml::Table,
    key: &str,
    value: toml::Value,
) -> Result<(), String> {
    let mut parts: Vec<&str> = key.split('.').collect();
    let last = parts.pop().unwrap_or_default();
    let mut cur = table;
    let mut path = String::new();
    for p in parts {
        if !path.is_empty() {
            path.push('.');
        }
        path.push_str(p);
        let entry = cur
            .entry(p.to_owned())
            .or_insert_with(|| toml::Value::Table(toml::Table::new()));
        cur = match entry {
            toml::Value::Table(t) => t,
            other => return Err(format!("`{path}` is a {}, not a table", other.type_str())),
        };
    }
    cur.insert(last.to_owned(), value);
    Ok(())
}

fn line_col(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let mut start = offset;
    while !text.is_char_boundary(start) {
        start -= 1;
    }
    let before = &text[..start];
    let line = before.matches('\n').count() + 1;
    let line_start = before.rfind('\n').map_or(0, |i| i + 1);
    let col = before[line_start..].chars().count() + 1;
    (line, col)
}

/// The message of a toml error, prefixed with the dotted key it concerns
/// (when toml knows it and the message does not already say it).
fn describe(err: &toml::de::Error) -> String {
    // serde names Rust types (`expected f64`): say what the file needs.
    let message = short_float(&describe_key(err))
        .replace("expected f64", "expected a number")
        .replace("expected usize", "expected a whole number")
        .replace("expected u64", "expected a whole number")
        .replace("expected u32", "expected a whole number");
    match suggestion(&message) {
        // `table: unknown field `x`, did you mean `y`? expected one of …`
        Some(hint) => message.replacen(", expected", &format!(", {hint}expected"), 1),
        None => message,
    }
}

/// serde quotes a number of the wrong type with every digit (`invalid
/// type: floating point `1000…000.0``, 310 characters for `1e308`):
/// short, as every message quotes numbers ([`fbd_kinematics::num::Num`]).
fn short_float(message: &str) -> String {
    const TAG: &str = "floating point `";
    let Some(start) = message.find(TAG).map(|i| i + TAG.len()) else {
        return message.to_owned();
    };
    let Some(len) = message[start..].find('`') else {
        return message.to_owned();
    };
    match message[start..start + len].parse::<f64>() {
        Ok(x) if len > 20 => format!(
            "{}{}{}",
            &message[..start],
            fbd_kinematics::num::Num(x),
            &message[start + len..]
        ),
        _ => message.to_owned(),
    }
}

fn describe_key(err: &toml::de::Error) -> String {
    let message = err.message().trim().replace('\n', "; ");
    let mut plain = err.clone();
    plain.set_input(None);
    let rendered = plain.to_string();
    let keys = rendered
        .lines()
        .rev()
        .find_map(|l| l.strip_prefix("in `").and_then(|l| l.strip_suffix('`')));
    match keys {
        Some(k) if !k.is_empty() => format!("{k}: {message}"),
        _ => message,
    }
}

/// `unknown field `x`, expected one of `a`, `b`` → `did you mean `a`?`
/// when one of the expected keys is close to the unknown one.
fn suggestion(message: &str) -> Option<String> {
    let rest = message.split("unknown field `").nth(1)?;
    let (unknown, rest) = rest.split_once('`')?;
    let expected = rest.split_once("expected")?.1;
    expected
        .split('`')
        .skip(1)
        .step_by(2)
        .map(|k| (strsim::damerau_levenshtein(unknown, k), k))
        .filter(|&(d, k)| d <= 2.max(k.len() / 3))
        .min()
        .map(|(_, k)| format!("did you mean `{k}`? "))
}

/// A TOML error of `file` (its `text`) as the loader reports it:
/// `file:line:col: key: message`, serde's Rust types said in the file's
/// terms (`expected a whole number`), a close key suggested, numbers
/// short. The sweep files' errors too.
pub fn syntax_error(file: &str, text: &str, err: &toml::de::Error) -> ConfigError {
    let (line, col) = err.span().map_or((1, 1), |s| line_col(text, s.start));
    let mut message = describe(err);
    // toml names no key for some errors (e.g. "duplicate key"): quote the
    // offending text when it is a short single-line snippet.
    if !message.contains('`')
        && !message.contains(": ")
        && let Some(snippet) = err
            .span()
            .and_then(|s| text.get(s))
            .map(str::trim)
            .filter(|s| !s.is_empty() && s.len() <= 60 && !s.contains('\n'))
    {
        message.push_str(&format!(" (at `{snippet}`)"));
    }
    ConfigError::Syntax {
        file: file.to_owned(),
        line,
        col,
        message,
    }
}

fn model_of(table: &toml::Table) -> ModelKind {
    match table.get("model") {
        Some(toml::Value::String(s)) if s == "hexapod" => ModelKind::Hexapod,
        _ => ModelKind::Planar,
    }
}

/// The error for `model = "robot"` where a configuration of the paper's
/// models is needed (every caller of [`parse_str`] / [`parse_table`],
/// which build a [`Config`]); imported robots load through
/// [`robot::load_str`] in the commands and functions that take them.
fn robot_not_yet(table: &toml::Table, file: &str) -> Result<(), ConfigError> {
    match table.get("model") {
        Some(toml::Value::String(s)) if s == robot::MODEL => Err(ConfigError::Semantic {
            file: file.to_owned(),
            message: "model = \"robot\": an imported URDF/MJCF robot works with the \
                      commands `fbd run` (on the ground or in flight), `fbd sweep`, \
                      `fbd kinematics`, `fbd inverse` and `fbd export mjcf`, and with \
                      Python's fbd.run, fbd.sweep, fbd.Simulator, fbd.kinematics, \
                      fbd.inverse and the Gymnasium environment fbd/Robot-v0; this takes \
                      model = \"planar\" or \"hexapod\""
                .to_owned(),
        }),
        _ => Ok(()),
    }
}

fn from_table(table: &toml::Table) -> Result<Config, toml::de::Error> {
    Ok(match model_of(table) {
        ModelKind::Hexapod => Config::Hexapod(Box::new(table.clone().try_into()?)),
        ModelKind::Planar => Config::Planar(Box::new(table.clone().try_into()?)),
    })
}

/// Loads a `[terrain] file` profile into `points` ([`TerrainConfig::load_profile_file`]).
fn load_profile(config: &mut Config, file: &str) -> Result<(), ConfigError> {
    match config {
        Config::Planar(c) => {
            c.terrain.load_profile_file(file)?;
            c.terrain.load_map(file)
        }
        Config::Hexapod(c) => {
            c.terrain.load_profile_file(file)?;
            c.terrain.load_map(file)
        }
    }
}

/// Parses configuration `text` (named `file` in errors), applies
/// `overrides` in order, fills defaults ([`Config::resolve`]) and validates
/// every key ([`Config::validate`]). An empty `text` is the built-in
/// default experiment (plus the overrides).
pub fn parse_str(text: &str, file: &str, overrides: &[Override]) -> Result<Config, ConfigError> {
    let mut table: toml::Table = toml::from_str(text).map_err(|e| syntax_error(file, text, &e))?;
    robot_not_yet(&table, file)?;
    // Deserialize the text itself so that errors carry its line and column.
    let mut config = match model_of(&table) {
        ModelKind::Hexapod => toml::from_str(text).map(|h| Config::Hexapod(Box::new(h))),
        ModelKind::Planar => toml::from_str(text).map(|p| Config::Planar(Box::new(p))),
    }
    .map_err(|e| syntax_error(file, text, &e))?;
    load_profile(&mut config, file)?;
    for o in overrides {
        let fail = |message: String| ConfigError::Override {
            file: file.to_owned(),
            key: o.key.clone(),
            message,
        };
        apply_override(&mut table, &o.key, o.value.clone()).map_err(fail)?;
        config = from_table(&table).map_err(|e| fail(describe(&e)))?;
        load_profile(&mut config, file)?;
    }
    gait::fill_hexapod_defaults(&mut config, &table, file)?;
    config.resolve();
    config.validate(file)?;
    Ok(config)
}

/// Builds a configuration from an in-memory TOML `table` (e.g. a Python
/// dict converted key by key), named `file` in errors, then applies
/// `overrides`, fills defaults and validates, as [`parse_str`]. A table
/// has no lines: a key or type error is a [`ConfigError::Semantic`] whose
/// message starts with the dotted key (`terrain: unknown field …`).
/// A `[terrain] file` is relative to the working directory.
pub fn parse_table(
    table: &toml::Table,
    file: &str,
    overrides: &[Override],
) -> Result<Config, ConfigError> {
    let mut table = table.clone();
    robot_not_yet(&table, file)?;
    for o in overrides {
        apply_override(&mut table, &o.key, o.value.clone()).map_err(|message| {
            ConfigError::Override {
                file: file.to_owned(),
                key: o.key.clone(),
                message,
            }
        })?;
    }
    let mut config = from_table(&table).map_err(|e| ConfigError::Semantic {
        file: file.to_owned(),
        message: describe(&e),
    })?;
    load_profile(&mut config, file)?;
    gait::fill_hexapod_defaults(&mut config, &table, file)?;
    config.resolve();
    config.validate(file)?;
    Ok(config)
}

/// Reads and parses the configuration file at `path` ([`parse_str`]).
pub fn load(path: &Path) -> Result<Config, ConfigError> {
    load_with_overrides(path, &[])
}

/// Reads the file at `path`, applies `overrides` (dotted keys, e.g. from a
/// sweep) and parses it ([`parse_str`]). An empty file is the built-in
/// default experiment, as a file with some keys is filled from defaults.
pub fn load_with_overrides(path: &Path, overrides: &[Override]) -> Result<Config, ConfigError> {
    let text = read_text(path)?;
    parse_str(&text, &path.display().to_string(), overrides)
}

/// The operating system's message without its `(os error N)` suffix and
/// with a lower-case first letter, as every other message:
/// `No such file or directory (os error 2)` → `no such file or directory`.
pub fn os_message(e: &std::io::Error) -> String {
    let s = e.to_string();
    let s = match s.rfind(" (os error ") {
        Some(i) if s.ends_with(')') => s[..i].to_owned(),
        _ => s,
    };
    let mut c = s.chars();
    match c.next() {
        Some(first) => first.to_lowercase().chain(c).collect(),
        None => s,
    }
}

/// Reads the UTF-8 text file at `path` with the messages every command
/// uses: `FILE: no such file`, `FILE: is a directory, expected a TOML
/// file`, `FILE: is not UTF-8 text (…)`, `FILE: cannot read: …`.
pub fn read_text(path: &Path) -> Result<String, ConfigError> {
    let file = path.display().to_string();
    let unreadable = |what: &str| ConfigError::Unreadable {
        file: file.clone(),
        what: what.to_owned(),
    };
    match std::fs::metadata(path) {
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(unreadable("no such file"));
        }
        Err(e) => {
            return Err(ConfigError::Io {
                file,
                what: os_message(&e),
            });
        }
        Ok(m) if m.is_dir() => {
            return Err(unreadable("is a directory, expected a TOML file"));
        }
        Ok(_) => {}
    }
    let bytes = std::fs::read(path).map_err(|e| ConfigError::Io {
        file: file.clone(),
        what: os_message(&e),
    })?;
    String::from_utf8(bytes).map_err(|e| {
        unreadable(&format!(
            "is not UTF-8 text (invalid byte at offset {})",
            e.utf8_error().valid_up_to()
        ))
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Config, ConfigError> {
        parse_str(text, "c.toml", &[])
    }

    #[test]
    fn default_config_is_the_default_experiment() {
        let Config::Planar(c) = Config::default() else {
            unreachable!()
        };
        assert_eq!(c.params(), PlanarParams::default());
        let Config::Planar(c) = parse("model = \"planar\"\n").unwrap() else {
            unreachable!()
        };
        assert_eq!(c.params(), PlanarParams::default());
    }

    #[test]
    fn complete_config_round_trips() {
        let text = "[leg]\nupper_mass = 0.7\n[initial]\nphi_z_deg = 0.1\n[initial.leg4]\ntheta_deg = [1.3, 250.7]\n[contact]\npoints = [\"knees\", \"tips\"]\n";
        let c = parse(text).unwrap();
        let full = c.to_toml();
        let again = parse_str(&full, "full.toml", &[]).unwrap();
        assert_eq!(c, again);
        assert_eq!(full, again.to_toml());
        let Config::Planar(p) = again else {
            unreachable!()
        };
        assert_eq!(p.leg.upper_inertia, Some(0.7 * 0.2 * 0.2 / 12.0));
        assert_eq!(p.initial.leg3.theta_deg, Some([0.0, 245.0]));
        assert_eq!(p.contact.points, vec![PointKind::Tips, PointKind::Knees]);
    }

    #[test]
    fn unknown_key_has_line_column_and_key() {
        let e = parse("[time]\ndt = 0.01\n\n[body]\nmass = 6.0\nmas = 3\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.toml:6:1: "), "{e}");
        assert!(e.contains("mas"), "{e}");
        let e = parse("[time]\ndt = \"fast\"\n").unwrap_err().to_string();
        assert!(e.starts_with("c.toml:2:6: time.dt: invalid type"), "{e}");
    }

    #[test]
    fn solver_table_is_filled_checked_and_set_by_overrides() {
        // Filled in with the defaults (the effective configuration).
        let full = parse("").unwrap();
        assert!(
            full.to_toml().contains("[solver]\nchord_steps = 6\n"),
            "{}",
            full.to_toml()
        );
        let Config::Planar(c) = full else {
            unreachable!()
        };
        assert_eq!(
            (c.solver.chord_steps, c.solver.tolerance),
            (
                Some(fbd_sim::DEFAULT_CHORD_STEPS),
                Some(fbd_sim::DEFAULT_TOLERANCE)
            )
        );
        // Given, and carried to the simulator's parameters of both models.
        let Config::Planar(c) = parse("[solver]\nchord_steps = 0\ntolerance = 1e-11\n").unwrap()
        else {
            unreachable!()
        };
        assert_eq!(c.params().solver.chord_steps, 0);
        assert_eq!(c.params().solver.tolerance, 1e-11);
        let o = [Override::parse("solver.chord_steps=2").unwrap()];
        let Config::Hexapod(h) = parse_str("model = \"hexapod\"\n", "h.toml", &o).unwrap() else {
            unreachable!()
        };
        assert_eq!(h.spatial_params("h.toml").unwrap().solver.chord_steps, 2);
        // Out of their domains, or misspelt: one line naming the key.
        let e = parse("[solver]\nchord_steps = 101\n")
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "c.toml: solver.chord_steps: is too large (got 101, expected an integer from 0 (full Newton) to 100)"
        );
        let e = parse("[solver]\ntolerance = 1e-6\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.toml: solver.tolerance: "), "{e}");
        let e = parse("[solver]\nchord_steps = -1\n")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("c.toml:2:15: solver.chord_steps: "), "{e}");
        let e = parse("[solver]\nchord = 1\n").unwrap_err().to_string();
        assert!(e.starts_with("c.toml:2:1: ") && e.contains("chord"), "{e}");
    }

    #[test]
    fn semantic_errors_name_table_key() {
        let e = parse("[leg]\nupper_mass = -1.0\n").unwrap_err().to_string();
        assert_eq!(
            e,
            "c.toml: leg.upper_mass: must be positive and finite (got -1, expected a finite value > 0)"
        );
        let e = parse("[initial]\nphi_z_deg = inf\n")
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("initial.phi_z_deg") && e.contains("got inf"),
            "{e}"
        );
    }

    #[test]
    fn overrides_apply_and_name_the_key() {
        let o = [
            Override::parse("terrain.mu_static=0.5").unwrap(),
            Override::parse("initial.position = [0.1, 0.7]").unwrap(),
        ];
        let Config::Planar(c) = parse_str("", "x", &o).unwrap() else {
            unreachable!()
        };
        assert_eq!(c.terrain.mu_static, 0.5);
        // Integers are accepted where floats are expected, in files and
        // overrides alike.
        let o = [Override::parse("time.duration=1").unwrap()];
        let Config::Planar(i) =
            parse_str("[body]\nmass = 6\n[initial]\nposition = [0, 1]\n", "x", &o).unwrap()
        else {
            unreachable!()
        };
        assert_eq!(
            (i.time.duration, i.body.mass, i.initial.position),
            (1.0, 6.0, [0.0, 1.0])
        );
        assert_eq!(c.initial.position, [0.1, 0.7]);
        let e = parse_str(
            "model = \"planar\"",
            "x.toml",
            &[Override::parse("terrain.mu_statc=0.5").unwrap()],
        )
        .unwrap_err()
        .to_string();
        assert!(
            e.starts_with("x.toml: override `terrain.mu_statc`:") && e.contains("unknown field"),
            "{e}"
        );
        let e = parse_str(
            "model = \"planar\"",
            "x.toml",
            &[Override::parse("terrain.mu_dynamic=0.9").unwrap()],
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("terrain.mu_dynamic"), "{e}");
    }

    #[test]
    fn a_table_parses_as_its_text_does() {
        let text = "[time]\ndt = 0.005\n[terrain]\nmu_static = 0.6\n";
        let table: toml::Table = toml::from_str(text).unwrap();
        let o = [Override::parse("body.mass = 7.0").unwrap()];
        assert_eq!(
            parse_table(&table, "<dict>", &o).unwrap(),
            parse_str(text, "t.toml", &o).unwrap()
        );
        let bad: toml::Table = toml::from_str("[terrain]\nmu_statc = 0.6\n").unwrap();
        let e = parse_table(&bad, "<dict>", &[]).unwrap_err().to_string();
        assert!(
            e.starts_with("<dict>: terrain: unknown field `mu_statc`, did you mean `mu_static`?"),
            "{e}"
        );
        let neg: toml::Table = toml::from_str("[world]\ngravity = -1.0\n").unwrap();
        let e = parse_table(&neg, "<dict>", &[]).unwrap_err().to_string();
        assert!(
            e.starts_with("<dict>: world.gravity: is the magnitude"),
            "{e}"
        );
    }

    #[test]
    fn hexapod_parses() {
        let c =
            parse("model = \"hexapod\"\n[initial.leg2]\ntheta_deg = [10.0, 5.0, 250.0]\n").unwrap();
        let Config::Hexapod(h) = c else { panic!() };
        assert_eq!(h.initial.leg2.theta_deg, [10.0, 5.0, 250.0]);
        let c = Config::Hexapod(h);
        let again = parse_str(&c.to_toml(), "full.toml", &[]).unwrap();
        assert_eq!(c, again);
        assert!(parse("model = \"hexapod\"\n[initial]\nphi_z_deg = 1.0\n").is_err());
    }
}

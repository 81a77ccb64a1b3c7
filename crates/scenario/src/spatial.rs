//! The 3D FBD dynamics of a `model = "hexapod"` configuration: which runs
//! are dynamic ([`HexapodConfig::is_dynamic`]), the keys only the dynamics
//! use (`dynamics`, `legs`, a tensor `[body] inertia`, `[leg]
//! upper_radius`/`lower_radius`, `[control]` of six legs), their defaults,
//! validation and the conversion into [`SpatialParams`].
//!
//! ## The dispatch rule
//!
//! A hexapod configuration runs the 3D dynamics unless it is a kinematic
//! gait run: it is kinematic when it has a `[gait]` table and its
//! `[control] kind` is not `"gait"`. The top-level key `dynamics = "fbd"`
//! or `"kinematic"` overrides the rule. [`crate::Config::resolve`] writes
//! the decision back as `dynamics`, so `config.toml` repeats the run.
//!
//! ## Defaults of a dynamic run (those of [`SpatialParams::default`])
//!
//! `[time] dt` 0.001 s; `[body] inertia` the thin hexagonal plate
//! ([`hexagon_inertia`] of the configured mass and side); `[leg]
//! upper_radius` 0.02 m, `lower_radius` 0.015 m, the transverse link
//! inertias those of solid cylinders `m·(3r² + l²)/12`; `legs` all six;
//! `[initial.legN] theta_deg` (0°, 0°, 250°) and, without an `[initial]`
//! table, the body 0.6 m up and level ([`default_q0`]); with `[gait]` (a
//! `kind = "gait"` controller) the kinematic gait's default stance.

use fbd_contact::ContactParams;
use fbd_kinematics::nalgebra::{Matrix3, SymmetricEigen, Vector3};
use fbd_kinematics::pose::{BodyPose, rot_x};
use fbd_sim::Control;
use fbd_sim::spatial::{
    LegTrajectory3, SpatialControl, SpatialModel, SpatialParams, default_q0, hexagon_inertia,
};
use serde::{Deserialize, Serialize};

use crate::{
    Config, ConfigError, ControlKind, ControlLegConfig, HexapodConfig, PlanarConfig, Quote,
    TargetDeg,
};

/// `dynamics = "fbd" | "kinematic"`: how a hexapod configuration runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum DynamicsKind {
    /// The 3D Free Body Diagram dynamics (forces, contacts, control).
    Fbd,
    /// The kinematic gait (joint angles, footholds, stability margin).
    Kinematic,
}

/// `[body] inertia`: one number (kg·m²) — the planar model's inertia
/// about Z, or an isotropic tensor for the hexapod — or the hexapod's
/// tensor about the centre of mass in the body frame, `[Ixx, Iyy, Izz]`
/// (principal) or `[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]` (the matrix entries,
/// MuJoCo's `fullinertia` order).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "expected a number (kg·m²), [Ixx, Iyy, Izz] or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz]"
)]
pub enum InertiaConfig {
    /// One number.
    Scalar(f64),
    /// 3 or 6 components.
    Components(Vec<f64>),
}

impl InertiaConfig {
    /// The inertia about Z (kg·m²): the number, or `Izz`; NaN for a list
    /// of the wrong length (rejected by [`InertiaConfig::tensor`]).
    pub fn about_z(&self) -> f64 {
        match self {
            InertiaConfig::Scalar(s) => *s,
            InertiaConfig::Components(v) => v.get(2).copied().unwrap_or(f64::NAN),
        }
    }

    /// The tensor `[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]` (kg·m²), checked:
    /// finite, symmetric positive definite and its principal moments
    /// satisfying the triangle inequalities (a real body's). Errors name
    /// `body.inertia`.
    pub fn tensor(&self, file: &str) -> Result<[f64; 6], ConfigError> {
        let err = |what: &str, got: String, expected: &str| {
            Err(ConfigError::semantic(
                file,
                "body.inertia",
                what,
                got,
                expected,
            ))
        };
        let t = match self {
            InertiaConfig::Scalar(s) => [*s, *s, *s, 0.0, 0.0, 0.0],
            InertiaConfig::Components(v) if v.len() == 3 => [v[0], v[1], v[2], 0.0, 0.0, 0.0],
            InertiaConfig::Components(v) if v.len() == 6 => [v[0], v[1], v[2], v[3], v[4], v[5]],
            InertiaConfig::Components(v) => {
                return err(
                    "must be a number or 3 or 6 components",
                    format!("{} numbers", v.len()),
                    "[Ixx, Iyy, Izz] or [Ixx, Iyy, Izz, Ixy, Ixz, Iyz] (kg·m²)",
                );
            }
        };
        let got = || match self {
            InertiaConfig::Scalar(s) => s.to_string(),
            InertiaConfig::Components(v) => format!("{v:?}"),
        };
        if !t.iter().all(|v| v.is_finite()) {
            return err("must be finite", got(), "finite values (kg·m²)");
        }
        let m = inertia_matrix(&t);
        let eig = SymmetricEigen::new(m).eigenvalues;
        if eig.iter().any(|&l| l <= 0.0) {
            return err(
                "must be positive definite",
                got(),
                "principal moments > 0 (kg·m²)",
            );
        }
        let (a, b, c) = (eig[0], eig[1], eig[2]);
        // A rigid body's principal moments satisfy I1 + I2 ≥ I3 (equality
        // for a flat body): allow rounding.
        let tol = 1e-9 * (a + b + c);
        if a + b < c - tol || a + c < b - tol || b + c < a - tol {
            return err(
                "its principal moments violate the triangle inequality",
                format!("{} (principal {a:.6}, {b:.6}, {c:.6})", got()),
                "I1 + I2 ≥ I3 for every ordering, as for any rigid body",
            );
        }
        Ok(t)
    }
}

/// The symmetric matrix of `[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]`.
fn inertia_matrix(t: &[f64; 6]) -> Matrix3<f64> {
    Matrix3::new(t[0], t[3], t[4], t[3], t[1], t[5], t[4], t[5], t[2])
}

/// `E(φ)`: the inertial angular velocity of the body is `ω = E(φ)·φ̇`,
/// its columns the axes about which `φx, φy, φz` turn (X, `Rx(φx)·Rz(φz)·Y`,
/// `Rx(φx)·Z`, as `fbd_kinematics::hexapod::HexapodData::phi_axes`).
pub fn euler_rate_matrix(phi: [f64; 3]) -> Matrix3<f64> {
    let ey: Vector3<f64> = BodyPose::new([0.0; 3], phi).rotation().column(1).into();
    let ez = rot_x(phi[0]) * Vector3::z();
    Matrix3::from_columns(&[Vector3::x(), ey, ez])
}

/// Distance (rad) from `φz = ±90°` within which `E(φ)` counts as singular.
pub const PHI_Z_SINGULAR: f64 = 1e-6;

/// All six legs.
const ALL_LEGS: [usize; 6] = [1, 2, 3, 4, 5, 6];

/// The transverse inertia of a solid cylinder about its centre (kg·m²).
fn cylinder(m: f64, r: f64, l: f64) -> f64 {
    m * (3.0 * r * r + l * l) / 12.0
}

fn leg_initial(h: &HexapodConfig, n: usize) -> &crate::HexapodLegInitial {
    h.initial.legs()[n - 1]
}

fn control_leg(c: &crate::ControlConfig, n: usize) -> &ControlLegConfig {
    [&c.leg1, &c.leg2, &c.leg3, &c.leg4, &c.leg5, &c.leg6][n - 1]
}

fn control_leg_mut(c: &mut crate::ControlConfig, n: usize) -> &mut ControlLegConfig {
    match n {
        1 => &mut c.leg1,
        2 => &mut c.leg2,
        3 => &mut c.leg3,
        4 => &mut c.leg4,
        5 => &mut c.leg5,
        _ => &mut c.leg6,
    }
}

/// `[θ1, θ2, θ3]` of `key`, finite.
fn triple(file: &str, key: &str, v: &[f64]) -> Result<[f64; 3], ConfigError> {
    match v {
        [a, b, c] if v.iter().all(|x| x.is_finite()) => Ok([*a, *b, *c]),
        [_, _, _] => Err(ConfigError::semantic(
            file,
            key,
            "must be finite",
            format!("{v:?}"),
            "finite values",
        )),
        _ => Err(ConfigError::semantic(
            file,
            key,
            "must be three angles [θ1, θ2, θ3]",
            format!("{v:?}"),
            "3 numbers (deg)",
        )),
    }
}

/// The value at the dotted `path` of `table`, if given.
fn lookup<'a>(table: &'a toml::Table, path: &[&str]) -> Option<&'a toml::Value> {
    let (last, tables) = path.split_last()?;
    let mut cur = table;
    for p in tables {
        cur = cur.get(*p)?.as_table()?;
    }
    cur.get(*last)
}

/// Whether the dotted `path` of `table` is given.
fn given(table: &toml::Table, path: &[&str]) -> bool {
    lookup(table, path).is_some()
}

/// Whether the dotted `path` of `table` is a table with at least one key.
fn non_empty_table(table: &toml::Table, path: &[&str]) -> bool {
    lookup(table, path)
        .and_then(toml::Value::as_table)
        .is_some_and(|t| !t.is_empty())
}

impl HexapodConfig {
    /// Whether this configuration runs the 3D FBD dynamics (else the
    /// kinematic gait): `dynamics` when given, else dynamic unless it has a
    /// `[gait]` table and no `[control] kind = "gait"`.
    pub fn is_dynamic(&self) -> bool {
        match self.dynamics {
            Some(DynamicsKind::Fbd) => true,
            Some(DynamicsKind::Kinematic) => false,
            None => self.gait.is_none() || self.control.kind == ControlKind::Gait,
        }
    }

    /// The leg numbers of the model: `legs`, all six by default.
    pub fn leg_numbers(&self) -> Vec<usize> {
        self.legs.clone().unwrap_or_else(|| ALL_LEGS.to_vec())
    }

    /// The defaults of a dynamic run that depend on what the file gives
    /// (`table`, with its overrides): `[time] dt`, the leg angles without
    /// `[gait]`; and the check that no `[initial.legN]`/`[control.legN]`
    /// is given for a leg not in `legs`.
    pub(crate) fn fill_dynamics_defaults(
        &mut self,
        table: &toml::Table,
        file: &str,
    ) -> Result<(), ConfigError> {
        if !self.is_dynamic() {
            return Ok(());
        }
        let d = SpatialParams::default();
        if !given(table, &["time", "dt"]) {
            self.time.dt = d.dt;
        }
        if self.gait.is_none() {
            let q0 = default_q0();
            for n in ALL_LEGS {
                let name = format!("leg{n}");
                if !given(table, &["initial", &name, "theta_deg"]) {
                    let l = &mut self.initial_leg_mut(n).theta_deg;
                    // Whole nano-degrees: 250, not 250.00000000000003.
                    *l = std::array::from_fn(|j| {
                        (q0[6 + 3 * (n - 1) + j].to_degrees() * 1e9).round() / 1e9
                    });
                }
            }
        }
        let legs = self.leg_numbers();
        for n in ALL_LEGS.into_iter().filter(|n| !legs.contains(n)) {
            let name = format!("leg{n}");
            for t in ["initial", "control"] {
                if non_empty_table(table, &[t, &name]) {
                    return Err(ConfigError::semantic(
                        file,
                        &format!("{t}.{name}"),
                        "is given for a leg the model does not have",
                        format!("leg {n}"),
                        &format!("only the legs of `legs` ({legs:?})"),
                    ));
                }
            }
        }
        Ok(())
    }

    fn initial_leg_mut(&mut self, n: usize) -> &mut crate::HexapodLegInitial {
        let i = &mut self.initial;
        match n {
            1 => &mut i.leg1,
            2 => &mut i.leg2,
            3 => &mut i.leg3,
            4 => &mut i.leg4,
            5 => &mut i.leg5,
            _ => &mut i.leg6,
        }
    }

    /// Fills the defaults of the dynamics that do not depend on the file
    /// (before the shared ones): `dynamics`, `legs`, the inertia tensor,
    /// the link radii and cylinder inertias, the `pd` targets.
    pub(crate) fn resolve_dynamics(&mut self) {
        let dynamic = self.is_dynamic();
        self.dynamics = Some(if dynamic {
            DynamicsKind::Fbd
        } else {
            DynamicsKind::Kinematic
        });
        if !dynamic {
            return;
        }
        self.legs = Some(self.leg_numbers());
        let (m, side) = (self.body.mass, self.body.side);
        // Only from a valid mass and side: otherwise the check names them.
        if m.is_finite() && m > 0.0 && side.is_finite() && side > 0.0 {
            self.body.inertia.get_or_insert_with(|| {
                InertiaConfig::Components(hexagon_inertia(m, side)[..3].to_vec())
            });
        }
        let d = SpatialParams::default();
        let l = &mut self.leg;
        let ru = *l.upper_radius.get_or_insert(d.upper_radius);
        let rl = *l.lower_radius.get_or_insert(d.lower_radius);
        let (mu, a, ml, c) = (l.upper_mass, l.upper_length, l.lower_mass, l.lower_length);
        l.upper_inertia.get_or_insert(cylinder(mu, ru, a));
        l.lower_inertia.get_or_insert(cylinder(ml, rl, c));
        if self.control.kind == ControlKind::Pd {
            for n in self.leg_numbers() {
                let init = leg_initial(self, n).theta_deg;
                control_leg_mut(&mut self.control, n)
                    .target_deg
                    .get_or_insert_with(|| TargetDeg::Point(init.to_vec()));
            }
        }
    }

    /// Checks the keys that depend on the dispatch (`dynamics`, `legs`,
    /// `[control]`, `[gait]`, `[body] inertia`, `[leg]` radii); called by
    /// [`HexapodConfig::validate`].
    pub(crate) fn validate_dispatch(&self, file: &str) -> Result<(), ConfigError> {
        let err = |key: &str, what: &str, got: &dyn Quote, expected: &str| {
            Err(ConfigError::semantic(file, key, what, got, expected))
        };
        if let Some(i) = &self.body.inertia {
            i.tensor(file)?;
        }
        for (key, r) in [
            ("leg.upper_radius", self.leg.upper_radius),
            ("leg.lower_radius", self.leg.lower_radius),
        ] {
            if let Some(r) = r
                && !(r.is_finite() && r > 0.0)
            {
                return err(key, "must be positive and finite", &r, "a radius > 0 (m)");
            }
        }
        if let Some(legs) = &self.legs {
            let ok = !legs.is_empty()
                && legs.iter().all(|n| (1..=6).contains(n))
                && legs.windows(2).all(|w| w[0] < w[1]);
            if !ok {
                return err(
                    "legs",
                    "must list leg numbers 1–6, increasing, without repeats",
                    &format!("{legs:?}"),
                    "e.g. [3, 4] or [1, 2, 3, 4, 5, 6]",
                );
            }
        }
        if !self.is_dynamic() {
            if self.control.kind == ControlKind::Gait {
                return err(
                    "control.kind",
                    "\"gait\" tracks the gait with the 3D dynamics",
                    &"dynamics = \"kinematic\"",
                    "dynamics = \"fbd\" (or no dynamics key)",
                );
            }
            if self.control != crate::ControlConfig::default() {
                return err(
                    "control",
                    "a kinematic hexapod run has no joint controller",
                    &"a [control] table",
                    "no [control], or dynamics = \"fbd\"",
                );
            }
            if let Some(legs) = &self.legs
                && legs[..] != ALL_LEGS
            {
                return err(
                    "legs",
                    "the kinematic gait moves all six legs",
                    &format!("{legs:?}"),
                    "no legs key, or dynamics = \"fbd\"",
                );
            }
            return Ok(());
        }
        match (self.control.kind, &self.gait) {
            (ControlKind::Gait, None) => {
                return err(
                    "gait",
                    "is required by control.kind = \"gait\"",
                    &"nothing",
                    "a [gait] table",
                );
            }
            (k, Some(_)) if k != ControlKind::Gait => {
                return err(
                    "gait",
                    "is used by the dynamics only with control.kind = \"gait\"",
                    &format!("control.kind = \"{}\"", kind_name(k)),
                    "control.kind = \"gait\", or dynamics = \"kinematic\"",
                );
            }
            _ => {}
        }
        let legs = self.leg_numbers();
        if self.control.kind == ControlKind::Gait && legs[..] != ALL_LEGS {
            return err(
                "legs",
                "control.kind = \"gait\" moves all six legs",
                &format!("{legs:?}"),
                "[1, 2, 3, 4, 5, 6]",
            );
        }
        let phi_z = self.initial.phi_deg[2].to_radians();
        if phi_z.cos().abs() < PHI_Z_SINGULAR.sin() {
            return err(
                "initial.phi_deg",
                "φz = ±90° is the singularity of the body angles (Y, Z, X)",
                &format!("{:?}", self.initial.phi_deg),
                "φz ≠ ±90°",
            );
        }
        self.spatial_control(file).map(|_| ())
    }

    /// The joint controller of the dynamics (radians), without the gait
    /// model (a placeholder `None` for `kind = "gait"`); errors name
    /// `control.key`.
    fn spatial_control(&self, file: &str) -> Result<SpatialControl, ConfigError> {
        let c = &self.control;
        let (kp, kd, torque_limit) = (c.kp, c.kd, c.torque_limit);
        // One source for the gains' domain: the planar controller's check.
        Control::Pd {
            kp,
            kd,
            torque_limit,
            target: [[0.0; 2]; 2],
        }
        .validate()
        .map_err(|(key, what, got)| {
            ConfigError::semantic(file, &key, what, got, "see [control] in docs/reference.md")
        })?;
        let legs = self.leg_numbers();
        let err = |key: String, what: &str, got: String, expected: &str| {
            Err(ConfigError::semantic(file, &key, what, got, expected))
        };
        for n in legs.iter().copied() {
            let l = control_leg(c, n);
            let name = format!("control.leg{n}");
            let uses_times = c.kind == ControlKind::Trajectory;
            if l.times.is_some() && !uses_times {
                return err(
                    format!("{name}.times"),
                    "is only used by kind = \"trajectory\"",
                    "a list".into(),
                    "no times",
                );
            }
            let uses_targets = matches!(c.kind, ControlKind::Pd | ControlKind::Trajectory);
            if l.target_deg.is_some() && !uses_targets {
                return err(
                    format!("{name}.target_deg"),
                    &format!("is not used by kind = \"{}\"", kind_name(c.kind)),
                    "a value".into(),
                    "kind = \"pd\" or \"trajectory\"",
                );
            }
        }
        Ok(match c.kind {
            ControlKind::None => SpatialControl::None,
            ControlKind::Gait => SpatialControl::None,
            ControlKind::Pd => {
                let mut target = Vec::with_capacity(legs.len());
                for n in legs {
                    let key = format!("control.leg{n}.target_deg");
                    target.push(match &control_leg(c, n).target_deg {
                        Some(TargetDeg::Point(v)) => triple(file, &key, v)?.map(f64::to_radians),
                        Some(TargetDeg::Points(v)) => {
                            return err(
                                key,
                                "must be one [θ1, θ2, θ3] for kind = \"pd\"",
                                format!("{v:?}"),
                                "[θ1, θ2, θ3]",
                            );
                        }
                        // Resolved to the initial angles.
                        None => leg_initial(self, n).theta_deg.map(f64::to_radians),
                    });
                }
                SpatialControl::Pd {
                    kp,
                    kd,
                    torque_limit,
                    target,
                }
            }
            ControlKind::Trajectory => {
                let mut trajectories = Vec::with_capacity(legs.len());
                for n in legs {
                    let l = control_leg(c, n);
                    let key = format!("control.leg{n}.target_deg");
                    let tkey = format!("control.leg{n}.times");
                    let Some(times) = &l.times else {
                        return err(
                            tkey,
                            "is required for kind = \"trajectory\"",
                            "nothing".into(),
                            "a list of strictly increasing times (s)",
                        );
                    };
                    if times.is_empty()
                        || !times.iter().all(|t| t.is_finite())
                        || times.windows(2).any(|w| w[1] <= w[0])
                    {
                        return err(
                            tkey,
                            "must be finite and strictly increasing",
                            format!("{times:?}"),
                            "at least one time, strictly increasing (s)",
                        );
                    }
                    let targets: Vec<[f64; 3]> = match &l.target_deg {
                        Some(TargetDeg::Points(v)) => v
                            .iter()
                            .map(|p| triple(file, &key, p).map(|p| p.map(f64::to_radians)))
                            .collect::<Result<_, _>>()?,
                        Some(TargetDeg::Point(v)) if v.is_empty() => Vec::new(),
                        Some(TargetDeg::Point(v)) => {
                            return err(
                                key,
                                "must be a list of [θ1, θ2, θ3] for kind = \"trajectory\"",
                                format!("{v:?}"),
                                "[[θ1, θ2, θ3], ...]",
                            );
                        }
                        None => {
                            return err(
                                key,
                                "is required for kind = \"trajectory\"",
                                "nothing".into(),
                                "[[θ1, θ2, θ3], ...]",
                            );
                        }
                    };
                    if targets.len() != times.len() {
                        return err(
                            key,
                            "must have one [θ1, θ2, θ3] per time",
                            format!("{} targets", targets.len()),
                            &format!("{} (as many as control.leg{n}.times)", times.len()),
                        );
                    }
                    trajectories.push(LegTrajectory3 {
                        times: times.clone(),
                        targets,
                    });
                }
                SpatialControl::Trajectory {
                    kp,
                    kd,
                    torque_limit,
                    legs: trajectories,
                }
            }
        })
    }

    /// The parameters of the 3D dynamics (SI units, radians), validated;
    /// errors name the file and `table.key`. The body's initial angular
    /// velocity `omega_deg` (inertial) enters as `φ̇ = E(φ)⁻¹·ω`
    /// ([`euler_rate_matrix`]). For `[control] kind = "gait"` the
    /// kinematic gait is built from the same geometry, Δt, duration and
    /// initial pose.
    pub fn spatial_params(&self, file: &str) -> Result<SpatialParams, ConfigError> {
        self.validate(file)?;
        let mut c = self.clone();
        c.resolve_dynamics();
        let d = SpatialParams::default();
        let legs = c.leg_numbers();
        let i = &c.initial;
        let phi = i.phi_deg.map(f64::to_radians);
        let omega = Vector3::from(i.omega_deg.map(f64::to_radians));
        let phi_dot = euler_rate_matrix(phi)
            .try_inverse()
            .map(|e| e * omega)
            .unwrap_or_else(Vector3::zeros);
        let mut q0 = Vec::with_capacity(6 + 3 * legs.len());
        let mut qdot0 = Vec::with_capacity(6 + 3 * legs.len());
        q0.extend(i.position);
        q0.extend(phi);
        qdot0.extend(i.velocity);
        qdot0.extend(phi_dot.iter());
        for &n in &legs {
            let l = leg_initial(&c, n);
            q0.extend(l.theta_deg.map(f64::to_radians));
            qdot0.extend(l.rate_deg.map(f64::to_radians));
        }
        let body_inertia = match &c.body.inertia {
            Some(t) => t.tensor(file)?,
            None => hexagon_inertia(c.body.mass, c.body.side),
        };
        let control = match c.spatial_control(file)? {
            SpatialControl::None if c.control.kind == ControlKind::Gait => SpatialControl::Gait {
                kp: c.control.kp,
                kd: c.control.kd,
                torque_limit: c.control.torque_limit,
                gait: Box::new(c.build_gait_model(file)?),
            },
            other => other,
        };
        let l = &c.leg;
        Ok(SpatialParams {
            dt: c.time.dt,
            duration: c.time.duration,
            gravity: c.world.gravity,
            body_mass: c.body.mass,
            body_inertia,
            side: c.body.side,
            upper_length: l.upper_length,
            upper_mass: l.upper_mass,
            upper_radius: l.upper_radius.unwrap_or(d.upper_radius),
            upper_inertia: l.upper_inertia(),
            upper_com: l.upper_com,
            lower_length: l.lower_length,
            lower_mass: l.lower_mass,
            lower_radius: l.lower_radius.unwrap_or(d.lower_radius),
            lower_inertia: l.lower_inertia(),
            lower_com: l.lower_com,
            legs,
            joint_limits: l.joint_limits(),
            q0,
            qdot0,
            terrain: c.terrain.surface(),
            friction: c.terrain.friction(),
            contact_points: c.contact.contact_points(),
            contact: ContactParams::default(),
            control,
            stride: c.output.stride,
            solver: c.solver.settings(),
        })
    }

    /// Validates and builds the 3D dynamic model ([`SpatialModel::new`] of
    /// [`HexapodConfig::spatial_params`]); errors name `table.key`
    /// (prefixed with `file`).
    pub fn spatial_model(&self, file: &str) -> Result<SpatialModel, ConfigError> {
        SpatialModel::new(&self.spatial_params(file)?).map_err(|e| ConfigError::Semantic {
            file: file.to_owned(),
            message: e.to_string(),
        })
    }
}

fn kind_name(k: ControlKind) -> &'static str {
    match k {
        ControlKind::None => "none",
        ControlKind::Pd => "pd",
        ControlKind::Trajectory => "trajectory",
        ControlKind::Gait => "gait",
    }
}

/// Rejects the hexapod-only keys in a planar configuration; errors name
/// the key.
pub(crate) fn reject_hexapod_keys(c: &PlanarConfig, file: &str) -> Result<(), ConfigError> {
    let err = |key: &str, got: &dyn Quote, expected: &str| {
        Err(ConfigError::semantic(
            file,
            key,
            "is for model = \"hexapod\"",
            got,
            expected,
        ))
    };
    if let Some(d) = c.dynamics {
        let d = if d == DynamicsKind::Fbd {
            "fbd"
        } else {
            "kinematic"
        };
        return err("dynamics", &d, "no dynamics key for the planar model");
    }
    if let Some(legs) = &c.legs {
        return err(
            "legs",
            &format!("{legs:?}"),
            "no legs key (the planar model has legs 3 and 4)",
        );
    }
    if let Some(InertiaConfig::Components(v)) = &c.body.inertia {
        return Err(ConfigError::semantic(
            file,
            "body.inertia",
            "the planar model takes one number, the inertia about Z",
            format!("{v:?}"),
            "a number (kg·m²)",
        ));
    }
    for (key, r) in [
        ("leg.upper_radius", c.leg.upper_radius),
        ("leg.lower_radius", c.leg.lower_radius),
    ] {
        if let Some(r) = r {
            return err(key, &r, "no link radius for the planar model");
        }
    }
    if c.control.kind == ControlKind::Gait {
        return err(
            "control.kind",
            &"\"gait\"",
            "\"none\", \"pd\" or \"trajectory\"",
        );
    }
    for n in [1, 2, 5, 6] {
        if *control_leg(&c.control, n) != ControlLegConfig::default() {
            return err(
                &format!("control.leg{n}"),
                &format!("leg {n}"),
                "control.leg3 and control.leg4 only",
            );
        }
    }
    Ok(())
}

/// `config.toml` of a hexapod whose `legs` is a subset: the
/// `[initial.legN]` and `[control.legN]` tables of the other legs (which
/// hold defaults) are left out, so that the file reads back.
pub(crate) fn drop_absent_legs(config: &Config, text: String) -> String {
    let Config::Hexapod(h) = config else {
        return text;
    };
    let legs = h.leg_numbers();
    let headers: Vec<String> = ALL_LEGS
        .into_iter()
        .filter(|n| !legs.contains(n))
        .flat_map(|n| [format!("[initial.leg{n}]"), format!("[control.leg{n}]")])
        .collect();
    if headers.is_empty() {
        return text;
    }
    let mut out = String::with_capacity(text.len());
    let mut skip = false;
    for line in text.split_inclusive('\n') {
        if line.starts_with('[') {
            skip = headers.iter().any(|h| line.trim_end() == h);
        }
        if !skip {
            out.push_str(line);
        }
    }
    out
}

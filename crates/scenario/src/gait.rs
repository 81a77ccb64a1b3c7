//! `[gait]` of the hexapod model: the kinematic gait (schema, defaults,
//! validation) and the conversion of a hexapod configuration into a
//! [`GaitModel`]. A kinematic run without `[gait]` (`dynamics =
//! "kinematic"`) stands: the initial pose is held for the duration.

use fbd_kinematics::hexapod::{HexapodData, HexapodModel, forward};
use fbd_kinematics::ik::KneeBranch;
use fbd_kinematics::leg::LegGeometry;
use fbd_kinematics::nalgebra::Vector3;
use fbd_kinematics::num::Num;
use fbd_kinematics::pose::BodyPose;
use fbd_kinematics::stance::stance_ik;
use fbd_sim::gait::{Command, GaitKind, GaitModel, GaitParams, InitialPose, Masses};
use serde::{Deserialize, Serialize};

use crate::{Config, ConfigError, HexapodConfig, HexapodInitial, HexapodLegInitial, Quote};

/// The joint angles `(θ1, θ2, θ3)` (deg) of the default stance, every leg
/// alike: the upper link horizontal and the lower link 25° outward from
/// the vertical (the paper's leg-3 pose). The body then stands
/// `c·sin 65°` above its feet (0.3806 m with `c` = 0.42 m) and every foot
/// is `d + a + c·cos 65°` from the body centre (0.5940 m).
pub const STANCE_THETA_DEG: [f64; 3] = [0.0, 0.0, 245.0];

/// Gait periods walked when neither `[time] duration` nor
/// `[gait] walk_time` is given: `walk_time = 5·period`, and the default
/// duration is `walk_time + period` (the last swings land).
pub const DEFAULT_WALK_PERIODS: f64 = 5.0;

/// The default forward speed of `[gait]` (m/s): a gait table alone walks.
pub const DEFAULT_FORWARD_SPEED: f64 = 0.1;

/// `[gait] kind`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GaitKindConfig {
    /// β = ½, legs {1, 4, 5} against {2, 3, 6} (default).
    #[default]
    Tripod,
    /// β = ⅔, rear-to-front waves on each side, half a period apart.
    Ripple,
    /// β = ⅚, one leg at a time: 5, 3, 1, 6, 4, 2.
    Wave,
    /// `duty_factor` and `phases` from the configuration.
    Custom,
}

impl GaitKindConfig {
    fn kind(self) -> GaitKind {
        match self {
            GaitKindConfig::Tripod => GaitKind::Tripod,
            GaitKindConfig::Ripple => GaitKind::Ripple,
            GaitKindConfig::Wave => GaitKind::Wave,
            GaitKindConfig::Custom => GaitKind::Custom,
        }
    }
}

/// A commanded speed: a number, or a piecewise-linear profile
/// `[[t, value], ...]` (t strictly increasing, constant beyond the ends).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(
    untagged,
    expecting = "a number or a profile [[t, value], ...] of [time, value] pairs"
)]
pub enum SpeedConfig {
    /// A constant.
    Constant(f64),
    /// `[[t, value], ...]`.
    Profile(Vec<[f64; 2]>),
}

impl Default for SpeedConfig {
    fn default() -> Self {
        SpeedConfig::Constant(0.0)
    }
}

impl SpeedConfig {
    fn command(&self, scale: f64) -> Command {
        match self {
            SpeedConfig::Constant(v) => Command::Constant(v * scale),
            SpeedConfig::Profile(p) => {
                Command::Profile(p.iter().map(|q| [q[0], q[1] * scale]).collect())
            }
        }
    }

    fn check(&self, file: &str, key: &str) -> Result<(), ConfigError> {
        match self {
            SpeedConfig::Constant(v) if !v.is_finite() => Err(ConfigError::semantic(
                file,
                key,
                "must be finite",
                v,
                "a finite value",
            )),
            SpeedConfig::Profile(p) => {
                if p.is_empty() {
                    return Err(ConfigError::semantic(
                        file,
                        key,
                        "profile is empty",
                        "[]",
                        "at least one [t, value] pair",
                    ));
                }
                for (i, q) in p.iter().enumerate() {
                    if !(q[0].is_finite() && q[1].is_finite()) {
                        return Err(ConfigError::semantic(
                            file,
                            key,
                            &format!("point {} must be finite", i + 1),
                            format!("{q:?}"),
                            "finite [t, value]",
                        ));
                    }
                    if i > 0 && q[0] <= p[i - 1][0] {
                        return Err(ConfigError::semantic(
                            file,
                            key,
                            &format!("times must increase strictly (point {})", i + 1),
                            q[0],
                            &format!("t > {}", p[i - 1][0]),
                        ));
                    }
                }
                Ok(())
            }
            SpeedConfig::Constant(_) => Ok(()),
        }
    }
}

/// `[gait]`: every key optional; defaults documented per field.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct GaitConfig {
    /// `"tripod"` (default), `"ripple"`, `"wave"` or `"custom"`.
    pub kind: GaitKindConfig,
    /// Duty factor β ∈ (0, 1); required with `custom`, fixed by the other
    /// kinds (½, ⅔, ⅚; may be given only with that value).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub duty_factor: Option<f64>,
    /// Lift-off phase of legs 1–6, fractions of the period in `[0, 1)`;
    /// required with `custom`, fixed by the other kinds.
    #[serde(skip_serializing_if = "Option::is_none")]
    #[serde(deserialize_with = "crate::fixed::opt")]
    pub phases: Option<[f64; 6]>,
    /// Gait period T (s). Default 1 s, or `step_length / |forward_speed|`
    /// when `step_length` is given.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub period: Option<f64>,
    /// Stride length (m) per period: an alternative to `period` for a
    /// constant, non-zero `forward_speed`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub step_length: Option<f64>,
    /// Swing height above the straight lift-off → touchdown line (m).
    /// Default 0.05.
    pub swing_height: f64,
    /// Forward speed (m/s): number or `[[t, v], ...]`. Default 0.1
    /// ([`DEFAULT_FORWARD_SPEED`]): a `[gait]` table alone walks forward.
    pub forward_speed: SpeedConfig,
    /// Lateral speed to the right (m/s): number or profile. Default 0.
    pub lateral_speed: SpeedConfig,
    /// Yaw rate (deg/s, positive turns left): number or profile. Default 0.
    pub yaw_rate_deg: SpeedConfig,
    /// Start-up and stop blend time (s). Default 0.5.
    pub ramp: f64,
    /// No lift-off from this time on; the body stops here (s). Default
    /// `time.duration − period`, so that every foot is down at the end;
    /// without `[time] duration`, `5·period` ([`DEFAULT_WALK_PERIODS`]).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub walk_time: Option<f64>,
    /// Body height offset (m). Default 0.
    pub body_height: f64,
    /// Body roll offset (deg, positive lowers the right side). Default 0.
    pub body_roll_deg: f64,
    /// Body pitch offset (deg, positive raises the front). Default 0.
    pub body_pitch_deg: f64,
    /// Lateral sway amplitude (m). Default 0.
    pub sway: f64,
    /// The body height follows the terrain under it. Default `true`.
    pub follow_terrain: bool,
    /// Warning threshold of the stability margin (m). Default 0.02.
    pub margin_warning: f64,
    /// Stop with an error when the margin drops below `margin_warning`.
    /// Default `false`.
    pub require_stable: bool,
}

impl Default for GaitConfig {
    fn default() -> Self {
        let p = GaitParams::default();
        Self {
            kind: GaitKindConfig::Tripod,
            duty_factor: None,
            phases: None,
            period: None,
            step_length: None,
            swing_height: p.swing_height,
            forward_speed: SpeedConfig::Constant(DEFAULT_FORWARD_SPEED),
            lateral_speed: SpeedConfig::default(),
            yaw_rate_deg: SpeedConfig::default(),
            ramp: p.ramp,
            walk_time: None,
            body_height: p.height,
            body_roll_deg: p.roll.to_degrees(),
            body_pitch_deg: p.pitch.to_degrees(),
            sway: p.sway,
            follow_terrain: p.follow_terrain,
            margin_warning: p.margin_warning,
            require_stable: p.require_stable,
        }
    }
}

impl GaitConfig {
    /// The period the gait will use (s): `period`, else
    /// `step_length / |forward_speed|`, else the default 1 s.
    fn period_used(&self) -> f64 {
        if let Some(t) = self.period {
            return t;
        }
        if let (Some(l), SpeedConfig::Constant(v)) = (self.step_length, &self.forward_speed)
            && *v != 0.0
            && l > 0.0
        {
            return l / v.abs();
        }
        GaitParams::default().period
    }

    /// The duration of a walk whose file gives no `[time] duration` (s):
    /// `walk_time + period`, `walk_time` defaulting to
    /// [`DEFAULT_WALK_PERIODS`] periods.
    pub fn default_duration(&self) -> f64 {
        let period = self.period_used();
        self.walk_time.unwrap_or(DEFAULT_WALK_PERIODS * period) + period
    }

    /// Fills the preset's β and phases, the period (from `step_length`) and
    /// `walk_time`, so that `config.toml` holds every value used.
    pub fn resolve(&mut self, duration: f64) {
        if let Some((duty, phases)) = self.kind.kind().preset() {
            self.duty_factor.get_or_insert(duty);
            self.phases.get_or_insert(phases);
        }
        if self.period.is_none()
            && let (Some(l), SpeedConfig::Constant(v)) = (self.step_length, &self.forward_speed)
            && *v != 0.0
            && l > 0.0
        {
            self.period = Some(l / v.abs());
            self.step_length = None;
        }
        if self.step_length.is_none() || self.period.is_some() {
            let period = *self.period.get_or_insert(GaitParams::default().period);
            if self.step_length.is_none() {
                self.walk_time.get_or_insert((duration - period).max(0.0));
            }
        }
    }

    /// Checks every key; errors name `gait.key`.
    pub fn validate(&self, file: &str) -> Result<(), ConfigError> {
        let err = |key: &str, what: &str, got: &dyn Quote, expected: &str| {
            Err(ConfigError::semantic(file, key, what, got, expected))
        };
        if let Some(l) = self.step_length {
            if self.period.is_some() {
                return err(
                    "gait.step_length",
                    "give period or step_length, not both",
                    &l,
                    "one of them",
                );
            }
            if !(l.is_finite() && l > 0.0) {
                return err(
                    "gait.step_length",
                    "must be positive",
                    &l,
                    "a finite value > 0",
                );
            }
            return err(
                "gait.step_length",
                "needs a constant, non-zero forward_speed",
                &l,
                "forward_speed = <number ≠ 0>",
            );
        }
        match (self.kind.kind().preset(), self.duty_factor, self.phases) {
            (None, None, _) => {
                return err(
                    "gait.duty_factor",
                    "is required with kind = \"custom\"",
                    &"nothing",
                    "a number in (0, 1)",
                );
            }
            (None, _, None) => {
                return err(
                    "gait.phases",
                    "are required with kind = \"custom\"",
                    &"nothing",
                    "6 numbers in [0, 1)",
                );
            }
            (Some((duty, phases)), d, p) => {
                if d.is_some_and(|d| d != duty) {
                    return err(
                        "gait.duty_factor",
                        "is fixed by the gait kind (use kind = \"custom\" to change it)",
                        &d.unwrap_or(duty),
                        &format!("{duty}"),
                    );
                }
                if p.is_some_and(|p| p != phases) {
                    return err(
                        "gait.phases",
                        "are fixed by the gait kind (use kind = \"custom\" to change them)",
                        &format!("{:?}", p.unwrap_or(phases)),
                        &format!("{phases:?}"),
                    );
                }
            }
            _ => {}
        }
        if let Some(d) = self.duty_factor
            && !(d > 0.0 && d < 1.0)
        {
            return err(
                "gait.duty_factor",
                "must lie strictly between 0 and 1",
                &d,
                "0 < duty_factor < 1",
            );
        }
        if let Some(p) = self.phases
            && let Some(x) = p.iter().find(|x| !(0.0..1.0).contains(*x))
        {
            return err(
                "gait.phases",
                "must be fractions of the period",
                x,
                "values in [0, 1)",
            );
        }
        if let Some(t) = self.period
            && !(t.is_finite() && t > 0.0)
        {
            return err("gait.period", "must be positive", &t, "a finite value > 0");
        }
        for (key, v) in [
            ("gait.swing_height", self.swing_height),
            ("gait.ramp", self.ramp),
            ("gait.sway", self.sway),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return err(key, "must be finite and ≥ 0", &v, "a finite value ≥ 0");
            }
        }
        for (key, v) in [
            ("gait.body_height", self.body_height),
            ("gait.body_roll_deg", self.body_roll_deg),
            ("gait.body_pitch_deg", self.body_pitch_deg),
            ("gait.margin_warning", self.margin_warning),
        ] {
            if !v.is_finite() {
                return err(key, "must be finite", &v, "a finite value");
            }
        }
        if let Some(w) = self.walk_time
            && !(w.is_finite() && w >= 0.0)
        {
            return err(
                "gait.walk_time",
                "must be finite and ≥ 0",
                &w,
                "a value ≥ 0",
            );
        }
        self.forward_speed.check(file, "gait.forward_speed")?;
        self.lateral_speed.check(file, "gait.lateral_speed")?;
        self.yaw_rate_deg.check(file, "gait.yaw_rate_deg")?;
        Ok(())
    }

    /// The swing `(1 − duty_factor)·period` against `time.dt`
    /// ([`swing_fits`]); call after [`GaitConfig::validate`].
    pub fn validate_swing(&self, file: &str, dt: f64) -> Result<(), ConfigError> {
        match self
            .duty_factor
            .or_else(|| self.kind.kind().preset().map(|(d, _)| d))
        {
            Some(duty) => swing_fits(file, self.period_used(), duty, dt),
            None => Ok(()),
        }
    }

    /// The library's parameters (SI units, radians); call after
    /// [`GaitConfig::resolve`].
    pub fn params(&self) -> GaitParams {
        let d = GaitParams::default();
        GaitParams {
            duty: self.duty_factor.unwrap_or(d.duty),
            phases: self.phases.unwrap_or(d.phases),
            period: self.period.unwrap_or(d.period),
            swing_height: self.swing_height,
            forward: self.forward_speed.command(1.0),
            lateral: self.lateral_speed.command(1.0),
            yaw_rate: self.yaw_rate_deg.command(1f64.to_radians()),
            ramp: self.ramp,
            walk_time: self.walk_time.unwrap_or(d.walk_time),
            height: self.body_height,
            roll: self.body_roll_deg.to_radians(),
            pitch: self.body_pitch_deg.to_radians(),
            sway: self.sway,
            follow_terrain: self.follow_terrain,
            margin_warning: self.margin_warning,
            require_stable: self.require_stable,
            limits: d.limits,
            walking: true,
        }
    }
}

/// [`fbd_robot::gait::check_swing`] as a configuration error naming
/// `gait.period`: the rule of the hexapod's `[gait]` and of an imported
/// robot's.
pub(crate) fn swing_fits(file: &str, period: f64, duty: f64, dt: f64) -> Result<(), ConfigError> {
    match fbd_robot::gait::check_swing(period, duty, dt) {
        Err(fbd_robot::gait::GaitError::ShortSwing {
            swing, min_period, ..
        }) => Err(ConfigError::semantic(
            file,
            "gait.period",
            &format!(
                "the swing (1 − duty_factor)·period = {} s spans fewer than {} steps of time.dt = {} s",
                Num(swing),
                fbd_robot::gait::MIN_SWING_STEPS,
                Num(dt)
            ),
            period,
            &format!("a period ≥ {} s, or a smaller time.dt", Num(min_period)),
        )),
        _ => Ok(()),
    }
}

/// The default `[initial]` of a hexapod on its terrain: the body level at
/// the origin, [`STANCE_THETA_DEG`]'s height above the ground under it, and
/// every foot where that pose puts it horizontally, on the terrain (the
/// leg inverse kinematics gives the angles; on flat ground they are
/// [`STANCE_THETA_DEG`]). `None` when the geometry cannot stand so (the
/// validation then names the key at fault).
pub fn default_stance(h: &HexapodConfig) -> Option<HexapodInitial> {
    let kin = HexapodModel::new(
        h.body.side,
        LegGeometry {
            a: h.leg.upper_length,
            c: h.leg.lower_length,
        },
        h.leg.upper_com,
        h.leg.lower_com,
    );
    let theta = STANCE_THETA_DEG.map(f64::to_radians);
    let mut fk = HexapodData::new();
    forward(
        &kin,
        &fbd_kinematics::hexapod::HexapodConfig {
            pose: BodyPose::default(),
            joints: [theta; 6],
        },
        &mut fk,
    );
    let surface = h.terrain.surface();
    let ground = |x: f64, z: f64| {
        if surface.exists() {
            surface.height(x, z)
        } else {
            0.0
        }
    };
    let below = -fk.legs[0].tip.y;
    let y0 = ground(0.0, 0.0) + below;
    let pose = BodyPose::new([0.0, y0, 0.0], [0.0; 3]);
    let feet = fk
        .legs
        .map(|l| Vector3::new(l.tip.x, ground(l.tip.x, l.tip.z), l.tip.z));
    let joints = stance_ik(&kin, &pose, &feet, &[KneeBranch::of(theta[2]); 6]).ok()?;
    // Whole nano-degrees, so that flat ground reads 245, not 244.99999999999997.
    let deg = |v: f64| (v.to_degrees() * 1e9).round() / 1e9;
    let leg = |n: usize| HexapodLegInitial {
        theta_deg: joints[n].map(deg),
        rate_deg: [0.0; 3],
    };
    (y0.is_finite() && joints.iter().flatten().all(|v| v.is_finite())).then(|| HexapodInitial {
        position: [0.0, y0, 0.0],
        leg1: leg(0),
        leg2: leg(1),
        leg3: leg(2),
        leg4: leg(3),
        leg5: leg(4),
        leg6: leg(5),
        ..HexapodInitial::default()
    })
}

/// The defaults of a hexapod file that depend on what else it gives,
/// filled before [`Config::resolve`]; `table` is the file's (with its
/// overrides): without `[initial]` the robot stands on its terrain
/// ([`default_stance`]) — unless it is a dynamic run without `[gait]`,
/// which starts from [`fbd_sim::spatial::default_q0`]; with `[gait]` and
/// without `[time] duration` it walks for
/// [`GaitConfig::default_duration`]; a dynamic run also takes its Δt and
/// leg angles ([`HexapodConfig::is_dynamic`]). Fails for
/// `[initial.legN]`/`[control.legN]` of a leg not in `legs`.
pub fn fill_hexapod_defaults(
    config: &mut Config,
    table: &toml::Table,
    file: &str,
) -> Result<(), ConfigError> {
    let Config::Hexapod(h) = config else {
        return Ok(());
    };
    let stands = !h.is_dynamic() || h.gait.is_some();
    if stands
        && !table.contains_key("initial")
        && let Some(initial) = default_stance(h)
    {
        h.initial = initial;
    }
    let duration_given = table
        .get("time")
        .and_then(toml::Value::as_table)
        .is_some_and(|t| t.contains_key("duration"));
    if !duration_given && let Some(g) = &h.gait {
        let d = g.default_duration();
        if d.is_finite() && d > 0.0 {
            h.time.duration = d;
        }
    }
    h.fill_dynamics_defaults(table, file)
}

impl HexapodConfig {
    /// The kinematic run of this configuration: the `[gait]`, or a standing
    /// run without it. Joint limits from `[leg] theta*_deg`.
    ///
    /// # Errors
    /// [`ConfigError::Semantic`] naming the key at fault.
    pub fn gait_model(&self, file: &str) -> Result<GaitModel, ConfigError> {
        self.validate(file)?;
        self.build_gait_model(file)
    }

    /// [`HexapodConfig::gait_model`] of a validated configuration.
    pub(crate) fn build_gait_model(&self, file: &str) -> Result<GaitModel, ConfigError> {
        let kin = HexapodModel::new(
            self.body.side,
            LegGeometry {
                a: self.leg.upper_length,
                c: self.leg.lower_length,
            },
            self.leg.upper_com,
            self.leg.lower_com,
        );
        let mut params = match &self.gait {
            Some(g) => {
                let mut g = g.clone();
                g.resolve(self.time.duration);
                g.params()
            }
            None => GaitParams::standing(),
        };
        params.limits = self.leg.joint_limits();
        let masses = Masses {
            body: self.body.mass,
            upper: self.leg.upper_mass,
            lower: self.leg.lower_mass,
        };
        let initial = InitialPose {
            position: self.initial.position,
            phi: self.phi_rad(),
            joints: self.joints_rad(),
        };
        GaitModel::new(
            kin,
            params,
            self.terrain.surface(),
            masses,
            self.time.dt,
            self.time.duration,
            initial,
        )
        .map_err(|e| ConfigError::Semantic {
            file: file.to_owned(),
            message: e.to_string(),
        })
    }
}

#[cfg(test)]
mod tests {
    use crate::{Config, parse_str};

    fn parse(text: &str) -> Result<Config, String> {
        parse_str(text, "g.toml", &[]).map_err(|e| e.to_string())
    }

    #[test]
    fn gait_round_trips_and_fills_defaults() {
        let text = "model = \"hexapod\"\n[time]\nduration = 5.0\n[gait]\nkind = \"wave\"\nforward_speed = [[0.0, 0.0], [2.0, 0.1]]\nyaw_rate_deg = 5\n";
        let c = parse(text).unwrap();
        let Config::Hexapod(h) = &c else { panic!() };
        let g = h.gait.as_ref().unwrap();
        assert_eq!(g.duty_factor, Some(5.0 / 6.0));
        assert_eq!(g.period, Some(1.0));
        assert_eq!(g.walk_time, Some(4.0));
        let again = parse(&c.to_toml()).unwrap();
        assert_eq!(c, again);
    }

    #[test]
    fn bad_gait_keys_are_named() {
        let e = parse("model = \"hexapod\"\n[gait]\nkind = \"trot\"\n").unwrap_err();
        assert!(e.starts_with("g.toml:3:8: gait.kind"), "{e}");
        let e = parse("model = \"hexapod\"\n[gait]\nduty = 0.5\n").unwrap_err();
        assert!(e.starts_with("g.toml:3:1: ") && e.contains("duty"), "{e}");
        let e = parse("model = \"hexapod\"\n[gait]\nkind = \"custom\"\nduty_factor = 0.6\n")
            .unwrap_err();
        assert!(e.contains("gait.phases: are required"), "{e}");
        let e = parse("model = \"hexapod\"\n[gait]\nduty_factor = 0.6\n").unwrap_err();
        assert!(e.contains("gait.duty_factor: is fixed"), "{e}");
        let e = parse("model = \"hexapod\"\n[gait]\nperiod = -1\n").unwrap_err();
        assert!(e.contains("gait.period: must be positive (got -1"), "{e}");
        let e = parse("model = \"hexapod\"\n[gait]\nforward_speed = [[1.0, 0.1], [0.5, 0.2]]\n")
            .unwrap_err();
        assert!(e.contains("gait.forward_speed: times must increase"), "{e}");
        let e = parse("model = \"hexapod\"\n[gait]\nforward_speed = \"fast\"\n").unwrap_err();
        assert!(
            e.contains("gait.forward_speed") && e.contains("profile"),
            "{e}"
        );
        let e = parse("[gait]\nkind = \"tripod\"\n").unwrap_err();
        assert!(e.contains("gait"), "{e}");
    }

    fn run(text: &str) -> (crate::HexapodConfig, fbd_sim::gait::GaitSummary) {
        let Config::Hexapod(h) = parse(text).unwrap() else {
            panic!()
        };
        let model = h.gait_model("g.toml").unwrap();
        let stop = std::sync::atomic::AtomicBool::new(false);
        let s = fbd_sim::gait::run_gait(&model, &stop, |_| {});
        (*h, s)
    }

    #[test]
    fn a_gait_table_alone_walks_from_the_default_stance() {
        let (h, s) = run("model = \"hexapod\"\n[gait]\n");
        // The default stance: the paper's leg-3 pose, feet on the ground.
        assert_eq!(h.initial.leg1.theta_deg, super::STANCE_THETA_DEG);
        let c = 0.42f64;
        assert!((h.initial.position[1] - c * 65f64.to_radians().sin()).abs() < 1e-12);
        // 5 periods of walking at 0.1 m/s, then one to set the feet down.
        assert_eq!(h.time.duration, 6.0);
        assert_eq!(h.gait.as_ref().unwrap().walk_time, Some(5.0));
        assert!(s.error.is_none(), "{:?}", s.error);
        // 0.1 m/s for 5 s less the two half-ramps of 0.5 s: 0.45 m.
        assert!((s.distance - 0.45).abs() < 1e-9, "{}", s.distance);
        assert!(s.min_margin.unwrap().0 > 0.2);
        // The walk's config.toml reruns the same walk.
        let again = parse(&Config::Hexapod(Box::new(h.clone())).to_toml()).unwrap();
        assert_eq!(again, Config::Hexapod(Box::new(h)));
    }

    #[test]
    fn a_kinematic_hexapod_without_gait_stands_on_the_ground() {
        // (A bare hexapod runs the 3D dynamics: `dynamics` asks for the
        // kinematic stand.)
        let (h, s) = run("model = \"hexapod\"\ndynamics = \"kinematic\"\n");
        assert!(h.gait.is_none());
        assert_eq!(h.time.duration, 1.0);
        assert!(s.error.is_none() && s.distance == 0.0, "{s:?}");
        let model = h.gait_model("g.toml").unwrap();
        for f in &model.initial_feet {
            assert!(f.y.abs() < 1e-9, "a foot off the ground: {f:?}");
        }
        // On a 10° slope the default stance puts every foot on the slope.
        let (h, _) = run(
            "model = \"hexapod\"\ndynamics = \"kinematic\"\n[terrain]\nkind = \"slope\"\nangle_deg = 10.0\n",
        );
        let model = h.gait_model("g.toml").unwrap();
        for f in &model.initial_feet {
            let g = model.surface.height(f.x, f.z);
            assert!((f.y - g).abs() < 1e-9, "foot {f:?} vs ground {g}");
        }
        // An explicit duration or [initial] is kept.
        let (h, _) = run(
            "model = \"hexapod\"\n[time]\nduration = 3.0\n[initial]\nposition = [0.0, 0.38, 0.0]\n[gait]\n",
        );
        assert_eq!((h.time.duration, h.initial.position[1]), (3.0, 0.38));
        assert_eq!(h.gait.unwrap().walk_time, Some(2.0));
    }

    #[test]
    fn step_length_sets_the_period() {
        let c = parse(
            "model = \"hexapod\"\n[time]\nduration = 3.0\n[gait]\nstep_length = 0.2\nforward_speed = 0.1\n",
        )
        .unwrap();
        let Config::Hexapod(h) = &c else { panic!() };
        let g = h.gait.as_ref().unwrap();
        assert_eq!(
            (g.period, g.step_length, g.walk_time),
            (Some(2.0), None, Some(1.0))
        );
    }
}

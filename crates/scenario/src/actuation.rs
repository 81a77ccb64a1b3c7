//! `[control]` (joint controllers) and the terrain kinds beyond flat ground
//! (slope, profile, sine, steps): their tables, validation and conversion to
//! the simulator's types.

use std::path::Path;

use fbd_contact::Terrain;
use fbd_sim::{Control, LegTrajectory};
use serde::{Deserialize, Serialize};

use super::{ConfigError, TerrainConfig, TerrainKind};

/// Controller kinds of `[control] kind`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ControlKind {
    /// Passive joints.
    #[default]
    None,
    /// PD regulation to fixed joint angles (`target_deg = [θ2, θ3]`).
    Pd,
    /// PD tracking of piecewise-linear joint trajectories (`times`,
    /// `target_deg = [[θ2, θ3], ...]`).
    Trajectory,
    /// Hexapod dynamics: tracking of the `[gait]`'s joint angles and rates
    /// (feed-forward rates + PD).
    Gait,
}

/// `target_deg` of a leg: one `[θ2, θ3]` (pd) or a list of them
/// (trajectory), degrees.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(untagged)]
pub enum TargetDeg {
    /// `[θ2, θ3]`.
    Point(Vec<f64>),
    /// `[[θ2, θ3], ...]`.
    Points(Vec<Vec<f64>>),
}

/// `[control.legN]`: legs 3 and 4 of the planar model, 1–6 of the
/// hexapod (three angles per target there).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControlLegConfig {
    /// Trajectory times (s), strictly increasing (trajectory only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub times: Option<Vec<f64>>,
    /// Target joint angles (degrees). For `pd`, defaults to the leg's
    /// initial angles.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub target_deg: Option<TargetDeg>,
}

/// `[control]`.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ControlConfig {
    /// Controller kind.
    pub kind: ControlKind,
    /// Stiffness (N·m/rad), ≥ 0.
    pub kp: f64,
    /// Damping (N·m·s/rad), ≥ 0.
    pub kd: f64,
    /// Torque saturation (N·m), > 0; omitted for none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub torque_limit: Option<f64>,
    /// Leg 1 targets (hexapod).
    #[serde(skip_serializing_if = "ControlLegConfig::is_empty")]
    pub leg1: ControlLegConfig,
    /// Leg 2 targets (hexapod).
    #[serde(skip_serializing_if = "ControlLegConfig::is_empty")]
    pub leg2: ControlLegConfig,
    /// Leg 3 targets.
    pub leg3: ControlLegConfig,
    /// Leg 4 targets.
    pub leg4: ControlLegConfig,
    /// Leg 5 targets (hexapod).
    #[serde(skip_serializing_if = "ControlLegConfig::is_empty")]
    pub leg5: ControlLegConfig,
    /// Leg 6 targets (hexapod).
    #[serde(skip_serializing_if = "ControlLegConfig::is_empty")]
    pub leg6: ControlLegConfig,
}

impl ControlLegConfig {
    /// No key given.
    pub fn is_empty(&self) -> bool {
        self.times.is_none() && self.target_deg.is_none()
    }
}

fn pair(file: &str, key: &str, v: &[f64]) -> Result<[f64; 2], ConfigError> {
    match v {
        [a, b] if a.is_finite() && b.is_finite() => Ok([*a, *b]),
        [_, _] => Err(ConfigError::semantic(
            file,
            key,
            "must be finite",
            format!("{v:?}"),
            "finite values",
        )),
        _ => Err(ConfigError::semantic(
            file,
            key,
            "must be a pair [θ2, θ3]",
            format!("{v:?}"),
            "2 numbers",
        )),
    }
}

impl ControlConfig {
    /// The leg tables, leg 3 first.
    fn legs(&self) -> [(&'static str, &ControlLegConfig); 2] {
        [("leg3", &self.leg3), ("leg4", &self.leg4)]
    }

    /// Fills the `pd` targets left out with the initial joint angles
    /// `initial_deg[leg]`.
    pub fn resolve(&mut self, initial_deg: [[f64; 2]; 2]) {
        if self.kind == ControlKind::Pd {
            for (l, init) in [&mut self.leg3, &mut self.leg4]
                .into_iter()
                .zip(initial_deg)
            {
                l.target_deg
                    .get_or_insert_with(|| TargetDeg::Point(init.to_vec()));
            }
        }
    }

    /// Checks every key and builds the controller (radians); errors name
    /// `control.key`.
    pub fn control(&self, file: &str) -> Result<Control, ConfigError> {
        let (kp, kd, torque_limit) = (self.kp, self.kd, self.torque_limit);
        let invalid = |(key, what, got): (String, &'static str, String)| {
            ConfigError::semantic(file, &key, what, got, "see [control] in docs/reference.md")
        };
        let control = match self.kind {
            ControlKind::Gait => {
                return Err(ConfigError::semantic(
                    file,
                    "control.kind",
                    "\"gait\" is for model = \"hexapod\"",
                    "\"gait\"",
                    "\"none\", \"pd\" or \"trajectory\"",
                ));
            }
            // Passive joints do not use the gains, but a value out of its
            // domain is still an error (the rule is the one of PD).
            ControlKind::None => {
                Control::Pd {
                    kp,
                    kd,
                    torque_limit,
                    target: [[0.0; 2]; 2],
                }
                .validate()
                .map_err(invalid)?;
                Control::None
            }
            ControlKind::Pd => {
                let mut target = [[0.0; 2]; 2];
                for (i, (name, l)) in self.legs().into_iter().enumerate() {
                    let key = format!("control.{name}.target_deg");
                    if l.times.is_some() {
                        return Err(ConfigError::semantic(
                            file,
                            &format!("control.{name}.times"),
                            "is only used by kind = \"trajectory\"",
                            "a list",
                            "no times for kind = \"pd\"",
                        ));
                    }
                    target[i] = match &l.target_deg {
                        Some(TargetDeg::Point(v)) => pair(file, &key, v)?.map(f64::to_radians),
                        Some(TargetDeg::Points(v)) => {
                            return Err(ConfigError::semantic(
                                file,
                                &key,
                                "must be one pair [θ2, θ3] for kind = \"pd\"",
                                format!("{v:?}"),
                                "[θ2, θ3]",
                            ));
                        }
                        None => {
                            return Err(ConfigError::semantic(
                                file,
                                &key,
                                "is required for kind = \"pd\"",
                                "nothing",
                                "[θ2, θ3]",
                            ));
                        }
                    };
                }
                Control::Pd {
                    kp,
                    kd,
                    torque_limit,
                    target,
                }
            }
            ControlKind::Trajectory => {
                let mut legs = [LegTrajectory::default(), LegTrajectory::default()];
                for (i, (name, l)) in self.legs().into_iter().enumerate() {
                    let key = format!("control.{name}.target_deg");
                    let Some(times) = &l.times else {
                        return Err(ConfigError::semantic(
                            file,
                            &format!("control.{name}.times"),
                            "is required for kind = \"trajectory\"",
                            "nothing",
                            "a list of strictly increasing times",
                        ));
                    };
                    let targets: Vec<[f64; 2]> = match &l.target_deg {
                        Some(TargetDeg::Points(v)) => v
                            .iter()
                            .map(|p| pair(file, &key, p).map(|p| p.map(f64::to_radians)))
                            .collect::<Result<_, _>>()?,
                        // An empty list parses as a single (empty) point.
                        Some(TargetDeg::Point(v)) if v.is_empty() => Vec::new(),
                        Some(TargetDeg::Point(v)) => {
                            return Err(ConfigError::semantic(
                                file,
                                &key,
                                "must be a list of pairs for kind = \"trajectory\"",
                                format!("{v:?}"),
                                "[[θ2, θ3], ...]",
                            ));
                        }
                        None => {
                            return Err(ConfigError::semantic(
                                file,
                                &key,
                                "is required for kind = \"trajectory\"",
                                "nothing",
                                "[[θ2, θ3], ...]",
                            ));
                        }
                    };
                    if targets.len() != times.len() {
                        return Err(ConfigError::semantic(
                            file,
                            &key,
                            "must have one pair per time",
                            format!("{} pairs", targets.len()),
                            &format!("{} pairs (as many as control.{name}.times)", times.len()),
                        ));
                    }
                    legs[i] = LegTrajectory {
                        times: times.clone(),
                        targets,
                    };
                }
                Control::Trajectory {
                    kp,
                    kd,
                    torque_limit,
                    legs,
                }
            }
        };
        control.validate().map_err(invalid)?;
        Ok(control)
    }
}

/// Keys of `[terrain]` each kind uses (besides `kind`, `mu_static`,
/// `mu_dynamic`).
fn terrain_keys(kind: TerrainKind) -> &'static [&'static str] {
    match kind {
        TerrainKind::None => &[],
        TerrainKind::Flat => &["height"],
        TerrainKind::Slope => &["angle_deg", "height"],
        TerrainKind::Profile => &["points", "file"],
        TerrainKind::Sine => &["amplitude", "wavelength", "phase_deg", "height"],
        TerrainKind::Steps => &["step_height", "step_width", "height"],
        TerrainKind::Heightfield => &["file", "size", "center", "elevation"],
        TerrainKind::Random => &[
            "amplitude",
            "wavelength",
            "seed",
            "size",
            "center",
            "resolution",
            "height",
        ],
        TerrainKind::Stairs => &[
            "tread",
            "riser",
            "heading_deg",
            "count",
            "origin",
            "size",
            "center",
            "resolution",
            "edge_radius",
            "height",
        ],
        TerrainKind::Stones => &[
            "stone",
            "gap",
            "depth",
            "amplitude",
            "seed",
            "size",
            "center",
            "resolution",
            "edge_radius",
            "height",
        ],
        TerrainKind::Pyramids => &[
            "amplitude",
            "wavelength",
            "size",
            "center",
            "resolution",
            "edge_radius",
            "height",
        ],
        TerrainKind::Sines => &[
            "amplitude",
            "wavelength",
            "size",
            "center",
            "resolution",
            "height",
        ],
    }
}

fn kind_name(kind: TerrainKind) -> &'static str {
    match kind {
        TerrainKind::None => "none",
        TerrainKind::Flat => "flat",
        TerrainKind::Slope => "slope",
        TerrainKind::Profile => "profile",
        TerrainKind::Sine => "sine",
        TerrainKind::Steps => "steps",
        TerrainKind::Heightfield => "heightfield",
        TerrainKind::Random => "random",
        TerrainKind::Stairs => "stairs",
        TerrainKind::Stones => "stones",
        TerrainKind::Pyramids => "pyramids",
        TerrainKind::Sines => "sines",
    }
}

impl TerrainConfig {
    /// Fills optional keys of the kind in use (`phase_deg = 0` for a sine).
    pub fn resolve_kind(&mut self) {
        if self.kind == TerrainKind::Sine {
            self.phase_deg.get_or_insert(0.0);
        }
    }

    /// Replaces `file = "..."` by the `points` it holds: a CSV of `x,y`
    /// lines (blank lines, `#` comments and a non-numeric header skipped),
    /// relative to the directory of `config_file`. The complete
    /// configuration written back then holds the points themselves.
    pub fn load_profile_file(&mut self, config_file: &str) -> Result<(), ConfigError> {
        if self.kind == TerrainKind::Heightfield {
            return Ok(()); // a height map ([`TerrainConfig::load_map`])
        }
        let Some(name) = self.file.take() else {
            return Ok(());
        };
        if self.points.is_some() {
            return Err(ConfigError::semantic(
                config_file,
                "terrain.file",
                "cannot be given together with terrain.points",
                &name,
                "either points or file",
            ));
        }
        let path = Path::new(config_file)
            .parent()
            .unwrap_or(Path::new(""))
            .join(&name);
        let text = crate::read_text(&path).map_err(|e| {
            ConfigError::semantic(
                config_file,
                "terrain.file",
                &format!("cannot read it: {e}"),
                &name,
                "a readable CSV of x,y lines",
            )
        })?;
        let mut points = Vec::new();
        for (n, line) in text.lines().enumerate() {
            let line = line.split('#').next().unwrap_or("").trim();
            if line.is_empty() {
                continue;
            }
            let fields: Vec<&str> = line.split(',').map(str::trim).collect();
            let parsed: Result<Vec<f64>, _> = fields.iter().map(|f| f.parse::<f64>()).collect();
            match parsed {
                Ok(v) if v.len() == 2 => points.push(v),
                Err(_) if points.is_empty() && n == 0 => continue, // header
                _ => {
                    return Err(ConfigError::semantic(
                        config_file,
                        "terrain.file",
                        &format!("{}:{}: expected `x,y`", path.display(), n + 1),
                        line,
                        "two numbers per line",
                    ));
                }
            }
        }
        self.points = Some(points);
        Ok(())
    }

    /// Checks the keys of the terrain kind; errors name `terrain.key`.
    pub fn validate_kind(&self, file: &str) -> Result<(), ConfigError> {
        let used = terrain_keys(self.kind);
        let given: [(&str, bool); 22] = [
            ("angle_deg", self.angle_deg.is_some()),
            ("points", self.points.is_some()),
            ("file", self.file.is_some()),
            ("amplitude", self.amplitude.is_some()),
            ("wavelength", self.wavelength.is_some()),
            ("phase_deg", self.phase_deg.is_some()),
            ("step_height", self.step_height.is_some()),
            ("step_width", self.step_width.is_some()),
            ("size", self.size.is_some()),
            ("center", self.center.is_some()),
            ("elevation", self.elevation.is_some()),
            ("resolution", self.resolution.is_some()),
            ("edge_radius", self.edge_radius.is_some()),
            ("seed", self.seed.is_some()),
            ("tread", self.tread.is_some()),
            ("riser", self.riser.is_some()),
            ("heading_deg", self.heading_deg.is_some()),
            ("count", self.count.is_some()),
            ("origin", self.origin.is_some()),
            ("stone", self.stone.is_some()),
            ("gap", self.gap.is_some()),
            ("depth", self.depth.is_some()),
        ];
        let kind = kind_name(self.kind);
        for (key, is_given) in given {
            if is_given && !used.contains(&key) {
                return Err(ConfigError::semantic(
                    file,
                    &format!("terrain.{key}"),
                    &format!("is not used by kind = \"{kind}\""),
                    "a value",
                    &format!("only {used:?}"),
                ));
            }
        }
        let required: &[(&str, bool)] = match self.kind {
            TerrainKind::Slope => &[("angle_deg", self.angle_deg.is_some())],
            TerrainKind::Profile => &[("points", self.points.is_some())],
            TerrainKind::Sine => &[
                ("amplitude", self.amplitude.is_some()),
                ("wavelength", self.wavelength.is_some()),
            ],
            TerrainKind::Steps => &[
                ("step_height", self.step_height.is_some()),
                ("step_width", self.step_width.is_some()),
            ],
            TerrainKind::Heightfield => {
                &[("file", self.file.is_some()), ("size", self.size.is_some())]
            }
            TerrainKind::Random | TerrainKind::Pyramids | TerrainKind::Sines => &[
                ("amplitude", self.amplitude.is_some()),
                ("wavelength", self.wavelength.is_some()),
            ],
            TerrainKind::Stairs => &[
                ("tread", self.tread.is_some()),
                ("riser", self.riser.is_some()),
            ],
            TerrainKind::Stones => &[
                ("stone", self.stone.is_some()),
                ("gap", self.gap.is_some()),
                ("depth", self.depth.is_some()),
            ],
            TerrainKind::None | TerrainKind::Flat => &[],
        };
        for (key, ok) in required {
            if !ok {
                return Err(ConfigError::semantic(
                    file,
                    &format!("terrain.{key}"),
                    &format!("is required for kind = \"{kind}\""),
                    "nothing",
                    "a value",
                ));
            }
        }
        if let Some(a) = self.angle_deg
            && !(a.is_finite() && a.abs() < 90.0)
        {
            return Err(ConfigError::semantic(
                file,
                "terrain.angle_deg",
                "must be finite and steeper than neither vertical",
                a,
                "-90 < angle_deg < 90",
            ));
        }
        if let Some(points) = &self.points {
            for p in points {
                if p.len() != 2 {
                    return Err(ConfigError::semantic(
                        file,
                        "terrain.points",
                        "must be [x, y] pairs",
                        format!("{p:?}"),
                        "2 numbers per point",
                    ));
                }
            }
        }
        if let Err(e) = self.terrain().validate() {
            return Err(ConfigError::semantic(
                file,
                &format!("terrain.{}", e.key),
                e.what,
                e.got,
                e.expected,
            ));
        }
        Ok(())
    }

    /// The simulator's terrain of the non-flat kinds (radians, pairs).
    pub(super) fn terrain_kind(&self) -> Terrain {
        let height = self.height;
        match self.kind {
            TerrainKind::None => Terrain::None,
            TerrainKind::Flat => Terrain::Flat { height },
            TerrainKind::Slope => Terrain::slope_deg(self.angle_deg.unwrap_or(0.0), height),
            TerrainKind::Profile => Terrain::Profile {
                points: self
                    .points
                    .iter()
                    .flatten()
                    .map(|p| {
                        [
                            p.first().copied().unwrap_or(f64::NAN),
                            p.get(1).copied().unwrap_or(f64::NAN),
                        ]
                    })
                    .collect(),
            },
            TerrainKind::Sine => Terrain::Sine {
                amplitude: self.amplitude.unwrap_or(0.0),
                wavelength: self.wavelength.unwrap_or(f64::NAN),
                phase: self.phase_deg.unwrap_or(0.0).to_radians(),
                height,
            },
            TerrainKind::Steps => Terrain::Steps {
                step_height: self.step_height.unwrap_or(0.0),
                step_width: self.step_width.unwrap_or(f64::NAN),
                height,
            },
            // Height maps: [`TerrainConfig::terrain`] takes their section.
            TerrainKind::Heightfield
            | TerrainKind::Random
            | TerrainKind::Stairs
            | TerrainKind::Stones
            | TerrainKind::Pyramids
            | TerrainKind::Sines => Terrain::Flat { height },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::{Config, parse_str};

    fn err(text: &str) -> String {
        parse_str(text, "c.toml", &[]).unwrap_err().to_string()
    }

    #[test]
    fn control_and_terrain_round_trip() {
        for text in [
            "[control]\nkind = \"pd\"\nkp = 100.0\nkd = 2.0\ntorque_limit = 30.0\n[control.leg3]\ntarget_deg = [1.0, 250.0]\n[terrain]\nkind = \"slope\"\nangle_deg = 10.0\n",
            "[control]\nkind = \"trajectory\"\nkp = 100.0\nkd = 2.0\n[control.leg3]\ntimes = [0.0, 0.5]\ntarget_deg = [[0.0, 245.0], [5.0, 250.0]]\n[control.leg4]\ntimes = [0.1]\ntarget_deg = [[0.0, 255.0]]\n[terrain]\nkind = \"sine\"\namplitude = 0.01\nwavelength = 0.5\nheight = -0.1\n",
            "[terrain]\nkind = \"steps\"\nstep_height = 0.02\nstep_width = 0.3\nheight = -0.1\n",
            "[terrain]\nkind = \"profile\"\npoints = [[-1.0, -0.1], [0.0, -0.05], [1.0, -0.1]]\n",
        ] {
            let c = parse_str(text, "c.toml", &[]).unwrap();
            let full = c.to_toml();
            assert!(full.contains("[control]"), "{full}");
            let again = parse_str(&full, "full.toml", &[]).unwrap();
            assert_eq!(c, again, "{full}");
            assert_eq!(full, again.to_toml());
            let Config::Planar(p) = again else {
                unreachable!()
            };
            assert_eq!(
                p.params(),
                match &c {
                    Config::Planar(q) => q.params(),
                    _ => unreachable!(),
                }
            );
        }
    }

    #[test]
    fn pd_targets_default_to_the_initial_angles() {
        let Config::Planar(c) =
            parse_str("[control]\nkind = \"pd\"\nkp = 1.0\n", "c.toml", &[]).unwrap()
        else {
            unreachable!()
        };
        let p = c.params();
        let fbd_sim::Control::Pd { target, .. } = p.control else {
            panic!("{:?}", p.control)
        };
        assert_eq!(target, [[p.q0[3], p.q0[4]], [p.q0[5], p.q0[6]]]);
    }

    #[test]
    fn errors_name_the_key() {
        assert!(err("[control]\nkind = \"pd\"\nkp = -1.0\n").contains("control.kp"));
        // Unused by passive joints, but still out of its domain.
        assert!(err("[control]\nkind = \"none\"\nkp = nan\n").contains("control.kp"));
        assert!(err("[control]\nkind = \"pd\"\nkd = -1.0\n").contains("control.kd"));
        assert!(
            err("[control]\nkind = \"pd\"\ntorque_limit = 0.0\n").contains("control.torque_limit")
        );
        assert!(
            err("[control]\nkind = \"pd\"\n[control.leg4]\ntarget_deg = [1.0]\n")
                .contains("control.leg4.target_deg")
        );
        let e = err(
            "[control]\nkind = \"trajectory\"\n[control.leg3]\ntimes = [0.0, 0.0]\ntarget_deg = [[0.0, 1.0], [0.0, 1.0]]\n[control.leg4]\ntimes = [0.0]\ntarget_deg = [[0.0, 1.0]]\n",
        );
        assert!(
            e.contains("control.leg3.times") && e.contains("strictly increasing"),
            "{e}"
        );
        let e = err(
            "[control]\nkind = \"trajectory\"\n[control.leg3]\ntimes = [0.0, 1.0]\ntarget_deg = [[0.0, 1.0]]\n[control.leg4]\ntimes = [0.0]\ntarget_deg = [[0.0, 1.0]]\n",
        );
        assert!(e.contains("control.leg3.target_deg"), "{e}");
        assert!(err("[control]\nkind = \"trajectory\"\n").contains("control.leg3.times"));
        assert!(
            err("[terrain]\nkind = \"sine\"\namplitude = 0.1\nwavelength = 0.0\n")
                .contains("terrain.wavelength")
        );
        assert!(
            err("[terrain]\nkind = \"sine\"\namplitude = 0.1\n").contains("terrain.wavelength")
        );
        assert!(
            err("[terrain]\nkind = \"steps\"\nstep_height = 0.1\nstep_width = -1.0\n")
                .contains("terrain.step_width")
        );
        assert!(
            err("[terrain]\nkind = \"profile\"\npoints = [[0.0, 0.0], [0.0, 1.0]]\n")
                .contains("terrain.points")
        );
        assert!(
            err("[terrain]\nkind = \"profile\"\npoints = [[0.0, 0.0]]\n")
                .contains("terrain.points")
        );
        assert!(
            err("[terrain]\nkind = \"slope\"\nangle_deg = 95.0\n").contains("terrain.angle_deg")
        );
        assert!(err("[terrain]\nkind = \"flat\"\namplitude = 0.1\n").contains("terrain.amplitude"));
    }

    #[test]
    fn profile_file_is_read_relative_to_the_config() {
        let dir = std::env::temp_dir().join(format!("fbd-profile-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("terrain.csv"),
            "x,y\n-1.0,-0.2\n# comment\n0.0,-0.1\n2.0,-0.3\n",
        )
        .unwrap();
        let cfg = dir.join("c.toml");
        std::fs::write(
            &cfg,
            "[terrain]\nkind = \"profile\"\nfile = \"terrain.csv\"\n",
        )
        .unwrap();
        let c = super::super::load(&cfg).unwrap();
        let Config::Planar(p) = &c else {
            unreachable!()
        };
        assert_eq!(
            p.terrain.points,
            Some(vec![vec![-1.0, -0.2], vec![0.0, -0.1], vec![2.0, -0.3]])
        );
        assert!(p.terrain.file.is_none() && c.to_toml().contains("points"));
        std::fs::remove_dir_all(&dir).unwrap();
    }
}

//! `fbd kinematics CONFIG`: hip, knee and tip of every leg at the initial
//! state, inertial frame, as JSON (docs/reference.md, "Command line"); for
//! an imported robot (`model = "robot"`) every body, joint and contact
//! point ([`fbd_scenario::robot::RobotKinematics`]).

use std::io::Write;
use std::path::Path;

use fbd_kinematics::hexapod::{HexapodData, HexapodModel, forward};
use fbd_kinematics::leg::LegGeometry;
use fbd_kinematics::planar::{PlanarChains, PlanarGeometry};
use fbd_kinematics::pose::BodyPose;
use serde::Serialize;

use crate::OutputError;
use crate::config::{self, Config, HexapodConfig, PlanarConfig};

/// The points of one leg (m, inertial frame).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LegPoints {
    /// Hexapod leg number (1–6).
    pub leg: usize,
    /// Hip.
    pub hip: [f64; 3],
    /// Knee.
    pub knee: [f64; 3],
    /// Tip (foot).
    pub tip: [f64; 3],
}

/// The JSON document `{"legs": [...]}`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Kinematics {
    /// One entry per leg of the model.
    pub legs: Vec<LegPoints>,
}

/// Planar geometry of a configuration.
pub fn planar_geometry(c: &PlanarConfig) -> PlanarGeometry {
    PlanarGeometry {
        d: c.body.side * (std::f64::consts::PI / 6.0).cos(),
        a: c.leg.upper_length,
        c: c.leg.lower_length,
        upper_com: c.leg.upper_com,
        lower_com: c.leg.lower_com,
    }
}

/// Hip, knee and tip of legs 3 and 4 for planar coordinates `q` (z = 0).
pub fn planar_points(geometry: &PlanarGeometry, q: &[f64]) -> Vec<LegPoints> {
    let (chains, ix) = PlanarChains::two_leg(geometry);
    let mut data = chains.new_data();
    chains.eval_positions(q, &mut data);
    let p = |i: usize| [data.pos[i][0], data.pos[i][1], 0.0];
    (0..2)
        .map(|leg| LegPoints {
            leg: fbd_kinematics::planar::hexapod_leg_number(leg),
            hip: p(ix.hip[leg]),
            knee: p(ix.knee[leg]),
            tip: p(ix.tip[leg]),
        })
        .collect()
}

/// Hip, knee and tip of the six legs of a hexapod configuration.
pub fn hexapod_points(c: &HexapodConfig) -> Vec<LegPoints> {
    let model = HexapodModel::new(
        c.body.side,
        LegGeometry {
            a: c.leg.upper_length,
            c: c.leg.lower_length,
        },
        c.leg.upper_com,
        c.leg.lower_com,
    );
    let cfg = fbd_kinematics::hexapod::HexapodConfig {
        pose: BodyPose::new(c.initial.position, c.phi_rad()),
        joints: c.joints_rad(),
    };
    let mut data = HexapodData::new();
    forward(&model, &cfg, &mut data);
    data.legs
        .iter()
        .enumerate()
        .map(|(i, l)| LegPoints {
            leg: i + 1,
            hip: l.hip.into(),
            knee: l.knee.into(),
            tip: l.tip.into(),
        })
        .collect()
}

/// The initial kinematics of a (validated) configuration.
pub fn initial_kinematics(config: &Config) -> Kinematics {
    let legs = match config {
        Config::Planar(c) => planar_points(&planar_geometry(c), &c.params().q0),
        Config::Hexapod(h) => hexapod_points(h),
    };
    Kinematics { legs }
}

impl Kinematics {
    /// The JSON text: `{"legs": [` then one leg object per line, then
    /// `]}`; numbers with full round-trip precision.
    pub fn to_json(&self) -> String {
        let legs: Vec<String> = self
            .legs
            .iter()
            .map(|l| serde_json::to_string(l).unwrap_or_else(|e| format!("{{\"error\": \"{e}\"}}")))
            .collect();
        format!("{{\"legs\": [\n  {}\n]}}\n", legs.join(",\n  "))
    }
}

/// `value` (an object) with one key per line and, for an array, one item
/// per line; each item compact, numbers round-trip exact.
fn one_item_per_line(value: &serde_json::Value) -> String {
    let Some(map) = value.as_object() else {
        return format!("{value}\n");
    };
    let fields: Vec<String> = map
        .iter()
        .map(|(k, v)| match v.as_array() {
            Some(items) if !items.is_empty() && items.iter().all(|i| i.is_object()) => {
                let items: Vec<String> = items.iter().map(|i| format!("    {i}")).collect();
                format!("  \"{k}\": [\n{}\n  ]", items.join(",\n"))
            }
            _ => format!("  \"{k}\": {v}"),
        })
        .collect();
    format!("{{\n{}\n}}\n", fields.join(",\n"))
}

/// `fbd kinematics CONFIG`.
pub fn kinematics_command(path: &Path, out: &mut dyn Write) -> Result<(), OutputError> {
    let text = config::read_text(path)?;
    let json = if config::robot::is_robot(&text) {
        let robot = config::robot::load_str(&text, path)?;
        let value = serde_json::to_value(robot.kinematics())
            .map_err(|e| OutputError::stdout(std::io::Error::other(e)))?;
        one_item_per_line(&value)
    } else {
        initial_kinematics(&config::load(path)?).to_json()
    };
    out.write_all(json.as_bytes())
        .and_then(|()| out.flush())
        .map_err(OutputError::stdout)
}

/// `fbd inverse CONFIG [--motion FILE [--out FILE]]` (an imported robot's
/// configuration).
pub fn inverse_command(
    path: &Path,
    motion: Option<&Path>,
    out_file: Option<&Path>,
    out: &mut dyn Write,
) -> Result<(), OutputError> {
    let text = config::read_text(path)?;
    if !config::robot::is_robot(&text) {
        return Err(config::ConfigError::Semantic {
            file: path.display().to_string(),
            message: "fbd inverse takes a model = \"robot\" configuration (an imported \
                      URDF or MJCF robot)"
                .to_owned(),
        }
        .into());
    }
    let robot = config::robot::load_str(&text, path)?;
    let Some(motion_path) = motion else {
        if out_file.is_some() {
            return Err(OutputError::Usage(
                "fbd inverse: --out writes the CSV of --motion; give --motion FILE".to_owned(),
            ));
        }
        let value = serde_json::to_value(robot.inverse())
            .map_err(|e| OutputError::stdout(std::io::Error::other(e)))?;
        return out
            .write_all(one_item_per_line(&value).as_bytes())
            .and_then(|()| out.flush())
            .map_err(OutputError::stdout);
    };
    let motion_text = config::read_text(motion_path)?;
    let motion = robot.read_motion(&motion_text, &motion_path.display().to_string())?;
    let rows = robot.inverse_along(&motion);
    let mut csv = robot.inverse_columns().join(",");
    csv.push('\n');
    for row in &rows {
        let cells: Vec<String> = row.iter().map(|x| format!("{x}")).collect();
        csv.push_str(&cells.join(","));
        csv.push('\n');
    }
    match out_file {
        Some(dest) => {
            let dir = dest
                .parent()
                .filter(|d| !d.as_os_str().is_empty())
                .unwrap_or(Path::new("."));
            let mut tmp = crate::output::temp_in(dir, "inverse.csv")?;
            tmp.write_all(csv.as_bytes())
                .and_then(|()| tmp.flush())
                .map_err(|e| OutputError::io(dest.display(), &e))?;
            crate::output::persist(tmp, dest)
        }
        None => out
            .write_all(csv.as_bytes())
            .and_then(|()| out.flush())
            .map_err(OutputError::stdout),
    }
}

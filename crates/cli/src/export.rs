//! `fbd export mjcf CONFIG [--out FILE]`: the hexapod of a configuration
//! as a MuJoCo model (the XML is written by
//! [`fbd_scenario::mjcf::mjcf`]; this module parses and prints).

use std::io::Write;
use std::path::{Path, PathBuf};

use clap::{Args, Subcommand};

use crate::CliError;
use crate::config::{self, Config};

/// The formats of `fbd export`.
#[derive(Debug, Subcommand)]
pub enum ExportFormat {
    /// The hexapod of a `model = "hexapod"` configuration as a MuJoCo MJCF
    /// model: bodies, inertias, joints (qpos = fbd's joint angles), sphere
    /// feet (and knees and hips when in `[contact] points`), position
    /// servos with the controller's gains, ground plane, Δt, gravity and
    /// the initial state as the keyframe "initial".
    Mjcf(MjcfArgs),
}

/// Arguments of `fbd export mjcf`.
#[derive(Debug, Args)]
pub struct MjcfArgs {
    /// TOML configuration of the hexapod (every key: docs/reference.md).
    #[arg(value_name = "CONFIG")]
    pub config: PathBuf,
    /// Write the model to FILE (all-or-nothing) instead of stdout.
    #[arg(short, long, value_name = "FILE")]
    pub out: Option<PathBuf>,
}

/// `fbd export FORMAT ...`.
pub fn export_command(format: ExportFormat, out: &mut dyn Write) -> Result<(), CliError> {
    match format {
        ExportFormat::Mjcf(a) => mjcf_command(&a.config, a.out.as_deref(), out),
    }
}

/// `fbd export mjcf CONFIG [--out FILE]`.
pub fn mjcf_command(path: &Path, dest: Option<&Path>, out: &mut dyn Write) -> Result<(), CliError> {
    let file = path.display().to_string();
    let text = config::read_text(path)?;
    if config::robot::is_robot(&text) {
        let robot = config::robot::load_str(&text, path)?;
        return write_out(&robot.mjcf(), dest, out);
    }
    let hexapod = match config::load(path)? {
        Config::Hexapod(h) => h,
        Config::Planar(_) => {
            return Err(CliError::Usage(format!(
                "{file}: model: `fbd export mjcf` exports the hexapod (got \"planar\", \
                 expected model = \"hexapod\")"
            )));
        }
    };
    let params = hexapod.spatial_params(&file)?;
    let xml = config::mjcf::mjcf(&params, &file)?;
    write_out(&xml, dest, out)
}

/// Writes `xml` to `dest` (all or nothing) or to `out`.
fn write_out(xml: &str, dest: Option<&Path>, out: &mut dyn Write) -> Result<(), CliError> {
    match dest {
        None => out
            .write_all(xml.as_bytes())
            .and_then(|()| out.flush())
            .map_err(CliError::stdout),
        Some(dest) => {
            let name = dest
                .file_name()
                .ok_or_else(|| CliError::Usage(format!("{}: not a file name", dest.display())))?
                .to_string_lossy()
                .into_owned();
            let dir = match dest.parent() {
                Some(p) if !p.as_os_str().is_empty() => p,
                _ => Path::new("."),
            };
            crate::output::write_file(dir, &name, xml.as_bytes())?;
            Ok(())
        }
    }
}

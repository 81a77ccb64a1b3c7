//! The command line (clap derive) and the dispatch to the commands.

use std::io::Write;
use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

use crate::CliError;

/// fbd: legged-robot simulator by the Free Body Diagram method.
///
/// Simulates the planar two-leg model of the paper's §6 (a hexapod
/// falling onto flat ground, legs 3 and 4), writing trajectories, contact
/// events and the plots of the paper's Fig. 7, and the 24-DOF hexapod
/// (`model = "hexapod"`): its 3D FBD dynamics with contact, friction and
/// joint control (standing, dropping, or walking a periodic gait tracked by
/// the joint controllers), or the gait alone, kinematically (`[gait]`
/// without `[control] kind = "gait"`). Every run writes a viewer.html to
/// open in a browser. Without a command, `fbd`
/// is `fbd run`: the built-in experiment, files in out/ (or --out DIR).
/// Exit status: 0 ok, 2 usage or configuration error, 3 simulation failed
/// (partial files written), 4 input/output error, 130 interrupted
/// (Ctrl-C; the steps computed so far are written). Every key, file and
/// column: docs/reference.md.
#[derive(Debug, Parser)]
#[command(
    name = "fbd",
    version,
    propagate_version = true,
    args_conflicts_with_subcommands = true
)]
pub struct Cli {
    /// The command to run (default: run).
    #[command(subcommand)]
    pub command: Option<Command>,
    /// Output directory of the built-in experiment when no command is
    /// given.
    #[arg(short, long, value_name = "DIR", default_value = "out")]
    pub out: PathBuf,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate a configuration (default: the built-in experiment) and
    /// write trajectory.csv, events.csv, summary.json, config.toml, the
    /// plots and viewer.html to DIR.
    Run(RunArgs),
    /// Print the inertial hip, knee and tip of every leg at the
    /// configuration's initial state, as JSON.
    Kinematics(KinematicsArgs),
    /// Inverse dynamics of an imported robot (`model = "robot"`) by the
    /// FBD method: every joint's force, moment and torque, and the root's
    /// external wrench, for the configuration's state and `[inverse]`
    /// accelerations (JSON), or along a recorded motion (`--motion`, CSV).
    Inverse(InverseArgs),
    /// Run many variations of a configuration in parallel (see
    /// docs/sweep.md): DIR/runs/<i>/, DIR/index.csv, DIR/sweep.svg;
    /// `fbd sweep merge` joins shard directories.
    Sweep(crate::sweep::SweepArgs),
    /// Write DIR/viewer.html, the animated viewer of a finished run, from
    /// DIR/config.toml, DIR/trajectory.csv and DIR/events.csv (`fbd run`
    /// writes it too); open it in a browser, no network needed.
    View(ViewArgs),
    /// Write a configuration's robot in another simulator's format:
    /// `fbd export mjcf CONFIG [--out FILE]`, the hexapod as a MuJoCo
    /// model (stdout by default).
    #[command(subcommand)]
    Export(crate::export::ExportFormat),
}

/// Arguments of `fbd view`.
#[derive(Debug, Args)]
pub struct ViewArgs {
    /// Output folder of `fbd run`.
    #[arg(value_name = "DIR")]
    pub dir: PathBuf,
}

/// Arguments of `fbd run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// TOML configuration, planar or hexapod (every key:
    /// docs/reference.md). Without it: the built-in default, the paper's
    /// falling experiment.
    #[arg(value_name = "CONFIG")]
    pub config: Option<PathBuf>,
    /// Output directory, created if needed.
    #[arg(short, long, value_name = "DIR", default_value = "out")]
    pub out: PathBuf,
    /// Set a key of the configuration (repeatable, applied in order):
    /// `--set time.dt=0.0005 --set time.duration=5`. VALUE is a TOML
    /// value (`0.5`, `[0.0, 0.6]`, `true`, `"flat"`), or a string when it
    /// is not one. The written config.toml holds the result.
    #[arg(long = "set", value_name = "KEY=VALUE", value_parser = crate::Override::parse)]
    pub set: Vec<crate::Override>,
}

/// Arguments of `fbd kinematics`.
#[derive(Debug, Args)]
pub struct KinematicsArgs {
    /// TOML configuration (planar, hexapod or robot).
    #[arg(value_name = "CONFIG")]
    pub config: PathBuf,
}

/// Arguments of `fbd inverse`.
#[derive(Debug, Args)]
pub struct InverseArgs {
    /// TOML configuration of an imported robot (`model = "robot"`).
    #[arg(value_name = "CONFIG")]
    pub config: PathBuf,
    /// A recorded motion (CSV: `t`, one column per joint in rad, optional
    /// `rx, ry, rz, phi_x, phi_y, phi_z`): the forces at every interior
    /// sample, velocities and accelerations by central differences, as CSV.
    #[arg(long, value_name = "FILE")]
    pub motion: Option<PathBuf>,
    /// Where the CSV of `--motion` goes (default stdout).
    #[arg(long, value_name = "FILE")]
    pub out: Option<PathBuf>,
}

/// Runs the parsed command, printing its normal output to `out`.
pub fn dispatch(cli: Cli, out: &mut dyn Write) -> Result<(), CliError> {
    match cli.command {
        None => crate::run::run_command(None, &cli.out, out),
        Some(Command::Run(a)) => {
            crate::run::run_command_with(a.config.as_deref(), &a.set, &a.out, out)
        }
        Some(Command::Kinematics(a)) => crate::kinematics::kinematics_command(&a.config, out),
        Some(Command::Inverse(a)) => crate::kinematics::inverse_command(
            &a.config,
            a.motion.as_deref(),
            a.out.as_deref(),
            out,
        ),
        Some(Command::Sweep(a)) => crate::sweep::sweep_command(a, out),
        Some(Command::View(a)) => crate::viewer::view::view_command(&a.dir, out),
        Some(Command::Export(f)) => crate::export::export_command(f, out),
    }
}

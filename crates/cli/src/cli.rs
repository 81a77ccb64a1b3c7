//! The command line (clap derive) and the dispatch to the commands.

use std::io::Write;
use std::path::PathBuf;

use clap::{Args, Parser, Subcommand};

use crate::CliError;

/// fbd: legged-robot simulator by the Free Body Diagram method.
///
/// Simulates the planar two-leg model of the paper's §6 (a hexapod
/// falling onto flat ground, legs 3 and 4), writing trajectories, contact
/// events and the plots of the paper's Fig. 7. Exit status: 0 ok, 2 usage
/// or configuration error, 3 simulation failed (partial files written),
/// 4 input/output error.
#[derive(Debug, Parser)]
#[command(
    name = "fbd",
    version,
    propagate_version = true,
    arg_required_else_help = true
)]
pub struct Cli {
    /// The command to run.
    #[command(subcommand)]
    pub command: Command,
}

/// The subcommands.
#[derive(Debug, Subcommand)]
pub enum Command {
    /// Simulate a configuration and write trajectory.csv, events.csv,
    /// summary.json, config.toml, tips.svg, forces.svg and stance.svg.
    Run(RunArgs),
    /// Print the inertial hip, knee and tip of every leg at the
    /// configuration's initial state, as JSON.
    Kinematics(KinematicsArgs),
    /// Run many variations of a configuration in parallel (see
    /// docs/sweep.md): DIR/runs/<i>/, DIR/index.csv, DIR/sweep.svg;
    /// `fbd sweep merge` joins shard directories.
    Sweep(crate::sweep::SweepArgs),
}

/// Arguments of `fbd run`.
#[derive(Debug, Args)]
pub struct RunArgs {
    /// TOML configuration (SPEC §4). Without it: the built-in default, the
    /// paper's falling experiment.
    #[arg(value_name = "CONFIG")]
    pub config: Option<PathBuf>,
    /// Output directory, created if needed.
    #[arg(short, long, value_name = "DIR", default_value = "out")]
    pub out: PathBuf,
}

/// Arguments of `fbd kinematics`.
#[derive(Debug, Args)]
pub struct KinematicsArgs {
    /// TOML configuration (planar or hexapod).
    #[arg(value_name = "CONFIG")]
    pub config: PathBuf,
}

/// Runs the parsed command, printing its normal output to `out`.
pub fn dispatch(cli: Cli, out: &mut dyn Write) -> Result<(), CliError> {
    match cli.command {
        Command::Run(a) => crate::run::run_command(a.config.as_deref(), &a.out, out),
        Command::Kinematics(a) => crate::kinematics::kinematics_command(&a.config, out),
        Command::Sweep(a) => crate::sweep::sweep_command(a, out),
    }
}

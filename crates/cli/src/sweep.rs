//! `fbd sweep`: its command line. The sweep itself, its files and `fbd
//! sweep merge` live in [`fbd_output::sweep`], re-exported here.

use std::io::Write;
use std::path::PathBuf;

use clap::{Args, Subcommand};

pub use fbd_output::sweep::*;

use crate::CliError;

/// Arguments of `fbd sweep` (converted into
/// [`fbd_output::sweep::SweepArgs`]).
#[derive(Debug, Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct SweepArgs {
    /// `fbd sweep merge DIR... --out DIR`.
    #[command(subcommand)]
    pub command: Option<SweepCommand>,
    /// The sweep file (TOML: base, mode, samples, seed, [vary], [set],
    /// [derive]; docs/sweep.md).
    #[arg(value_name = "SWEEP", required = true)]
    pub sweep: Option<PathBuf>,
    /// Output directory, created if needed.
    #[arg(short, long, value_name = "DIR", default_value = "sweep")]
    pub out: PathBuf,
    /// Runs at a time (default: every core).
    #[arg(short, long, value_name = "N")]
    pub jobs: Option<usize>,
    /// Run only the indices with `index % N == I` (0 ≤ I < N).
    #[arg(long, value_name = "I/N")]
    pub shard: Option<String>,
    /// Skip runs whose directory holds a finished run with status ok.
    #[arg(long)]
    pub resume: bool,
    /// Column of index.csv plotted in sweep.svg (touchdown: the first
    /// touchdown of either tip).
    #[arg(long, value_name = "COLUMN", default_value = "touchdown")]
    pub plot: String,
    /// Write each run's viewer.html (some 0.8 MB a run; off by default:
    /// `fbd view runs/<i>` writes one later).
    #[arg(long)]
    pub viewer: bool,
    /// Write each run's plots (*.svg; off by default).
    #[arg(long)]
    pub plots: bool,
}

/// Subcommands of `fbd sweep`.
#[derive(Debug, Subcommand)]
pub enum SweepCommand {
    /// Combine shard directories into one (runs/<i>, one index.csv) and
    /// report missing runs.
    Merge(MergeArgs),
}

/// Arguments of `fbd sweep merge`.
#[derive(Debug, Args)]
pub struct MergeArgs {
    /// Shard output directories.
    #[arg(value_name = "DIR", required = true)]
    pub dirs: Vec<PathBuf>,
    /// The merged directory, created if needed.
    #[arg(short, long, value_name = "DIR")]
    pub out: PathBuf,
    /// Column plotted in the merged sweep.svg.
    #[arg(long, value_name = "COLUMN", default_value = "touchdown")]
    pub plot: String,
}

impl From<SweepArgs> for fbd_output::sweep::SweepArgs {
    fn from(a: SweepArgs) -> Self {
        Self {
            command: a
                .command
                .map(|SweepCommand::Merge(m)| fbd_output::sweep::SweepCommand::Merge(m.into())),
            sweep: a.sweep,
            out: a.out,
            jobs: a.jobs,
            shard: a.shard,
            resume: a.resume,
            plot: a.plot,
            viewer: a.viewer,
            plots: a.plots,
        }
    }
}

impl From<MergeArgs> for fbd_output::sweep::MergeArgs {
    fn from(m: MergeArgs) -> Self {
        Self {
            dirs: m.dirs,
            out: m.out,
            plot: m.plot,
        }
    }
}

/// `fbd sweep SWEEP.toml` or `fbd sweep merge DIR... --out DIR`.
pub fn sweep_command(a: SweepArgs, out: &mut dyn Write) -> Result<(), CliError> {
    fbd_output::sweep::sweep_command(a.into(), out)
}

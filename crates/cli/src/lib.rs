//! # fbd-cli
//!
//! The command-line front end of the simulator (docs/reference.md): the
//! command line ([`cli`], clap), printing, and the exit status of every
//! error ([`error::exit_code`]). The runs and every file they write live in
//! the `fbd-output` crate, re-exported here under their old paths: the TOML
//! configuration ([`config`]), the `fbd run` command writing
//! `trajectory.csv`, `events.csv`, `summary.json`, `config.toml` and the
//! plots ([`run`], [`output`], [`plot`]; a kinematic hexapod run in
//! [`hexapod`], a dynamic one in [`spatial`]), and `fbd kinematics`
//! ([`kinematics`]). The binary `fbd` only calls [`main_with_args`].
//!
//! Exit status ([`error::exit_code`]): 0 success, 2 usage or
//! configuration error, 3 simulation failed (files still written), 4 input
//! or output error. Every error is one line on stderr, `error: …`.

pub mod cli;
/// The configuration: the `fbd-scenario` crate.
pub use fbd_scenario as config;
pub mod error;
pub mod export;
pub mod sweep;
pub use fbd_output::{
    columnar, hexapod, interrupt, kinematics, output, plot, robot_run, run, spatial, steptime,
    sweep_plot, viewer,
};

pub use config::{Config, ConfigError, Override};
pub use error::CliError;

use std::ffi::OsString;
use std::io::Write;
use std::process::ExitCode;

use clap::Parser;

/// Parses `args` (program name first), runs the command, prints errors as
/// one line on stderr and returns the exit status. Panics are caught and
/// reported as one line too.
pub fn main_with_args<I, T>(args: I) -> ExitCode
where
    I: IntoIterator<Item = T>,
    T: Into<OsString> + Clone,
{
    std::panic::set_hook(Box::new(|info| {
        let msg = info
            .payload()
            .downcast_ref::<&str>()
            .map(|s| (*s).to_owned())
            .or_else(|| info.payload().downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "panic".into());
        let at = info
            .location()
            .map(|l| format!(" at {}:{}", l.file(), l.line()))
            .unwrap_or_default();
        eprintln!("error: internal error: {}{at}", msg.replace('\n', " "));
    }));
    interrupt::install();
    let cli = match cli::Cli::try_parse_from(args) {
        Ok(c) => c,
        Err(e) => {
            use clap::error::ErrorKind;
            return match e.kind() {
                ErrorKind::DisplayHelp
                | ErrorKind::DisplayVersion
                | ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand => {
                    let _ = e.print();
                    if e.kind() == ErrorKind::DisplayHelpOnMissingArgumentOrSubcommand {
                        ExitCode::from(2)
                    } else {
                        ExitCode::SUCCESS
                    }
                }
                _ => {
                    let rendered = e.render().to_string();
                    let first = rendered
                        .lines()
                        .find(|l| !l.trim().is_empty())
                        .unwrap_or("invalid command line");
                    let first = first.strip_prefix("error: ").unwrap_or(first);
                    // `fbd CONFIG.toml`: a configuration where a command
                    // is expected; point to `fbd run`.
                    let hint = match e.get(clap::error::ContextKind::InvalidSubcommand) {
                        Some(clap::error::ContextValue::String(arg))
                            if arg.ends_with(".toml") || std::path::Path::new(arg).is_file() =>
                        {
                            format!("; to simulate a configuration: `fbd run {arg}`")
                        }
                        _ => String::new(),
                    };
                    eprintln!("error: {first} (see `fbd --help`){hint}");
                    ExitCode::from(2)
                }
            };
        }
    };
    let result = std::panic::catch_unwind(|| {
        let stdout = std::io::stdout();
        let mut out = stdout.lock();
        cli::dispatch(cli, &mut out)
    });
    match result {
        Ok(Ok(())) => ExitCode::SUCCESS,
        Ok(Err(e)) => {
            if !e.is_broken_pipe() {
                let _ = writeln!(std::io::stderr(), "error: {e}");
            }
            ExitCode::from(error::exit_code(&e))
        }
        // The panic hook already printed the message.
        Err(_) => ExitCode::from(error::INTERNAL),
    }
}

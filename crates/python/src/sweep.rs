//! `sweep(sweep_config, out, jobs=None)`: `fbd sweep` with the GIL
//! released.

use std::path::PathBuf;

use fbd_output::OutputError;
use fbd_output::sweep::{SweepArgs, sweep_command};
use pyo3::prelude::*;

use crate::errors::{cli_error, guard};

/// Runs the sweep file `sweep_config` into `out` on `jobs` threads (every
/// core by default). Returns the message `fbd sweep` prints and, when runs
/// failed, the error message (index.csv is written either way); raises
/// `ConfigError` or `OSError` when the sweep cannot start.
#[pyfunction]
#[pyo3(signature = (sweep_config, out, jobs=None, plot="touchdown", viewer=false, plots=false))]
pub fn sweep(
    py: Python<'_>,
    sweep_config: PathBuf,
    out: PathBuf,
    jobs: Option<usize>,
    plot: &str,
    viewer: bool,
    plots: bool,
) -> PyResult<(String, Option<String>)> {
    guard(|| {
        let args = SweepArgs {
            command: None,
            sweep: Some(sweep_config),
            out: out.clone(),
            jobs,
            shard: None,
            resume: false,
            plot: plot.to_owned(),
            viewer,
            plots,
        };
        let mut text = Vec::new();
        let result = py.detach(|| sweep_command(args, &mut text));
        let text = String::from_utf8_lossy(&text).into_owned();
        match result {
            Ok(()) => Ok((text, None)),
            Err(OutputError::Simulation(m)) if out.join("index.csv").is_file() => {
                Ok((text, Some(m)))
            }
            Err(e) => Err(cli_error(py, &e, true)),
        }
    })
}

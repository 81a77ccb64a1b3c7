//! `run(config)` of a dynamic hexapod configuration: the 3D FBD dynamics
//! ([`fbd_output::spatial::simulate`]), every column of its `trajectory.csv`
//! in memory from the CLI's own columns and row writer
//! ([`fbd_output::spatial::csv::plan`], [`fbd_output::tree::Plan::row`]):
//! the same names and values as the file.

use std::path::Path;

use fbd_output::spatial::csv::{Slots, plan};
use fbd_output::spatial::{Feet, Layout, simulate};
use fbd_scenario::{Config, HexapodConfig};
use fbd_sim::robot::RobotRecord;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::columns::Columns;
use crate::errors::config_error;
use crate::run::{dynamics_columns, run_result, watched};

/// The dynamic hexapod's `run` dict, as the planar run's: `columns`,
/// `data` (float64 arrays; `state{n}` and `*point{n}_state` lists of
/// `"ST1"`/`"ST2"`/`"ST3"`; `newton_iterations` int64), `events` (dicts
/// `t`, `step`, `leg`, `point`, `from`, `to`, as `events.csv`), `summary`
/// (JSON text), `error`, `source`. Runs with the GIL released; Ctrl-C
/// stops it ([`crate::run::SignalWatch`]).
pub fn run<'py>(
    py: Python<'py>,
    h: &HexapodConfig,
    config: &Config,
    source: &str,
    from_text: bool,
    out: Option<&Path>,
) -> PyResult<Bound<'py, PyDict>> {
    let params = h
        .spatial_params(source)
        .map_err(|e| config_error(py, &e, from_text))?;
    let dt = params.dt;
    let ((sim, cols), signal) = watched(py, from_text, |stop, watch| {
        let layout = Layout::of(&params);
        let stride = params.stride.max(1);
        // Room for the rows planned, at most 2^16 up front (some 230
        // columns of a six-legged model): a long run grows as it goes.
        let rows = ((params.duration / dt).round().max(0.0) as usize + 1)
            .div_ceil(stride)
            .min(1 << 16);
        let plan = plan(&layout, &Slots::of(&layout, &params.record_index()));
        let mut cols = Columns::named(plan.names.clone(), dt, rows);
        let mut feet = Feet::new(&params);
        simulate(
            &params,
            &config.to_toml(),
            source,
            out,
            stop,
            &mut |r: &RobotRecord| {
                plan.row(r, Some(&mut feet), &mut cols.sink());
                watch.row(stop);
            },
        )
        .map(|s| (s, cols))
    })?;
    run_result(py, sim, signal, from_text, source, dt, |d, run| {
        dynamics_columns(d, cols, run, dt)
    })
}

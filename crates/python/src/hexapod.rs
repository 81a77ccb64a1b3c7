//! `run(config)` of a kinematic hexapod configuration: the kinematic gait
//! (or a kinematic standing run, `dynamics = "kinematic"`), every column of its `trajectory.csv` in
//! memory ([`fbd_output::hexapod::columns`]), the same values as the file.

use std::path::Path;

use fbd_output::hexapod::{ROW_VALUES, columns, row_values, simulate};
use fbd_output::steptime::StepTimes;
use fbd_scenario::{Config, HexapodConfig};
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::run::{run_result, watched};

/// The hexapod's `run` dict: `columns` (names of `trajectory.csv`),
/// `data` (float64 arrays; `stance{n}` is 1.0 or 0.0), `events` (dicts
/// `t`, `leg` (None for stability events), `event`, `margin`, as
/// `events.csv`), `summary` (JSON text), `error`, `source`. Runs with the
/// GIL released.
pub fn run<'py>(
    py: Python<'py>,
    h: &HexapodConfig,
    config: &Config,
    source: &str,
    from_text: bool,
    out: Option<&Path>,
) -> PyResult<Bound<'py, PyDict>> {
    let names = columns();
    let ((sim, data), signal) = watched(py, from_text, |stop, watch| {
        let mut data: Vec<Vec<f64>> = vec![Vec::new(); names.len()];
        let times = StepTimes::new(h.time.dt);
        let mut row = [0.0; ROW_VALUES];
        simulate(h, config, source, out, stop, &mut |d| {
            data[0].push(times.value(d.step, d.t));
            row_values(d, &mut row);
            for (col, v) in data[1..].iter_mut().zip(row) {
                col.push(v);
            }
            watch.row(stop);
        })
        .map(|r| (r, data))
    })?;
    run_result(py, sim, signal, from_text, source, h.time.dt, |d, run| {
        let arrays = PyDict::new(py);
        for (name, v) in names.iter().zip(data) {
            arrays.set_item(name, PyArray1::from_vec(py, v))?;
        }
        d.set_item("columns", PyList::new(py, &names)?)?;
        d.set_item("data", arrays)?;
        let events = PyList::empty(py);
        for e in &run.events {
            let ev = PyDict::new(py);
            ev.set_item("t", fbd_output::hexapod::tidy(e.t))?;
            ev.set_item("leg", e.leg)?;
            ev.set_item("event", e.kind.as_str())?;
            ev.set_item("margin", e.margin)?;
            events.append(ev)?;
        }
        d.set_item("events", events)
    })
}

//! `run(config=None, out=None)`: a whole run, every trajectory column in
//! memory, the CLI's files written only when `out` is given.

use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

use fbd_cli::run::{Simulated, simulate};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::columns::Columns;
use crate::errors::{cli_error, guard};

/// Every event of a run — contact, joint-limit and retried-step events, as
/// `events.csv` lists them ([`fbd_cli::output::run_events`]) — as a list of
/// dicts (`t`, `step`, `leg` (None for a retried step), `point`, `from`,
/// `to`).
pub fn events<'py>(
    py: Python<'py>,
    run: &fbd_sim::RunSummary,
    dt: f64,
) -> PyResult<Bound<'py, PyList>> {
    let times = fbd_cli::steptime::StepTimes::new(dt);
    let list = PyList::empty(py);
    for (step, _, e) in fbd_cli::output::run_events(run, &times) {
        let d = PyDict::new(py);
        d.set_item("t", e.t)?;
        d.set_item("step", step)?;
        d.set_item("leg", e.leg)?;
        d.set_item("point", e.point)?;
        d.set_item("from", e.from)?;
        d.set_item("to", e.to)?;
        list.append(d)?;
    }
    Ok(list)
}

/// `run(config=None, out=None) -> dict`: simulates `config` with the GIL
/// released. Returns `{"columns", "data", "events", "summary" (JSON text),
/// "error" (None or {"message", "step", "t"}), "source"}`; the Python layer
/// wraps it in `fbd.Result` and raises `fbd.SimulationError` on an error.
#[pyfunction]
#[pyo3(signature = (config=None, out=None))]
pub fn run<'py>(
    py: Python<'py>,
    config: Option<&Bound<'py, PyAny>>,
    out: Option<PathBuf>,
) -> PyResult<Bound<'py, PyDict>> {
    guard(|| {
        let loaded = crate::config::load(py, config)?;
        let (dt, stride, steps) = match &loaded.config {
            fbd_scenario::Config::Planar(c) => (c.time.dt, c.output.stride.max(1), {
                let n = (c.time.duration / c.time.dt).round();
                if n.is_finite() && n < 1e8 {
                    n as usize + 1
                } else {
                    0
                }
            }),
            fbd_scenario::Config::Hexapod(c) => (c.time.dt, 1, 0),
        };
        let outcome = py.detach(|| {
            let names = match &loaded.config {
                fbd_scenario::Config::Planar(c) => c.model(&loaded.source).ok().map(|m| {
                    m.mech
                        .contacts
                        .iter()
                        .map(|c| c.name.clone())
                        .collect::<Vec<_>>()
                }),
                fbd_scenario::Config::Hexapod(_) => None,
            };
            let mut cols = Columns::new(names.as_deref().unwrap_or(&[]), dt, steps / stride + 1);
            let stop = AtomicBool::new(false);
            simulate(
                &loaded.config,
                &loaded.source,
                out.as_deref(),
                &stop,
                &mut |r| cols.push(r),
            )
            .map(|s| (s, cols))
        });
        let (sim, cols) = outcome.map_err(|e| cli_error(py, &e, loaded.from_text))?;
        let Simulated {
            run,
            summary,
            io_error,
            ..
        } = sim;
        if let Some(e) = io_error {
            return Err(cli_error(py, &e, loaded.from_text));
        }
        let d = PyDict::new(py);
        let (names, data) = cols.into_py(py)?;
        d.set_item("columns", names)?;
        d.set_item("data", data)?;
        d.set_item("events", events(py, &run, dt)?)?;
        let json = serde_json::to_string(&summary).unwrap_or_else(|_| "{}".into());
        d.set_item("summary", json)?;
        d.set_item("source", &loaded.source)?;
        let error = match &run.error {
            Some(e) => {
                let err = PyDict::new(py);
                err.set_item("message", format!("{e} ({})", loaded.source))?;
                err.set_item("step", e.step())?;
                err.set_item("t", e.step().map(|k| k as f64 * dt))?;
                Some(err)
            }
            None => None,
        };
        d.set_item("error", error)?;
        Ok(d)
    })
}

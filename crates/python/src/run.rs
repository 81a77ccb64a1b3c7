//! `run(config=None, out=None)`: a whole run, every trajectory column in
//! memory, the CLI's files written only when `out` is given; an imported
//! robot's run in [`crate::robot`].

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};

use fbd_output::driver::{Outcome, RunOutput};
use fbd_output::output::ContactSlots;
use fbd_output::run::simulate;
use pyo3::exceptions::PyKeyboardInterrupt;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::columns::Columns;
use crate::errors::{cli_error, guard};

/// Rows between two looks at Python's signals during a run.
pub const SIGNAL_CHECK: usize = 4096;

/// Ctrl-C (KeyboardInterrupt) during a run: every [`SIGNAL_CHECK`] rows the
/// GIL is taken back to let Python run its signal handlers (on the main
/// thread only, as Python does); an exception they raise sets the run's
/// stop flag and is kept to be raised when the run returns.
#[derive(Default)]
pub struct SignalWatch {
    /// The exception a signal handler raised.
    pub signal: Option<PyErr>,
    rows: usize,
}

impl SignalWatch {
    /// A watch that caught `signal` already (a run watched in a thread of
    /// its own).
    pub fn caught(signal: Option<PyErr>) -> Self {
        Self { signal, rows: 0 }
    }

    /// Counts one row; every [`SIGNAL_CHECK`] rows, looks at the signals.
    pub fn row(&mut self, stop: &AtomicBool) {
        self.rows += 1;
        if self.rows.is_multiple_of(SIGNAL_CHECK)
            && self.signal.is_none()
            && let Err(e) = Python::attach(|py| py.check_signals())
        {
            self.signal = Some(e);
            stop.store(true, Ordering::Relaxed);
        }
    }
}

/// The one run binding of the planar, kinematic-hexapod and dynamic
/// hexapod runs: `go` runs with the GIL released, given the stop flag and
/// the [`SignalWatch`] its row callback calls; an error it returns becomes
/// the Python exception of that error.
pub fn watched<T: Send>(
    py: Python<'_>,
    from_text: bool,
    go: impl FnOnce(&AtomicBool, &mut SignalWatch) -> Result<T, fbd_output::OutputError> + Send,
) -> PyResult<(T, SignalWatch)> {
    py.detach(|| {
        let stop = AtomicBool::new(false);
        let mut watch = SignalWatch::default();
        go(&stop, &mut watch).map(|t| (t, watch))
    })
    .map_err(|e| cli_error(py, &e, from_text))
}

impl SignalWatch {
    /// After the run of `source` that stopped after `steps` steps: an
    /// output file that could not be written (`io_error`, as the CLI's
    /// error), else the signal handler's exception, if one was raised (a
    /// KeyboardInterrupt for Ctrl-C, with where the run stopped).
    pub fn raise(
        self,
        io_error: Option<fbd_output::OutputError>,
        from_text: bool,
        source: &str,
        steps: usize,
    ) -> PyResult<()> {
        if let Some(e) = io_error {
            return Python::attach(|py| Err(cli_error(py, &e, from_text)));
        }
        let Some(e) = self.signal else {
            return Ok(());
        };
        Python::attach(|py| {
            if e.is_instance_of::<PyKeyboardInterrupt>(py) {
                Err(PyKeyboardInterrupt::new_err(format!(
                    "{source}: interrupted after {steps} steps"
                )))
            } else {
                Err(e)
            }
        })
    }
}

/// Completes a run's dict `d` with its `summary` (JSON text), `source` and
/// `error` (None, or `{"message", "step", "t"}` for a run that stopped at
/// `step` (time `t`) with `message`).
pub fn finish<'py>(
    d: Bound<'py, PyDict>,
    summary: &impl serde::Serialize,
    source: &str,
    error: Option<(String, Option<usize>, Option<f64>)>,
) -> PyResult<Bound<'py, PyDict>> {
    let json = serde_json::to_string(summary).unwrap_or_else(|_| "{}".into());
    d.set_item("summary", json)?;
    d.set_item("source", source)?;
    let error = match error {
        Some((message, step, t)) => {
            let err = PyDict::new(d.py());
            err.set_item("message", format!("{message} ({source})"))?;
            err.set_item("step", step)?;
            err.set_item("t", t)?;
            Some(err)
        }
        None => None,
    };
    d.set_item("error", error)?;
    Ok(d)
}

/// The one unpacking of a run's result ([`RunOutput`], every model's):
/// a file that could not be written or a signal raised first
/// ([`SignalWatch::raise`]), then the dict: what `fill` puts in it (the
/// columns and the events of the model), `summary`, `source`, `error`
/// ([`finish`], the failing step at time step `dt`).
pub fn run_result<'py, R: Outcome, S: serde::Serialize>(
    py: Python<'py>,
    out: RunOutput<R, S>,
    signal: SignalWatch,
    from_text: bool,
    source: &str,
    dt: f64,
    fill: impl FnOnce(&Bound<'py, PyDict>, &R) -> PyResult<()>,
) -> PyResult<Bound<'py, PyDict>> {
    let RunOutput {
        run,
        summary,
        io_error,
        ..
    } = out;
    signal.raise(io_error, from_text, source, run.steps())?;
    let d = PyDict::new(py);
    fill(&d, &run)?;
    finish(d, &summary, source, run.failure(dt))
}

/// The `columns`, `data` and `events` of a dynamics run (planar or 3D).
pub fn dynamics_columns<'py>(
    d: &Bound<'py, PyDict>,
    cols: Columns,
    run: &fbd_sim::RunSummary,
    dt: f64,
) -> PyResult<()> {
    let py = d.py();
    let (names, data) = cols.into_py(py)?;
    d.set_item("columns", names)?;
    d.set_item("data", data)?;
    d.set_item(
        "events",
        events(py, &run.events, &run.limit_events, &run.retries, dt)?,
    )
}

/// Every event of a run — contact, joint-limit and retried-step events, as
/// `events.csv` lists them ([`fbd_output::output::merge_events`]) — as a list
/// of dicts (`t`, `step`, `leg` (None for a retried step), `point`, `from`,
/// `to`).
pub fn events<'py>(
    py: Python<'py>,
    events: &[fbd_sim::Event],
    limit_events: &[fbd_sim::LimitEvent],
    retries: &[fbd_sim::RetryEvent],
    dt: f64,
) -> PyResult<Bound<'py, PyList>> {
    let times = fbd_output::steptime::StepTimes::new(dt);
    let list = PyList::empty(py);
    for (step, _, e) in fbd_output::output::merge_events(events, limit_events, retries, &times) {
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
        if let Some(robot) = crate::config::load_robot(py, config)? {
            let (source, from_text) = crate::config::robot_source(config);
            return crate::robot::run(py, &robot, &source, from_text, out.as_deref());
        }
        let loaded = crate::config::load(py, config)?;
        if let fbd_scenario::Config::Hexapod(h) = &loaded.config
            && h.is_dynamic()
        {
            return crate::spatial::run(
                py,
                h,
                &loaded.config,
                &loaded.source,
                loaded.from_text,
                out.as_deref(),
            );
        }
        if let fbd_scenario::Config::Hexapod(h) = &loaded.config {
            return crate::hexapod::run(
                py,
                h,
                &loaded.config,
                &loaded.source,
                loaded.from_text,
                out.as_deref(),
            );
        }
        let ((sim, cols, dt), signal) = watched(py, loaded.from_text, |stop, watch| {
            // The columns' names and capacity; an invalid model is reported
            // by `simulate` itself.
            let (slots, dt, rows) = match &loaded.config {
                fbd_scenario::Config::Planar(c) => match c.model(&loaded.source) {
                    Ok(m) => (
                        ContactSlots::of(&m.mech.contacts),
                        m.dt(),
                        m.steps.div_ceil(m.params.stride.max(1)),
                    ),
                    Err(_) => (ContactSlots::default(), c.time.dt, 0),
                },
                fbd_scenario::Config::Hexapod(c) => (ContactSlots::default(), c.time.dt, 0),
            };
            let mut cols = Columns::new(slots, dt, rows);
            simulate(
                &loaded.config,
                &loaded.source,
                out.as_deref(),
                stop,
                &mut |r| {
                    cols.push(r);
                    watch.row(stop);
                },
            )
            .map(|s| (s, cols, dt))
        })?;
        run_result(
            py,
            sim,
            signal,
            loaded.from_text,
            &loaded.source,
            dt,
            |d, run| dynamics_columns(d, cols, run, dt),
        )
    })
}

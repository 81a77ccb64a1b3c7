//! Raising the package's exceptions (defined in Python, `fbd._errors`) and
//! catching panics at the boundary.

use std::panic::{AssertUnwindSafe, catch_unwind};

use fbd_output::OutputError;
use fbd_scenario::ConfigError;
use pyo3::exceptions::{PyKeyboardInterrupt, PyOSError, PyRuntimeError};
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// An instance of `fbd._errors.<class>` called with `message` and `kwargs`.
fn raise(py: Python<'_>, class: &str, message: &str, kwargs: &Bound<'_, PyDict>) -> PyErr {
    let make = || -> PyResult<PyErr> {
        let cls = py.import("fbd._errors")?.getattr(class)?;
        let value = cls.call((message,), Some(kwargs))?;
        Ok(PyErr::from_value(value))
    };
    make().unwrap_or_else(|e| e)
}

/// The dotted `table.key` a message starts with (`"time.dt: must be …"`).
fn leading_key(message: &str) -> Option<String> {
    let (head, _) = message.split_once(": ")?;
    let ok = !head.is_empty()
        && head
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || c == '_' || c == '.' || c == '[' || c == ']');
    ok.then(|| head.to_owned())
}

/// `fbd.ConfigError` for a configuration error: `file`, `line`, `column`
/// (None when unknown or when the configuration was a dict) and `key`.
pub fn config_error(py: Python<'_>, e: &ConfigError, from_text: bool) -> PyErr {
    let kwargs = PyDict::new(py);
    let fill = || -> PyResult<()> {
        match e {
            ConfigError::Unreadable { file, .. } | ConfigError::Io { file, .. } => {
                kwargs.set_item("file", file)?;
            }
            ConfigError::Syntax {
                file,
                line,
                col,
                message,
            } => {
                kwargs.set_item("file", file)?;
                if from_text {
                    kwargs.set_item("line", line)?;
                    kwargs.set_item("column", col)?;
                }
                kwargs.set_item("key", leading_key(message))?;
            }
            ConfigError::Semantic { file, message } => {
                kwargs.set_item("file", file)?;
                kwargs.set_item("key", leading_key(message))?;
            }
            ConfigError::Override { file, key, .. } => {
                kwargs.set_item("file", file)?;
                kwargs.set_item("key", key)?;
            }
            ConfigError::Robot(r) => {
                kwargs.set_item("file", r.file().display().to_string())?;
            }
        }
        Ok(())
    };
    if let Err(err) = fill() {
        return err;
    }
    if e.is_io() {
        return PyOSError::new_err(e.to_string());
    }
    raise(py, "ConfigError", &e.to_string(), &kwargs)
}

/// `fbd.SimulationError` at `step`, time `t`, with `result` (the partial
/// result, or None).
pub fn simulation_error(
    py: Python<'_>,
    message: &str,
    step: Option<usize>,
    t: Option<f64>,
    result: Option<Bound<'_, PyAny>>,
) -> PyErr {
    let kwargs = PyDict::new(py);
    let fill = || -> PyResult<()> {
        kwargs.set_item("step", step)?;
        kwargs.set_item("time", t)?;
        kwargs.set_item("result", result)?;
        Ok(())
    };
    if let Err(err) = fill() {
        return err;
    }
    raise(py, "SimulationError", message, &kwargs)
}

/// A CLI-library error as a Python exception: configuration errors as
/// `fbd.ConfigError` (a hexapod `Simulator` names the key `model`), file errors as
/// `OSError`.
pub fn cli_error(py: Python<'_>, e: &OutputError, from_text: bool) -> PyErr {
    match e {
        OutputError::Config(c) => config_error(py, c, from_text),
        OutputError::Usage(m) => {
            let kwargs = PyDict::new(py);
            let key = m.contains("model = ").then_some("model");
            if let Err(err) = kwargs.set_item("key", key) {
                return err;
            }
            raise(py, "ConfigError", m, &kwargs)
        }
        OutputError::Simulation(m) => simulation_error(py, m, None, None, None),
        OutputError::Io(m) => PyOSError::new_err(m.clone()),
        OutputError::BrokenPipe => PyOSError::new_err("broken pipe"),
        OutputError::Interrupted(m) => PyKeyboardInterrupt::new_err(m.clone()),
    }
}

/// Runs `f`, turning a panic into `RuntimeError` (never unwinding into
/// Python).
pub fn guard<T>(f: impl FnOnce() -> PyResult<T>) -> PyResult<T> {
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(r) => r,
        Err(payload) => {
            let msg = payload
                .downcast_ref::<&str>()
                .map(|s| (*s).to_owned())
                .or_else(|| payload.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "panic".into());
            Err(PyRuntimeError::new_err(format!(
                "fbd internal error: {msg}"
            )))
        }
    }
}

//! `run(config)` of an imported robot (`model = "robot"`): the CLI's own
//! run ([`fbd_output::robot_run::simulate`]) into `out` or a temporary
//! directory, every column of its `trajectory.csv` read back into memory
//! (shortest round-trip numbers: the file's values, bit for bit; the
//! names and kinds of [`LoadedRobot::columns`]), its events and summary.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use fbd_output::config::robot::{ColumnKind, LoadedRobot, RobotColumns};
use fbd_output::robot_run::{robot_events, simulate};
use fbd_output::steptime::StepTimes;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::errors::{cli_error, config_error};
use crate::run::run_result;

/// The values of one column of a robot's trajectory.
enum Values {
    /// Numbers.
    Float(Vec<f64>),
    /// Contact states `ST1`, `ST2`, `ST3`.
    State(Vec<&'static str>),
    /// Counts.
    Int(Vec<i64>),
}

/// A robot's columns, filled row by row.
struct RobotTable {
    names: Vec<String>,
    values: Vec<Values>,
}

impl RobotTable {
    fn new(columns: &RobotColumns, rows: usize) -> Self {
        let values = columns
            .kinds
            .iter()
            .map(|k| match k {
                ColumnKind::Number => Values::Float(Vec::with_capacity(rows)),
                ColumnKind::State => Values::State(Vec::with_capacity(rows)),
                ColumnKind::Count => Values::Int(Vec::with_capacity(rows)),
            })
            .collect();
        Self {
            names: columns.names.clone(),
            values,
        }
    }

    /// Appends the rows of a `trajectory.csv` written by the CLI (its
    /// header skipped); `None` for a file that does not parse.
    fn read_csv(&mut self, text: &str) -> Option<()> {
        for line in text.lines().skip(1) {
            let mut cells = line.split(',');
            for v in &mut self.values {
                let cell = cells.next()?;
                match v {
                    Values::Float(v) => v.push(cell.parse().ok()?),
                    Values::State(v) => v.push(match cell {
                        "ST1" => "ST1",
                        "ST2" => "ST2",
                        "ST3" => "ST3",
                        _ => return None,
                    }),
                    Values::Int(v) => v.push(cell.parse().ok()?),
                }
            }
        }
        Some(())
    }

    fn into_py<'py>(self, py: Python<'py>, d: &Bound<'py, PyDict>) -> PyResult<()> {
        let data = PyDict::new(py);
        for (name, v) in self.names.iter().zip(self.values) {
            match v {
                Values::Float(v) => data.set_item(name, PyArray1::from_vec(py, v))?,
                Values::Int(v) => data.set_item(name, PyArray1::from_vec(py, v))?,
                Values::State(v) => data.set_item(name, PyList::new(py, v)?)?,
            }
        }
        d.set_item("columns", PyList::new(py, &self.names)?)?;
        d.set_item("data", data)?;
        Ok(())
    }
}

/// A robot's events as `events.csv` lists them: dicts `t`, `step`,
/// `point` (a contact point's name, `<joint>_limit`, or `substeps`),
/// `from`, `to`.
pub fn events<'py>(
    py: Python<'py>,
    robot: &LoadedRobot,
    sim: &fbd_sim::robot::RobotSim,
    run: &fbd_sim::RunSummary,
) -> PyResult<Bound<'py, PyList>> {
    let times = StepTimes::new(sim.params.dt);
    let list = PyList::empty(py);
    for (step, _, e) in robot_events(robot, sim, run, &times) {
        let d = PyDict::new(py);
        d.set_item("t", e.t)?;
        d.set_item("step", step)?;
        d.set_item("point", e.point)?;
        d.set_item("from", e.from)?;
        d.set_item("to", e.to)?;
        list.append(d)?;
    }
    Ok(list)
}

/// A fresh directory for a run without `out` (removed when dropped).
struct TempDir(std::path::PathBuf);

impl TempDir {
    fn new() -> std::io::Result<Self> {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        let base = std::env::temp_dir();
        loop {
            let n = NEXT.fetch_add(1, Ordering::Relaxed);
            let dir = base.join(format!("fbd-python-run-{}-{n}", std::process::id()));
            match std::fs::create_dir(&dir) {
                Ok(()) => return Ok(Self(dir)),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        }
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// The robot's `run` dict, as the other models': `columns`, `data`
/// (float64 arrays; `<point>_state` lists of `"ST1"`/`"ST2"`/`"ST3"`;
/// `newton_iterations` int64), `events` ([`events`]), `summary` (JSON
/// text, `summary.json`'s), `error`, `source`. The run is the CLI's own
/// ([`simulate`]: the same files, the same summary), into `out` or, without
/// it, a temporary directory (no `viewer.html`) removed afterwards; the
/// columns are read back from its `trajectory.csv`. The GIL is released;
/// Ctrl-C (Python's signal handlers, looked at every 50 ms while the run
/// goes on in a thread of its own) stops it.
pub fn run<'py>(
    py: Python<'py>,
    robot: &LoadedRobot,
    source: &str,
    from_text: bool,
    out: Option<&Path>,
) -> PyResult<Bound<'py, PyDict>> {
    let sim = robot.sim().map_err(|e| {
        config_error(
            py,
            &fbd_output::ConfigError::Semantic {
                file: source.to_owned(),
                message: e.to_string(),
            },
            from_text,
        )
    })?;
    let columns = robot.columns(&sim);
    let rows = sim.steps.div_ceil(sim.params.stride.max(1)).min(1 << 16);
    let mut table = RobotTable::new(&columns, rows);
    let (temp, dir, quiet);
    let robot = match out {
        Some(out) => {
            dir = out.to_path_buf();
            robot
        }
        None => {
            temp = TempDir::new().map_err(|e| {
                cli_error(
                    py,
                    &fbd_output::OutputError::io(std::env::temp_dir().display(), &e),
                    from_text,
                )
            })?;
            dir = temp.0.clone();
            let mut r = robot.clone();
            r.config.output.viewer = false;
            quiet = r;
            &quiet
        }
    };
    let stop = AtomicBool::new(false);
    let mut signal: Option<PyErr> = None;
    let output = py.detach(|| {
        std::thread::scope(|scope| {
            let worker = scope.spawn(|| simulate(robot, source, &dir, &stop));
            while !worker.is_finished() {
                std::thread::sleep(std::time::Duration::from_millis(50));
                if signal.is_none()
                    && let Err(e) = Python::attach(|py| py.check_signals())
                {
                    signal = Some(e);
                    stop.store(true, std::sync::atomic::Ordering::Relaxed);
                }
            }
            worker.join()
        })
    });
    let output = match output {
        Ok(o) => o.map_err(|e| cli_error(py, &e, from_text))?,
        Err(_) => {
            return Err(pyo3::exceptions::PyRuntimeError::new_err(format!(
                "{source}: the run panicked"
            )));
        }
    };
    let dt = sim.params.dt;
    let signal = crate::run::SignalWatch::caught(signal);
    run_result(py, output, signal, from_text, source, dt, |d, run| {
        let path = dir.join("trajectory.csv");
        let text = std::fs::read_to_string(&path).map_err(|e| {
            cli_error(
                py,
                &fbd_output::OutputError::io(path.display(), &e),
                from_text,
            )
        })?;
        table.read_csv(&text).ok_or_else(|| {
            pyo3::exceptions::PyRuntimeError::new_err(format!(
                "{}: not a robot's trajectory.csv",
                path.display()
            ))
        })?;
        table.into_py(py, d)?;
        d.set_item("events", events(py, robot, &sim, &run.summary)?)
    })
}

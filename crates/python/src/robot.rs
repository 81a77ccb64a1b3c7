//! `run(config)` of an imported robot (`model = "robot"`): the CLI's own
//! run ([`fbd_output::robot_run::simulate`]) into `out` or a temporary
//! directory, every column of its `trajectory.csv` in memory from the
//! same columns and row writer ([`fbd_output::robot_run::plan`],
//! [`fbd_output::tree::Plan::row`]: the file's values, bit for bit), its
//! events and summary.

use std::path::Path;
use std::sync::atomic::AtomicBool;

use fbd_output::config::robot::LoadedRobot;
use fbd_output::robot_run::{plan, robot_events, simulate};
use fbd_output::steptime::StepTimes;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

use crate::columns::Columns;

use crate::errors::{cli_error, config_error};
use crate::run::run_result;

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
/// it, a temporary directory (no `viewer.html`, no plots) removed
/// afterwards; the columns are the file's, kept as the rows are written.
/// The GIL is released;
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
    let plan = plan(robot, &sim);
    let rows = sim.steps.div_ceil(sim.params.stride.max(1)).min(1 << 16);
    let mut cols = Columns::named(plan.names.clone(), sim.params.dt, rows);
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
            r.config.output.plots = false;
            quiet = r;
            &quiet
        }
    };
    let stop = AtomicBool::new(false);
    let mut signal: Option<PyErr> = None;
    let output = py.detach(|| {
        std::thread::scope(|scope| {
            let worker = scope.spawn(|| {
                simulate(robot, source, &dir, &stop, &mut |r| {
                    plan.row(r, None, &mut cols.sink());
                })
            });
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
        let (names, data) = cols.into_py(py)?;
        d.set_item("columns", names)?;
        d.set_item("data", data)?;
        d.set_item("events", events(py, robot, &sim, &run.summary)?)
    })
}

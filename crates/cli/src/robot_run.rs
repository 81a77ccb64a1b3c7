//! `fbd run` of an imported robot (`model = "robot"`) in flight: the run
//! itself is [`fbd_scenario::robot::LoadedRobot::run_flight`]; this module
//! writes `trajectory.csv` (streamed, every `[output] stride`-th step),
//! `events.csv` (header only: no contact yet), `summary.json` and
//! `config.toml`, each all-or-nothing, also after a simulation error or an
//! interruption.

use std::io::{BufWriter, Write};
use std::path::Path;

use serde::Serialize;

use crate::CliError;
use crate::config::robot::{FlightRun, LoadedRobot};
use crate::output::{self, Ending};

/// The files of a robot's run, in the order they are written.
pub const FILES: [&str; 4] = [
    "trajectory.csv",
    "events.csv",
    "summary.json",
    "config.toml",
];

/// `events.csv` of a flight: the header alone.
pub const EVENTS_HEADER: &str = "t,contact,from,to\n";

/// `summary.json` of a robot's run.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RobotSummary {
    /// `"ok"`, `"error"` or `"interrupted"`.
    pub status: &'static str,
    /// The error message, or null.
    pub error: Option<String>,
    /// `"robot"`.
    pub model: &'static str,
    /// The robot's name (from its description).
    pub robot: String,
    /// Steps solved.
    pub steps: usize,
    /// Steps planned (`round(duration/Δt) + 1`).
    pub steps_planned: usize,
    /// Rows of `trajectory.csv`.
    pub rows_written: usize,
    /// Newton iterations over the run.
    pub newton_iterations: usize,
    /// Time in the stepping loop (s).
    pub wall_seconds: f64,
    /// `steps / wall_seconds` (null when not measurable).
    pub steps_per_second: Option<f64>,
    /// Contact events: none in flight.
    pub events: Vec<()>,
}

/// What [`simulate`] did.
#[derive(Debug)]
pub struct RobotRunOutput {
    /// How the run ended.
    pub run: FlightRun,
    /// `summary.json`'s content.
    pub summary: RobotSummary,
    /// The first error writing the files, if any.
    pub io_error: Option<CliError>,
}

fn write_number(w: &mut impl Write, x: f64, buf: &mut ryu::Buffer) -> std::io::Result<()> {
    if x.is_finite() {
        w.write_all(buf.format_finite(x).as_bytes())
    } else {
        write!(w, "{x}")
    }
}

/// Simulates `robot` in flight and writes its files in `out_dir` (created
/// if needed; files of an earlier run that this one does not write are
/// removed). The run stops before its next step once `stop` is set.
pub fn simulate(
    robot: &LoadedRobot,
    source: &str,
    out_dir: &Path,
    stop: &std::sync::atomic::AtomicBool,
) -> Result<RobotRunOutput, CliError> {
    output::prepare_dir(out_dir)?;
    let flight = robot.flight().map_err(|e| crate::ConfigError::Semantic {
        file: source.to_owned(),
        message: e.to_string(),
    })?;
    let columns = robot.flight_columns(&flight);
    let stride = robot.config.output.stride;
    let dest = out_dir.join("trajectory.csv");
    let tmp = output::temp_in(out_dir, "trajectory.csv")?;
    let mut w = BufWriter::new(tmp);
    let mut io: std::io::Result<()> = w.write_all(format!("{}\n", columns.join(",")).as_bytes());
    let mut rows = 0;
    let mut row = Vec::with_capacity(columns.len());
    let mut buf = ryu::Buffer::new();
    let last = columns.len() - 1;
    let run = robot
        .run_flight(stop, &mut |r| {
            if r.step % stride != 0 || io.is_err() {
                return;
            }
            LoadedRobot::flight_row(r, &mut row);
            rows += 1;
            io = (|| {
                for (i, &x) in row.iter().enumerate() {
                    if i == last {
                        write!(w, "{}", r.newton_iterations)?;
                    } else {
                        write_number(&mut w, x, &mut buf)?;
                    }
                    w.write_all(if i == last { b"\n" } else { b"," })?;
                }
                Ok(())
            })();
        })
        .map_err(|e| crate::ConfigError::Semantic {
            file: source.to_owned(),
            message: e.to_string(),
        })?;
    let mut io_error = None;
    let mut keep = |r: Result<std::path::PathBuf, CliError>| {
        if let Err(e) = r
            && io_error.is_none()
        {
            io_error = Some(e);
        }
    };
    let trajectory = io
        .and_then(|()| w.flush())
        .map_err(|e| CliError::io(dest.display(), &e))
        .and_then(|()| {
            let tmp = w
                .into_inner()
                .map_err(|e| CliError::io(dest.display(), e.error()))?;
            output::persist(tmp, &dest)?;
            Ok(dest.clone())
        });
    keep(trajectory);
    let dt = robot.config.time.dt;
    let times = crate::steptime::StepTimes::new(dt);
    let interrupted = format!(
        "interrupted after {} of {} steps (t = {} s)",
        run.steps,
        run.steps_planned,
        times.string(run.steps, run.steps as f64 * dt)
    );
    let summary = RobotSummary {
        status: if run.error.is_some() {
            "error"
        } else if run.interrupted {
            "interrupted"
        } else {
            "ok"
        },
        error: match (&run.error, run.interrupted) {
            (Some(e), _) => Some(e.clone()),
            (None, true) => Some(interrupted),
            (None, false) => None,
        },
        model: crate::config::robot::MODEL,
        robot: robot.model.name.clone(),
        steps: run.steps,
        steps_planned: run.steps_planned,
        rows_written: rows,
        newton_iterations: run.newton_iterations,
        wall_seconds: run.wall_seconds,
        steps_per_second: (run.wall_seconds > 0.0).then(|| run.steps as f64 / run.wall_seconds),
        events: Vec::new(),
    };
    output::write_run_files(
        out_dir,
        EVENTS_HEADER,
        &summary,
        &robot.config.to_toml(),
        &mut keep,
    );
    if io_error.is_none() {
        io_error = output::remove_stale(out_dir, &FILES).err();
    }
    Ok(RobotRunOutput {
        run,
        summary,
        io_error,
    })
}

/// `fbd run` of a `model = "robot"` configuration `text` read from `path`:
/// simulates, writes the files, prints the step count, and ends like every
/// run ([`output::conclude`]: exit 3 after a simulation error, 130 when
/// interrupted).
pub fn run_command(
    text: &str,
    path: &Path,
    out_dir: &Path,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let source = path.display().to_string();
    let robot = crate::config::robot::load_str(text, path)?;
    let RobotRunOutput {
        run,
        summary,
        io_error,
    } = simulate(&robot, &source, out_dir, crate::interrupt::flag())?;
    let text = output::solved_line(
        run.error.is_some() || run.interrupted,
        run.steps,
        run.newton_iterations,
        run.wall_seconds,
    );
    let ending = if let Some(e) = &run.error {
        Ending::Failed {
            error: e.clone(),
            source,
            advice: None,
        }
    } else if run.interrupted {
        Ending::Interrupted(summary.error.clone().unwrap_or_default())
    } else {
        Ending::Completed
    };
    output::conclude(out, text, out_dir, &FILES, io_error, ending)
}

//! `fbd run` of an imported robot (`model = "robot"`): the run itself is
//! [`fbd_scenario::robot::LoadedRobot::run`] (the generic FBD model on its
//! terrain, or in flight with `[terrain] kind = "none"`); this module
//! writes `trajectory.csv` (streamed, every `[output] stride`-th step),
//! `events.csv`, `summary.json`, `config.toml` and `viewer.html` (unless
//! `[output] viewer = false`; [`crate::viewer::robot`]), each
//! all-or-nothing, also after a simulation error or an interruption.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use fbd_sim::robot::RobotRecord;

use serde::Serialize;

use crate::OutputError;
use crate::config::robot::{ColumnKind, LoadedRobot, RobotRun};
use crate::driver::{self, Recording, RunFiles, RunOutput, Stepper};
use crate::output::{self, Ending, IterationsPerStep};
use crate::steptime::StepTimes;

/// The files of a robot's run, in the order they are written (the last
/// only with `[output] viewer`).
pub const FILES: [&str; 5] = [
    "trajectory.csv",
    "events.csv",
    "summary.json",
    "config.toml",
    "viewer.html",
];

/// `events.csv`'s header for a robot.
pub const EVENTS_HEADER: &str = "t,point,from,to\n";

/// An event of a robot's run (`events.csv`, `summary.json`).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RobotEvent {
    /// Start of the first step solved in the new state (s).
    pub t: f64,
    /// The contact point's name; `<joint>_limit` for a joint reaching
    /// (`free` → `min`/`max`) or leaving an end of its range; `substeps`
    /// for a step solved again in substeps (`1` → `n`).
    pub point: String,
    /// Previous state.
    pub from: String,
    /// New state.
    pub to: String,
}

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
    /// Time step (s).
    pub dt: f64,
    /// Simulated time asked for (s).
    pub duration: f64,
    /// Steps solved.
    pub steps: usize,
    /// Steps planned (`round(duration/Δt) + 1`).
    pub steps_planned: usize,
    /// `[output] stride`.
    pub stride: usize,
    /// Rows of `trajectory.csv`.
    pub rows_written: usize,
    /// The contact points, in the order of their columns (none in flight).
    pub contact_points: Vec<String>,
    /// The root's horizontal distance from its start after the last step
    /// (m).
    pub distance: f64,
    /// The root's height `ry` after the last step (m).
    pub final_height: f64,
    /// The largest `|τ|` of any joint over the written rows (N·m).
    pub peak_torque_max: f64,
    /// The largest normal force of any contact point over the written
    /// rows (N).
    pub peak_normal_force: f64,
    /// Per contact point, the time of its first touchdown (`ST1` → `ST2`
    /// or `ST3`; null if it never touched or started in contact).
    pub first_touchdown: std::collections::BTreeMap<String, Option<f64>>,
    /// Newton iterations over the run.
    pub newton_iterations: usize,
    /// Mean and largest Newton iterations of one step.
    pub newton_iterations_per_step: IterationsPerStep,
    /// Time in the stepping loop (s).
    pub wall_seconds: f64,
    /// `steps / wall_seconds` (null when not measurable).
    pub steps_per_second: Option<f64>,
    /// Symbolic LU analyses (one per contact-state pattern).
    pub symbolic_factorizations: usize,
    /// Contact, joint-limit and retried-step events, as `events.csv`.
    pub events: Vec<RobotEvent>,
    /// Steps solved again in substeps.
    pub retried_steps: usize,
    /// Substeps solved over all retries.
    pub substeps: usize,
    /// State searches closed by their least inconsistent combination.
    pub resolved_cycles: usize,
    /// The largest violation of a contact or limit law over the accepted
    /// solutions (N; at most the cycle tolerance, 1e-7 of the weight).
    pub max_law_violation: f64,
}

/// What [`simulate`] did: how the run ended, `summary.json`'s content,
/// the files written.
pub type RobotRunOutput = RunOutput<RobotRun, RobotSummary>;

fn write_number(w: &mut impl Write, x: f64, buf: &mut ryu::Buffer) -> std::io::Result<()> {
    if x.is_finite() {
        w.write_all(buf.format_finite(x).as_bytes())
    } else {
        write!(w, "{x}")
    }
}

/// Every event of a robot's run in time order (contact events first at
/// equal times), named for `events.csv`, with each one's step.
pub fn robot_events(
    robot: &LoadedRobot,
    sim: &fbd_sim::robot::RobotSim,
    run: &fbd_sim::RunSummary,
    times: &StepTimes,
) -> Vec<(usize, f64, RobotEvent)> {
    let event = |point: String, from: &str, to: String, step, t| RobotEvent {
        t: times.value(step, t),
        point,
        from: from.to_owned(),
        to,
    };
    output::merge_events_as(
        &run.events,
        &run.limit_events,
        &run.retries,
        |e| {
            event(
                sim.mech.contacts[e.contact].name.clone(),
                e.from.as_str(),
                e.to.as_str().to_owned(),
                e.step,
                e.t,
            )
        },
        |e| {
            event(
                format!("{}_limit", robot.model.joints[e.joint_index].name),
                e.from.as_str(),
                e.to.as_str().to_owned(),
                e.step,
                e.t,
            )
        },
        |e| {
            event(
                output::RETRY_POINT.to_owned(),
                "1",
                e.substeps.to_string(),
                e.step,
                e.t,
            )
        },
    )
}

/// A robot's stepping: the engine on its simulator ([`LoadedRobot::run_sim`],
/// which hands over every `[output] stride`-th step).
struct RobotStepper<'a> {
    robot: &'a LoadedRobot,
    sim: &'a fbd_sim::robot::RobotSim,
}

impl Stepper<RobotRecord> for RobotStepper<'_> {
    type Run = RobotRun;
    fn step(&self, stop: &AtomicBool, mut each: impl FnMut(&RobotRecord)) -> RobotRun {
        self.robot.run_sim(self.sim, stop, &mut each)
    }
}

/// A robot's files ([`RunFiles`]): `trajectory.csv` streamed, the peaks,
/// the viewer's frames.
struct RobotFiles<'a> {
    robot: &'a LoadedRobot,
    sim: &'a fbd_sim::robot::RobotSim,
    dest: PathBuf,
    w: Option<BufWriter<tempfile::NamedTempFile>>,
    io: std::io::Result<()>,
    rows: usize,
    row: Vec<f64>,
    kinds: Vec<ColumnKind>,
    buf: ryu::Buffer,
    frames: Option<crate::viewer::robot::RobotFrames>,
    states: Vec<u8>,
    forces: Vec<[f64; 3]>,
    peak_torque: f64,
    peak_normal: f64,
    events_csv: String,
}

impl RunFiles for RobotFiles<'_> {
    type Record = RobotRecord;
    type Run = RobotRun;
    type Summary = RobotSummary;

    /// Every record is a row: the engine applies the stride.
    fn step_of(_: &RobotRecord) -> usize {
        0
    }

    fn row(&mut self, r: &RobotRecord) {
        for c in &r.contacts {
            self.peak_normal = self.peak_normal.max(c.normal);
        }
        for t in &r.torque {
            self.peak_torque = self.peak_torque.max(t.abs());
        }
        let contacts = self.states.len();
        if let Some(f) = self.frames.as_mut() {
            for (i, c) in r.contacts.iter().enumerate() {
                self.states[i] = c.state as u8 + 1;
                self.forces[i] = c.force;
            }
            f.push(
                r.t,
                &r.q,
                (contacts > 0).then_some((&self.states[..], &self.forces[..])),
            );
        }
        if self.io.is_err() {
            return;
        }
        LoadedRobot::row(r, &mut self.row);
        self.rows += 1;
        let last = self.kinds.len() - 1;
        let (Some(w), buf) = (self.w.as_mut(), &mut self.buf) else {
            return;
        };
        self.io = (|| {
            for (i, (&x, kind)) in self.row.iter().zip(&self.kinds).enumerate() {
                match kind {
                    ColumnKind::Number => write_number(w, x, buf)?,
                    ColumnKind::State => write!(w, "ST{}", x as u8)?,
                    ColumnKind::Count => write!(w, "{}", x as usize)?,
                }
                w.write_all(if i == last { b"\n" } else { b"," })?;
            }
            Ok(())
        })();
    }

    fn observe(&mut self, _: &RobotRecord) {}

    /// The rows counted are those written before a failure.
    fn summary(&mut self, run: &RobotRun, _: usize) -> RobotSummary {
        let (robot, sim) = (self.robot, self.sim);
        let dt = robot.config.time.dt;
        let times = StepTimes::new(dt);
        let s = &run.summary;
        let events = robot_events(robot, sim, s, &times);
        self.events_csv = output::events_table(EVENTS_HEADER, &events, &times, |e| {
            format!("{},{},{}", e.point, e.from, e.to)
        });
        RobotSummary {
            status: output::run_status(s),
            error: match (&s.error, s.interrupted) {
                (Some(e), _) => Some(e.to_string()),
                (None, true) => Some(output::interrupted_after(s, run.steps_planned, dt)),
                (None, false) => None,
            },
            model: crate::config::robot::MODEL,
            robot: robot.model.name.clone(),
            dt,
            duration: robot.config.time.duration,
            steps: s.steps,
            steps_planned: run.steps_planned,
            stride: robot.config.output.stride,
            rows_written: self.rows,
            contact_points: sim.mech.contacts.iter().map(|c| c.name.clone()).collect(),
            distance: (run.final_q[0] - robot.params().q0[0])
                .hypot(run.final_q[2] - robot.params().q0[2]),
            final_height: run.final_q[1],
            peak_torque_max: self.peak_torque,
            peak_normal_force: self.peak_normal,
            first_touchdown: sim
                .mech
                .contacts
                .iter()
                .enumerate()
                .map(|(c, tc)| {
                    let t = s
                        .events
                        .iter()
                        .find(|e| e.contact == c && e.from == fbd_contact::StateCode::St1)
                        .map(|e| times.value(e.step, e.t));
                    (tc.name.clone(), t)
                })
                .collect(),
            newton_iterations: s.newton_iterations,
            newton_iterations_per_step: IterationsPerStep::of(s),
            wall_seconds: s.wall_seconds,
            steps_per_second: output::steps_per_second(s),
            symbolic_factorizations: s.symbolic_factorizations,
            events: events.into_iter().map(|(_, _, e)| e).collect(),
            retried_steps: s.retries.len(),
            substeps: s.substeps,
            resolved_cycles: s.resolved_cycles,
            max_law_violation: s.max_law_violation,
        }
    }

    fn finish_trajectory(&mut self) -> Option<Result<PathBuf, OutputError>> {
        let dest = self.dest.clone();
        let io = std::mem::replace(&mut self.io, Ok(()));
        let mut w = self.w.take()?;
        Some(
            io.and_then(|()| w.flush().map(|()| w))
                .map_err(|e| OutputError::io(dest.display(), &e))
                .and_then(|w| {
                    let tmp = w
                        .into_inner()
                        .map_err(|e| OutputError::io(dest.display(), e.error()))?;
                    output::persist(tmp, &dest)?;
                    Ok(dest.clone())
                }),
        )
    }

    fn events_csv(&self, _: &RobotRun) -> String {
        self.events_csv.clone()
    }

    fn write_extras(
        self,
        dir: &Path,
        _: &RobotRun,
        keep: &mut output::FirstError,
    ) -> Vec<&'static str> {
        if let Some(mut f) = self.frames {
            if !self.states.is_empty() {
                f = f.with_surface(self.robot.config.terrain.surface());
            }
            f.set_event_rows(self.events_csv.lines().count() - 1);
            keep.keep(f.write(dir));
        }
        files(self.robot).to_vec()
    }
}

/// Simulates `robot` and writes its files in `out_dir` (created if
/// needed; files of an earlier run that this one does not write are
/// removed). The run stops before its next step once `stop` is set.
pub fn simulate(
    robot: &LoadedRobot,
    source: &str,
    out_dir: &Path,
    stop: &AtomicBool,
) -> Result<RobotRunOutput, OutputError> {
    let sim = robot.sim().map_err(|e| crate::ConfigError::Semantic {
        file: source.to_owned(),
        message: e.to_string(),
    })?;
    output::prepare_dir(out_dir)?;
    let columns = robot.columns(&sim);
    let dest = out_dir.join("trajectory.csv");
    let tmp = output::temp_in(out_dir, "trajectory.csv")?;
    let mut w = BufWriter::new(tmp);
    let io: std::io::Result<()> = w.write_all(format!("{}\n", columns.names.join(",")).as_bytes());
    let contacts = sim.mech.contacts.len();
    let files = RobotFiles {
        robot,
        sim: &sim,
        dest,
        w: Some(w),
        io,
        rows: 0,
        row: Vec::with_capacity(columns.names.len()),
        kinds: columns.kinds,
        buf: ryu::Buffer::new(),
        frames: robot
            .config
            .output
            .viewer
            .then(|| crate::viewer::robot::RobotFrames::new(&robot.model, contacts > 0)),
        states: vec![0u8; contacts],
        forces: vec![[0.0; 3]; contacts],
        peak_torque: 0.0,
        peak_normal: 0.0,
        events_csv: String::new(),
    };
    let stepper = RobotStepper { robot, sim: &sim };
    Ok(driver::drive(
        &stepper,
        Recording::new(files, 1, Some(out_dir)),
        stop,
        &robot.config.to_toml(),
        &mut |_| {},
    ))
}

/// The files a run of `robot` writes ([`FILES`], `viewer.html` only with
/// `[output] viewer`).
pub fn files(robot: &LoadedRobot) -> &'static [&'static str] {
    if robot.config.output.viewer {
        &FILES
    } else {
        &FILES[..4]
    }
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
) -> Result<(), OutputError> {
    let source = path.display().to_string();
    let robot = crate::config::robot::load_str(text, path)?;
    let RobotRunOutput {
        run,
        summary: _,
        io_error,
        files,
    } = simulate(&robot, &source, out_dir, crate::interrupt::flag())?;
    let s = &run.summary;
    let text = output::solved_line(
        s.error.is_some() || s.interrupted,
        s.steps,
        s.newton_iterations,
        s.wall_seconds,
    );
    let ending = Ending::of_run(s, &source, None, run.steps_planned, robot.config.time.dt);
    output::conclude(out, text, out_dir, &files, io_error, ending)
}

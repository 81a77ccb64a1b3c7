//! The files of `fbd run` (docs/reference.md): every file is written to a temporary
//! file in the output directory and renamed into place, so that it appears
//! completely or not at all.
//!
//! Numbers are written with [`ryu`]: the shortest decimal that reads back
//! bit-identical, deterministic across runs and platforms.

use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use fbd_sim::{Event, LimitEvent, RetryEvent, RunSummary, StepRecord};
use serde::Serialize;
use tempfile::NamedTempFile;

use crate::CliError;
use crate::steptime::StepTimes;

/// Names of the files `fbd run` writes, in the order they are written.
/// (`torques.svg` is written too when a joint is actuated.)
pub const FILES: [&str; 10] = [
    "trajectory.csv",
    "events.csv",
    "summary.json",
    "config.toml",
    "tips.svg",
    "forces.svg",
    "stance.svg",
    "joints.svg",
    "energy.svg",
    "viewer.html",
];

/// The contract's trajectory columns, in order; extras follow (see
/// [`trajectory_columns`]).
pub const SPEC_COLUMNS: [&str; 26] = [
    "t", "rx", "ry", "phi_z", "theta2_3", "theta3_3", "theta2_4", "theta3_4", "tip3_x", "tip3_y",
    "tip4_x", "tip4_y", "state3", "state4", "fa3", "n3", "fa4", "n4", "hip3_fx", "hip3_fy",
    "knee3_fx", "knee3_fy", "hip4_fx", "hip4_fy", "knee4_fx", "knee4_fy",
];

/// Columns after the contact-point triples; `stop_*` are the moments of
/// the joint-limit stops (N·m, like the torques positive towards larger
/// joint angles; 0 while the joint is inside its range).
pub const TAIL_COLUMNS: [&str; 12] = [
    "tau_hip3",
    "tau_knee3",
    "tau_hip4",
    "tau_knee4",
    "kinetic",
    "potential",
    "energy",
    "newton_iterations",
    "stop_hip3",
    "stop_knee3",
    "stop_hip4",
    "stop_knee4",
];

/// A new temporary file in `dir`, readable like an ordinary file once
/// renamed ([`persist`]).
pub fn temp_in(dir: &Path, name: &str) -> Result<NamedTempFile, CliError> {
    let prefix = format!(".{name}.");
    let mut b = tempfile::Builder::new();
    b.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    b.tempfile_in(dir)
        .map_err(|e| CliError::io(format!("{}: cannot create a file", dir.display()), &e))
}

/// Renames a finished temporary file to `dest` (all-or-nothing).
pub fn persist(tmp: NamedTempFile, dest: &Path) -> Result<(), CliError> {
    tmp.persist(dest)
        .map_err(|e| CliError::io(dest.display(), &e.error))?;
    Ok(())
}

/// `n` and the noun agreeing with it: `count(1, "run", "runs")` is
/// `"1 run"`, `count(2, …)` `"2 runs"`.
pub fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// How a run ended, for [`conclude`]: `Ok` or the message of its error.
pub enum Ending {
    /// Every step was solved.
    Completed,
    /// The simulation failed.
    Failed {
        /// The simulator's message (names the step and time).
        error: String,
        /// The configuration's file name.
        source: String,
        /// What to change, if the loader can tell (e.g. a smaller Δt).
        advice: Option<String>,
    },
    /// Stopped by SIGINT/SIGTERM; the message says where.
    Interrupted(String),
}

/// The end of `fbd run` for every model: prints the report `text` (with
/// the list of files unless writing them failed), then turns the outcome
/// into the command's result: the I/O error first, then the simulation
/// error or the interruption, each saying where the steps computed so far
/// are.
pub fn conclude(
    out: &mut dyn Write,
    mut text: String,
    out_dir: &Path,
    files: &[&str],
    io_error: Option<CliError>,
    ending: Ending,
) -> Result<(), CliError> {
    if io_error.is_none() {
        text.push_str(&format!(
            "files in {}: {}\n",
            out_dir.display(),
            files.join(" ")
        ));
    }
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(CliError::stdout)?;
    if let Some(e) = io_error {
        return Err(e);
    }
    let saved = format!("the steps computed so far are in {}", out_dir.display());
    match ending {
        Ending::Completed => Ok(()),
        Ending::Failed {
            error,
            source,
            advice,
        } => Err(CliError::Simulation(format!(
            "{error} ({source}; {saved}){}",
            advice.map(|a| format!("; {a}")).unwrap_or_default()
        ))),
        Ending::Interrupted(msg) => Err(CliError::Interrupted(format!("{msg}; {saved}"))),
    }
}

/// The files every run writes beside its trajectory and plots:
/// `events.csv`, `summary.json` (pretty JSON of `summary`) and `config.toml`,
/// each all-or-nothing. Every file is attempted; each result goes to `keep`
/// (which remembers the first failure).
pub fn write_run_files(
    dir: &Path,
    events_csv: &str,
    summary: &impl Serialize,
    config_toml: &str,
    keep: &mut impl FnMut(Result<PathBuf, CliError>),
) {
    keep(write_file(dir, "events.csv", events_csv.as_bytes()));
    let json = serde_json::to_string_pretty(summary)
        .map_err(|e| CliError::Io(format!("summary.json: {e}")));
    keep(json.and_then(|j| write_file(dir, "summary.json", format!("{j}\n").as_bytes())));
    keep(write_file(dir, "config.toml", config_toml.as_bytes()));
}

/// Writes `bytes` to `dir/name` all-or-nothing; returns the path.
pub fn write_file(dir: &Path, name: &str, bytes: &[u8]) -> Result<PathBuf, CliError> {
    let dest = dir.join(name);
    let mut tmp = temp_in(dir, name)?;
    tmp.write_all(bytes)
        .and_then(|()| tmp.flush())
        .map_err(|e| CliError::io(dest.display(), &e))?;
    persist(tmp, &dest)?;
    Ok(dest)
}

/// Removes from `dir` every file that `fbd run` may write, for any
/// model ([`FILES`], `torques.svg`, [`crate::hexapod::FILES`],
/// [`crate::spatial::FILES`]), that the
/// run just finished did not write (`written`), so that no file of an
/// earlier run (its `torques.svg`, or the planar plots after a hexapod run)
/// is left beside the new ones looking current. A file that cannot be
/// removed is an input/output error.
pub fn remove_stale(dir: &Path, written: &[&str]) -> Result<(), CliError> {
    let known = FILES
        .iter()
        .chain(&["torques.svg"])
        .chain(&crate::hexapod::FILES)
        .chain(&crate::spatial::FILES);
    for name in known.filter(|n| !written.contains(n)) {
        let path = dir.join(name);
        match std::fs::remove_file(&path) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => {
                return Err(CliError::io(
                    format!(
                        "{}: cannot remove the file of an earlier run",
                        path.display()
                    ),
                    &e,
                ));
            }
            _ => {}
        }
    }
    Ok(())
}

/// Creates `dir` if needed and checks that files can be created in it.
pub fn prepare_dir(dir: &Path) -> Result<(), CliError> {
    if dir.exists() && !dir.is_dir() {
        return Err(CliError::Io(format!(
            "{}: exists and is not a directory",
            dir.display()
        )));
    }
    std::fs::create_dir_all(dir).map_err(|e| {
        CliError::io(
            format!("{}: cannot create the output directory", dir.display()),
            &e,
        )
    })?;
    // Probe: creating (and dropping) a temporary file proves writability.
    temp_in(dir, "probe").map(drop)
}

/// The trajectory columns for a model whose contact points are named
/// `contacts` (e.g. `["tip3", "tip4", "knee3", "knee4"]`): the contract's list,
/// then `<name>_state, <name>_fa, <name>_n` for every contact point that is
/// not a tip, then [`TAIL_COLUMNS`].
pub fn trajectory_columns(contacts: &[String]) -> Vec<String> {
    let mut c: Vec<String> = SPEC_COLUMNS.iter().map(|s| (*s).to_owned()).collect();
    for name in contacts.iter().filter(|n| !is_tip(n)) {
        for suffix in ["state", "fa", "n"] {
            c.push(format!("{name}_{suffix}"));
        }
    }
    c.extend(TAIL_COLUMNS.iter().map(|s| (*s).to_owned()));
    c
}

fn is_tip(name: &str) -> bool {
    name == "tip3" || name == "tip4"
}

/// Streams `trajectory.csv` through a buffer into a temporary file; no
/// allocation per row.
pub struct TrajectoryWriter {
    out: BufWriter<NamedTempFile>,
    dest: PathBuf,
    num: ryu::Buffer,
    times: StepTimes,
    tips: [Option<usize>; 2],
    extras: Vec<usize>,
    error: Option<io::Error>,
    rows: usize,
}

impl TrajectoryWriter {
    /// Opens the temporary file in `dir` and writes the header; `dt` is
    /// the time step (times are written as the decimal of k·Δt).
    pub fn create(dir: &Path, contacts: &[String], dt: f64) -> Result<Self, CliError> {
        let dest = dir.join("trajectory.csv");
        let tmp = temp_in(dir, "trajectory.csv")?;
        let mut w = Self {
            out: BufWriter::with_capacity(1 << 16, tmp),
            dest,
            num: ryu::Buffer::new(),
            times: StepTimes::new(dt),
            tips: [
                contacts.iter().position(|n| n == "tip3"),
                contacts.iter().position(|n| n == "tip4"),
            ],
            extras: (0..contacts.len())
                .filter(|&i| !is_tip(&contacts[i]))
                .collect(),
            error: None,
            rows: 0,
        };
        let header = trajectory_columns(contacts).join(",");
        if let Err(e) = writeln!(w.out, "{header}") {
            return Err(CliError::io(w.dest.display(), &e));
        }
        Ok(w)
    }

    /// Rows written so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Appends the row of `r`. An I/O error is kept and reported by
    /// [`TrajectoryWriter::finish`]; later rows are skipped.
    pub fn write(&mut self, r: &StepRecord) {
        if self.error.is_some() {
            return;
        }
        match self.write_row(r) {
            Ok(()) => self.rows += 1,
            Err(e) => self.error = Some(e),
        }
    }

    fn f(&mut self, x: f64) -> io::Result<()> {
        self.out.write_all(b",")?;
        self.out.write_all(self.num.format(x).as_bytes())
    }

    fn s(&mut self, s: &str) -> io::Result<()> {
        self.out.write_all(b",")?;
        self.out.write_all(s.as_bytes())
    }

    fn write_row(&mut self, r: &StepRecord) -> io::Result<()> {
        self.times.write(&mut self.out, r.step, r.t)?;
        for &x in &r.q {
            self.f(x)?;
        }
        let tips = self.tips;
        for c in tips {
            let p = c.map_or([f64::NAN; 2], |c| r.point[c]);
            self.f(p[0])?;
            self.f(p[1])?;
        }
        for c in tips {
            self.s(c.map_or("ST1", |c| r.state[c].as_str()))?;
        }
        for c in tips {
            let (fa, n) = c.map_or((0.0, 0.0), |c| (r.fa[c], r.n[c]));
            self.f(fa)?;
            self.f(n)?;
        }
        for j in &r.joint_force {
            self.f(j[0])?;
            self.f(j[1])?;
        }
        for k in 0..self.extras.len() {
            let c = self.extras[k];
            self.s(r.state[c].as_str())?;
            self.f(r.fa[c])?;
            self.f(r.n[c])?;
        }
        for &t in &r.torque {
            self.f(t)?;
        }
        self.f(r.kinetic)?;
        self.f(r.potential)?;
        self.f(r.kinetic + r.potential)?;
        write!(self.out, ",{}", r.newton_iterations)?;
        for &m in &r.limit_moment {
            self.f(m)?;
        }
        self.out.write_all(b"\n")
    }

    /// Flushes and renames the file into place.
    pub fn finish(self) -> Result<PathBuf, CliError> {
        let dest = self.dest;
        if let Some(e) = self.error {
            return Err(CliError::io(dest.display(), &e));
        }
        let tmp = self
            .out
            .into_inner()
            .map_err(|e| CliError::io(dest.display(), e.error()))?;
        persist(tmp, &dest)?;
        Ok(dest)
    }
}

/// `events.csv`: header `t,leg,from,to,point`, one row per event; times
/// as the decimal of k·Δt.
pub fn events_csv(events: &[Event], dt: f64) -> String {
    let mut s = String::from("t,leg,from,to,point\n");
    let times = StepTimes::new(dt);
    for e in events {
        s.push_str(&times.string(e.step, e.t));
        s.push_str(&format!(
            ",{},{},{},{}\n",
            e.leg,
            e.from.as_str(),
            e.to.as_str(),
            e.point
        ));
    }
    s
}

/// An event as written to `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EventJson {
    /// Start of the first step solved in the new state (s).
    pub t: f64,
    /// Hexapod leg number (null for a retried step).
    pub leg: Option<usize>,
    /// `tip`, `knee` or `hip`; `hip_limit` or `knee_limit` for a joint
    /// reaching (`free` → `min`/`max`) or leaving an end of its range;
    /// `substeps` for a step solved again in substeps (`1` → `n`).
    pub point: String,
    /// Previous state.
    pub from: String,
    /// New state.
    pub to: String,
}

impl EventJson {
    /// The event with its time rounded to the decimal of k·Δt.
    pub fn new(e: &Event, times: &StepTimes) -> Self {
        Self {
            t: times.value(e.step, e.t),
            leg: Some(e.leg),
            point: e.point.to_owned(),
            from: e.from.as_str().to_owned(),
            to: e.to.as_str().to_owned(),
        }
    }

    /// A joint-limit event.
    pub fn limit(e: &LimitEvent, times: &StepTimes) -> Self {
        Self {
            t: times.value(e.step, e.t),
            leg: Some(e.leg),
            point: e.point().to_owned(),
            from: e.from.as_str().to_owned(),
            to: e.to.as_str().to_owned(),
        }
    }

    /// A step retried in `n` substeps: `from` 1, `to` n.
    pub fn retry(e: &RetryEvent, times: &StepTimes) -> Self {
        Self {
            t: times.value(e.step, e.t),
            leg: None,
            point: "substeps".to_owned(),
            from: "1".to_owned(),
            to: e.substeps.to_string(),
        }
    }
}

/// Every event of a run — contact, joint-limit and retried-step events —
/// in time order (contact events first at equal times), with the step and
/// floating-point time of each.
pub fn run_events(run: &RunSummary, times: &StepTimes) -> Vec<(usize, f64, EventJson)> {
    merge_events(&run.events, &run.limit_events, &run.retries, times)
}

/// [`run_events`] of the event lists themselves (e.g. a
/// [`fbd_sim::Data`]'s during a run stepped from outside).
pub fn merge_events(
    events: &[Event],
    limit_events: &[LimitEvent],
    retries: &[RetryEvent],
    times: &StepTimes,
) -> Vec<(usize, f64, EventJson)> {
    let mut all: Vec<(usize, f64, EventJson)> = events
        .iter()
        .map(|e| (e.step, e.t, EventJson::new(e, times)))
        .chain(
            limit_events
                .iter()
                .map(|e| (e.step, e.t, EventJson::limit(e, times))),
        )
        .chain(
            retries
                .iter()
                .map(|e| (e.step, e.t, EventJson::retry(e, times))),
        )
        .collect();
    all.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    all
}

/// `events.csv` of a whole run ([`run_events`]): contact events as
/// [`events_csv`] writes them, then joint-limit rows (`t,4,free,max,knee_limit`)
/// and retried steps (`t,,1,8,substeps`: the leg is empty) in time order.
pub fn run_events_csv(run: &RunSummary, dt: f64) -> String {
    let mut s = String::from("t,leg,from,to,point\n");
    let times = StepTimes::new(dt);
    for (step, t, e) in run_events(run, &times) {
        s.push_str(&times.string(step, t));
        let leg = e.leg.map(|l| l.to_string()).unwrap_or_default();
        s.push_str(&format!(",{leg},{},{},{}\n", e.from, e.to, e.point));
    }
    s
}

/// Newton iterations per step (`summary.json`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct IterationsPerStep {
    /// Mean over the solved steps (0 when none).
    pub mean: f64,
    /// Most of one step (all its state trials and substeps).
    pub max: usize,
}

impl IterationsPerStep {
    /// The figures of a run.
    pub fn of(run: &fbd_sim::RunSummary) -> Self {
        Self {
            mean: if run.steps > 0 {
                run.newton_iterations as f64 / run.steps as f64
            } else {
                0.0
            },
            max: run.max_newton_iterations,
        }
    }
}

/// Peak contact forces of one contact point over the run (N).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct PeakForce {
    /// Largest normal force.
    pub n: f64,
    /// Largest |tangential force|.
    pub fa: f64,
}

/// Mechanical energy at the last solved step.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Energy {
    /// Time of that step (s).
    pub t: f64,
    /// Kinetic energy (J).
    pub kinetic: f64,
    /// Gravitational potential energy (J).
    pub potential: f64,
    /// Their sum (J).
    pub total: f64,
}

/// `summary.json`.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// `"ok"`, `"error"`, or `"interrupted"` (SIGINT/SIGTERM stopped the
    /// run; the steps before are written).
    pub status: &'static str,
    /// The error message, or null.
    pub error: Option<String>,
    /// Steps solved.
    pub steps: usize,
    /// Newton iterations over the whole run.
    pub newton_iterations: usize,
    /// Newton iterations per step: the mean and the most of one step.
    pub newton_iterations_per_step: IterationsPerStep,
    /// Of `newton_iterations`, the chord steps (a factorisation kept from
    /// an earlier iterate or step).
    pub chord_iterations: usize,
    /// Of `newton_iterations`, the full Newton steps (the Jacobian factored
    /// at the iterate).
    pub full_newton_iterations: usize,
    /// Numeric LU factorisations over the whole run.
    pub numeric_factorizations: u64,
    /// Time in the stepping loop alone (s).
    pub wall_seconds: f64,
    /// `steps / wall_seconds` (null when not measurable).
    pub steps_per_second: Option<f64>,
    /// Symbolic LU factorisations performed.
    pub symbolic_factorizations: usize,
    /// Contact, joint-limit and retried-step events, as `events.csv`.
    pub events: Vec<EventJson>,
    /// Steps that could not be solved whole and were solved in substeps
    /// of Δt/2, Δt/4, … (each is a `substeps` event).
    pub retried_steps: usize,
    /// State searches that found no consistent combination and were closed
    /// by the combination that violates the contact and limit laws least.
    pub resolved_cycles: usize,
    /// `"planar"`.
    pub model: &'static str,
    /// Time step (s).
    pub dt: f64,
    /// Configured duration (s).
    pub duration: f64,
    /// Steps the run was to solve.
    pub steps_planned: usize,
    /// Every `stride`-th step is in `trajectory.csv`.
    pub stride: usize,
    /// Rows of `trajectory.csv`.
    pub rows_written: usize,
    /// Contact points of the model, e.g. `["tip3", "tip4"]`.
    pub contact_points: Vec<String>,
    /// First ST1 → contact change of each leg's tip (s), e.g. `"leg4"`.
    pub first_touchdown: std::collections::BTreeMap<String, Option<f64>>,
    /// First change of each leg's tip into ST3 (s).
    pub first_slip: std::collections::BTreeMap<String, Option<f64>>,
    /// Largest contact forces of each contact point.
    pub peak_contact_force: std::collections::BTreeMap<String, PeakForce>,
    /// Largest joint force magnitude of each joint (N).
    pub peak_joint_force: std::collections::BTreeMap<String, f64>,
    /// Largest joint force magnitude of all joints (N).
    pub peak_joint_force_max: f64,
    /// Energy at the last solved step (null if none).
    pub final_energy: Option<Energy>,
}

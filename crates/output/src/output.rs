//! The files of `fbd run` (docs/reference.md): every file is written to a temporary
//! file in the output directory and renamed into place, so that it appears
//! completely or not at all.
//!
//! Numbers are written with [`ryu`]: the shortest decimal that reads back
//! bit-identical, deterministic across runs and platforms.

use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};

use fbd_contact::StateCode;
use fbd_dynamics::{ContactSpec, PointKind};
use fbd_kinematics::planar::hexapod_leg_number;
use fbd_sim::{Event, LimitEvent, RetryEvent, RunSummary};
use serde::Serialize;
use tempfile::NamedTempFile;

use crate::OutputError;
use crate::steptime::StepTimes;
use crate::tree::{Plan, Source};

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
pub fn temp_in(dir: &Path, name: &str) -> Result<NamedTempFile, OutputError> {
    let prefix = format!(".{name}.");
    let mut b = tempfile::Builder::new();
    b.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        b.permissions(std::fs::Permissions::from_mode(0o666));
    }
    b.tempfile_in(dir)
        .map_err(|e| OutputError::io(format!("{}: cannot create a file", dir.display()), &e))
}

/// Renames a finished temporary file to `dest` (all-or-nothing).
pub fn persist(tmp: NamedTempFile, dest: &Path) -> Result<(), OutputError> {
    tmp.persist(dest)
        .map_err(|e| OutputError::io(dest.display(), &e.error))?;
    Ok(())
}

/// A trajectory file larger than this (bytes, estimated before the run)
/// gets a warning on stderr (docs/reference.md, "Output size").
pub const LARGE_TRAJECTORY: f64 = 100e6;

/// Bytes per value of `trajectory.csv` (a shortest round-trip decimal and
/// its comma; about 19 for the 3D hexapod's values) and of
/// `trajectory.parquet` (8-byte doubles, less where a column repeats).
fn bytes_per_value(format: fbd_scenario::OutputFormat) -> f64 {
    match format {
        fbd_scenario::OutputFormat::Csv => 19.0,
        fbd_scenario::OutputFormat::Parquet => 8.0,
    }
}

/// The warning for a run writing `rows` rows of `columns` values every
/// `stride`-th step in `format`, when the estimate exceeds
/// [`LARGE_TRAJECTORY`]: the size and the stride (and format) that would
/// keep it under.
pub fn size_warning(
    rows: usize,
    columns: usize,
    stride: usize,
    format: fbd_scenario::OutputFormat,
) -> Option<String> {
    let bytes = rows as f64 * columns as f64 * bytes_per_value(format);
    if bytes <= LARGE_TRAJECTORY {
        return None;
    }
    let factor = (bytes / LARGE_TRAJECTORY).ceil() as usize;
    let parquet = match format {
        fbd_scenario::OutputFormat::Csv => {
            " or `format = \"parquet\"` (about 2.5 times smaller, many times faster to load)"
        }
        fbd_scenario::OutputFormat::Parquet => "",
    };
    Some(format!(
        "warning: {} will be about {:.0} MB ({rows} rows of {columns} columns); `[output] stride = {}` keeps it under {:.0} MB{parquet}",
        format.trajectory_file(),
        bytes / 1e6,
        stride.max(1) * factor,
        LARGE_TRAJECTORY / 1e6
    ))
}

/// Prints [`size_warning`] on stderr, once per process (a sweep's runs
/// share one).
pub fn warn_size(rows: usize, columns: usize, stride: usize, format: fbd_scenario::OutputFormat) {
    static WARNED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
    if let Some(w) = size_warning(rows, columns, stride, format)
        && !WARNED.swap(true, std::sync::atomic::Ordering::Relaxed)
    {
        eprintln!("{w}");
    }
}

/// A sweep that will write more than this (bytes, estimated before its
/// first run: every run's trajectory file, and its viewer and plots when
/// asked for) gets one warning on stderr (docs/sweep.md, "Output size").
pub const LARGE_SWEEP: f64 = 500e6;

/// About what one run's `viewer.html` adds: three.js and the page (some
/// 0.76 MB a planar run; a hexapod's page is larger, about 2 MB).
pub const VIEWER_BYTES: [f64; 2] = [0.8e6, 2.0e6];

/// About what one run's plots (`*.svg`) add: planar, hexapod.
pub const PLOTS_BYTES: [f64; 2] = [0.1e6, 0.3e6];

/// One run's trajectory file as a sweep plans it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TrajectorySize {
    /// Rows written (`steps / stride`, rounded up).
    pub rows: usize,
    /// Columns of a row.
    pub columns: usize,
    /// `[output] stride`.
    pub stride: usize,
    /// `[output] format`.
    pub format: fbd_scenario::OutputFormat,
    /// A hexapod run (its viewer and plots are larger).
    pub hexapod: bool,
}

impl TrajectorySize {
    /// The estimated size of the trajectory file (bytes).
    pub fn bytes(&self) -> f64 {
        self.rows as f64 * self.columns as f64 * bytes_per_value(self.format)
    }

    /// The estimated size of the run's viewer and plots (bytes), as asked.
    pub fn extras(&self, viewer: bool, plots: bool) -> f64 {
        let h = usize::from(self.hexapod);
        f64::from(u8::from(viewer)) * VIEWER_BYTES[h] + f64::from(u8::from(plots)) * PLOTS_BYTES[h]
    }
}

/// The warning for a sweep whose runs will write about more than
/// [`LARGE_SWEEP`] bytes: the estimate, what it is made of, and what would
/// shrink it (the runs without `--viewer`/`--plots`; a stride that keeps
/// the trajectory files under the limit; Parquet for CSV).
pub fn sweep_size_warning(runs: &[TrajectorySize], viewer: bool, plots: bool) -> Option<String> {
    let traj: f64 = runs.iter().map(TrajectorySize::bytes).sum();
    let extras: f64 = runs.iter().map(|r| r.extras(viewer, plots)).sum();
    let total = traj + extras;
    if total <= LARGE_SWEEP {
        return None;
    }
    let mb = |b: f64| crate::sweep::human_bytes(b as u64);
    let mut parts = format!("trajectory files {}", mb(traj));
    if viewer || plots {
        parts.push_str(&format!(", viewers and plots {}", mb(extras)));
    }
    let mut shrink = Vec::new();
    if (viewer || plots) && extras >= total / 10.0 {
        let flags = match (viewer, plots) {
            (true, true) => "--viewer and --plots",
            (true, false) => "--viewer",
            _ => "--plots",
        };
        shrink.push(format!(
            "without {flags} it writes {} (`fbd view DIR/runs/<i>` writes one run's viewer later)",
            mb(traj)
        ));
    }
    if traj > LARGE_SWEEP / 2.0 {
        let stride = runs.iter().map(|r| r.stride.max(1)).max().unwrap_or(1);
        let factor = (traj / (LARGE_SWEEP / 2.0)).ceil() as usize;
        shrink.push(format!(
            "`[output] stride = {s}` in the base configuration (or `[set] \"output.stride\" = {s}` in the sweep file) keeps the trajectory files under {}",
            mb(LARGE_SWEEP / 2.0),
            s = stride * factor,
        ));
        if runs
            .iter()
            .any(|r| r.format == fbd_scenario::OutputFormat::Csv)
        {
            shrink.push("`format = \"parquet\"` makes them about 2.5 times smaller".to_owned());
        }
    }
    Some(format!(
        "warning: this sweep will write about {} ({}: {parts}); {}",
        mb(total),
        count(runs.len(), "run", "runs"),
        shrink.join("; ")
    ))
}

/// `x` with `decimals` decimals, never `-0.0000`: a value that rounds to
/// zero prints without a sign.
pub fn fixed(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    match s.strip_prefix('-') {
        Some(rest) if rest.bytes().all(|b| b == b'0' || b == b'.') => rest.to_owned(),
        _ => s,
    }
}

/// `n` and the noun agreeing with it: `count(1, "run", "runs")` is
/// `"1 run"`, `count(2, …)` `"2 runs"`.
pub fn count(n: usize, one: &str, many: &str) -> String {
    format!("{n} {}", if n == 1 { one } else { many })
}

/// What a run of the paper's models prints before its own figures: every
/// contact, limit and retry event in time order, one line each
/// ([`crate::run::event_line`]), then [`solved`].
pub fn run_report(run: &RunSummary, dt: f64) -> String {
    let mut text = String::new();
    let times = StepTimes::new(dt);
    for (step, t, e) in run_events(run, &times) {
        text.push_str(&crate::run::event_line(&times.string(step, t), &e));
        text.push('\n');
    }
    text.push_str(&solved(run));
    text
}

/// [`solved_line`] of a run.
pub fn solved(run: &RunSummary) -> String {
    solved_line(
        run.error.is_some() || run.interrupted,
        run.steps,
        run.newton_iterations,
        run.wall_seconds,
    )
}

/// The closing line every run prints: `solved 101 steps, 214 Newton
/// iterations, 0.001 s` (or `stopped after …` when the run did not finish).
pub fn solved_line(stopped: bool, steps: usize, newton_iterations: usize, wall: f64) -> String {
    format!(
        "{} {}, {}, {:.3} s\n",
        if stopped { "stopped after" } else { "solved" },
        count(steps, "step", "steps"),
        count(newton_iterations, "Newton iteration", "Newton iterations"),
        wall
    )
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

impl Ending {
    /// How a dynamic run (planar, 3D hexapod, robot) of `steps_planned`
    /// steps of `dt` ended: failed with its error (and `advice`),
    /// interrupted after its last step, or completed.
    pub fn of_run(
        run: &RunSummary,
        source: &str,
        advice: Option<String>,
        steps_planned: usize,
        dt: f64,
    ) -> Self {
        if let Some(e) = &run.error {
            Ending::Failed {
                error: e.to_string(),
                source: source.to_owned(),
                advice,
            }
        } else if run.interrupted {
            Ending::Interrupted(interrupted_after(run, steps_planned, dt))
        } else {
            Ending::Completed
        }
    }
}

/// `interrupted after 12 of 500 steps (t = 0.011 s)`.
pub fn interrupted_after(run: &RunSummary, steps_planned: usize, dt: f64) -> String {
    format!(
        "interrupted after {} of {} steps (t = {} s)",
        run.steps,
        steps_planned,
        StepTimes::new(dt).string(run.steps, run.steps as f64 * dt)
    )
}

/// The first failure among the files of a run, every file being
/// attempted ([`FirstError::keep`] each result).
#[derive(Debug, Default)]
pub struct FirstError(pub Option<OutputError>);

impl FirstError {
    /// Keeps `r`'s error unless an earlier one is kept.
    pub fn keep(&mut self, r: Result<PathBuf, OutputError>) {
        if let Err(e) = r
            && self.0.is_none()
        {
            self.0 = Some(e);
        }
    }
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
    io_error: Option<OutputError>,
    ending: Ending,
) -> Result<(), OutputError> {
    if io_error.is_none() {
        text.push_str(&format!(
            "files in {}: {}\n",
            out_dir.display(),
            files.join(" ")
        ));
    }
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(OutputError::stdout)?;
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
        } => Err(OutputError::Simulation(format!(
            "{error} ({source}; {saved}){}",
            advice.map(|a| format!("; {a}")).unwrap_or_default()
        ))),
        Ending::Interrupted(msg) => Err(OutputError::Interrupted(format!("{msg}; {saved}"))),
    }
}

/// The files every run writes beside its trajectory and plots:
/// `events.csv`, `summary.json` (pretty JSON of `summary`) and `config.toml`,
/// each all-or-nothing. Every file is attempted; `keep` remembers the
/// first failure.
pub fn write_run_files(
    dir: &Path,
    events_csv: &str,
    summary: &impl Serialize,
    config_toml: &str,
    keep: &mut FirstError,
) {
    keep.keep(write_file(dir, "events.csv", events_csv.as_bytes()));
    let json = serde_json::to_string_pretty(summary)
        .map_err(|e| OutputError::Io(format!("summary.json: {e}")));
    keep.keep(json.and_then(|j| write_file(dir, "summary.json", format!("{j}\n").as_bytes())));
    keep.keep(write_file(dir, "config.toml", config_toml.as_bytes()));
}

/// Writes `bytes` to `dir/name` all-or-nothing; returns the path.
pub fn write_file(dir: &Path, name: &str, bytes: &[u8]) -> Result<PathBuf, OutputError> {
    let dest = dir.join(name);
    let mut tmp = temp_in(dir, name)?;
    tmp.write_all(bytes)
        .and_then(|()| tmp.flush())
        .map_err(|e| OutputError::io(dest.display(), &e))?;
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
pub fn remove_stale(dir: &Path, written: &[&str]) -> Result<(), OutputError> {
    let known = FILES
        .iter()
        .chain(&["torques.svg", "trajectory.parquet"])
        .chain(&crate::hexapod::FILES)
        .chain(&crate::spatial::FILES);
    for name in known.filter(|n| !written.contains(n)) {
        let path = dir.join(name);
        match std::fs::remove_file(&path) {
            Err(e) if e.kind() != io::ErrorKind::NotFound => {
                return Err(OutputError::io(
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

/// The file names of a run (`files`, with `trajectory.csv`) when its
/// trajectory is written in `format`.
pub fn files_as(files: &[&'static str], format: fbd_scenario::OutputFormat) -> Vec<&'static str> {
    files
        .iter()
        .map(|&f| {
            if f == "trajectory.csv" {
                format.trajectory_file()
            } else {
                f
            }
        })
        .collect()
}

/// `files` without the plots (`*.svg`) when `output.plots` is false and
/// without `viewer.html` when `output.viewer` is false.
pub fn selected(
    files: Vec<&'static str>,
    output: &fbd_scenario::OutputConfig,
) -> Vec<&'static str> {
    files
        .into_iter()
        .filter(|f| {
            (output.plots || !f.ends_with(".svg")) && (output.viewer || *f != "viewer.html")
        })
        .collect()
}

/// Creates `dir` if needed and checks that files can be created in it.
pub fn prepare_dir(dir: &Path) -> Result<(), OutputError> {
    if dir.exists() && !dir.is_dir() {
        return Err(OutputError::Io(format!(
            "{}: exists and is not a directory",
            dir.display()
        )));
    }
    std::fs::create_dir_all(dir).map_err(|e| {
        OutputError::io(
            format!("{}: cannot create the output directory", dir.display()),
            &e,
        )
    })?;
    // Probe: creating (and dropping) a temporary file proves writability.
    temp_in(dir, "probe").map(drop)
}

/// The legs of the planar model by their hexapod numbers (3, 4), in the
/// order of the contract's per-leg columns (`tip3_x`, …, `tip4_x`, …).
pub const PLANAR_LEGS: [usize; 2] = [hexapod_leg_number(0), hexapod_leg_number(1)];

/// The columns of a contact point's state, tangential and normal force,
/// named from its `{leg, kind}`: the contract's `state{leg}, fa{leg},
/// n{leg}` for a tip, `{kind}{leg}_state, {kind}{leg}_fa, {kind}{leg}_n`
/// (`knee3_state`, `hip4_n`) for a knee or a hip.
pub fn contact_columns(leg: usize, kind: PointKind) -> [String; 3] {
    match kind {
        PointKind::Tip => [format!("state{leg}"), format!("fa{leg}"), format!("n{leg}")],
        PointKind::Knee | PointKind::Hip => {
            ["state", "fa", "n"].map(|s| format!("{}{leg}_{s}", kind.as_str()))
        }
    }
}

/// Where the values of each contact point go in a row of
/// `trajectory.csv`, found by the points' `{leg, kind}` (never by name).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct ContactSlots {
    /// Per leg of [`PLANAR_LEGS`]: the index of its tip among the contact
    /// points; `None` when the tip is not one (the row then holds a NaN
    /// position, `ST1` and zero forces).
    pub tips: [Option<usize>; 2],
    /// Every other contact point (knees and hips), in the model's order:
    /// its index, leg and kind.
    pub extras: Vec<(usize, usize, PointKind)>,
}

impl ContactSlots {
    /// The slots of a model whose contact points are `contacts` (record
    /// order, e.g. `model.mech.contacts`).
    pub fn of(contacts: &[ContactSpec]) -> Self {
        let tips = PLANAR_LEGS.map(|leg| {
            contacts
                .iter()
                .position(|c| c.kind == PointKind::Tip && c.leg == leg)
        });
        let extras = contacts
            .iter()
            .enumerate()
            .filter(|(i, _)| !tips.contains(&Some(*i)))
            .map(|(i, c)| (i, c.leg, c.kind))
            .collect();
        Self { tips, extras }
    }

    /// The trajectory columns: the contract's list ([`SPEC_COLUMNS`]), then
    /// the [`contact_columns`] of every extra point, then [`TAIL_COLUMNS`].
    pub fn columns(&self) -> Vec<String> {
        let mut c: Vec<String> = SPEC_COLUMNS.iter().map(|s| (*s).to_owned()).collect();
        for &(_, leg, kind) in &self.extras {
            c.extend(contact_columns(leg, kind));
        }
        c.extend(TAIL_COLUMNS.iter().map(|s| (*s).to_owned()));
        c
    }

    /// The planar model's trajectory as a [`Plan`] over its record (the
    /// one record of every model, [`fbd_sim::RobotRecord`], its plane
    /// embedded): the [`Self::columns`] and where each one's value is. A
    /// tip that is not a contact point has a NaN position, `ST1` and zero
    /// forces.
    pub fn plan(&self) -> Plan {
        use fbd_sim::robot::plane_q_index;
        let names = self.columns();
        let mut sources = Vec::with_capacity(names.len());
        sources.push(Source::Time);
        sources.extend((0..3 + PLANAR_JOINTS).map(|i| Source::Q(plane_q_index(i))));
        for c in self.tips {
            sources.extend(match c {
                Some(c) => [Source::ContactPoint(c, 0), Source::ContactPoint(c, 1)],
                None => [Source::Nan; 2],
            });
        }
        for c in self.tips {
            sources.push(c.map_or(Source::Free, Source::ContactState));
        }
        for c in self.tips {
            sources.extend(match c {
                Some(c) => [Source::ContactTangential(c, 0), Source::ContactNormal(c)],
                None => [Source::Zero; 2],
            });
        }
        for j in 0..PLANAR_JOINTS {
            sources.extend([Source::ReactionForce(j, 0), Source::ReactionForce(j, 1)]);
        }
        for &(c, _, _) in &self.extras {
            sources.extend([
                Source::ContactState(c),
                Source::ContactTangential(c, 0),
                Source::ContactNormal(c),
            ]);
        }
        sources.extend((0..PLANAR_JOINTS).map(Source::Torque));
        sources.extend([
            Source::Kinetic,
            Source::Potential,
            Source::Energy,
            Source::Iterations,
        ]);
        sources.extend((0..PLANAR_JOINTS).map(Source::Stop));
        assert_eq!(names.len(), sources.len(), "a source for every column");
        let mut plan = Plan::default();
        for (name, source) in names.into_iter().zip(sources) {
            plan.push(name, source);
        }
        plan
    }
}

/// The joints of the planar model (`hip3, knee3, hip4, knee4`: the
/// contract's joint-force columns, [`SPEC_COLUMNS`], and the torques and
/// stops of [`TAIL_COLUMNS`]).
pub const PLANAR_JOINTS: usize = 4;

/// The trajectory columns for a model whose contact points are `contacts`
/// (e.g. tips, knees and hips of legs 3 and 4): the contract's list, then
/// `knee3_state, knee3_fa, knee3_n`, … for every contact point that is not
/// a tip ([`contact_columns`]), then [`TAIL_COLUMNS`].
pub fn trajectory_columns(contacts: &[ContactSpec]) -> Vec<String> {
    ContactSlots::of(contacts).columns()
}

/// Receives the values of one row of `trajectory.csv`, column by column
/// in the order of the file's columns: the files' writers and the
/// in-memory columns of the Python package share the row builder
/// ([`crate::tree::Plan::row`]), one source of the values.
pub trait RowSink {
    /// `t`: the time of step `step` (`t = step·Δt`; the file writes the
    /// exact decimal of `step·Δt`, [`StepTimes`]).
    fn time(&mut self, step: usize, t: f64);
    /// A number (m, rad, N, N·m, J).
    fn num(&mut self, x: f64);
    /// A contact state (`ST1`, `ST2`, `ST3`).
    fn state(&mut self, s: StateCode);
    /// A count (`newton_iterations`).
    fn count(&mut self, n: usize);
    /// A flag (the kinematic gait's `stance{n}`): 1.0 or 0.0 (`1`, `0` in
    /// the CSV file).
    fn flag(&mut self, on: bool) {
        self.num(if on { 1.0 } else { 0.0 });
    }
}

/// One row of a CSV file: comma-separated values, the first I/O error
/// kept (later values of the row are skipped).
pub(crate) struct CsvRow<'a, W: Write> {
    out: &'a mut W,
    num: &'a mut ryu::Buffer,
    times: &'a StepTimes,
    error: Option<io::Error>,
    first: bool,
}

impl<'a, W: Write> CsvRow<'a, W> {
    /// A row written to `out`, numbers with `num`, times with `times`.
    pub(crate) fn new(out: &'a mut W, num: &'a mut ryu::Buffer, times: &'a StepTimes) -> Self {
        Self {
            out,
            num,
            times,
            error: None,
            first: true,
        }
    }

    /// Ends the row with a newline; the first error of the row, if any.
    pub(crate) fn end(self) -> io::Result<()> {
        match self.error {
            Some(e) => Err(e),
            None => self.out.write_all(b"\n"),
        }
    }

    fn put(&mut self, f: impl FnOnce(&mut W, &mut ryu::Buffer) -> io::Result<()>) {
        if self.error.is_some() {
            return;
        }
        let r = if self.first {
            self.first = false;
            Ok(())
        } else {
            self.out.write_all(b",")
        };
        if let Err(e) = r.and_then(|()| f(&mut *self.out, &mut *self.num)) {
            self.error = Some(e);
        }
    }
}

impl<W: Write> RowSink for CsvRow<'_, W> {
    fn time(&mut self, step: usize, t: f64) {
        let times = self.times;
        self.put(|out, _| times.write(out, step, t));
    }
    fn num(&mut self, x: f64) {
        self.put(|out, num| out.write_all(num.format(x).as_bytes()));
    }
    fn state(&mut self, s: StateCode) {
        self.put(|out, _| out.write_all(s.as_str().as_bytes()));
    }
    fn count(&mut self, n: usize) {
        self.put(|out, _| write!(out, "{n}"));
    }
    fn flag(&mut self, on: bool) {
        self.put(|out, _| out.write_all(if on { b"1" } else { b"0" }));
    }
}

/// The trajectory file of a run in the configuration's format
/// (`[output] format`): `trajectory.csv` or `trajectory.parquet`, the same
/// columns, each written to a temporary file and renamed into place when
/// complete. The planar, kinematic and 3D writers hand their rows to it.
pub enum Table {
    /// `trajectory.csv`, streamed through a buffer; no allocation per row.
    Csv {
        /// The buffered temporary file.
        out: BufWriter<NamedTempFile>,
        /// `dir/trajectory.csv`.
        dest: PathBuf,
        /// Number formatting.
        num: ryu::Buffer,
        /// Times as the decimal of k·Δt.
        times: StepTimes,
        /// The first I/O error.
        error: Option<io::Error>,
    },
    /// `trajectory.parquet` ([`crate::columnar`]).
    Parquet(Box<crate::columnar::ParquetTable>),
}

impl Table {
    /// Opens the trajectory file in `dir` for `columns` (CSV: writes the
    /// header); `dt` is the time step.
    pub fn create(
        dir: &Path,
        format: fbd_scenario::OutputFormat,
        columns: Vec<String>,
        dt: f64,
    ) -> Result<Self, OutputError> {
        match format {
            fbd_scenario::OutputFormat::Csv => {
                let dest = dir.join("trajectory.csv");
                let tmp = temp_in(dir, "trajectory.csv")?;
                let mut out = BufWriter::with_capacity(1 << 16, tmp);
                writeln!(out, "{}", columns.join(","))
                    .map_err(|e| OutputError::io(dest.display(), &e))?;
                Ok(Self::Csv {
                    out,
                    dest,
                    num: ryu::Buffer::new(),
                    times: StepTimes::new(dt),
                    error: None,
                })
            }
            fbd_scenario::OutputFormat::Parquet => Ok(Self::Parquet(Box::new(
                crate::columnar::ParquetTable::create(dir, columns, dt)?,
            ))),
        }
    }

    /// Whether an error was kept (later rows are skipped).
    pub fn failed(&self) -> bool {
        match self {
            Self::Csv { error, .. } => error.is_some(),
            Self::Parquet(_) => false,
        }
    }

    /// Writes one row: `fill` hands its values to the sink, in the order of
    /// the columns. An error is kept and reported by [`Table::finish`].
    pub fn row(&mut self, fill: impl FnOnce(&mut dyn RowSink)) {
        match self {
            Self::Csv {
                out,
                num,
                times,
                error,
                ..
            } => {
                if error.is_some() {
                    return;
                }
                let mut row = CsvRow::new(out, num, times);
                fill(&mut row);
                if let Err(e) = row.end() {
                    *error = Some(e);
                }
            }
            Self::Parquet(p) => {
                fill(&mut **p);
                p.end_row();
            }
        }
    }

    /// Flushes (the Parquet footer) and renames the file into place.
    pub fn finish(self) -> Result<PathBuf, OutputError> {
        match self {
            Self::Csv {
                out, dest, error, ..
            } => {
                if let Some(e) = error {
                    return Err(OutputError::io(dest.display(), &e));
                }
                let tmp = out
                    .into_inner()
                    .map_err(|e| OutputError::io(dest.display(), e.error()))?;
                persist(tmp, &dest)?;
                Ok(dest)
            }
            Self::Parquet(p) => (*p).finish(),
        }
    }
}

/// The `point` of a retried step's event (`events.csv`, `summary.json`).
pub const RETRY_POINT: &str = "substeps";

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
            point: e.point.as_str().to_owned(),
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
            point: RETRY_POINT.to_owned(),
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
    merge_events_as(
        events,
        limit_events,
        retries,
        |e| EventJson::new(e, times),
        |e| EventJson::limit(e, times),
        |e| EventJson::retry(e, times),
    )
}

/// The one merge of a run's events, each named by the run's own type `E`
/// (the planar and hexapod runs' [`EventJson`], a robot's
/// `RobotEvent`): contact, joint-limit and retried-step events in time
/// order (contact events first at equal times), with the step and
/// floating-point time of each.
pub fn merge_events_as<E>(
    events: &[Event],
    limit_events: &[LimitEvent],
    retries: &[RetryEvent],
    contact: impl Fn(&Event) -> E,
    limit: impl Fn(&LimitEvent) -> E,
    retry: impl Fn(&RetryEvent) -> E,
) -> Vec<(usize, f64, E)> {
    let mut all: Vec<(usize, f64, E)> = events
        .iter()
        .map(|e| (e.step, e.t, contact(e)))
        .chain(limit_events.iter().map(|e| (e.step, e.t, limit(e))))
        .chain(retries.iter().map(|e| (e.step, e.t, retry(e))))
        .collect();
    all.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    all
}

/// The one writer of `events.csv`: `header`, then a row per event, its
/// time as the decimal of k·Δt and then `rest` of it (the columns after
/// `t`, without the leading comma).
pub fn events_table<E>(
    header: &str,
    events: &[(usize, f64, E)],
    times: &StepTimes,
    rest: impl Fn(&E) -> String,
) -> String {
    let mut s = String::from(header);
    for (step, t, e) in events {
        s.push_str(&times.string(*step, *t));
        s.push(',');
        s.push_str(&rest(e));
        s.push('\n');
    }
    s
}

/// `events.csv` of a whole run ([`run_events`], [`events_table`]):
/// header `t,leg,from,to,point`, contact events (`t,4,ST1,ST2,tip`),
/// joint-limit rows (`t,4,free,max,knee_limit`) and retried steps
/// (`t,,1,8,substeps`: the leg is empty) in time order; times as the
/// decimal of k·Δt.
pub fn run_events_csv(run: &RunSummary, dt: f64) -> String {
    let times = StepTimes::new(dt);
    events_table(
        "t,leg,from,to,point\n",
        &run_events(run, &times),
        &times,
        |e| {
            let leg = e.leg.map(|l| l.to_string()).unwrap_or_default();
            format!("{leg},{},{},{}", e.from, e.to, e.point)
        },
    )
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

/// The head of every dynamic run's `summary.json` (planar and 3D
/// hexapod): how it ended and the solver's counters, in this order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunHead {
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
    /// Contact-state patterns evicted from the solver's bounded cache (each
    /// analysed again if it comes back; docs/reference.md, "Speed").
    pub evicted_patterns: usize,
}

impl RunHead {
    /// The head of `run`, a run of `steps_planned` steps whose most Newton
    /// iterations in one step were `max_iterations`.
    pub fn of(run: &RunSummary, steps_planned: usize, max_iterations: usize) -> Self {
        Self {
            status: run_status(run),
            error: match &run.error {
                Some(e) => Some(e.to_string()),
                None if run.interrupted => Some(format!(
                    "interrupted (SIGINT or SIGTERM) after {} of {steps_planned} steps",
                    run.steps
                )),
                None => None,
            },
            steps: run.steps,
            newton_iterations: run.newton_iterations,
            newton_iterations_per_step: IterationsPerStep {
                max: max_iterations,
                ..IterationsPerStep::of(run)
            },
            chord_iterations: run.chord_iterations,
            full_newton_iterations: run.newton_iterations.saturating_sub(run.chord_iterations),
            numeric_factorizations: run.numeric_factorizations,
            wall_seconds: run.wall_seconds,
            steps_per_second: steps_per_second(run),
            symbolic_factorizations: run.symbolic_factorizations,
            evicted_patterns: run.evicted_patterns,
        }
    }
}

/// The retries, state-search closures and law audit of every dynamic
/// run's `summary.json` (after its events), in this order.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunAudit {
    /// Steps that could not be solved whole and were solved in substeps
    /// of Δt/2, Δt/4, … (each is a `substeps` event).
    pub retried_steps: usize,
    /// State searches that found no consistent combination and were closed
    /// by the combination that violates the contact and limit laws least.
    pub resolved_cycles: usize,
    /// State searches closed by a consistent combination found by trying
    /// every combination of the few points involved.
    pub enumerated_cycles: usize,
    /// Solutions consistent by the switching rules that broke a contact or
    /// limit law (the law audit) and were solved again in substeps.
    pub rejected_solutions: usize,
    /// Failed Newton solves the state search recovered from by sticking
    /// its slowest slide.
    pub newton_fallbacks: usize,
    /// Crawling Newton solves given up at a certain touchdown (3D models;
    /// the search touched the point down and solved again).
    pub abandoned_crawls: usize,
    /// Substeps solved in retries, failed attempts included.
    pub substeps: usize,
    /// Of `retried_steps`, those solved with faer's reference LU after
    /// every attempt with the compiled LU had failed (docs/reference.md,
    /// "Speed").
    pub reference_lu_retries: usize,
    /// Re-solves that moved a fixed friction direction to the step's own
    /// slip (slides Newton could not solve with the implicit direction).
    pub direction_refinements: usize,
    /// Accepted slides whose slip ran against their reference direction:
    /// in 3D a slide turning back (its friction follows the slip: lawful);
    /// in the plane a slide kept in ST3 running backwards (the planar
    /// model is not audited: its friction then pushes along the slip).
    pub backward_slides: usize,
    /// The largest violation of a contact or joint-limit law over every
    /// step solved (N); a step that cannot be solved within the run's
    /// tolerance (1e-7 of the weight in the plane, 1e-6 in 3D) ends the run
    /// with an error instead.
    pub max_law_violation: f64,
}

impl RunAudit {
    /// The figures of `run`.
    pub fn of(run: &RunSummary) -> Self {
        Self {
            retried_steps: run.retries.len(),
            resolved_cycles: run.resolved_cycles,
            enumerated_cycles: run.enumerated_cycles,
            rejected_solutions: run.rejected_solutions,
            newton_fallbacks: run.newton_fallbacks,
            abandoned_crawls: run.abandoned_crawls,
            substeps: run.substeps,
            reference_lu_retries: run.retries.iter().filter(|r| r.reference_lu).count(),
            direction_refinements: run.direction_refinements,
            backward_slides: run.backward_slides,
            max_law_violation: run.max_law_violation,
        }
    }
}

/// `"ok"`, `"error"` or `"interrupted"` (every run's `summary.json`).
pub fn run_status(run: &RunSummary) -> &'static str {
    if run.error.is_some() {
        "error"
    } else if run.interrupted {
        "interrupted"
    } else {
        "ok"
    }
}

/// `steps / wall_seconds`, or `None` when not measurable.
pub fn steps_per_second(run: &RunSummary) -> Option<f64> {
    (run.wall_seconds > 0.0).then(|| run.steps as f64 / run.wall_seconds)
}

impl Energy {
    /// The energy of the step `step` at `t`, its time as written.
    pub fn at(times: &StepTimes, step: usize, t: f64, kinetic: f64, potential: f64) -> Self {
        Self {
            t: times.value(step, t),
            kinetic,
            potential,
            total: kinetic + potential,
        }
    }
}

/// What the `summary.json` of every dynamic model says of the run's
/// extent and its contact points, in this order (the planar model's
/// [`Summary`] and the tree models' [`crate::tree::summary::TreeSummary`]).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RunExtent {
    /// Time step (s).
    pub dt: f64,
    /// Configured duration (s).
    pub duration: f64,
    /// Steps the run was to solve (`round(duration/Δt) + 1`).
    pub steps_planned: usize,
    /// Every `stride`-th step is in `trajectory.csv`.
    pub stride: usize,
    /// Rows of `trajectory.csv`.
    pub rows_written: usize,
    /// Contact points of the model, in the order of their columns (e.g.
    /// `["tip3", "tip4"]`; none in flight).
    pub contact_points: Vec<String>,
    /// First change out of `ST1` (to `ST2` or `ST3`) of each foot (s; null
    /// if it never touched or started in contact): the paper's models' per
    /// leg (`"leg4"`, its foot), a robot's per contact point.
    pub first_touchdown: std::collections::BTreeMap<String, Option<f64>>,
    /// First change into `ST3` of each foot (s; null if none), keyed as
    /// `first_touchdown`.
    pub first_slip: std::collections::BTreeMap<String, Option<f64>>,
    /// Largest normal force `n` and tangential force magnitude `fa` of
    /// each contact point (N; empty when no step was given).
    pub peak_contact_force: std::collections::BTreeMap<String, PeakForce>,
}

/// `summary.json` of the planar model.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Summary {
    /// Status, error and the solver's counters (as every dynamic run).
    #[serde(flatten)]
    pub head: RunHead,
    /// Contact, joint-limit and retried-step events, as `events.csv`.
    pub events: Vec<EventJson>,
    /// Retries, state-search closures and the law audit (as every dynamic
    /// run).
    #[serde(flatten)]
    pub audit: RunAudit,
    /// `"planar"`.
    pub model: &'static str,
    /// The run's extent and its contact points' figures (the planar
    /// model's feet by leg, `"leg4"`, and contact points, `"tip4"`).
    #[serde(flatten)]
    pub extent: RunExtent,
    /// Largest joint force magnitude of each joint (N).
    pub peak_joint_force: std::collections::BTreeMap<String, f64>,
    /// Largest joint force magnitude of all joints (N).
    pub peak_joint_force_max: f64,
    /// Energy at the last solved step (null if none).
    pub final_energy: Option<Energy>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `n` planar runs of `rows` rows of 50 CSV columns.
    fn planar(n: usize, rows: usize) -> Vec<TrajectorySize> {
        vec![
            TrajectorySize {
                rows,
                columns: 50,
                stride: 1,
                format: fbd_scenario::OutputFormat::Csv,
                hexapod: false,
            };
            n
        ]
    }

    #[test]
    fn a_sweep_warns_above_its_size_with_what_would_shrink_it() {
        // Like the 10 ms landings: 1000 runs of 100 rows, 95 MB of CSV.
        let landings = planar(1000, 100);
        assert_eq!(sweep_size_warning(&landings, false, false), None);
        // With their viewers and plots, some 0.9 GB: drop the flags.
        let w = sweep_size_warning(&landings, true, true).unwrap();
        assert!(w.starts_with("warning: this sweep will write about 995.0 MB (1000 runs: trajectory files 95.0 MB, viewers and plots 900.0 MB); without --viewer and --plots it writes 95.0 MB"), "{w}");
        assert!(!w.contains("stride"), "{w}");
        // The 1 ms landings: ten times the rows. A stride of 4 keeps them
        // under a half of the limit; Parquet shrinks them too.
        let w = sweep_size_warning(&planar(1000, 1000), false, false).unwrap();
        assert!(w.contains("(1000 runs: trajectory files 950.0 MB)"), "{w}");
        assert!(w.contains("`[output] stride = 4` in the base configuration (or `[set] \"output.stride\" = 4` in the sweep file) keeps the trajectory files under 250.0 MB; `format = \"parquet\"`"), "{w}");
        let strided: Vec<TrajectorySize> = planar(1000, 250)
            .into_iter()
            .map(|t| TrajectorySize { stride: 4, ..t })
            .collect();
        assert_eq!(sweep_size_warning(&strided, false, false), None);
        // Parquet already: no format advice.
        let parquet: Vec<TrajectorySize> = planar(1000, 10_001)
            .into_iter()
            .map(|t| TrajectorySize {
                format: fbd_scenario::OutputFormat::Parquet,
                ..t
            })
            .collect();
        let w = sweep_size_warning(&parquet, false, false).unwrap();
        assert!(w.contains("stride = 17`") && !w.contains("format"), "{w}");
    }

    /// A contact point named `name` (deliberately unrelated to its
    /// identity: nothing may decide by it).
    fn point(name: &str, leg: usize, kind: PointKind) -> ContactSpec {
        ContactSpec {
            name: name.to_owned(),
            leg,
            kind,
            body: 0,
            point: 0,
        }
    }

    /// Counts the values of a row.
    #[derive(Default)]
    struct Count(usize);

    impl RowSink for Count {
        fn time(&mut self, _: usize, _: f64) {
            self.0 += 1;
        }
        fn num(&mut self, _: f64) {
            self.0 += 1;
        }
        fn state(&mut self, _: StateCode) {
            self.0 += 1;
        }
        fn count(&mut self, _: usize) {
            self.0 += 1;
        }
    }

    #[test]
    fn points_are_placed_by_leg_and_kind_not_by_name() {
        let contacts = [
            point("tip3", 4, PointKind::Hip),
            point("knee4", 4, PointKind::Tip),
            point("hip3", 3, PointKind::Knee),
            point("x", 3, PointKind::Tip),
        ];
        let slots = ContactSlots::of(&contacts);
        assert_eq!(slots.tips, [Some(3), Some(1)]);
        assert_eq!(
            slots.extras,
            [(0, 4, PointKind::Hip), (2, 3, PointKind::Knee)]
        );
        let c = trajectory_columns(&contacts);
        let n = SPEC_COLUMNS.len();
        assert_eq!(c[..n], SPEC_COLUMNS.map(str::to_owned));
        assert_eq!(
            c[n..n + 6],
            [
                "hip4_state",
                "hip4_fa",
                "hip4_n",
                "knee3_state",
                "knee3_fa",
                "knee3_n"
            ]
            .map(str::to_owned)
        );
        assert_eq!(c[n + 6..], TAIL_COLUMNS.map(str::to_owned));
    }

    #[test]
    fn tip_columns_are_the_contracts_and_no_column_repeats() {
        for leg in PLANAR_LEGS {
            for c in contact_columns(leg, PointKind::Tip)
                .into_iter()
                .chain([format!("tip{leg}_x"), format!("tip{leg}_y")])
            {
                assert!(SPEC_COLUMNS.contains(&c.as_str()), "{c}");
            }
        }
        let all: Vec<ContactSpec> = PointKind::ALL
            .into_iter()
            .flat_map(|kind| PLANAR_LEGS.map(|leg| point("p", leg, kind)))
            .collect();
        let mut c = trajectory_columns(&all);
        assert_eq!(c.len(), SPEC_COLUMNS.len() + 12 + TAIL_COLUMNS.len());
        c.sort();
        let n = c.len();
        c.dedup();
        assert_eq!(c.len(), n, "a column name repeats");
    }

    #[test]
    fn every_row_has_one_value_per_column_in_place() {
        let tip3 = point("a", 3, PointKind::Tip);
        let tip4 = point("b", 4, PointKind::Tip);
        let knee4 = point("c", 4, PointKind::Knee);
        let hip3 = point("d", 3, PointKind::Hip);
        let layouts: [Vec<ContactSpec>; 4] = [
            vec![],
            vec![tip3.clone(), tip4.clone()],
            vec![tip3.clone(), knee4.clone(), hip3.clone()],
            vec![hip3, tip4, knee4, tip3],
        ];
        for contacts in &layouts {
            let slots = ContactSlots::of(contacts);
            let plan = slots.plan();
            let mut r = fbd_sim::RobotRecord::planar(contacts.len(), 4);
            (r.step, r.t) = (3, 0.03);
            for c in 0..contacts.len() {
                let row = &mut r.contacts[c];
                row.point = [10.0 + c as f64, 20.0 + c as f64, 0.0];
                row.state = StateCode::St2;
                row.tangential = [30.0 + c as f64, 0.0];
                row.normal = 40.0 + c as f64;
            }
            let mut count = Count::default();
            plan.row(&r, None, &mut count);
            let columns = slots.columns();
            assert_eq!(plan.names, columns);
            assert_eq!(count.0, columns.len(), "{contacts:?}");

            let mut bytes = Vec::new();
            let (mut num, times) = (ryu::Buffer::new(), StepTimes::new(0.01));
            let mut row = CsvRow::new(&mut bytes, &mut num, &times);
            plan.row(&r, None, &mut row);
            row.end().unwrap();
            let line = String::from_utf8(bytes).unwrap();
            let cell: std::collections::HashMap<&str, &str> = columns
                .iter()
                .map(String::as_str)
                .zip(line.trim_end().split(','))
                .collect();
            assert_eq!(cell["t"], "0.03");
            // Every point's values are under its own `{leg, kind}` columns.
            for (c, p) in contacts.iter().enumerate() {
                let [s, fa, n] = contact_columns(p.leg, p.kind);
                assert_eq!(cell[s.as_str()], "ST2", "{s}");
                assert_eq!(cell[fa.as_str()].parse::<f64>(), Ok(30.0 + c as f64));
                assert_eq!(cell[n.as_str()].parse::<f64>(), Ok(40.0 + c as f64));
                if p.kind == PointKind::Tip {
                    let x = format!("tip{}_x", p.leg);
                    assert_eq!(cell[x.as_str()].parse::<f64>(), Ok(10.0 + c as f64));
                }
            }
            // A tip that is not a contact point: no position, ST1, no force.
            for leg in PLANAR_LEGS {
                if !contacts
                    .iter()
                    .any(|p| p.leg == leg && p.kind == PointKind::Tip)
                {
                    assert_eq!(cell[format!("tip{leg}_x").as_str()], "NaN");
                    assert_eq!(cell[format!("state{leg}").as_str()], "ST1");
                    assert_eq!(cell[format!("n{leg}").as_str()], "0.0");
                }
            }
        }
    }
}

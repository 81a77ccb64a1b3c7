//! The one run driver of every model: step → every step observed, every
//! `stride`-th one written (trajectory row, viewer frame, the caller's
//! `on_row`) → the summary → the files, each all-or-nothing, also after a
//! simulation error or an interruption (the first write failure kept) →
//! the files of an earlier run of another kind removed. A model brings its
//! stepping ([`Stepper`]) and its files ([`RunFiles`]: columns and row
//! writer, summary, `events.csv`, plots and viewer); every run returns one
//! [`RunOutput`].

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;

use serde::Serialize;

use crate::OutputError;
use crate::output::{self, FirstError};

/// A model's stepping: runs to the end (or until `stop` is set), handing
/// every step's record to `each` (the driver applies the stride).
pub trait Stepper<R> {
    /// What the run returns (steps, events, the error that stopped it).
    type Run;
    /// Runs the model. Of the records handed to `each`, only every
    /// `written`-th step's is written (the others are observed: plots,
    /// peaks); a model may leave out of those what only a written row
    /// reads ([`fbd_sim::engine::run::run_in_written`]).
    fn step(&self, stop: &AtomicBool, written: usize, each: impl FnMut(&R)) -> Self::Run;
}

impl Stepper<fbd_sim::RobotRecord> for fbd_sim::Model {
    type Run = fbd_sim::RunSummary;
    /// Every record whole (the planar record has nothing to leave out).
    fn step(
        &self,
        stop: &AtomicBool,
        _written: usize,
        each: impl FnMut(&fbd_sim::RobotRecord),
    ) -> Self::Run {
        fbd_sim::run_until(self, stop, each)
    }
}

impl Stepper<fbd_sim::robot::RobotRecord> for fbd_sim::spatial::SpatialModel {
    type Run = fbd_sim::RunSummary;
    fn step(
        &self,
        stop: &AtomicBool,
        written: usize,
        each: impl FnMut(&fbd_sim::robot::RobotRecord),
    ) -> Self::Run {
        fbd_sim::spatial::run_until_written(self, stop, written, each)
    }
}

impl Stepper<fbd_sim::gait::GaitData> for fbd_sim::gait::GaitModel {
    type Run = fbd_sim::gait::GaitSummary;
    /// Every record whole (a kinematic gait's is its state).
    fn step(
        &self,
        stop: &AtomicBool,
        _written: usize,
        each: impl FnMut(&fbd_sim::gait::GaitData),
    ) -> Self::Run {
        fbd_sim::gait::run_gait(self, stop, each)
    }
}

/// A record of one step: its step number (a written row when a multiple
/// of the stride).
pub trait Stepped {
    /// The step index k.
    fn step(&self) -> usize;
}

impl Stepped for fbd_sim::robot::RobotRecord {
    fn step(&self) -> usize {
        self.step
    }
}

impl Stepped for fbd_sim::gait::GaitData {
    fn step(&self) -> usize {
        self.step
    }
}

/// A model's files and summary, fed by the driver; the trajectory's file
/// is the driver's ([`Recording`]), the model gives its rows' values.
pub trait RunFiles {
    /// One step's record.
    type Record: Stepped;
    /// What the stepping returns.
    type Run;
    /// `summary.json`'s content.
    type Summary: Serialize;
    /// The values of a written row of the trajectory, in its columns'
    /// order.
    fn row_values(&mut self, r: &Self::Record, sink: &mut dyn output::RowSink);
    /// What else a written row makes (the viewer's frame); nothing by
    /// default.
    fn written(&mut self, _r: &Self::Record) {}
    /// Every step (the written ones too, after [`RunFiles::written`]):
    /// plots, peaks.
    fn observe(&mut self, r: &Self::Record);
    /// The summary of `run`, of which `rows` rows were written.
    fn summary(&mut self, run: &Self::Run, rows: usize) -> Self::Summary;
    /// `events.csv`'s text.
    fn events_csv(&self, run: &Self::Run) -> String;
    /// Writes the plots and the viewer into `dir` (each attempted, the
    /// first failure kept); returns the files of the run, in order.
    fn write_extras(self, dir: &Path, run: &Self::Run, keep: &mut FirstError) -> Vec<&'static str>;
}

/// What a run produced, for every model.
#[derive(Debug)]
pub struct RunOutput<R, S> {
    /// The run: steps, events, and the error that stopped it, if any.
    pub run: R,
    /// The content of `summary.json`.
    pub summary: S,
    /// The first failure writing a file (every file is still attempted).
    pub io_error: Option<OutputError>,
    /// The files written, in order (none without an output directory).
    pub files: Vec<&'static str>,
}

/// How a run ended, as the Python package reports it.
pub trait Outcome {
    /// Steps solved.
    fn steps(&self) -> usize;
    /// The error that stopped the run (time step `dt`): its message, the
    /// failing step and its time, where known.
    fn failure(&self, dt: f64) -> Option<(String, Option<usize>, Option<f64>)>;
}

impl Outcome for fbd_sim::RunSummary {
    fn steps(&self) -> usize {
        self.steps
    }
    fn failure(&self, dt: f64) -> Option<(String, Option<usize>, Option<f64>)> {
        self.error
            .as_ref()
            .map(|e| (e.to_string(), e.step(), e.step().map(|k| k as f64 * dt)))
    }
}

impl Outcome for fbd_sim::gait::GaitSummary {
    fn steps(&self) -> usize {
        self.steps
    }
    /// The failing step is the one after the last computed.
    fn failure(&self, dt: f64) -> Option<(String, Option<usize>, Option<f64>)> {
        self.error.as_ref().map(|e| {
            (
                e.to_string(),
                Some(self.steps),
                Some(self.steps as f64 * dt),
            )
        })
    }
}

impl Outcome for fbd_scenario::robot::RobotRun {
    fn steps(&self) -> usize {
        self.summary.steps
    }
    fn failure(&self, dt: f64) -> Option<(String, Option<usize>, Option<f64>)> {
        self.summary.failure(dt)
    }
}

/// A run being recorded: the model's files, the trajectory's file (with
/// an output directory), the stride, the rows written.
pub struct Recording<F> {
    files: F,
    table: Option<output::Table>,
    stride: usize,
    rows: usize,
    dir: Option<PathBuf>,
}

impl<F: RunFiles> Recording<F> {
    /// Records into `files` every `stride`-th step; the trajectory's rows
    /// go to `table`, the files to `dir`.
    pub fn new(files: F, table: Option<output::Table>, stride: usize, dir: Option<&Path>) -> Self {
        Self {
            files,
            table,
            stride: stride.max(1),
            rows: 0,
            dir: dir.map(Path::to_owned),
        }
    }

    /// Adds one step's record, handing a written one to `on_row`.
    #[inline]
    pub fn push(&mut self, r: &F::Record, on_row: &mut dyn FnMut(&F::Record)) {
        if r.step().is_multiple_of(self.stride) {
            if let Some(t) = self.table.as_mut() {
                let files = &mut self.files;
                t.row(|sink| files.row_values(r, sink));
            }
            self.files.written(r);
            on_row(r);
            self.rows += 1;
        }
        self.files.observe(r);
    }

    /// The model's files, for a last look before [`Recording::finish`].
    pub fn files_mut(&mut self) -> &mut F {
        &mut self.files
    }

    /// The summary of `run`, then, with an output directory, every file
    /// (`config_toml` as `config.toml`), each attempted, the first failure
    /// kept, and, when all were written, those of an earlier run that this
    /// one does not write removed.
    pub fn finish(mut self, run: F::Run, config_toml: &str) -> RunOutput<F::Run, F::Summary> {
        let summary = self.files.summary(&run, self.rows);
        let (Some(dir), Some(table)) = (self.dir, self.table) else {
            return RunOutput {
                run,
                summary,
                io_error: None,
                files: Vec::new(),
            };
        };
        let mut keep = FirstError::default();
        keep.keep(table.finish());
        output::write_run_files(
            &dir,
            &self.files.events_csv(&run),
            &summary,
            config_toml,
            &mut keep,
        );
        let files = self.files.write_extras(&dir, &run, &mut keep);
        if keep.0.is_none()
            && let Err(e) = output::remove_stale(&dir, &files)
        {
            keep.0 = Some(e);
        }
        RunOutput {
            run,
            summary,
            io_error: keep.0,
            files,
        }
    }
}

/// Runs `stepper` into `rec` (see [`Recording`]): the one loop of every
/// model.
pub fn drive<F: RunFiles, S: Stepper<F::Record, Run = F::Run>>(
    stepper: &S,
    mut rec: Recording<F>,
    stop: &AtomicBool,
    config_toml: &str,
    on_row: &mut dyn FnMut(&F::Record),
) -> RunOutput<F::Run, F::Summary> {
    let written = rec.stride;
    let run = stepper.step(stop, written, |r| rec.push(r, on_row));
    rec.finish(run, config_toml)
}

/// Writes the named SVGs into `dir`, keeping the first failure.
pub fn write_svgs<E: std::fmt::Display>(
    dir: &Path,
    svgs: impl IntoIterator<Item = (&'static str, Result<String, E>)>,
    keep: &mut FirstError,
) {
    for (name, svg) in svgs {
        keep.keep(
            svg.map_err(|e| OutputError::Io(format!("{name}: {e}")))
                .and_then(|s| output::write_file(dir, name, s.as_bytes())),
        );
    }
}

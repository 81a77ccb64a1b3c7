//! `fbd run [CONFIG] [--out DIR]`: simulate and write the files (docs/reference.md).

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;
use std::sync::atomic::AtomicBool;

use fbd_dynamics::PointKind;
use fbd_kinematics::planar::PlanarChains;
use fbd_sim::{Model, RobotRecord, RunSummary};

use crate::OutputError;
use crate::config::{self, Config};
use crate::driver::{self, Recording, RunFiles, RunOutput};
use crate::output::{self, Ending, Energy, EventJson, PeakForce, Summary};
use crate::plot::{self, PlotData, PlotRecorder, Stance};
use crate::steptime::StepTimes;
use crate::viewer::{self, planar::PlanarScene};

/// How messages name the configuration of a run without a file.
const DEFAULT_SOURCE: &str = "the built-in default";

/// Snapshot intervals of `stance.svg` (one more snapshot than this).
const STANCE_INTERVALS: usize = 10;

/// What the summary and the last stance need of the last row (copied row by
/// row into one buffer).
struct LastRow {
    step: usize,
    t: f64,
    kinetic: f64,
    potential: f64,
    /// The record's `q` (the plane embedded, [`RobotRecord::plane_q`]).
    q: Vec<f64>,
}

/// What the plots and the summary need, gathered step by step.
struct Collector {
    snapshot_steps: Vec<usize>,
    plot: PlotRecorder,
    /// Time and the planar model's coordinates ([`RobotRecord::plane_q`]).
    snapshots: Vec<(f64, Vec<f64>)>,
    last: Option<LastRow>,
    peak_contact: Vec<PeakForce>,
    peak_joint: Vec<f64>,
    /// Just below the square of each `peak_joint`: a joint force whose
    /// squared magnitude is smaller cannot raise the peak, and its
    /// magnitude (a libm `hypot`, the one exact to rounding) is not taken.
    /// The peaks are the same as with every magnitude taken.
    peak_joint_sq: Vec<f64>,
}

impl Collector {
    fn new(model: &Model) -> Self {
        let contacts = &model.mech.contacts;
        let steps = model.steps.max(1);
        let plot = PlotRecorder::new(contacts, (steps - 1) as f64 * model.params.dt);
        let last_step = steps - 1;
        let mut snapshot_steps: Vec<usize> = (0..=STANCE_INTERVALS)
            .map(|i| ((i * last_step) as f64 / STANCE_INTERVALS as f64).round() as usize)
            .collect();
        snapshot_steps.dedup();
        Self {
            snapshots: Vec::with_capacity(snapshot_steps.len() + 1),
            snapshot_steps,
            plot,
            last: None,
            peak_contact: vec![PeakForce::default(); contacts.len()],
            peak_joint: vec![0.0; model.mech.joints.len()],
            peak_joint_sq: vec![0.0; model.mech.joints.len()],
        }
    }

    fn push(&mut self, r: &RobotRecord) {
        self.plot.push(r);
        if self.snapshot_steps.binary_search(&r.step).is_ok() {
            self.snapshots.push((r.t, r.plane_q()));
        }
        for (p, row) in self.peak_contact.iter_mut().zip(&r.contacts) {
            p.n = p.n.max(row.normal.abs());
            p.fa = p.fa.max(row.tangential[0].abs());
        }
        let peaks = self.peak_joint.iter_mut().zip(&mut self.peak_joint_sq);
        for ((p, sq), f) in peaks.zip(&r.reaction_force) {
            // A NaN force fails the test, as `max` ignores it.
            if f[0] * f[0] + f[1] * f[1] >= *sq {
                *p = p.max(f[0].hypot(f[1]));
                // 1e-9 below p², far beyond the rounding of either side.
                *sq = *p * *p * (1.0 - 1e-9);
            }
        }
        match &mut self.last {
            Some(last) => {
                (last.step, last.t) = (r.step, r.t);
                (last.kinetic, last.potential) = (r.kinetic, r.potential);
                last.q.copy_from_slice(&r.q);
            }
            None => {
                self.last = Some(LastRow {
                    step: r.step,
                    t: r.t,
                    kinetic: r.kinetic,
                    potential: r.potential,
                    q: r.q.clone(),
                })
            }
        }
    }

    /// Completes the plot data after the run.
    fn finish(
        mut self,
        model: &Model,
        run: &RunSummary,
    ) -> (PlotData, Option<LastRow>, Vec<PeakForce>, Vec<f64>) {
        if let Some(r) = &self.last
            && self.snapshots.last().map(|s| s.0) != Some(r.t)
        {
            let q = &r.q;
            let plane = fbd_sim::robot::PLANE_ROOT.iter().map(|&i| q[i]);
            self.snapshots
                .push((r.t, plane.chain(q[6..].iter().copied()).collect()));
        }
        let chains: &PlanarChains = &model.mech.chains;
        let ix = &model.index;
        let mut data = chains.new_data();
        let mut stances = Vec::with_capacity(self.snapshots.len());
        for (t, q) in &self.snapshots {
            chains.eval_positions(q, &mut data);
            let p = |i: [usize; 2]| [data.pos[i[0]], data.pos[i[1]]];
            stances.push(Stance {
                t: *t,
                hip: p(ix.hip),
                knee: p(ix.knee),
                tip: p(ix.tip),
            });
        }
        let plot = self
            .plot
            .finish(&run.events, stances, Some(model.params.terrain.clone()));
        (plot, self.last, self.peak_contact, self.peak_joint)
    }
}

/// The time of the first event of leg `leg`'s tip (the contact point of
/// `{leg, kind: Tip}`) for which `pred` holds.
fn first_time(
    model: &Model,
    run: &RunSummary,
    times: &StepTimes,
    leg: usize,
    pred: impl Fn(&fbd_sim::Event) -> bool,
) -> Option<f64> {
    let contacts = &model.mech.contacts;
    run.events
        .iter()
        .find(|e| {
            let c = &contacts[e.contact];
            c.leg == leg && c.kind == PointKind::Tip && pred(e)
        })
        .map(|e| times.value(e.step, e.t))
}

fn summary(
    model: &Model,
    names: &[String],
    run: &RunSummary,
    rows: usize,
    last: Option<LastRow>,
    peaks: Vec<PeakForce>,
    joints: Vec<f64>,
) -> Summary {
    use fbd_contact::StateCode;
    let times = StepTimes::new(model.params.dt);
    let by_leg = |pred: &dyn Fn(&fbd_sim::Event) -> bool| -> BTreeMap<String, Option<f64>> {
        output::PLANAR_LEGS
            .iter()
            .map(|&leg| {
                (
                    format!("leg{leg}"),
                    first_time(model, run, &times, leg, pred),
                )
            })
            .collect()
    };
    Summary {
        head: output::RunHead::of(run, model.steps, run.max_newton_iterations),
        events: output::run_events(run, &times)
            .into_iter()
            .map(|e| e.2)
            .collect(),
        audit: output::RunAudit::of(run),
        model: "planar",
        extent: output::RunExtent {
            dt: model.params.dt,
            duration: model.params.duration,
            steps_planned: model.steps,
            stride: model.params.stride,
            rows_written: rows,
            contact_points: names.to_vec(),
            first_touchdown: by_leg(&|e| e.from == StateCode::St1 && e.to != StateCode::St1),
            first_slip: by_leg(&|e| e.to == StateCode::St3),
            peak_contact_force: names.iter().cloned().zip(peaks).collect(),
        },
        peak_joint_force: model
            .mech
            .joints
            .iter()
            .map(|j| j.name.clone())
            .zip(joints.iter().copied())
            .collect(),
        peak_joint_force_max: joints.iter().copied().fold(0.0, f64::max),
        final_energy: last.map(|r| Energy::at(&times, r.step, r.t, r.kinetic, r.potential)),
    }
}

/// One line per event of `events.csv` ([`output::run_events`]):
/// `t=0.19 s  leg 4  ST1 -> ST2`. The point is named when it is not the
/// tip (`leg 4  hip_limit  free -> min`); an event of no leg (a retried
/// step) reads `t=0.5 s  substeps  1 -> 4`. `t` is the time as written in
/// `events.csv` (the decimal of k·Δt).
pub fn event_line(t: &str, e: &EventJson) -> String {
    let point = if e.point == PointKind::Tip.as_str() {
        String::new()
    } else {
        format!("{}  ", e.point)
    };
    let leg = e.leg.map(|l| format!("leg {l}  ")).unwrap_or_default();
    format!("t={t} s  {leg}{point}{} -> {}", e.from, e.to)
}

/// What [`simulate`] produced: the planar run, its `summary.json`, the
/// files written.
pub type Simulated = RunOutput<RunSummary, Summary>;

/// The planar model's files ([`RunFiles`]): the trajectory, the plots'
/// and peaks' collector, the viewer.
struct PlanarFiles<'a> {
    model: &'a Model,
    planar: &'a fbd_scenario::PlanarConfig,
    names: Vec<String>,
    plan: crate::tree::Plan,
    collect: Option<Collector>,
    view: Option<PlanarScene<'a>>,
    plot: Option<PlotData>,
}

impl RunFiles for PlanarFiles<'_> {
    type Record = RobotRecord;
    type Run = RunSummary;
    type Summary = Summary;

    fn row_values(&mut self, r: &RobotRecord, sink: &mut dyn output::RowSink) {
        self.plan.row(r, None, sink);
    }

    fn written(&mut self, r: &RobotRecord) {
        if let Some(v) = self.view.as_mut() {
            v.push(r);
        }
    }

    fn observe(&mut self, r: &RobotRecord) {
        if let Some(c) = self.collect.as_mut() {
            c.push(r);
        }
    }

    fn summary(&mut self, run: &RunSummary, rows: usize) -> Summary {
        let collect = self.collect.take().expect("summarised once");
        let (plot, last, peaks, joints) = collect.finish(self.model, run);
        self.plot = Some(plot);
        summary(self.model, &self.names, run, rows, last, peaks, joints)
    }

    fn events_csv(&self, run: &RunSummary) -> String {
        output::run_events_csv(run, self.model.dt())
    }

    fn write_extras(
        self,
        dir: &Path,
        run: &RunSummary,
        keep: &mut output::FirstError,
    ) -> Vec<&'static str> {
        let plot_data = self.plot.expect("summarised");
        let plots = self.planar.output.plots;
        let torques = plots
            .then(|| plot::torques_svg(&plot_data).map(|svg| ("torques.svg", svg)))
            .flatten();
        let torques_written = torques.is_some();
        let svgs = plots.then(|| {
            [
                ("tips.svg", plot::tips_svg(&plot_data)),
                ("forces.svg", plot::forces_svg(&plot_data)),
                ("stance.svg", plot::stance_svg(&plot_data)),
                ("joints.svg", plot::joints_svg(&plot_data)),
                ("energy.svg", plot::energy_svg(&plot_data)),
            ]
        });
        driver::write_svgs(dir, svgs.into_iter().flatten().chain(torques), keep);
        if let Some(v) = self.view {
            let mut scene = v.finish(&run.events);
            scene.event_rows = output::run_events(run, &StepTimes::new(self.model.dt())).len();
            keep.keep(viewer::write(dir, &scene));
        }
        let mut files = output::selected(
            output::files_as(&output::FILES, self.planar.output.format),
            &self.planar.output,
        );
        files.extend(torques_written.then_some("torques.svg"));
        files
    }
}

/// Simulates the loaded `config` (named `source` in messages), handing every
/// `output.stride`-th step's record to `on_row`; when `out_dir` is given,
/// writes the files of `fbd run` there, streaming `trajectory.csv`. A
/// simulation error does not make this fail: it is in `run.error`, with
/// every file written. The run stops before its next step once `stop` is
/// set (`run.interrupted`). Fails for a hexapod configuration (see
/// [`crate::spatial::simulate`] and [`crate::hexapod::simulate`]), an
/// invalid model or an output directory that cannot be created.
pub fn simulate(
    config: &Config,
    source: &str,
    out_dir: Option<&Path>,
    stop: &AtomicBool,
    on_row: &mut dyn FnMut(&RobotRecord),
) -> Result<Simulated, OutputError> {
    let planar = match config {
        Config::Planar(c) => c,
        Config::Hexapod(_) => {
            return Err(OutputError::Usage(format!(
                "{source}: model = \"hexapod\": a hexapod runs in `fbd_cli::spatial::simulate` (the 3D dynamics) or `fbd_cli::hexapod::simulate` (the kinematic gait), not in the planar `simulate`"
            )));
        }
    };
    let model = planar.model(source)?;

    let names: Vec<String> = model.mech.contacts.iter().map(|c| c.name.clone()).collect();
    let plan = output::ContactSlots::of(&model.mech.contacts).plan();
    let table = match out_dir {
        Some(dir) => {
            output::prepare_dir(dir)?;
            let columns = plan.names.clone();
            output::warn_size(
                model.steps.div_ceil(model.params.stride.max(1)),
                columns.len(),
                model.params.stride,
                planar.output.format,
            );
            Some(output::Table::create(
                dir,
                planar.output.format,
                columns,
                model.dt(),
            )?)
        }
        None => None,
    };
    let collect = Collector::new(&model);
    // The simulator hands over every `stride`-th step; the plots and peaks
    // want them all, so stride is applied by the driver.
    let stride = model.params.stride.max(1);
    let mut every_step = model.clone();
    every_step.params.stride = 1;
    // viewer.html: one frame per trajectory row (decimated when long).
    let view = out_dir.filter(|_| planar.output.viewer).map(|_| {
        PlanarScene::new(
            &model,
            model.steps.div_ceil(stride),
            &viewer::title_of(source, "planar model"),
        )
    });
    let files = PlanarFiles {
        model: &model,
        planar,
        names,
        plan,
        collect: Some(collect),
        view,
        plot: None,
    };
    let rec = Recording::new(files, table, stride, out_dir);
    Ok(driver::drive(
        &every_step,
        rec,
        stop,
        &config.to_toml(),
        on_row,
    ))
}

/// `fbd run`: loads `config` (the built-in default when `None`), checks
/// the output directory, simulates while streaming `trajectory.csv`, then
/// writes the other files ([`simulate`]). On a simulation error every file
/// is still written and the error is returned ([`OutputError::Simulation`],
/// exit 3).
pub fn run_command(
    config_path: Option<&Path>,
    out_dir: &Path,
    out: &mut dyn Write,
) -> Result<(), OutputError> {
    run_command_with(config_path, &[], out_dir, out)
}

/// [`run_command`] with `overrides` (dotted keys, `fbd run --set
/// KEY=VALUE`) applied to the configuration, or to the built-in default
/// without one, in order, before it is validated: an unknown key or a
/// value of the wrong type is a configuration error naming the key, and
/// the `config.toml` written holds the result (so that `fbd run
/// DIR/config.toml` repeats the run).
pub fn run_command_with(
    config_path: Option<&Path>,
    overrides: &[config::Override],
    out_dir: &Path,
    out: &mut dyn Write,
) -> Result<(), OutputError> {
    if let Some(p) = config_path {
        let text = config::read_text(p)?;
        if config::robot::is_robot(&text) {
            // An imported robot: every file in `robot_run`.
            return crate::robot_run::run_command(&text, p, overrides, out_dir, out);
        }
    }
    let (config, source) = match config_path {
        Some(p) => (
            config::load_with_overrides(p, overrides)?,
            p.display().to_string(),
        ),
        None if overrides.is_empty() => (Config::default(), DEFAULT_SOURCE.to_owned()),
        None => (
            config::parse_str(&Config::default().to_toml(), DEFAULT_SOURCE, overrides)?,
            DEFAULT_SOURCE.to_owned(),
        ),
    };
    let dynamic = match &config {
        Config::Planar(p) => p.dt_warning(),
        Config::Hexapod(h) if h.is_dynamic() => h.dt_warning(),
        Config::Hexapod(_) => None,
    };
    if let Some(w) = dynamic {
        eprintln!("{w}");
    }
    if let Config::Hexapod(h) = &config
        && h.is_dynamic()
    {
        // The 3D FBD dynamics: every file, and the removal of an earlier
        // run's, in `spatial`.
        let params = h.spatial_params(&source)?;
        return crate::spatial::run_command(&params, &config.to_toml(), &source, out_dir, out);
    }
    if let Config::Hexapod(h) = &config {
        return crate::hexapod::run_command(h, &config, &source, out_dir, out);
    }
    let Simulated {
        run,
        io_error,
        summary,
        files,
    } = simulate(
        &config,
        &source,
        Some(out_dir),
        crate::interrupt::flag(),
        &mut |_| {},
    )?;

    let text = output::run_report(&run, summary.extent.dt);
    let advice = match (&config, &run.error) {
        (Config::Planar(p), Some(e)) => p.advice(e),
        _ => None,
    };
    let ending = Ending::of_run(
        &run,
        &source,
        advice,
        summary.extent.steps_planned,
        summary.extent.dt,
    );
    output::conclude(out, text, out_dir, &files, io_error, ending)
}

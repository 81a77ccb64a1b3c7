//! `fbd run` of a hexapod configuration: the kinematic gait (or a standing
//! run without `[gait]`), writing `trajectory.csv`, `events.csv`,
//! `summary.json`, `config.toml`, `gait.svg`, `footprints.svg` and
//! `joints.svg`.

mod plots;

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;
use std::sync::atomic::AtomicBool;

use fbd_sim::gait::{GaitData, GaitEvent, GaitModel, GaitSummary, LEGS};
use serde::Serialize;

use crate::OutputError;
use crate::config::{Config, HexapodConfig};
use crate::driver::{Recording, RunFiles, RunOutput};
use crate::output::{self, Ending};
use crate::viewer::hexapod::HexapodView;

pub use plots::{GaitPlotData, footprints_svg, gait_svg, joints_svg};

/// The files a hexapod run writes, in order.
pub const FILES: [&str; 8] = [
    "trajectory.csv",
    "events.csv",
    "summary.json",
    "config.toml",
    "gait.svg",
    "footprints.svg",
    "joints.svg",
    "viewer.html",
];

/// The columns of the hexapod `trajectory.csv`, in order: `t`, the body
/// pose `rx, ry, rz, phi_x, phi_y, phi_z`, `theta{j}_{n}`, `omega{j}_{n}`,
/// `alpha{j}_{n}` (joint j = 1..3 of leg n = 1..6, leg by leg),
/// `foot{n}_x, foot{n}_y, foot{n}_z`, `stance{n}`, `com_x, com_y, com_z`,
/// `margin`, `roll, pitch, heading` ([`ATTITUDE_COLUMNS`]).
pub fn columns() -> Vec<String> {
    let mut c: Vec<String> = ["t", "rx", "ry", "rz", "phi_x", "phi_y", "phi_z"]
        .iter()
        .map(|s| (*s).to_owned())
        .collect();
    for q in ["theta", "omega", "alpha"] {
        for n in 1..=LEGS {
            for j in 1..=3 {
                c.push(format!("{q}{j}_{n}"));
            }
        }
    }
    for n in 1..=LEGS {
        for a in ["x", "y", "z"] {
            c.push(format!("foot{n}_{a}"));
        }
    }
    for n in 1..=LEGS {
        c.push(format!("stance{n}"));
    }
    c.extend(["com_x", "com_y", "com_z", "margin"].map(str::to_owned));
    c.extend(ATTITUDE_COLUMNS.map(str::to_owned));
    c
}

/// The body's attitude derived from φ, after the other columns of the
/// hexapod files (rad; [`fbd_kinematics::pose::BodyPose::attitude`]):
/// roll (right side down positive), pitch (nose up positive) and heading
/// (yaw about the vertical +Y, equal to `phi_y` when level).
pub const ATTITUDE_COLUMNS: [&str; 3] = ["roll", "pitch", "heading"];

/// Values of a `trajectory.csv` row after `t` ([`row_values`]).
pub const ROW_VALUES: usize = 6 + 3 * 3 * LEGS + 3 * LEGS + LEGS + 4 + 3;

/// Where the `stance{n}` flags are among the [`row_values`] (1 or 0).
pub const STANCE: std::ops::Range<usize> = 6 + 12 * LEGS..6 + 13 * LEGS;

/// The values of one `trajectory.csv` row after `t`, in the order of
/// [`columns`]: body pose, joint angles, rates, accelerations, feet (where
/// the solved joint angles put them), stance flags (1.0 or 0.0), centre of
/// mass, margin. The file and the Python package both write these.
pub fn row_values(d: &GaitData, out: &mut [f64; ROW_VALUES]) {
    let body = &d.body;
    let mut i = 0;
    let mut put = |v: f64| {
        out[i] = v;
        i += 1;
    };
    for v in [
        body.position.x,
        body.position.y,
        body.position.z,
        body.phi.x,
        body.phi.y,
        body.phi.z,
    ] {
        put(v);
    }
    for l in &d.legs {
        l.theta.into_iter().for_each(&mut put);
    }
    for l in &d.legs {
        l.rate.into_iter().for_each(&mut put);
    }
    for l in &d.legs {
        l.accel.into_iter().for_each(&mut put);
    }
    for l in &d.fk.legs {
        [l.tip.x, l.tip.y, l.tip.z].into_iter().for_each(&mut put);
    }
    for s in d.stance() {
        put(if s { 1.0 } else { 0.0 });
    }
    [d.com.x, d.com.y, d.com.z, d.margin]
        .into_iter()
        .for_each(&mut put);
    fbd_kinematics::pose::BodyPose {
        position: body.position,
        phi: body.phi,
    }
    .attitude()
    .into_iter()
    .for_each(&mut put);
}

/// The values of the trajectory row of `d`, in [`columns`]' order.
fn gait_row(d: &GaitData, sink: &mut dyn output::RowSink) {
    let mut v = [0.0; ROW_VALUES];
    row_values(d, &mut v);
    sink.time(d.step, d.t);
    for (i, x) in v.iter().enumerate() {
        if STANCE.contains(&i) {
            sink.flag(*x == 1.0);
        } else {
            sink.num(*x);
        }
    }
}

/// A scheduled event time for the files: `(k + φ)·T` rounded to 1e-12 s,
/// so that `1.7999999999999998` reads `1.8`.
pub fn tidy(t: f64) -> f64 {
    (t * 1e12).round() / 1e12
}

/// `events.csv` of a hexapod run: `t, leg, event, margin` (`leg` empty for
/// the stability events).
pub fn events_csv(events: &[GaitEvent]) -> String {
    let mut s = String::from("t,leg,event,margin\n");
    let mut b = ryu::Buffer::new();
    for e in events {
        s.push_str(b.format(tidy(e.t)));
        s.push(',');
        if let Some(l) = e.leg {
            s.push_str(&l.to_string());
        }
        s.push(',');
        s.push_str(e.kind.as_str());
        s.push(',');
        s.push_str(b.format(e.margin));
        s.push('\n');
    }
    s
}

/// A figure with its time.
#[derive(Clone, Debug, Serialize)]
pub struct AtTime {
    /// The value.
    pub value: f64,
    /// When (s).
    pub t: f64,
}

/// One event in `summary.json`.
#[derive(Clone, Debug, Serialize)]
pub struct EventJson {
    /// Time (s).
    pub t: f64,
    /// Leg number (null for stability events).
    pub leg: Option<usize>,
    /// `liftoff`, `touchdown`, `margin_low`, `margin_recovered`.
    pub event: &'static str,
    /// Stability margin at the event (m).
    pub margin: Option<f64>,
}

/// `summary.json` of a hexapod run.
#[derive(Clone, Debug, Serialize)]
pub struct HexapodSummary {
    /// `ok`, `error` or `interrupted`.
    pub status: &'static str,
    /// The error message, if any.
    pub error: Option<String>,
    /// `hexapod`.
    pub model: &'static str,
    /// `walking` or `standing`.
    pub run: &'static str,
    /// Steps computed.
    pub steps: usize,
    /// Always 0: the kinematic gait solves no equations iteratively.
    pub newton_iterations: usize,
    /// Wall time of the stepping loop (s).
    pub wall_seconds: f64,
    /// Steps per second of wall time.
    pub steps_per_second: Option<f64>,
    /// Time step (s).
    pub dt: f64,
    /// Configured duration (s).
    pub duration: f64,
    /// Steps planned (rows at `k·Δt`, `k = 0..=steps_planned`).
    pub steps_planned: usize,
    /// Rows written to `trajectory.csv`.
    pub rows_written: usize,
    /// `output.stride`.
    pub stride: usize,
    /// Horizontal path length of the body centre (m).
    pub distance: f64,
    /// Net horizontal displacement of the body centre (m).
    pub displacement: f64,
    /// Mean horizontal speed (m/s).
    pub mean_speed: f64,
    /// Heading change (deg).
    pub heading_change_deg: f64,
    /// Smallest stability margin (m) and when.
    pub min_margin: Option<AtTime>,
    /// Largest |θ̇| of every joint, `theta{j}_{n}` (rad/s).
    pub peak_joint_rate: BTreeMap<String, f64>,
    /// Largest |θ̈| of every joint (rad/s²).
    pub peak_joint_acceleration: BTreeMap<String, f64>,
    /// Largest |θ̇| over all joints (rad/s).
    pub peak_joint_rate_max: f64,
    /// Largest |θ̈| over all joints (rad/s²).
    pub peak_joint_acceleration_max: f64,
    /// Lift-off, touchdown and stability events.
    pub events: Vec<EventJson>,
}

fn finite(v: f64) -> Option<f64> {
    v.is_finite().then_some(v)
}

fn summary(model: &GaitModel, stride: usize, rows: usize, s: &GaitSummary) -> HexapodSummary {
    let per_joint = |p: &[[f64; 3]; LEGS]| -> BTreeMap<String, f64> {
        let mut m = BTreeMap::new();
        for (n, leg) in p.iter().enumerate() {
            for (j, v) in leg.iter().enumerate() {
                m.insert(format!("theta{}_{}", j + 1, n + 1), *v);
            }
        }
        m
    };
    let max = |p: &[[f64; 3]; LEGS]| p.iter().flatten().copied().fold(0.0, f64::max);
    HexapodSummary {
        status: if s.error.is_some() {
            "error"
        } else if s.interrupted {
            "interrupted"
        } else {
            "ok"
        },
        error: s.error.as_ref().map(ToString::to_string),
        model: "hexapod",
        run: if model.params.walking {
            "walking"
        } else {
            "standing"
        },
        steps: s.steps,
        newton_iterations: 0,
        wall_seconds: s.wall_seconds,
        steps_per_second: (s.wall_seconds > 0.0).then(|| s.steps as f64 / s.wall_seconds),
        dt: model.dt,
        duration: model.steps as f64 * model.dt,
        steps_planned: model.steps,
        rows_written: rows,
        stride,
        distance: s.distance,
        displacement: s.displacement,
        mean_speed: s.mean_speed(),
        heading_change_deg: s.heading_change.to_degrees(),
        min_margin: s
            .min_margin
            .and_then(|(v, t)| finite(v).map(|value| AtTime { value, t: tidy(t) })),
        peak_joint_rate: per_joint(&s.peak_rate),
        peak_joint_acceleration: per_joint(&s.peak_accel),
        peak_joint_rate_max: max(&s.peak_rate),
        peak_joint_acceleration_max: max(&s.peak_accel),
        events: s
            .events
            .iter()
            .map(|e| EventJson {
                t: tidy(e.t),
                leg: e.leg,
                event: e.kind.as_str(),
                margin: finite(e.margin),
            })
            .collect(),
    }
}

/// What a hexapod run produced: the library's summary, `summary.json`'s
/// content, the files written.
pub type HexapodRun = RunOutput<GaitSummary, HexapodSummary>;

/// The kinematic gait's files ([`RunFiles`]).
struct GaitFiles {
    model: GaitModel,
    output: fbd_scenario::OutputConfig,
    plot: Option<GaitPlotData>,
    view: Option<HexapodView>,
}

impl RunFiles for GaitFiles {
    type Record = GaitData;
    type Run = GaitSummary;
    type Summary = HexapodSummary;

    fn row_values(&mut self, d: &GaitData, sink: &mut dyn output::RowSink) {
        gait_row(d, sink);
    }

    fn written(&mut self, d: &GaitData) {
        if let Some(v) = self.view.as_mut() {
            v.push_gait_data(d);
        }
    }

    fn observe(&mut self, d: &GaitData) {
        if let Some(p) = self.plot.as_mut() {
            p.push(d);
        }
    }

    fn summary(&mut self, run: &GaitSummary, rows: usize) -> HexapodSummary {
        summary(&self.model, self.output.stride.max(1), rows, run)
    }

    fn events_csv(&self, run: &GaitSummary) -> String {
        events_csv(&run.events)
    }

    fn write_extras(
        self,
        dir: &Path,
        run: &GaitSummary,
        keep: &mut output::FirstError,
    ) -> Vec<&'static str> {
        if let Some(plot) = self.plot {
            crate::driver::write_svgs(
                dir,
                [
                    ("gait.svg", gait_svg(&plot)),
                    ("footprints.svg", footprints_svg(&plot)),
                    ("joints.svg", joints_svg(&plot)),
                ],
                keep,
            );
        }
        if let Some(mut view) = self.view {
            view.set_event_rows(run.events.len());
            keep.keep(view.write(dir));
        }
        output::selected(output::files_as(&FILES, self.output.format), &self.output)
    }
}

/// Runs the hexapod configuration `h` (`config` is the same, for
/// `config.toml`), handing every `output.stride`-th step to `on_row`; when
/// `out_dir` is given, writes every file there, even after a run error
/// (which is in `run.error`), and removes those of an earlier run of
/// another kind. The run stops before its next step once `stop` is set.
pub fn simulate(
    h: &HexapodConfig,
    config: &Config,
    source: &str,
    out_dir: Option<&Path>,
    stop: &AtomicBool,
    on_row: &mut dyn FnMut(&GaitData),
) -> Result<HexapodRun, OutputError> {
    let model = h.gait_model(source)?;
    let stride = h.output.stride.max(1);
    let traj = match out_dir {
        Some(dir) => {
            output::prepare_dir(dir)?;
            output::warn_size(
                model.steps.div_ceil(stride),
                columns().len(),
                stride,
                h.output.format,
            );
            Some(output::Table::create(
                dir,
                h.output.format,
                columns(),
                model.dt,
            )?)
        }
        None => None,
    };
    let plot = out_dir
        .filter(|_| h.output.plots)
        .map(|_| GaitPlotData::new(&model));
    // viewer.html: one frame per trajectory row (decimated when long).
    let view = out_dir.filter(|_| h.output.viewer).map(|_| {
        HexapodView::gait(
            &model.kin,
            model.surface.clone(),
            model.steps.div_ceil(stride),
            &crate::viewer::title_of(source, "hexapod, kinematic gait"),
        )
    });
    let files = GaitFiles {
        model: model.clone(),
        output: h.output.clone(),
        plot,
        view,
    };
    let rec = Recording::new(files, traj, stride, out_dir);
    Ok(crate::driver::drive(
        &model,
        rec,
        stop,
        &config.to_toml(),
        on_row,
    ))
}

/// `fbd run` of a hexapod configuration: simulates, writes the files,
/// prints the stability warnings, distance, speed and minimum margin.
pub fn run_command(
    h: &HexapodConfig,
    config: &Config,
    source: &str,
    out_dir: &Path,
    out: &mut dyn Write,
) -> Result<(), OutputError> {
    let HexapodRun {
        run,
        summary,
        io_error,
        files,
    } = simulate(
        h,
        config,
        source,
        Some(out_dir),
        crate::interrupt::flag(),
        &mut |_| {},
    )?;
    let mut text = String::new();
    for e in run.events.iter().filter(|e| e.leg.is_none()) {
        text.push_str(&format!(
            "t={} s  stability margin {} m {}\n",
            fbd_sim::gait::error::fmt_time(e.t),
            output::fixed(e.margin, 4),
            if e.kind == fbd_sim::gait::GaitEventKind::MarginLow {
                "below the warning threshold"
            } else {
                "back above the warning threshold"
            }
        ));
    }
    let liftoffs = run
        .events
        .iter()
        .filter(|e| e.kind == fbd_sim::gait::GaitEventKind::Liftoff)
        .count();
    text.push_str(&format!(
        "{} {} ({} s, {} lift-offs), {:.3} s\n",
        if run.error.is_some() || run.interrupted {
            "stopped after"
        } else {
            "computed"
        },
        output::count(run.steps, "step", "steps"),
        fbd_sim::gait::error::fmt_time(run.time),
        liftoffs,
        run.wall_seconds
    ));
    text.push_str(&format!(
        "distance walked {} m (net {} m, heading change {}°), mean speed {} m/s\n",
        output::fixed(summary.distance, 4),
        output::fixed(summary.displacement, 4),
        output::fixed(summary.heading_change_deg, 2),
        output::fixed(summary.mean_speed, 4)
    ));
    match &summary.min_margin {
        Some(m) => text.push_str(&format!(
            "minimum stability margin {} m at t = {} s\n",
            output::fixed(m.value, 4),
            fbd_sim::gait::error::fmt_time(m.t)
        )),
        None => text.push_str("minimum stability margin: no support polygon\n"),
    }
    let ending = if let Some(e) = &run.error {
        Ending::Failed {
            error: e.to_string(),
            source: source.to_string(),
            advice: None,
        }
    } else if run.interrupted {
        Ending::Interrupted(format!(
            "interrupted after {} steps (t = {} s)",
            run.steps,
            fbd_sim::gait::error::fmt_time(run.time)
        ))
    } else {
        Ending::Completed
    };
    output::conclude(out, text, out_dir, &files, io_error, ending)
}

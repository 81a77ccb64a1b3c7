//! `fbd run [CONFIG] [--out DIR]`: simulate and write the files of SPEC §6.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

use fbd_kinematics::planar::PlanarChains;
use fbd_sim::{Model, RunSummary, StepRecord};

use crate::CliError;
use crate::config::{self, Config};
use crate::output::{self, Energy, EventJson, PeakForce, Summary, TrajectoryWriter};
use crate::plot::{self, PlotData, Stance};

/// Most samples kept per plotted curve.
const PLOT_SAMPLES: usize = 4000;
/// Snapshot intervals of `stance.svg` (one more snapshot than this).
const STANCE_INTERVALS: usize = 10;

/// What the plots and the summary need, gathered step by step.
struct Collector {
    every: usize,
    snapshot_steps: Vec<usize>,
    tips: [Option<usize>; 2],
    plot: PlotData,
    snapshots: Vec<(f64, [f64; 7])>,
    last: Option<StepRecord>,
    peak_contact: Vec<PeakForce>,
    peak_joint: [f64; 4],
}

impl Collector {
    fn new(model: &Model, names: &[String]) -> Self {
        let steps = model.steps.max(1);
        let every = steps.div_ceil(PLOT_SAMPLES).max(1);
        let n = steps.div_ceil(every) + 1;
        let mut plot = PlotData {
            terrain: Some(model.params.terrain.clone()),
            ..PlotData::default()
        };
        plot.t.reserve(n);
        for v in plot
            .tip
            .iter_mut()
            .flatten()
            .chain(plot.fa.iter_mut())
            .chain(plot.n.iter_mut())
        {
            v.reserve(n);
        }
        let last_step = steps - 1;
        let mut snapshot_steps: Vec<usize> = (0..=STANCE_INTERVALS)
            .map(|i| ((i * last_step) as f64 / STANCE_INTERVALS as f64).round() as usize)
            .collect();
        snapshot_steps.dedup();
        Self {
            every,
            snapshots: Vec::with_capacity(snapshot_steps.len() + 1),
            snapshot_steps,
            tips: [
                names.iter().position(|n| n == "tip3"),
                names.iter().position(|n| n == "tip4"),
            ],
            plot,
            last: None,
            peak_contact: vec![PeakForce::default(); names.len()],
            peak_joint: [0.0; 4],
        }
    }

    fn push(&mut self, r: &StepRecord) {
        if r.step.is_multiple_of(self.every) {
            self.sample(r);
        }
        if self.snapshot_steps.binary_search(&r.step).is_ok() {
            self.snapshots.push((r.t, r.q));
        }
        for (c, p) in self.peak_contact.iter_mut().enumerate().take(r.contacts) {
            p.n = p.n.max(r.n[c].abs());
            p.fa = p.fa.max(r.fa[c].abs());
        }
        for (p, f) in self.peak_joint.iter_mut().zip(&r.joint_force) {
            *p = p.max(f[0].hypot(f[1]));
        }
        self.last = Some(*r);
    }

    fn sample(&mut self, r: &StepRecord) {
        self.plot.t.push(r.t);
        for (leg, c) in self.tips.iter().enumerate() {
            let (p, fa, n) = c.map_or(([f64::NAN; 2], f64::NAN, f64::NAN), |c| {
                (r.point[c], r.fa[c], r.n[c])
            });
            self.plot.tip[leg][0].push(p[0]);
            self.plot.tip[leg][1].push(p[1]);
            self.plot.fa[leg].push(fa);
            self.plot.n[leg].push(n);
        }
    }

    /// Completes the plot data after the run.
    fn finish(
        mut self,
        model: &Model,
        run: &RunSummary,
    ) -> (PlotData, Option<StepRecord>, Vec<PeakForce>, [f64; 4]) {
        if let Some(r) = self.last {
            if self.plot.t.last() != Some(&r.t) {
                self.sample(&r);
            }
            if self.snapshots.last().map(|s| s.0) != Some(r.t) {
                self.snapshots.push((r.t, r.q));
            }
        }
        self.plot.events = run.events.iter().map(|e| e.t).collect();
        let chains: &PlanarChains = &model.mech.chains;
        let ix = &model.index;
        let mut data = chains.new_data();
        for (t, q) in &self.snapshots {
            chains.eval_positions(q, &mut data);
            let p = |i: [usize; 2]| [data.pos[i[0]], data.pos[i[1]]];
            self.plot.stances.push(Stance {
                t: *t,
                hip: p(ix.hip),
                knee: p(ix.knee),
                tip: p(ix.tip),
            });
        }
        (self.plot, self.last, self.peak_contact, self.peak_joint)
    }
}

fn first_time(run: &RunSummary, leg: usize, pred: impl Fn(&fbd_sim::Event) -> bool) -> Option<f64> {
    run.events
        .iter()
        .find(|e| e.leg == leg && e.point == "tip" && pred(e))
        .map(|e| e.t)
}

fn summary(
    model: &Model,
    names: &[String],
    run: &RunSummary,
    rows: usize,
    last: Option<StepRecord>,
    peaks: Vec<PeakForce>,
    joints: [f64; 4],
) -> Summary {
    use fbd_contact::StateCode;
    let legs = ["leg3", "leg4"];
    let by_leg = |pred: &dyn Fn(&fbd_sim::Event) -> bool| -> BTreeMap<String, Option<f64>> {
        legs.iter()
            .zip([3, 4])
            .map(|(name, leg)| ((*name).to_owned(), first_time(run, leg, pred)))
            .collect()
    };
    let steps_per_second = (run.wall_seconds > 0.0).then(|| run.steps as f64 / run.wall_seconds);
    Summary {
        status: if run.error.is_some() { "error" } else { "ok" },
        error: run.error.as_ref().map(ToString::to_string),
        steps: run.steps,
        newton_iterations: run.newton_iterations,
        wall_seconds: run.wall_seconds,
        steps_per_second,
        symbolic_factorizations: run.symbolic_factorizations,
        events: run.events.iter().map(EventJson::from).collect(),
        model: "planar",
        dt: model.params.dt,
        duration: model.params.duration,
        steps_planned: model.steps,
        stride: model.params.stride,
        rows_written: rows,
        contact_points: names.to_vec(),
        first_touchdown: by_leg(&|e| e.from == StateCode::St1 && e.to != StateCode::St1),
        first_slip: by_leg(&|e| e.to == StateCode::St3),
        peak_contact_force: names.iter().cloned().zip(peaks).collect(),
        peak_joint_force: ["hip3", "knee3", "hip4", "knee4"]
            .iter()
            .map(|s| (*s).to_owned())
            .zip(joints)
            .collect(),
        peak_joint_force_max: joints.iter().copied().fold(0.0, f64::max),
        final_energy: last.map(|r| Energy {
            t: r.t,
            kinetic: r.kinetic,
            potential: r.potential,
            total: r.kinetic + r.potential,
        }),
    }
}

/// One line per event: `t=0.190 s  leg 4  ST1 -> ST2` (the point is named
/// when it is not the tip).
pub fn event_line(e: &fbd_sim::Event) -> String {
    let kind = e.point;
    let point = if kind == "tip" {
        String::new()
    } else {
        format!("{kind}  ")
    };
    format!(
        "t={:.3} s  leg {}  {point}{} -> {}",
        e.t,
        e.leg,
        e.from.as_str(),
        e.to.as_str()
    )
}

/// `fbd run`: loads `config` (the built-in default when `None`), checks
/// the output directory, simulates while streaming `trajectory.csv`, then
/// writes the other files. On a simulation error every file is still
/// written and the error is returned ([`CliError::Simulation`], exit 3).
pub fn run_command(
    config_path: Option<&Path>,
    out_dir: &Path,
    out: &mut dyn Write,
) -> Result<(), CliError> {
    let (config, source) = match config_path {
        Some(p) => (config::load(p)?, p.display().to_string()),
        None => (Config::default(), "the built-in default".to_owned()),
    };
    let planar = match &config {
        Config::Planar(c) => c,
        Config::Hexapod(_) => {
            return Err(CliError::Usage(format!(
                "{source}: model = \"hexapod\": the 3D dynamics are not implemented yet; `fbd kinematics {source}` works for hexapod configurations"
            )));
        }
    };
    let model = planar.model(&source)?;

    output::prepare_dir(out_dir)?;
    let names: Vec<String> = model.mech.contacts.iter().map(|c| c.name.clone()).collect();
    let mut traj = TrajectoryWriter::create(out_dir, &names)?;
    let mut collect = Collector::new(&model, &names);
    // The simulator hands over every `stride`-th step; the plots and peaks
    // want them all, so stride is applied here.
    let stride = model.params.stride.max(1);
    let mut every_step = model.clone();
    every_step.params.stride = 1;
    let run = fbd_sim::run(&every_step, |r: &StepRecord| {
        if r.step.is_multiple_of(stride) {
            traj.write(r);
        }
        collect.push(r);
    });
    let rows = traj.rows();
    let (plot_data, last, peaks, joints) = collect.finish(&model, &run);

    // Write every file even if one fails; report the first failure.
    let mut io_error: Option<CliError> = None;
    let mut keep = |r: Result<std::path::PathBuf, CliError>| {
        if let Err(e) = r
            && io_error.is_none()
        {
            io_error = Some(e);
        }
    };
    keep(traj.finish());
    keep(output::write_file(
        out_dir,
        "events.csv",
        output::events_csv(&run.events).as_bytes(),
    ));
    let s = summary(&model, &names, &run, rows, last, peaks, joints);
    let json =
        serde_json::to_string_pretty(&s).map_err(|e| CliError::Io(format!("summary.json: {e}")));
    keep(
        json.and_then(|j| output::write_file(out_dir, "summary.json", format!("{j}\n").as_bytes())),
    );
    keep(output::write_file(
        out_dir,
        "config.toml",
        config.to_toml().as_bytes(),
    ));
    for (name, svg) in [
        ("tips.svg", plot::tips_svg(&plot_data)),
        ("forces.svg", plot::forces_svg(&plot_data)),
        ("stance.svg", plot::stance_svg(&plot_data)),
    ] {
        keep(
            svg.map_err(|e| CliError::Io(format!("{name}: {e}")))
                .and_then(|s| output::write_file(out_dir, name, s.as_bytes())),
        );
    }

    let mut text = String::new();
    for e in &run.events {
        text.push_str(&event_line(e));
        text.push('\n');
    }
    text.push_str(&format!(
        "{} {} steps, {} Newton iterations, {:.3} s\n",
        if run.error.is_some() {
            "stopped after"
        } else {
            "solved"
        },
        run.steps,
        run.newton_iterations,
        run.wall_seconds
    ));
    if io_error.is_none() {
        text.push_str(&format!(
            "files in {}: {}\n",
            out_dir.display(),
            output::FILES.join(" ")
        ));
    }
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(CliError::stdout)?;

    if let Some(e) = io_error {
        return Err(e);
    }
    if let Some(e) = &run.error {
        return Err(CliError::Simulation(format!(
            "{e} ({source}; the steps computed so far are in {})",
            out_dir.display()
        )));
    }
    Ok(())
}

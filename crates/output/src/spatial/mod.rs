//! `fbd run` of a dynamic hexapod configuration (the 3D FBD dynamics,
//! [`fbd_sim::spatial`]): `trajectory.csv` ([`csv`]), `events.csv` (the
//! planar run's writer), `summary.json` ([`summary`]), `config.toml`,
//! `feet.svg`, `torques.svg`, `body.svg`, `energy.svg` (the plots of every
//! model on the tree equations, [`crate::tree::plots`], in the hexapod's
//! names and colours: [`plot_plan`]) and
//! `viewer.html` (the hexapod viewer with contact states and forces).

pub mod csv;
pub mod summary;

use std::io::Write;
use std::path::Path;
use std::sync::atomic::AtomicBool;

use fbd_dynamics::PointKind;
use fbd_kinematics::hexapod::{HexapodConfig, HexapodData, HexapodModel, NQ, forward};
use fbd_scenario::OutputConfig;
use fbd_sim::RunSummary;
use fbd_sim::robot::RobotRecord;
use fbd_sim::spatial::{SpatialModel, SpatialParams};

use crate::OutputError;
use crate::config::ConfigError;
use crate::driver::{Recording, RunFiles, RunOutput};
use crate::output::{self, Ending};
use crate::plot::EventMark;
use crate::steptime::StepTimes;
use crate::tree::plots::{self, Curve, PlotPlan, leg_color};
use crate::viewer::hexapod::{HexapodView, LegValues};

pub use csv::columns;
pub use summary::SpatialSummary;

/// The files a dynamic hexapod run writes, in order: every tree
/// model's ([`crate::tree::FILES`]).
pub use crate::tree::FILES;

/// The legs and contact points of a spatial model, as the output files
/// name them.
#[derive(Clone, Debug, PartialEq)]
pub struct Layout {
    /// Leg numbers (1–6), increasing.
    pub legs: Vec<usize>,
    /// The knee and hip contact points `(leg, kind)`: leg by leg, knee
    /// before hip (the feet are in the per-leg columns).
    pub extra_points: Vec<(usize, PointKind)>,
}

impl Layout {
    /// The layout of `params`: its legs, and its knees and hips when they
    /// are contact points.
    pub fn of(params: &SpatialParams) -> Self {
        let mut legs = params.legs.clone();
        legs.sort_unstable();
        legs.dedup();
        let cp = params.contact_points;
        let mut extra_points = Vec::new();
        for &n in &legs {
            if cp.knees {
                extra_points.push((n, PointKind::Knee));
            }
            if cp.hips {
                extra_points.push((n, PointKind::Hip));
            }
        }
        Self { legs, extra_points }
    }

    /// The names of the contact points (`tip3`, `knee3`, `hip3`, …), leg by
    /// leg, for messages and `summary.json`.
    pub fn point_names(&self, params: &SpatialParams) -> Vec<String> {
        let cp = params.contact_points;
        let mut names = Vec::new();
        for &n in &self.legs {
            for (on, kind) in [
                (cp.tips, PointKind::Tip),
                (cp.knees, PointKind::Knee),
                (cp.hips, PointKind::Hip),
            ] {
                if on {
                    names.push(format!("{}{n}", kind.as_str()));
                }
            }
        }
        names
    }
}

/// The forward kinematics of a spatial model's `q` (its legs only; the
/// others are folded at zero and never reported): feet, link centres of
/// mass, the whole robot's centre of mass.
#[derive(Clone, Debug)]
pub struct Feet {
    model: HexapodModel,
    data: HexapodData,
    legs: Vec<usize>,
    q: [f64; NQ],
    masses: [f64; 3],
}

impl Feet {
    /// For the geometry and masses of `params`.
    pub fn new(params: &SpatialParams) -> Self {
        Self {
            model: params.kinematic_model(),
            data: HexapodData::new(),
            legs: Layout::of(params).legs,
            q: [0.0; NQ],
            masses: [params.body_mass, params.upper_mass, params.lower_mass],
        }
    }

    /// Evaluates the kinematics at the model's coordinates `q` (`6 + 3·legs`
    /// values).
    pub fn update(&mut self, q: &[f64]) {
        self.q[..6].copy_from_slice(&q[..6]);
        for (i, &n) in self.legs.iter().enumerate() {
            let at = 6 + 3 * (n - 1);
            self.q[at..at + 3].copy_from_slice(&q[6 + 3 * i..9 + 3 * i]);
        }
        forward(&self.model, &HexapodConfig::from_q(&self.q), &mut self.data);
    }

    /// The foot of the `i`-th leg of the layout at the last [`Feet::update`].
    pub fn tip(&self, i: usize) -> [f64; 3] {
        let t = self.data.legs[self.legs[i] - 1].tip;
        [t.x, t.y, t.z]
    }

    /// The whole robot's centre of mass (body and the model's links).
    pub fn com(&self) -> [f64; 3] {
        let [mb, mu, ml] = self.masses;
        let mut c = mb * self.data.body_com;
        let mut m = mb;
        for &n in &self.legs {
            let l = &self.data.legs[n - 1];
            c += mu * l.upper_com + ml * l.lower_com;
            m += mu + ml;
        }
        let c = c / m;
        [c.x, c.y, c.z]
    }

    /// The full 24-coordinate vector of the last update.
    pub fn q(&self) -> &[f64; NQ] {
        &self.q
    }
}

impl crate::tree::Feet for Feet {
    fn update(&mut self, q: &[f64]) {
        Feet::update(self, q);
    }
    fn tip(&self, i: usize) -> [f64; 3] {
        Feet::tip(self, i)
    }
}

/// The curves of the hexapod's plots: one colour per leg, each foot
/// labelled `leg n`, and the torques τ1, τ2, τ3 of every leg, one chart
/// per joint.
pub fn plot_plan(layout: &Layout, slots: &csv::Slots) -> PlotPlan {
    let leg = |n: usize, source: Option<usize>| Curve {
        label: format!("leg {n}"),
        short: n.to_string(),
        color: leg_color(n),
        source,
    };
    let joint = |j: usize| -> Vec<Curve> {
        layout
            .legs
            .iter()
            .enumerate()
            .map(|(i, &n)| leg(n, slots.legs[i].map(|l| l.joint + j)))
            .collect()
    };
    PlotPlan {
        feet: layout
            .legs
            .iter()
            .enumerate()
            .map(|(i, &n)| leg(n, slots.tips[i]))
            .collect(),
        torques: vec![
            ("τ1 (hip, about the body's vertical axis)".into(), joint(0)),
            ("τ2 (hip, lift)".into(), joint(1)),
            ("τ3 (knee)".into(), joint(2)),
        ],
        torques_title: "Joint torques".into(),
    }
}

/// The viewer of a run and its row buffers.
struct View {
    view: HexapodView,
    /// Per contact point of the scene, its row in the records.
    rows: Vec<Option<usize>>,
    contacts: Vec<(fbd_contact::StateCode, [f64; 3])>,
    legs: Vec<LegValues>,
}

impl View {
    fn new(view: HexapodView, slots: &csv::Slots) -> Self {
        let rows = view
            .contacts()
            .iter()
            .map(|&point| slots.contacts.iter().position(|&p| p == point))
            .collect();
        let n = view.legs().len();
        Self {
            view,
            rows,
            contacts: Vec::new(),
            legs: vec![LegValues::default(); n],
        }
    }

    /// Adds a record: the model's `q`, each contact point's state and
    /// ground force, each leg's forces and torques.
    fn push(&mut self, slots: &csv::Slots, r: &RobotRecord) {
        self.contacts.clear();
        self.contacts.extend(self.rows.iter().map(|c| {
            c.map_or((fbd_contact::StateCode::St1, [0.0; 3]), |c| {
                (r.contacts[c].state, r.contacts[c].force)
            })
        }));
        for (i, l) in self.legs.iter_mut().enumerate() {
            let normal = slots.tips[i].map_or(0.0, |c| r.contacts[c].normal);
            *l = slots.leg(r, i).map_or(
                LegValues {
                    normal,
                    ..LegValues::default()
                },
                |l| LegValues {
                    normal,
                    hip_force: l.hip_force,
                    knee_force: l.knee_force,
                    torque: l.torque,
                },
            );
        }
        self.view
            .push_dynamic(r.t, &r.q, &self.contacts, &self.legs);
    }
}

/// What a dynamic hexapod run produced.
pub type SpatialRun = RunOutput<RunSummary, SpatialSummary>;

/// Everything a run writes ([`RunFiles`]), fed by the driver
/// ([`Outputs::recording`]).
pub struct Outputs {
    params: SpatialParams,
    layout: Layout,
    steps: usize,
    plan: crate::tree::Plan,
    output: OutputConfig,
    plot: Option<plots::Recorder>,
    view: Option<View>,
    collect: Option<crate::tree::summary::Collector>,
    feet: Feet,
    slots: csv::Slots,
    /// The model's start-up stability check (s), for `summary.json`.
    pub stability_check_seconds: f64,
}

impl Outputs {
    /// A recording of a run of `params` solving `steps` steps, with every
    /// file; with `out_dir`, creates it and opens `trajectory.csv` there.
    pub fn new(
        params: &SpatialParams,
        steps: usize,
        out_dir: Option<&Path>,
    ) -> Result<Recording<Self>, OutputError> {
        Self::new_as(params, steps, out_dir, &OutputConfig::default(), "hexapod")
    }

    /// [`Outputs::new`] with the files `output` selects (`[output] format`,
    /// `viewer`, `plots`).
    pub fn new_as(
        params: &SpatialParams,
        steps: usize,
        out_dir: Option<&Path>,
        output: &OutputConfig,
        source: &str,
    ) -> Result<Recording<Self>, OutputError> {
        let format = output.format;
        let layout = Layout::of(params);
        let stride = params.stride.max(1);
        let slots = csv::Slots::of(&layout, &params.record_index());
        let plan = csv::plan(&layout, &slots);
        let table = match out_dir {
            Some(dir) => {
                output::prepare_dir(dir)?;
                output::warn_size(steps.div_ceil(stride), plan.names.len(), stride, format);
                Some(output::Table::create(
                    dir,
                    format,
                    plan.names.clone(),
                    params.dt,
                )?)
            }
            None => None,
        };
        let t_end = (steps.max(1) - 1) as f64 * params.dt;
        let files = Self {
            stability_check_seconds: 0.0,
            collect: Some(summary::collector(&layout, &slots, params)),
            plot: out_dir.filter(|_| output.plots).map(|_| {
                plots::Recorder::new(plot_plan(&layout, &slots), t_end)
                    .with_surface(&params.terrain)
            }),
            view: out_dir.filter(|_| output.viewer).map(|_| {
                let view = HexapodView::dynamic(
                    params,
                    steps.div_ceil(stride),
                    &crate::viewer::title_of(source, "hexapod, 3D dynamics"),
                );
                View::new(view, &slots)
            }),
            feet: Feet::new(params),
            params: params.clone(),
            plan,
            output: output.clone(),
            slots,
            layout,
            steps,
        };
        Ok(Recording::new(files, table, stride, out_dir))
    }
}

impl RunFiles for Outputs {
    type Record = RobotRecord;
    type Run = RunSummary;
    type Summary = SpatialSummary;

    fn row_values(&mut self, r: &RobotRecord, sink: &mut dyn output::RowSink) {
        self.plan.row(r, Some(&mut self.feet), sink);
    }

    fn written(&mut self, r: &RobotRecord) {
        if let Some(v) = self.view.as_mut() {
            v.push(&self.slots, r);
        }
    }

    fn observe(&mut self, r: &RobotRecord) {
        if let Some(c) = self.collect.as_mut() {
            c.push(r);
        }
        if let Some(p) = self.plot.as_mut() {
            p.push(r);
        }
    }

    fn summary(&mut self, run: &RunSummary, rows: usize) -> SpatialSummary {
        let collect = self.collect.take().expect("summarised once");
        summary::finish(
            collect,
            &self.params,
            self.steps,
            &self.layout,
            run,
            rows,
            self.stability_check_seconds,
        )
    }

    fn events_csv(&self, run: &RunSummary) -> String {
        output::run_events_csv(run, self.params.dt)
    }

    fn write_extras(
        self,
        dir: &Path,
        run: &RunSummary,
        keep: &mut output::FirstError,
    ) -> Vec<&'static str> {
        if let Some(plot) = self.plot {
            let plot = plot.finish(run.events.iter().map(EventMark::of).collect());
            plots::write(dir, &plot, keep);
        }
        if let Some(View { mut view, .. }) = self.view {
            view.set_event_rows(output::run_events(run, &StepTimes::new(self.params.dt)).len());
            keep.keep(view.write(dir));
        }
        output::selected(output::files_as(&FILES, self.output.format), &self.output)
    }
}

/// `[output]` of a configuration's text (the defaults when it has none).
fn output_of(config_toml: &str) -> OutputConfig {
    toml::from_str::<toml::Table>(config_toml)
        .ok()
        .and_then(|t| t.get("output")?.clone().try_into().ok())
        .unwrap_or_default()
}

/// Simulates `params` (read from `source`; `config_toml` is the complete
/// configuration for `config.toml`), handing every `stride`-th record to
/// `on_row`; when `out_dir` is given, writes every file of a dynamic
/// (the trajectory in the `[output] format` of `config_toml`)
/// hexapod run there, streaming `trajectory.csv`, even after a simulation
/// error (which is in `run.error`). The run stops before its next step
/// once `stop` is set (`run.interrupted`). Fails for an invalid model or
/// an output directory that cannot be created.
pub fn simulate(
    params: &SpatialParams,
    config_toml: &str,
    source: &str,
    out_dir: Option<&Path>,
    stop: &AtomicBool,
    on_row: &mut dyn FnMut(&RobotRecord),
) -> Result<SpatialRun, OutputError> {
    // The plots and peaks want every step: stride is applied by Outputs.
    let mut every_step = params.clone();
    every_step.stride = 1;
    let model = SpatialModel::new(&every_step).map_err(|e| ConfigError::Semantic {
        file: source.to_owned(),
        message: e.to_string(),
    })?;
    let mut rec = Outputs::new_as(
        params,
        model.steps,
        out_dir,
        &output_of(config_toml),
        source,
    )?;
    rec.files_mut().stability_check_seconds = model.stability_check_seconds;
    Ok(crate::driver::drive(&model, rec, stop, config_toml, on_row))
}

/// `fbd run` of a dynamic hexapod configuration: simulates, writes the
/// files, prints the events, the step count, the distance walked and the
/// final height, and ends like every run ([`output::conclude`]).
pub fn run_command(
    params: &SpatialParams,
    config_toml: &str,
    source: &str,
    out_dir: &Path,
    out: &mut dyn Write,
) -> Result<(), OutputError> {
    let SpatialRun {
        run,
        summary,
        io_error,
        files,
    } = simulate(
        params,
        config_toml,
        source,
        Some(out_dir),
        crate::interrupt::flag(),
        &mut |_| {},
    )?;
    let mut text = output::run_report(&run, params.dt);
    if let Some(h) = summary.final_height {
        text.push_str(&format!(
            "body moved {} m (x {} m, z {} m), final height {} m\n",
            output::fixed(summary.distance, 4),
            output::fixed(summary.displacement[0], 4),
            output::fixed(summary.displacement[2], 4),
            output::fixed(h, 4)
        ));
    }
    let ending = Ending::of_run(&run, source, None, summary.extent.steps_planned, params.dt);
    output::conclude(out, text, out_dir, &files, io_error, ending)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fbd_contact::StateCode;
    use fbd_dynamics::tree::{TreeMechanism, contacts_by_kind};
    use fbd_sim::Event;
    use fbd_sim::robot::RobotContactRow;

    /// A made-up step `k` of `params`: the robot falling rigidly, foot 4
    /// on the ground (ST2) from step 5.
    fn record(p: &SpatialParams, k: usize) -> RobotRecord {
        let t = k as f64 * p.dt;
        let mut q = p.q0.clone();
        q[1] -= 0.5 * p.gravity * t * t;
        let robot = p.robot_model();
        let mech = TreeMechanism::with_contacts(&robot, p.gravity, &contacts_by_kind(&robot));
        let mut r = RobotRecord::new(&mech, &q);
        let index = p.record_index();
        for (c, &(n, kind)) in index.contacts.iter().enumerate() {
            let down = n == 4 && kind == PointKind::Tip && k >= 5;
            r.contacts[c] = RobotContactRow {
                point: [n as f64, 0.0, 0.0],
                state: if down { StateCode::St2 } else { StateCode::St1 },
                force: if down { [1.0, 50.0, 0.0] } else { [0.0; 3] },
                normal: if down { 50.0 } else { 0.0 },
                tangential: if down { [1.0, 0.0] } else { [0.0; 2] },
            };
        }
        for l in &index.legs {
            let j = l.joint;
            r.torque[j..j + 3].copy_from_slice(&[0.1 * l.leg as f64, -2.0, 3.0]);
            r.rate[j..j + 3].copy_from_slice(&[1.0, 2.0, -1.0]);
        }
        r.step = k;
        r.t = t;
        r.kinetic = 1.0;
        r.potential = 2.0;
        r.newton_iterations = 2 + k % 3;
        r.state_trials = 1;
        r
    }

    #[test]
    fn a_run_writes_every_file_from_its_records() {
        let dir = tempfile::tempdir().unwrap();
        let p = SpatialParams {
            duration: 0.01,
            legs: vec![3, 4],
            q0: {
                let mut q = vec![0.0, 0.6, 0.0, 0.0, 0.0, 0.0];
                q.extend([0.0, 0.0, 4.3, 0.0, 0.0, 4.3]);
                q
            },
            stride: 2,
            ..SpatialParams::default()
        };
        let steps = 11;
        let mut out = Outputs::new(&p, steps, Some(dir.path())).unwrap();
        let mut written = 0;
        for k in 0..steps {
            out.push(&record(&p, k), &mut |_| written += 1);
        }
        let run = RunSummary {
            steps,
            newton_iterations: 30,
            // The most of one step, as the records say (2 + k % 3).
            max_newton_iterations: 4,
            events: vec![Event {
                t: 0.005,
                step: 5,
                contact: p
                    .record_index()
                    .contacts
                    .iter()
                    .position(|&c| c == (4, PointKind::Tip))
                    .unwrap(),
                point: PointKind::Tip,
                leg: 4,
                from: StateCode::St1,
                to: StateCode::St2,
            }],
            ..RunSummary::default()
        };
        let r = out.finish(run, "# config\n");
        assert!(r.io_error.is_none(), "{:?}", r.io_error);
        assert_eq!(written, 6);
        for f in FILES {
            assert!(dir.path().join(f).exists(), "{f}");
        }
        let csv = std::fs::read_to_string(dir.path().join("trajectory.csv")).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        assert_eq!(lines.len(), 7);
        assert_eq!(lines[0], columns(&Layout::of(&p)).join(","));
        assert!(lines[0].starts_with("t,rx,ry,rz,phi_x,phi_y,phi_z,theta1_3,"));
        // Row 3 is step 6: foot 4 sticks with its force.
        let row: Vec<&str> = lines[4].split(',').collect();
        let header: Vec<&str> = lines[0].split(',').collect();
        let at = |name: &str| row[header.iter().position(|h| *h == name).unwrap()];
        assert_eq!(at("t"), "0.006");
        assert_eq!(at("state4"), "ST2");
        assert_eq!(at("state3"), "ST1");
        assert_eq!(at("foot4_fy"), "50.0");
        assert_eq!(at("foot4_n"), "50.0");
        assert_eq!(at("foot4_x"), "4.0");
        assert_eq!(at("tau1_4"), "0.4");
        assert_eq!(at("kneepoint3_state"), "ST1");
        let events = std::fs::read_to_string(dir.path().join("events.csv")).unwrap();
        assert_eq!(events, "t,leg,from,to,point\n0.005,4,ST1,ST2,tip\n");
        let s = r.summary;
        assert_eq!(s.extent.rows_written, 6);
        assert_eq!(s.head.newton_iterations_per_step.max, 4);
        assert_eq!(s.extent.first_touchdown["leg4"], Some(0.005));
        assert_eq!(s.extent.first_touchdown["leg3"], None);
        let peak = &s.peak_actuation[5];
        assert_eq!((peak.leg, peak.joint.as_str()), (Some(4), "theta3"));
        assert_eq!((peak.torque, peak.power), (3.0, 3.0));
        assert_eq!(s.peak_torque_max, 3.0);
        assert_eq!(s.peak_power_max, 4.0);
        assert_eq!(s.extent.peak_contact_force["tip4"].n, 50.0);
        assert_eq!(s.extent.peak_contact_force["tip4"].fa, 1.0);
        let fall = 0.5 * p.gravity * 0.01f64.powi(2);
        assert!((s.displacement[1] + fall).abs() < 1e-15);
        assert_eq!(s.final_height, Some(0.6 - fall));
        let page = std::fs::read_to_string(dir.path().join("viewer.html")).unwrap();
        assert!(page.contains("\"dynamic\":true"));
        assert!(page.contains("\"model\":\"robot\""));
        assert!(page.contains("\"tip4\""));
        assert!(!page.contains("\"tip1\""));
        for f in ["feet.svg", "torques.svg", "body.svg", "energy.svg"] {
            let svg = std::fs::read_to_string(dir.path().join(f)).unwrap();
            assert!(
                svg.starts_with("<svg") && svg.trim_end().ends_with("</svg>"),
                "{f}"
            );
        }
        let feet = std::fs::read_to_string(dir.path().join("feet.svg")).unwrap();
        assert!(feet.contains("leg 4") && feet.contains("4 tip ST2"));
    }

    #[test]
    fn feet_that_are_not_contact_points_are_placed_by_the_kinematics() {
        let dir = tempfile::tempdir().unwrap();
        let mut p = SpatialParams {
            duration: 0.002,
            ..SpatialParams::default()
        };
        p.contact_points.tips = false;
        let mut out = Outputs::new(&p, 3, Some(dir.path())).unwrap();
        for k in 0..3 {
            out.push(&record(&p, k), &mut |_| {});
        }
        let r = out.finish(RunSummary::default(), "");
        assert!(r.io_error.is_none());
        let csv = std::fs::read_to_string(dir.path().join("trajectory.csv")).unwrap();
        let lines: Vec<&str> = csv.lines().collect();
        let header: Vec<&str> = lines[0].split(',').collect();
        let row: Vec<&str> = lines[2].split(',').collect();
        let at = |name: &str| row[header.iter().position(|h| *h == name).unwrap()];
        let mut feet = Feet::new(&p);
        feet.update(&record(&p, 1).q);
        for (i, n) in (1..=6).enumerate() {
            let tip = feet.tip(i);
            for (a, v) in ["x", "y", "z"].iter().zip(tip) {
                assert_eq!(at(&format!("foot{n}_{a}")), ryu::Buffer::new().format(v));
            }
            assert_eq!(at(&format!("state{n}")), "ST1");
            assert_eq!(at(&format!("foot{n}_fy")), "0.0");
        }
        // The default legs put the feet c·sin 250° = −0.395 m below the hips.
        let ry = record(&p, 1).q[1];
        assert!((feet.tip(0)[1] - (ry + 0.42 * 250f64.to_radians().sin())).abs() < 1e-12);
    }
}

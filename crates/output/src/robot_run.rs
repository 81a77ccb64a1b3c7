//! `fbd run` of an imported robot (`model = "robot"`): the run itself is
//! [`fbd_scenario::robot::LoadedRobot::run`] (the generic FBD model on its
//! terrain, or in flight with `[terrain] kind = "none"`); this module
//! writes `trajectory.csv` (or `trajectory.parquet` with `[output] format
//! = "parquet"`; streamed, every `[output] stride`-th step: the columns of
//! [`plan`] through the row writer of every model on the tree equations,
//! [`crate::tree`]), `events.csv`, `summary.json`, `config.toml`, the
//! plots `feet.svg`, `torques.svg`, `body.svg`, `energy.svg` (unless
//! `[output] plots = false`; the hexapod's, [`crate::tree::plots`], in the
//! robot's names: [`plot_plan`]) and `viewer.html` (unless `[output]
//! viewer = false`; [`crate::viewer::robot`]), each all-or-nothing, also
//! after a simulation error or an interruption.

use std::io::Write;
use std::path::Path;
use std::sync::atomic::AtomicBool;

use fbd_sim::robot::{RobotRecord, RobotSim};
use serde::Serialize;

use crate::OutputError;
use crate::config::robot::{LoadedRobot, MOTION_BASE_COLUMNS, RobotRun};
use crate::driver::{self, Recording, RunFiles, RunOutput, Stepper};
use crate::output::{self, Ending};
use crate::plot::{EventMark, PALETTE};
use crate::steptime::StepTimes;
use crate::tree::plots::{self, Curve, PlotPlan};
use crate::tree::summary::{Collector, Facts, Keys, TreeSummary};
use crate::tree::{Plan, Source};

/// The files of a robot's run, in the order they are written (the plots
/// only with `[output] plots`, the viewer only with `[output] viewer`;
/// `trajectory.parquet` instead of `trajectory.csv` with `[output] format
/// = "parquet"`): every tree model's ([`crate::tree::FILES`]).
pub use crate::tree::FILES;

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

/// `summary.json` of a robot's run: the summary of every model on the
/// tree equations ([`crate::tree::summary`]) in the robot's names (its
/// contact points, its joints, each reaction by its first joint; the feet
/// of `first_touchdown` and `first_slip` are the contact points), with
/// `robot` (its name), `peak_normal_force`, and its events by point
/// ([`RobotEvent`]). Its peaks, path and final energy are over the written
/// rows; its final position is after the last solved step.
pub type RobotSummary = TreeSummary<RobotEvent>;

/// The robot's keys of its figures (run by `sim`): every contact point by
/// its name (its own foot in `first_touchdown`), every reaction by its
/// first joint's name, every joint by its name.
pub fn keys(robot: &LoadedRobot, sim: &RobotSim) -> Keys {
    let joints = &robot.model.joints;
    let contacts: Vec<String> = sim.mech.contacts.iter().map(|c| c.name.clone()).collect();
    Keys {
        feet: contacts
            .iter()
            .enumerate()
            .map(|(c, name)| (name.clone(), Some(c)))
            .collect(),
        contacts,
        reactions: sim
            .mech
            .reactions
            .iter()
            .enumerate()
            .map(|(i, r)| (joints[r.joints[0]].name.clone(), Some(i)))
            .collect(),
        joints: joints
            .iter()
            .enumerate()
            .map(|(j, joint)| (None, joint.name.clone(), Some(j)))
            .collect(),
    }
}

/// What [`simulate`] did: how the run ended, `summary.json`'s content,
/// the files written.
pub type RobotRunOutput = RunOutput<RobotRun, RobotSummary>;

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

/// The columns of a robot's `trajectory.csv` (run by `sim`): `t, rx, ry,
/// rz, phi_x, phi_y, phi_z`, one per joint angle (rad, the joint's name);
/// per reaction `<joint>_fx, _fy, _fz` (force of the parent on the child
/// at the joint's origin, N, inertial) and `<joint>_mx, _my, _mz` (its
/// moment on the child about that point: constraint moments, actuator
/// torques and stops, N·m), named by the reaction's first joint;
/// `tau_<joint>` per joint (N·m); per contact point `<c>`: `<c>_state`,
/// `<c>_x, _y, _z` (where it touches, m), `<c>_fx, _fy, _fz` (the ground's
/// force on it, N, inertial) and `<c>_n` (its normal component); then
/// `com_x, com_y, com_z, kinetic, potential, newton_iterations`.
pub fn plan(robot: &LoadedRobot, sim: &RobotSim) -> Plan {
    let joints = &robot.model.joints;
    let mut p = Plan::default();
    p.push("t", Source::Time);
    for (i, name) in MOTION_BASE_COLUMNS.iter().enumerate() {
        p.push(*name, Source::Q(i));
    }
    for (j, joint) in joints.iter().enumerate() {
        p.push(joint.name.clone(), Source::Q(MOTION_BASE_COLUMNS.len() + j));
    }
    for (i, r) in sim.mech.reactions.iter().enumerate() {
        let prefix = format!("{}_", joints[r.joints[0]].name);
        p.push_each(&prefix, ["fx", "fy", "fz"], |a| Source::ReactionForce(i, a));
        p.push_each(&prefix, ["mx", "my", "mz"], |a| {
            Source::ReactionMoment(i, a)
        });
    }
    for (j, joint) in joints.iter().enumerate() {
        p.push(format!("tau_{}", joint.name), Source::Torque(j));
    }
    for (c, point) in sim.mech.contacts.iter().enumerate() {
        let prefix = format!("{}_", point.name);
        p.push(format!("{prefix}state"), Source::ContactState(c));
        p.push_each(&prefix, ["x", "y", "z"], |a| Source::ContactPoint(c, a));
        p.push_each(&prefix, ["fx", "fy", "fz"], |a| Source::ContactForce(c, a));
        p.push(format!("{prefix}n"), Source::ContactNormal(c));
    }
    p.push_each("com_", ["x", "y", "z"], Source::Com);
    p.push("kinetic", Source::Kinetic);
    p.push("potential", Source::Potential);
    p.push("newton_iterations", Source::Iterations);
    p
}

/// The curves of a robot's plots: every contact point a foot (its name,
/// a colour each); the joints in one torque chart per depth from the root
/// (the first joint of every limb, the second, …: a quadruped's hip
/// abduction, hip flexion and knee), each joint in its limb's colour (the
/// limbs: the subtrees of the root, in model order).
pub fn plot_plan(robot: &LoadedRobot, sim: &RobotSim) -> PlotPlan {
    let model = &robot.model;
    let color = |k: usize| PALETTE[k % PALETTE.len()];
    // Each joint's depth (1: on the root) and limb.
    let mut depth = vec![0usize; model.joints.len()];
    let mut limb = vec![0usize; model.joints.len()];
    let mut limbs = 0;
    for (j, joint) in model.joints.iter().enumerate() {
        match model.bodies[joint.parent].joint {
            Some(up) => {
                depth[j] = depth[up] + 1;
                limb[j] = limb[up];
            }
            None => {
                depth[j] = 1;
                limb[j] = limbs;
                limbs += 1;
            }
        }
    }
    let deepest = depth.iter().copied().max().unwrap_or(0);
    let torques = (1..=deepest)
        .map(|d| {
            let curves: Vec<Curve> = (0..model.joints.len())
                .filter(|&j| depth[j] == d)
                .map(|j| Curve {
                    label: model.joints[j].name.clone(),
                    short: model.joints[j].name.clone(),
                    color: color(limb[j]),
                    source: Some(j),
                })
                .collect();
            let names: Vec<&str> = curves.iter().map(|c| c.label.as_str()).collect();
            let listed = if names.len() > 4 {
                format!("{}, … ({} joints)", names[..4].join(", "), names.len())
            } else {
                names.join(", ")
            };
            let title = format!("Depth {d} from the root: {listed}");
            (title, curves)
        })
        .collect();
    PlotPlan {
        feet: sim
            .mech
            .contacts
            .iter()
            .enumerate()
            .map(|(c, point)| Curve {
                label: point.name.clone(),
                short: point.name.clone(),
                color: color(c),
                source: Some(c),
            })
            .collect(),
        torques,
        torques_title: "Joint torques, by depth from the root".into(),
    }
}

/// The event marks of a robot's plots: a contact point's name and its new
/// state.
fn event_marks(sim: &RobotSim, run: &fbd_sim::RunSummary) -> Vec<EventMark> {
    run.events
        .iter()
        .map(|e| EventMark {
            t: e.t,
            label: format!("{} {}", sim.mech.contacts[e.contact].name, e.to.as_str()),
        })
        .collect()
}

/// A robot's stepping: the engine on its simulator ([`LoadedRobot::run_sim`]).
struct RobotStepper<'a> {
    robot: &'a LoadedRobot,
    sim: &'a RobotSim,
}

impl Stepper<RobotRecord> for RobotStepper<'_> {
    type Run = RobotRun;
    fn step(
        &self,
        stop: &AtomicBool,
        written: usize,
        mut each: impl FnMut(&RobotRecord),
    ) -> RobotRun {
        self.robot
            .run_sim_written(self.sim, stop, written, &mut each)
    }
}

/// A robot's files ([`RunFiles`]): the trajectory streamed, the plots, the
/// peaks, the viewer's frames.
struct RobotFiles<'a> {
    robot: &'a LoadedRobot,
    sim: &'a RobotSim,
    plan: Plan,
    plot: Option<plots::Recorder>,
    frames: Option<crate::viewer::robot::RobotFrames>,
    states: Vec<u8>,
    forces: Vec<[f64; 3]>,
    collect: Option<Collector>,
    events_csv: String,
}

impl RunFiles for RobotFiles<'_> {
    type Record = RobotRecord;
    type Run = RobotRun;
    type Summary = RobotSummary;

    fn row_values(&mut self, r: &RobotRecord, sink: &mut dyn output::RowSink) {
        self.plan.row(r, None, sink);
    }

    fn written(&mut self, r: &RobotRecord) {
        // The summary's figures are over the written rows (the same with
        // or without the plots, which make the run record every step).
        if let Some(c) = self.collect.as_mut() {
            c.push(r);
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
    }

    fn observe(&mut self, r: &RobotRecord) {
        if let Some(p) = self.plot.as_mut() {
            p.push(r);
        }
    }

    fn summary(&mut self, run: &RobotRun, rows: usize) -> RobotSummary {
        let (robot, sim) = (self.robot, self.sim);
        let dt = robot.config.time.dt;
        let times = StepTimes::new(dt);
        let s = &run.summary;
        let events = robot_events(robot, sim, s, &times);
        self.events_csv = output::events_table(EVENTS_HEADER, &events, &times, |e| {
            format!("{},{},{}", e.point, e.from, e.to)
        });
        let mut collect = self.collect.take().expect("summarised once");
        collect.end_at(&run.final_q);
        let facts = Facts {
            model: crate::config::robot::MODEL,
            robot: Some(robot.model.name.clone()),
            hexapod: None,
            dt,
            duration: robot.config.time.duration,
            steps_planned: run.steps_planned,
            stride: robot.config.output.stride,
            contact_points: sim.mech.contacts.iter().map(|c| c.name.clone()).collect(),
            stability_check_seconds: Some(sim.stability_check_seconds),
            peak_normal_force: true,
        };
        let events = events.into_iter().map(|(_, _, e)| e).collect();
        let mut summary = collect.finish(facts, s, rows, events);
        if s.error.is_none() && s.interrupted {
            // A robot's run names the time it stopped at.
            summary.head.error = Some(output::interrupted_after(s, run.steps_planned, dt));
        }
        summary
    }

    fn events_csv(&self, _: &RobotRun) -> String {
        self.events_csv.clone()
    }

    fn write_extras(
        self,
        dir: &Path,
        run: &RobotRun,
        keep: &mut output::FirstError,
    ) -> Vec<&'static str> {
        if let Some(plot) = self.plot {
            let plot = plot.finish(event_marks(self.sim, &run.summary));
            plots::write(dir, &plot, keep);
        }
        if let Some(mut f) = self.frames {
            if !self.states.is_empty() {
                f = f.with_surface(self.robot.config.terrain.surface());
            }
            f.set_event_rows(self.events_csv.lines().count() - 1);
            keep.keep(f.write(dir));
        }
        files(self.robot)
    }
}

/// Simulates `robot` and writes its files in `out_dir` (created if
/// needed; files of an earlier run that this one does not write are
/// removed), handing every written row's record to `on_row`. The run
/// stops before its next step once `stop` is set.
pub fn simulate(
    robot: &LoadedRobot,
    source: &str,
    out_dir: &Path,
    stop: &AtomicBool,
    on_row: &mut dyn FnMut(&RobotRecord),
) -> Result<RobotRunOutput, OutputError> {
    let mut sim = robot.sim().map_err(|e| crate::ConfigError::Semantic {
        file: source.to_owned(),
        message: e.to_string(),
    })?;
    let output = &robot.config.output;
    // The plots want every step: the stride is then applied by the
    // recording (a record's step is a multiple of the stride either way).
    if output.plots {
        sim.params.stride = 1;
    }
    output::prepare_dir(out_dir)?;
    let plan = plan(robot, &sim);
    let traj = output::Table::create(out_dir, output.format, plan.names.clone(), sim.params.dt)?;
    let contacts = sim.mech.contacts.len();
    let t_end = (sim.steps.max(1) - 1) as f64 * sim.params.dt;
    let surface = robot.config.terrain.surface();
    let files = RobotFiles {
        robot,
        sim: &sim,
        plan,
        plot: output.plots.then(|| {
            let r = plots::Recorder::new(plot_plan(robot, &sim), t_end);
            if contacts > 0 {
                r.with_surface(&surface)
            } else {
                r
            }
        }),
        frames: output
            .viewer
            .then(|| crate::viewer::robot::RobotFrames::new(&robot.model, contacts > 0)),
        states: vec![0u8; contacts],
        forces: vec![[0.0; 3]; contacts],
        collect: Some(Collector::new(keys(robot, &sim), &surface)),
        events_csv: String::new(),
    };
    let stepper = RobotStepper { robot, sim: &sim };
    Ok(driver::drive(
        &stepper,
        Recording::new(files, Some(traj), output.stride, Some(out_dir)),
        stop,
        &robot.config.to_toml(),
        on_row,
    ))
}

/// The files a run of `robot` writes ([`FILES`] as `[output]` selects
/// them).
pub fn files(robot: &LoadedRobot) -> Vec<&'static str> {
    let output = &robot.config.output;
    output::selected(output::files_as(&FILES, output.format), output)
}

/// `fbd run` of a `model = "robot"` configuration `text` read from `path`,
/// with `overrides` (`fbd run --set`) applied:
/// simulates, writes the files, prints the step count, and ends like every
/// run ([`output::conclude`]: exit 3 after a simulation error, 130 when
/// interrupted).
pub fn run_command(
    text: &str,
    path: &Path,
    overrides: &[crate::config::Override],
    out_dir: &Path,
    out: &mut dyn Write,
) -> Result<(), OutputError> {
    let source = path.display().to_string();
    let robot = crate::config::robot::load_with_overrides(text, path, overrides)?;
    let RobotRunOutput {
        run,
        summary: _,
        io_error,
        files,
    } = simulate(
        &robot,
        &source,
        out_dir,
        crate::interrupt::flag(),
        &mut |_| {},
    )?;
    let s = &run.summary;
    let text = output::solved(s);
    let ending = Ending::of_run(s, &source, None, run.steps_planned, robot.config.time.dt);
    output::conclude(out, text, out_dir, &files, io_error, ending)
}

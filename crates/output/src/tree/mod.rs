//! The trajectory of any model on the tree equations (the paper's hexapod
//! and every imported robot): its columns as data, a [`Plan`] — each
//! column's name and where its value is in the one record of every robot
//! ([`RobotRecord`]) — and the one row writer that follows it into a
//! [`crate::output::Table`] (`trajectory.csv` or `trajectory.parquet`),
//! the Python package's columns or a sweep's. A model names its columns
//! ([`crate::spatial::csv::plan`] the hexapod's, leg by leg;
//! [`crate::robot_run::plan`] an imported robot's, by its joints and
//! points; [`crate::output::ContactSlots::plan`] the planar model's, the
//! contract's columns); what a row holds is written once, here. Their
//! plots: [`plots`].

pub mod plots;

/// The files a run of a model on the tree equations writes (the hexapod's
/// dynamic runs and every imported robot's), in order: the plots only
/// with `[output] plots`, the viewer only with `[output] viewer`,
/// `trajectory.parquet` instead of `trajectory.csv` with `[output] format
/// = "parquet"`.
pub const FILES: [&str; 9] = [
    "trajectory.csv",
    "events.csv",
    "summary.json",
    "config.toml",
    "feet.svg",
    "torques.svg",
    "body.svg",
    "energy.svg",
    "viewer.html",
];
pub mod summary;

use fbd_contact::StateCode;
use fbd_sim::robot::RobotRecord;

use crate::output::RowSink;

/// Where one column's value is in a [`RobotRecord`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Source {
    /// `t` (the exact decimal of k·Δt in a CSV file).
    Time,
    /// `q[i]` (m, rad).
    Q(usize),
    /// Component `a` of reaction `i`'s force on its child (N, inertial).
    ReactionForce(usize, usize),
    /// Component `a` of reaction `i`'s moment on its child (N·m, inertial).
    ReactionMoment(usize, usize),
    /// Joint `j`'s actuator torque (N·m).
    Torque(usize),
    /// Contact point `c`'s state.
    ContactState(usize),
    /// Component `a` of where contact point `c` touches (m).
    ContactPoint(usize, usize),
    /// Component `a` of the ground's force on contact point `c` (N).
    ContactForce(usize, usize),
    /// The normal component of that force (N).
    ContactNormal(usize),
    /// Component `a` of the whole robot's centre of mass (m).
    Com(usize),
    /// Kinetic energy (J).
    Kinetic,
    /// Potential energy (J).
    Potential,
    /// Newton iterations of the step.
    Iterations,
    /// A point that is not a contact point of the model: free (`ST1`).
    Free,
    /// A force of a point that is not a contact point of the model: 0.
    Zero,
    /// A position of a point that is not a contact point of the planar
    /// model: NaN.
    Nan,
    /// Component `a` of the ground's force on contact point `c` along the
    /// contact frame's tangents (N; the planar model's `fa` is `a` = 0).
    ContactTangential(usize, usize),
    /// Joint `j`'s stop moment (N·m).
    Stop(usize),
    /// Kinetic plus potential energy (J).
    Energy,
    /// Component `a` of the `i`-th foot of the model placed by its
    /// kinematics (a foot that is not a contact point; [`Feet`]).
    Foot(usize, usize),
    /// Roll, pitch and heading of the root (rad, from its `φ`,
    /// `fbd_kinematics::pose::BodyPose::attitude`): `a` = 0, 1, 2.
    Attitude(usize),
}

/// Places the feet that are not contact points from a record's `q`.
pub trait Feet {
    /// Evaluates the kinematics at `q`.
    fn update(&mut self, q: &[f64]);
    /// The `i`-th foot at the last update (m).
    fn tip(&self, i: usize) -> [f64; 3];
}

/// The columns of a trajectory: each one's name and source, in order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Plan {
    /// Column names, in order.
    pub names: Vec<String>,
    /// Each column's source.
    pub sources: Vec<Source>,
    /// Whether a column is a [`Source::Foot`].
    feet: bool,
}

impl Plan {
    /// Appends column `name` from `source`.
    pub fn push(&mut self, name: impl Into<String>, source: Source) {
        self.names.push(name.into());
        self.sources.push(source);
        self.feet |= matches!(source, Source::Foot(..));
    }

    /// Appends `prefix{suffix}` for every suffix, from `source(i)`.
    pub fn push_each<const N: usize>(
        &mut self,
        prefix: &str,
        suffixes: [&str; N],
        source: impl Fn(usize) -> Source,
    ) {
        for (i, s) in suffixes.iter().enumerate() {
            self.push(format!("{prefix}{s}"), source(i));
        }
    }

    /// Whether a row needs the feet placed by the kinematics.
    pub fn needs_feet(&self) -> bool {
        self.feet
    }

    /// Hands the values of the row of `r` to `sink`, in column order;
    /// `feet` places the feet of [`Source::Foot`] columns. No allocation.
    pub fn row(&self, r: &RobotRecord, feet: Option<&mut dyn Feet>, sink: &mut dyn RowSink) {
        let feet: Option<&dyn Feet> = match feet {
            Some(f) => {
                if self.feet {
                    f.update(&r.q);
                }
                Some(f)
            }
            None => None,
        };
        let mut attitude = None;
        for s in &self.sources {
            match *s {
                Source::Time => sink.time(r.step, r.t),
                Source::Q(i) => sink.num(r.q[i]),
                Source::ReactionForce(i, a) => sink.num(r.reaction_force[i][a]),
                Source::ReactionMoment(i, a) => sink.num(r.reaction_moment[i][a]),
                Source::Torque(j) => sink.num(r.torque[j]),
                Source::ContactState(c) => sink.state(r.contacts[c].state),
                Source::ContactPoint(c, a) => sink.num(r.contacts[c].point[a]),
                Source::ContactForce(c, a) => sink.num(r.contacts[c].force[a]),
                Source::ContactNormal(c) => sink.num(r.contacts[c].normal),
                Source::Com(a) => sink.num(r.com[a]),
                Source::Kinetic => sink.num(r.kinetic),
                Source::Potential => sink.num(r.potential),
                Source::Iterations => sink.count(r.newton_iterations),
                Source::Free => sink.state(StateCode::St1),
                Source::Zero => sink.num(0.0),
                Source::Nan => sink.num(f64::NAN),
                Source::ContactTangential(c, a) => sink.num(r.contacts[c].tangential[a]),
                Source::Stop(j) => sink.num(r.stop[j]),
                Source::Energy => sink.num(r.kinetic + r.potential),
                Source::Foot(i, a) => {
                    let f = feet.expect("a plan with feet placed by the kinematics");
                    sink.num(f.tip(i)[a]);
                }
                Source::Attitude(a) => {
                    let att = *attitude.get_or_insert_with(|| {
                        fbd_kinematics::pose::BodyPose::new(
                            [r.q[0], r.q[1], r.q[2]],
                            [r.q[3], r.q[4], r.q[5]],
                        )
                        .attitude()
                    });
                    sink.num(att[a]);
                }
            }
        }
    }
}

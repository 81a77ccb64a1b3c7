//! The one 3D scene, of every 3D model: a robot ([`fbd_robot::RobotModel`]:
//! an imported URDF/MJCF robot, or the hexapod built from its D-H
//! parameters, [`super::hexapod`]), every body drawn as capsules from joint
//! to joint, computed frame by frame with `fbd_robot`'s forward kinematics;
//! the contact points coloured by state (ST1/ST2/ST3) with their ground
//! forces as arrows, the whole robot's centre of mass; panels of the base
//! and centre-of-mass heights, the joint angles and, with contacts, the
//! vertical ground forces. What a model adds to that drawing is data of
//! the scene ([`Decor`], all optional): points fixed in bodies, the root's
//! outline, labels beside points, a heading arrow, the feet's trails and
//! support polygon, joint-force arrows, the names of the contact points in
//! events and of their states, the limbs' colours and its own panels.
//!
//! The drawn points ([`Scene::points`]), in this order:
//!
//! * `base`: the root's origin, `(rx, ry, rz)` of `trajectory.csv`;
//! * one per joint, named by the joint: its origin (the child body's
//!   origin), inertial;
//! * one per contact point, named by the point: the sphere's centre;
//! * one per point fixed in a body ([`Decor::fixed`]), named by it;
//! * `<body>_com`: the centre of mass of each leaf body (no child joint)
//!   without contact or fixed points, when it is off the body's origin.
//!
//! The capsules ([`Scene::lines`], one colour per limb, the root's grey):
//!
//! * the root, with an outline ([`Decor::outline`]): a ring through its
//!   points; else, with three or more child joints: a ring through their
//!   origins in the order of their angle about the root's `+y` axis (a
//!   hexapod's body outline); either ring is filled with a translucent
//!   plate fanned from `base` ([`RobotScene::plate`]); with fewer, from
//!   `base` to each child joint's origin (a star); and, without an outline,
//!   from `base` to each of its own contact points;
//! * every other body: from its joint's origin to each child joint's
//!   origin; a leaf body from its joint's origin to each of its contact and
//!   fixed points, or to its centre of mass when it has none;
//! * segments of zero length (a massless frame between two joints at one
//!   point) are left out: a segment's ends are fixed in one body, so its
//!   length never changes.
//!
//! The capsules' radius ([`RobotScene::radius`]) is 2 % of the robot's
//! size, the largest side of the box around its drawn points at the zero
//! pose (1 cm for a robot of no size). Points are written to 1 µm (a
//! thousandth of a pixel of a metre-sized robot on a screen; the test
//! compares them with forward kinematics to 1e-6 m), forces to 1e-6 N.
//!
//! Use: [`RobotFrames::new`] (or [`RobotFrames::with_decor`]),
//! [`RobotFrames::push`] (or [`RobotFrames::push_row`]) for every row of
//! `trajectory.csv`, then [`RobotFrames::write`]. The rows are kept until
//! then (8 bytes per coordinate, contact state and force value, e.g.
//! 0.4 MB per 1000 rows of an 18-joint robot with 6 contact points), since
//! the decimation ([`super::Decimator`]) needs their count: every k-th
//! row, the last one, and the rows at which a contact state changes; a run
//! that knows its count at the start ([`RobotFrames::with_rows_planned`])
//! keeps only the frames (at most [`super::MAX_FRAMES`] rows).
//!
//! `fbd view DIR` ([`super::view`]) pushes the rows of `trajectory.csv`,
//! gives [`RobotFrames::with_surface`] the configuration's terrain when
//! the file has contact columns, and [`RobotFrames::set_event_rows`] the
//! rows of `events.csv`; `fbd run` writes the same page byte for byte when
//! it does the same with the rows it writes (their values read back from
//! the CSV are the same numbers).

use std::path::{Path, PathBuf};

use fbd_contact::Surface;
use fbd_robot::RobotModel;
use fbd_robot::forward::{RobotData, base_frame, forward};
use fbd_robot::nalgebra::{Isometry3, Vector3};
use serde::Serialize;

use super::{
    Curve, Decimator, EventMark, Line, Marker, Panel, Scene, SceneKind, round, round_time,
    surface_view, value,
};
use crate::OutputError;

/// Capsule radius as a share of the robot's size (see the module docs).
pub const RADIUS_SHARE: f64 = 0.02;

/// Segments shorter than this (m) are not drawn.
const MIN_SEGMENT: f64 = 1e-9;

/// A 3D scene: the [`Scene`] and what only a 3D robot has.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RobotScene {
    /// Points, capsules ([`Scene::lines`]), contacts, frames, panels.
    #[serde(flatten)]
    pub scene: Scene,
    /// Radius of every capsule (m).
    pub radius: f64,
    /// The root's outline, point indices in order: filled with a
    /// translucent plate fanned from `base` (empty: no plate).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub plate: Vec<usize>,
    /// Labels drawn beside points (a hexapod's leg numbers).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub labels: Vec<LabelView>,
    /// A heading arrow from `base` towards this point.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub heading: Option<usize>,
    /// Names of the contact states 1, 2, … in the legend, when they are
    /// not ST1–ST3 (a kinematic gait: swing, stance).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub state_names: Vec<String>,
}

/// A label drawn beside a point, in the colour of a group.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct LabelView {
    /// Its text.
    pub text: String,
    /// The point (index).
    pub point: usize,
    /// Colour group (as [`Line::group`]).
    pub group: usize,
}

/// A point fixed in a body, drawn beside the robot's own points.
#[derive(Clone, Debug, PartialEq)]
pub struct FixedPoint {
    /// Its name (unique among the drawn points).
    pub name: String,
    /// The body carrying it.
    pub body: usize,
    /// Its position in the body's frame (m).
    pub position: Vector3<f64>,
}

/// A label of the scene ([`Decor::labels`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Label {
    /// Its text.
    pub text: String,
    /// The drawn point it is beside (its name).
    pub point: String,
    /// Colour group.
    pub group: usize,
}

/// A value plotted in a panel, per frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Series {
    /// The root's height `ry` (m).
    BaseHeight,
    /// The centre of mass's height (m).
    ComHeight,
    /// The angle of joint `j` (°).
    Angle(usize),
    /// The vertical ground force on contact point `k` (N).
    GroundFy(usize),
    /// The `k`-th value of the rows ([`Row::values`]); NaN is no value.
    Value(usize),
}

/// A time-series panel of the scene ([`Decor::panels`]).
#[derive(Clone, Debug, PartialEq)]
pub struct PanelPlan {
    /// Title with the unit.
    pub title: String,
    /// Its curves: legend label and series.
    pub curves: Vec<(String, Series)>,
    /// Left out when none of its curves has a value.
    pub optional: bool,
}

/// What a scene adds to the drawing of a robot's model, all optional
/// (the default adds nothing): points fixed in bodies, the root's outline,
/// labels, a heading arrow, the support polygon, joint-force arrows, the
/// contact points' labels and states, the limbs' colours and the panels.
/// Points are named as drawn ([`Scene::points`]); unknown names are
/// ignored.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Decor {
    /// Points fixed in bodies: drawn after the contact points; a leaf body
    /// ends at its contact and fixed points (at its centre of mass only
    /// when it has neither).
    pub fixed: Vec<FixedPoint>,
    /// The root's outline, points fixed in the root in order: a ring of
    /// capsules filled with the plate, instead of the ring through the
    /// root's child joints. The root's contact points are then drawn on
    /// the plate, without capsules from `base`.
    pub outline: Vec<String>,
    /// Labels beside points.
    pub labels: Vec<Label>,
    /// The point the heading arrow from `base` points to.
    pub heading: Option<String>,
    /// The points whose paths are drawn (default every contact point).
    pub trails: Option<Vec<String>>,
    /// Contact points (indices) around the body, in order: the support
    /// polygon of those not in ST1.
    pub ring: Vec<usize>,
    /// Joint-force arrows, each at a joint's origin: name and joint index;
    /// every row gives one force for each ([`Row::joint_forces`]).
    pub joint_forces: Vec<(String, usize)>,
    /// Each contact point's name in event labels (default its name).
    pub contact_labels: Vec<String>,
    /// A kinematic gait: the rows' contact states are swing (1) and stance
    /// (2), without forces.
    pub kinematic: bool,
    /// Colour group of each of the root's child joints, in order (default
    /// 1, 2, …): the group of its limb.
    pub limb_groups: Vec<usize>,
    /// The panels (default: the base's and the centre of mass's heights,
    /// the joint angles and, with forces, the vertical ground forces).
    pub panels: Option<Vec<PanelPlan>>,
    /// How many values every row gives ([`Row::values`], [`Series::Value`]).
    pub values: usize,
}

/// One row of a run, for [`RobotFrames::push_row`].
#[derive(Clone, Copy, Debug, Default)]
pub struct Row<'a> {
    /// Time (s).
    pub t: f64,
    /// `(rx, ry, rz, φx, φy, φz, θ…)` (m, rad; the joints in the model's
    /// order).
    pub q: &'a [f64],
    /// With contacts: each contact point's state code (1, 2, 3 for
    /// ST1–ST3) and the ground's force on it (N, inertial); `None` is ST1
    /// without force.
    pub contacts: Option<(&'a [u8], &'a [[f64; 3]])>,
    /// The force of each joint-force arrow ([`Decor::joint_forces`]), N,
    /// inertial; empty: none drawn.
    pub joint_forces: &'a [[f64; 3]],
    /// The centre of mass (m), when the run gives it (default: the
    /// model's, by forward kinematics).
    pub com: Option<[f64; 3]>,
    /// [`Decor::values`] values for the panels (empty: none).
    pub values: &'a [f64],
}

/// Where a drawn point is, at each frame.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Source {
    /// The root's origin.
    Base,
    /// The origin of a body's frame (its joint's origin).
    Origin(usize),
    /// A contact point.
    Contact(usize),
    /// A body's centre of mass.
    Com(usize),
    /// A point fixed in a body ([`Decor::fixed`]).
    Fixed(usize),
}

/// Builds a robot's scene from its rows (see the module docs).
#[derive(Clone, Debug)]
pub struct RobotFrames {
    model: RobotModel,
    contacts: bool,
    decor: Decor,
    title: String,
    surface: Option<Surface>,
    event_rows: Option<usize>,
    points: Vec<String>,
    sources: Vec<Source>,
    lines: Vec<Line>,
    plate: Vec<usize>,
    radius: f64,
    /// `t` of every row pushed.
    t: Vec<f64>,
    /// `6 + joints` coordinates per row.
    q: Vec<f64>,
    /// One state code per contact per row (with contacts).
    state: Vec<u8>,
    /// Three force components per contact per row (with contacts).
    force: Vec<f64>,
    /// Three components per joint-force arrow per row.
    joint_force: Vec<f64>,
    /// The centre of mass of each row (NaN: the model's).
    com: Vec<[f64; 3]>,
    /// [`Decor::values`] per row.
    values: Vec<f64>,
    /// The run's row of each row kept.
    index: Vec<usize>,
    /// Rows pushed.
    seen: usize,
    /// Decimation while the rows come ([`RobotFrames::with_rows_planned`]).
    stream: Option<Stream>,
    /// The first malformed row, reported by [`RobotFrames::write`].
    error: Option<String>,
}

/// The decimation of a run whose row count is known at its start: rows
/// that are not frames are dropped as they come (the last one pushed is
/// kept until the next, to end the run).
#[derive(Clone, Debug)]
struct Stream {
    decimator: Decimator,
    planned: usize,
    last_state: Option<String>,
    /// Whether the last row kept is not a frame.
    pending: bool,
}

impl RobotFrames {
    /// A builder for `model`'s rows; `contacts` when the rows carry each
    /// contact point's state and ground force (a run on a terrain), false
    /// in flight (the points are then drawn ST1, without arrows).
    pub fn new(model: &RobotModel, contacts: bool) -> Self {
        Self::with_decor(model, contacts, Decor::default())
    }

    /// [`RobotFrames::new`] with what `decor` adds to the drawing.
    pub fn with_decor(model: &RobotModel, contacts: bool, decor: Decor) -> Self {
        let nb = model.bodies.len();
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); nb];
        for (j, joint) in model.joints.iter().enumerate() {
            if joint.parent < nb && joint.child < nb {
                children[joint.parent].push(j);
            }
        }
        let mut on_body: Vec<Vec<usize>> = vec![Vec::new(); nb];
        for (k, c) in model.contacts.iter().enumerate() {
            if c.body < nb {
                on_body[c.body].push(k);
            }
        }
        let mut fixed_on: Vec<Vec<usize>> = vec![Vec::new(); nb];
        for (k, f) in decor.fixed.iter().enumerate() {
            if f.body < nb {
                fixed_on[f.body].push(k);
            }
        }
        // The limb of each body: the group of the root's child joint above
        // it (bodies come parents first); the root's is 0.
        let mut limb = vec![0usize; nb];
        for (j, joint) in model.joints.iter().enumerate() {
            if joint.child >= nb || joint.parent >= nb {
                continue;
            }
            limb[joint.child] = if joint.parent == 0 {
                let k = children[0].iter().position(|&c| c == j).unwrap_or(0);
                decor.limb_groups.get(k).copied().unwrap_or(1 + k)
            } else {
                limb[joint.parent]
            };
        }
        let mut points = vec!["base".to_owned()];
        let mut sources = vec![Source::Base];
        // Point of body `b`'s origin: `base` for the root, else its joint's.
        let origin_point = |b: usize| model.bodies[b].joint.map_or(0, |j| 1 + j);
        for joint in &model.joints {
            points.push(joint.name.clone());
            sources.push(Source::Origin(joint.child.min(nb.saturating_sub(1))));
        }
        let contact_point = |k: usize| 1 + model.joints.len() + k;
        for (k, c) in model.contacts.iter().enumerate() {
            points.push(c.name.clone());
            sources.push(Source::Contact(k));
        }
        let fixed_point = |k: usize| 1 + model.joints.len() + model.contacts.len() + k;
        for (k, f) in decor.fixed.iter().enumerate() {
            points.push(f.name.clone());
            sources.push(Source::Fixed(k));
        }
        let index = |points: &[String], name: &str| points.iter().position(|p| p == name);
        // The root's outline: the decor's, or its child joints' origins by
        // angle about its +y axis when it has three or more.
        let outline: Vec<usize> = decor
            .outline
            .iter()
            .filter_map(|n| index(&points, n))
            .collect();
        let mut lines = Vec::new();
        let mut segment = |a: usize, b: usize, length: f64, group: usize| {
            if length >= MIN_SEGMENT {
                lines.push(Line { a, b, group });
            }
        };
        let ring = outline.len() >= 3 || children.first().is_some_and(|c| c.len() >= 3);
        for b in 0..nb {
            let from = origin_point(b);
            let group = limb[b];
            for &j in children[b].iter().filter(|_| b != 0 || !ring) {
                segment(
                    from,
                    1 + j,
                    model.joints[j].origin.translation.vector.norm(),
                    group,
                );
            }
            let leaf = children[b].is_empty();
            if (b == 0 && outline.len() < 3) || (b != 0 && leaf) {
                for &k in &on_body[b] {
                    segment(
                        from,
                        contact_point(k),
                        model.contacts[k].position.norm(),
                        group,
                    );
                }
            }
            if b != 0 && leaf {
                for &k in &fixed_on[b] {
                    segment(from, fixed_point(k), decor.fixed[k].position.norm(), group);
                }
            }
            if leaf && on_body[b].is_empty() && fixed_on[b].is_empty() {
                let com = model.bodies[b].com;
                if com.norm() >= MIN_SEGMENT {
                    points.push(format!("{}_com", model.bodies[b].name));
                    sources.push(Source::Com(b));
                    segment(from, points.len() - 1, com.norm(), group);
                }
            }
        }
        let mut plate = Vec::new();
        if outline.len() >= 3 {
            let at = |i: usize| match sources[i] {
                Source::Fixed(k) => decor.fixed[k].position,
                Source::Origin(b) => model.bodies[b].joint.map_or(Vector3::zeros(), |j| {
                    model.joints[j].origin.translation.vector
                }),
                Source::Contact(k) => model.contacts[k].position,
                _ => Vector3::zeros(),
            };
            for k in 0..outline.len() {
                let (a, b) = (outline[k], outline[(k + 1) % outline.len()]);
                segment(a, b, (at(a) - at(b)).norm(), 0);
            }
            plate = outline;
        } else if ring {
            // The ring through the root's child joints, by angle about its
            // +y axis.
            let mut ring: Vec<(f64, usize)> = children[0]
                .iter()
                .map(|&j| {
                    let o = model.joints[j].origin.translation.vector;
                    (o.z.atan2(o.x), j)
                })
                .collect();
            ring.sort_by(|a, b| a.0.total_cmp(&b.0));
            for k in 0..ring.len() {
                let (a, b) = (ring[k].1, ring[(k + 1) % ring.len()].1);
                let d = model.joints[a].origin.translation.vector
                    - model.joints[b].origin.translation.vector;
                segment(1 + a, 1 + b, d.norm(), 0);
            }
            plate = ring.iter().map(|&(_, j)| 1 + j).collect();
        }
        let mut me = Self {
            model: model.clone(),
            contacts,
            decor,
            title: super::title_of("", &format!("robot {}", model.name)),
            surface: None,
            event_rows: None,
            points,
            sources,
            lines,
            plate,
            radius: 0.01,
            t: Vec::new(),
            q: Vec::new(),
            state: Vec::new(),
            force: Vec::new(),
            joint_force: Vec::new(),
            com: Vec::new(),
            values: Vec::new(),
            index: Vec::new(),
            seen: 0,
            stream: None,
            error: None,
        };
        // The radius: a share of the size at the zero pose.
        let mut data = RobotData::new(&me.model);
        let zero = vec![0.0; me.model.joints.len()];
        forward(&me.model, &Isometry3::identity(), &zero, &mut data);
        let (mut lo, mut hi) = (
            Vector3::repeat(f64::INFINITY),
            Vector3::repeat(f64::NEG_INFINITY),
        );
        for s in &me.sources {
            let p = me.position(&data, *s);
            lo = lo.inf(&p);
            hi = hi.sup(&p);
        }
        let size = (hi - lo).max();
        if size.is_finite() && size > 0.0 {
            me.radius = round(RADIUS_SHARE * size);
        }
        me
    }

    /// The ground drawn under the robot (none unless given; `fbd view`
    /// gives the configuration's `[terrain]` unless its kind is `"none"`).
    pub fn with_surface(mut self, surface: Surface) -> Self {
        self.surface = Some(surface);
        self
    }

    /// The title of the page (default `robot <name>`).
    pub fn with_title(mut self, title: &str) -> Self {
        title.clone_into(&mut self.title);
        self
    }

    /// The rows of the run's `events.csv`, counted in the page's header
    /// (default: the contact changes among the frames).
    pub fn set_event_rows(&mut self, rows: usize) {
        self.event_rows = Some(rows);
    }

    /// Decimates the rows as they come, for a run of `rows` rows: keeps
    /// only the frames ([`super::Decimator`]: every k-th row, the rows at
    /// which a contact state changes, the last one pushed) instead of every
    /// row until [`RobotFrames::finish`]. The page is the same when the run
    /// pushes `rows` rows.
    pub fn with_rows_planned(mut self, rows: usize) -> Self {
        self.stream = Some(Stream {
            decimator: Decimator::new(rows),
            planned: rows,
            last_state: None,
            pending: false,
        });
        self
    }

    /// Rows pushed so far.
    pub fn rows(&self) -> usize {
        self.seen
    }

    /// The capsules' radius (m).
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// The names of the drawn points, in order.
    pub fn points(&self) -> &[String] {
        &self.points
    }

    /// Adds the row at time `t`: `q = (rx, ry, rz, φx, φy, φz, θ…)` (m,
    /// rad; the joints in the model's order) and, with contacts, each
    /// contact point's state code (1, 2, 3 for ST1–ST3) and the ground's
    /// force on it (N, inertial). A row of the wrong size is reported by
    /// [`RobotFrames::write`]; without contacts, `contacts` is ignored.
    pub fn push(&mut self, t: f64, q: &[f64], contacts: Option<(&[u8], &[[f64; 3]])>) {
        self.push_row(&Row {
            t,
            q,
            contacts,
            ..Row::default()
        });
    }

    /// Adds a row with everything it may carry ([`Row`]).
    pub fn push_row(&mut self, row: &Row) {
        let nq = 6 + self.model.joints.len();
        let nc = self.model.contacts.len();
        let (nf, nv) = (self.decor.joint_forces.len(), self.decor.values);
        if self.error.is_some() {
            return;
        }
        let r = self.seen;
        if row.q.len() != nq {
            self.error = Some(format!(
                "viewer.html: row {r}: {} coordinates for a robot of {nq}",
                row.q.len()
            ));
            return;
        }
        if !row.joint_forces.is_empty() && row.joint_forces.len() != nf {
            self.error = Some(format!(
                "viewer.html: row {r}: {} joint forces for {nf} arrows",
                row.joint_forces.len()
            ));
            return;
        }
        if !row.values.is_empty() && row.values.len() != nv {
            self.error = Some(format!(
                "viewer.html: row {r}: {} values for {nv}",
                row.values.len()
            ));
            return;
        }
        let contacts = match row.contacts {
            Some((state, force)) if self.contacts && (state.len() != nc || force.len() != nc) => {
                self.error = Some(format!(
                    "viewer.html: row {r}: {} contact states and {} forces for {nc} contact points",
                    state.len(),
                    force.len()
                ));
                return;
            }
            c if self.contacts => c,
            _ => None,
        };
        if let Some(stream) = self.stream.as_mut() {
            // The row before, when it is not a frame, is dropped.
            if stream.pending {
                let n = self.t.len() - 1;
                self.t.truncate(n);
                self.index.truncate(n);
                self.q.truncate(n * nq);
                self.state.truncate(n * if self.contacts { nc } else { 0 });
                self.force
                    .truncate(3 * n * if self.contacts { nc } else { 0 });
                self.joint_force.truncate(3 * n * nf);
                self.com.truncate(n);
                self.values.truncate(n * nv);
            }
            let state: String = match contacts {
                Some((state, _)) => state.iter().map(|&s| char::from(b'0' + code(s))).collect(),
                None => "1".repeat(nc),
            };
            let changed = stream.last_state.as_ref().is_some_and(|s| *s != state);
            stream.last_state = Some(state);
            stream.pending = !stream.decimator.keep(r, changed, r + 1 >= stream.planned);
        }
        if self.contacts {
            match contacts {
                Some((state, force)) => {
                    self.state.extend(state.iter().map(|&s| code(s)));
                    self.force.extend(force.iter().flatten());
                }
                None => {
                    self.state.extend(std::iter::repeat_n(1, nc));
                    self.force.extend(std::iter::repeat_n(0.0, 3 * nc));
                }
            }
        }
        self.seen += 1;
        self.index.push(r);
        self.t.push(row.t);
        self.q.extend_from_slice(row.q);
        if row.joint_forces.is_empty() {
            self.joint_force.extend(std::iter::repeat_n(0.0, 3 * nf));
        } else {
            self.joint_force.extend(row.joint_forces.iter().flatten());
        }
        self.com.push(row.com.unwrap_or([f64::NAN; 3]));
        if row.values.is_empty() {
            self.values.extend(std::iter::repeat_n(f64::NAN, nv));
        } else {
            self.values.extend_from_slice(row.values);
        }
    }

    /// Where point source `s` is in `data`.
    fn position(&self, data: &RobotData, s: Source) -> Vector3<f64> {
        match s {
            Source::Base => data.frames[0].translation.vector,
            Source::Origin(b) => data.frames[b].translation.vector,
            Source::Contact(k) => data.contacts[k],
            Source::Com(b) => data.com(&self.model, b),
            Source::Fixed(k) => {
                let f = &self.decor.fixed[k];
                (data.frames[f.body] * fbd_robot::nalgebra::Point3::from(f.position)).coords
            }
        }
    }

    /// The state digits of row `r`.
    fn states(&self, r: usize) -> String {
        let nc = self.model.contacts.len();
        if self.contacts {
            self.state[r * nc..(r + 1) * nc]
                .iter()
                .map(|&s| char::from(b'0' + s))
                .collect()
        } else {
            "1".repeat(nc)
        }
    }

    /// Index of the drawn point `name`.
    fn point(&self, name: &str) -> Option<usize> {
        self.points.iter().position(|p| p == name)
    }

    /// The panels drawn: the decor's, or the default ones.
    fn panel_plan(&self) -> Vec<PanelPlan> {
        if let Some(p) = &self.decor.panels {
            return p.clone();
        }
        let mut plan = vec![
            PanelPlan {
                title: "Heights (m)".into(),
                curves: vec![
                    ("base Ry".into(), Series::BaseHeight),
                    ("centre of mass".into(), Series::ComHeight),
                ],
                optional: false,
            },
            PanelPlan {
                title: "Joint angles (°)".into(),
                curves: (self.model.joints.iter().enumerate())
                    .map(|(j, joint)| (joint.name.clone(), Series::Angle(j)))
                    .collect(),
                optional: false,
            },
        ];
        if self.forces() && !self.model.contacts.is_empty() {
            plan.push(PanelPlan {
                title: "Vertical ground forces Fy (N)".into(),
                curves: (self.model.contacts.iter().enumerate())
                    .map(|(k, c)| (c.name.clone(), Series::GroundFy(k)))
                    .collect(),
                optional: false,
            });
        }
        plan
    }

    /// Whether the rows carry contact forces.
    fn forces(&self) -> bool {
        self.contacts && !self.decor.kinematic
    }

    /// The complete scene, the rows decimated to at most
    /// [`super::MAX_FRAMES`] frames; an error for a malformed row.
    pub fn finish(self) -> Result<RobotScene, OutputError> {
        if let Some(e) = &self.error {
            return Err(OutputError::Simulation(e.clone()));
        }
        let (nj, nc) = (self.model.joints.len(), self.model.contacts.len());
        let nq = 6 + nj;
        let (nf, nv) = (self.decor.joint_forces.len(), self.decor.values);
        let rows = self.seen;
        let stored = self.t.len();
        let forces = self.forces();
        let names = |names: &[String]| -> Vec<usize> {
            names.iter().filter_map(|n| self.point(n)).collect()
        };
        let trails = match &self.decor.trails {
            Some(t) => names(t),
            None => (0..nc).map(|k| 1 + nj + k).collect(),
        };
        let joints: Vec<Marker> = self
            .decor
            .joint_forces
            .iter()
            .map(|(name, j)| Marker {
                name: name.clone(),
                point: 1 + j,
            })
            .collect();
        let mut scene = Scene {
            model: SceneKind::Robot,
            title: self.title.clone(),
            points: self.points.clone(),
            lines: self.lines.clone(),
            contacts: self
                .model
                .contacts
                .iter()
                .enumerate()
                .map(|(k, c)| Marker {
                    name: c.name.clone(),
                    point: 1 + nj + k,
                })
                .collect(),
            joints,
            trails,
            ring: self
                .decor
                .ring
                .iter()
                .copied()
                .filter(|&k| k < nc)
                .collect(),
            dynamic: forces,
            rows,
            ..Scene::default()
        };
        let plan = self.panel_plan();
        let mut series: Vec<Vec<Vec<Option<f64>>>> = plan
            .iter()
            .map(|p| vec![Vec::new(); p.curves.len()])
            .collect();
        let mut data = RobotData::new(&self.model);
        // Every row kept (decimated as they came) or every k-th row, the
        // rows at which a state changes and the last row.
        let mut decimator = Decimator::new(stored);
        let mut last_state: Option<String> = None;
        for r in 0..stored {
            let state = self.states(r);
            let changed = last_state.as_ref().is_some_and(|s| *s != state);
            let keep = self.stream.is_some() || decimator.keep(r, changed, r + 1 == stored);
            last_state = Some(state);
            if !keep {
                continue;
            }
            let q = &self.q[r * nq..(r + 1) * nq];
            let base = base_frame([q[0], q[1], q[2]], [q[3], q[4], q[5]]);
            forward(&self.model, &base, &q[6..], &mut data);
            let mut p = Vec::with_capacity(3 * self.sources.len());
            for &s in &self.sources {
                p.extend(self.position(&data, s).iter().map(|&x| fine(x)));
            }
            scene.row.push(self.index[r]);
            scene.t.push(round_time(self.t[r]));
            scene.p.push(p);
            scene.state.push(last_state.clone().unwrap_or_default());
            let contact_forces = if self.contacts {
                &self.force[3 * nc * r..3 * nc * (r + 1)]
            } else {
                &[][..]
            };
            scene.fc.push(if forces {
                contact_forces.iter().map(|&f| round(f)).collect()
            } else {
                vec![0.0; 3 * nc]
            });
            scene.fj.push(
                self.joint_force[3 * nf * r..3 * nf * (r + 1)]
                    .iter()
                    .map(|&f| round(f))
                    .collect(),
            );
            let com = if self.com[r].iter().all(|c| c.is_finite()) {
                Vector3::from(self.com[r])
            } else {
                data.total_com(&self.model)
            };
            scene.com.push([com.x, com.y, com.z].map(fine));
            let values = &self.values[nv * r..nv * (r + 1)];
            for (p, out) in plan.iter().zip(series.iter_mut()) {
                for ((_, s), v) in p.curves.iter().zip(out.iter_mut()) {
                    v.push(match *s {
                        Series::BaseHeight => value(q[1]),
                        Series::ComHeight => value(com.y),
                        Series::Angle(j) => q.get(6 + j).and_then(|a| value(a.to_degrees())),
                        Series::GroundFy(k) if forces => {
                            contact_forces.get(3 * k + 1).and_then(|&f| value(f))
                        }
                        Series::GroundFy(_) => None,
                        Series::Value(k) => values.get(k).and_then(|&x| value(x)),
                    });
                }
            }
        }
        // Contact events between consecutive frames.
        let state_name = |s: Option<&u8>| match s {
            Some(&s) => match self
                .decor
                .state_names()
                .get(usize::from(s.wrapping_sub(b'1')))
            {
                Some(name) => (*name).to_owned(),
                None => format!("ST{}", char::from(s)),
            },
            None => "ST?".to_owned(),
        };
        for k in 1..scene.state.len() {
            let (a, b) = (scene.state[k - 1].as_bytes(), scene.state[k].as_bytes());
            for (c, point) in self.model.contacts.iter().enumerate() {
                if a.get(c) != b.get(c) {
                    let what = self.decor.contact_labels.get(c).unwrap_or(&point.name);
                    scene.events.push(EventMark {
                        t: scene.t[k],
                        frame: k,
                        label: format!("{what} {}→{}", state_name(a.get(c)), state_name(b.get(c))),
                    });
                }
            }
        }
        scene.event_rows = self.event_rows.unwrap_or(scene.events.len());
        if let Some(surface) = &self.surface {
            scene.terrain = surface_view(surface, &scene.p);
            scene.patches = super::patch_views(surface.patches());
        }
        for (p, curves) in plan.iter().zip(series) {
            if p.optional && curves.iter().flatten().all(Option::is_none) {
                continue;
            }
            scene.panels.push(Panel {
                title: p.title.clone(),
                curves: p
                    .curves
                    .iter()
                    .zip(curves)
                    .map(|((label, _), v)| Curve {
                        label: label.clone(),
                        v,
                    })
                    .collect(),
            });
        }
        let labels = self
            .decor
            .labels
            .iter()
            .filter_map(|l| {
                Some(LabelView {
                    text: l.text.clone(),
                    point: self.point(&l.point)?,
                    group: l.group,
                })
            })
            .collect();
        Ok(RobotScene {
            scene,
            radius: self.radius,
            plate: self.plate.clone(),
            labels,
            heading: self.decor.heading.as_deref().and_then(|h| self.point(h)),
            state_names: self
                .decor
                .state_names()
                .iter()
                .map(|s| (*s).to_owned())
                .collect(),
        })
    }

    /// Writes `out_dir/viewer.html` all-or-nothing; returns its path.
    pub fn write(self, out_dir: &Path) -> Result<PathBuf, OutputError> {
        let scene = self.finish()?;
        let page = super::render_json(&scene, &scene.scene.title)?;
        crate::output::write_file(out_dir, "viewer.html", page.as_bytes())
    }
}

impl Decor {
    /// The names of the contact states when they are not ST1–ST3.
    fn state_names(&self) -> &'static [&'static str] {
        if self.kinematic {
            &["swing", "stance"]
        } else {
            &[]
        }
    }
}

/// A contact state code 1, 2 or 3 (ST1 for any other).
fn code(s: u8) -> u8 {
    if (1..=3).contains(&s) { s } else { 1 }
}

/// A coordinate rounded to 1 µm (see the module docs).
fn fine(x: f64) -> f64 {
    round(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fbd_robot::nalgebra::{Matrix3, Translation3, Unit, UnitQuaternion};
    use fbd_robot::{Body, ContactPoint, Joint};

    /// A root with one two-link leg ending in a foot, and a tail link
    /// without contact points.
    fn model() -> RobotModel {
        let body = |name: &str, com: [f64; 3], joint: Option<usize>| Body {
            name: name.into(),
            mass: 1.0,
            com: Vector3::from(com),
            inertia: Matrix3::identity() * 0.01,
            joint,
        };
        let joint = |name: &str, parent, child, at: [f64; 3]| Joint {
            name: name.into(),
            parent,
            child,
            origin: Isometry3::from_parts(
                Translation3::from(Vector3::from(at)),
                UnitQuaternion::identity(),
            ),
            axis: Unit::new_normalize(Vector3::x()),
            limits: None,
            effort: None,
            velocity: None,
        };
        RobotModel {
            name: "test".into(),
            bodies: vec![
                body("trunk", [0.0; 3], None),
                body("thigh", [0.0, -0.1, 0.0], Some(0)),
                body("shank", [0.0, -0.1, 0.0], Some(1)),
                body("tail", [0.0, 0.0, 0.15], Some(2)),
            ],
            joints: vec![
                joint("hip", 0, 1, [0.1, 0.0, 0.0]),
                joint("knee", 1, 2, [0.0, -0.2, 0.0]),
                joint("tail_joint", 0, 3, [0.0, 0.0, 0.2]),
            ],
            contacts: vec![ContactPoint {
                name: "foot".into(),
                body: 2,
                position: Vector3::new(0.0, -0.2, 0.0),
                radius: 0.01,
            }],
            actuators: Vec::new(),
        }
    }

    #[test]
    fn capsules_run_joint_to_joint_and_end_at_feet_and_leaf_coms() {
        let m = model();
        let f = RobotFrames::new(&m, false);
        let names: Vec<&str> = f.points.iter().map(String::as_str).collect();
        assert_eq!(
            names,
            ["base", "hip", "knee", "tail_joint", "foot", "tail_com"]
        );
        let segs: Vec<(usize, usize, usize)> =
            f.lines.iter().map(|l| (l.a, l.b, l.group)).collect();
        // Root star (base–hip, base–tail), thigh (hip–knee), shank
        // (knee–foot), tail (tail joint–tail CoM); two root children: no ring.
        assert_eq!(
            segs,
            [(0, 1, 0), (0, 3, 0), (1, 2, 1), (2, 4, 1), (3, 5, 2)]
        );
        // Size at the zero pose: x 0..0.1, y −0.4..0, z 0..0.35.
        assert!(
            (f.radius() - RADIUS_SHARE * 0.4).abs() < 1e-9,
            "{}",
            f.radius()
        );
    }

    #[test]
    fn frames_follow_forward_kinematics_and_events_mark_state_changes() {
        let m = model();
        let mut f = RobotFrames::new(&m, true);
        let q = [
            0.0,
            0.5,
            0.0,
            0.0,
            0.0,
            0.0,
            0.5 * std::f64::consts::PI,
            0.0,
            0.0,
        ];
        f.push(0.0, &q, Some((&[1], &[[0.0; 3]])));
        f.push(0.001, &q, Some((&[2], &[[0.0, 9.81, 0.0]])));
        let s = f.finish().unwrap().scene;
        assert_eq!(s.model, SceneKind::Robot);
        assert_eq!((s.rows, s.t.len()), (2, 2));
        assert_eq!(s.state, ["1", "2"]);
        assert_eq!(s.events.len(), 1);
        assert_eq!(s.events[0].label, "foot ST1→ST2");
        // The hip turned 90° about x: the leg points along −z... the knee
        // at hip + R_x(90°)·(0, −0.2, 0) = (0.1, 0.5, −0.2).
        let p = &s.p[1];
        let knee = &p[6..9];
        assert!(
            (knee[0] - 0.1).abs() < 1e-9
                && (knee[1] - 0.5).abs() < 1e-9
                && (knee[2] + 0.2).abs() < 1e-9,
            "{knee:?}"
        );
        let foot = &p[12..15];
        assert!((foot[2] + 0.4).abs() < 1e-9, "{foot:?}");
        assert_eq!(s.fc[1], [0.0, 9.81, 0.0]);
    }

    #[test]
    fn rows_decimated_as_they_come_make_the_same_scene() {
        let m = model();
        let rows = 3 * crate::viewer::MAX_FRAMES + 7;
        let mut all = RobotFrames::new(&m, true);
        let mut stream = RobotFrames::new(&m, true).with_rows_planned(rows);
        for r in 0..rows {
            let q = [0.0, 0.5, 0.0, 0.0, 0.0, 0.0, 1e-4 * r as f64, 0.0, 0.0];
            // The foot touches down and lifts off at rows off the grid.
            let state = [if (r / 777) % 2 == 1 { 2 } else { 1 }];
            let force = [[0.0, r as f64, 0.0]];
            for f in [&mut all, &mut stream] {
                f.push(0.001 * r as f64, &q, Some((&state, &force)));
            }
        }
        assert!(stream.t.len() <= crate::viewer::MAX_FRAMES);
        let (a, b) = (all.finish().unwrap(), stream.finish().unwrap());
        assert!(a.scene.row.contains(&777) && a.scene.row.contains(&1554));
        assert_eq!(a, b);
    }

    #[test]
    fn a_row_of_the_wrong_size_is_an_error() {
        let m = model();
        let mut f = RobotFrames::new(&m, false);
        f.push(0.0, &[0.0; 4], None);
        let e = f.finish().unwrap_err().to_string();
        assert!(e.contains("4 coordinates for a robot of 9"), "{e}");
    }
}

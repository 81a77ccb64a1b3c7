//! The scene of an imported robot (URDF/MJCF, [`fbd_robot::RobotModel`]):
//! every body drawn as capsules from joint to joint, computed frame by
//! frame with `fbd_robot`'s forward kinematics; the contact points
//! coloured by state (ST1/ST2/ST3) with their ground forces as arrows, the
//! whole robot's centre of mass; panels of the base and centre-of-mass
//! heights, the joint angles and, with contacts, the vertical ground
//! forces.
//!
//! The drawn points ([`Scene::points`]), in this order:
//!
//! * `base`: the root's origin, `(rx, ry, rz)` of `trajectory.csv`;
//! * one per joint, named by the joint: its origin (the child body's
//!   origin), inertial;
//! * one per contact point, named by the point: the sphere's centre;
//! * `<body>_com`: the centre of mass of each leaf body (no child joint)
//!   without contact points, when it is off the body's origin.
//!
//! The capsules ([`Scene::lines`], one colour per limb, the root's grey):
//!
//! * the root, with three or more child joints: a ring through their
//!   origins in the order of their angle about the root's `+y` axis (a
//!   hexapod's body outline; the page fills it with a translucent plate
//!   fanned from `base`); with fewer, from `base` to each child joint's
//!   origin (a star); and from `base` to each of its own contact points;
//! * every other body: from its joint's origin to each child joint's
//!   origin; a leaf body from its joint's origin to each of its contact
//!   points, or to its centre of mass when it has none;
//! * segments of zero length (a massless frame between two joints at one
//!   point) are left out: a segment's ends are fixed in one body, so its
//!   length never changes.
//!
//! The capsules' radius ([`RobotScene::radius`]) is 2 % of the robot's
//! size, the largest side of the box around its drawn points at the zero
//! pose (1 cm for a robot of no size). Points are written to 1e-10 m (the
//! test compares them with forward kinematics to 1e-9), forces to 1e-6 N.
//!
//! Use: [`RobotFrames::new`], [`RobotFrames::push`] for every row of
//! `trajectory.csv`, then [`RobotFrames::write`]. The rows are kept until
//! then (8 bytes per coordinate, contact state and force value, e.g.
//! 0.4 MB per 1000 rows of an 18-joint robot with 6 contact points), since
//! the decimation ([`super::Decimator`]) needs their count: every k-th
//! row, the last one, and the rows at which a contact state changes.
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

/// A robot's scene: the [`Scene`] and the capsules' radius.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RobotScene {
    /// Points, capsules ([`Scene::lines`]), contacts, frames, panels.
    #[serde(flatten)]
    pub scene: Scene,
    /// Radius of every capsule (m).
    pub radius: f64,
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
}

/// Builds a robot's scene from its rows (see the module docs).
#[derive(Clone, Debug)]
pub struct RobotFrames {
    model: RobotModel,
    contacts: bool,
    title: String,
    surface: Option<Surface>,
    event_rows: Option<usize>,
    points: Vec<String>,
    sources: Vec<Source>,
    lines: Vec<Line>,
    radius: f64,
    /// `t` of every row pushed.
    t: Vec<f64>,
    /// `6 + joints` coordinates per row.
    q: Vec<f64>,
    /// One state code per contact per row (with contacts).
    state: Vec<u8>,
    /// Three force components per contact per row (with contacts).
    force: Vec<f64>,
    /// The first malformed row, reported by [`RobotFrames::write`].
    error: Option<String>,
}

impl RobotFrames {
    /// A builder for `model`'s rows; `contacts` when the rows carry each
    /// contact point's state and ground force (a run on a terrain), false
    /// in flight (the points are then drawn ST1, without arrows).
    pub fn new(model: &RobotModel, contacts: bool) -> Self {
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
        // The limb of each body: 1 + the index of the root's child joint
        // above it (bodies come parents first); the root's is 0.
        let mut limb = vec![0usize; nb];
        for (j, joint) in model.joints.iter().enumerate() {
            if joint.child >= nb || joint.parent >= nb {
                continue;
            }
            limb[joint.child] = if joint.parent == 0 {
                1 + children[0].iter().position(|&c| c == j).unwrap_or(0)
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
        let mut lines = Vec::new();
        let mut segment = |a: usize, b: usize, length: f64, group: usize| {
            if length >= MIN_SEGMENT {
                lines.push(Line { a, b, group });
            }
        };
        let ring = children.first().is_some_and(|c| c.len() >= 3);
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
            if b == 0 || children[b].is_empty() {
                for &k in &on_body[b] {
                    segment(
                        from,
                        contact_point(k),
                        model.contacts[k].position.norm(),
                        group,
                    );
                }
            }
            if children[b].is_empty() && on_body[b].is_empty() {
                let com = model.bodies[b].com;
                if com.norm() >= MIN_SEGMENT {
                    points.push(format!("{}_com", model.bodies[b].name));
                    sources.push(Source::Com(b));
                    segment(from, points.len() - 1, com.norm(), group);
                }
            }
        }
        // The root's ring through its child joints' origins, by angle
        // about its +y axis.
        if ring {
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
        }
        let mut me = Self {
            model: model.clone(),
            contacts,
            title: super::title_of("", &format!("robot {}", model.name)),
            surface: None,
            event_rows: None,
            points,
            sources,
            lines,
            radius: 0.01,
            t: Vec::new(),
            q: Vec::new(),
            state: Vec::new(),
            force: Vec::new(),
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

    /// Rows pushed so far.
    pub fn rows(&self) -> usize {
        self.t.len()
    }

    /// The capsules' radius (m).
    pub fn radius(&self) -> f64 {
        self.radius
    }

    /// Adds the row at time `t`: `q = (rx, ry, rz, φx, φy, φz, θ…)` (m,
    /// rad; the joints in the model's order) and, with contacts, each
    /// contact point's state code (1, 2, 3 for ST1–ST3) and the ground's
    /// force on it (N, inertial). A row of the wrong size is reported by
    /// [`RobotFrames::write`]; without contacts, `contacts` is ignored.
    pub fn push(&mut self, t: f64, q: &[f64], contacts: Option<(&[u8], &[[f64; 3]])>) {
        let nq = 6 + self.model.joints.len();
        let nc = self.model.contacts.len();
        if self.error.is_some() {
            return;
        }
        if q.len() != nq {
            self.error = Some(format!(
                "viewer.html: row {}: {} coordinates for a robot of {nq}",
                self.t.len(),
                q.len()
            ));
            return;
        }
        self.t.push(t);
        self.q.extend_from_slice(q);
        if self.contacts {
            match contacts {
                Some((state, force)) if state.len() == nc && force.len() == nc => {
                    self.state.extend(
                        state
                            .iter()
                            .map(|&s| if (1..=3).contains(&s) { s } else { 1 }),
                    );
                    self.force.extend(force.iter().flatten());
                }
                Some((state, force)) => {
                    self.error = Some(format!(
                        "viewer.html: row {}: {} contact states and {} forces for {nc} contact points",
                        self.t.len() - 1,
                        state.len(),
                        force.len()
                    ));
                }
                None => {
                    self.state.extend(std::iter::repeat_n(1, nc));
                    self.force.extend(std::iter::repeat_n(0.0, 3 * nc));
                }
            }
        }
    }

    /// Where point source `s` is in `data`.
    fn position(&self, data: &RobotData, s: Source) -> Vector3<f64> {
        match s {
            Source::Base => data.frames[0].translation.vector,
            Source::Origin(b) => data.frames[b].translation.vector,
            Source::Contact(k) => data.contacts[k],
            Source::Com(b) => data.com(&self.model, b),
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

    /// The complete scene, the rows decimated to at most
    /// [`super::MAX_FRAMES`] frames; an error for a malformed row.
    pub fn finish(self) -> Result<RobotScene, OutputError> {
        if let Some(e) = &self.error {
            return Err(OutputError::Simulation(e.clone()));
        }
        let (nj, nc) = (self.model.joints.len(), self.model.contacts.len());
        let nq = 6 + nj;
        let rows = self.t.len();
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
            trails: (0..nc).map(|k| 1 + nj + k).collect(),
            dynamic: self.contacts,
            rows,
            ..Scene::default()
        };
        let mut data = RobotData::new(&self.model);
        let mut decimator = Decimator::new(rows);
        let mut height = Vec::new();
        let mut com_y = Vec::new();
        let mut angles: Vec<Vec<Option<f64>>> = vec![Vec::new(); nj];
        let mut fy: Vec<Vec<Option<f64>>> = vec![Vec::new(); if self.contacts { nc } else { 0 }];
        let mut last_state: Option<String> = None;
        for r in 0..rows {
            let state = self.states(r);
            let changed = last_state.as_ref().is_some_and(|s| *s != state);
            let keep = decimator.keep(r, changed, r + 1 == rows);
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
            scene.row.push(r);
            scene.t.push(round_time(self.t[r]));
            scene.p.push(p);
            scene.state.push(last_state.clone().unwrap_or_default());
            let forces = if self.contacts {
                &self.force[3 * nc * r..3 * nc * (r + 1)]
            } else {
                &[][..]
            };
            scene.fc.push(if self.contacts {
                forces.iter().map(|&f| round(f)).collect()
            } else {
                vec![0.0; 3 * nc]
            });
            scene.fj.push(Vec::new());
            let com = data.total_com(&self.model);
            scene.com.push([com.x, com.y, com.z].map(fine));
            height.push(value(q[1]));
            com_y.push(value(com.y));
            for (a, v) in angles.iter_mut().zip(&q[6..]) {
                a.push(value(v.to_degrees()));
            }
            for (k, f) in fy.iter_mut().enumerate() {
                f.push(value(forces[3 * k + 1]));
            }
        }
        // Contact events between consecutive frames.
        for k in 1..scene.state.len() {
            let (a, b) = (scene.state[k - 1].as_bytes(), scene.state[k].as_bytes());
            for (c, point) in self.model.contacts.iter().enumerate() {
                if a.get(c) != b.get(c) {
                    let st = |s: Option<&u8>| format!("ST{}", s.map_or('?', |&s| char::from(s)));
                    scene.events.push(EventMark {
                        t: scene.t[k],
                        frame: k,
                        label: format!("{} {}→{}", point.name, st(a.get(c)), st(b.get(c))),
                    });
                }
            }
        }
        scene.event_rows = self.event_rows.unwrap_or(scene.events.len());
        if let Some(surface) = &self.surface {
            scene.terrain = surface_view(surface, &scene.p);
            scene.patches = super::patch_views(surface.patches());
        }
        scene.panels.push(Panel {
            title: "Heights (m)".into(),
            curves: vec![
                Curve {
                    label: "base Ry".into(),
                    v: height,
                },
                Curve {
                    label: "centre of mass".into(),
                    v: com_y,
                },
            ],
        });
        scene.panels.push(Panel {
            title: "Joint angles (°)".into(),
            curves: self
                .model
                .joints
                .iter()
                .zip(angles)
                .map(|(j, v)| Curve {
                    label: j.name.clone(),
                    v,
                })
                .collect(),
        });
        if self.contacts && nc > 0 {
            scene.panels.push(Panel {
                title: "Vertical ground forces Fy (N)".into(),
                curves: self
                    .model
                    .contacts
                    .iter()
                    .zip(fy)
                    .map(|(c, v)| Curve {
                        label: c.name.clone(),
                        v,
                    })
                    .collect(),
            });
        }
        Ok(RobotScene {
            scene,
            radius: self.radius,
        })
    }

    /// Writes `out_dir/viewer.html` all-or-nothing; returns its path.
    pub fn write(self, out_dir: &Path) -> Result<PathBuf, OutputError> {
        let scene = self.finish()?;
        let page = super::render_json(&scene, &scene.scene.title)?;
        crate::output::write_file(out_dir, "viewer.html", page.as_bytes())
    }
}

/// A coordinate rounded to 1e-10 m (see the module docs).
fn fine(x: f64) -> f64 {
    if x.is_finite() {
        let r = (x * 1e10).round() / 1e10;
        if r == 0.0 { 0.0 } else { r }
    } else {
        0.0
    }
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
    fn a_row_of_the_wrong_size_is_an_error() {
        let m = model();
        let mut f = RobotFrames::new(&m, false);
        f.push(0.0, &[0.0; 4], None);
        let e = f.finish().unwrap_err().to_string();
        assert!(e.contains("4 coordinates for a robot of 9"), "{e}");
    }
}

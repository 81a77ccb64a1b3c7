//! The FBD mechanism of any robot model ([`fbd_robot::RobotModel`])
//! (immutable): its free bodies, joint reactions, contact points and joint
//! stops, and the index layout of one step's unknowns and equations.
//!
//! ## Bodies and reactions
//! Every body of the model is an FBD body, in the model's order, except
//! the massless frame between the two joints of a compound joint
//! ([`RobotModel::compound_joints`]: two axes that meet, the paper's
//! two-axis hip): it carries no equations, and its two joints are **one**
//! reaction between the body before the first joint and the body after the
//! second, at the point where the axes meet, with a force (3 unknowns) and
//! one constraint moment along `u1 × u2` (1 unknown), plus the actuator
//! torques `τ1·u1 + τ2·u2`. Every other revolute joint is a reaction with a
//! force (3) and two constraint moments (2) across its axis `u`, plus
//! `τ·u`: the knee of the spatial hexapod ([`crate::spatial`]).
//!
//! ## Layout
//! Unknowns `[q[k+1] | reactions | contact forces | stop moments]`:
//! `q = (R, φ, θ_0 … θ_{n−1})` ([`super::kin`]); the reactions in the order
//! of their first joint in `model.joints`, each `[F (3) | moments (1 or
//! 2)]`; 3 force components per contact point, in the order the
//! mechanism was built with; one stop moment per joint with a finite limit,
//! in joint order. Equations: 6 per FBD body (3 translation, 3 rotation),
//! 3 per contact point, 1 per stop. For the paper's hexapod built from D-H
//! rows ([`fbd_robot::dh::hexapod`]) with its contact points ordered by
//! [`contacts_by_kind`], this is exactly the layout of
//! [`crate::spatial::SpatialMechanism`].

use crate::assembly::Dims;
use crate::space::{Space, Space3};
use fbd_robot::RobotModel;
use fbd_robot::nalgebra::Matrix3;

use super::kin::BASE_DOF;

/// One FBD body: a body of the model with its equations.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeBody {
    /// The model body's name.
    pub name: String,
    /// Its index in `model.bodies`.
    pub model_body: usize,
    /// Mass (kg).
    pub mass: f64,
    /// Inertia about the centre of mass in the body's frame (kg·m²).
    pub inertia: Matrix3<f64>,
}

/// One joint reaction: a revolute joint, or the two joints of a compound
/// joint.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TreeReaction {
    /// The model joints, `[first, second]`; `joints[1] == joints[0]` for a
    /// single joint.
    pub joints: [usize; 2],
    /// Whether it is a compound joint (two joints, one constraint moment).
    pub compound: bool,
    /// The FBD body the reaction acts on with `+` (after the last joint).
    pub child: usize,
    /// The FBD body it acts on with `−` (before the first joint).
    pub parent: usize,
    /// Offset of its first unknown from the first reaction column.
    pub offset: usize,
}

impl TreeReaction {
    /// The model joints (one or two).
    pub fn joint_list(&self) -> &[usize] {
        if self.compound {
            &self.joints
        } else {
            &self.joints[..1]
        }
    }
    /// Constraint moments: 1 for a compound joint, 2 otherwise.
    pub fn moments(&self) -> usize {
        if self.compound { 1 } else { 2 }
    }
    /// Unknowns: 3 force components and the constraint moments.
    pub fn unknowns(&self) -> usize {
        3 + self.moments()
    }
}

/// One contact point of the mechanism.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeContact {
    /// The model contact's name.
    pub name: String,
    /// Its index in `model.contacts`.
    pub model_contact: usize,
    /// The FBD body it is on.
    pub body: usize,
}

/// A joint stop: a joint with a finite lower or upper limit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TreeLimit {
    /// The model joint.
    pub joint: usize,
    /// Its angle's index in `q`.
    pub q_index: usize,
    /// The reaction the joint belongs to.
    pub reaction: usize,
    /// `[lower, upper]` (rad, ±∞ where open).
    pub range: [f64; 2],
}

/// The FBD mechanism of a robot model (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct TreeMechanism {
    /// The robot model (its kinematics: [`super::kin::TreeKin`]).
    pub model: RobotModel,
    /// The FBD bodies, in model order.
    pub bodies: Vec<TreeBody>,
    /// For every model body, its FBD body (`None` for the massless frame
    /// inside a compound joint).
    pub body_of: Vec<Option<usize>>,
    /// The joint reactions, in the order of their first joint.
    pub reactions: Vec<TreeReaction>,
    /// For every model joint, the reaction it belongs to.
    pub reaction_of: Vec<usize>,
    /// The contact points, in the order of their unknowns.
    pub contacts: Vec<TreeContact>,
    /// The joint stops, in joint order.
    pub limits: Vec<TreeLimit>,
    /// Gravitational acceleration (m/s², along −Y).
    pub gravity: f64,
    reaction_unknowns: usize,
    length_scale: f64,
}

/// The model's contact points grouped by kind: points named
/// `<stem><digits>` (`tip3`, `knee3`) by stem, the stems in the order they
/// first appear, each group in model order. For the D-H hexapod (points
/// `tip{n}`, `knee{n}`, `hip{n}` leg by leg) that is every tip, then every
/// knee, then every hip: the order of [`crate::spatial::SpatialMechanism`].
pub fn contacts_by_kind(model: &RobotModel) -> Vec<usize> {
    let stem = |name: &str| {
        name.trim_end_matches(|c: char| c.is_ascii_digit())
            .to_owned()
    };
    let mut stems: Vec<String> = Vec::new();
    for c in &model.contacts {
        let s = stem(&c.name);
        if !stems.contains(&s) {
            stems.push(s);
        }
    }
    let mut out = Vec::with_capacity(model.contacts.len());
    for s in &stems {
        out.extend((0..model.contacts.len()).filter(|&c| stem(&model.contacts[c].name) == *s));
    }
    out
}

impl TreeMechanism {
    /// The mechanism of `model` with every contact point, in model order.
    pub fn new(model: &RobotModel, gravity: f64) -> Self {
        let all: Vec<usize> = (0..model.contacts.len()).collect();
        Self::with_contacts(model, gravity, &all)
    }

    /// The mechanism of `model` with the contact points `contacts`
    /// (indices into `model.contacts`, in the order of their unknowns;
    /// e.g. [`contacts_by_kind`]).
    ///
    /// # Panics
    /// On a contact index out of range or repeated, or a model that
    /// breaks the conventions of [`fbd_robot::model`] (see
    /// [`super::kin::TreeKin::new`]).
    pub fn with_contacts(model: &RobotModel, gravity: f64, contacts: &[usize]) -> Self {
        let nb = model.bodies.len();
        let nj = model.joints.len();
        // Compound pairs, each joint in at most one (a chain of massless
        // frames pairs greedily from the root).
        let mut second_of = vec![None; nj];
        let mut in_pair = vec![false; nj];
        let mut inner = vec![false; nb];
        for (a, b) in model.compound_joints() {
            if in_pair[a] || in_pair[b] {
                continue;
            }
            in_pair[a] = true;
            in_pair[b] = true;
            second_of[a] = Some(b);
            inner[model.joints[a].child] = true;
        }
        let mut bodies = Vec::new();
        let mut body_of = vec![None; nb];
        for (b, body) in model.bodies.iter().enumerate() {
            if inner[b] {
                continue;
            }
            body_of[b] = Some(bodies.len());
            bodies.push(TreeBody {
                name: body.name.clone(),
                model_body: b,
                mass: body.mass,
                inertia: body.inertia,
            });
        }
        let mut reactions: Vec<TreeReaction> = Vec::new();
        let mut reaction_of = vec![usize::MAX; nj];
        let mut offset = 0;
        for (j, joint) in model.joints.iter().enumerate() {
            if reaction_of[j] != usize::MAX {
                continue;
            }
            let last = second_of[j].unwrap_or(j);
            let fbd = |b: usize| body_of[b].expect("a reaction joins two FBD bodies");
            let re = TreeReaction {
                joints: [j, last],
                compound: last != j,
                child: fbd(model.joints[last].child),
                parent: fbd(joint.parent),
                offset,
            };
            offset += re.unknowns();
            reaction_of[j] = reactions.len();
            reaction_of[last] = reactions.len();
            reactions.push(re);
        }
        let mut seen = vec![false; model.contacts.len()];
        let contacts = contacts
            .iter()
            .map(|&c| {
                assert!(!seen[c], "contact {c} given twice");
                seen[c] = true;
                let p = &model.contacts[c];
                TreeContact {
                    name: p.name.clone(),
                    model_contact: c,
                    body: body_of[p.body].expect("a contact point is on an FBD body"),
                }
            })
            .collect();
        let limits = model
            .joints
            .iter()
            .enumerate()
            .filter_map(|(j, joint)| {
                let l = joint.limits?;
                (l.lower.is_finite() || l.upper.is_finite()).then_some(TreeLimit {
                    joint: j,
                    q_index: BASE_DOF + j,
                    reaction: reaction_of[j],
                    range: [l.lower, l.upper],
                })
            })
            .collect();
        Self {
            model: model.clone(),
            bodies,
            body_of,
            reactions,
            reaction_of,
            contacts,
            limits,
            gravity,
            reaction_unknowns: offset,
            length_scale: length_scale(model),
        }
    }

    /// Number of generalised coordinates, `6 + joints`.
    pub fn nq(&self) -> usize {
        BASE_DOF + self.model.joints.len()
    }

    /// The layout of unknowns and equations.
    pub fn dims(&self) -> Dims {
        Dims {
            nq: self.nq(),
            reaction_unknowns: self.reaction_unknowns,
            bodies: self.bodies.len(),
            contacts: self.contacts.len(),
            limits: self.limits.len(),
            lin: Space3::LIN,
            ang: Space3::ANG,
        }
    }

    /// Unknowns = equations.
    pub fn dim(&self) -> usize {
        self.dims().dim()
    }

    /// Column of reaction `i`'s force component `axis` (x, y, z).
    pub fn reaction_force(&self, i: usize, axis: usize) -> usize {
        self.dims().reaction() + self.reactions[i].offset + axis
    }

    /// Column of reaction `i`'s constraint moment `m` (0, or 0–1 for a
    /// single joint).
    pub fn reaction_moment(&self, i: usize, m: usize) -> usize {
        self.dims().reaction() + self.reactions[i].offset + 3 + m
    }

    /// Total mass (kg).
    pub fn total_mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.mass).sum()
    }

    /// A characteristic length (m), the scale of the stop rows: the
    /// longest path from the root's origin along the joint origins to a
    /// contact point or a centre of mass (for the hexapod: hip distance +
    /// upper + lower link), at least 0.01 m.
    pub fn length_scale(&self) -> f64 {
        self.length_scale
    }
}

/// See [`TreeMechanism::length_scale`].
fn length_scale(model: &RobotModel) -> f64 {
    // Path length from the root's origin to each body's origin.
    let mut reach = vec![0.0; model.bodies.len()];
    for joint in &model.joints {
        reach[joint.child] = reach[joint.parent] + joint.origin.translation.vector.norm();
    }
    let mut l: f64 = 0.0;
    for (b, body) in model.bodies.iter().enumerate() {
        l = l.max(reach[b] + body.com.norm());
    }
    for c in &model.contacts {
        l = l.max(reach[c.body] + c.position.norm());
    }
    l.max(0.01)
}

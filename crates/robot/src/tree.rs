//! The one builder every importer feeds: links and joints as a
//! description writes them (fixed joints included), turned into a
//! [`RobotModel`] — one tree checked, fixed joints merged into their
//! parents, inertias combined, contact points chosen.

use std::collections::HashMap;
use std::path::PathBuf;

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, Unit, UnitQuaternion, Vector3};

use crate::error::{Place, Result, RobotError};
use crate::model::{Actuator, Body, ContactPoint, Joint, JointLimits, RobotModel};

/// Which way is up in a description: its root is turned so that this axis
/// becomes fbd's `+y` (and the description's forward axis fbd's `−z`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Up {
    /// `+z` up, `+x` forward, `+y` left (ROS REP 103, MuJoCo's default):
    /// the root is turned by `x → −z`, `y → −x`, `z → y`. The default.
    #[default]
    Z,
    /// `+y` up, `−z` forward, as fbd (`fbd export mjcf` writes such
    /// models): no turn.
    Y,
}

impl Up {
    /// The rotation from the description's root frame to fbd's body frame.
    pub fn rotation(self) -> Rotation3<f64> {
        match self {
            Up::Y => Rotation3::identity(),
            Up::Z => Rotation3::from_matrix_unchecked(Matrix3::new(
                0.0, -1.0, 0.0, //
                0.0, 0.0, 1.0, //
                -1.0, 0.0, 0.0,
            )),
        }
    }
}

/// The mass properties of a link as written: mass, the inertial frame in
/// the link frame, the inertia tensor in the inertial frame's axes.
#[derive(Clone, Debug, PartialEq)]
pub struct RawInertial {
    /// Mass (kg).
    pub mass: f64,
    /// Inertial frame (origin = centre of mass) in the link frame.
    pub origin: Isometry3<f64>,
    /// Inertia about the centre of mass, inertial-frame axes (kg·m²).
    pub inertia: Matrix3<f64>,
}

/// A named point of a link (an MJCF site, a collision sphere).
#[derive(Clone, Debug, PartialEq)]
pub struct RawPoint {
    /// Its name (`None` for an unnamed collision sphere).
    pub name: Option<String>,
    /// Position in the link frame (m).
    pub position: Vector3<f64>,
    /// Sphere radius (m), 0 for a site.
    pub radius: f64,
    /// Where it is written.
    pub place: Place,
}

/// A link (URDF `<link>`, MJCF `<body>`) as written.
#[derive(Clone, Debug, PartialEq)]
pub struct RawLink {
    /// Its name.
    pub name: String,
    /// Where it is written.
    pub place: Place,
    /// Its mass properties (`None`: massless).
    pub inertial: Option<RawInertial>,
    /// Its collision spheres.
    pub spheres: Vec<RawPoint>,
    /// Its sites (named points that do not collide).
    pub sites: Vec<RawPoint>,
    /// Its collision elements that are not spheres (meshes, boxes, …).
    pub other_collisions: Vec<Place>,
}

impl RawLink {
    /// A link with no mass, collisions or sites.
    pub fn new(name: impl Into<String>, place: Place) -> Self {
        Self {
            name: name.into(),
            place,
            inertial: None,
            spheres: Vec::new(),
            sites: Vec::new(),
            other_collisions: Vec::new(),
        }
    }
}

/// What joins two links.
#[derive(Clone, Debug, PartialEq)]
pub enum RawJointKind {
    /// Welded: the child merges into the parent.
    Fixed,
    /// One rotation about the axis, within the limits if any.
    Revolute(Option<JointLimits>),
}

/// A joint as written.
#[derive(Clone, Debug, PartialEq)]
pub struct RawJoint {
    /// Its name.
    pub name: String,
    /// Where it is written.
    pub place: Place,
    /// Fixed or revolute.
    pub kind: RawJointKind,
    /// The parent link's name.
    pub parent: String,
    /// The child link's name.
    pub child: String,
    /// The child link's frame in the parent link's frame at zero angle.
    pub origin: Isometry3<f64>,
    /// The axis in the child link's frame (any length but 0).
    pub axis: Vector3<f64>,
    /// Effort limit (N·m).
    pub effort: Option<f64>,
    /// Velocity limit (rad/s).
    pub velocity: Option<f64>,
}

/// An actuator as written: its name, the joint's name, its torque limit.
#[derive(Clone, Debug, PartialEq)]
pub struct RawActuator {
    /// Its name.
    pub name: String,
    /// The joint it drives.
    pub joint: String,
    /// `|τ| ≤ effort_limit` at the joint (N·m).
    pub effort_limit: Option<f64>,
    /// Where it is written.
    pub place: Place,
}

/// Which points of the description are contact points.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum ContactChoice {
    /// Every collision sphere (the default).
    #[default]
    CollisionSpheres,
    /// These names, each a collision sphere, a site or a link (the link
    /// frame's origin, radius 0), in this order.
    Named(Vec<String>),
}

/// Links, joints and actuators as a description writes them.
#[derive(Clone, Debug, PartialEq)]
pub struct RawTree {
    /// The description file.
    pub file: PathBuf,
    /// The robot's name.
    pub name: String,
    /// The links, in the file's order.
    pub links: Vec<RawLink>,
    /// The joints, in the file's order.
    pub joints: Vec<RawJoint>,
    /// The actuators, `None` for one per revolute joint (named as the
    /// joint, its effort limit).
    pub actuators: Option<Vec<RawActuator>>,
}

/// Where a link ended up: its body and its frame in the body's frame.
#[derive(Clone, Copy, Debug)]
struct Placed {
    body: usize,
    frame: Isometry3<f64>,
}

/// Mass, first moment and second moment of a body, summed link by link.
#[derive(Clone, Copy, Debug)]
struct MassSum {
    mass: f64,
    /// Σ m·c.
    moment: Vector3<f64>,
    /// Σ (I_c + m·(|c|²·1 − c·cᵀ)): inertia about the body origin.
    inertia: Matrix3<f64>,
}

impl MassSum {
    fn zero() -> Self {
        Self {
            mass: 0.0,
            moment: Vector3::zeros(),
            inertia: Matrix3::zeros(),
        }
    }

    fn add(&mut self, mass: f64, com: Vector3<f64>, inertia: Matrix3<f64>) {
        self.mass += mass;
        self.moment += mass * com;
        self.inertia +=
            inertia + mass * (Matrix3::identity() * com.norm_squared() - com * com.transpose());
    }

    /// `(mass, centre of mass, inertia about it)`.
    fn finish(&self) -> (f64, Vector3<f64>, Matrix3<f64>) {
        if self.mass <= 0.0 {
            return (0.0, Vector3::zeros(), Matrix3::zeros());
        }
        let c = self.moment / self.mass;
        let shift = self.mass * (Matrix3::identity() * c.norm_squared() - c * c.transpose());
        let i = self.inertia - shift;
        (self.mass, c, 0.5 * (i + i.transpose()))
    }
}

impl RawTree {
    /// A place in this file for messages about the whole file.
    fn root_place(&self) -> Place {
        self.links
            .first()
            .map(|l| l.place.clone())
            .unwrap_or_else(|| Place::new(self.file.clone(), 1, "robot"))
    }

    /// The robot model: one tree (one root, one parent joint per link, no
    /// loops), fixed joints merged, the root turned so that `up` is fbd's
    /// `+y`, the contact points of `contacts`.
    pub fn build(&self, up: Up, contacts: &ContactChoice) -> Result<RobotModel> {
        let mut by_name: HashMap<&str, usize> = HashMap::new();
        for (i, l) in self.links.iter().enumerate() {
            if by_name.insert(&l.name, i).is_some() {
                return Err(RobotError::Tree {
                    place: l.place.clone(),
                    message: format!("a second link named \"{}\"", l.name),
                });
            }
        }
        let mut parent_joint: Vec<Option<usize>> = vec![None; self.links.len()];
        let mut children: Vec<Vec<usize>> = vec![Vec::new(); self.links.len()];
        for (j, joint) in self.joints.iter().enumerate() {
            let find = |name: &str, role: &str| {
                by_name.get(name).copied().ok_or_else(|| RobotError::Tree {
                    place: joint.place.clone(),
                    message: format!("{role} link \"{name}\" is not in the description"),
                })
            };
            let p = find(&joint.parent, "parent")?;
            let c = find(&joint.child, "child")?;
            if let Some(first) = parent_joint[c] {
                return Err(RobotError::Unsupported {
                    place: joint.place.clone(),
                    what: format!(
                        "a closed loop: link \"{}\" already hangs from joint \"{}\"; \
                         fbd models trees of bodies",
                        joint.child, self.joints[first].name
                    ),
                });
            }
            if joint.axis.norm() == 0.0 && joint.kind != RawJointKind::Fixed {
                return Err(RobotError::BadValue {
                    place: joint.place.clone(),
                    attribute: "axis".to_owned(),
                    value: "0 0 0".to_owned(),
                    expected: "a nonzero vector".to_owned(),
                });
            }
            parent_joint[c] = Some(j);
            children[p].push(j);
        }
        let roots: Vec<usize> = (0..self.links.len())
            .filter(|&l| parent_joint[l].is_none())
            .collect();
        let root = match roots[..] {
            [r] => r,
            [] => {
                return Err(RobotError::Tree {
                    place: self.root_place(),
                    message: "no root link: every link hangs from a joint (a loop)".to_owned(),
                });
            }
            [a, b, ..] => {
                return Err(RobotError::Tree {
                    place: self.links[b].place.clone(),
                    message: format!(
                        "two root links, \"{}\" and \"{}\": fbd models one tree",
                        self.links[a].name, self.links[b].name
                    ),
                });
            }
        };

        // Depth first from the root, children in the file's order: parents
        // come before their children.
        let mut placed: Vec<Option<Placed>> = vec![None; self.links.len()];
        let mut bodies = vec![Body {
            name: self.links[root].name.clone(),
            mass: 0.0,
            com: Vector3::zeros(),
            inertia: Matrix3::zeros(),
            joint: None,
        }];
        let mut joints: Vec<Joint> = Vec::new();
        placed[root] = Some(Placed {
            body: 0,
            frame: Isometry3::from_parts(
                Translation3::identity(),
                UnitQuaternion::from_rotation_matrix(&up.rotation()),
            ),
        });
        let mut stack: Vec<usize> = children[root].iter().rev().copied().collect();
        let mut visited = 1;
        while let Some(j) = stack.pop() {
            let joint = &self.joints[j];
            let p = by_name[joint.parent.as_str()];
            let c = by_name[joint.child.as_str()];
            let parent = placed[p].expect("parents are placed before their children");
            let frame_in_parent_body = parent.frame * joint.origin;
            placed[c] = Some(match &joint.kind {
                RawJointKind::Fixed => Placed {
                    body: parent.body,
                    frame: frame_in_parent_body,
                },
                RawJointKind::Revolute(limits) => {
                    let body = bodies.len();
                    joints.push(Joint {
                        name: joint.name.clone(),
                        parent: parent.body,
                        child: body,
                        origin: frame_in_parent_body,
                        axis: Unit::new_normalize(joint.axis),
                        limits: *limits,
                        effort: joint.effort,
                        velocity: joint.velocity,
                    });
                    bodies.push(Body {
                        name: self.links[c].name.clone(),
                        mass: 0.0,
                        com: Vector3::zeros(),
                        inertia: Matrix3::zeros(),
                        joint: Some(joints.len() - 1),
                    });
                    Placed {
                        body,
                        frame: Isometry3::identity(),
                    }
                }
            });
            visited += 1;
            stack.extend(children[c].iter().rev().copied());
        }
        if visited != self.links.len() {
            // Links not reached from the root hang in a loop of their own.
            let lost = (0..self.links.len())
                .find(|&l| placed[l].is_none())
                .expect("an unvisited link");
            return Err(RobotError::Unsupported {
                place: self.links[lost].place.clone(),
                what: format!(
                    "link \"{}\" is on a closed loop not attached to the root \"{}\"",
                    self.links[lost].name, self.links[root].name
                ),
            });
        }

        // Mass properties, merged per body.
        let mut sums = vec![MassSum::zero(); bodies.len()];
        for (l, link) in self.links.iter().enumerate() {
            let Some(inertial) = &link.inertial else {
                continue;
            };
            let at = placed[l].expect("every link is placed");
            let frame = at.frame * inertial.origin;
            let r = frame.rotation.to_rotation_matrix().into_inner();
            sums[at.body].add(
                inertial.mass,
                frame.translation.vector,
                r * inertial.inertia * r.transpose(),
            );
        }
        for (body, sum) in bodies.iter_mut().zip(&sums) {
            (body.mass, body.com, body.inertia) = sum.finish();
        }

        let contacts = self.contacts(contacts, &placed, &by_name)?;
        let actuators = self.actuators(&joints)?;
        Ok(RobotModel {
            name: self.name.clone(),
            bodies,
            joints,
            contacts,
            actuators,
        })
    }

    /// The contact points of `choice`, in their bodies' frames.
    fn contacts(
        &self,
        choice: &ContactChoice,
        placed: &[Option<Placed>],
        by_name: &HashMap<&str, usize>,
    ) -> Result<Vec<ContactPoint>> {
        let point = |l: usize, p: &RawPoint, name: String| {
            let at = placed[l].expect("every link is placed");
            ContactPoint {
                name,
                body: at.body,
                position: (at.frame * nalgebra::Point3::from(p.position)).coords,
                radius: p.radius,
            }
        };
        let fix = |v: nalgebra::Point3<f64>| v.coords;
        match choice {
            ContactChoice::CollisionSpheres => {
                let mut out = Vec::new();
                for (l, link) in self.links.iter().enumerate() {
                    for (k, s) in link.spheres.iter().enumerate() {
                        let name = s
                            .name
                            .clone()
                            .unwrap_or_else(|| format!("{}_sphere{}", link.name, k));
                        let at = placed[l].expect("every link is placed");
                        out.push(ContactPoint {
                            name,
                            body: at.body,
                            position: fix(at.frame * nalgebra::Point3::from(s.position)),
                            radius: s.radius,
                        });
                    }
                }
                if out.is_empty() {
                    // A foot is a link without children; if one collides
                    // through a mesh only, say so at its element.
                    let leaves = self
                        .links
                        .iter()
                        .filter(|l| !self.joints.iter().any(|j| j.parent == l.name));
                    if let Some(mesh) = leaves.flat_map(|l| l.other_collisions.first()).next() {
                        return Err(RobotError::Unsupported {
                            place: mesh.clone(),
                            what: "a foot whose collision is a mesh (or box, cylinder): fbd's \
                                   contact points are spheres or points; name the foot links \
                                   or sites in [robot] contacts = [...]"
                                .to_owned(),
                        });
                    }
                    return Err(RobotError::NoContacts {
                        file: self.file.clone(),
                        message: "the description has no collision spheres; name the foot \
                                  links or sites in [robot] contacts = [...]"
                            .to_owned(),
                    });
                }
                Ok(out)
            }
            ContactChoice::Named(names) => {
                let mut out = Vec::with_capacity(names.len());
                for name in names {
                    let found = self.links.iter().enumerate().find_map(|(l, link)| {
                        link.spheres
                            .iter()
                            .chain(&link.sites)
                            .find(|p| p.name.as_deref() == Some(name.as_str()))
                            .map(|p| point(l, p, name.clone()))
                    });
                    let found = found.or_else(|| {
                        by_name.get(name.as_str()).map(|&l| {
                            let at = placed[l].expect("every link is placed");
                            ContactPoint {
                                name: name.clone(),
                                body: at.body,
                                position: at.frame.translation.vector,
                                radius: 0.0,
                            }
                        })
                    });
                    match found {
                        Some(c) => out.push(c),
                        None => {
                            let known: Vec<&str> = self
                                .links
                                .iter()
                                .flat_map(|l| {
                                    std::iter::once(l.name.as_str()).chain(
                                        l.spheres
                                            .iter()
                                            .chain(&l.sites)
                                            .filter_map(|p| p.name.as_deref()),
                                    )
                                })
                                .collect();
                            return Err(RobotError::UnknownName {
                                file: self.file.clone(),
                                kind: "link, site or collision sphere",
                                name: name.clone(),
                                hint: crate::suggest(name, &known),
                            });
                        }
                    }
                }
                if out.is_empty() {
                    return Err(RobotError::NoContacts {
                        file: self.file.clone(),
                        message: "[robot] contacts is empty".to_owned(),
                    });
                }
                Ok(out)
            }
        }
    }

    /// The actuators, each on a revolute joint of the model.
    fn actuators(&self, joints: &[Joint]) -> Result<Vec<Actuator>> {
        let Some(raw) = &self.actuators else {
            return Ok(joints
                .iter()
                .enumerate()
                .map(|(j, joint)| Actuator {
                    name: joint.name.clone(),
                    joint: j,
                    effort_limit: joint.effort,
                })
                .collect());
        };
        raw.iter()
            .map(|a| {
                let joint = joints
                    .iter()
                    .position(|j| j.name == a.joint)
                    .ok_or_else(|| RobotError::Tree {
                        place: a.place.clone(),
                        message: format!(
                            "actuator \"{}\" drives \"{}\", which is not a revolute joint \
                             of the model",
                            a.name, a.joint
                        ),
                    })?;
                Ok(Actuator {
                    name: a.name.clone(),
                    joint,
                    effort_limit: a.effort_limit,
                })
            })
            .collect()
    }
}

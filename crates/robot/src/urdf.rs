//! URDF (ROS) robot descriptions: `<link>` (inertial, collision spheres),
//! `<joint>` (`revolute`, `continuous`, `fixed`), into a [`RawTree`].
//!
//! * `<origin xyz rpy>`: `rpy` is roll–pitch–yaw about the fixed axes,
//!   `R = Rz(yaw)·Ry(pitch)·Rx(roll)`; absent means identity;
//! * `<axis xyz>` defaults to `1 0 0`; a `revolute` joint needs
//!   `<limit lower upper>` (rad) and may give `effort` (N·m) and
//!   `velocity` (rad/s); a `continuous` one has no position limits;
//! * `<inertial>`: `<mass value>`, `<inertia ixx ixy ixz iyy iyz izz>` in
//!   the axes of its `<origin>`;
//! * `<collision>` with `<sphere radius>` is a collision sphere (named by
//!   the collision's `name`); any other collision geometry is kept only to
//!   say where a mesh-only foot is;
//! * `prismatic`, `floating` and `planar` joints and `<mimic>` are errors
//!   naming the element; `<visual>`, `<transmission>`, `<gazebo>`,
//!   `<material>` are ignored.

use std::path::Path;

use nalgebra::{Isometry3, Matrix3, Translation3, UnitQuaternion, Vector3};
use roxmltree::Node;

use crate::error::{Result, RobotError};
use crate::model::{JointLimits, RobotModel};
use crate::tree::{
    ContactChoice, RawInertial, RawJoint, RawJointKind, RawLink, RawPoint, RawTree, Up,
};
use crate::xml::{self, number_opt, numbers, place, require, vec3_or};

/// Reads and builds the model of URDF `file`.
pub fn load(file: &Path, up: Up, contacts: &ContactChoice) -> Result<RobotModel> {
    let text = xml::read(file)?;
    parse(file, &text)?.build(up, contacts)
}

/// The links and joints of a URDF document as written (`file` names it in
/// messages).
pub fn parse(file: &Path, text: &str) -> Result<RawTree> {
    let doc = xml::parse(file, text)?;
    let robot = doc.root_element();
    if robot.tag_name().name() != "robot" {
        return Err(RobotError::Unsupported {
            place: place(file, robot),
            what: "a URDF's root element is <robot>".to_owned(),
        });
    }
    let mut tree = RawTree {
        file: file.to_owned(),
        name: robot.attribute("name").unwrap_or("robot").to_owned(),
        links: Vec::new(),
        joints: Vec::new(),
        actuators: None,
    };
    for node in robot.children().filter(Node::is_element) {
        match node.tag_name().name() {
            "link" => tree.links.push(link(file, node)?),
            "joint" => tree.joints.push(joint(file, node)?),
            _ => {}
        }
    }
    Ok(tree)
}

/// Attribute `name` of `node`, required.
fn name<'a>(file: &Path, node: Node<'a, '_>, attr: &str) -> Result<&'a str> {
    node.attribute(attr).ok_or_else(|| RobotError::Missing {
        place: place(file, node),
        what: format!("attribute {attr}"),
    })
}

/// The one child element `tag` of `node`, if any.
fn child<'a, 'i>(node: Node<'a, 'i>, tag: &str) -> Option<Node<'a, 'i>> {
    node.children().find(|c| c.has_tag_name(tag))
}

/// `R = Rz(yaw)·Ry(pitch)·Rx(roll)`.
pub fn rpy(roll: f64, pitch: f64, yaw: f64) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::z_axis(), yaw)
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), pitch)
        * UnitQuaternion::from_axis_angle(&Vector3::x_axis(), roll)
}

/// The `<origin>` child of `node` (identity when absent).
fn origin(file: &Path, node: Node) -> Result<Isometry3<f64>> {
    let Some(o) = child(node, "origin") else {
        return Ok(Isometry3::identity());
    };
    let xyz = vec3_or(file, o, "xyz", Vector3::zeros())?;
    let r = vec3_or(file, o, "rpy", Vector3::zeros())?;
    Ok(Isometry3::from_parts(
        Translation3::from(xyz),
        rpy(r.x, r.y, r.z),
    ))
}

/// One `<link>`.
fn link(file: &Path, node: Node) -> Result<RawLink> {
    let mut out = RawLink::new(name(file, node, "name")?, place(file, node));
    if let Some(i) = child(node, "inertial") {
        let Some(m) = child(i, "mass") else {
            return Err(RobotError::Missing {
                place: place(file, i),
                what: "<mass value=\"…\"/>".to_owned(),
            });
        };
        let mass = numbers(file, m, "value", Some(1))?[0];
        require(mass >= 0.0, file, m, "value", "a mass ≥ 0 kg")?;
        let inertia = match child(i, "inertia") {
            None => Matrix3::zeros(),
            Some(t) => {
                let get = |a: &str| Ok::<f64, RobotError>(numbers(file, t, a, Some(1))?[0]);
                let (xx, xy, xz) = (get("ixx")?, get("ixy")?, get("ixz")?);
                let (yy, yz, zz) = (get("iyy")?, get("iyz")?, get("izz")?);
                let m = Matrix3::new(xx, xy, xz, xy, yy, yz, xz, yz, zz);
                let ok = m
                    .symmetric_eigenvalues()
                    .iter()
                    .all(|&e| e >= -1e-12 * m.norm());
                require(
                    ok,
                    file,
                    t,
                    "ixx",
                    "an inertia tensor with no negative principal moment",
                )?;
                m
            }
        };
        out.inertial = Some(RawInertial {
            mass,
            origin: origin(file, i)?,
            inertia,
        });
    }
    for c in node.children().filter(|c| c.has_tag_name("collision")) {
        let at = origin(file, c)?;
        let geometry = child(c, "geometry").and_then(|g| g.children().find(Node::is_element));
        match geometry {
            Some(s) if s.has_tag_name("sphere") => {
                let radius = numbers(file, s, "radius", Some(1))?[0];
                require(radius >= 0.0, file, s, "radius", "a radius ≥ 0 m")?;
                out.spheres.push(RawPoint {
                    name: c.attribute("name").map(str::to_owned),
                    position: at.translation.vector,
                    radius,
                    place: place(file, c),
                });
            }
            Some(g) => out.other_collisions.push(place(file, g)),
            None => {
                return Err(RobotError::Missing {
                    place: place(file, c),
                    what: "<geometry> with a shape".to_owned(),
                });
            }
        }
    }
    Ok(out)
}

/// One `<joint>`.
fn joint(file: &Path, node: Node) -> Result<RawJoint> {
    let jname = name(file, node, "name")?;
    let kind = name(file, node, "type")?;
    let link_of = |tag: &str| -> Result<String> {
        let Some(n) = child(node, tag) else {
            return Err(RobotError::Missing {
                place: place(file, node),
                what: format!("<{tag} link=\"…\"/>"),
            });
        };
        Ok(name(file, n, "link")?.to_owned())
    };
    if let Some(m) = child(node, "mimic") {
        return Err(RobotError::Unsupported {
            place: place(file, m),
            what: "a mimic joint (a constraint between joints)".to_owned(),
        });
    }
    let limit = child(node, "limit");
    let (mut effort, mut velocity) = (None, None);
    if let Some(l) = limit {
        effort = number_opt(file, l, "effort")?;
        velocity = number_opt(file, l, "velocity")?;
        if let Some(e) = effort {
            require(e >= 0.0, file, l, "effort", "an effort limit ≥ 0 N·m")?;
        }
    }
    let kind = match kind {
        "fixed" => RawJointKind::Fixed,
        "continuous" => RawJointKind::Revolute(None),
        "revolute" => {
            let Some(l) = limit else {
                return Err(RobotError::Missing {
                    place: place(file, node),
                    what: "<limit lower=\"…\" upper=\"…\"/> (a revolute joint has limits; \
                           use type=\"continuous\" for none)"
                        .to_owned(),
                });
            };
            let lower = numbers(file, l, "lower", Some(1))?[0];
            let upper = numbers(file, l, "upper", Some(1))?[0];
            require(lower <= upper, file, l, "upper", "upper ≥ lower")?;
            RawJointKind::Revolute(Some(JointLimits { lower, upper }))
        }
        other => {
            return Err(RobotError::Unsupported {
                place: place(file, node),
                what: format!("a {other} joint: fbd models revolute, continuous and fixed joints"),
            });
        }
    };
    let axis = match child(node, "axis") {
        None => Vector3::x(),
        Some(a) => vec3_or(file, a, "xyz", Vector3::x())?,
    };
    Ok(RawJoint {
        name: jname.to_owned(),
        place: place(file, node),
        kind,
        parent: link_of("parent")?,
        child: link_of("child")?,
        origin: origin(file, node)?,
        axis,
        effort,
        velocity,
    })
}

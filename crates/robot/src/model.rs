//! The robot model as data: a tree of rigid bodies joined by revolute
//! joints, contact points on the bodies, actuators on the joints.
//!
//! Conventions (every importer and builder produces them):
//!
//! * body 0 is the **root** (the floating base); every other body `b` has
//!   exactly one parent joint, `bodies[b].joint`, and bodies are ordered so
//!   that a parent comes before its children (a topological order: one
//!   forward pass visits them all);
//! * a body's frame is its parent joint's frame: the joint's
//!   [`Joint::origin`] places it in the parent body's frame at `q = 0`, and
//!   the joint turns it about [`Joint::axis`] (a unit vector in the body's
//!   own frame, through its origin) by the joint angle;
//! * the root's frame is fbd's body frame: `+y` up, `−z` forward, `+x` to
//!   the robot's right (importers rotate a description's root to it, see
//!   [`crate::Up`]); the floating base's pose `(R, Rot)` places it in the
//!   inertial frame (`Y` up), as for the hexapod;
//! * masses kg, lengths m, inertias kg·m² about the body's centre of mass
//!   in the body's frame, angles rad.

use nalgebra::{Isometry3, Matrix3, Unit, Vector3};

/// One rigid body.
#[derive(Clone, Debug, PartialEq)]
pub struct Body {
    /// The body's name (the URDF link or MJCF body it came from; merged
    /// fixed children keep only the parent's name).
    pub name: String,
    /// Mass (kg); 0 for a massless body (a frame between two joints).
    pub mass: f64,
    /// Centre of mass in the body's frame (m).
    pub com: Vector3<f64>,
    /// Inertia tensor about the centre of mass, body axes (kg·m²).
    pub inertia: Matrix3<f64>,
    /// The joint connecting the body to its parent (`None` for the root).
    pub joint: Option<usize>,
}

/// Limits of a revolute joint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointLimits {
    /// Lower bound (rad).
    pub lower: f64,
    /// Upper bound (rad).
    pub upper: f64,
}

/// A revolute joint (one degree of freedom).
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// The joint's name (a `trajectory.csv` column of the robot's runs).
    pub name: String,
    /// The parent body.
    pub parent: usize,
    /// The child body (its frame is this joint's frame).
    pub child: usize,
    /// The child's frame in the parent's frame at zero angle.
    pub origin: Isometry3<f64>,
    /// The rotation axis in the child's frame, through its origin (unit).
    pub axis: Unit<Vector3<f64>>,
    /// Position limits, `None` for a continuous joint.
    pub limits: Option<JointLimits>,
    /// `|τ| ≤ effort` (N·m), if the description gives it.
    pub effort: Option<f64>,
    /// `|θ̇| ≤ velocity` (rad/s), if the description gives it.
    pub velocity: Option<f64>,
}

/// A point of a body that can touch the ground.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactPoint {
    /// The point's name (a collision sphere's, a site's or a link's).
    pub name: String,
    /// The body carrying it.
    pub body: usize,
    /// Its position in the body's frame (m): a sphere's centre.
    pub position: Vector3<f64>,
    /// The sphere's radius (m); 0 for a point.
    pub radius: f64,
}

/// A torque source on a joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Actuator {
    /// The actuator's name.
    pub name: String,
    /// The joint it drives.
    pub joint: usize,
    /// `|τ| ≤ effort_limit` (N·m) at the joint, if any.
    pub effort_limit: Option<f64>,
}

/// A robot: bodies, joints, contact points and actuators (see the module
/// docs for the conventions).
#[derive(Clone, Debug, PartialEq)]
pub struct RobotModel {
    /// The robot's name.
    pub name: String,
    /// The bodies, root first, parents before children.
    pub bodies: Vec<Body>,
    /// The revolute joints, `joints[j].child` in the order of the bodies.
    pub joints: Vec<Joint>,
    /// The contact points.
    pub contacts: Vec<ContactPoint>,
    /// The actuators.
    pub actuators: Vec<Actuator>,
}

impl RobotModel {
    /// Number of joint angles (`q` has 6 more: the floating base).
    pub fn joint_count(&self) -> usize {
        self.joints.len()
    }

    /// Total mass (kg).
    pub fn mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.mass).sum()
    }

    /// The index of the body named `name`.
    pub fn body_index(&self, name: &str) -> Option<usize> {
        self.bodies.iter().position(|b| b.name == name)
    }

    /// The index of the joint named `name`.
    pub fn joint_index(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The parent body of body `b` (`None` for the root).
    pub fn parent(&self, b: usize) -> Option<usize> {
        self.bodies[b].joint.map(|j| self.joints[j].parent)
    }

    /// Bodies with no mass that carry exactly one child joint whose axis
    /// passes through their own joint's origin: the frames between two
    /// joints at one point (the paper's two-axis hip), which the FBD model
    /// treats as one joint of two degrees of freedom. Returned as
    /// `(first joint, second joint)` pairs.
    pub fn compound_joints(&self) -> Vec<(usize, usize)> {
        let mut out = Vec::new();
        for (b, body) in self.bodies.iter().enumerate() {
            let Some(first) = body.joint else { continue };
            if body.mass != 0.0 || self.contacts.iter().any(|c| c.body == b) {
                continue;
            }
            let children: Vec<usize> = (0..self.joints.len())
                .filter(|&j| self.joints[j].parent == b)
                .collect();
            if let [second] = children[..] {
                // The second axis passes through the first joint's origin
                // (the body's origin): the origin's offset has no component
                // across the axis.
                let o = &self.joints[second].origin;
                let axis_in_body = o.rotation * self.joints[second].axis.into_inner();
                let t = o.translation.vector;
                let across = t - axis_in_body * axis_in_body.dot(&t);
                if across.norm() <= 1e-12 {
                    out.push((first, second));
                }
            }
        }
        out
    }
}

//! Forward kinematics of any [`RobotModel`]: every body's frame, joint
//! axis and contact point in the inertial frame, one pass from the root.

use nalgebra::{Isometry3, Point3, Translation3, UnitQuaternion, Vector3};

use crate::model::RobotModel;

/// The workspace of [`forward`], built once per model.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotData {
    /// Each body's frame in the inertial frame.
    pub frames: Vec<Isometry3<f64>>,
    /// Each joint's axis in the inertial frame (unit).
    pub axes: Vec<Vector3<f64>>,
    /// Each contact point (sphere centre) in the inertial frame (m).
    pub contacts: Vec<Vector3<f64>>,
}

impl RobotData {
    /// A workspace for `model` (every frame the identity until
    /// [`forward`] fills it).
    pub fn new(model: &RobotModel) -> Self {
        Self {
            frames: vec![Isometry3::identity(); model.bodies.len()],
            axes: vec![Vector3::zeros(); model.joints.len()],
            contacts: vec![Vector3::zeros(); model.contacts.len()],
        }
    }

    /// Body `b`'s centre of mass in the inertial frame (m).
    pub fn com(&self, model: &RobotModel, b: usize) -> Vector3<f64> {
        (self.frames[b] * Point3::from(model.bodies[b].com)).coords
    }

    /// The whole robot's centre of mass (m), the origin for a massless one.
    pub fn total_com(&self, model: &RobotModel) -> Vector3<f64> {
        let m = model.mass();
        if m <= 0.0 {
            return Vector3::zeros();
        }
        (0..model.bodies.len())
            .map(|b| model.bodies[b].mass * self.com(model, b))
            .sum::<Vector3<f64>>()
            / m
    }
}

/// The floating base's frame from fbd's pose `R`, `(φx, φy, φz)`
/// (`Rot = Rx(φx)·Rz(φz)·Ry(φy)`, docs/reference.md).
pub fn base_frame(position: [f64; 3], phi: [f64; 3]) -> Isometry3<f64> {
    let pose = fbd_kinematics::pose::BodyPose::new(position, phi);
    let rot = nalgebra::Rotation3::from_matrix_unchecked(pose.rotation());
    Isometry3::from_parts(
        Translation3::from(pose.position),
        UnitQuaternion::from_rotation_matrix(&rot),
    )
}

/// Fills `data` for the root at `base` and joint angles `q` (rad, in the
/// order of `model.joints`).
///
/// # Panics
/// If `q` or `data` do not match the model.
pub fn forward(model: &RobotModel, base: &Isometry3<f64>, q: &[f64], data: &mut RobotData) {
    assert_eq!(q.len(), model.joints.len(), "one angle per joint");
    data.frames[0] = *base;
    for (j, joint) in model.joints.iter().enumerate() {
        let turn = UnitQuaternion::from_axis_angle(&joint.axis, q[j]);
        let frame = data.frames[joint.parent] * joint.origin * turn;
        data.axes[j] = frame.rotation * joint.axis.into_inner();
        data.frames[joint.child] = frame;
    }
    for (k, c) in model.contacts.iter().enumerate() {
        data.contacts[k] = (data.frames[c.body] * Point3::from(c.position)).coords;
    }
}

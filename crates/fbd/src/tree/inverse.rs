//! Inverse dynamics of any robot model body by body.
//!
//! Every body is isolated. Body `b`, hanging from joint `j` at its frame's
//! origin `o_b`, receives from its parent the force `F_j` and the moment
//! `M_j` (about `o_b`), gives `−F_k`, `−M_k` to each child joint `k` (at
//! `o_k`), and carries its weight `m_b·g` at its centre of mass `c_b`:
//!
//! ```text
//! F_j − Σ_k F_k + m_b·g                                    = m_b·a_c
//! M_j − Σ_k (M_k + (o_k − o_b)×F_k) + (c_b − o_b)×m_b·g    = (c_b − o_b)×m_b·a_c + I·α + ω×(I·ω)
//! ```
//!
//! (inertial frame; `I` the body's inertia about `c_b` in inertial axes).
//! With the motion given (pose, velocities, accelerations), each body's
//! two equations give its parent joint's `F_j` and `M_j` once its children's
//! are known: a pass from the leaves to the root. `M_j` splits into the
//! joint torque `τ_j = M_j·u_j` along the axis `u_j` and the constraint
//! moment `M_j − τ_j·u_j` across it; the root's `(F, M)` is the external
//! wrench the motion needs (zero for a motion the robot makes in flight).
//!
//! Kinematics, one pass from the root: a child's frame origin moves with
//! its parent (`a_o = a_p + α_p×r + ω_p×(ω_p×r)`, `r = o_b − o_p`), and
//! `ω_b = ω_p + u·θ̇`, `α_b = α_p + u·θ̈ + ω_p×u·θ̇`.

use fbd_robot::nalgebra::{Isometry3, Matrix3, Point3, Vector3};
use fbd_robot::{RobotData, RobotModel, forward};

/// The motion of the robot at one instant.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeMotion {
    /// The root frame's pose.
    pub base: Isometry3<f64>,
    /// Velocity of the root frame's origin (m/s, inertial).
    pub velocity: Vector3<f64>,
    /// Angular velocity of the root (rad/s, inertial).
    pub omega: Vector3<f64>,
    /// Acceleration of the root frame's origin (m/s², inertial).
    pub acceleration: Vector3<f64>,
    /// Angular acceleration of the root (rad/s², inertial).
    pub alpha: Vector3<f64>,
    /// Joint angles (rad), the model's joint order.
    pub q: Vec<f64>,
    /// Joint rates (rad/s).
    pub qd: Vec<f64>,
    /// Joint accelerations (rad/s²).
    pub qdd: Vec<f64>,
}

/// The workspace and results of [`inverse`], built once per model.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeData {
    /// Frames, axes and contact points ([`fbd_robot::forward()`]).
    pub kin: RobotData,
    /// Each body's angular velocity (rad/s, inertial).
    pub omega: Vec<Vector3<f64>>,
    /// Each body's angular acceleration (rad/s², inertial).
    pub alpha: Vec<Vector3<f64>>,
    /// Each body frame origin's acceleration (m/s², inertial).
    pub origin_acceleration: Vec<Vector3<f64>>,
    /// Each body's centre-of-mass acceleration (m/s², inertial).
    pub com_acceleration: Vec<Vector3<f64>>,
    /// Force of the parent on each joint's child (N, inertial).
    pub force: Vec<Vector3<f64>>,
    /// Moment of the parent on each joint's child about the joint's origin
    /// (N·m, inertial): the axis torque plus the constraint moment.
    pub moment: Vec<Vector3<f64>>,
    /// Each joint's torque along its axis (N·m).
    pub torque: Vec<f64>,
    /// The external force the root needs (N, inertial).
    pub base_force: Vector3<f64>,
    /// The external moment the root needs about its frame's origin (N·m).
    pub base_moment: Vector3<f64>,
    /// Per body: the force and moment (about its origin) of its children's
    /// joints on it, summed during the pass.
    child_force: Vec<Vector3<f64>>,
    child_moment: Vec<Vector3<f64>>,
}

impl TreeData {
    /// A workspace for `model`.
    pub fn new(model: &RobotModel) -> Self {
        let b = model.bodies.len();
        let j = model.joints.len();
        let z = Vector3::zeros();
        Self {
            kin: RobotData::new(model),
            omega: vec![z; b],
            alpha: vec![z; b],
            origin_acceleration: vec![z; b],
            com_acceleration: vec![z; b],
            force: vec![z; j],
            moment: vec![z; j],
            torque: vec![0.0; j],
            base_force: z,
            base_moment: z,
            child_force: vec![z; b],
            child_moment: vec![z; b],
        }
    }

    /// The constraint moment of joint `j`: `M_j` less its axis component.
    pub fn constraint_moment(&self, j: usize) -> Vector3<f64> {
        self.moment[j] - self.torque[j] * self.kin.axes[j]
    }
}

/// Inverse dynamics by the FBD method (module docs): every joint's force,
/// moment and torque, and the root's external wrench, for `motion` under
/// gravity `gravity` (m/s², inertial vector, e.g. `(0, −9.81, 0)`).
///
/// # Panics
/// If the motion's joint vectors do not have one entry per joint.
pub fn inverse(
    model: &RobotModel,
    motion: &TreeMotion,
    gravity: Vector3<f64>,
    data: &mut TreeData,
) {
    let n = model.joints.len();
    assert!(motion.q.len() == n && motion.qd.len() == n && motion.qdd.len() == n);
    forward(model, &motion.base, &motion.q, &mut data.kin);
    let origin = |d: &TreeData, b: usize| d.kin.frames[b].translation.vector;

    // Root to leaves: velocities and accelerations.
    data.omega[0] = motion.omega;
    data.alpha[0] = motion.alpha;
    data.origin_acceleration[0] = motion.acceleration;
    for (j, joint) in model.joints.iter().enumerate() {
        let (p, c) = (joint.parent, joint.child);
        let u = data.kin.axes[j];
        let r = origin(data, c) - origin(data, p);
        let (wp, ap) = (data.omega[p], data.alpha[p]);
        data.origin_acceleration[c] =
            data.origin_acceleration[p] + ap.cross(&r) + wp.cross(&wp.cross(&r));
        data.omega[c] = wp + u * motion.qd[j];
        data.alpha[c] = ap + u * motion.qdd[j] + wp.cross(&(u * motion.qd[j]));
    }
    for b in 0..model.bodies.len() {
        let rc = (data.kin.frames[b] * Point3::from(model.bodies[b].com)).coords - origin(data, b);
        let (w, a) = (data.omega[b], data.alpha[b]);
        data.com_acceleration[b] =
            data.origin_acceleration[b] + a.cross(&rc) + w.cross(&w.cross(&rc));
        data.child_force[b] = Vector3::zeros();
        data.child_moment[b] = Vector3::zeros();
    }

    // Leaves to root: each body's balance gives its parent joint's wrench.
    for b in (0..model.bodies.len()).rev() {
        let body = &model.bodies[b];
        let o = origin(data, b);
        let rc = (data.kin.frames[b] * Point3::from(body.com)).coords - o;
        let rot: Matrix3<f64> = data.kin.frames[b]
            .rotation
            .to_rotation_matrix()
            .into_inner();
        let inertia = rot * body.inertia * rot.transpose();
        let (w, a) = (data.omega[b], data.alpha[b]);
        let ma = body.mass * data.com_acceleration[b];
        let weight = body.mass * gravity;
        // F_parent = m·a_c − m·g + Σ F_children;
        // M_parent = rc×(m·a_c) + I·α + ω×Iω − rc×m·g + Σ (M_k + r_k×F_k).
        let force = ma - weight + data.child_force[b];
        let moment =
            rc.cross(&(ma - weight)) + inertia * a + w.cross(&(inertia * w)) + data.child_moment[b];
        match body.joint {
            None => {
                data.base_force = force;
                data.base_moment = moment;
            }
            Some(j) => {
                data.force[j] = force;
                data.moment[j] = moment;
                data.torque[j] = moment.dot(&data.kin.axes[j]);
                let p = model.joints[j].parent;
                let r = o - origin(data, p);
                data.child_force[p] += force;
                data.child_moment[p] += moment + r.cross(&force);
            }
        }
    }
}

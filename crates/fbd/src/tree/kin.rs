//! Kinematics of any robot model ([`fbd_robot::RobotModel`]) at the
//! generalised coordinates
//!
//! ```text
//! q = (Rx, Ry, Rz, φx, φy, φz, θ_0, …, θ_{n−1})
//! ```
//!
//! `R` the root frame's origin (inertial, `Y` up), `φ` fbd's body pose
//! (`Rot = Rx(φx)·Rz(φz)·Ry(φy)`, [`fbd_kinematics::pose::BodyPose`]), then
//! the joint angles in the order of `model.joints` (`θ_j` is `q[6 + j]`).
//!
//! [`TreeKin`] is a workspace built once per model; [`TreeKin::eval`]
//! places every body frame, centre of mass, joint axis and contact point
//! in one pass from the root without touching the heap. The Jacobians are
//! analytic and sparse: a point `p` rigidly attached to body `b` moves
//! with
//!
//! ```text
//! ∂p/∂R_i = e_i,   ∂p/∂φ_k = a_k × (p − R),   ∂p/∂θ_j = u_j × (p − o_j)
//! ```
//!
//! for the ancestor joints `j` of `b` only (`a_k` the base's
//! [`TreeKin::phi_axes`], `u_j` and `o_j` joint `j`'s axis and origin,
//! inertial), and the body turns with `ω_b = Σ_k a_k·φ̇_k + Σ_j u_j·θ̇_j`.
//! Each body's ancestor joints are listed once, at construction.

use fbd_kinematics::pose::BodyPose;
use fbd_robot::RobotModel;
use fbd_robot::nalgebra::{Matrix3, Vector3};

/// Number of floating-base coordinates at the front of `q`.
pub const BASE_DOF: usize = 6;

/// Index of `φx` in `q` (`φy`, `φz` follow).
pub const PHI: usize = 3;

/// The kinematics of one robot model at one `q` (see the module docs).
///
/// Build it once per model with [`TreeKin::new`], then call
/// [`TreeKin::eval`] at each configuration; the Jacobian methods read the
/// last evaluation.
#[derive(Clone, Debug, PartialEq)]
pub struct TreeKin {
    /// Number of generalised coordinates, `6 + joints`.
    nq: usize,
    /// Per body `b`, its ancestor joints (root to `b`, so increasing) are
    /// `chain[chain_start[b]..chain_start[b + 1]]`.
    chain_start: Vec<usize>,
    /// The ancestor joints of every body, concatenated.
    chain: Vec<usize>,
    /// The longest chain of joints from the root to a body.
    max_depth: usize,
    /// Each body's frame origin (m, inertial); `origin[0]` is `R`.
    pub origin: Vec<Vector3<f64>>,
    /// Each body's rotation, body frame → inertial.
    pub rotation: Vec<Matrix3<f64>>,
    /// Each body's centre of mass (m, inertial).
    pub com: Vec<Vector3<f64>>,
    /// Each joint's axis (inertial, unit).
    pub axis: Vec<Vector3<f64>>,
    /// Each joint's origin (m, inertial): its child body's frame origin,
    /// a point of the axis.
    pub joint_origin: Vec<Vector3<f64>>,
    /// Each contact point where it touches the ground (m, inertial): a
    /// point's own position; for a sphere its lowest point, the centre
    /// minus the radius along `Y` (the point of a sphere that touches a
    /// level ground). It moves with the sphere's centre, whose Jacobian it
    /// has ([`Self::contact_jacobian`]).
    pub contact: Vec<Vector3<f64>>,
    /// Each contact sphere's centre (a point's own position) (m, inertial).
    pub contact_center: Vec<Vector3<f64>>,
    /// Each contact sphere's radius (0 for a point) (m).
    contact_radius: Vec<f64>,
    /// The inertial axes about which `φx, φy, φz` turn the root:
    /// `ω_root = Σ_k phi_axes[k]·φ̇_k`.
    pub phi_axes: [Vector3<f64>; 3],
    /// The body each contact point is on (from the model).
    contact_body: Vec<usize>,
    /// Each joint's constants, made once from the model.
    joints: Vec<JointConst>,
    /// Each body's centre of mass in its frame (from the model).
    body_com: Vec<Vector3<f64>>,
    /// Each contact point's position in its body's frame (from the model).
    contact_local: Vec<Vector3<f64>>,
    /// Scratch of [`Self::eval`]: per joint, the sine and cosine of its
    /// angle times its [`JointConst::angle_sign`], all taken before the
    /// frames are placed (no library call among them, whose registers
    /// would have to be saved).
    sin_cos: Vec<(f64, f64)>,
    /// The coordinates of the last evaluation, bit for bit (when
    /// `evaluated`): [`Self::eval`] at the same `q` again finds everything
    /// in place.
    at: Vec<f64>,
    /// Whether [`Self::eval`] was called.
    evaluated: bool,
}

/// The axis of a joint in its child's frame, as the rotation about it is
/// computed: a coordinate axis (`±x`, `±y`, `±z`) turns two columns of the
/// frame in place; any other axis by Rodrigues' formula.
#[derive(Clone, Copy, Debug, PartialEq)]
enum AxisKind {
    /// `sign·e_k` (`k` 0–2).
    Coordinate { k: usize, sign: f64 },
    /// Any other unit axis.
    General(Vector3<f64>),
}

/// A joint's fixed origin rotation `O`, as `F = R_parent·O` is computed.
#[derive(Clone, Copy, Debug, PartialEq)]
enum FixedRotation {
    /// `O = I` (to 1e-15): `F = R_parent`.
    Identity,
    /// `O` a signed permutation (to 1e-15; a D-H `α` of ±90°, an axis
    /// swap): column `i` of `F` is `sign[i]` times column `from[i]` of
    /// `R_parent`, `from` one of the six orders ([`Order`]).
    Permutation { from: Order, sign: [f64; 3] },
    /// Any other rotation.
    General(Matrix3<f64>),
}

/// The order `from` of a [`FixedRotation::Permutation`]'s columns, named so
/// that [`FixedRotation::apply`] reads them at fixed places.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Order {
    O012,
    O021,
    O102,
    O120,
    O201,
    O210,
}

impl Order {
    fn of(from: [usize; 3]) -> Option<Self> {
        Some(match from {
            [0, 1, 2] => Self::O012,
            [0, 2, 1] => Self::O021,
            [1, 0, 2] => Self::O102,
            [1, 2, 0] => Self::O120,
            [2, 0, 1] => Self::O201,
            [2, 1, 0] => Self::O210,
            _ => return None,
        })
    }

    /// The columns `(a[from[0]], a[from[1]], a[from[2]])`.
    #[inline]
    fn pick<T: Copy>(self, a: [T; 3]) -> [T; 3] {
        let [x, y, z] = a;
        match self {
            Self::O012 => [x, y, z],
            Self::O021 => [x, z, y],
            Self::O102 => [y, x, z],
            Self::O120 => [y, z, x],
            Self::O201 => [z, x, y],
            Self::O210 => [z, y, x],
        }
    }
}

impl FixedRotation {
    fn of(r: &Matrix3<f64>) -> Self {
        let tol = 1e-15;
        let mut from = [0; 3];
        let mut sign = [0.0; 3];
        for i in 0..3 {
            let col = r.column(i);
            let Some(k) = (0..3).find(|&k| (col[k].abs() - 1.0).abs() <= tol) else {
                return Self::General(*r);
            };
            if (0..3).any(|m| m != k && col[m].abs() > tol) {
                return Self::General(*r);
            }
            from[i] = k;
            sign[i] = col[k].signum();
        }
        match Order::of(from) {
            Some(Order::O012) if sign == [1.0; 3] => Self::Identity,
            Some(from) => Self::Permutation { from, sign },
            None => Self::General(*r),
        }
    }

    /// `R_parent·O`.
    #[inline]
    fn apply(&self, rp: &Matrix3<f64>) -> Matrix3<f64> {
        match self {
            Self::Identity => *rp,
            Self::Permutation { from, sign } => {
                let [a, b, c] = from.pick([
                    rp.column(0).into_owned(),
                    rp.column(1).into_owned(),
                    rp.column(2).into_owned(),
                ]);
                Matrix3::from_columns(&[sign[0] * a, sign[1] * b, sign[2] * c])
            }
            Self::General(r) => rp * r,
        }
    }
}

/// One joint's constants (made once from the model by [`TreeKin::new`]).
#[derive(Clone, Copy, Debug, PartialEq)]
struct JointConst {
    parent: usize,
    child: usize,
    /// The child's frame in the parent's at zero angle: rotation and
    /// translation.
    rotation: FixedRotation,
    translation: Vector3<f64>,
    axis: AxisKind,
}

impl JointConst {
    fn of(joint: &fbd_robot::Joint) -> Self {
        let r = joint.origin.rotation.to_rotation_matrix().into_inner();
        let u = joint.axis.into_inner();
        let axis = (0..3)
            .find_map(|k| {
                let mut e = Vector3::zeros();
                e[k] = 1.0;
                if u == e {
                    Some(AxisKind::Coordinate { k, sign: 1.0 })
                } else if u == -e {
                    Some(AxisKind::Coordinate { k, sign: -1.0 })
                } else {
                    None
                }
            })
            .unwrap_or(AxisKind::General(u));
        Self {
            parent: joint.parent,
            child: joint.child,
            rotation: FixedRotation::of(&r),
            translation: joint.origin.translation.vector,
            axis,
        }
    }

    /// The factor of the joint angle whose sine and cosine [`Self::turn`]
    /// takes: the sign of a coordinate axis, 1 for any other.
    #[inline]
    fn angle_sign(&self) -> f64 {
        match self.axis {
            AxisKind::Coordinate { sign, .. } => sign,
            AxisKind::General(_) => 1.0,
        }
    }

    /// The child's rotation `F·T(θ)` and the joint's axis `F·u`, with
    /// `F` the parent's rotation times the fixed origin rotation and
    /// `T(θ)` the turn by `θ` about `u`, given `(s, c)` the sine and cosine
    /// of `θ` times [`Self::angle_sign`].
    #[inline]
    fn turn(&self, f: &Matrix3<f64>, (s, c): (f64, f64)) -> (Matrix3<f64>, Vector3<f64>) {
        match self.axis {
            AxisKind::Coordinate { k, sign } => {
                // T turns column a towards column b, (a, b, k) cyclic; the
                // columns are named, not indexed, so that the result stays
                // in registers.
                let (f0, f1, f2) = (
                    f.column(0).into_owned(),
                    f.column(1).into_owned(),
                    f.column(2).into_owned(),
                );
                let turn = |fa: Vector3<f64>, fb: Vector3<f64>| (c * fa + s * fb, c * fb - s * fa);
                let (cols, axis) = match k {
                    0 => {
                        let (a, b) = turn(f1, f2);
                        ([f0, a, b], f0)
                    }
                    1 => {
                        let (a, b) = turn(f2, f0);
                        ([b, f1, a], f1)
                    }
                    _ => {
                        let (a, b) = turn(f0, f1);
                        ([a, b, f2], f2)
                    }
                };
                (Matrix3::from_columns(&cols), sign * axis)
            }
            AxisKind::General(u) => {
                let k = u.cross_matrix();
                let t = Matrix3::identity() + s * k + (1.0 - c) * (k * k);
                (f * t, f * u)
            }
        }
    }
}

impl TreeKin {
    /// A workspace for `model` (every frame at the origin, unrotated,
    /// until [`TreeKin::eval`] fills it).
    ///
    /// # Panics
    /// If the model breaks the conventions of [`fbd_robot::model`]: body 0
    /// has a parent joint, another body has none, a joint's child does not
    /// name it back, or a parent does not come before its child.
    pub fn new(model: &RobotModel) -> Self {
        let nb = model.bodies.len();
        let nj = model.joints.len();
        assert!(nb >= 1, "a model has a root body");
        assert!(
            model.bodies[0].joint.is_none(),
            "the root has no parent joint"
        );
        let mut chain_start = Vec::with_capacity(nb + 1);
        let mut chain = Vec::new();
        let mut max_depth = 0;
        chain_start.push(0);
        chain_start.push(0);
        for (b, body) in model.bodies.iter().enumerate().skip(1) {
            let j = body
                .joint
                .unwrap_or_else(|| panic!("body {b} has no parent joint"));
            let joint = &model.joints[j];
            assert_eq!(joint.child, b, "joint {j} does not turn body {b}");
            let p = joint.parent;
            assert!(p < b, "body {b}'s parent {p} does not come before it");
            let (s, e) = (chain_start[p], chain_start[p + 1]);
            for k in s..e {
                chain.push(chain[k]);
            }
            chain.push(j);
            max_depth = max_depth.max(e - s + 1);
            chain_start.push(chain.len());
        }
        for (j, joint) in model.joints.iter().enumerate() {
            assert_eq!(
                model.bodies[joint.child].joint,
                Some(j),
                "joint {j}'s child"
            );
        }
        let z = Vector3::zeros();
        Self {
            at: vec![0.0; BASE_DOF + nj],
            evaluated: false,
            nq: BASE_DOF + nj,
            chain_start,
            chain,
            max_depth,
            origin: vec![z; nb],
            rotation: vec![Matrix3::identity(); nb],
            com: vec![z; nb],
            axis: vec![z; nj],
            joint_origin: vec![z; nj],
            contact: vec![z; model.contacts.len()],
            contact_center: vec![z; model.contacts.len()],
            contact_radius: model.contacts.iter().map(|c| c.radius).collect(),
            phi_axes: [Vector3::x(), Vector3::y(), Vector3::z()],
            contact_body: model.contacts.iter().map(|c| c.body).collect(),
            joints: model.joints.iter().map(JointConst::of).collect(),
            body_com: model.bodies.iter().map(|b| b.com).collect(),
            contact_local: model.contacts.iter().map(|c| c.position).collect(),
            sin_cos: vec![(0.0, 1.0); nj],
        }
    }

    /// Number of generalised coordinates, `6 + model.joints.len()`.
    pub fn nq(&self) -> usize {
        self.nq
    }

    /// The most joints between the root and a body: a Jacobian has at most
    /// `6 + max_depth()` columns.
    pub fn max_depth(&self) -> usize {
        self.max_depth
    }

    /// The joints between the root and body `b`, root first (so in
    /// increasing order); empty for the root.
    pub fn ancestors(&self, b: usize) -> &[usize] {
        &self.chain[self.chain_start[b]..self.chain_start[b + 1]]
    }

    /// Evaluates every frame, centre of mass, joint axis and contact point
    /// at `q` (module docs for its layout). Does not allocate.
    ///
    /// # Panics
    /// If `q` is not `6 + joints` long or `model` is not the one the
    /// workspace was built for (its counts differ).
    pub fn eval(&mut self, model: &RobotModel, q: &[f64]) {
        assert_eq!(q.len(), self.nq, "q is 6 base coordinates + one per joint");
        assert!(
            model.bodies.len() == self.origin.len()
                && model.joints.len() == self.axis.len()
                && model.contacts.len() == self.contact.len(),
            "the workspace was built for another model"
        );
        // The frames are a function of `q` alone (the model's constants
        // are the workspace's own): at the last evaluation's `q`, bit for
        // bit, they are already here — a robot at rest, whose predicted
        // configuration is the last one, which the workspace handed over
        // at the step before holds.
        if self.evaluated && same_bits(&self.at, q) {
            return;
        }
        self.at.copy_from_slice(q);
        self.evaluated = true;
        let pose = BodyPose::new([q[0], q[1], q[2]], [q[PHI], q[PHI + 1], q[PHI + 2]]);
        let rot = pose.rotation();
        let (sx, cx) = q[PHI].sin_cos();
        // ω = φ̇x·X + φ̇z·Rx·Z + φ̇y·Rx·Rz·Y, and Rx·Rz·Y = Rot·Y.
        self.phi_axes = [
            Vector3::x(),
            rot.column(1).into(),
            Vector3::new(0.0, -sx, cx),
        ];
        self.origin[0] = pose.position;
        self.rotation[0] = rot;
        for ((sc, jc), &theta) in self
            .sin_cos
            .iter_mut()
            .zip(&self.joints)
            .zip(&q[BASE_DOF..])
        {
            *sc = (jc.angle_sign() * theta).sin_cos();
        }
        for ((jc, &sc), (axis, joint_origin)) in self
            .joints
            .iter()
            .zip(&self.sin_cos)
            .zip(self.axis.iter_mut().zip(self.joint_origin.iter_mut()))
        {
            let (p, c) = (jc.parent, jc.child);
            let rp = &self.rotation[p];
            let o = self.origin[p] + rp * jc.translation;
            let (rc, u) = jc.turn(&jc.rotation.apply(rp), sc);
            self.rotation[c] = rc;
            self.origin[c] = o;
            *axis = u;
            *joint_origin = o;
        }
        for (((com, local), o), r) in self
            .com
            .iter_mut()
            .zip(&self.body_com)
            .zip(&self.origin)
            .zip(&self.rotation)
        {
            *com = o + r * local;
        }
        for (k, local) in self.contact_local.iter().enumerate() {
            let b = self.contact_body[k];
            let centre = self.origin[b] + self.rotation[b] * local;
            self.contact_center[k] = centre;
            self.contact[k] = Vector3::new(centre.x, centre.y - self.contact_radius[k], centre.z);
        }
    }

    /// The coordinates of the last [`Self::eval`] (none before the first).
    pub fn evaluated_at(&self) -> Option<&[f64]> {
        self.evaluated.then_some(&self.at[..])
    }

    /// A point given in body `b`'s frame, in the inertial frame (m).
    pub fn body_point(&self, b: usize, local: &Vector3<f64>) -> Vector3<f64> {
        self.origin[b] + self.rotation[b] * local
    }

    /// Jacobian `∂p/∂q` of a point `p` (inertial, at the evaluated `q`)
    /// rigidly attached to body `b`.
    pub fn point_jacobian(&self, b: usize, p: &Vector3<f64>) -> Columns<'_> {
        Columns {
            kin: self,
            joints: self.ancestors(b),
            point: Some(*p),
        }
    }

    /// Jacobian of body `b`'s centre of mass.
    pub fn com_jacobian(&self, b: usize) -> Columns<'_> {
        self.point_jacobian(b, &self.com[b])
    }

    /// Jacobian of contact point `c`: its sphere's centre's (the lowest
    /// point [`Self::contact`] is the centre moved by a constant).
    pub fn contact_jacobian(&self, c: usize) -> Columns<'_> {
        self.point_jacobian(self.contact_body[c], &self.contact_center[c])
    }

    /// Angular-velocity Jacobian of body `b`: `ω_b = Σ col_i·q̇_i`
    /// (inertial).
    pub fn angular_jacobian(&self, b: usize) -> Columns<'_> {
        Columns {
            kin: self,
            joints: self.ancestors(b),
            point: None,
        }
    }
}

/// Whether `a` and `b` hold the same values bit for bit (a zero's sign
/// included: the values a function of them gives are then the same).
pub(crate) fn same_bits(a: &[f64], b: &[f64]) -> bool {
    a.len() == b.len() && a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// A sparse Jacobian with three rows: a point's `∂p/∂q` or a body's
/// angular-velocity Jacobian, as columns `(q index, 3-vector)`; every
/// other column is zero.
///
/// It is a view of a [`TreeKin`], not a copy: it holds the body's list of
/// ancestor joints (made at construction) and computes each column when
/// asked from the evaluated axes and origins (one cross product), so it
/// has room for any depth without allocating, is `Copy`, and can be
/// iterated any number of times. The columns come in increasing `q` index:
/// for a point the base's `e_x, e_y, e_z` (`q` 0–2) and
/// `phi_axes[k] × (p − R)` (`q` 3–5), then `u_j × (p − o_j)` for each
/// ancestor joint `j` (`q` `6 + j`); for an angular Jacobian `phi_axes[k]`
/// (`q` 3–5), then `u_j`. At most `6 + TreeKin::max_depth()` columns.
#[derive(Clone, Copy, Debug)]
pub struct Columns<'a> {
    kin: &'a TreeKin,
    /// The body's ancestor joints.
    joints: &'a [usize],
    /// The point (inertial); `None` for the angular Jacobian.
    point: Option<Vector3<f64>>,
}

impl<'a> Columns<'a> {
    /// The number of columns.
    pub fn len(&self) -> usize {
        self.base_columns() + self.joints.len()
    }

    /// Whether there is no column (never: a body always turns with the
    /// base).
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Columns before the joints': 6 for a point, 3 for an angle.
    #[inline]
    fn base_columns(&self) -> usize {
        if self.point.is_some() { 6 } else { 3 }
    }

    /// Column `k` (`k < len()`): `(q index, ∂/∂q_index)`.
    ///
    /// # Panics
    /// If `k >= len()`.
    #[inline]
    pub fn column(&self, k: usize) -> (usize, Vector3<f64>) {
        let kin = self.kin;
        match self.point {
            Some(p) => match k {
                0..3 => {
                    let mut e = Vector3::zeros();
                    e[k] = 1.0;
                    (k, e)
                }
                3..6 => (k, kin.phi_axes[k - 3].cross(&(p - kin.origin[0]))),
                _ => {
                    let j = self.joints[k - 6];
                    (BASE_DOF + j, kin.axis[j].cross(&(p - kin.joint_origin[j])))
                }
            },
            None => match k {
                0..3 => (PHI + k, kin.phi_axes[k]),
                _ => {
                    let j = self.joints[k - 3];
                    (BASE_DOF + j, kin.axis[j])
                }
            },
        }
    }

    /// Calls `f(q index, column)` for every column, in increasing `q`
    /// index (as [`Self::iter`], without its per-column dispatch).
    #[inline]
    pub fn for_each(&self, mut f: impl FnMut(usize, Vector3<f64>)) {
        let kin = self.kin;
        match self.point {
            Some(p) => {
                f(0, Vector3::x());
                f(1, Vector3::y());
                f(2, Vector3::z());
                let r = p - kin.origin[0];
                for (k, a) in kin.phi_axes.iter().enumerate() {
                    f(PHI + k, a.cross(&r));
                }
                for &j in self.joints {
                    f(BASE_DOF + j, kin.axis[j].cross(&(p - kin.joint_origin[j])));
                }
            }
            None => {
                for (k, a) in kin.phi_axes.iter().enumerate() {
                    f(PHI + k, *a);
                }
                for &j in self.joints {
                    f(BASE_DOF + j, kin.axis[j]);
                }
            }
        }
    }

    /// The columns, in increasing `q` index.
    pub fn iter(&self) -> impl ExactSizeIterator<Item = (usize, Vector3<f64>)> + 'a {
        let this = *self;
        (0..self.len()).map(move |k| this.column(k))
    }

    /// `J·v` for a generalised velocity `v` (`nq` long).
    pub fn apply(&self, v: &[f64]) -> Vector3<f64> {
        self.iter().map(|(i, c)| c * v[i]).sum()
    }

    /// Writes the dense `3 × nq` matrix, row-major, into `out`
    /// (`out.len() == 3·nq`; zero outside the columns).
    ///
    /// # Panics
    /// If `out` is not `3·nq` long.
    pub fn dense_into(&self, out: &mut [f64]) {
        let nq = self.kin.nq;
        assert_eq!(out.len(), 3 * nq, "a 3 × nq matrix");
        out.fill(0.0);
        for (i, c) in self.iter() {
            for r in 0..3 {
                out[r * nq + i] = c[r];
            }
        }
    }
}

//! Kinematics of the spatial model at one configuration: every body's
//! centre of mass and rotation, every point, and their analytic Jacobians
//! with respect to `q` (linear) and `q̇` (angular velocity).

use super::mechanism::{BodyKind, SpatialMechanism, q_joint};
use crate::mechanism::PointKind;
use fbd_kinematics::hexapod::{HexapodConfig, HexapodData, NQ, forward};
use fbd_kinematics::nalgebra::{Matrix3, Vector3};

/// Most columns of a point's or a body's Jacobian: 6 body + 3 joints.
pub const MAX_COLS: usize = 9;

/// Sparse Jacobian of one point or body: `n` columns `(q index, ∂/∂q_i)`.
#[derive(Clone, Copy, Debug)]
pub struct Columns {
    /// Number of columns in use.
    pub n: usize,
    /// `(q index, 3-vector)`.
    pub col: [(usize, Vector3<f64>); MAX_COLS],
}

impl Columns {
    fn new() -> Self {
        Self {
            n: 0,
            col: [(0, Vector3::zeros()); MAX_COLS],
        }
    }
    #[inline]
    fn push(&mut self, i: usize, v: Vector3<f64>) {
        self.col[self.n] = (i, v);
        self.n += 1;
    }
    /// The columns in use.
    #[inline]
    pub fn iter(&self) -> impl Iterator<Item = &(usize, Vector3<f64>)> {
        self.col[..self.n].iter()
    }
    /// `J·v` for a generalised velocity `v`.
    pub fn apply(&self, v: &[f64]) -> Vector3<f64> {
        self.iter().map(|(i, c)| c * v[*i]).sum()
    }
}

/// The spatial kinematics at one `q` (see the module docs).
#[derive(Clone, Debug)]
pub struct SpatialKin {
    /// Full 24-DOF forward kinematics (legs not in the model at zero angles).
    pub fk: HexapodData,
    /// Centre of mass of every body (m).
    pub com: Vec<Vector3<f64>>,
    /// Rotation of every body, body frame → inertial (see
    /// [`super::SpatialBody::inertia`] for the link frames).
    pub rot: Vec<Matrix3<f64>>,
}

impl SpatialKin {
    /// A zeroed workspace for `mech`.
    pub fn new(mech: &SpatialMechanism) -> Self {
        let n = mech.bodies.len();
        Self {
            fk: HexapodData::new(),
            com: vec![Vector3::zeros(); n],
            rot: vec![Matrix3::identity(); n],
        }
    }

    /// Evaluates every point, centre of mass and rotation at `q`.
    pub fn eval(&mut self, mech: &SpatialMechanism, q: &[f64]) {
        let nq = mech.layout().nq;
        assert_eq!(q.len(), nq, "q has the wrong length");
        let mut full = [0.0; NQ];
        full[..6].copy_from_slice(&q[..6]);
        for (s, &leg) in mech.legs.iter().enumerate() {
            for j in 0..3 {
                full[6 + 3 * (leg - 1) + j] = q[q_joint(s, j)];
            }
        }
        forward(&mech.geometry, &HexapodConfig::from_q(&full), &mut self.fk);
        let (a, c) = (mech.geometry.leg().a, mech.geometry.leg().c);
        for (b, body) in mech.bodies.iter().enumerate() {
            match body.kind {
                BodyKind::Central => {
                    self.com[b] = self.fk.body_com;
                    self.rot[b] = self.fk.rotation;
                }
                BodyKind::Upper(s) => {
                    let l = &self.fk.legs[mech.legs[s] - 1];
                    self.com[b] = l.upper_com;
                    let e1 = (l.knee - l.hip) / a;
                    let e3 = l.upper_versor;
                    self.rot[b] = Matrix3::from_columns(&[e1, e3.cross(&e1), e3]);
                }
                BodyKind::Lower(s) => {
                    let l = &self.fk.legs[mech.legs[s] - 1];
                    self.com[b] = l.lower_com;
                    let e1 = (l.tip - l.knee) / c;
                    let e3 = l.lower_versor;
                    self.rot[b] = Matrix3::from_columns(&[e1, e3.cross(&e1), e3]);
                }
            }
        }
    }

    /// Position of `kind` of the leg in slot `s`.
    #[inline]
    pub fn point(&self, mech: &SpatialMechanism, s: usize, kind: PointKind) -> Vector3<f64> {
        let l = &self.fk.legs[mech.legs[s] - 1];
        match kind {
            PointKind::Hip => l.hip,
            PointKind::Knee => l.knee,
            PointKind::Tip => l.tip,
        }
    }

    /// The joint axes `(z0, z1, z2)` of slot `s`.
    #[inline]
    pub fn axes(&self, mech: &SpatialMechanism, s: usize) -> [Vector3<f64>; 3] {
        let l = &self.fk.legs[mech.legs[s] - 1];
        [l.hip_axis, l.upper_versor, l.lower_versor]
    }

    /// Jacobian `∂p/∂q` of a point `p` rigidly attached to the chain up to
    /// `depth` joints of slot `s` (0: the central body, 2: the upper link,
    /// 3: the lower link).
    pub fn point_jacobian(
        &self,
        mech: &SpatialMechanism,
        s: Option<usize>,
        depth: usize,
        p: &Vector3<f64>,
    ) -> Columns {
        let mut j = Columns::new();
        for i in 0..3 {
            let mut e = Vector3::zeros();
            e[i] = 1.0;
            j.push(i, e);
        }
        let r = p - self.fk.body_com;
        for k in 0..3 {
            j.push(3 + k, self.fk.phi_axes[k].cross(&r));
        }
        if let Some(s) = s {
            let l = &self.fk.legs[mech.legs[s] - 1];
            if depth >= 1 {
                j.push(q_joint(s, 0), l.hip_axis.cross(&(p - l.hip)));
            }
            if depth >= 2 {
                j.push(q_joint(s, 1), l.upper_versor.cross(&(p - l.hip)));
            }
            if depth >= 3 {
                j.push(q_joint(s, 2), l.lower_versor.cross(&(p - l.knee)));
            }
        }
        j
    }

    /// Jacobian of the centre of mass of body `b`.
    pub fn com_jacobian(&self, mech: &SpatialMechanism, b: usize) -> Columns {
        let (s, depth) = body_chain(mech, b);
        self.point_jacobian(mech, s, depth, &self.com[b])
    }

    /// Jacobian of contact-able point `kind` of slot `s` (on the body it
    /// belongs to: hips on the central body, knees and tips on the lower
    /// link).
    pub fn contact_jacobian(&self, mech: &SpatialMechanism, s: usize, kind: PointKind) -> Columns {
        let p = self.point(mech, s, kind);
        match kind {
            PointKind::Hip => self.point_jacobian(mech, None, 0, &p),
            _ => self.point_jacobian(mech, Some(s), 3, &p),
        }
    }

    /// Angular-velocity Jacobian of body `b`: `ω = Σ col_i·q̇_i` (inertial).
    pub fn angular_jacobian(&self, mech: &SpatialMechanism, b: usize) -> Columns {
        let mut j = Columns::new();
        for k in 0..3 {
            j.push(3 + k, self.fk.phi_axes[k]);
        }
        let (s, depth) = body_chain(mech, b);
        if let Some(s) = s {
            let l = &self.fk.legs[mech.legs[s] - 1];
            let axes = [l.hip_axis, l.upper_versor, l.lower_versor];
            for (i, axis) in axes.iter().enumerate().take(depth) {
                j.push(q_joint(s, i), *axis);
            }
        }
        j
    }
}

/// The slot and the number of joints between the central body and body `b`.
#[inline]
pub fn body_chain(mech: &SpatialMechanism, b: usize) -> (Option<usize>, usize) {
    match mech.bodies[b].kind {
        BodyKind::Central => (None, 0),
        BodyKind::Upper(s) => (Some(s), 2),
        BodyKind::Lower(s) => (Some(s), 3),
    }
}

//! The spatial mechanism (immutable): the hexapod's central body and, per
//! leg, its upper and lower link; hips, knees, contact points and joint
//! limits; the index layout of one step's unknowns and equations.

use crate::assembly::Dims;
use crate::mechanism::{ContactPoints, ContactSpec, PointKind};
use crate::space::{Space, Space3};
use fbd_kinematics::hexapod::HexapodModel;
use fbd_kinematics::nalgebra::Matrix3;
use fbd_kinematics::{Joint, JointLimits};

/// What a body is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BodyKind {
    /// The central body (floating base).
    Central,
    /// Upper link of the leg in slot `s`.
    Upper(usize),
    /// Lower link of the leg in slot `s`.
    Lower(usize),
}

/// One rigid body of the spatial model.
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialBody {
    /// Name, e.g. `"upper3"`.
    pub name: String,
    /// What it is.
    pub kind: BodyKind,
    /// Mass (kg).
    pub mass: f64,
    /// Inertia tensor about the centre of mass in the body's own frame
    /// (kg·m²): for the central body the body frame of the kinematics, for
    /// a link the frame `(e1, e2, e3)` with `e1` along the link (hip → knee,
    /// knee → tip), `e3` its joint axis `z1` and `e2 = e3 × e1`.
    pub inertia: Matrix3<f64>,
}

/// A joint limit: a one-sided stop on joint `joint` of the leg in `slot`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpatialLimit {
    /// Leg slot (index into [`SpatialMechanism::legs`]).
    pub slot: usize,
    /// θ1, θ2 or θ3.
    pub joint: Joint,
    /// Index in `q`.
    pub q_index: usize,
}

/// Masses and inertias of the spatial model (all legs alike).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpatialInertia {
    /// Central body mass (kg).
    pub body_mass: f64,
    /// Central body inertia in its frame (kg·m²).
    pub body_inertia: Matrix3<f64>,
    /// Upper link mass (kg).
    pub upper_mass: f64,
    /// Upper link inertia about its own axis (kg·m²).
    pub upper_axial: f64,
    /// Upper link inertia about a transverse axis through its CoM (kg·m²).
    pub upper_transverse: f64,
    /// Lower link mass (kg).
    pub lower_mass: f64,
    /// Lower link inertia about its own axis (kg·m²).
    pub lower_axial: f64,
    /// Lower link transverse inertia (kg·m²).
    pub lower_transverse: f64,
}

/// The index layout of one step (see the module docs of
/// [`crate::spatial`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SpatialLayout {
    /// Generalised coordinates, `6 + 3·legs`.
    pub nq: usize,
    /// Legs.
    pub legs: usize,
    /// Bodies, `1 + 2·legs`.
    pub bodies: usize,
    /// Contact points.
    pub contacts: usize,
    /// Joint limits.
    pub limits: usize,
}

impl SpatialLayout {
    /// The generic layout of the assembly ([`crate::assembly::Dims`]): the
    /// one source of where each block of unknowns and equations sits.
    pub fn dims(&self) -> Dims {
        Dims {
            nq: self.nq,
            reaction_unknowns: 9 * self.legs,
            bodies: self.bodies,
            contacts: self.contacts,
            limits: self.limits,
            lin: Space3::LIN,
            ang: Space3::ANG,
        }
    }
    /// Unknowns = equations: `nq + 9·legs + 3·contacts + limits`.
    pub fn dim(&self) -> usize {
        self.dims().dim()
    }
    /// Column of the hip force of slot `s`, component `axis` (x, y, z).
    pub fn hip_force(&self, s: usize, axis: usize) -> usize {
        self.dims().reaction() + 9 * s + axis
    }
    /// Column of the hip's constraint moment (along `z0 × z1`).
    pub fn hip_moment(&self, s: usize) -> usize {
        self.dims().reaction() + 9 * s + 3
    }
    /// Column of the knee force of slot `s`, component `axis`.
    pub fn knee_force(&self, s: usize, axis: usize) -> usize {
        self.dims().reaction() + 9 * s + 4 + axis
    }
    /// Column of the knee's constraint moment `i` (0: along `b1`, 1: `b2`).
    pub fn knee_moment(&self, s: usize, i: usize) -> usize {
        self.dims().reaction() + 9 * s + 7 + i
    }
    /// Column of contact `c`'s force component `i` (0: `t1`, 1: `n`, 2: `t2`).
    pub fn contact_force(&self, c: usize, i: usize) -> usize {
        self.dims().contact_force(c, i)
    }
    /// Column of limit `l`'s stop moment (N·m, towards larger angles).
    pub fn limit_moment(&self, l: usize) -> usize {
        self.dims().limit_moment(l)
    }
    /// First row of body `b` (3 translation rows, then 3 rotation rows).
    pub fn body_row(&self, b: usize) -> usize {
        self.dims().body_row(b)
    }
    /// First row of contact `c`'s three equations.
    pub fn contact_row(&self, c: usize) -> usize {
        self.dims().contact_row(c)
    }
    /// Row of limit `l`.
    pub fn limit_row(&self, l: usize) -> usize {
        self.dims().limit_row(l)
    }
}

/// Index of joint `j` (0–2) of slot `s` in `q`.
#[inline]
pub const fn q_joint(s: usize, j: usize) -> usize {
    6 + 3 * s + j
}

/// Body index of slot `s`'s upper link.
#[inline]
pub const fn upper_body(s: usize) -> usize {
    1 + 2 * s
}

/// Body index of slot `s`'s lower link.
#[inline]
pub const fn lower_body(s: usize) -> usize {
    2 + 2 * s
}

/// The point id of `kind` of slot `s` (`ContactSpec::point`).
#[inline]
pub const fn point_id(s: usize, kind: PointKind) -> usize {
    3 * s
        + match kind {
            PointKind::Hip => 0,
            PointKind::Knee => 1,
            PointKind::Tip => 2,
        }
}

/// The spatial hexapod mechanism.
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialMechanism {
    /// Geometry (body side, link lengths, centres of mass).
    pub geometry: HexapodModel,
    /// Leg numbers (1–6) of the slots, increasing.
    pub legs: Vec<usize>,
    /// Bodies: `[central, upper, lower of slot 0, upper, lower of slot 1, …]`.
    pub bodies: Vec<SpatialBody>,
    /// Contact points: tips of every leg, then knees, then hips (those
    /// enabled); `point` is [`point_id`], `body` the body it belongs to.
    pub contacts: Vec<ContactSpec>,
    /// Joint limits, per slot θ1, θ2, θ3 (those with a finite range).
    pub limits: Vec<SpatialLimit>,
    /// Gravitational acceleration (m/s², along −Y).
    pub gravity: f64,
}

impl SpatialMechanism {
    /// Builds the mechanism of `legs` (numbers 1–6, increasing).
    ///
    /// # Panics
    /// On a leg number outside 1–6 or not increasing (programming errors:
    /// the configuration validates them).
    pub fn new(
        geometry: HexapodModel,
        legs: &[usize],
        inertia: &SpatialInertia,
        gravity: f64,
        points: ContactPoints,
        limits: &JointLimits,
    ) -> Self {
        assert!(
            legs.windows(2).all(|w| w[0] < w[1]) && legs.iter().all(|&l| (1..=6).contains(&l)),
            "legs must be increasing numbers 1–6"
        );
        let mut bodies = vec![SpatialBody {
            name: "body".into(),
            kind: BodyKind::Central,
            mass: inertia.body_mass,
            inertia: inertia.body_inertia,
        }];
        for (s, &n) in legs.iter().enumerate() {
            bodies.push(SpatialBody {
                name: format!("upper{n}"),
                kind: BodyKind::Upper(s),
                mass: inertia.upper_mass,
                inertia: Matrix3::from_diagonal(&fbd_kinematics::nalgebra::Vector3::new(
                    inertia.upper_axial,
                    inertia.upper_transverse,
                    inertia.upper_transverse,
                )),
            });
            bodies.push(SpatialBody {
                name: format!("lower{n}"),
                kind: BodyKind::Lower(s),
                mass: inertia.lower_mass,
                inertia: Matrix3::from_diagonal(&fbd_kinematics::nalgebra::Vector3::new(
                    inertia.lower_axial,
                    inertia.lower_transverse,
                    inertia.lower_transverse,
                )),
            });
        }
        let mut contacts = Vec::new();
        for (on, kind) in [
            (points.tips, PointKind::Tip),
            (points.knees, PointKind::Knee),
            (points.hips, PointKind::Hip),
        ] {
            if !on {
                continue;
            }
            for (s, &n) in legs.iter().enumerate() {
                contacts.push(ContactSpec {
                    name: format!("{}{n}", kind.as_str()),
                    leg: n,
                    kind,
                    body: match kind {
                        PointKind::Hip => 0,
                        _ => lower_body(s),
                    },
                    point: point_id(s, kind),
                });
            }
        }
        let mut lim = Vec::new();
        for s in 0..legs.len() {
            for (j, joint) in [Joint::Theta1, Joint::Theta2, Joint::Theta3]
                .into_iter()
                .enumerate()
            {
                let [lo, hi] = limits.range(joint);
                if lo.is_finite() || hi.is_finite() {
                    lim.push(SpatialLimit {
                        slot: s,
                        joint,
                        q_index: q_joint(s, j),
                    });
                }
            }
        }
        Self {
            geometry,
            legs: legs.to_vec(),
            bodies,
            contacts,
            limits: lim,
            gravity,
        }
    }

    /// The index layout.
    pub fn layout(&self) -> SpatialLayout {
        SpatialLayout {
            nq: 6 + 3 * self.legs.len(),
            legs: self.legs.len(),
            bodies: self.bodies.len(),
            contacts: self.contacts.len(),
            limits: self.limits.len(),
        }
    }

    /// Total mass (kg).
    pub fn total_mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.mass).sum()
    }

    /// A characteristic length (m): hip distance + upper + lower link.
    pub fn length_scale(&self) -> f64 {
        (self.geometry.d() + self.geometry.leg().a + self.geometry.leg().c).max(0.01)
    }
}

//! The mechanism description: rigid bodies, revolute joints and contact
//! points over a planar kinematic tree (immutable, the "Model").

use crate::assembly::Dims;
use crate::rows::NORMAL;
use crate::space::{Plane, Space};
use fbd_kinematics::planar::{PlanarChains, PlanarGeometry, TwoLegIndex};

/// One rigid body.
#[derive(Clone, Debug, PartialEq)]
pub struct BodySpec {
    /// Name, e.g. `"upper3"`.
    pub name: String,
    /// Mass (kg).
    pub mass: f64,
    /// Moment of inertia about the centre of mass, about Z (kg·m²).
    pub inertia: f64,
    /// Point (index into the chains) at the centre of mass.
    pub com: usize,
    /// Angle (index into the chains) giving the body's absolute orientation.
    pub angle: usize,
    /// Z component of the body's rotation versor (+1 or −1, paper §5.2): the
    /// moment equation is projected on it.
    pub versor_z: f64,
}

/// A revolute joint: the parent exerts `+F` on the child at `point`.
#[derive(Clone, Debug, PartialEq)]
pub struct JointSpec {
    /// Name, e.g. `"hip3"`.
    pub name: String,
    /// Parent body index.
    pub parent: usize,
    /// Child body index.
    pub child: usize,
    /// The joint point (index into the chains).
    pub point: usize,
    /// Z component of the joint axis (+1 or −1): a positive joint torque acts
    /// `+axis_z·τ` about Z on the child and `−axis_z·τ` on the parent, and
    /// drives the joint angle towards larger values.
    pub axis_z: f64,
    /// Index in `q` of this joint's angle.
    pub q_index: usize,
    /// Hexapod leg number (1–6) the joint belongs to.
    pub leg: usize,
    /// Which joint of the leg's D-H chain (θ1, θ2 or θ3).
    pub joint: fbd_kinematics::Joint,
}

/// Which point of a leg a contact point is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PointKind {
    /// The foot (the paper's tip).
    Tip,
    /// The knee joint.
    Knee,
    /// The hip joint, on the central body.
    Hip,
}

impl PointKind {
    /// The three kinds, in the order of a leg's contact points in the
    /// mechanism (tips, then knees, then hips).
    pub const ALL: [PointKind; 3] = [PointKind::Tip, PointKind::Knee, PointKind::Hip];

    /// `"tip"`, `"knee"` or `"hip"`, as written to the output files.
    pub fn as_str(self) -> &'static str {
        match self {
            PointKind::Tip => "tip",
            PointKind::Knee => "knee",
            PointKind::Hip => "hip",
        }
    }
}

impl std::fmt::Display for PointKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A point of a body that can touch the terrain.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactSpec {
    /// Name, e.g. `"tip3"` (for messages and column names).
    pub name: String,
    /// Hexapod leg number (1–6) the point belongs to.
    pub leg: usize,
    /// Which point of the leg it is.
    pub kind: PointKind,
    /// The body the point belongs to.
    pub body: usize,
    /// The point (index into the chains).
    pub point: usize,
}

/// Masses and inertias of the two-leg model (both legs alike).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TwoLegInertia {
    /// Central body mass (kg).
    pub body_mass: f64,
    /// Central body inertia about Z through R (kg·m²).
    pub body_inertia: f64,
    /// Upper link mass (kg).
    pub upper_mass: f64,
    /// Upper link inertia about its centre of mass (kg·m²).
    pub upper_inertia: f64,
    /// Lower link mass (kg).
    pub lower_mass: f64,
    /// Lower link inertia about its centre of mass (kg·m²).
    pub lower_inertia: f64,
}

/// Index layout of unknowns and equations of one step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Layout {
    /// Generalised coordinates.
    pub nq: usize,
    /// Bodies.
    pub bodies: usize,
    /// Joints.
    pub joints: usize,
    /// Contact points.
    pub contacts: usize,
    /// Joint limits (one stop moment each).
    pub limits: usize,
}

impl Layout {
    /// The generic layout of the assembly ([`crate::assembly::Dims`]): the
    /// one source of where each block of unknowns and equations sits.
    pub fn dims(&self) -> Dims {
        Dims {
            nq: self.nq,
            reaction_unknowns: 2 * self.joints,
            bodies: self.bodies,
            contacts: self.contacts,
            limits: self.limits,
            lin: Plane::LIN,
            ang: Plane::ANG,
        }
    }
    /// Unknowns = equations.
    pub fn dim(&self) -> usize {
        self.dims().dim()
    }
    /// Column of joint limit `l`'s stop moment (N·m, positive towards
    /// larger joint angles).
    pub fn limit_moment(&self, l: usize) -> usize {
        self.dims().limit_moment(l)
    }
    /// Row of joint limit `l`'s equation.
    pub fn limit_row(&self, l: usize) -> usize {
        self.dims().limit_row(l)
    }
    /// Column of joint `j`'s force component `axis` (0 = x, 1 = y).
    pub fn joint_force(&self, j: usize, axis: usize) -> usize {
        self.dims().reaction() + 2 * j + axis
    }
    /// Column of contact `c`'s tangential force `Fa`.
    pub fn contact_fa(&self, c: usize) -> usize {
        self.dims().contact_force(c, 0)
    }
    /// Column of contact `c`'s normal force `N`.
    pub fn contact_n(&self, c: usize) -> usize {
        self.dims().contact_force(c, NORMAL)
    }
    /// First row of body `b`'s equations (x, y, rotation).
    pub fn body_row(&self, b: usize) -> usize {
        self.dims().body_row(b)
    }
    /// First row of contact `c`'s two equations.
    pub fn contact_row(&self, c: usize) -> usize {
        self.dims().contact_row(c)
    }
}

/// The mechanism: kinematic tree, bodies, joints, contact points, gravity.
#[derive(Clone, Debug, PartialEq)]
pub struct Mechanism {
    /// Planar kinematics of every point and angle.
    pub chains: PlanarChains,
    /// Rigid bodies; body 0 is the floating base.
    pub bodies: Vec<BodySpec>,
    /// Revolute joints.
    pub joints: Vec<JointSpec>,
    /// Contact points.
    pub contacts: Vec<ContactSpec>,
    /// Gravitational acceleration (m/s², acting along −Y).
    pub gravity: f64,
    /// Joints with a limit (indices into `joints`), in order; each adds a
    /// stop moment to the unknowns and an equation ([`Mechanism::with_limits`]).
    pub limits: Vec<usize>,
    /// Structural `q` columns of each point's Jacobian (sorted).
    pub(crate) point_cols: Vec<Vec<usize>>,
}

/// Which points of each leg of the two-leg model can touch the terrain.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ContactPoints {
    /// Feet (always on in the paper).
    pub tips: bool,
    /// Knees.
    pub knees: bool,
    /// Hips.
    pub hips: bool,
}

impl Default for ContactPoints {
    /// Tips, knees and hips: a collapsing robot comes to rest on its knees
    /// and body instead of falling through the ground. (The paper's model
    /// has the tips only; its reported events are those of the tips and do
    /// not change.)
    fn default() -> Self {
        Self {
            tips: true,
            knees: true,
            hips: true,
        }
    }
}

impl Mechanism {
    /// Assembles a mechanism and checks its structure (a tree rooted at body
    /// 0, `nq = 3 + joints`, one body more than joints).
    ///
    /// # Panics
    /// On an inconsistent structure (a programming error, not user input).
    pub fn new(
        chains: PlanarChains,
        bodies: Vec<BodySpec>,
        joints: Vec<JointSpec>,
        contacts: Vec<ContactSpec>,
        gravity: f64,
    ) -> Self {
        assert_eq!(
            bodies.len(),
            joints.len() + 1,
            "a planar tree has one body more than joints"
        );
        assert_eq!(
            chains.nq,
            3 + joints.len(),
            "nq must be 3 + number of joints"
        );
        for j in &joints {
            assert!(
                j.parent < bodies.len() && j.child < bodies.len() && j.point < chains.points.len()
            );
        }
        for c in &contacts {
            assert!(c.body < bodies.len() && c.point < chains.points.len());
        }
        let point_cols = chains
            .points
            .iter()
            .map(|p| {
                let mut cols = vec![0, 1];
                for &(a, _) in &p.segments {
                    cols.extend(chains.angles[a].terms.iter().map(|&(i, _)| i));
                }
                cols.sort_unstable();
                cols.dedup();
                cols
            })
            .collect();
        Self {
            chains,
            bodies,
            joints,
            contacts,
            gravity,
            limits: Vec::new(),
            point_cols,
        }
    }

    /// The mechanism with a joint limit (a one-sided stop, see
    /// `fbd_dynamics::assemble`) on each of `joints` (indices into
    /// [`Mechanism::joints`]).
    ///
    /// # Panics
    /// On an unknown or repeated joint index.
    pub fn with_limits(mut self, joints: Vec<usize>) -> Self {
        for (i, &j) in joints.iter().enumerate() {
            assert!(j < self.joints.len(), "no joint {j}");
            assert!(!joints[..i].contains(&j), "joint {j} limited twice");
        }
        self.limits = joints;
        self
    }

    /// The paper's planar model: central body, legs 3 and 4 (docs/reference.md).
    /// Bodies `[body, upper3, lower3, upper4, lower4]`; joints
    /// `[hip3, knee3, hip4, knee4]`; contacts in the order tips (3, 4), knees
    /// (3, 4), hips (3, 4) for those enabled.
    pub fn two_leg(
        geometry: &PlanarGeometry,
        inertia: &TwoLegInertia,
        gravity: f64,
        points: ContactPoints,
    ) -> (Self, TwoLegIndex) {
        use fbd_kinematics::planar::{hexapod_leg_number, side_sign, theta2_index, theta3_index};
        let (chains, ix) = PlanarChains::two_leg(geometry);
        let mut bodies = vec![BodySpec {
            name: "body".into(),
            mass: inertia.body_mass,
            inertia: inertia.body_inertia,
            com: ix.body_com,
            angle: ix.body_angle,
            versor_z: 1.0,
        }];
        let mut joints = Vec::new();
        for leg in 0..2 {
            let n = hexapod_leg_number(leg);
            // Leg 3's joint axes are +Z, leg 4's −Z (paper §5.2).
            let axis = -side_sign(leg);
            let upper = bodies.len();
            bodies.push(BodySpec {
                name: format!("upper{n}"),
                mass: inertia.upper_mass,
                inertia: inertia.upper_inertia,
                com: ix.upper_com[leg],
                angle: ix.upper_angle[leg],
                versor_z: axis,
            });
            bodies.push(BodySpec {
                name: format!("lower{n}"),
                mass: inertia.lower_mass,
                inertia: inertia.lower_inertia,
                com: ix.lower_com[leg],
                angle: ix.lower_angle[leg],
                versor_z: axis,
            });
            joints.push(JointSpec {
                name: format!("hip{n}"),
                parent: 0,
                child: upper,
                point: ix.hip[leg],
                axis_z: axis,
                q_index: theta2_index(leg),
                leg: n,
                joint: fbd_kinematics::Joint::Theta2,
            });
            joints.push(JointSpec {
                name: format!("knee{n}"),
                parent: upper,
                child: upper + 1,
                point: ix.knee[leg],
                axis_z: axis,
                q_index: theta3_index(leg),
                leg: n,
                joint: fbd_kinematics::Joint::Theta3,
            });
        }
        let mut contacts = Vec::new();
        let groups: [(bool, PointKind, [usize; 2], [usize; 2]); 3] = [
            (points.tips, PointKind::Tip, ix.tip, [2, 4]),
            (points.knees, PointKind::Knee, ix.knee, [2, 4]),
            (points.hips, PointKind::Hip, ix.hip, [0, 0]),
        ];
        for (on, kind, pts, body) in groups {
            if on {
                for leg in 0..2 {
                    contacts.push(ContactSpec {
                        name: format!("{}{}", kind.as_str(), hexapod_leg_number(leg)),
                        leg: hexapod_leg_number(leg),
                        kind,
                        body: body[leg],
                        point: pts[leg],
                    });
                }
            }
        }
        (Self::new(chains, bodies, joints, contacts, gravity), ix)
    }

    /// The index layout of one step's unknowns and equations.
    pub fn layout(&self) -> Layout {
        Layout {
            nq: self.chains.nq,
            bodies: self.bodies.len(),
            joints: self.joints.len(),
            contacts: self.contacts.len(),
            limits: self.limits.len(),
        }
    }

    /// Total mass (kg).
    pub fn total_mass(&self) -> f64 {
        self.bodies.iter().map(|b| b.mass).sum()
    }

    /// A characteristic length (m): the sum of all segment lengths of the
    /// longest point chain, at least 1 cm.
    pub fn length_scale(&self) -> f64 {
        self.chains
            .points
            .iter()
            .map(|p| p.segments.iter().map(|s| s.1.abs()).sum::<f64>())
            .fold(0.01, f64::max)
    }

    /// Structural `q` columns of point `p`'s Jacobian.
    pub fn point_columns(&self, p: usize) -> &[usize] {
        &self.point_cols[p]
    }
}

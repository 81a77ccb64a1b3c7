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

/// Masses and inertias (about Z) of the two-leg model's bodies: those of
/// its D-H instance in the plane (`fbd_robot::dh::planar`).
pub use fbd_robot::dh::PlanarMasses as TwoLegInertia;

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

    /// The mechanism of a robot model in the plane (`fbd_robot`: every
    /// joint axis along `±Z`, every joint origin, centre of mass and
    /// contact point at `z = 0`; e.g. the paper's planar model,
    /// `fbd_robot::dh::planar`), with the contact points `contacts`
    /// (indices into `robot.contacts`, in the order of their unknowns) as
    /// contact points, under `gravity`. Its coordinates are `q = (Rx, Ry,
    /// φz, θ per joint)`, the root's frame at `(Rx, Ry)` turned by `φz`.
    ///
    /// Each body's planar frame is an angle linear in `q` and an origin
    /// point; each body's angle (of its rotation row) is its frame's,
    /// projected on its joint's axis (the root's on `+Z`); a joint's
    /// point is its origin; the points are named as the model names them
    /// (a body's origin as its joint, or as the root body, its centre of
    /// mass `{body}_com`, a contact point by its name). Angle offsets are
    /// kept in `(−π, π]`, and within 1e-12 rad of a quarter turn they are
    /// that quarter turn exactly; points at the same place of a body are
    /// one point (a knee joint and a knee contact point), named by the
    /// first. A joint named `theta{k}_{n}`, `hip{n}` (θ2) or `knee{n}`
    /// (θ3) is that joint of leg `n`, a contact point named `tip{n}`
    /// (`knee{n}`, `hip{n}`) that point of leg `n` (others: leg 0, `θ2`, a
    /// tip).
    ///
    /// # Errors
    /// A description of what is not in the plane.
    pub fn in_plane(
        robot: &fbd_robot::RobotModel,
        contacts: &[usize],
        gravity: f64,
    ) -> Result<Self, String> {
        use fbd_kinematics::planar::{LinearAngle, PHI_Z, PointDef};
        use fbd_robot::nalgebra::Vector3;
        const TOL: f64 = 1e-12;
        let snap = |offset: f64| {
            use std::f64::consts::{FRAC_PI_2, PI};
            let mut a = offset;
            if a > PI {
                a -= 2.0 * PI;
            } else if a <= -PI {
                a += 2.0 * PI;
            }
            let k = (a / FRAC_PI_2).round();
            if (a - k * FRAC_PI_2).abs() < TOL {
                a = match k as i64 {
                    0 => 0.0,
                    1 => FRAC_PI_2,
                    -1 => -FRAC_PI_2,
                    _ => PI,
                };
            }
            a
        };
        let in_plane = |what: &str, v: &Vector3<f64>| {
            if v.z.abs() > TOL {
                Err(format!("{what} is off the plane z = 0 (z = {:e})", v.z))
            } else {
                Ok(())
            }
        };
        let mut angles: Vec<LinearAngle> = Vec::new();
        // An angle's index, the same for equal angles.
        fn intern(angles: &mut Vec<LinearAngle>, a: LinearAngle) -> usize {
            match angles.iter().position(|b| *b == a) {
                Some(i) => i,
                None => {
                    angles.push(a);
                    angles.len() - 1
                }
            }
        }
        let mut points: Vec<PointDef> = Vec::new();
        // A point's index, the same for the same segments.
        fn place(points: &mut Vec<PointDef>, name: String, segments: Vec<(usize, f64)>) -> usize {
            match points.iter().position(|p| p.segments == segments) {
                Some(i) => i,
                None => {
                    points.push(PointDef { name, segments });
                    points.len() - 1
                }
            }
        }
        let mut frame_angle: Vec<LinearAngle> = Vec::with_capacity(robot.bodies.len());
        let mut mirror: Vec<f64> = Vec::with_capacity(robot.bodies.len());
        let mut origin: Vec<Vec<(usize, f64)>> = Vec::with_capacity(robot.bodies.len());
        // The segments of a point of a body: its frame's origin's (`base`),
        // then `local` turned into the frame (`m = −1`: its z is −Z).
        let segment = |angles: &mut Vec<LinearAngle>,
                       frame: &LinearAngle,
                       m: f64,
                       base: &[(usize, f64)],
                       local: &Vector3<f64>| {
            let mut segs = base.to_vec();
            let len = local.x.hypot(local.y);
            if len > 0.0 {
                let dir = (m * local.y + 0.0).atan2(local.x);
                let a = LinearAngle {
                    offset: snap(frame.offset + dir),
                    terms: frame.terms.clone(),
                };
                segs.push((intern(angles, a), len));
            }
            segs
        };
        let nq = 3 + robot.joints.len();
        let mut bodies = Vec::with_capacity(robot.bodies.len());
        let mut joints = Vec::with_capacity(robot.joints.len());
        for (b, body) in robot.bodies.iter().enumerate() {
            let (frame, m, base, versor, name) = match body.joint {
                None => {
                    if b != 0 {
                        return Err(format!("body {}: a second root", body.name));
                    }
                    let frame = LinearAngle {
                        offset: 0.0,
                        terms: vec![(PHI_Z, 1.0)],
                    };
                    (frame, 1.0, Vec::new(), 1.0, body.name.clone())
                }
                Some(j) => {
                    let joint = &robot.joints[j];
                    let p = joint.parent;
                    let t = joint.origin.translation.vector;
                    in_plane(&format!("joint {}'s origin", joint.name), &t)?;
                    let r = joint.origin.rotation.to_rotation_matrix();
                    let z = r.matrix().column(2).into_owned();
                    if z.x.hypot(z.y) > TOL {
                        return Err(format!(
                            "joint {}'s frame is not turned about Z",
                            joint.name
                        ));
                    }
                    let axis = joint.axis.into_inner();
                    if axis.x.hypot(axis.y) > TOL {
                        return Err(format!("joint {}'s axis is not along Z", joint.name));
                    }
                    let (mp, fp) = (mirror[p], frame_angle[p].clone());
                    let base = segment(&mut angles, &fp, mp, &origin[p], &t);
                    let m = mp * z.z.signum();
                    let beta = r.matrix()[(1, 0)].atan2(r.matrix()[(0, 0)]);
                    let coef = m * axis.z.signum();
                    let mut terms = fp.terms.clone();
                    terms.push((3 + j, coef));
                    let frame = LinearAngle {
                        offset: snap(fp.offset + mp * beta),
                        terms,
                    };
                    (frame, m, base, coef, joint.name.clone())
                }
            };
            let origin_point = place(&mut points, name, base.clone());
            in_plane(&format!("body {}'s centre of mass", body.name), &body.com)?;
            let segs = segment(&mut angles, &frame, m, &base, &body.com);
            let com = place(&mut points, format!("{}_com", body.name), segs);
            bodies.push(BodySpec {
                name: body.name.clone(),
                mass: body.mass,
                inertia: body.inertia[(2, 2)],
                com,
                angle: intern(&mut angles, frame.clone()),
                versor_z: versor,
            });
            if let Some(j) = body.joint {
                let joint = &robot.joints[j];
                let (leg, kind) = leg_joint(&joint.name);
                joints.push(JointSpec {
                    name: joint.name.clone(),
                    parent: joint.parent,
                    child: b,
                    point: origin_point,
                    axis_z: versor,
                    q_index: 3 + j,
                    leg,
                    joint: kind,
                });
            }
            frame_angle.push(frame);
            mirror.push(m);
            origin.push(base);
        }
        let mut contact_point = Vec::with_capacity(robot.contacts.len());
        for c in &robot.contacts {
            in_plane(&format!("contact point {}", c.name), &c.position)?;
            if c.radius != 0.0 {
                return Err(format!(
                    "contact point {}: a sphere (the plane has points)",
                    c.name
                ));
            }
            let segs = segment(
                &mut angles,
                &frame_angle[c.body],
                mirror[c.body],
                &origin[c.body],
                &c.position,
            );
            contact_point.push(place(&mut points, c.name.clone(), segs));
        }
        let contacts = contacts
            .iter()
            .map(|&c| {
                let point = &robot.contacts[c];
                let (leg, kind) = leg_point(&point.name);
                ContactSpec {
                    name: point.name.clone(),
                    leg,
                    kind,
                    body: point.body,
                    point: contact_point[c],
                }
            })
            .collect();
        let chains = PlanarChains::new(nq, angles, points);
        Ok(Self::new(chains, bodies, joints, contacts, gravity))
    }

    /// The paper's planar model written out by hand: central body, legs 3
    /// and 4 (docs/reference.md). The runs build it as an instance of the
    /// generic robot model in the plane ([`Mechanism::in_plane`] of
    /// `fbd_robot::dh::planar`), which is this mechanism to the bit
    /// (`crates/fbd/tests/planar_instance.rs`); this one is the tests'
    /// reference.
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

/// Leg `n` and joint `k` of a joint named `theta{k}_{n}`, `hip{n}` (θ2)
/// or `knee{n}` (θ3) (leg 0, θ2 otherwise).
fn leg_joint(name: &str) -> (usize, fbd_kinematics::Joint) {
    use fbd_kinematics::Joint;
    for (prefix, joint) in [("hip", Joint::Theta2), ("knee", Joint::Theta3)] {
        if let Some(n) = name.strip_prefix(prefix).and_then(|n| n.parse().ok()) {
            return (n, joint);
        }
    }
    let parsed = name.strip_prefix("theta").and_then(|rest| {
        let (k, n) = rest.split_once('_')?;
        let joint = match k {
            "1" => Joint::Theta1,
            "2" => Joint::Theta2,
            "3" => Joint::Theta3,
            _ => return None,
        };
        Some((n.parse().ok()?, joint))
    });
    parsed.unwrap_or((0, Joint::Theta2))
}

/// Leg `n` and kind of a contact point named `tip{n}`, `knee{n}` or
/// `hip{n}` (leg 0, a tip otherwise).
fn leg_point(name: &str) -> (usize, PointKind) {
    PointKind::ALL
        .into_iter()
        .find_map(|kind| Some((name.strip_prefix(kind.as_str())?.parse().ok()?, kind)))
        .unwrap_or((0, PointKind::Tip))
}

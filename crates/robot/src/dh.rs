//! Models from Denavit–Hartenberg rows, and the paper's hexapod as one
//! instance of [`RobotModel`] built from its D-H parameters (paper eqs.
//! 1–5, docs/reference.md).
//!
//! A row `(d, a, α)` of joint `k` is the transform
//! `Rz(θk)·Tz(d)·Tx(a)·Rx(α)` from D-H frame `k−1` to frame `k`. In the
//! model, joint `k` turns body `k` about its own `z` and body `k`'s frame is
//! frame `k−1` turned by `θk`: the fixed part `Tz(d)·Tx(a)·Rx(α)` of row `k`
//! is then the origin of joint `k+1` in body `k` (and the chain's end, for
//! the last row).

use nalgebra::{Isometry3, Matrix3, Translation3, Unit, UnitQuaternion, Vector3};

use fbd_kinematics::body::{GAMMA_DEG, LegMount, hip_distance};

use crate::model::{Actuator, Body, ContactPoint, Joint, JointLimits, RobotModel};

/// One D-H joint and the body it turns.
#[derive(Clone, Debug, PartialEq)]
pub struct DhRow {
    /// The joint's name.
    pub joint: String,
    /// `d` (m).
    pub d: f64,
    /// `a` (m).
    pub a: f64,
    /// `α` (rad).
    pub alpha: f64,
    /// The joint's limits (`None`: continuous).
    pub limits: Option<JointLimits>,
    /// The body it turns (its `joint` field is set by [`add_chain`]); its
    /// centre of mass and inertia in the frame `frame k−1 · Rz(θk)`.
    pub body: Body,
}

/// The fixed part `Tz(d)·Tx(a)·Rx(α)` of a row.
fn row_end(d: f64, a: f64, alpha: f64) -> Isometry3<f64> {
    Isometry3::from_parts(
        Translation3::new(a, 0.0, d),
        UnitQuaternion::from_axis_angle(&Vector3::x_axis(), alpha),
    )
}

/// Appends the chain `rows` to `model`, its D-H frame 0 at `base` in body
/// `parent`. Returns the new bodies' indices and the chain's end frame in
/// the last body.
pub fn add_chain(
    model: &mut RobotModel,
    parent: usize,
    base: Isometry3<f64>,
    rows: &[DhRow],
) -> (Vec<usize>, Isometry3<f64>) {
    let mut origin = base;
    let mut from = parent;
    let mut bodies = Vec::with_capacity(rows.len());
    for row in rows {
        let b = model.bodies.len();
        model.joints.push(Joint {
            name: row.joint.clone(),
            parent: from,
            child: b,
            origin,
            axis: Unit::new_normalize(Vector3::z()),
            limits: row.limits,
            effort: None,
            velocity: None,
        });
        model.bodies.push(Body {
            joint: Some(model.joints.len() - 1),
            ..row.body.clone()
        });
        origin = row_end(row.d, row.a, row.alpha);
        from = b;
        bodies.push(b);
    }
    (bodies, origin)
}

/// Masses and inertias of the paper's hexapod (as `[body]` and `[leg]`
/// of a configuration; defaults as `fbd_sim::spatial::SpatialParams`).
#[derive(Clone, Debug, PartialEq)]
pub struct HexapodMasses {
    /// Central body mass (kg). Default 10.
    pub body_mass: f64,
    /// Central body inertia about its centre of mass, body axes,
    /// `[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]` (kg·m²). Default the hexagonal
    /// plate of side 0.25 m: `(0.1953125, 0.390625, 0.1953125, 0, 0, 0)`.
    pub body_inertia: [f64; 6],
    /// Upper link mass (kg). Default 0.3.
    pub upper_mass: f64,
    /// Upper link radius (m): `m·r²/2` about the link. Default 0.02.
    pub upper_radius: f64,
    /// Upper link inertia across the link at its centre of mass (kg·m²).
    /// Default the solid cylinder `m·(3r² + a²)/12` for a = 0.2 m.
    pub upper_inertia: f64,
    /// Lower link mass (kg). Default 1.1.
    pub lower_mass: f64,
    /// Lower link radius (m). Default 0.015.
    pub lower_radius: f64,
    /// Lower link inertia across the link (kg·m²). Default the solid
    /// cylinder for c = 0.42 m.
    pub lower_inertia: f64,
}

impl Default for HexapodMasses {
    fn default() -> Self {
        let cyl = |m: f64, r: f64, l: f64| m * (3.0 * r * r + l * l) / 12.0;
        let i = 5.0 / 16.0 * 10.0 * 0.25 * 0.25;
        Self {
            body_mass: 10.0,
            body_inertia: [i, 2.0 * i, i, 0.0, 0.0, 0.0],
            upper_mass: 0.3,
            upper_radius: 0.02,
            upper_inertia: cyl(0.3, 0.02, 0.2),
            lower_mass: 1.1,
            lower_radius: 0.015,
            lower_inertia: cyl(1.1, 0.015, 0.42),
        }
    }
}

/// Which legs and points the hexapod instance has.
#[derive(Clone, Debug, PartialEq)]
pub struct HexapodLayout {
    /// Leg numbers (1–6), increasing. Default all six.
    pub legs: Vec<usize>,
    /// Limits of `(θ1, θ2, θ3)` (`None`: continuous). Default none.
    pub limits: [Option<JointLimits>; 3],
    /// Tips (feet) are contact points. Default true.
    pub tips: bool,
    /// Knees are contact points. Default true.
    pub knees: bool,
    /// Hips are contact points. Default true.
    pub hips: bool,
}

impl Default for HexapodLayout {
    fn default() -> Self {
        Self {
            legs: (1..=6).collect(),
            limits: [None; 3],
            tips: true,
            knees: true,
            hips: true,
        }
    }
}

/// One actuator per joint of `model`, named as the joint, without an
/// effort limit.
fn actuate_every_joint(model: &mut RobotModel) {
    model.actuators = (0..model.joints.len())
        .map(|j| Actuator {
            name: model.joints[j].name.clone(),
            joint: j,
            effort_limit: None,
        })
        .collect();
}

/// A body with mass `m`, centre of mass `com` and diagonal inertia.
fn body(name: String, m: f64, com: Vector3<f64>, diag: [f64; 3]) -> Body {
    Body {
        name,
        mass: m,
        com,
        inertia: Matrix3::from_diagonal(&Vector3::from(diag)),
        joint: None,
    }
}

/// The paper's hexapod as a [`RobotModel`]: the central body (`body`, its
/// frame fbd's body frame with the origin at its centre of mass), and per
/// leg `n` the D-H chain of eqs. (1)–(3) mounted by eq. (5):
///
/// | joint | `d` | `a` | `α` | body | mass, centre of mass |
/// |---|---|---|---|---|---|
/// | `theta1_n` | 0 | 0 | 90° | `coxa{n}` | none (the two-axis hip) |
/// | `theta2_n` | 0 | −a | 0 | `upper{n}` | at `(−a·upper_com, 0, 0)` |
/// | `theta3_n` | 0 | c | 0 | `lower{n}` | at `(c·lower_com, 0, 0)` |
///
/// Link inertias are `m·r²/2` about the link (`x`) and the given
/// transverse inertia across it, as `fbd export mjcf` writes them.
/// Contact points: `tip{n}` at `(c, 0, 0)` of the lower link, `knee{n}` at
/// its origin, `hip{n}` on the central body at the hip; one actuator per joint,
/// named as the joint. Joint names are `trajectory.csv`'s columns.
pub fn hexapod(
    geometry: &fbd_kinematics::hexapod::HexapodModel,
    masses: &HexapodMasses,
    layout: &HexapodLayout,
) -> RobotModel {
    let bi = masses.body_inertia;
    let mut model = RobotModel {
        name: "hexapod".to_owned(),
        bodies: vec![Body {
            name: "body".to_owned(),
            mass: masses.body_mass,
            com: Vector3::zeros(),
            inertia: Matrix3::new(
                bi[0], bi[3], bi[4], //
                bi[3], bi[1], bi[5], //
                bi[4], bi[5], bi[2],
            ),
            joint: None,
        }],
        joints: Vec::new(),
        contacts: Vec::new(),
        actuators: Vec::new(),
    };
    let (a, c) = (geometry.leg().a, geometry.leg().c);
    let d = hip_distance(geometry.side());
    let m = masses;
    for &n in &layout.legs {
        let mount = LegMount::new(GAMMA_DEG[n - 1].to_radians(), d);
        let base = Isometry3::from_parts(
            Translation3::from(mount.hip),
            UnitQuaternion::from_rotation_matrix(&nalgebra::Rotation3::from_matrix_unchecked(
                mount.rotation(),
            )),
        );
        let rows = [
            DhRow {
                joint: format!("theta1_{n}"),
                d: 0.0,
                a: 0.0,
                alpha: std::f64::consts::FRAC_PI_2,
                limits: layout.limits[0],
                body: body(format!("coxa{n}"), 0.0, Vector3::zeros(), [0.0; 3]),
            },
            DhRow {
                joint: format!("theta2_{n}"),
                d: 0.0,
                a: -a,
                alpha: 0.0,
                limits: layout.limits[1],
                body: body(
                    format!("upper{n}"),
                    m.upper_mass,
                    Vector3::new(-a * geometry.upper_com(), 0.0, 0.0),
                    [
                        m.upper_mass * m.upper_radius * m.upper_radius / 2.0,
                        m.upper_inertia,
                        m.upper_inertia,
                    ],
                ),
            },
            DhRow {
                joint: format!("theta3_{n}"),
                d: 0.0,
                a: c,
                alpha: 0.0,
                limits: layout.limits[2],
                body: body(
                    format!("lower{n}"),
                    m.lower_mass,
                    Vector3::new(c * geometry.lower_com(), 0.0, 0.0),
                    [
                        m.lower_mass * m.lower_radius * m.lower_radius / 2.0,
                        m.lower_inertia,
                        m.lower_inertia,
                    ],
                ),
            },
        ];
        let (bodies, end) = add_chain(&mut model, 0, base, &rows);
        let point = |name: String, body: usize, position: Vector3<f64>| ContactPoint {
            name,
            body,
            position,
            radius: 0.0,
        };
        if layout.tips {
            model
                .contacts
                .push(point(format!("tip{n}"), bodies[2], end.translation.vector));
        }
        if layout.knees {
            model
                .contacts
                .push(point(format!("knee{n}"), bodies[2], Vector3::zeros()));
        }
        if layout.hips {
            // On the central body, as in the spatial model (a hip cannot
            // move against the body it is mounted on).
            model.contacts.push(point(format!("hip{n}"), 0, mount.hip));
        }
    }
    actuate_every_joint(&mut model);
    model
}

/// Masses and inertias of the paper's planar model (as `[body]` and
/// `[leg]` of a planar configuration): each body's inertia about `Z`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlanarMasses {
    /// Central body mass (kg).
    pub body_mass: f64,
    /// Central body inertia about `Z` (kg·m²).
    pub body_inertia: f64,
    /// Upper link mass (kg).
    pub upper_mass: f64,
    /// Upper link inertia about `Z` at its centre of mass (kg·m²).
    pub upper_inertia: f64,
    /// Lower link mass (kg).
    pub lower_mass: f64,
    /// Lower link inertia about `Z` at its centre of mass (kg·m²).
    pub lower_inertia: f64,
}

/// The paper's planar model (its legs 3 and 4 in the `X–Y` plane, θ1 = 0)
/// as a [`RobotModel`] in the plane: every joint axis along `±Z`, every
/// frame origin, centre of mass and point at `z = 0`, so that it is
/// stepped by the planar FBD equations (`fbd_dynamics::Mechanism::in_plane`).
///
/// The central body `body` (its frame at its centre of mass); per leg `n`
/// (3 and 4, on the side `s = −1`, `+1` of the body: the hip at
/// `(s·d, 0, 0)`) the joints `hip{n}` (θ2) and `knee{n}` (θ3), named as
/// the planar run's columns name them (`hip3_fx`, `tau_hip3`, …), each
/// about `Z·(−s)` (leg 3's axes `+Z`, leg 4's `−Z`, paper §5.2), and the
/// links `upper{n}` and `lower{n}`, each with its frame's `x` along the
/// link (hip → knee, knee → tip: their angles are the links' absolute
/// angles) and its centre of mass on it; the points `tip{n}` (the lower
/// link's end), `knee{n}` and `hip{n}` (on the central body). Each body's
/// inertia tensor is isotropic with the planar value (only its `Z` part
/// acts in the plane).
pub fn planar(
    geometry: &fbd_kinematics::planar::PlanarGeometry,
    masses: &PlanarMasses,
) -> RobotModel {
    use fbd_kinematics::planar::{hexapod_leg_number, side_sign};
    use std::f64::consts::PI;
    let iso = |m: f64, com: Vector3<f64>, i: f64, name: String| Body {
        name,
        mass: m,
        com,
        inertia: Matrix3::from_diagonal_element(i),
        joint: None,
    };
    let mut model = RobotModel {
        name: "planar".to_owned(),
        bodies: vec![iso(
            masses.body_mass,
            Vector3::zeros(),
            masses.body_inertia,
            "body".to_owned(),
        )],
        joints: Vec::new(),
        contacts: Vec::new(),
        actuators: Vec::new(),
    };
    let g = geometry;
    let turn = |angle: f64| {
        Isometry3::from_parts(
            Translation3::identity(),
            UnitQuaternion::from_axis_angle(&Vector3::z_axis(), angle),
        )
    };
    for leg in 0..2 {
        let (s, n) = (side_sign(leg), hexapod_leg_number(leg));
        let axis = Unit::new_normalize(Vector3::new(0.0, 0.0, -s));
        // The upper link's x along hip → knee at θ2 = 0 (outwards), the
        // lower link's along knee → tip (turned back by π from it).
        let hip = Translation3::new(s * g.d, 0.0, 0.0) * turn(if s < 0.0 { PI } else { 0.0 });
        let knee = Translation3::new(g.a, 0.0, 0.0) * turn(PI);
        let upper = model.bodies.len();
        for (joint, parent, origin, body) in [
            (
                format!("hip{n}"),
                0,
                hip,
                iso(
                    masses.upper_mass,
                    Vector3::new(g.a * g.upper_com, 0.0, 0.0),
                    masses.upper_inertia,
                    format!("upper{n}"),
                ),
            ),
            (
                format!("knee{n}"),
                upper,
                knee,
                iso(
                    masses.lower_mass,
                    Vector3::new(g.c * g.lower_com, 0.0, 0.0),
                    masses.lower_inertia,
                    format!("lower{n}"),
                ),
            ),
        ] {
            model.joints.push(Joint {
                name: joint,
                parent,
                child: model.bodies.len(),
                origin,
                axis,
                limits: None,
                effort: None,
                velocity: None,
            });
            model.bodies.push(Body {
                joint: Some(model.joints.len() - 1),
                ..body
            });
        }
        let point = |name: String, body: usize, position: Vector3<f64>| ContactPoint {
            name,
            body,
            position,
            radius: 0.0,
        };
        model.contacts.extend([
            point(format!("tip{n}"), upper + 1, Vector3::new(g.c, 0.0, 0.0)),
            point(format!("knee{n}"), upper + 1, Vector3::zeros()),
            point(format!("hip{n}"), 0, Vector3::new(s * g.d, 0.0, 0.0)),
        ]);
    }
    actuate_every_joint(&mut model);
    model
}

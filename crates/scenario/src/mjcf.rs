//! The spatial hexapod as a MuJoCo model (MJCF XML), for cross-checks in
//! MuJoCo: `fbd export mjcf CONFIG`.
//!
//! The model is the robot of [`SpatialParams`], written so that MuJoCo's
//! coordinates *are* fbd's:
//!
//! * the inertial frame is fbd's (`Y` up, `gravity = (0, −g, 0)`);
//! * the central body's frame is fbd's body frame, its origin the centre of
//!   mass, with a free joint (`qpos` = `(R, quaternion of Rot)`, where
//!   `Rot = Rx(φx)·Rz(φz)·Ry(φy)`); mass and full inertia tensor
//!   (`body_inertia`, body frame);
//! * per leg one body for the upper link, at the hip, oriented as D-H frame
//!   1 at θ1 = 0 (`cA0i·Rx(90°)`) and carrying two hinges through the hip:
//!   θ1 about the local `y` (that is `z0`, the body's vertical) and θ2
//!   about the local `z` (`z1`). MuJoCo composes a body's joints like a
//!   D-H chain (`R = R0·Rot(y, θ1)·Rot(z, θ2)`), so the upper body's frame
//!   is D-H frame 2 placed at the hip: the link lies along its `−x`, the
//!   knee at `(−a, 0, 0)`;
//! * the lower link is a child body at the knee with the θ3 hinge about
//!   its `z` (`z2`): its frame is D-H frame 3 at the knee, the tip at
//!   `(c, 0, 0)`;
//! * every hinge's `qpos` is fbd's angle itself (zero where fbd's is zero);
//!   joint names are the `trajectory.csv` columns (`theta2_4`), ranges the
//!   joint limits (MuJoCo's soft limits instead of fbd's plastic stops);
//! * link masses at their centre-of-mass fractions, solid-cylinder
//!   inertias: `m·r²/2` about the link, `upper_inertia` / `lower_inertia`
//!   across it;
//! * contact: a sphere of radius [`SPHERE_RADIUS`] centred on each enabled
//!   contact point (tips always; knees and hips when `contact_points` has
//!   them). The ground is a plane with normal `+Y` one radius below the
//!   terrain height, so that a sphere touches it when its centre — fbd's
//!   point — is on fbd's terrain. Only sphere–ground pairs collide. MuJoCo
//!   has one friction coefficient: μS (the static one); its contacts are
//!   soft (default `solref`/`solimp`), with an elliptic cone like fbd's
//!   `|Ft| ≤ μ·N`;
//! * actuators: one `position` servo per joint (named as the `tau` columns)
//!   with `kp` and `kv = kd` of the controller and `forcerange`
//!   `±torque_limit`: `τ = kp·(ctrl − θ) − kd·θ̇`. fbd's `kd·θ̇*` feed-forward
//!   is `ctrl = θ* + (kd/kp)·θ̇*`. A passive model has no actuators;
//! * the keyframe `initial` holds `q0`, `q̇0` (free joint: linear velocity
//!   inertial, angular velocity in the body frame, as MuJoCo wants) and the
//!   controller's targets at t = 0;
//! * sites `hip{n}`, `knee{n}`, `tip{n}` at the points `fbd kinematics`
//!   prints; Δt is the `timestep`, integrator `implicitfast`.
//!
//! Terrain: flat ground, a slope (a tilted plane, its `zaxis` the slope's
//! normal), none, or a height map (`heightfield` and the generated kinds,
//! as a MuJoCo `hfield`); any other kind is an error naming
//! `terrain.kind` (MuJoCo's height fields are not fbd's analytic
//! profiles).

use std::fmt::Write;

use fbd_contact::Terrain;
use fbd_kinematics::body::LegMount;
use fbd_kinematics::nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};
use fbd_sim::spatial::{SpatialControl, SpatialParams};

use crate::ConfigError;

/// Radius of the contact spheres at the tips, knees and hips (m).
pub const SPHERE_RADIUS: f64 = 0.01;

/// The name of the keyframe holding the initial state.
pub const KEYFRAME: &str = "initial";

use fbd_robot::mjcf_export::{num, nums};

/// `w x y z` of a rotation matrix.
fn quat(m: &Matrix3<f64>) -> String {
    let q = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(*m));
    nums(&[q.w, q.i, q.j, q.k])
}

/// The body rotation `Rot = Rx(φx)·Rz(φz)·Ry(φy)` as a unit quaternion.
fn body_quaternion(phi: [f64; 3]) -> UnitQuaternion<f64> {
    UnitQuaternion::from_axis_angle(&Vector3::x_axis(), phi[0])
        * UnitQuaternion::from_axis_angle(&Vector3::z_axis(), phi[2])
        * UnitQuaternion::from_axis_angle(&Vector3::y_axis(), phi[1])
}

/// The body's angular velocity in its own frame from the angle rates:
/// `ω = φ̇x·X + φ̇z·Rx(φx)·Z + φ̇y·Rot·Y` (inertial), then `Rotᵀ·ω`.
fn body_omega_local(phi: [f64; 3], rate: [f64; 3]) -> Vector3<f64> {
    let rot = body_quaternion(phi);
    let (s, c) = phi[0].sin_cos();
    let w = Vector3::x() * rate[0]
        + Vector3::new(0.0, -s, c) * rate[2]
        + (rot * Vector3::y()) * rate[1];
    rot.inverse() * w
}

/// The position servos of a controlled model.
struct Servo {
    /// Stiffness (N·m/rad).
    kp: f64,
    /// Damping (N·m·s/rad), MuJoCo's `kv`.
    kd: f64,
    /// `|τ| ≤ limit` (N·m), if any.
    torque_limit: Option<f64>,
    /// `(θ1, θ2, θ3)` targets at t = 0 (rad), per leg of the model.
    targets: Vec<[f64; 3]>,
}

/// The servos of the controller, or `None` for passive joints.
fn servo(p: &SpatialParams) -> Option<Servo> {
    let (kp, kd, torque_limit, targets) = match &p.control {
        SpatialControl::None => return None,
        SpatialControl::Pd {
            kp,
            kd,
            torque_limit,
            target,
        } => (kp, kd, torque_limit, target.clone()),
        SpatialControl::Trajectory {
            kp,
            kd,
            torque_limit,
            legs,
        } => (
            kp,
            kd,
            torque_limit,
            legs.iter().map(|l| l.at(0.0)).collect(),
        ),
        SpatialControl::Gait {
            kp,
            kd,
            torque_limit,
            ..
        } => (
            kp,
            kd,
            torque_limit,
            (0..p.legs.len())
                .map(|i| std::array::from_fn(|j| p.q0[6 + 3 * i + j]))
                .collect(),
        ),
    };
    Some(Servo {
        kp: *kp,
        kd: *kd,
        torque_limit: *torque_limit,
        targets,
    })
}

/// MuJoCo's hfield of the height map `g` (see the module docs): MuJoCo's
/// hfield lies in its geom's x–y plane with elevation along z; the geom's
/// frame has x = fbd's +X, y = fbd's −Z and z = fbd's +Y. MuJoCo's columns
/// run along its x (fbd's rows), its rows along its y from +y to −y (fbd's
/// columns, from −Z to +Z: checked with MuJoCo 4.0.0's `mj_ray` on a
/// sampled plane). The elevation data are normalised by MuJoCo to `[0, 1]`
/// and scaled by `size[2]` = the map's height range.
fn hfield_asset(g: &fbd_contact::HeightGrid) -> String {
    let (nr, nc) = (g.nrow(), g.ncol());
    let [x0, x1, z0, z1] = g.bounds();
    let [lo, hi] = g.range();
    let h = g.heights();
    let mut data = Vec::with_capacity(nr * nc);
    for r in 0..nc {
        for c in 0..nr {
            data.push(h[c * nc + r] - lo);
        }
    }
    format!(
        "    <hfield name=\"terrain\" nrow=\"{nc}\" ncol=\"{nr}\" size=\"{} {} {} {}\" elevation=\"{}\"/>",
        num(0.5 * (x1 - x0)),
        num(0.5 * (z1 - z0)),
        num((hi - lo).max(1e-9)),
        num(HFIELD_BASE),
        nums(&data)
    )
}

/// Thickness (m) of the hfield's base below its lowest point.
const HFIELD_BASE: f64 = 0.1;

/// The geom placing the hfield of `g` (one sphere radius below fbd's
/// surface, as the plane).
fn hfield_geom(g: &fbd_contact::HeightGrid, mu: f64) -> String {
    let [x0, x1, z0, z1] = g.bounds();
    let [lo, _] = g.range();
    format!(
        "    <geom name=\"ground\" type=\"hfield\" hfield=\"terrain\" pos=\"{} {} {}\" \
         xyaxes=\"1 0 0 0 0 -1\" contype=\"0\" conaffinity=\"1\" condim=\"3\" \
         friction=\"{} 0.005 0.0001\" group=\"0\" rgba=\"0.8 0.8 0.8 1\"/>",
        num(0.5 * (x0 + x1)),
        num(lo - SPHERE_RADIUS),
        num(0.5 * (z0 + z1)),
        num(mu)
    )
}

/// The robot of `params` as a MuJoCo MJCF document (see the module docs).
/// `file` names the configuration in errors.
///
/// # Errors
/// [`ConfigError::Semantic`] naming `terrain.kind` for a terrain other
/// than flat ground, a slope, a height map or none, and naming
/// `terrain.patch` for friction patches.
pub fn mjcf(params: &SpatialParams, file: &str) -> Result<String, ConfigError> {
    let p = params;
    let unsupported = |kind: &str| {
        ConfigError::semantic(
            file,
            "terrain.kind",
            "MuJoCo export supports flat ground, a slope, a height map or none",
            format!("\"{kind}\""),
            "\"flat\", \"slope\", \"heightfield\" (or a generated height map) or \"none\"",
        )
    };
    if !p.terrain.patches().is_empty() {
        return Err(ConfigError::semantic(
            file,
            "terrain.patch",
            "cannot be exported: MuJoCo's friction belongs to a geom, not to a place",
            format!("{} patches", p.terrain.patches().len()),
            "no [[terrain.patch]]",
        ));
    }
    // The ground plane: a point of fbd's terrain and its unit normal.
    let ground = match &p.terrain.terrain {
        _ if p.terrain.grid().is_some() => None,
        Terrain::Flat { height } => Some(([0.0, *height, 0.0], [0.0, 1.0, 0.0])),
        Terrain::None => None,
        Terrain::Slope { .. } => Some((
            [0.0, p.terrain.height(0.0, 0.0), 0.0],
            p.terrain.normal(0.0, 0.0),
        )),
        Terrain::Profile { .. } => return Err(unsupported("profile")),
        Terrain::Sine { .. } => return Err(unsupported("sine")),
        Terrain::Steps { .. } => return Err(unsupported("steps")),
    };
    assert_eq!(p.q0.len(), 6 + 3 * p.legs.len(), "q0 sized from the legs");
    assert_eq!(p.qdot0.len(), p.q0.len(), "q̇0 sized as q0");
    let servo = servo(p);
    let mu = p.friction.mu_static;
    let r = SPHERE_RADIUS;
    let sphere = |name: &str, pos: [f64; 3]| {
        format!(
            "<geom name=\"{name}\" class=\"contact\" pos=\"{}\"/>",
            nums(&pos)
        )
    };

    let mut x = String::new();
    let w = &mut x;
    // `write!` to a String cannot fail.
    let _ = writeln!(
        w,
        "<!-- The fbd hexapod as a MuJoCo model, written by `fbd export mjcf`.\n     \
         Inertial frame Y up; every hinge's qpos is fbd's joint angle (rad);\n     \
         keyframe \"{KEYFRAME}\" = the configuration's initial state.\n     \
         Friction: MuJoCo has one coefficient, fbd's static one (muS = {}).\n     \
         The ground plane lies one sphere radius ({} m) below fbd's terrain,\n     \
         so that a contact sphere touches it when its centre (fbd's point)\n     \
         is on the terrain. -->",
        num(mu),
        num(r)
    );
    let _ = writeln!(w, "<mujoco model=\"fbd_hexapod\">");
    let _ = writeln!(w, "  <compiler angle=\"radian\" autolimits=\"true\"/>");
    let _ = writeln!(
        w,
        "  <option timestep=\"{}\" gravity=\"0 {} 0\" integrator=\"implicitfast\" cone=\"elliptic\"/>",
        num(p.dt),
        num(-p.gravity)
    );
    let _ = writeln!(w, "  <default>");
    let _ = writeln!(
        w,
        "    <geom contype=\"0\" conaffinity=\"0\" group=\"1\" rgba=\"0.6 0.6 0.65 1\"/>"
    );
    let _ = writeln!(
        w,
        "    <default class=\"contact\">\n      \
         <geom type=\"sphere\" size=\"{}\" contype=\"1\" conaffinity=\"0\" condim=\"3\" \
         friction=\"{} 0.005 0.0001\" group=\"0\" rgba=\"0.9 0.4 0.2 1\"/>\n    </default>",
        num(r),
        num(mu)
    );
    let _ = writeln!(w, "  </default>");
    if let Some(g) = p.terrain.grid() {
        let _ = writeln!(w, "  <asset>");
        let _ = writeln!(w, "{}", hfield_asset(g));
        let _ = writeln!(w, "  </asset>");
    }
    let _ = writeln!(w, "  <worldbody>");
    if let Some(g) = p.terrain.grid() {
        let _ = writeln!(w, "{}", hfield_geom(g, mu));
    }
    if let Some((at, n)) = ground {
        // One sphere radius below the terrain, along its normal (a slope's
        // plane is tilted: zaxis is its normal).
        let pos = [at[0] - r * n[0], at[1] - r * n[1], at[2] - r * n[2]];
        let _ = writeln!(
            w,
            "    <geom name=\"ground\" type=\"plane\" size=\"0 0 1\" pos=\"{}\" \
             zaxis=\"{}\" contype=\"0\" conaffinity=\"1\" condim=\"3\" \
             friction=\"{} 0.005 0.0001\" group=\"0\" rgba=\"0.8 0.8 0.8 1\"/>",
            nums(&pos),
            nums(&n),
            num(mu)
        );
    }
    let q = &p.q0;
    let phi = [q[3], q[4], q[5]];
    let _ = writeln!(
        w,
        "    <body name=\"body\" pos=\"{}\" quat=\"{}\">",
        nums(&q[0..3]),
        {
            let b = body_quaternion(phi);
            nums(&[b.w, b.i, b.j, b.k])
        }
    );
    let _ = writeln!(w, "      <freejoint name=\"root\"/>");
    let bi = p.body_inertia;
    let _ = writeln!(
        w,
        "      <inertial pos=\"0 0 0\" mass=\"{}\" fullinertia=\"{}\"/>",
        num(p.body_mass),
        nums(&bi)
    );
    let d = fbd_kinematics::body::hip_distance(p.side);
    let _ = writeln!(
        w,
        "      <geom name=\"plate\" type=\"cylinder\" size=\"{} 0.01\" zaxis=\"0 1 0\"/>",
        num(d)
    );
    let limits = [
        p.joint_limits.theta1,
        p.joint_limits.theta2,
        p.joint_limits.theta3,
    ];
    let (a, c) = (p.upper_length, p.lower_length);
    for &n in &p.legs {
        let mount = LegMount::for_leg(n, p.side).expect("leg numbers are 1–6");
        let hip = mount.hip;
        let _ = writeln!(
            w,
            "      <site name=\"hip{n}\" pos=\"{}\" size=\"{}\"/>",
            nums(hip.as_slice()),
            num(r / 2.0)
        );
        if p.contact_points.hips {
            let _ = writeln!(w, "      {}", sphere(&format!("hip{n}"), hip.into()));
        }
        // Frame 1 at θ1 = 0: cA0i·Rx(90°).
        let rx90 = Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0);
        let _ = writeln!(
            w,
            "      <body name=\"upper{n}\" pos=\"{}\" quat=\"{}\">",
            nums(hip.as_slice()),
            quat(&(mount.rotation() * rx90))
        );
        let range = |j: usize| nums(&limits[j]);
        let _ = writeln!(
            w,
            "        <joint name=\"theta1_{n}\" type=\"hinge\" axis=\"0 1 0\" range=\"{}\"/>",
            range(0)
        );
        let _ = writeln!(
            w,
            "        <joint name=\"theta2_{n}\" type=\"hinge\" axis=\"0 0 1\" range=\"{}\"/>",
            range(1)
        );
        let ur = p.upper_radius;
        let _ = writeln!(
            w,
            "        <inertial pos=\"{} 0 0\" mass=\"{}\" diaginertia=\"{}\"/>",
            num(-p.upper_com * a),
            num(p.upper_mass),
            nums(&[
                p.upper_mass * ur * ur / 2.0,
                p.upper_inertia,
                p.upper_inertia
            ])
        );
        let _ = writeln!(
            w,
            "        <geom name=\"upper{n}\" type=\"capsule\" size=\"{}\" fromto=\"0 0 0 {} 0 0\"/>",
            num(ur),
            num(-a)
        );
        let _ = writeln!(
            w,
            "        <body name=\"lower{n}\" pos=\"{} 0 0\">",
            num(-a)
        );
        let _ = writeln!(
            w,
            "          <joint name=\"theta3_{n}\" type=\"hinge\" axis=\"0 0 1\" range=\"{}\"/>",
            range(2)
        );
        let lr = p.lower_radius;
        let _ = writeln!(
            w,
            "          <inertial pos=\"{} 0 0\" mass=\"{}\" diaginertia=\"{}\"/>",
            num(p.lower_com * c),
            num(p.lower_mass),
            nums(&[
                p.lower_mass * lr * lr / 2.0,
                p.lower_inertia,
                p.lower_inertia
            ])
        );
        let _ = writeln!(
            w,
            "          <geom name=\"lower{n}\" type=\"capsule\" size=\"{}\" fromto=\"0 0 0 {} 0 0\"/>",
            num(lr),
            num(c)
        );
        let _ = writeln!(
            w,
            "          <site name=\"knee{n}\" pos=\"0 0 0\" size=\"{}\"/>",
            num(r / 2.0)
        );
        let _ = writeln!(
            w,
            "          <site name=\"tip{n}\" pos=\"{} 0 0\" size=\"{}\"/>",
            num(c),
            num(r / 2.0)
        );
        if p.contact_points.knees {
            let _ = writeln!(w, "          {}", sphere(&format!("knee{n}"), [0.0; 3]));
        }
        if p.contact_points.tips {
            let _ = writeln!(w, "          {}", sphere(&format!("tip{n}"), [c, 0.0, 0.0]));
        }
        let _ = writeln!(w, "        </body>\n      </body>");
    }
    let _ = writeln!(w, "    </body>\n  </worldbody>");

    if let Some(Servo {
        kp,
        kd,
        torque_limit,
        ..
    }) = &servo
    {
        let _ = writeln!(w, "  <actuator>");
        let force = torque_limit
            .map(|l| format!(" forcerange=\"{}\"", nums(&[-l, l])))
            .unwrap_or_default();
        for &n in &p.legs {
            for j in 1..=3 {
                let _ = writeln!(
                    w,
                    "    <position name=\"tau{j}_{n}\" joint=\"theta{j}_{n}\" kp=\"{}\" kv=\"{}\"{force}/>",
                    num(*kp),
                    num(*kd)
                );
            }
        }
        let _ = writeln!(w, "  </actuator>");
    }

    // Keyframe: MuJoCo's free-joint qpos is (R, quaternion), its qvel
    // (Ṙ inertial, ω in the body frame).
    let b = body_quaternion(phi);
    let mut qpos = vec![q[0], q[1], q[2], b.w, b.i, b.j, b.k];
    qpos.extend_from_slice(&q[6..]);
    let v = &p.qdot0;
    let om = body_omega_local(phi, [v[3], v[4], v[5]]);
    let mut qvel = vec![v[0], v[1], v[2], om.x, om.y, om.z];
    qvel.extend_from_slice(&v[6..]);
    let ctrl = servo
        .map(|s| {
            let flat: Vec<f64> = s.targets.iter().flatten().copied().collect();
            format!(" ctrl=\"{}\"", nums(&flat))
        })
        .unwrap_or_default();
    let _ = writeln!(
        w,
        "  <keyframe>\n    <key name=\"{KEYFRAME}\" qpos=\"{}\" qvel=\"{}\"{ctrl}/>\n  </keyframe>",
        nums(&qpos),
        nums(&qvel)
    );
    let _ = writeln!(w, "</mujoco>");
    Ok(x)
}

#[cfg(test)]
mod tests {
    use super::*;
    use fbd_contact::Surface;

    fn parse(xml: &str) -> roxmltree::Document<'_> {
        roxmltree::Document::parse(xml).unwrap_or_else(|e| panic!("not well-formed: {e}\n{xml}"))
    }

    fn names<'a>(doc: &'a roxmltree::Document, tag: &str) -> Vec<&'a str> {
        doc.descendants()
            .filter(|n| n.has_tag_name(tag))
            .filter_map(|n| n.attribute("name"))
            .collect()
    }

    fn numbers(s: &str) -> Vec<f64> {
        s.split_whitespace().map(|t| t.parse().unwrap()).collect()
    }

    /// Every body, joint, site, contact sphere and actuator of the robot
    /// is in the document, in fbd's order, and the keyframe has one value
    /// per MuJoCo coordinate.
    #[test]
    fn lists_every_body_joint_and_actuator() {
        let p = SpatialParams {
            control: SpatialControl::Pd {
                kp: 80.0,
                kd: 2.0,
                torque_limit: Some(30.0),
                target: vec![[0.1, 0.2, 4.3]; 6],
            },
            ..SpatialParams::default()
        };
        let xml = mjcf(&p, "robot.toml").unwrap();
        let doc = parse(&xml);
        let mut bodies = vec!["body".to_owned()];
        let mut joints = vec!["root".to_owned()];
        let mut actuators = vec![];
        for n in 1..=6 {
            bodies.extend([format!("upper{n}"), format!("lower{n}")]);
            for j in 1..=3 {
                joints.push(format!("theta{j}_{n}"));
                actuators.push(format!("tau{j}_{n}"));
            }
        }
        assert_eq!(names(&doc, "body"), bodies);
        let mut got_joints = names(&doc, "freejoint");
        got_joints.extend(names(&doc, "joint"));
        assert_eq!(got_joints, joints);
        assert_eq!(names(&doc, "position"), actuators);
        // Tips, knees and hips by default; 18 spheres and the ground.
        let spheres = doc
            .descendants()
            .filter(|n| n.has_tag_name("geom") && n.attribute("class") == Some("contact"))
            .count();
        assert_eq!(spheres, 18);
        assert_eq!(names(&doc, "site").len(), 18);
        let key = doc
            .descendants()
            .find(|n| n.has_tag_name("key"))
            .expect("keyframe");
        assert_eq!(numbers(key.attribute("qpos").unwrap()).len(), 7 + 18);
        assert_eq!(numbers(key.attribute("qvel").unwrap()).len(), 6 + 18);
        let ctrl = numbers(key.attribute("ctrl").unwrap());
        assert_eq!(ctrl.len(), 18);
        assert_eq!(&ctrl[..3], &[0.1, 0.2, 4.3]);
        // Gains and torque limit on every servo.
        for a in doc.descendants().filter(|n| n.has_tag_name("position")) {
            assert_eq!(a.attribute("kp"), Some("80"));
            assert_eq!(a.attribute("kv"), Some("2"));
            assert_eq!(a.attribute("forcerange"), Some("-30 30"));
        }
    }

    /// Total mass, link inertias, Δt, gravity and the ground are the
    /// parameters', exactly (the numbers round-trip).
    #[test]
    fn physical_parameters_round_trip() {
        let p = SpatialParams {
            legs: vec![3, 4],
            q0: vec![
                0.1, 0.7, -0.2, 0.3, -0.4, 0.2, 0.1, 0.2, 4.2, -0.1, 0.3, 4.0,
            ],
            qdot0: vec![0.0; 12],
            dt: 0.0007,
            gravity: 9.5,
            terrain: Surface::new(Terrain::Flat { height: 0.05 }, 0.0),
            ..SpatialParams::default()
        };
        let xml = mjcf(&p, "robot.toml").unwrap();
        let doc = parse(&xml);
        let mass: f64 = doc
            .descendants()
            .filter(|n| n.has_tag_name("inertial"))
            .map(|n| n.attribute("mass").unwrap().parse::<f64>().unwrap())
            .sum();
        let want = p.body_mass + 2.0 * (p.upper_mass + p.lower_mass);
        assert!((mass - want).abs() < 1e-12, "mass {mass} vs {want}");
        let opt = doc
            .descendants()
            .find(|n| n.has_tag_name("option"))
            .unwrap();
        assert_eq!(opt.attribute("timestep"), Some("0.0007"));
        assert_eq!(opt.attribute("gravity"), Some("0 -9.5 0"));
        let ground = doc
            .descendants()
            .find(|n| n.attribute("name") == Some("ground"))
            .unwrap();
        let y = numbers(ground.attribute("pos").unwrap())[1];
        assert!((y - (0.05 - SPHERE_RADIUS)).abs() < 1e-15);
        let inertia = doc
            .descendants()
            .find(|n| {
                n.has_tag_name("inertial")
                    && n.parent().unwrap().attribute("name") == Some("lower4")
            })
            .unwrap();
        let di = numbers(inertia.attribute("diaginertia").unwrap());
        let r = p.lower_radius;
        assert_eq!(
            di,
            vec![p.lower_mass * r * r / 2.0, p.lower_inertia, p.lower_inertia]
        );
        // Passive: no actuators, no ctrl.
        assert!(names(&doc, "position").is_empty());
        assert_eq!(
            names(&doc, "body"),
            ["body", "upper3", "lower3", "upper4", "lower4"]
        );
    }

    /// The keyframe's quaternion is `Rx(φx)·Rz(φz)·Ry(φy)` of the
    /// kinematics, and the body angular velocity is that of the angle
    /// rates (finite difference of the rotation).
    #[test]
    fn body_orientation_and_spin() {
        let phi = [0.3, -0.7, 0.45];
        let pose = fbd_kinematics::pose::BodyPose::new([0.0; 3], phi);
        let want = pose.rotation();
        let got = body_quaternion(phi).to_rotation_matrix().into_inner();
        assert!((got - want).norm() < 1e-15, "{got} vs {want}");
        let rate = [0.4, -1.1, 0.9];
        let h = 1e-6;
        let at = |s: f64| {
            let f: [f64; 3] = std::array::from_fn(|k| phi[k] + s * rate[k]);
            fbd_kinematics::pose::BodyPose::new([0.0; 3], f).rotation()
        };
        // Rᵀ·Ṙ = [ω_body]×.
        let wx = want.transpose() * (at(h) - at(-h)) / (2.0 * h);
        let fd = Vector3::new(wx[(2, 1)], wx[(0, 2)], wx[(1, 0)]);
        let om = body_omega_local(phi, rate);
        assert!((om - fd).norm() < 1e-8, "{om} vs {fd}");
    }

    /// MuJoCo's forward kinematics of the document, by its documented
    /// rule: a body's frame is its parent's composed with `pos`/`quat`; a
    /// free joint sets the frame to `(qpos[0..3], qpos[3..7])`; each
    /// hinge then turns the frame about its local axis by its `qpos`
    /// (`R ← R·Rot(axis, q)`, in the order written). Returns every site's
    /// position.
    fn sites(doc: &roxmltree::Document, qpos: &[f64]) -> Vec<(String, Vector3<f64>)> {
        fn attr(n: roxmltree::Node, key: &str) -> Option<Vec<f64>> {
            n.attribute(key).map(numbers)
        }
        fn quat(v: &[f64]) -> UnitQuaternion<f64> {
            UnitQuaternion::from_quaternion(fbd_kinematics::nalgebra::Quaternion::new(
                v[0], v[1], v[2], v[3],
            ))
        }
        fn walk(
            n: roxmltree::Node,
            p: Vector3<f64>,
            r: UnitQuaternion<f64>,
            qpos: &[f64],
            next: &mut usize,
            out: &mut Vec<(String, Vector3<f64>)>,
        ) {
            let pos = attr(n, "pos").map_or(Vector3::zeros(), |v| Vector3::new(v[0], v[1], v[2]));
            let (mut p, mut r) = (
                p + r * pos,
                r * attr(n, "quat").map_or(UnitQuaternion::identity(), |v| quat(&v)),
            );
            for c in n.children().filter(|c| c.is_element()) {
                match c.tag_name().name() {
                    "freejoint" => {
                        p = Vector3::new(qpos[0], qpos[1], qpos[2]);
                        r = quat(&qpos[3..7]);
                        *next = 7;
                    }
                    "joint" => {
                        let a = attr(c, "axis").unwrap();
                        let axis = fbd_kinematics::nalgebra::Unit::new_normalize(Vector3::new(
                            a[0], a[1], a[2],
                        ));
                        r *= UnitQuaternion::from_axis_angle(&axis, qpos[*next]);
                        *next += 1;
                    }
                    _ => {}
                }
            }
            for c in n.children().filter(|c| c.is_element()) {
                match c.tag_name().name() {
                    "site" => {
                        let v = attr(c, "pos").unwrap();
                        out.push((
                            c.attribute("name").unwrap().to_owned(),
                            p + r * Vector3::new(v[0], v[1], v[2]),
                        ));
                    }
                    "body" => walk(c, p, r, qpos, next, out),
                    _ => {}
                }
            }
        }
        let world = doc
            .descendants()
            .find(|n| n.has_tag_name("worldbody"))
            .unwrap();
        let mut out = vec![];
        let mut next = 0;
        for b in world.children().filter(|c| c.has_tag_name("body")) {
            walk(
                b,
                Vector3::zeros(),
                UnitQuaternion::identity(),
                qpos,
                &mut next,
                &mut out,
            );
        }
        out
    }

    /// The exported frames put every hip, knee and tip where fbd's
    /// kinematics does (eqs. 1–5), for the keyframe's qpos: the same check
    /// `bench/peer/test_mjcf.py` makes in MuJoCo itself.
    #[test]
    fn frames_reproduce_fbd_kinematics() {
        use fbd_kinematics::hexapod::{HexapodConfig, HexapodData, HexapodModel, forward};
        use fbd_kinematics::leg::LegGeometry;
        let mut q0 = vec![0.3, 0.5, -0.2, 0.4, -2.1, 0.3];
        let joints = [
            [0.1, 0.2, 4.0],
            [-0.3, -0.1, 4.4],
            [0.5, 0.6, 3.9],
            [0.0, 0.0, 4.3],
            [-0.7, 0.3, 2.0],
            [1.1, -0.5, 4.7],
        ];
        q0.extend(joints.iter().flatten());
        let p = SpatialParams {
            q0: q0.clone(),
            side: 0.27,
            upper_length: 0.21,
            lower_length: 0.4,
            ..SpatialParams::default()
        };
        let xml = mjcf(&p, "robot.toml").unwrap();
        let doc = parse(&xml);
        let key = doc.descendants().find(|n| n.has_tag_name("key")).unwrap();
        let got = sites(&doc, &numbers(key.attribute("qpos").unwrap()));
        assert_eq!(got.len(), 18);
        let model = HexapodModel::new(0.27, LegGeometry { a: 0.21, c: 0.4 }, 0.5, 0.75);
        let mut d = HexapodData::new();
        forward(
            &model,
            &HexapodConfig::from_q(&q0.clone().try_into().unwrap()),
            &mut d,
        );
        for (name, at) in got {
            let (kind, n) = name.split_at(name.len() - 1);
            let leg = &d.legs[n.parse::<usize>().unwrap() - 1];
            let want = match kind {
                "hip" => leg.hip,
                "knee" => leg.knee,
                _ => leg.tip,
            };
            assert!((at - want).norm() < 1e-14, "{name}: {at} vs fbd {want}");
        }
    }

    #[test]
    fn a_slope_is_a_tilted_plane_one_radius_below_it() {
        let p = SpatialParams {
            terrain: Surface::new(Terrain::slope_deg(10.0, 0.05), 0.0),
            ..SpatialParams::default()
        };
        let xml = mjcf(&p, "slope.toml").unwrap();
        let doc = parse(&xml);
        let g = doc
            .descendants()
            .find(|n| n.attribute("name") == Some("ground"))
            .unwrap();
        let v = |k: &str| -> Vec<f64> {
            g.attribute(k)
                .unwrap()
                .split_whitespace()
                .map(|x| x.parse().unwrap())
                .collect()
        };
        let (pos, n) = (v("pos"), v("zaxis"));
        let a = 10f64.to_radians();
        assert!((n[0] + a.sin()).abs() < 1e-12 && (n[1] - a.cos()).abs() < 1e-12);
        // pos + r·n is on fbd's terrain y = 0.05 + tan(10°)·x.
        let on = [pos[0] + SPHERE_RADIUS * n[0], pos[1] + SPHERE_RADIUS * n[1]];
        assert!((on[1] - (0.05 + a.tan() * on[0])).abs() < 1e-12, "{pos:?}");
    }

    #[test]
    fn other_terrains_are_an_error_naming_the_key() {
        let p = SpatialParams {
            terrain: Surface::new(
                Terrain::Sine {
                    amplitude: 0.01,
                    wavelength: 1.0,
                    phase: 0.0,
                    height: 0.0,
                },
                0.0,
            ),
            ..SpatialParams::default()
        };
        let e = mjcf(&p, "sine.toml").unwrap_err().to_string();
        assert!(e.starts_with("sine.toml: terrain.kind:"), "{e}");
        assert!(e.contains("\"sine\""), "{e}");
        let none = SpatialParams {
            terrain: Surface::new(Terrain::None, 0.0),
            ..SpatialParams::default()
        };
        let xml = mjcf(&none, "x.toml").unwrap();
        assert!(names(&parse(&xml), "geom").iter().all(|&n| n != "ground"));
    }
}

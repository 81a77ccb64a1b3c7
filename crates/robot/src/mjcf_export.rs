//! Any [`RobotModel`] as a MuJoCo model (MJCF), in fbd's frames: `Y` up,
//! gravity `(0, −g, 0)`, the root a free body whose frame is the model's
//! root frame, every hinge's `qpos` the model's joint angle.
//!
//! * each body with mass becomes a `<body>` with an `<inertial>` (`pos` its
//!   centre of mass, `fullinertia` about it in body axes);
//! * a massless body with one child joint and no contact point (a frame
//!   between two joints, as the two-axis hip) is not written: its joint
//!   joins the child's body as one more hinge, at its point and along its
//!   axis expressed in the child's frame at zero angles (MuJoCo composes a
//!   body's hinges in order, as the chain does); any other massless moving
//!   body gets `mass = 1e-9`, `diaginertia = 1e-12` (MuJoCo refuses a
//!   moving body without mass), which the export's header says;
//! * joints are hinges named as the model's, `range` their limits;
//! * contact points are spheres (`contype 1`, `conaffinity 0`) named as
//!   the points, radius theirs or [`POINT_RADIUS`] for a point; the ground
//!   is a plane at `y = 0` (`conaffinity 1`);
//! * one `motor` per actuator, `forcerange` its effort limit.

use std::fmt::Write;

use nalgebra::{Isometry3, Matrix3, Point3, UnitQuaternion, Vector3};

use crate::model::RobotModel;

/// The time step written (s): MuJoCo's own runs of the model choose theirs.
pub const TIMESTEP: f64 = 0.001;

/// Radius of the sphere written for a contact point of radius 0 (m).
pub const POINT_RADIUS: f64 = 0.005;

/// Shortest round-trip decimal of `x` (what `f64` parsing gives back
/// exactly; `{:?}` switches to exponents for tiny and huge values).
pub fn num(x: f64) -> String {
    if x == 0.0 {
        return "0".to_owned();
    }
    let s = format!("{x:?}");
    s.strip_suffix(".0").map(str::to_owned).unwrap_or(s)
}

/// Space-separated numbers ([`num`]).
pub fn nums(xs: &[f64]) -> String {
    xs.iter().map(|&x| num(x)).collect::<Vec<_>>().join(" ")
}

fn vec3(v: &Vector3<f64>) -> String {
    nums(&[v.x, v.y, v.z])
}

fn quat(q: &UnitQuaternion<f64>) -> String {
    nums(&[q.w, q.i, q.j, q.k])
}

/// Whether body `b` is a frame between two joints that the export folds
/// into its one child.
fn folded(model: &RobotModel, b: usize) -> bool {
    b != 0
        && model.bodies[b].mass == 0.0
        && !model.contacts.iter().any(|c| c.body == b)
        && model.joints.iter().filter(|j| j.parent == b).count() == 1
}

/// The MJCF text of `model` with gravity `g` (m/s², along −Y) and time
/// step `dt` (s); the root placed at `base`.
pub fn to_mjcf(model: &RobotModel, g: f64, dt: f64, base: &Isometry3<f64>) -> String {
    let mut x = String::new();
    let light = (1..model.bodies.len())
        .filter(|&b| model.bodies[b].mass == 0.0 && !folded(model, b))
        .count();
    let _ = writeln!(x, "<mujoco model=\"{}\">", model.name);
    let _ = writeln!(
        x,
        "  <!-- Written by fbd from its robot model: inertial frame Y up; the root's frame is fbd's body frame;\n       every hinge's qpos is fbd's joint angle (rad); frames between two joints folded into their child's body.{}\n  -->",
        if light > 0 {
            format!(
                "\n       {light} massless moving bodies carry mass 1e-9 kg (MuJoCo needs one)."
            )
        } else {
            String::new()
        }
    );
    let _ = writeln!(
        x,
        "  <compiler angle=\"radian\" inertiafromgeom=\"false\"/>"
    );
    let _ = writeln!(
        x,
        "  <option timestep=\"{}\" gravity=\"0 {} 0\" integrator=\"implicitfast\"/>",
        num(dt),
        num(-g)
    );
    let _ = writeln!(x, "  <worldbody>");
    let _ = writeln!(
        x,
        "    <geom name=\"ground\" type=\"plane\" size=\"0 0 1\" zaxis=\"0 1 0\" contype=\"0\" conaffinity=\"1\"/>"
    );
    body(model, 0, base, &[], 2, &mut x);
    let _ = writeln!(x, "  </worldbody>");
    if !model.actuators.is_empty() {
        let _ = writeln!(x, "  <actuator>");
        for a in &model.actuators {
            let range = a
                .effort_limit
                .map(|e| {
                    format!(
                        " forcelimited=\"true\" forcerange=\"{} {}\"",
                        num(-e),
                        num(e)
                    )
                })
                .unwrap_or_default();
            let _ = writeln!(
                x,
                "    <motor name=\"{}\" joint=\"{}\"{range}/>",
                a.name, model.joints[a.joint].name
            );
        }
        let _ = writeln!(x, "  </actuator>");
    }
    let _ = writeln!(x, "</mujoco>");
    x
}

/// A hinge folded into a body: its name, point and axis in the body's
/// frame, limits.
struct Hinge {
    joint: usize,
    pos: Vector3<f64>,
    axis: Vector3<f64>,
}

/// Writes body `b`, placed at `pose` in its MJCF parent's frame, with the
/// folded hinges `hinges` before its own joint.
fn body(
    model: &RobotModel,
    b: usize,
    pose: &Isometry3<f64>,
    hinges: &[Hinge],
    depth: usize,
    x: &mut String,
) {
    let pad = "  ".repeat(depth);
    let bd = &model.bodies[b];
    let _ = writeln!(
        x,
        "{pad}<body name=\"{}\" pos=\"{}\" quat=\"{}\">",
        bd.name,
        vec3(&pose.translation.vector),
        quat(&pose.rotation)
    );
    let joint_line = |j: usize, pos: &Vector3<f64>, axis: &Vector3<f64>| {
        let joint = &model.joints[j];
        let range = joint
            .limits
            .map(|l| format!(" range=\"{} {}\"", num(l.lower), num(l.upper)))
            .unwrap_or_default();
        format!(
            "{pad}  <joint name=\"{}\" type=\"hinge\" pos=\"{}\" axis=\"{}\"{range}/>",
            joint.name,
            vec3(pos),
            vec3(axis)
        )
    };
    if b == 0 {
        let _ = writeln!(x, "{pad}  <freejoint name=\"root\"/>");
    }
    for h in hinges {
        let _ = writeln!(x, "{}", joint_line(h.joint, &h.pos, &h.axis));
    }
    if let Some(j) = bd.joint {
        let _ = writeln!(
            x,
            "{}",
            joint_line(j, &Vector3::zeros(), &model.joints[j].axis.into_inner())
        );
    }
    let (mass, inertia) = if bd.mass > 0.0 {
        (bd.mass, bd.inertia)
    } else {
        (1e-9, Matrix3::identity() * 1e-12)
    };
    let i = &inertia;
    let _ = writeln!(
        x,
        "{pad}  <inertial pos=\"{}\" mass=\"{}\" fullinertia=\"{}\"/>",
        vec3(&bd.com),
        num(mass),
        nums(&[
            i[(0, 0)],
            i[(1, 1)],
            i[(2, 2)],
            i[(0, 1)],
            i[(0, 2)],
            i[(1, 2)]
        ])
    );
    for c in model.contacts.iter().filter(|c| c.body == b) {
        let r = if c.radius > 0.0 {
            c.radius
        } else {
            POINT_RADIUS
        };
        let _ = writeln!(
            x,
            "{pad}  <geom name=\"{}\" type=\"sphere\" size=\"{}\" pos=\"{}\" contype=\"1\" conaffinity=\"0\"/>",
            c.name,
            num(r),
            vec3(&c.position)
        );
        let _ = writeln!(
            x,
            "{pad}  <site name=\"{}\" pos=\"{}\"/>",
            c.name,
            vec3(&c.position)
        );
    }
    for (j, joint) in model
        .joints
        .iter()
        .enumerate()
        .filter(|(_, j)| j.parent == b)
    {
        let child = joint.child;
        if folded(model, child) {
            // The folded frame's one child joint and body: the child's pose
            // in this body at zero angles, this joint's point and axis in
            // the child's frame.
            let next = model
                .joints
                .iter()
                .find(|n| n.parent == child)
                .expect("a folded body has one child joint");
            let child_pose = joint.origin * next.origin;
            let to_child = next.origin.inverse();
            let mut more = vec![Hinge {
                joint: j,
                pos: (to_child * Point3::origin()).coords,
                axis: to_child.rotation * joint.axis.into_inner(),
            }];
            // Deeper folds (a frame after a frame) compose the same way.
            write_folded(model, next.child, &child_pose, &mut more, depth + 1, x);
        } else {
            body(model, child, &joint.origin, &[], depth + 1, x);
        }
    }
    let _ = writeln!(x, "{pad}</body>");
}

/// Writes body `b` reached through folded frames (`hinges` already in its
/// frame), folding further frames if `b` is one too.
fn write_folded(
    model: &RobotModel,
    b: usize,
    pose: &Isometry3<f64>,
    hinges: &mut Vec<Hinge>,
    depth: usize,
    x: &mut String,
) {
    if folded(model, b) {
        let next = model
            .joints
            .iter()
            .find(|n| n.parent == b)
            .expect("a folded body has one child joint");
        let own = model.bodies[b]
            .joint
            .expect("a folded body hangs from a joint");
        let to_child = next.origin.inverse();
        for h in hinges.iter_mut() {
            h.pos = (to_child * Point3::from(h.pos)).coords;
            h.axis = to_child.rotation * h.axis;
        }
        hinges.push(Hinge {
            joint: own,
            pos: (to_child * Point3::origin()).coords,
            axis: to_child.rotation * model.joints[own].axis.into_inner(),
        });
        let pose = pose * next.origin;
        write_folded(model, next.child, &pose, hinges, depth, x);
        return;
    }
    // `b`'s own joint is written by `body`; the folded ones go before it.
    body(model, b, pose, hinges, depth, x);
}

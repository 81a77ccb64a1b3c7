//! The kinematic gait generator (`fbd_robot::gait`) on the lab hexapod
//! (tripod) and on Solo-12 from PyPI `example-robot-data` 6.0.0 (trot,
//! walk, turning trot; skipped with a note when its URDF is not found —
//! `ROS_PACKAGE_PATH` or `python3`'s `importlib.metadata`). Forward
//! kinematics of the planned base pose and the joint targets is checked
//! against the gait's rules: stance feet fixed in the world at their
//! footholds, swing apex at mid-swing, landings on the Raibert footholds,
//! per-cycle displacement `velocity·period`, enough feet standing, joints
//! within limits, targets continuous and rates the derivative of the
//! angles.

use std::path::{Path, PathBuf};

use fbd_robot::forward::base_frame;
use fbd_robot::gait::{GaitError, GaitParams, GaitPlan};
use fbd_robot::nalgebra::{Point3, Vector3};
use fbd_robot::{ContactChoice, RobotData, RobotModel, Up, forward};

fn lab() -> RobotModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../examples/robots/lab_hexapod.urdf");
    fbd_robot::urdf::load(&path, Up::Z, &ContactChoice::CollisionSpheres).unwrap()
}

const LAB_FEET: [&str; 6] = [
    "lf_foot_sphere",
    "lm_foot_sphere",
    "lr_foot_sphere",
    "rf_foot_sphere",
    "rm_foot_sphere",
    "rr_foot_sphere",
];

/// The lab hexapod standing (examples/robots/lab_hexapod.toml): femurs
/// 20° up, tibias −20°, the base 0.102638 m high.
fn lab_standing(model: &RobotModel) -> ([f64; 3], Vec<f64>) {
    let mut q = vec![0.0; model.joint_count()];
    for (j, joint) in model.joints.iter().enumerate() {
        if joint.name.ends_with("_femur_joint") {
            q[j] = 20f64.to_radians();
        } else if joint.name.ends_with("_tibia_joint") {
            q[j] = -20f64.to_radians();
        }
    }
    ([0.0, 0.102638, 0.0], q)
}

/// Solo-12's URDF from example-robot-data, if installed.
fn solo_urdf() -> Option<PathBuf> {
    let rel = "solo_description/robots/solo12.urdf";
    if let Ok(paths) = std::env::var("ROS_PACKAGE_PATH") {
        for dir in paths.split(':').filter(|d| !d.is_empty()) {
            let p = Path::new(dir).join(rel);
            if p.is_file() {
                return Some(p);
            }
        }
    }
    let out = std::process::Command::new("python3")
        .args([
            "-c",
            "import importlib.metadata as m; print(m.distribution('example-robot-data').locate_file('cmeel.prefix/share/example-robot-data/robots'))",
        ])
        .output()
        .ok()?;
    let dir = String::from_utf8(out.stdout).ok()?;
    let p = Path::new(dir.trim()).join(rel);
    p.is_file().then_some(p)
}

const SOLO_FEET: [&str; 4] = ["FL_FOOT", "FR_FOOT", "HL_FOOT", "HR_FOOT"];

/// Solo-12 in the SRDF's straight standing pose (as
/// examples/robots/solo12_stand.toml), set down on its feet; `None` (with
/// a note) when example-robot-data is not installed.
fn solo() -> Option<(RobotModel, [f64; 3], Vec<f64>)> {
    let Some(path) = solo_urdf() else {
        eprintln!(
            "note: Solo-12 gait test skipped: example-robot-data 6.0.0 not found (pip install example-robot-data==6.0.0, or set ROS_PACKAGE_PATH)"
        );
        return None;
    };
    let names = SOLO_FEET.iter().map(|s| s.to_string()).collect();
    let model = fbd_robot::urdf::load(&path, Up::Z, &ContactChoice::Named(names)).unwrap();
    let mut q = vec![0.0; model.joint_count()];
    for (j, joint) in model.joints.iter().enumerate() {
        let front = joint.name.starts_with('F');
        if joint.name.ends_with("_HFE") {
            q[j] = if front { 0.8 } else { -0.8 };
        } else if joint.name.ends_with("_KFE") {
            q[j] = if front { -1.6 } else { 1.6 };
        }
    }
    let mut d = RobotData::new(&model);
    forward(&model, &base_frame([0.0; 3], [0.0; 3]), &q, &mut d);
    let low = d.contacts.iter().map(|c| c.y).fold(f64::INFINITY, f64::min);
    Some((model, [0.0, -low, 0.0], q))
}

/// A leg's event: (leg, kind, cycle).
type Event = (usize, usize, i64);

/// What the run measured.
#[derive(Debug, Default)]
struct Figures {
    /// Largest change of any joint target between samples 1 ms apart (rad).
    max_jump: f64,
    /// Largest rate error against the central difference (rad/s).
    max_rate_error: f64,
    /// Largest stance foot drift from its foothold (m).
    max_drift: f64,
    /// Fewest feet standing at once.
    min_standing: usize,
    /// Landings checked.
    landings: usize,
    /// Mean wall time of one `targets` call (µs).
    us_per_call: f64,
}

/// Runs `params` for `cycles` periods after start-up and ramp, sampling
/// every millisecond plus each leg's lift-off, mid-swing, touchdown and
/// mid-stance, and checks every rule of the gait (see the module docs).
#[allow(clippy::too_many_arguments)]
fn check(
    model: &RobotModel,
    names: &[&str],
    position: [f64; 3],
    q0: &[f64],
    params: GaitParams,
    cycles: usize,
    min_standing: usize,
) -> Figures {
    let feet = GaitPlan::feet_by_name(model, names).unwrap();
    let mut plan = GaitPlan::new(model, &feet, position, [0.0; 3], q0, params.clone()).unwrap();
    let (t_period, duty, h) = (params.period, params.duty, params.step_height);
    let swing = (1.0 - duty) * t_period;
    let steady = params.startup + params.ramp;
    let end = steady + cycles as f64 * t_period;
    let straight = params.yaw_rate == 0.0;
    let v = Vector3::new(params.velocity[0], 0.0, params.velocity[1]);

    // The standing feet in the base frame (the nominal footholds).
    let mut d = RobotData::new(model);
    let base0 = base_frame(position, [0.0; 3]);
    forward(model, &base0, q0, &mut d);
    let nominal: Vec<Vector3<f64>> = feet
        .iter()
        .map(|&f| {
            let mut n = base0
                .inverse_transform_point(&Point3::from(d.contacts[f]))
                .coords;
            n.x += params.stance_width * n.x.signum();
            n
        })
        .collect();

    // Sample times: a 1 ms grid and each leg's events (kind 0 lift-off,
    // 1 mid-swing, 2 touchdown, 3 mid-stance).
    let mut times: Vec<(f64, Option<Event>)> = (0..=(end / 1e-3).round() as usize)
        .map(|k| (k as f64 * 1e-3, None))
        .collect();
    for (leg, &o) in params.phases.iter().enumerate() {
        for c in 0.. {
            let lift = params.startup + (o + c as f64) * t_period;
            if lift + t_period > end {
                break;
            }
            for (kind, t) in [
                lift,
                lift + 0.5 * swing,
                lift + swing,
                lift + swing + 0.5 * duty * t_period,
            ]
            .into_iter()
            .enumerate()
            {
                times.push((t, Some((leg, kind, c))));
            }
        }
    }
    times.sort_by(|a, b| a.0.total_cmp(&b.0));

    let n = model.joint_count();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    let (mut q_prev, mut t_prev) = (q0.to_vec(), 0.0);
    let mut anchor: Vec<Option<Vector3<f64>>> = vec![None; feet.len()];
    let mut landings: Vec<Vec<(i64, Vector3<f64>, f64)>> = vec![Vec::new(); feet.len()];
    let mut fig = Figures {
        min_standing: usize::MAX,
        ..Figures::default()
    };
    for (step, &(t, event)) in times.iter().enumerate() {
        let clock = std::time::Instant::now();
        let pose = plan.targets(t, &mut q, &mut qd).unwrap();
        fig.us_per_call += clock.elapsed().as_secs_f64() * 1e6 / times.len() as f64;
        let frame = pose.frame();
        forward(model, &frame, &q, &mut d);
        // Joints within their limits.
        for (j, joint) in model.joints.iter().enumerate() {
            if let Some(l) = joint.limits {
                assert!(
                    l.lower <= q[j] && q[j] <= l.upper,
                    "{} = {} at t = {t}",
                    joint.name,
                    q[j]
                );
            }
        }
        // Continuity: no jump larger than the rates allow (and < 0.02 rad
        // per millisecond).
        if t > t_prev {
            let jump = q
                .iter()
                .zip(&q_prev)
                .map(|(a, b)| (a - b).abs())
                .fold(0.0, f64::max);
            if event.is_none() && t_prev > 0.0 && (t - t_prev - 1e-3).abs() < 1e-9 {
                fig.max_jump = fig.max_jump.max(jump);
            }
            assert!(jump < 20.0 * (t - t_prev) + 1e-9, "jump {jump} at t = {t}");
        }
        // Rates: central differences on a copy of the plan.
        if step % 23 == 0 {
            let mut copy = plan.clone();
            let hstep = 1e-5;
            let (mut qp, mut qm, mut scratch) = (vec![0.0; n], vec![0.0; n], vec![0.0; n]);
            copy.targets(t + hstep, &mut qp, &mut scratch).unwrap();
            copy.targets(t - hstep, &mut qm, &mut scratch).unwrap();
            for j in 0..n {
                let fd = (qp[j] - qm[j]) / (2.0 * hstep);
                let err = (fd - qd[j]).abs();
                fig.max_rate_error = fig.max_rate_error.max(err);
                assert!(
                    err < 1e-3 * (1.0 + qd[j].abs()),
                    "{}: q̇ {} vs finite difference {fd} at t = {t}",
                    model.joints[j].name,
                    qd[j]
                );
            }
        }
        let mut standing = 0;
        for (leg, &f) in feet.iter().enumerate() {
            let p = d.contacts[f];
            let radius = model.contacts[f].radius;
            let planned = plan.foot(leg, t).unwrap();
            assert!(
                (p - Vector3::from(planned.position)).norm() < 1e-9,
                "{} at t = {t}: {p} vs {:?}",
                names[leg],
                planned.position
            );
            assert_eq!(planned.stance, plan.stance(leg, t));
            if plan.stance(leg, t) {
                standing += 1;
                assert!(
                    (p.y - radius).abs() < 1e-9,
                    "{} y = {} in stance",
                    names[leg],
                    p.y
                );
                let a = *anchor[leg].get_or_insert(p);
                let drift = (p - a).norm();
                fig.max_drift = fig.max_drift.max(drift);
                assert!(drift < 1e-9, "{} slides {drift} m at t = {t}", names[leg]);
            } else if let Some(a) = anchor[leg].take() {
                // Lift-off from where it stood.
                assert!((p - a).norm() < 1e-6, "{} leaves its foothold", names[leg]);
            }
            if p.y < radius - 1e-9 {
                panic!("{} below the ground at t = {t}: y = {}", names[leg], p.y);
            }
        }
        fig.min_standing = fig.min_standing.min(standing);
        assert!(
            standing >= min_standing,
            "{standing} feet standing at t = {t}"
        );
        if let Some((leg, kind, c)) = event {
            let f = feet[leg];
            let p = d.contacts[f];
            let radius = model.contacts[f].radius;
            match kind {
                0 => assert!((p.y - radius).abs() < 1e-9, "lift-off from the ground"),
                1 => assert!(
                    (p.y - (radius + h)).abs() < 1e-9,
                    "{} at mid-swing: y = {}, want {}",
                    names[leg],
                    p.y,
                    radius + h
                ),
                2 => {
                    assert!((p.y - radius).abs() < 1e-9);
                    landings[leg].push((c, p, t));
                    fig.landings += 1;
                    // Raibert: at touchdown the foot is the nominal
                    // foothold plus velocity·stance time/2 ahead of the
                    // body (a constant command only).
                    if straight && t - params.startup >= params.ramp {
                        let body = Vector3::from(pose.position);
                        let want = nominal[leg] + v * (0.5 * duty * t_period);
                        let rel = p - body;
                        assert!(
                            (rel.x - want.x).abs() < 1e-9 && (rel.z - want.z).abs() < 1e-9,
                            "{} lands at {rel} from the body, want {want}",
                            names[leg]
                        );
                    }
                }
                _ => {
                    // Mid-stance: the foot under its nominal place in the
                    // body frame (turning or not).
                    let rel = frame.inverse_transform_point(&Point3::from(p)).coords;
                    let want = nominal[leg];
                    assert!(
                        (rel.x - want.x).abs() < 1e-9 && (rel.z - want.z).abs() < 1e-9,
                        "{} at mid-stance at {rel} in the body frame, want {want}",
                        names[leg]
                    );
                }
            }
        }
        q_prev.copy_from_slice(&q);
        t_prev = t;
    }
    // Per cycle, each foot moves velocity·period (walking straight once
    // both mid-stances are past the ramp).
    if straight {
        for (leg, list) in landings.iter().enumerate() {
            let mut checked = 0;
            for w in list.windows(2) {
                let ((_, a, ta), (_, b, _)) = (w[0], w[1]);
                if ta + 0.5 * duty * t_period - params.startup < params.ramp {
                    continue;
                }
                let step = b - a;
                assert!(
                    (step - v * t_period).norm() < 1e-9,
                    "{}: step {step}, want {}",
                    names[leg],
                    v * t_period
                );
                checked += 1;
            }
            assert!(checked >= 2, "{}: {checked} steady strides", names[leg]);
        }
    }
    assert!(
        fig.landings >= feet.len() * (cycles - 1),
        "{} landings",
        fig.landings
    );
    fig
}

#[test]
fn hexapod_tripod_walks_on_its_footholds() {
    let model = lab();
    let (position, q0) = lab_standing(&model);
    let mut params = GaitParams::tripod().with_forward_speed(0.05);
    params.step_height = 0.02;
    let fig = check(&model, &LAB_FEET, position, &q0, params, 4, 3);
    eprintln!("hexapod tripod: {fig:?}");
    assert_eq!(fig.min_standing, 3);
}

#[test]
fn hexapod_tripod_sideways_with_wider_stance_and_lower_body() {
    let model = lab();
    let (position, q0) = lab_standing(&model);
    let mut params = GaitParams::tripod();
    params.velocity = [0.03, 0.0];
    params.step_height = 0.015;
    params.stance_width = 0.01;
    params.body_height = Some(0.09);
    let fig = check(&model, &LAB_FEET, position, &q0, params.clone(), 3, 3);
    eprintln!("hexapod sideways: {fig:?}");
    // The body goes to its commanded height during start-up and stays.
    let feet = GaitPlan::feet_by_name(&model, &LAB_FEET).unwrap();
    let plan = GaitPlan::new(&model, &feet, position, [0.0; 3], &q0, params.clone()).unwrap();
    assert_eq!(plan.base(0.0).position, position);
    for k in 0..30 {
        let y = plan.base(params.startup + 0.1 * k as f64).position[1];
        assert!((y - 0.09).abs() < 1e-15, "{y}");
    }
}

#[test]
fn hexapod_turns_in_place() {
    let model = lab();
    let (position, q0) = lab_standing(&model);
    let mut params = GaitParams::tripod();
    params.yaw_rate = 0.3;
    params.step_height = 0.02;
    let fig = check(&model, &LAB_FEET, position, &q0, params.clone(), 3, 3);
    eprintln!("hexapod turning: {fig:?}");
    let feet = GaitPlan::feet_by_name(&model, &LAB_FEET).unwrap();
    let plan = GaitPlan::new(&model, &feet, position, [0.0; 3], &q0, params.clone()).unwrap();
    let t = 3.0;
    let psi = 0.3 * (t - params.startup - params.ramp / 2.0);
    let pose = plan.base(t);
    assert!((pose.phi[1] - psi).abs() < 1e-12);
    assert!((pose.position[0] - position[0]).abs() < 1e-12);
    assert!((pose.position[2] - position[2]).abs() < 1e-12);
}

#[test]
fn solo12_trots() {
    let Some((model, position, q0)) = solo() else {
        return;
    };
    let mut params = GaitParams::trot().with_forward_speed(0.2);
    params.period = 0.4;
    params.step_height = 0.04;
    let fig = check(&model, &SOLO_FEET, position, &q0, params, 5, 2);
    eprintln!("solo trot: {fig:?}");
    assert_eq!(fig.min_standing, 2);
}

#[test]
fn solo12_walks() {
    let Some((model, position, q0)) = solo() else {
        return;
    };
    let mut params = GaitParams::walk().with_forward_speed(0.1);
    params.step_height = 0.05;
    let fig = check(&model, &SOLO_FEET, position, &q0, params, 4, 3);
    eprintln!("solo walk: {fig:?}");
    assert_eq!(fig.min_standing, 3);
}

#[test]
fn solo12_trots_on_a_curve() {
    let Some((model, position, q0)) = solo() else {
        return;
    };
    let mut params = GaitParams::trot().with_forward_speed(0.15);
    params.yaw_rate = 0.5;
    params.period = 0.4;
    params.body_height = Some(position[1] - 0.02);
    let fig = check(&model, &SOLO_FEET, position, &q0, params.clone(), 5, 2);
    eprintln!("solo curve: {fig:?}");
    // The body runs on a circle of radius v/ω about the turn's centre.
    let feet = GaitPlan::feet_by_name(&model, &SOLO_FEET).unwrap();
    let plan = GaitPlan::new(&model, &feet, position, [0.0; 3], &q0, params.clone()).unwrap();
    // Heading 0 faces −Z; turning left (ω > 0) the centre is at −X.
    let r = 0.15 / 0.5;
    let centre = [position[0] - r, position[2]];
    for k in 0..20 {
        let pose = plan.base(params.startup + params.ramp + 0.1 * k as f64);
        let dist = ((pose.position[0] - centre[0]).powi(2)
            + (pose.position[2] - centre[1]).powi(2))
        .sqrt();
        assert!((dist - r).abs() < 1e-12, "{dist} vs {r}");
        assert!((pose.position[1] - params.body_height.unwrap()).abs() < 1e-12);
    }
}

#[test]
fn bad_inputs_are_structured_errors() {
    let model = lab();
    let (position, q0) = lab_standing(&model);
    let feet = GaitPlan::feet_by_name(&model, &LAB_FEET).unwrap();
    let new = |feet: &[usize], q0: &[f64], p: GaitParams| {
        GaitPlan::new(&model, feet, position, [0.0; 3], q0, p).map(|_| ())
    };
    assert_eq!(
        new(&feet, &q0, GaitParams::trot()),
        Err(GaitError::PhaseCount { phases: 4, feet: 6 })
    );
    let phases = vec![0.0, 0.5, 0.0, 0.5, 0.0, 1.0];
    assert_eq!(
        new(&feet, &q0, GaitParams::tripod().with_phases(phases)),
        Err(GaitError::Phase { leg: 5, value: 1.0 })
    );
    let mut p = GaitParams::tripod();
    p.duty = 1.0;
    assert_eq!(new(&feet, &q0, p), Err(GaitError::Duty(1.0)));
    let mut p = GaitParams::tripod();
    p.period = 0.0;
    assert!(matches!(
        new(&feet, &q0, p),
        Err(GaitError::Parameter { name: "period", .. })
    ));
    assert_eq!(
        new(&[0, 1, 2, 3, 4, 99], &q0, GaitParams::tripod()),
        Err(GaitError::NoSuchContact {
            index: 99,
            count: 6
        })
    );
    assert_eq!(
        new(&[0, 1, 2, 3, 4, 0], &q0, GaitParams::tripod()),
        Err(GaitError::DuplicateFoot {
            foot: "lf_foot_sphere".into()
        })
    );
    assert_eq!(
        new(&feet, &q0[..17], GaitParams::tripod()),
        Err(GaitError::JointCount {
            what: "q0",
            got: 17,
            expected: 18
        })
    );
    let err = GaitPlan::feet_by_name(&model, &["lf_fot_sphere"]).unwrap_err();
    assert!(
        err.to_string().contains("did you mean \"lf_foot_sphere\""),
        "{err}"
    );
    // A body too high for the legs: out of reach at t = 0.
    let mut p = GaitParams::tripod();
    p.body_height = Some(0.5);
    p.startup = 0.0;
    match new(&feet, &q0, p) {
        Err(GaitError::OutOfReach {
            foot,
            time,
            residual,
        }) => {
            assert_eq!(foot, "lf_foot_sphere");
            assert_eq!(time, 0.0);
            assert!(residual > 0.2, "{residual}");
        }
        other => panic!("{other:?}"),
    }
    // Steps too high: the first swinging foot fails mid-swing.
    let mut p = GaitParams::tripod();
    p.step_height = 0.3;
    let mut plan = GaitPlan::new(&model, &feet, position, [0.0; 3], &q0, p.clone()).unwrap();
    let (mut q, mut qd) = (vec![0.0; 18], vec![0.0; 18]);
    let mut failed = None;
    for k in 0..2000 {
        if let Err(e) = plan.targets(k as f64 * 1e-3, &mut q, &mut qd) {
            failed = Some(e);
            break;
        }
    }
    match failed {
        Some(GaitError::OutOfReach { foot, time, .. }) => {
            let leg = LAB_FEET.iter().position(|n| *n == foot).unwrap();
            assert!(!plan.stance(leg, time), "{foot} fails in swing");
            assert!(time > p.startup && time < p.startup + p.period);
        }
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        plan.targets(1.0, &mut q[..3], &mut qd),
        Err(GaitError::JointCount { what: "q", .. })
    ));
}

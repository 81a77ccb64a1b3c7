//! Any robot model in flight ([`fbd_sim::robot`] with no terrain):
//!
//! * on the paper's hexapod built as a generic robot model
//!   ([`fbd_scenario::robot::hexapod_robot`]), a passive tumbling flight
//!   of the generic robot run reproduces the hexapod's run
//!   ([`fbd_sim::spatial`]: the same equations, with the hexapod's own
//!   parameters, controller and record around them) step by step: every
//!   coordinate and every hip and knee reaction force (matched by joint
//!   name) agree to the solver's tolerance;
//! * the lab hexapod URDF in passive flight keeps the discrete momentum
//!   laws (linear momentum changes by exactly `−M·g·Δt` a step, the
//!   angular momentum about the centre of mass is conserved), its centre
//!   of mass follows the parabola, and its energy error is of second order
//!   in Δt;
//! * a constant joint torque is internal: the angular momentum about the
//!   centre of mass is still conserved, while the joint does move;
//! * a joint driven onto an end of its range is held there by its stop
//!   (a limit event, the angle never beyond the end, the stop pushing).

use std::path::Path;

use fbd_contact::{Surface, Terrain};
use fbd_kinematics::JointLimits;
use fbd_kinematics::nalgebra::Vector3;
use fbd_robot::{ContactChoice, RobotModel, Up};
use fbd_sim::robot::{RobotData, RobotParams, RobotSim, step};
use fbd_sim::spatial::{SpatialModel, SpatialParams, run_collect};

/// `model` in flight (no terrain) from `q0`, `qdot0`, at `dt` for
/// `duration` under 9.81 m/s² (or `gravity`), passive.
fn in_flight(
    model: &RobotModel,
    dt: f64,
    duration: f64,
    gravity: f64,
    q0: &[f64],
    qdot0: &[f64],
) -> RobotSim {
    let mut p = RobotParams::new(q0.len());
    p.dt = dt;
    p.duration = duration;
    p.gravity = gravity;
    p.q0 = q0.to_vec();
    p.qdot0 = qdot0.to_vec();
    p.terrain = None;
    RobotSim::new(model, &p).expect("valid parameters")
}

/// A workspace stepping with the constant joint `torques`.
fn data_with(sim: &RobotSim, torques: &[f64]) -> RobotData {
    let mut data = RobotData::new(sim);
    data.external_torque = Some(torques.to_vec());
    data
}

/// The tumbling hexapod of `tests/spatial_flight.rs`: tilted body
/// spinning about all three axes, every joint moving, no ground, no stops.
fn tumbling(dt: f64, duration: f64) -> SpatialParams {
    let mut p = SpatialParams {
        dt,
        duration,
        terrain: Surface::new(Terrain::None, 0.0),
        joint_limits: JointLimits::none(),
        ..SpatialParams::default()
    };
    p.q0[3..6].copy_from_slice(&[0.2, -0.3, 0.25]);
    p.qdot0[..6].copy_from_slice(&[0.3, 1.0, -0.2, 1.2, -2.0, 0.8]);
    for s in 0..6 {
        let f = s as f64;
        p.q0[6 + 3 * s] = 0.1 * (f - 2.5);
        p.q0[7 + 3 * s] = -0.2 + 0.05 * f;
        p.qdot0[6 + 3 * s] = 1.5 - 0.5 * f;
        p.qdot0[7 + 3 * s] = -1.0 + 0.4 * f;
        p.qdot0[8 + 3 * s] = 2.4 - 0.7 * f;
    }
    p
}

fn diff(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (Vector3::from(*a) - Vector3::from(*b)).norm()
}

/// Newton's tolerance of the comparison of the two engines.
const TOL: f64 = 1e-11;

/// The key check: the generic flight stepper on the hexapod's robot model
/// is the spatial engine, step by step, for 0.3 s at Δt = 1 ms.
#[test]
fn the_hexapod_flies_as_the_spatial_engine_flies_it() {
    let params = tumbling(1e-3, 0.3);
    let mut model = SpatialModel::new(&params).expect("parameters");
    // Both solved to a hundredth of the engines' default tolerance (at the
    // default, 1e-9, the two trajectories part by the solver's tolerance,
    // 1e-9 after 190 steps).
    model.newton.residual_tol = TOL;
    let (rows, summary) = run_collect(&model);
    assert!(summary.error.is_none(), "{:?}", summary.error);

    let robot = fbd_scenario::robot::hexapod_robot(&params);
    let mut flight = in_flight(
        &robot,
        params.dt,
        params.duration,
        params.gravity,
        &params.q0,
        &params.qdot0,
    );
    assert_eq!(flight.steps, model.steps);
    assert_eq!(rows.len(), flight.steps);
    flight.newton.residual_tol = TOL;
    assert!(flight.mech.limits.is_empty());
    let torques = vec![0.0; robot.joints.len()];
    let mut data = data_with(&flight, &torques);
    // The reactions of each leg's hip (the compound joint θ1, θ2) and knee
    // (θ3), by joint name.
    let reaction = |name: String| {
        let j = robot.joint_index(&name).expect("joint");
        flight.mech.reaction_of[j]
    };
    let legs: Vec<(usize, usize)> = params
        .legs
        .iter()
        .map(|n| {
            (
                reaction(format!("theta1_{n}")),
                reaction(format!("theta3_{n}")),
            )
        })
        .collect();
    for &(hip, knee) in &legs {
        assert!(flight.mech.reactions[hip].compound && !flight.mech.reactions[knee].compound);
    }
    let weight = flight.mech.total_mass() * params.gravity;
    let (mut dq, mut df, mut dm): (f64, f64, f64) = (0.0, 0.0, 0.0);
    let mut largest_force: f64 = 0.0;
    for (k, row) in rows.iter().enumerate() {
        step(&flight, &mut data).unwrap_or_else(|e| panic!("{e}"));
        let rec = &data.record;
        assert_eq!(rec.step, k);
        assert_eq!(rec.t, row.t);
        for (a, b) in rec.q.iter().zip(&row.q) {
            dq = dq.max((a - b).abs());
        }
        for (s, &(hip, knee)) in legs.iter().enumerate() {
            let leg = model.leg_row(row, s);
            df = df
                .max(diff(&rec.reaction_force[hip], &leg.hip_force))
                .max(diff(&rec.reaction_force[knee], &leg.knee_force));
            dm = dm
                .max(diff(&rec.reaction_moment[hip], &leg.hip_moment))
                .max(diff(&rec.reaction_moment[knee], &leg.knee_moment));
            largest_force = largest_force
                .max(Vector3::from(leg.hip_force).norm())
                .max(Vector3::from(leg.knee_force).norm());
        }
        assert!(
            dq <= 1e-10,
            "step {k}: q differs from the spatial engine's by {dq:e}"
        );
    }
    // The last step's q[k+1] as well.
    assert_eq!(data.k, rows.len());
    println!(
        "tree vs spatial over {} steps: max |Δq| {dq:.2e}, max |ΔF| {df:.2e} N, \
         max |ΔM| {dm:.2e} N·m (largest joint force {largest_force:.1} N, weight {weight:.1} N)",
        rows.len()
    );
    // The solvers converge the force rows to 1e-11 of ~ the weight.
    assert!(largest_force > 0.1, "the legs carry no joint forces");
    assert!(df <= 1e-9 * weight, "joint forces differ by {df:e} N");
    assert!(dm <= 1e-9 * weight, "joint moments differ by {dm:e} N·m");
}

/// A small deterministic generator (uniform in [−1, 1)).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
    }
}

fn lab() -> RobotModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/robots/lab_hexapod.urdf");
    fbd_robot::urdf::load(&path, Up::Z, &ContactChoice::CollisionSpheres).expect("lab hexapod")
}

/// The lab hexapod's initial state: 1 m up, base tilted and tumbling,
/// joints at random angles with random rates.
fn lab_start(model: &RobotModel) -> (Vec<f64>, Vec<f64>) {
    let nq = 6 + model.joints.len();
    let mut rng = Rng(5);
    let mut q = vec![0.0; nq];
    q[1] = 1.0;
    for v in &mut q[3..6] {
        *v = 0.3 * rng.next();
    }
    for v in &mut q[6..] {
        *v = 0.3 * rng.next();
    }
    let qdot = (0..nq)
        .map(|i| if i < 6 { rng.next() } else { 1.5 * rng.next() })
        .collect();
    (q, qdot)
}

/// Per step: `(t, com, momentum, angular momentum about the origin,
/// energy)`.
type Sample = (f64, Vector3<f64>, Vector3<f64>, Vector3<f64>, f64);

/// Flies `model` for `duration` at `dt` with constant `torques`.
fn fly(model: &RobotModel, dt: f64, duration: f64, torques: &[f64]) -> (RobotSim, Vec<Sample>) {
    let (q0, qdot0) = lab_start(model);
    let mut flight = in_flight(model, dt, duration, 9.81, &q0, &qdot0);
    // Conservation is to the solver's tolerance: a hundredth of the
    // default.
    flight.newton.residual_tol = TOL;
    let mut data = data_with(&flight, torques);
    let mut out = Vec::with_capacity(flight.steps);
    for _ in 0..flight.steps {
        step(&flight, &mut data).unwrap_or_else(|e| panic!("{e}"));
        let r = &data.record;
        out.push((
            r.t,
            Vector3::from(r.com),
            Vector3::from(r.momentum),
            Vector3::from(r.angular_momentum),
            r.kinetic + r.potential,
        ));
    }
    (flight, out)
}

/// The largest change of the angular momentum about the centre of mass,
/// `H − C × P` (the record's `H` about the origin, `C` at k, `P` over the
/// step), relative to its size.
fn angular_drift(samples: &[Sample]) -> (f64, f64) {
    let hc = |s: &Sample| s.3 - s.1.cross(&s.2);
    let h0 = hc(&samples[0]);
    let worst = samples
        .iter()
        .map(|s| (hc(s) - h0).norm())
        .fold(0.0, f64::max);
    (worst, h0.norm())
}

#[test]
fn the_lab_hexapod_keeps_the_momentum_laws_and_the_parabola() {
    let model = lab();
    assert!(model.compound_joints().is_empty());
    let torques = vec![0.0; model.joints.len()];
    let dt = 1e-3;
    let (flight, s) = fly(&model, dt, 0.2, &torques);
    let m = flight.mech.total_mass();
    let g = 9.81;
    let mg_dt = m * g * dt;
    // Linear momentum: exactly −M·g·Δt per step.
    for w in s.windows(2) {
        let want = w[0].2 - Vector3::new(0.0, mg_dt, 0.0);
        let off = (w[1].2 - want).norm();
        assert!(
            off < 1e-8 * mg_dt,
            "t = {}: momentum off by {off:e}",
            w[1].0
        );
    }
    // Angular momentum about the centre of mass: conserved.
    let (worst, h) = angular_drift(&s);
    println!("lab hexapod: |ΔH_c| ≤ {worst:.2e} of |H_c| = {h:.3e}");
    assert!(h > 1e-3, "the robot does not turn");
    assert!(worst < 1e-10 * (h + mg_dt), "H_c drifts by {worst:e}");
    // The centre of mass on the parabola of its first step's velocity.
    let (c0, p_half) = (s[0].1, s[0].2);
    let v0 = p_half / m + Vector3::new(0.0, 0.5 * g * dt, 0.0);
    let mut off: f64 = 0.0;
    for &(t, c, ..) in &s {
        let want = c0 + v0 * t - Vector3::new(0.0, 0.5 * g * t * t, 0.0);
        off = off.max((c - want).norm());
    }
    println!("lab hexapod: CoM off the parabola by {off:.2e} m");
    assert!(
        off < 1e-9,
        "the centre of mass leaves the parabola by {off:e} m"
    );
    let fell = c0.y - s.last().unwrap().1.y;
    assert!(fell > 0.15, "it did not fall: {fell}");
}

/// The energy error over 0.2 s of flight: second order in Δt.
#[test]
fn the_lab_hexapods_energy_error_is_of_second_order() {
    let model = lab();
    let torques = vec![0.0; model.joints.len()];
    let drift = |dt: f64| {
        let (_, s) = fly(&model, dt, 0.2, &torques);
        let e0 = s[0].4;
        s.iter().map(|x| (x.4 - e0).abs()).fold(0.0, f64::max)
    };
    let (coarse, fine) = (drift(2e-3), drift(1e-3));
    let ratio = coarse / fine;
    println!(
        "energy drift over 0.2 s: {coarse:.3e} J at 2 ms, {fine:.3e} J at 1 ms (ratio {ratio:.2})"
    );
    assert!(fine > 0.0);
    assert!((3.0..=5.0).contains(&ratio), "ratio {ratio}");
}

/// A constant torque on one joint acts on both bodies it joins: the
/// angular momentum about the centre of mass is still conserved (and the
/// linear momentum law holds), while the joint moves otherwise than the
/// passive flight's.
#[test]
fn a_joint_torque_is_internal() {
    let model = lab();
    let mut torques = vec![0.0; model.joints.len()];
    let j = 0;
    torques[j] = 0.2;
    let (flight, s) = fly(&model, 1e-3, 0.1, &torques);
    let mg_dt = flight.mech.total_mass() * 9.81 * 1e-3;
    for w in s.windows(2) {
        let want = w[0].2 - Vector3::new(0.0, mg_dt, 0.0);
        assert!((w[1].2 - want).norm() < 1e-8 * mg_dt);
    }
    let (worst, h) = angular_drift(&s);
    println!("torqued lab hexapod: |ΔH_c| ≤ {worst:.2e} of |H_c| = {h:.3e}");
    assert!(worst < 1e-10 * (h + mg_dt), "H_c drifts by {worst:e}");
    // The torque did something: the joint's angle differs from the
    // passive flight's.
    let angle = |torques: &[f64]| {
        let (q0, qdot0) = lab_start(&model);
        let flight = in_flight(&model, 1e-3, 0.1, 9.81, &q0, &qdot0);
        let mut data = data_with(&flight, torques);
        for _ in 0..flight.steps {
            step(&flight, &mut data).unwrap();
        }
        data.q[6 + j]
    };
    let passive = angle(&vec![0.0; model.joints.len()]);
    let driven = angle(&torques);
    assert!(
        (driven - passive).abs() > 1e-3,
        "the torque has no effect: {driven} vs {passive}"
    );
}

/// A joint driven onto an end of its range is held by its stop: a limit
/// event, the angle never beyond the end (to the stop rows' tolerance),
/// the stop's moment pushing the joint back into its range.
#[test]
fn a_joint_driven_onto_its_limit_is_held_by_its_stop() {
    let model = lab();
    let j = 0;
    let upper = model.joints[j].limits.unwrap().upper;
    let (mut q0, mut qdot0) = lab_start(&model);
    q0[6 + j] = upper - 0.01;
    qdot0[6 + j] = 5.0;
    let flight = in_flight(&model, 1e-3, 0.1, 9.81, &q0, &qdot0);
    let mut data = data_with(&flight, &vec![0.0; model.joints.len()]);
    let mut held = 0;
    for _ in 0..flight.steps {
        step(&flight, &mut data).unwrap_or_else(|e| panic!("{e}"));
        let r = &data.record;
        assert!(r.q[6 + j] <= upper + 1e-9, "beyond the end: {}", r.q[6 + j]);
        if r.limit[j] == fbd_sim::LimitCode::Max {
            held += 1;
            assert!(r.stop[j] <= 1e-9, "the stop pulls: {} N·m", r.stop[j]);
        }
    }
    let arrival = data
        .limit_events
        .iter()
        .find(|e| e.joint_index == j)
        .expect("a limit event");
    assert!(arrival.step < 10, "arrives at step {}", arrival.step);
    assert_eq!(arrival.to, fbd_sim::LimitCode::Max);
    assert!(held > 0);
}

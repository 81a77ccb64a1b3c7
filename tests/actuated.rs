//! Actuated runs: PD-held and trajectory-tracking joints (`[control]`),
//! standing on flat ground and on a slope.

mod common;

use common::physics::{points, run_ok, standing_q, worst_body_imbalance};
use fbd_contact::{StateCode, Terrain};
use fbd_sim::{Control, Model, PlanarParams, RobotRecord};

/// PD gains that hold the standing robot (N·m/rad, N·m·s/rad).
const KP: f64 = 3000.0;
const KD: f64 = 10.0;

/// The standing pose (θ3 = 250°, θ2 = 0) held by PD at its own angles,
/// dropped from `drop` above ground contact.
fn pd_stand(drop: f64) -> PlanarParams {
    let mut p = PlanarParams {
        dt: 0.002,
        duration: 1.5,
        ..PlanarParams::default()
    };
    p.q0 = standing_q(&p, 250.0);
    p.q0[1] += drop;
    p.control = Control::Pd {
        kp: KP,
        kd: KD,
        torque_limit: None,
        target: [[p.q0[3], p.q0[4]], [p.q0[5], p.q0[6]]],
    };
    p
}

fn weight(model: &Model) -> f64 {
    model.mech.total_mass() * model.params.gravity
}

/// The states of the first two contact points (the tips).
fn states(r: &RobotRecord) -> [StateCode; 2] {
    [r.contacts[0].state, r.contacts[1].state]
}

/// Largest generalised velocity between the last two rows.
fn final_speed(rows: &[RobotRecord], dt: f64) -> f64 {
    let (a, b) = (&rows[rows.len() - 2], &rows[rows.len() - 1]);
    (0..b.q.len())
        .map(|i| ((b.q[i] - a.q[i]) / dt).abs())
        .fold(0.0, f64::max)
}

/// The PD-held standing robot on a 10° slope (rising towards +X), tilted
/// with it (φz = 10°) so that both tips rest on the surface.
fn slope_stand(mu_static: f64, mu_dynamic: f64) -> PlanarParams {
    let mut p = pd_stand(0.0);
    p.duration = 1.0;
    p.terrain = Terrain::slope_deg(10.0, 0.0);
    p.friction.mu_static = mu_static;
    p.friction.mu_dynamic = mu_dynamic;
    p.q0[2] = 10f64.to_radians();
    // The geometry only: no ground, no controller (its gains are for the
    // robot standing, not floating).
    let model = Model::planar(&PlanarParams {
        terrain: Terrain::None,
        control: Control::None,
        ..p.clone()
    })
    .unwrap();
    let pts = points(&model, &p.q0);
    let tip3 = pts[model.index.tip[0]];
    p.q0[1] -= p.terrain.clearance(tip3);
    p
}

/// `(θ2, θ3)` of leg `leg` (0 = leg 3) that put its tip at `tip − hip =
/// rel` with the body as in `q` (Newton with a difference Jacobian).
fn leg_ik(model: &Model, q: [f64; 7], leg: usize, rel: [f64; 2]) -> [f64; 2] {
    let (hip, tip) = (model.index.hip[leg], model.index.tip[leg]);
    let mut q = q;
    let i = 3 + 2 * leg;
    let f = |q: &[f64; 7]| {
        let p = points(model, q);
        [
            p[tip][0] - p[hip][0] - rel[0],
            p[tip][1] - p[hip][1] - rel[1],
        ]
    };
    for _ in 0..30 {
        let r = f(&q);
        let mut j = [[0.0; 2]; 2];
        for c in 0..2 {
            let mut qh = q;
            qh[i + c] += 1e-7;
            let rh = f(&qh);
            j[0][c] = (rh[0] - r[0]) / 1e-7;
            j[1][c] = (rh[1] - r[1]) / 1e-7;
        }
        let det = j[0][0] * j[1][1] - j[0][1] * j[1][0];
        q[i] -= (j[1][1] * r[0] - j[0][1] * r[1]) / det;
        q[i + 1] -= (-j[1][0] * r[0] + j[0][0] * r[1]) / det;
    }
    assert!(f(&q).iter().all(|v| v.abs() < 1e-10));
    [q[i], q[i + 1]]
}

#[test]
fn a_pd_held_joint_moves_towards_its_target_in_flight() {
    // Positive torque drives the joint angle to larger values: a single
    // joint with an offset target, every other joint held where it is.
    for (joint, offset) in [(4, 0.3), (3, -0.2), (6, -0.3), (5, 0.25)] {
        let mut p = PlanarParams {
            dt: 0.002,
            duration: 0.3,
            terrain: Terrain::None,
            ..PlanarParams::default()
        };
        let mut target = [[p.q0[3], p.q0[4]], [p.q0[5], p.q0[6]]];
        target[(joint - 3) / 2][(joint - 3) % 2] += offset;
        p.control = Control::Pd {
            kp: 20.0,
            kd: 1.0,
            torque_limit: None,
            target,
        };
        let (model, rows, _) = run_ok(&p);
        let moved = rows.last().unwrap().q[fbd_sim::robot::plane_q_index(joint)] - p.q0[joint];
        assert!(
            moved * offset > 0.0 && (moved - offset).abs() < 0.5 * offset.abs(),
            "joint q[{joint}]: moved {moved}, target offset {offset}"
        );
        let (worst, at) = worst_body_imbalance(&model, &rows);
        assert!(worst < 1e-6, "{at}");
    }
}

#[test]
fn pd_stand_lands_and_comes_to_rest() {
    let p = pd_stand(0.05);
    let (model, rows, summary) = run_ok(&p);
    assert!(
        summary.events.iter().any(|e| e.to == StateCode::St2),
        "{:?}",
        summary.events
    );
    let (last, w) = (rows.last().unwrap(), weight(&model));
    assert_eq!(&states(last), &[StateCode::St2, StateCode::St2]);
    assert!(
        final_speed(&rows, p.dt) < 1e-6,
        "still moving: {}",
        final_speed(&rows, p.dt)
    );
    let (n, fa) = (
        last.contacts[0].normal + last.contacts[1].normal,
        last.contacts[0].tangential[0] + last.contacts[1].tangential[0],
    );
    assert!((n - w).abs() < 1e-6 * w, "n3 + n4 = {n}, weight {w}");
    assert!(fa.abs() < 1e-6 * w, "fa3 + fa4 = {fa}");
    // The joints carry the robot: torques are far from zero, and every
    // body's balance includes them.
    assert!(
        last.torque.iter().all(|t| t.abs() > 1.0),
        "{:?}",
        last.torque
    );
    let (worst, at) = worst_body_imbalance(&model, &rows);
    assert!(worst < 1e-6, "{at}");
}

#[test]
fn torque_limit_saturates() {
    let mut p = pd_stand(0.05);
    p.duration = 0.4;
    let Control::Pd { torque_limit, .. } = &mut p.control else {
        unreachable!()
    };
    *torque_limit = Some(15.0);
    let (model, rows, _) = run_ok(&p);
    let peak = rows
        .iter()
        .flat_map(|r| r.torque.iter().copied())
        .fold(0.0f64, |m, t| m.max(t.abs()));
    assert!((peak - 15.0).abs() < 1e-12, "peak torque {peak}");
    let (worst, at) = worst_body_imbalance(&model, &rows);
    assert!(worst < 1e-6, "{at}");
}

#[test]
fn sticks_on_a_10_degree_slope_when_mu_static_exceeds_tan_10() {
    let p = slope_stand(0.4, 0.3);
    let (model, rows, _) = run_ok(&p);
    // After the load-up transient (the legs start unloaded) both tips stick.
    let settled: Vec<&RobotRecord> = rows.iter().filter(|r| r.t >= 0.3).collect();
    let first = settled[0];
    for r in &settled {
        assert_eq!(&states(r), &[StateCode::St2, StateCode::St2], "t = {}", r.t);
        for c in 0..2 {
            let d = (r.contacts[c].point[0] - first.contacts[c].point[0])
                .hypot(r.contacts[c].point[1] - first.contacts[c].point[1]);
            assert!(d < 1e-9, "t = {}: tip {c} moved {d}", r.t);
            assert!(
                r.contacts[c].tangential[0].abs() < 0.4 * r.contacts[c].normal,
                "t = {}: tip {c} |fa| = {} > μS n = {}",
                r.t,
                r.contacts[c].tangential[0],
                0.4 * r.contacts[c].normal
            );
        }
    }
    let last = rows.last().unwrap();
    assert!(final_speed(&rows, p.dt) < 1e-3);
    // At rest the friction needed is tan 10°: Σfa/Σn along the slope.
    let ratio = (last.contacts[0].tangential[0] + last.contacts[1].tangential[0])
        / (last.contacts[0].normal + last.contacts[1].normal);
    assert!(
        (ratio - 10f64.to_radians().tan()).abs() < 1e-3,
        "friction ratio {ratio}"
    );
    let w = weight(&model);
    let (c, s) = (10f64.to_radians().cos(), 10f64.to_radians().sin());
    assert!((last.contacts[0].normal + last.contacts[1].normal - w * c).abs() < 1e-3 * w);
    assert!(
        (last.contacts[0].tangential[0] + last.contacts[1].tangential[0] - w * s).abs() < 1e-3 * w
    );
    let (worst, at) = worst_body_imbalance(&model, &rows);
    assert!(worst < 1e-6, "{at}");
}

#[test]
fn slides_down_a_10_degree_slope_when_mu_static_is_below_tan_10() {
    let p = slope_stand(0.12, 0.1);
    let (model, rows, summary) = run_ok(&p);
    assert!(summary.events.iter().any(|e| e.to == StateCode::St3));
    let (first, last) = (&rows[0], rows.last().unwrap());
    assert_eq!(&states(last), &[StateCode::St3, StateCode::St3]);
    for c in 0..2 {
        let (dx, dy) = (
            last.contacts[c].point[0] - first.contacts[c].point[0],
            last.contacts[c].point[1] - first.contacts[c].point[1],
        );
        assert!(dx < -0.1 && dy < -0.01, "tip {c} moved ({dx}, {dy})");
        assert!(
            (dy / dx - 10f64.to_radians().tan()).abs() < 1e-6,
            "tip {c} left the slope"
        );
        // Sliding downhill (−tangent): friction acts uphill, Fa = μD N.
        assert!(
            (last.contacts[c].tangential[0] - 0.1 * last.contacts[c].normal).abs()
                < 1e-9 * last.contacts[c].normal,
            "fa {} n {}",
            last.contacts[c].tangential[0],
            last.contacts[c].normal
        );
    }
    let (worst, at) = worst_body_imbalance(&model, &rows);
    assert!(worst < 1e-6, "{at}");
}

#[test]
fn squat_and_rise_tracks_the_trajectory() {
    let mut p = PlanarParams {
        dt: 0.002,
        duration: 2.0,
        ..PlanarParams::default()
    };
    p.friction.mu_static = 0.8;
    p.friction.mu_dynamic = 0.6;
    p.q0 = standing_q(&p, 250.0);
    let model = Model::planar(&p).unwrap();
    let pts = points(&model, &p.q0);
    let legs = [0, 1].map(|leg| {
        let (hip, tip) = (pts[model.index.hip[leg]], pts[model.index.tip[leg]]);
        let down = leg_ik(&model, p.q0, leg, [tip[0] - hip[0], tip[1] - hip[1] + 0.06]);
        let up = [p.q0[3 + 2 * leg], p.q0[4 + 2 * leg]];
        fbd_sim::LegTrajectory {
            times: vec![0.2, 0.7, 1.0, 1.5],
            targets: vec![up, down, down, up],
        }
    });
    p.control = Control::Trajectory {
        kp: KP,
        kd: KD,
        torque_limit: Some(200.0),
        legs,
    };
    let (model, rows, _) = run_ok(&p);
    let at = |t: f64| rows.iter().find(|r| (r.t - t).abs() < 1e-9).unwrap();
    let (y0, y_low, y_end) = (at(0.2).q[1], at(1.0).q[1], rows.last().unwrap().q[1]);
    assert!(
        (y0 - y_low - 0.06).abs() < 0.01,
        "squat depth {}",
        y0 - y_low
    );
    assert!(
        (y_end - y0).abs() < 0.01,
        "rose to {y_end}, started at {y0}"
    );
    assert!(final_speed(&rows, p.dt) < 1e-3);
    let (worst, at) = worst_body_imbalance(&model, &rows);
    assert!(worst < 1e-6, "{at}");
}

//! Imported robots on the ground (`fbd_sim::robot`): the generic tree
//! model stepped by the engine with the foot–soil state machine. Every
//! record is checked against the laws it reports — each FBD body's
//! translation balanced by the forces of the row (its joint reactions, its
//! contact forces, its weight), the whole robot's momentum changed by the
//! contact forces and gravity alone, `N ≥ 0`, `|Ft| ≤ μS·N` while
//! sticking, `Ft = −μD·N·ŝ` while sliding (ŝ the step's own slip).

use fbd_contact::StateCode;
use fbd_robot::RobotModel;
use fbd_robot::nalgebra::Vector3;
use fbd_sim::Engine;
use fbd_sim::robot::{RobotControl, RobotData, RobotParams, RobotRecord, RobotSim, step};

fn lab_stand() -> (RobotModel, Vec<f64>, Vec<f64>) {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/robots/lab_hexapod_stand.toml");
    let robot = fbd_scenario::robot::load(&path).expect("loads");
    let (q0, qd0) = robot.flight_state();
    (robot.model, q0, qd0)
}

/// Runs `sim` to the end, every record kept.
fn run(sim: &RobotSim) -> (Vec<RobotRecord>, RobotData) {
    let mut data = RobotData::new(sim);
    let mut out = Vec::with_capacity(sim.steps);
    for _ in 0..sim.steps {
        step(sim, &mut data).unwrap_or_else(|e| panic!("{e}"));
        out.push(data.record.clone());
    }
    (out, data)
}

/// The largest violation (N) of a body's translational balance, of the
/// whole robot's momentum change and of the contact laws over `rows`.
fn audit(sim: &RobotSim, rows: &[RobotRecord]) -> [f64; 3] {
    let mech = &sim.mech;
    let model = &mech.model;
    let dt = sim.params.dt;
    let g = Vector3::new(0.0, -sim.params.gravity, 0.0);
    let mut kin = fbd_dynamics::tree::kin::TreeKin::new(model);
    let com: Vec<Vec<Vector3<f64>>> = rows
        .iter()
        .map(|r| {
            kin.eval(model, &r.q);
            mech.bodies.iter().map(|b| kin.com[b.model_body]).collect()
        })
        .collect();
    let friction = sim.params.friction;
    let (mut body_err, mut momentum_err, mut law_err) = (0.0f64, 0.0f64, 0.0f64);
    for k in 1..rows.len() - 1 {
        let r = &rows[k];
        // Each FBD body: m·Δ²c/Δt² = m·g + Σ reactions + Σ contacts.
        for (b, body) in mech.bodies.iter().enumerate() {
            let acc = (com[k + 1][b] - 2.0 * com[k][b] + com[k - 1][b]) / (dt * dt);
            let mut f = body.mass * g;
            for (i, re) in mech.reactions.iter().enumerate() {
                let fr = Vector3::from(r.reaction_force[i]);
                if re.child == b {
                    f += fr;
                }
                if re.parent == b {
                    f -= fr;
                }
            }
            for (c, tc) in mech.contacts.iter().enumerate() {
                if tc.body == b {
                    f += Vector3::from(r.contacts[c].force);
                }
            }
            body_err = body_err.max((body.mass * acc - f).norm());
        }
        // The whole robot: Δp/Δt = Σ contact forces + M·g.
        let dp = (Vector3::from(r.momentum) - Vector3::from(rows[k - 1].momentum)) / dt;
        let mut f = mech.total_mass() * g;
        for c in &r.contacts {
            f += Vector3::from(c.force);
        }
        momentum_err = momentum_err.max((dp - f).norm());
        // The contact laws (flat ground: normal +Y).
        for (c, row) in r.contacts.iter().enumerate() {
            let n = row.force[1];
            let ft = Vector3::new(row.force[0], 0.0, row.force[2]);
            match row.state {
                StateCode::St1 => law_err = law_err.max(Vector3::from(row.force).norm()),
                StateCode::St2 => {
                    law_err = law_err.max(-n).max(ft.norm() - friction.mu_static * n);
                }
                StateCode::St3 => {
                    let next = Vector3::from(rows[k + 1].contacts[c].point);
                    let s = next - Vector3::from(row.point);
                    let s = Vector3::new(s.x, 0.0, s.z);
                    let want = if s.norm() > 1e-9 {
                        -friction.mu_dynamic * n * s / s.norm()
                    } else {
                        ft
                    };
                    law_err = law_err.max(-n).max((ft - want).norm());
                }
            }
        }
    }
    [body_err, momentum_err, law_err]
}

#[test]
fn lab_hexapod_stands_under_pd_with_every_row_balanced() {
    let (model, q0, qd0) = lab_stand();
    let nj = model.joints.len();
    let mut p = RobotParams::new(q0.len());
    p.q0 = q0.clone();
    p.qdot0 = qd0;
    p.duration = 1.0;
    p.control = RobotControl::Pd {
        kp: vec![20.0; nj],
        kd: vec![0.2; nj],
        target: q0[6..].to_vec(),
        torque_limit: None,
    };
    let sim = RobotSim::new(&model, &p).expect("valid");
    let (rows, data) = run(&sim);
    let weight = model.mass() * 9.81;
    let last = rows.last().expect("rows");
    let total: f64 = last.contacts.iter().map(|c| c.force[1]).sum();
    assert!(
        (total - weight).abs() < 1e-6 * weight,
        "at rest the feet carry the weight: {total} vs {weight} N"
    );
    assert!(data.events.is_empty(), "a robot at rest writes no events");
    assert!(
        last.contacts.iter().all(|c| c.state == StateCode::St2),
        "every foot sticks"
    );
    let [body, momentum, law] = audit(&sim, &rows);
    eprintln!("stand: body {body:.3e} N, momentum {momentum:.3e} N, laws {law:.3e} N");
    assert!(body < 1e-6 * weight, "body balance {body} N");
    assert!(momentum < 1e-6 * weight, "momentum {momentum} N");
    assert!(law < 1e-6 * weight, "contact laws {law} N");
}

#[test]
fn lab_hexapod_landing_tumbles_within_the_laws() {
    let (model, mut q0, mut qd0) = lab_stand();
    // Dropped from 6 cm higher, tilted, spinning and sliding sideways,
    // the joints held by PD at the standing angles: feet touch down one by
    // one, slide and stick.
    q0[1] += 0.06;
    q0[3] = 0.15;
    q0[5] = -0.1;
    qd0[0] = 0.4;
    qd0[2] = -0.2;
    qd0[4] = 1.5;
    let nj = model.joints.len();
    let mut p = RobotParams::new(q0.len());
    p.control = RobotControl::Pd {
        kp: vec![20.0; nj],
        kd: vec![0.2; nj],
        target: q0[6..].to_vec(),
        torque_limit: None,
    };
    p.q0 = q0;
    p.qdot0 = qd0;
    p.duration = 0.6;
    p.friction = fbd_contact::Friction {
        mu_static: 0.5,
        mu_dynamic: 0.4,
    };
    let sim = RobotSim::new(&model, &p).expect("valid");
    let (rows, data) = run(&sim);
    let weight = model.mass() * 9.81;
    let slides = rows
        .iter()
        .flat_map(|r| &r.contacts)
        .filter(|c| c.state == StateCode::St3)
        .count();
    let touched = (0..sim.contacts())
        .filter(|&c| rows.iter().any(|r| r.contacts[c].state != StateCode::St1))
        .count();
    eprintln!(
        "landing: {} events, {} limit events, {} retries, {slides} sliding rows, {touched} feet touched, {} iterations",
        data.events.len(),
        data.limit_events.len(),
        data.retries.len(),
        data.newton_iterations
    );
    assert_eq!(touched, 6, "every foot lands");
    assert!(slides > 0, "some foot slides");
    assert!(data.events.len() < 100, "events stay bounded");
    let [body, momentum, law] = audit(&sim, &rows);
    eprintln!("landing: body {body:.3e} N, momentum {momentum:.3e} N, laws {law:.3e} N");
    assert!(body < 1e-6 * weight, "body balance {body} N");
    assert!(momentum < 1e-6 * weight, "momentum {momentum} N");
    assert!(law < 1e-6 * weight, "contact laws {law} N");
}

//! An imported robot through the stepping API ([`fbd_sim::simulator`],
//! `impl Plant for RobotSim`): the lab hexapod of
//! `examples/robots/lab_hexapod_stand.toml` set down on its feet. Asserted:
//! a saved state restored (in the same simulator or another) repeats the
//! steps bit for bit through touchdown; PD targets through the API are the
//! configured `[control] kind = "pd"` run bit for bit; the readouts agree
//! with the run's records and carry the robot's weight.

use fbd_sim::robot::{RobotControl, RobotSim};
use fbd_sim::simulator::{Action, PdTargets, Plant, Simulator};

fn lab_stand() -> fbd_scenario::robot::LoadedRobot {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/robots/lab_hexapod_stand.toml");
    fbd_scenario::robot::load(&path).expect("loads")
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

const KP: f64 = 20.0;
const KD: f64 = 0.2;

fn hold(sim: &RobotSim) -> PdTargets {
    let q0 = &sim.params.q0;
    let angles: Vec<f64> = sim.joint_indices().iter().map(|&i| q0[i]).collect();
    PdTargets::hold(KP, KD, None, &angles)
}

#[test]
fn restore_is_bit_identical_robot() {
    let robot = lab_stand();
    let model = robot.sim().expect("valid");
    let n = model.joint_indices().len();
    assert_eq!(n, model.mech.model.joints.len());
    assert_eq!(model.joint_indices()[0], 6);
    let pd = hold(&model);
    let mut sim = Simulator::new(model);
    for _ in 0..5 {
        sim.step(&Action::Pd(&pd)).unwrap();
    }
    let saved = sim.state();
    let tau = vec![0.05; n];
    let run = |sim: &mut Simulator<RobotSim>| {
        let mut out = Vec::new();
        for k in 0..60 {
            if k % 2 == 0 {
                sim.step(&Action::Pd(&pd)).unwrap();
            } else {
                sim.step(&Action::Torques(&tau)).unwrap();
            }
            let r = sim.readout();
            out.push(bits(&r.q));
            out.push(bits(
                &r.contacts
                    .iter()
                    .flat_map(|c| c.force)
                    .chain(r.reactions.iter().flat_map(|x| x.moment))
                    .collect::<Vec<_>>(),
            ));
        }
        out
    };
    let first = run(&mut sim);
    let r = sim.readout();
    assert!(
        r.contacts.iter().any(|c| c.normal_force > 0.0),
        "the feet carry load in the compared steps"
    );
    sim.set_state(&saved);
    assert_eq!(run(&mut sim), first);
    let mut other = Simulator::new(sim.model().clone());
    other.set_state(&saved);
    assert_eq!(run(&mut other), first);
}

#[test]
fn pd_through_the_api_is_the_configured_pd_robot() {
    let robot = lab_stand();
    let passive = robot.sim().expect("valid");
    let nj = passive.mech.model.joints.len();
    let mut params = passive.params.clone();
    params.duration = 0.2;
    let targets = hold(&passive);
    params.control = RobotControl::Pd {
        kp: vec![KP; nj],
        kd: vec![KD; nj],
        target: targets.position.clone(),
        torque_limit: None,
    };
    let configured = RobotSim::new(&robot.model, &params).expect("stable gains");
    let mut rows = Vec::new();
    let run = robot.run_sim(
        &configured,
        &std::sync::atomic::AtomicBool::new(false),
        &mut |r| rows.push(r.clone()),
    );
    assert!(run.summary.error.is_none());
    assert_eq!(rows.len(), configured.steps);
    // The lab hexapod's joints have effort limits; PD through the API is
    // clamped by its torque_limit only: compare while no torque reaches an
    // effort limit.
    let effort = passive.effort.clone();
    let mut sim = Simulator::new(passive);
    let mut compared = 0;
    for row in rows.iter().skip(1) {
        let prev = &rows[row.step - 1];
        let clamped = prev
            .torque
            .iter()
            .zip(&effort)
            .any(|(t, e)| e.is_some_and(|e| t.abs() >= e));
        if clamped {
            break;
        }
        sim.step(&Action::Pd(&targets)).unwrap();
        assert_eq!(bits(sim.q()), bits(&row.q), "step {}", row.step);
        compared += 1;
    }
    assert!(compared > 100, "{compared} steps compared");
    let r = sim.readout();
    let row = &rows[r.k - 1];
    for (c, want) in r.contacts.iter().zip(&row.contacts) {
        assert_eq!(
            (c.force, c.normal_force, c.state),
            (want.force, want.normal, want.state)
        );
    }
    for (j, joint) in r.joints.iter().enumerate() {
        assert_eq!(joint.torque, row.torque[j]);
    }
    for (x, (f, m)) in r
        .reactions
        .iter()
        .zip(row.reaction_force.iter().zip(&row.reaction_moment))
    {
        assert_eq!((x.force, x.moment), (*f, *m));
    }
    assert_eq!((r.kinetic, r.potential), (row.kinetic, row.potential));
    // Standing: the ground carries the weight, the root's pose is q's.
    let weight = sim.model().mech.total_mass() * 9.81;
    let fy: f64 = r.contacts.iter().map(|c| c.force[1]).sum();
    assert!((fy - weight).abs() < 0.05 * weight, "{fy} vs {weight}");
    assert!(r.legs.is_empty());
    assert_eq!(r.bodies.len(), sim.model().mech.model.bodies.len());
    let dt = sim.model().params.dt;
    for c in &r.contacts {
        if c.state == fbd_contact::StateCode::St2 {
            assert!(c.slip_velocity.iter().all(|v| v.abs() < 1e-9), "{c:?}");
        }
        assert_eq!(c.normal, [0.0, 1.0, 0.0]);
    }
    // The root body's twist is the backward difference of its pose.
    let b = &r.bodies[0];
    let (q, qp) = (sim.q(), sim.q_prev());
    let moved: f64 = (0..3).map(|i| (q[i] - qp[i]).abs()).sum();
    assert!(b.velocity.iter().all(|v| v.is_finite()));
    assert!(moved / dt < 1.0, "standing still: {}", moved / dt);
}

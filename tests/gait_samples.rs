//! The targets an imported robot's gait records for its start-up
//! stability check (`fbd_robot::gait::SampledTargets`): recorded by the
//! configuration's reach check, they are the run's own targets at the
//! sampled steps, bit for bit, and the check gives the same verdicts with
//! them as with the poses it solves itself.

use fbd_sim::robot::{RobotControl, RobotSim, gait_pose_stride};

fn lab_walk() -> fbd_scenario::robot::LoadedRobot {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples/robots/lab_hexapod_walk.toml");
    fbd_scenario::robot::load(&path).expect("loads")
}

/// The gait plan of `params` (mutable, to drop its samples).
fn plan_of(params: &mut fbd_sim::robot::RobotParams) -> &mut fbd_robot::gait::GaitPlan {
    match &mut params.control {
        RobotControl::Gait { plan, .. } => plan,
        _ => panic!("a gait controller"),
    }
}

#[test]
fn the_samples_are_the_runs_targets_at_the_sampled_steps() {
    let robot = lab_walk();
    let mut params = robot.params();
    let dt = params.dt;
    let plan = plan_of(&mut params).clone();
    let samples = plan.samples().expect("recorded by the reach check").clone();
    assert_eq!(samples.dt, dt);
    let g = plan.params();
    let horizon = params.duration.min(g.startup + g.ramp + 2.0 * g.period);
    let steps = (horizon / dt).round() as usize + 1;
    assert_eq!(samples.stride, gait_pose_stride(steps));
    assert_eq!(samples.targets.len(), (steps - 1) / samples.stride + 1);
    assert!(
        samples.targets.len() > 150,
        "about 200 poses over the horizon"
    );
    // The run's controller steps its own copy of the plan every Δt.
    let mut stepped = plan.clone();
    let n = stepped.standing().len();
    let (mut q, mut qd) = (vec![0.0; n], vec![0.0; n]);
    for k in 0..steps {
        stepped.targets(k as f64 * dt, &mut q, &mut qd).unwrap();
        if k % samples.stride == 0 {
            assert_eq!(q, samples.targets[k / samples.stride], "step {k}");
        }
    }
}

#[test]
fn the_check_gives_the_same_verdicts_with_and_without_the_samples() {
    let robot = lab_walk();
    // The example's gains pass; gains a hundred times higher fail (the
    // explicit PD's limit), with the samples and without.
    for scale in [1.0, 100.0] {
        let mut with = robot.params();
        if let RobotControl::Gait { kp, kd, .. } = &mut with.control {
            kp.iter_mut().for_each(|k| *k *= scale);
            kd.iter_mut().for_each(|k| *k *= scale);
        }
        let mut without = with.clone();
        plan_of(&mut without).forget_samples();
        assert!(plan_of(&mut with).samples().is_some());
        let a = RobotSim::new(&robot.model, &with).map(|_| ());
        let b = RobotSim::new(&robot.model, &without).map(|_| ());
        assert_eq!(a.is_ok(), b.is_ok(), "gains × {scale}: {a:?} / {b:?}");
        assert_eq!(a.is_ok(), scale == 1.0, "gains × {scale}: {a:?}");
        if let (Err(a), Err(b)) = (&a, &b) {
            // The same joint is named (the fastest mode's).
            let joint = |e: &fbd_sim::SimError| {
                let s = e.to_string();
                s.split("joint ")
                    .nth(1)
                    .map(|j| j.split_whitespace().next().unwrap_or("").to_owned())
            };
            assert!(joint(a).is_some(), "{a}");
            assert_eq!(joint(a), joint(b), "{a} / {b}");
        }
    }
}

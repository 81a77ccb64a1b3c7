//! The stability rule of the explicit joint controller: the damping and
//! stiffness that make the explicit PD torques unstable are refused before
//! the run, with the key named; the rule's effective inertia and limit
//! predict the engine's own stability boundary.

use fbd_kinematics::nalgebra::DMatrix;
use fbd_scenario::{Config, Override, load_with_overrides};
use fbd_sim::joint_inertia::{fastest_mode, planar_mass_matrix};
use fbd_sim::{Control, Data, Model, PlanarParams, step};
use std::path::Path;

fn example(name: &str, overrides: &[Override]) -> Result<(), String> {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name);
    let file_s = file.display().to_string();
    match load_with_overrides(&file, overrides).map_err(|e| e.to_string())? {
        Config::Planar(p) => p.model(&file_s).map(|_| ()),
        Config::Hexapod(h) => h.spatial_model(&file_s).map(|_| ()),
    }
    .map_err(|e| e.to_string())
}

#[test]
fn the_walk_refuses_kd_30_and_22_and_keeps_15() {
    example("hexapod_walk.toml", &[]).unwrap();
    example("hexapod_walk.toml", &[Override::new("control.kd", 19.5)]).unwrap();
    for kd in [22.0, 30.0] {
        let e = example("hexapod_walk.toml", &[Override::new("control.kd", kd)]).unwrap_err();
        assert!(e.contains("hexapod_walk.toml: control.kd: "), "{e}");
        assert!(e.contains("control.kd < 19.7"), "{e}");
        assert!(!e.contains('\n'), "{e}");
    }
}

#[test]
fn every_shipped_controller_passes() {
    for f in [
        "hexapod_walk.toml",
        "hexapod_walk_ice.toml",
        "hexapod_stand.toml",
        "hexapod_slope.toml",
        "pd_stand.toml",
        "squat.toml",
        "slope_slide.toml",
        "slope_stick.toml",
    ] {
        example(f, &[]).unwrap_or_else(|e| panic!("{f}: {e}"));
    }
}

#[test]
fn a_planar_pd_with_an_unstable_kd_is_refused() {
    let e = example("pd_stand.toml", &[Override::new("control.kd", 30.0)]).unwrap_err();
    assert!(e.contains("pd_stand.toml: control.kd: "), "{e}");
    assert!(e.contains("control.kd < 23.18"), "{e}");
    let e = example("pd_stand.toml", &[Override::new("time.dt", 0.01)]).unwrap_err();
    // At Δt = 10 ms the stiffness alone is unstable.
    assert!(
        e.contains("control.kp: ") && e.contains("time.dt below 3.451e-3 s"),
        "{e}"
    );
}

/// The planar robot floating in space (no gravity), its joints kicked:
/// the free robot's effective inertia (no foot on the ground) and the
/// closed-form limit give the engine's stability boundary. 10 % below
/// it the joints settle, 10 % above the kick grows tenfold and more.
#[test]
fn the_limit_is_the_engine_s_boundary_in_flight() {
    let (kp, dt) = (1000.0, 0.002);
    let mut p = PlanarParams {
        dt,
        duration: 1.0,
        gravity: 0.0,
        ..PlanarParams::default()
    };
    p.q0[1] = 100.0;
    let target = [[p.q0[3], p.q0[4]], [p.q0[5], p.q0[6]]];
    p.qdot0[4] = 1.0;
    p.qdot0[5] = -1.0;
    let probe = Model::planar(&p).unwrap();
    let joints: Vec<usize> = probe.mech.joints.iter().map(|j| j.q_index).collect();
    let free = fastest_mode(
        &planar_mass_matrix(&probe.mech, &p.q0),
        &DMatrix::zeros(0, 7),
        &joints,
    );
    let kd_max = 2.0 * free.inertia / dt - 0.5 * kp * dt;
    assert!(kd_max > 5.0, "{kd_max}");
    let mut excursion = |kd: f64| {
        p.control = Control::Pd {
            kp,
            kd,
            torque_limit: None,
            target,
        };
        let model = Model::planar(&p).expect("the standing robot's limit is higher");
        let mut data = Data::new(&model);
        let mut worst: f64 = 0.0;
        for k in 0..model.steps {
            match step(&model, &mut data) {
                Ok(_) => {}
                Err(_) => return f64::INFINITY,
            }
            if k > model.steps / 2 {
                for &i in &joints {
                    worst = worst.max((data.q[i] - p.q0[i]).abs());
                }
            }
        }
        worst
    };
    let below = excursion(0.9 * kd_max);
    let above = excursion(1.1 * kd_max);
    assert!(below < 1e-3, "kd = 0.9 × {kd_max}: {below} rad");
    // The kick alone moves the joints by about 0.01 rad.
    assert!(
        above > 0.1 && above > 100.0 * below,
        "kd = 1.1 × {kd_max}: {above} rad"
    );
}

/// The parameters of a shipped 3D example (with `overrides`).
fn spatial_params(name: &str, overrides: &[Override]) -> fbd_sim::spatial::SpatialParams {
    let file = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("examples")
        .join(name);
    match load_with_overrides(&file, overrides).unwrap() {
        Config::Hexapod(h) => h.spatial_params(&file.display().to_string()).unwrap(),
        Config::Planar(_) => panic!("{name} is planar"),
    }
}

/// The start-up check's fast path (a Cholesky test per pose,
/// `modes_slower_than`) against the eigenvalues of every pose
/// (`fastest_mode_over_poses`): bisecting on the fast test's inertia
/// finds the eigenvalues' smallest inertia to 1e-9; and over a grid of
/// gains and steps the verdict of the model (fast test, eigenvalues only
/// when it fails) is the eigenvalues' rule `kp·Δt² + 2·kd·Δt < 4·I`.
#[test]
fn the_fast_check_gives_the_eigenvalues_verdict() {
    use fbd_sim::spatial::{
        SpatialControl, SpatialModel, fastest_mode_over_poses, modes_slower_than,
    };
    let mut checked = 0;
    for name in [
        "hexapod_walk.toml",
        "hexapod_stand.toml",
        "hexapod_slope.toml",
        "hexapod_rough.toml",
        "hexapod_stairs.toml",
    ] {
        for dt in [0.0005, 0.001, 0.002] {
            // Gains that pass at every step: the poses do not depend on them.
            let base = spatial_params(
                name,
                &[
                    Override::new("time.dt", dt),
                    Override::new("control.kp", 1.0),
                    Override::new("control.kd", 0.0),
                ],
            );
            let probe = base.robot_model();
            let (inertia, _) = fastest_mode_over_poses(&base, &probe);
            assert!(inertia > 0.0 && inertia.is_finite(), "{name}: {inertia}");
            // Bisection on the fast test recovers the smallest inertia.
            let (mut lo, mut hi) = (0.0, 10.0 * inertia);
            for _ in 0..80 {
                let mid = 0.5 * (lo + hi);
                match modes_slower_than(&base, &probe, mid) {
                    Some(true) => lo = mid,
                    Some(false) => hi = mid,
                    None => panic!("{name}: a singular standing leg"),
                }
            }
            assert!(
                (lo - inertia).abs() <= 1e-9 * inertia,
                "{name} at Δt = {dt}: fast {lo:e}, eigenvalues {inertia:e}"
            );
            for kp in [0.0, 300.0, 1000.0, 3000.0] {
                // kd from well inside to well beyond the limit.
                let kd_max = 2.0 * inertia / dt - 0.5 * kp * dt;
                for f in [-0.5, 0.0, 0.5, 0.9, 0.99, 0.999, 1.001, 1.01, 1.1, 2.0] {
                    let kd = (f * kd_max.abs()).max(0.0);
                    if kp == 0.0 && kd == 0.0 {
                        continue;
                    }
                    let mut p = base.clone();
                    match &mut p.control {
                        SpatialControl::Pd { kp: a, kd: b, .. }
                        | SpatialControl::Trajectory { kp: a, kd: b, .. }
                        | SpatialControl::Gait { kp: a, kd: b, .. } => (*a, *b) = (kp, kd),
                        SpatialControl::None => panic!("{name} has no controller"),
                    }
                    let limit = 0.25 * (kp * dt * dt + 2.0 * kd * dt);
                    let stable = limit < inertia;
                    assert_eq!(
                        modes_slower_than(&p, &probe, limit),
                        Some(stable),
                        "{name}: Δt = {dt}, kp = {kp}, kd = {kd}"
                    );
                    assert_eq!(
                        SpatialModel::new(&p).is_ok(),
                        stable,
                        "{name}: Δt = {dt}, kp = {kp}, kd = {kd}"
                    );
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 500, "{checked}");
}

/// The start-up check on the hexapod's D-H instance (the generic robot
/// model, `tree_modes_slower_than`, as for any robot) against the
/// closed-form hexapod's leg-by-leg test (`spatial_modes_slower_than`, an
/// independent reference): on random poses (every joint within ±0.4 rad
/// of the examples' initial angles) and random sets of standing feet, the
/// smallest inertia each test passes, found by bisection, agrees to 1e-9.
#[test]
fn the_generic_check_is_the_closed_form_hexapod_s() {
    use fbd_dynamics::spatial::SpatialKin;
    use fbd_sim::joint_inertia::{ModeWork, spatial_modes_slower_than, tree_modes_slower_than};
    use fbd_sim::spatial::closed_form;
    let mut seed = 0x9e37_79b9_7f4a_7c15u64;
    let mut uniform = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    let mut compared = 0;
    for name in [
        "hexapod_walk.toml",
        "hexapod_stand.toml",
        "hexapod_slope.toml",
    ] {
        let p = spatial_params(name, &[]);
        let robot = p.robot_model();
        let hexapod = closed_form(&p);
        let (mut tk, mut sk) = (ModeWork::new(&robot), SpatialKin::new(&hexapod));
        for _ in 0..40 {
            let mut q = p.q0.clone();
            for x in &mut q[6..] {
                *x += 0.8 * (uniform() - 0.5);
            }
            let slots: Vec<usize> = (0..p.legs.len()).filter(|_| uniform() < 0.6).collect();
            let feet: Vec<usize> = slots
                .iter()
                .map(|&s| {
                    let tip = format!("tip{}", p.legs[s]);
                    robot.contacts.iter().position(|c| c.name == tip).unwrap()
                })
                .collect();
            let threshold = |test: &mut dyn FnMut(f64) -> Option<bool>| {
                let (mut lo, mut hi) = (0.0, 1.0);
                for _ in 0..80 {
                    let mid = 0.5 * (lo + hi);
                    match test(mid)? {
                        true => lo = mid,
                        false => hi = mid,
                    }
                }
                Some(lo)
            };
            let generic = threshold(&mut |i| tree_modes_slower_than(&robot, &mut tk, &q, &feet, i));
            let closed =
                threshold(&mut |i| spatial_modes_slower_than(&hexapod, &mut sk, &q, &slots, i));
            match (generic, closed) {
                (Some(a), Some(b)) => {
                    assert!(
                        a > 0.0 && (a - b).abs() <= 1e-9 * b,
                        "{name}: standing {slots:?}: generic {a:e}, closed form {b:e}"
                    );
                    compared += 1;
                }
                (None, None) => {}
                other => panic!("{name}: standing {slots:?}: {other:?}"),
            }
        }
    }
    assert!(compared > 100, "{compared}");
}

/// An imported robot's joint controller is held to the hexapod's rule:
/// the lab hexapod's PD stand (`examples/robots/lab_hexapod_pd.toml`) is
/// checked at its initial pose and its target with every contact point
/// on the ground, not on the free robot. The largest stable `kd` follows
/// from the eigenvalues of those poses (computed here from the mass
/// matrix and the feet's Jacobian); 1 % below it the robot is accepted
/// and stands still for a second on its six feet; 1 % above it is
/// refused with that limit in the message. The free robot's limit is far
/// lower: the rule is not the free robot's.
#[test]
fn a_robot_s_pd_is_held_to_the_hexapod_s_rule() {
    use fbd_sim::joint_inertia::tree_feet_jacobian;
    use fbd_sim::robot::{RobotControl, RobotData, mass_matrix, step};
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/robots/lab_hexapod_pd.toml");
    let text = std::fs::read_to_string(&file).unwrap();
    assert!(text.contains("\nkd = 0.2\n"), "the example's damping");
    let with_kd = |kd: f64| {
        let t = text.replace("\nkd = 0.2\n", &format!("\nkd = {kd}\n"));
        fbd_scenario::robot::load_str(&t, &file).expect("loads")
    };
    let loaded = with_kd(0.2);
    let (model, p) = (&loaded.model, loaded.params());
    let RobotControl::Pd { kp, target, .. } = &p.control else {
        panic!("a PD example")
    };
    let kp = kp.iter().copied().fold(0.0, f64::max);
    let n = p.q0.len();
    let joints: Vec<usize> = (6..n).collect();
    let all: Vec<usize> = (0..model.contacts.len()).collect();
    let mut at_target = p.q0.clone();
    at_target[6..].copy_from_slice(target);
    let inertia = [&p.q0, &at_target]
        .iter()
        .map(|q| {
            fastest_mode(
                &mass_matrix(model, q),
                &tree_feet_jacobian(model, &all, q),
                &joints,
            )
            .inertia
        })
        .fold(f64::INFINITY, f64::min);
    let free = fastest_mode(&mass_matrix(model, &p.q0), &DMatrix::zeros(0, n), &joints).inertia;
    assert!(inertia > 1.5 * free, "standing {inertia:e}, free {free:e}");
    let kd_max = 2.0 * inertia / p.dt - 0.5 * kp * p.dt;
    let e = with_kd(1.01 * kd_max).sim().unwrap_err().to_string();
    assert!(
        e.contains("control.kd: ") && e.contains(&format!("control.kd < {kd_max:.4} ")),
        "{e} (expected the limit {kd_max})"
    );
    let sim = with_kd(0.99 * kd_max)
        .sim()
        .expect("accepted below the limit");
    let mut data = RobotData::new(&sim);
    let mut worst: f64 = 0.0;
    for _ in 0..sim.steps {
        step(&sim, &mut data).unwrap_or_else(|e| panic!("{e}"));
        let r = &data.record;
        for c in &r.contacts {
            assert_ne!(c.state, fbd_contact::StateCode::St1, "a foot lifted");
        }
        worst = r.q[6..]
            .iter()
            .zip(target)
            .fold(worst, |w, (a, b)| w.max((a - b).abs()));
    }
    // Stands: every joint within a few degrees of its target, no foot
    // lifted, no joint oscillation grown.
    assert!(worst < 0.1, "a joint {worst} rad from its target");
}

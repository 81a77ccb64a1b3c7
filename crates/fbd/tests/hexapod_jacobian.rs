//! The analytic Jacobian of the paper's hexapod's 3D FBD residual (the
//! generic tree assembly on its D-H instance, as the 3D simulator steps
//! it) against central differences, through the shared checker: six legs,
//! a body inertia with products of inertia, generic (tumbling, tilted)
//! configurations, every contact state (free, sticking, sliding in
//! a generic direction) on flat and tilted, rotated terrain, joint limits
//! free and at a stop, at the first step (history from the initial
//! velocities) and at a later one. The pattern declared by `pattern`
//! covers every entry written.

use fbd_contact::spatial::frame;
use fbd_contact::{SpatialState, Surface, Terrain};
use fbd_dynamics::check::{check_step, dense_jacobian};
use fbd_dynamics::spatial::SpatialContactEquation;
use fbd_dynamics::tree::assemble::{prepare_step, set_configuration, set_previous};
use fbd_dynamics::tree::{TreeFbdData, TreeMechanism, contacts_by_kind};
use fbd_dynamics::{History, LimitEquation, LimitState};
use fbd_kinematics::fd::FdTolerance;
use fbd_kinematics::hexapod::HexapodModel;
use fbd_kinematics::{Joint, JointLimits, LimitSide};
use fbd_robot::dh::{HexapodLayout, HexapodMasses, hexapod};

/// The hexapod of `legs` with every contact point (tips, knees, hips, in
/// the simulator's order) and the default joint limits.
fn mechanism(legs: &[usize]) -> TreeMechanism {
    let masses = HexapodMasses {
        body_mass: 10.0,
        body_inertia: [0.2, 0.39, 0.21, 0.01, -0.02, 0.015],
        upper_mass: 0.3,
        upper_radius: 0.02,
        upper_inertia: 1.0e-3,
        lower_mass: 1.1,
        lower_radius: 0.015,
        lower_inertia: 1.6e-2,
    };
    let l = JointLimits::default();
    let range = |j| {
        let [lower, upper] = l.range(j);
        Some(fbd_robot::JointLimits { lower, upper })
    };
    let layout = HexapodLayout {
        legs: legs.to_vec(),
        limits: [
            range(Joint::Theta1),
            range(Joint::Theta2),
            range(Joint::Theta3),
        ],
        ..HexapodLayout::default()
    };
    let robot = hexapod(&HexapodModel::default(), &masses, &layout);
    TreeMechanism::with_contacts(&robot, 9.81, &contacts_by_kind(&robot))
}

/// A generic configuration: tilted, turned body; every leg different.
fn q_at(mech: &TreeMechanism, shift: f64) -> Vec<f64> {
    let nq = mech.nq();
    let mut q = vec![0.0; nq];
    q[..6].copy_from_slice(&[0.1, 0.45, -0.05, 0.2, -0.4, 0.3]);
    for s in 0..(nq - 6) / 3 {
        let f = s as f64;
        q[6 + 3 * s] = 0.1 * f - 0.2;
        q[7 + 3 * s] = -0.3 + 0.1 * f;
        q[8 + 3 * s] = 4.2 + 0.05 * f;
    }
    for (i, v) in q.iter_mut().enumerate() {
        *v += shift * (1.0 + 0.1 * i as f64) * if i % 2 == 0 { 1.0 } else { -0.7 };
    }
    q
}

fn check(surface: &Surface, first_step: bool, limits_at: bool) {
    check_rows(surface, first_step, limits_at, false);
}

/// `complementarity`: ST2 and ST3 as complementarity rows, in either
/// branch (a huge μS keeps some points inside their disc, the others
/// slide; a negative `N` unloads).
fn check_rows(surface: &Surface, first_step: bool, limits_at: bool, complementarity: bool) {
    let mech = mechanism(&[1, 2, 3, 4, 5, 6]);
    let lay = mech.dims();
    let n = lay.dim();
    let mut data = TreeFbdData::new(&mech);
    let q_prev = q_at(&mech, -0.004);
    let q_k = q_at(&mech, 0.0);
    set_previous(&mech, &mut data, &q_prev);
    set_configuration(&mech, &mut data, &q_k);
    let nq = mech.nq();
    let qdot: Vec<f64> = (0..nq).map(|i| 0.3 - 0.05 * i as f64).collect();
    let history = if first_step {
        History::Initial { qdot: &qdot }
    } else {
        History::Previous
    };
    prepare_step(&mech, &mut data, history, 0.002);
    for (j, t) in data.torque.iter_mut().enumerate() {
        *t = [1.0 + (j / 3) as f64, -2.0, 0.5][j % 3];
    }
    for (c, eq) in data.contact.iter_mut().enumerate() {
        let state = match c % 4 {
            0 => SpatialState::Free,
            1 => SpatialState::Stick {
                anchor: [0.1 * c as f64, 0.01, -0.2],
            },
            2 => SpatialState::Slide { dir: [0.6, -0.8] },
            _ => SpatialState::Slide { dir: [-1.0, 0.0] },
        };
        *eq = SpatialContactEquation {
            state,
            frame: frame(surface, 0.05 * c as f64, -0.1),
            mu_dynamic: if complementarity && c % 3 == 0 {
                1e9
            } else {
                0.3
            },
            regularization: 1e-3,
            mu_static: if c % 3 == 1 { 1e9 } else { 0.4 },
            complementarity,
            frozen: None,
        };
    }
    if limits_at {
        for (l, eq) in data.limit.iter_mut().enumerate() {
            if l % 2 == 0 {
                *eq = LimitEquation {
                    state: LimitState::At {
                        side: if complementarity && l % 4 == 2 {
                            LimitSide::Upper
                        } else {
                            LimitSide::Lower
                        },
                        angle: 0.1,
                    },
                    regularization: 1e-3,
                    complementarity,
                };
            }
        }
    }
    // A generic iterate.
    let mut z: Vec<f64> = (0..n).map(|i| 3.0 * ((i as f64) * 0.37).sin()).collect();
    z[..nq].copy_from_slice(&q_at(&mech, 0.003));
    if complementarity {
        // Large normal forces on every other point: held on the surface.
        for c in (0..data.contact.len()).step_by(2) {
            z[lay.contact_force(c, 1)] = 2e6 * (1.0 + 0.1 * c as f64);
        }
    }
    let jac = dense_jacobian(&mech, surface, &mut data, &z);
    if complementarity && limits_at {
        // Both branches of the stops: held and unloaded.
        let at: Vec<bool> = (0..data.limit.len())
            .filter(|&l| data.limit[l].state.is_at())
            .map(|l| data.limit_unloaded[l])
            .collect();
        assert!(at.contains(&true) && at.contains(&false), "{at:?}");
    }
    if complementarity && !first_step {
        // Every branch is visited: sticking and sliding, loaded and not.
        let b: Vec<_> = (0..data.contact.len())
            .filter(|&c| data.contact[c].state != SpatialState::Free)
            .map(|c| data.branch[c])
            .collect();
        for want in [
            |b: &fbd_dynamics::rows::Branch| b.sliding && !b.unloaded,
            |b: &fbd_dynamics::rows::Branch| !b.sliding && !b.unloaded,
            |b: &fbd_dynamics::rows::Branch| b.unloaded,
            |b: &fbd_dynamics::rows::Branch| b.sliding && b.drho > 0.0,
        ] {
            assert!(b.iter().any(want), "a branch is not visited: {b:?}");
        }
    }
    // The declared pattern covers every non-zero entry, each equal to the
    // residual's central differences.
    check_step(
        &mech,
        surface,
        &data,
        &z,
        &jac,
        FdTolerance {
            step: 1e-6,
            rel: 1e-6,
            // Contact rows hold K·p with K = M/Δt² ≈ 3.5e6 N/m: their
            // central differences carry K·ε·|p|/h ≈ 1e-3 of round-off.
            abs: 2e-3,
        },
    )
    .unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn jacobian_on_flat_ground_later_step() {
    check(&Surface::default(), false, false);
}

#[test]
fn jacobian_at_the_first_step_with_limits_at_stops() {
    check(&Surface::default(), true, true);
}

#[test]
fn jacobian_on_a_rotated_slope() {
    let s = Surface::new(
        Terrain::Slope {
            slope: 0.2,
            height: 0.05,
        },
        0.6,
    );
    check(&s, false, true);
}

#[test]
fn jacobian_of_complementarity_rows_on_flat_ground() {
    check_rows(&Surface::default(), false, false, true);
}

#[test]
fn jacobian_of_complementarity_rows_on_a_rotated_slope_at_the_first_step() {
    let s = Surface::new(
        Terrain::Slope {
            slope: 0.2,
            height: 0.05,
        },
        0.6,
    );
    check_rows(&s, true, true, true);
}

/// At rest (`q[k−1] = q[k]`), the residual at the rest configuration is
/// the same, bit for bit, whether the workspace evaluated it fresh or
/// holds the frames and momenta of earlier evaluations (the kinematics
/// at the same `q` and each body's `L[k+½]` at the same rotations are
/// kept, not evaluated again), with other iterates in between and after
/// a step accepted there; and after every evaluation the workspace's
/// frames and momenta are those computed afresh, outside it (a fresh
/// `TreeKin` at the iterate, `half_momentum_and_rotation` of its
/// rotations).
#[test]
fn kept_frames_and_momenta_give_the_fresh_residual() {
    use fbd_dynamics::spatial::half_momentum_and_rotation;
    use fbd_dynamics::tree::assemble::{advance, evaluate_next, step_momentum};
    use fbd_dynamics::tree::kin::TreeKin;
    let mech = mechanism(&[1, 2, 3, 4, 5, 6]);
    let n = mech.dims().dim();
    let nq = mech.nq();
    let dt = 0.001;
    let rest = q_at(&mech, 0.0);
    let at = |q: &[f64]| {
        let mut z: Vec<f64> = (0..n).map(|i| 2.0 * ((i as f64) * 0.53).cos()).collect();
        z[..nq].copy_from_slice(q);
        z
    };
    let prepared = || {
        let mut data = TreeFbdData::new(&mech);
        set_previous(&mech, &mut data, &rest);
        set_configuration(&mech, &mut data, &rest);
        prepare_step(&mech, &mut data, History::Previous, dt);
        data
    };
    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    // The residual at `z`, with the workspace's kinematics at `z`'s `q`
    // and every body's momentum checked against fresh computations.
    let residual = |data: &mut TreeFbdData, z: &[f64]| {
        let mut r = vec![0.0; n];
        fbd_dynamics::eval(
            &mech,
            &Surface::default(),
            data,
            z,
            &mut r,
            &mut fbd_dynamics::NoJacobian,
        );
        let mut fresh = TreeKin::new(&mech.model);
        fresh.eval(&mech.model, &z[..nq]);
        assert_eq!(data.kin_next, fresh, "kinematics at the iterate");
        for (b, body) in mech.bodies.iter().enumerate() {
            let mb = body.model_body;
            let (l, psi) = half_momentum_and_rotation(
                &data.kin.rotation[mb],
                &data.kin_next.rotation[mb],
                &body.inertia,
                dt,
            );
            let (kl, kpsi) = step_momentum(data, b).expect("computed at the iterate");
            assert_eq!(
                bits(kl.as_slice()),
                bits(l.as_slice()),
                "body {b}'s momentum"
            );
            assert_eq!(
                bits(kpsi.as_slice()),
                bits(psi.as_slice()),
                "body {b}'s rotation"
            );
        }
        bits(&r)
    };
    let fresh = residual(&mut prepared(), &at(&rest));
    let mut data = prepared();
    let moved = at(&q_at(&mech, 1e-4));
    let mut joints_moved = at(&rest);
    joints_moved[nq - 1] += 1e-3;
    for z in [
        at(&rest),
        moved.clone(),
        at(&rest),
        joints_moved,
        at(&rest),
        at(&rest),
    ] {
        let r = residual(&mut data, &z);
        if z[..nq] == rest[..] {
            assert_eq!(r, fresh);
        }
    }
    // The step accepted at rest: the next one is at rest again, its
    // workspace handed the frames of q[k−1] = q[k].
    evaluate_next(&mech, &mut data, &rest);
    advance(&mut data);
    prepare_step(&mech, &mut data, History::Previous, dt);
    assert_eq!(residual(&mut data, &at(&rest)), fresh);
    assert_ne!(residual(&mut data, &moved), fresh);
    assert_eq!(residual(&mut data, &at(&rest)), fresh);
}

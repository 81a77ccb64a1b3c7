//! The analytic Jacobian of the FBD residual against central differences,
//! through the shared checker, in every contact state, at the first step
//! (history from the initial velocity) and later ones, on flat and curved
//! terrains (sliding rows use the terrain height and slope at the iterate,
//! and the contact frames tilt with the ground).

use fbd_contact::{ContactState, Terrain};
use fbd_dynamics::check::{check_step, dense_jacobian};
use fbd_dynamics::mechanism::ContactPoints;
use fbd_dynamics::{
    ContactEquation, FbdData, History, LimitEquation, LimitState, Mechanism, TwoLegInertia,
    pattern, prepare_step, set_configuration,
};
use fbd_kinematics::fd::FdTolerance;
use fbd_kinematics::planar::PlanarGeometry;

fn mechanism() -> Mechanism {
    let inertia = TwoLegInertia {
        body_mass: 6.0,
        body_inertia: 0.1,
        upper_mass: 0.8,
        upper_inertia: 0.003,
        lower_mass: 0.5,
        lower_inertia: 0.007,
    };
    let all = ContactPoints {
        tips: true,
        knees: true,
        hips: true,
    };
    Mechanism::two_leg(&PlanarGeometry::default(), &inertia, 9.81, all).0
}

/// Assembles at a generic state with contact points in `states` (tips,
/// knees, hips), frames taken from `terrain` under each point as the
/// simulator sets them, and compares the Jacobian with central differences.
fn check(terrain: &Terrain, states: [ContactState; 6], first_step: bool) {
    check_with_limits(terrain, states, first_step, &[]);
}

/// [`check`] with a joint limit on every joint in `limits` (one state per
/// joint, `[hip3, knee3, hip4, knee4]`), or none.
fn check_with_limits(
    terrain: &Terrain,
    states: [ContactState; 6],
    first_step: bool,
    limits: &[LimitState],
) {
    let mut mech = mechanism();
    if !limits.is_empty() {
        mech = mech.with_limits((0..limits.len()).collect());
    }
    let lay = mech.layout();
    let n = lay.dim();
    assert_eq!(n, 3 * 5 + 2 * 6 + limits.len());
    let mut data = FbdData::new(&mech);
    let q0 = [0.05, 0.55, 0.1, 0.2, 4.2, -0.15, 4.4];
    let q1 = [0.051, 0.549, 0.102, 0.21, 4.19, -0.14, 4.41];
    let qdot = [0.3, -0.5, 0.2, 1.0, -1.0, 0.5, 0.7];
    set_configuration(&mech, &mut data, &q0);
    if first_step {
        prepare_step(&mech, &mut data, History::Initial { qdot: &qdot }, 0.01);
    } else {
        fbd_dynamics::evaluate_next(&mech, &mut data, &q1);
        fbd_dynamics::advance(&mech, &mut data);
        prepare_step(&mech, &mut data, History::Previous, 0.01);
    }
    let curved = !matches!(terrain, Terrain::Flat { .. } | Terrain::None);
    for (c, st) in states.iter().enumerate() {
        let x = match st {
            ContactState::Stick { anchor } => anchor[0],
            _ => data.kin.pos[mech.contacts[c].point][0],
        };
        let (tangent, normal) = terrain.frame(x);
        if curved {
            assert!(tangent[1] != 0.0, "the frame should be tilted at x = {x}");
        }
        data.contact[c] = ContactEquation {
            state: *st,
            tangent,
            normal,
            mu_dynamic: 0.3,
            // Far larger than the default so that its entries show in the
            // finite differences.
            regularization: 0.05,
        };
    }
    for (l, &state) in limits.iter().enumerate() {
        data.limit[l] = LimitEquation {
            state,
            // Far larger than the default, as for the contacts.
            regularization: 0.03,
            complementarity: false,
        };
    }
    data.torque
        .iter_mut()
        .enumerate()
        .for_each(|(j, t)| *t = 0.5 * j as f64 - 0.7);
    let z: Vec<f64> = (0..n)
        .map(|i| {
            if i < 7 {
                q1[i] + 0.003 * (i as f64).sin()
            } else {
                3.0 * ((i * 7) as f64).cos()
            }
        })
        .collect();
    // Every entry written must be in the declared pattern, and equal the
    // residual's central differences.
    let jm = dense_jacobian(&mech, terrain, &mut data, &z);
    check_step(
        &mech,
        terrain,
        &data,
        &z,
        &jm,
        FdTolerance {
            rel: 1e-6,
            abs: 1e-4,
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{terrain:?}, states {states:?}, limits {limits:?}: {e}"));
}

const SL: ContactState = ContactState::Slide { dir: -1.0 };
const SR: ContactState = ContactState::Slide { dir: 1.0 };
const FREE: ContactState = ContactState::Free;

#[test]
fn jacobian_in_flight() {
    check(&Terrain::Flat { height: 0.01 }, [FREE; 6], true);
    check(&Terrain::Flat { height: 0.01 }, [FREE; 6], false);
}

#[test]
fn jacobian_sticking_and_sliding() {
    let flat = Terrain::Flat { height: 0.01 };
    let st = ContactState::Stick {
        anchor: [0.5, 0.01],
    };
    check(&flat, [st, SL, FREE, st, SL, SR], false);
    check(&flat, [SL, st, st, SL, FREE, st], true);
    let slope = Terrain::slope_deg(16.7, 0.01);
    let st = ContactState::Stick {
        anchor: [0.5, slope.height(0.5)],
    };
    check(&slope, [st, SL, FREE, st, SL, SR], false);
    check(&slope, [SL, st, st, SL, FREE, st], true);
}

#[test]
fn jacobian_on_a_sine_terrain() {
    let sine = Terrain::Sine {
        amplitude: 0.03,
        wavelength: 0.37,
        phase: 0.4,
        height: 0.01,
    };
    let st = ContactState::Stick {
        anchor: [0.5, sine.height(0.5)],
    };
    check(&sine, [SL, SR, SL, SR, SL, SR], false);
    check(&sine, [st, SL, FREE, st, SR, SL], false);
}

#[test]
fn jacobian_on_a_slope_and_a_profile() {
    check(
        &Terrain::slope_deg(10.0, 0.0),
        [SL, SR, SL, SR, SL, SR],
        false,
    );
    let profile = Terrain::Profile {
        points: vec![
            [-2.0, 0.0],
            [-0.3, 0.1],
            [-0.07, 0.05],
            [0.02, 0.12],
            [0.31, -0.1],
            [2.0, 0.3],
        ],
    };
    check(&profile, [SL, SR, SL, SR, SL, SR], false);
}

#[test]
fn jacobian_with_joint_limits_free_and_at_either_end() {
    use fbd_kinematics::LimitSide;
    let lower = LimitState::At {
        side: LimitSide::Lower,
        angle: 0.3,
    };
    let upper = LimitState::At {
        side: LimitSide::Upper,
        angle: 4.5,
    };
    let flat = Terrain::Flat { height: 0.01 };
    let st = ContactState::Stick {
        anchor: [0.5, 0.01],
    };
    for first_step in [true, false] {
        check_with_limits(&flat, [FREE; 6], first_step, &[LimitState::Free; 4]);
        check_with_limits(
            &flat,
            [st, SL, FREE, st, SL, SR],
            first_step,
            &[lower, upper, LimitState::Free, upper],
        );
        check_with_limits(
            &flat,
            [SL, st, st, SL, FREE, st],
            first_step,
            &[LimitState::Free, lower, lower, upper],
        );
    }
}

/// A stop moment acts on the joint's two bodies only, equal and opposite:
/// the rotation rows of child and parent see `∓v·axis` and no other row
/// depends on it.
#[test]
fn stop_moment_enters_child_and_parent_rotation_rows_only() {
    let mech = mechanism().with_limits(vec![1, 2]);
    let lay = mech.layout();
    let data = FbdData::new(&mech);
    let mut entries = Vec::new();
    pattern(&mech, &Terrain::None, &data, &mut entries);
    for (l, &j) in mech.limits.iter().enumerate() {
        let col = lay.limit_moment(l);
        let mut rows: Vec<usize> = entries.iter().filter(|e| e.1 == col).map(|e| e.0).collect();
        rows.sort_unstable();
        let spec = &mech.joints[j];
        let mut expected = vec![
            lay.body_row(spec.parent) + 2,
            lay.body_row(spec.child) + 2,
            lay.limit_row(l),
        ];
        expected.sort_unstable();
        assert_eq!(rows, expected, "limit {l} on joint {}", spec.name);
    }
}

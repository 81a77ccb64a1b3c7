//! The analytic Jacobian of the FBD residual against central differences,
//! through the shared checker, in every contact state, at the first step
//! (history from the initial velocity) and later ones, on flat and curved
//! terrains (sliding rows use the terrain height and slope at the iterate,
//! and the contact frames tilt with the ground).

use fbd_contact::{ContactState, Terrain};
use fbd_dynamics::mechanism::ContactPoints;
use fbd_dynamics::{
    ContactEquation, FbdData, History, JacobianSink, Mechanism, NoJacobian, TwoLegInertia, eval,
    pattern, prepare_step, set_configuration,
};
use fbd_kinematics::fd::{FdTolerance, check_jacobian};
use fbd_kinematics::planar::PlanarGeometry;

struct Dense<'a> {
    n: usize,
    m: &'a mut [f64],
}
impl JacobianSink for Dense<'_> {
    const ACTIVE: bool = true;
    fn add(&mut self, r: usize, c: usize, v: f64) {
        self.m[r * self.n + c] += v;
    }
}

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
    let mech = mechanism();
    let lay = mech.layout();
    let n = lay.dim();
    assert_eq!(n, 3 * 5 + 2 * 6);
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
    let mut r = vec![0.0; n];
    let mut jm = vec![0.0; n * n];
    eval(
        &mech,
        terrain,
        &mut data,
        &z,
        &mut r,
        &mut Dense { n, m: &mut jm },
    );
    // Every entry written must be in the declared pattern.
    let mut entries = Vec::new();
    pattern(&mech, &data, &mut entries);
    for i in 0..n {
        for j in 0..n {
            if jm[i * n + j] != 0.0 {
                assert!(
                    entries.contains(&(i, j)),
                    "entry ({i}, {j}) = {} is outside the pattern",
                    jm[i * n + j]
                );
            }
        }
    }
    let mut work = data.clone();
    check_jacobian(
        &z,
        n,
        |x, out| eval(&mech, terrain, &mut work, x, out, &mut NoJacobian),
        |i, j| jm[i * n + j],
        FdTolerance {
            rel: 1e-6,
            abs: 1e-4,
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{terrain:?}, states {states:?}: {e}"));
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

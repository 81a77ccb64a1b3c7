//! The analytic Jacobian of the FBD residual against central differences,
//! in every contact state, through the shared checker.

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

fn check(states: [ContactState; 6], history_first: bool) {
    let mech = mechanism();
    let lay = mech.layout();
    let n = lay.dim();
    assert_eq!(n, 3 * 5 + 2 * 6);
    let mut data = FbdData::new(&mech);
    let q0 = [0.05, 0.55, 0.1, 0.2, 4.2, -0.15, 4.4];
    let q1 = [0.051, 0.549, 0.102, 0.21, 4.19, -0.14, 4.41];
    let qdot = [0.3, -0.5, 0.2, 1.0, -1.0, 0.5, 0.7];
    set_configuration(&mech, &mut data, &q0);
    if history_first {
        prepare_step(&mech, &mut data, History::Initial { qdot: &qdot }, 0.01);
    } else {
        fbd_dynamics::advance(&mech, &mut data, &q1);
        prepare_step(&mech, &mut data, History::Previous, 0.01);
    }
    let s = 0.3f64;
    let k = 1.0 / (1.0 + s * s).sqrt();
    for (c, st) in states.iter().enumerate() {
        data.contact[c] = ContactEquation {
            state: *st,
            tangent: [k, s * k],
            normal: [-s * k, k],
            mu_dynamic: 0.3,
        };
        data.torque
            .iter_mut()
            .enumerate()
            .for_each(|(j, t)| *t = 0.5 * j as f64 - 0.7);
    }
    let terrain = Terrain::Flat { height: 0.01 };
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
        &terrain,
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
        |x, out| eval(&mech, &terrain, &mut work, x, out, &mut NoJacobian),
        |i, j| jm[i * n + j],
        FdTolerance {
            rel: 1e-6,
            abs: 1e-4,
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("states {states:?}: {e}"));
}

#[test]
fn jacobian_in_flight() {
    check([ContactState::Free; 6], true);
    check([ContactState::Free; 6], false);
}

#[test]
fn jacobian_sticking_and_sliding() {
    let st = ContactState::Stick {
        anchor: [0.5, 0.01],
    };
    let sl = ContactState::Slide { dir: -1.0 };
    check(
        [
            st,
            sl,
            ContactState::Free,
            st,
            sl,
            ContactState::Slide { dir: 1.0 },
        ],
        false,
    );
    check([sl, st, st, sl, ContactState::Free, st], true);
}

//! The FBD equations of any robot tree ([`fbd_dynamics::tree::assemble`],
//! issue 25: one robot model as data):
//!
//! * on the paper's hexapod, the mechanism built from the generic model
//!   ([`fbd_scenario::robot::hexapod_robot`], the two-axis hip a compound
//!   joint; the model the 3D simulator steps) has the closed-form
//!   hexapod's bodies, reactions, contact points and stops in the layout
//!   of its output columns (its analytic Jacobian against central
//!   differences: `crates/fbd/tests/hexapod_jacobian.rs`);
//! * on the lab hexapod URDF (no compound joint: every joint a reaction of
//!   3 forces and 2 constraint moments), the analytic Jacobian against
//!   central differences of the residual through the shared checker
//!   ([`fbd_kinematics::fd::check_jacobian`]), in flight and with feet in
//!   contact, and the declared pattern covers every entry;
//! * driven by Newton through the stepping entry points (as an engine
//!   would), the lab hexapod in flight keeps the discrete momentum laws of
//!   the whole tree (linear momentum changes by `−M·g·Δt`, angular
//!   momentum by gravity's moment), and every joint's constraint moments
//!   span the plane across its axis (also at the fallback direction).

use std::path::Path;

use fbd_contact::spatial::frame;
use fbd_contact::{SpatialState, Surface, Terrain};
use fbd_dynamics::check::{check_step, dense_jacobian};
use fbd_dynamics::spatial::{SpatialContactEquation, SpatialMechanism};
use fbd_dynamics::tree::assemble as tree;
use fbd_dynamics::tree::{TreeFbdData, TreeMechanism, contacts_by_kind};
use fbd_dynamics::{History, JacobianSink, LimitEquation, LimitState, NoJacobian};
use fbd_kinematics::LimitSide;
use fbd_kinematics::fd::FdTolerance;
use fbd_robot::{ContactChoice, RobotModel, Up};
use fbd_sim::spatial::SpatialParams;

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

/// The hexapod both ways: the spatial model the simulator builds from its
/// parameters, and the tree mechanism of the same parameters' robot model.
fn both() -> (SpatialMechanism, TreeMechanism) {
    let params = SpatialParams::default();
    let spatial = fbd_sim::spatial::closed_form(&params);
    let model = fbd_scenario::robot::hexapod_robot(&params);
    let tree = TreeMechanism::with_contacts(&model, params.gravity, &contacts_by_kind(&model));
    (spatial, tree)
}

/// `q` moved a little (a step's worth) at random.
fn near(rng: &mut Rng, q: &[f64], h: f64) -> Vec<f64> {
    q.iter().map(|v| v + h * rng.next()).collect()
}

/// The contact equations of point `c` in a random state.
fn contact_equation(
    rng: &mut Rng,
    surface: &Surface,
    c: usize,
    complementarity: bool,
) -> SpatialContactEquation {
    let state = match c % 4 {
        0 => SpatialState::Free,
        1 => SpatialState::Stick {
            anchor: [0.3 * rng.next(), 0.01 * rng.next(), 0.3 * rng.next()],
        },
        _ => {
            let a = 3.0 * rng.next();
            SpatialState::Slide {
                dir: [a.cos(), a.sin()],
            }
        }
    };
    SpatialContactEquation {
        state,
        frame: frame(surface, 0.3 * rng.next(), 0.3 * rng.next()),
        mu_dynamic: if complementarity && c.is_multiple_of(3) {
            1e9
        } else {
            0.3 + 0.2 * rng.next().abs()
        },
        regularization: 1e-3,
        mu_static: if c % 3 == 1 { 1e9 } else { 0.5 },
        complementarity,
        frozen: None,
    }
}

/// The mechanism the 3D simulator steps (the D-H instance) has the closed-
/// form hexapod's bodies, masses, reactions, contact points (in the order
/// of the output columns) and stops, and the `q` layout of SPEC §1.2.
#[test]
fn hexapod_layout_is_the_spatial_models() {
    let (sm, tm) = both();
    let lay = sm.layout();
    let dims = fbd_dynamics::assembly::FbdModel::dims(&tm);
    assert_eq!(dims, lay.dims());
    assert_eq!(tm.bodies.len(), sm.bodies.len());
    for (a, b) in tm.bodies.iter().zip(&sm.bodies) {
        assert_eq!(a.name, b.name);
        assert_eq!(a.mass, b.mass);
    }
    assert_eq!(tm.reactions.len(), 2 * sm.legs.len());
    for s in 0..sm.legs.len() {
        let (hip, knee) = (2 * s, 2 * s + 1);
        assert!(tm.reactions[hip].compound && !tm.reactions[knee].compound);
        assert_eq!(tm.reaction_force(hip, 0), lay.hip_force(s, 0));
        assert_eq!(tm.reaction_moment(hip, 0), lay.hip_moment(s));
        assert_eq!(tm.reaction_force(knee, 0), lay.knee_force(s, 0));
        assert_eq!(tm.reaction_moment(knee, 0), lay.knee_moment(s, 0));
        assert_eq!(tm.reaction_moment(knee, 1), lay.knee_moment(s, 1));
    }
    let names: Vec<&str> = tm.contacts.iter().map(|c| c.name.as_str()).collect();
    let spatial: Vec<&str> = sm.contacts.iter().map(|c| c.name.as_str()).collect();
    assert_eq!(names, spatial);
    for (a, b) in tm.contacts.iter().zip(&sm.contacts) {
        assert_eq!(a.body, b.body, "{}", a.name);
    }
    let lq: Vec<usize> = tm.limits.iter().map(|l| l.q_index).collect();
    let sq: Vec<usize> = sm.limits.iter().map(|l| l.q_index).collect();
    assert_eq!(lq, sq);
    assert!((tm.length_scale() - sm.length_scale()).abs() < 1e-14);
}

fn lab() -> RobotModel {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/robots/lab_hexapod.urdf");
    fbd_robot::urdf::load(&path, Up::Z, &ContactChoice::CollisionSpheres).expect("lab hexapod")
}

/// The lab hexapod's residual Jacobian against central differences:
/// `contact`: the feet in contact (sticking, sliding, complementarity
/// rows), otherwise in flight; stops at an end with `limits_at`.
fn check_lab(first_step: bool, contact: bool, complementarity: bool, limits_at: bool) {
    let model = lab();
    assert!(model.compound_joints().is_empty());
    let mech = TreeMechanism::new(&model, 9.81);
    assert!(mech.reactions.iter().all(|r| r.unknowns() == 5));
    assert_eq!(mech.reactions.len(), model.joints.len());
    assert!(!mech.contacts.is_empty() && !mech.limits.is_empty());
    let dims = mech.dims();
    let n = dims.dim();
    let nq = mech.nq();
    let surface = Surface::new(
        Terrain::Slope {
            slope: 0.15,
            height: 0.02,
        },
        0.4,
    );
    let mut rng = Rng(7 + u64::from(contact) + 2 * u64::from(first_step));
    let mut q_k = vec![0.0; nq];
    q_k[1] = 0.15;
    for v in &mut q_k[3..6] {
        *v = 0.4 * rng.next();
    }
    for v in &mut q_k[6..] {
        *v = 0.8 * rng.next();
    }
    let q_prev = near(&mut rng, &q_k, 0.01);
    let q_next = near(&mut rng, &q_k, 0.01);
    let mut data = TreeFbdData::new(&mech);
    tree::set_previous(&mech, &mut data, &q_prev);
    tree::set_configuration(&mech, &mut data, &q_k);
    let qdot: Vec<f64> = (0..nq).map(|_| rng.next()).collect();
    let history = if first_step {
        History::Initial { qdot: &qdot }
    } else {
        History::Previous
    };
    tree::prepare_step(&mech, &mut data, history, 0.002);
    for t in &mut data.torque {
        *t = 0.5 * rng.next();
    }
    for c in 0..dims.contacts {
        data.contact[c] = if contact {
            contact_equation(&mut rng, &surface, c, complementarity)
        } else {
            SpatialContactEquation::default()
        };
    }
    if limits_at {
        for l in (0..dims.limits).step_by(2) {
            data.limit[l] = LimitEquation {
                state: LimitState::At {
                    side: if l % 4 == 0 {
                        LimitSide::Lower
                    } else {
                        LimitSide::Upper
                    },
                    angle: mech.limits[l].range[usize::from(l % 4 != 0)],
                },
                regularization: 1e-3,
                complementarity,
            };
        }
    }
    let mut z: Vec<f64> = (0..n).map(|_| 5.0 * rng.next()).collect();
    z[..nq].copy_from_slice(&q_next);
    if complementarity {
        for c in (0..dims.contacts).step_by(2) {
            z[dims.contact_force(c, 1)] = 1e5 * (1.0 + rng.next().abs());
        }
    }
    let jac = dense_jacobian(&mech, &surface, &mut data, &z);
    // Every body row has its q[k+1] columns: the dynamics are coupled.
    for b in 0..dims.bodies {
        let row = dims.body_row(b);
        assert!((0..nq).any(|j| jac[row * n + j] != 0.0), "body {b}");
    }
    // The declared pattern covers every entry, each equal to the residual's
    // central differences.
    check_step(
        &mech,
        &surface,
        &data,
        &z,
        &jac,
        FdTolerance {
            step: 1e-6,
            rel: 1e-6,
            abs: 2e-3,
        },
    )
    .unwrap_or_else(|e| panic!("{e}"));
}

#[test]
fn lab_hexapod_jacobian_in_flight() {
    check_lab(false, false, false, false);
    check_lab(true, false, false, true);
}

#[test]
fn lab_hexapod_jacobian_with_feet_in_contact() {
    check_lab(false, true, false, true);
    check_lab(true, true, false, false);
}

#[test]
fn lab_hexapod_jacobian_with_complementarity_rows() {
    check_lab(false, true, true, true);
}

/// One step of a [`TreeMechanism`] as a Newton system (how an engine
/// drives it, as `fbd_sim`'s spatial step drives the hexapod's).
struct TreeSystem<'a> {
    mech: &'a TreeMechanism,
    surface: &'a Surface,
    data: &'a mut TreeFbdData,
}

struct SolverSink<'a, 'b>(&'a mut fbd_solver::JacobianSink<'b>);
impl JacobianSink for SolverSink<'_, '_> {
    const ACTIVE: bool = true;
    fn add(&mut self, r: usize, c: usize, v: f64) {
        self.0.add(r, c, v);
    }
}

impl fbd_solver::NewtonSystem for TreeSystem<'_> {
    fn dim(&self) -> usize {
        self.mech.dim()
    }
    fn pattern_key(&self) -> u64 {
        tree::pattern_key(self.data)
    }
    fn pattern(&self, entries: &mut Vec<(usize, usize)>) {
        fbd_dynamics::pattern(self.mech, self.surface, self.data, entries);
    }
    fn eval(&mut self, x: &[f64], r: &mut [f64], jac: Option<&mut fbd_solver::JacobianSink<'_>>) {
        match jac {
            Some(j) => {
                fbd_dynamics::eval(self.mech, self.surface, self.data, x, r, &mut SolverSink(j))
            }
            None => fbd_dynamics::eval(self.mech, self.surface, self.data, x, r, &mut NoJacobian),
        }
    }
}

/// Total linear and angular momentum (about the origin) over the step
/// from `kin` to `kin_next`: `Σ m·(c[k+1] − c[k])/Δt` and
/// `Σ m·c[k] × (c[k+1] − c[k])/Δt + L[k+½]`.
fn momenta(
    mech: &TreeMechanism,
    data: &TreeFbdData,
    dt: f64,
) -> (
    fbd_kinematics::nalgebra::Vector3<f64>,
    fbd_kinematics::nalgebra::Vector3<f64>,
) {
    let (mut p, mut h) = (
        fbd_kinematics::nalgebra::Vector3::zeros(),
        fbd_kinematics::nalgebra::Vector3::zeros(),
    );
    for body in &mech.bodies {
        let b = body.model_body;
        let (c0, c1) = (data.kin.com[b], data.kin_next.com[b]);
        let v = body.mass * (c1 - c0) / dt;
        p += v;
        h += c0.cross(&v)
            + fbd_dynamics::spatial::half_momentum_value(
                &data.kin.rotation[b],
                &data.kin_next.rotation[b],
                &body.inertia,
                dt,
            );
    }
    (p, h)
}

/// The lab hexapod in flight, stepped by Newton on its FBD equations
/// (tumbling base, legs swinging, no torque): over every step the total
/// linear momentum changes by exactly `−M·g·Δt` along Y and the angular
/// momentum about the origin by the moment of gravity `Δt·Σ c_b × m_b·g`
/// (every joint force and moment is internal and cancels), to solver
/// tolerance: the generic equations are Newton–Euler's for the whole tree.
#[test]
fn lab_hexapod_flight_keeps_the_momentum_laws() {
    let model = lab();
    let g = 9.81;
    let mech = TreeMechanism::new(&model, g);
    let dims = mech.dims();
    let (n, nq) = (dims.dim(), mech.nq());
    let surface = Surface::default();
    let mut data = TreeFbdData::new(&mech);
    let mut rng = Rng(11);
    let mut q = vec![0.0; nq];
    q[1] = 1.0;
    for v in &mut q[6..] {
        *v = 0.5 * rng.next();
    }
    let qdot: Vec<f64> = (0..nq)
        .map(|i| {
            if i < 6 {
                1.0 * rng.next()
            } else {
                3.0 * rng.next()
            }
        })
        .collect();
    tree::set_configuration(&mech, &mut data, &q);
    let mut q_prev = q.clone();
    let mut solver = fbd_solver::NewtonSolver::new(fbd_solver::NewtonParams::default());
    let dt = 1e-3;
    let mass = mech.total_mass();
    let mut z = vec![0.0; n];
    let mut last: Option<(
        fbd_kinematics::nalgebra::Vector3<f64>,
        fbd_kinematics::nalgebra::Vector3<f64>,
    )> = None;
    let mut turned: f64 = 0.0;
    for k in 0..60 {
        let history = if k == 0 {
            History::Initial { qdot: &qdot }
        } else {
            History::Previous
        };
        tree::prepare_step(&mech, &mut data, history, dt);
        // Guess: q[k] moved on by the last step's motion (forces: the
        // last step's).
        for i in 0..nq {
            z[i] = if k == 0 {
                q[i] + dt * qdot[i]
            } else {
                2.0 * q[i] - q_prev[i]
            };
        }
        let mut sys = TreeSystem {
            mech: &mech,
            surface: &surface,
            data: &mut data,
        };
        solver
            .solve(&mut sys, &mut z)
            .unwrap_or_else(|e| panic!("step {k}: {e:?}"));
        tree::evaluate_next(&mech, &mut data, &z[..nq]);
        let (p, h) = momenta(&mech, &data, dt);
        if let Some((p0, h0)) = last {
            let want_p = p0 - mass * g * dt * fbd_kinematics::nalgebra::Vector3::y();
            assert!(
                (p - want_p).norm() < 1e-8 * mass * g * dt,
                "step {k}: linear momentum {p} vs {want_p}"
            );
            let mut gravity = fbd_kinematics::nalgebra::Vector3::zeros();
            for body in &mech.bodies {
                let c = data.kin.com[body.model_body];
                gravity += c.cross(&(-body.mass * g * fbd_kinematics::nalgebra::Vector3::y()));
            }
            let want_h = h0 + dt * gravity;
            assert!(
                (h - want_h).norm() < 1e-8 * (h.norm() + mass * g * dt),
                "step {k}: angular momentum {h} vs {want_h}"
            );
        }
        last = Some((p, h));
        turned = turned.max((z[3] - q[3]).abs());
        q_prev.copy_from_slice(&q);
        q.copy_from_slice(&z[..nq]);
        tree::advance(&mut data);
    }
    // It did tumble and fall.
    assert!(q[1] < 1.0 - 0.5 * g * (60.0 * dt).powi(2) * 0.9, "{}", q[1]);
    assert!(turned > 0.0);
}

/// Every single joint's two constraint moments are orthonormal and
/// across its axis (so with `τ·u` they span every moment), also where the
/// joint sits at its parent's origin (the fallback direction); a compound
/// joint's one moment is across both axes.
#[test]
fn constraint_moments_span_the_plane_across_each_axis() {
    let mut at_origin = lab();
    for j in 0..at_origin.joints.len() {
        if at_origin.joints[j].parent != 0 {
            at_origin.joints[j].origin.translation.vector.fill(0.0);
        }
    }
    let params = SpatialParams::default();
    let dh = fbd_scenario::robot::hexapod_robot(&params);
    for model in [lab(), at_origin, dh] {
        let mech = TreeMechanism::new(&model, 9.81);
        let mut data = TreeFbdData::new(&mech);
        let mut rng = Rng(3);
        let mut q = vec![0.0; mech.nq()];
        for v in &mut q[3..] {
            *v = rng.next();
        }
        tree::set_configuration(&mech, &mut data, &q);
        tree::set_previous(&mech, &mut data, &q);
        tree::prepare_step(&mech, &mut data, History::Previous, 1e-3);
        for (i, re) in mech.reactions.iter().enumerate() {
            let [d1, d2] = data.moment_dir[i];
            let u = data.kin.axis[re.joints[0]];
            assert!((d1.norm() - 1.0).abs() < 1e-12, "{}: {i}", model.name);
            assert!(d1.dot(&u).abs() < 1e-12, "{}: {i}", model.name);
            if re.compound {
                let u2 = data.kin.axis[re.joints[1]];
                assert!(d1.dot(&u2).abs() < 1e-12, "{}: {i}", model.name);
            } else {
                assert!((d2.norm() - 1.0).abs() < 1e-12, "{}: {i}", model.name);
                assert!(d2.dot(&u).abs() < 1e-12 && d2.dot(&d1).abs() < 1e-12);
            }
        }
    }
}

//! The effective inertia that the joint controller drives, at one pose:
//! the inertia of the stability rule of the explicit joint torques
//! (`rules::pd_stability`, documented in docs/reference.md, `[control]`).
//!
//! Every joint has the same gains, so the linearised closed loop of the
//! free (flying) robot, `M(q)·q̈ = −kp·Sᵀ·S·q − kd·Sᵀ·S·q̇` (`M` the mass
//! matrix in the generalised coordinates, `S` the selection of the joint
//! angles), falls apart into independent modes: the eigenvectors of the
//! joint block `S·M⁻¹·Sᵀ` of the inverse mass matrix. A mode of
//! eigenvalue `μ` is one joint of inertia `1/μ` under `kp` and `kd`, so
//! the binding inertia is `1/μ_max`, the smallest of the modes.
//!
//! It is much smaller than any one link's inertia about its joint: hip
//! and knee turning in opposite directions swing the light upper link
//! while the heavy lower link mostly translates. On the default planar
//! robot in flight it is 0.0103 kg·m² at θ3 = 250° and 0.0025 kg·m² with
//! the legs straight (θ3 = 180°), and 0.026 kg·m² at θ3 = 250° standing on
//! both feet, against 0.125 kg·m² for the lower link about the knee.
//!
//! A robot with feet on the ground has constraints `G·q̈ = …` and the
//! inverse inertia `M⁻¹ − M⁻¹Gᵀ(G·M⁻¹Gᵀ)⁺G·M⁻¹ ≤ M⁻¹`: its modes are
//! slower, the free robot's the fastest. The rule takes the feet that the
//! configuration stands on (every foot for `pd` and `trajectory`, the
//! stance feet of each step for `gait`, none without ground): with the
//! free robot's modes the shipped standing examples, stable in practice,
//! would be refused (the planar PD stand, kd = 10 at Δt = 2 ms: limit
//! 7.3 N·m·s/rad in flight, 23.2 standing), and with every foot down the
//! walk's swinging legs would be missed. On `examples/hexapod_walk.toml`
//! the rule allows kd < 19.74 N·m·s/rad; the walk runs with kd = 20 and
//! blows up with kd = 22.

use fbd_dynamics::spatial::{SpatialKin, SpatialMechanism};
use fbd_dynamics::{Mechanism, PointKind};
use fbd_kinematics::nalgebra::{DMatrix, Matrix3};

/// The mass matrix `M(q)` (kinetic energy `½·q̇ᵀ·M·q̇`) of the planar
/// model at `q`.
pub fn planar_mass_matrix(mech: &Mechanism, q: &[f64]) -> DMatrix<f64> {
    let chains = &mech.chains;
    let nq = chains.nq;
    let mut kin = chains.new_data();
    chains.eval_positions(q, &mut kin);
    chains.eval_jacobians(&mut kin);
    let mut m = DMatrix::zeros(nq, nq);
    for b in &mech.bodies {
        let angle = &chains.angles[b.angle];
        for i in 0..nq {
            for j in 0..nq {
                let v: f64 = (0..2)
                    .map(|axis| kin.jac_at(b.com, axis, i) * kin.jac_at(b.com, axis, j))
                    .sum();
                m[(i, j)] += b.mass * v + b.inertia * angle.coefficient(i) * angle.coefficient(j);
            }
        }
    }
    m
}

/// The mass matrix `M(q)` of the spatial model at `q`: every body's
/// `m·Jcᵀ·Jc + Jωᵀ·(R·I·Rᵀ)·Jω`.
pub fn spatial_mass_matrix(mech: &SpatialMechanism, q: &[f64]) -> DMatrix<f64> {
    let nq = mech.layout().nq;
    let mut kin = SpatialKin::new(mech);
    kin.eval(mech, q);
    let mut m = DMatrix::zeros(nq, nq);
    for (b, body) in mech.bodies.iter().enumerate() {
        let jc = kin.com_jacobian(mech, b);
        let jw = kin.angular_jacobian(mech, b);
        let r = kin.rot[b];
        let inertia: Matrix3<f64> = r * body.inertia * r.transpose();
        for (i, ci) in jc.iter() {
            for (j, cj) in jc.iter() {
                m[(*i, *j)] += body.mass * ci.dot(cj);
            }
        }
        for (i, wi) in jw.iter() {
            for (j, wj) in jw.iter() {
                m[(*i, *j)] += wi.dot(&(inertia * wj));
            }
        }
    }
    m
}

/// The Jacobian `∂p/∂q` of the feet of the planar model (2 rows per foot,
/// feet in the order of `index.tip`): the constraints of the feet on the
/// ground.
pub fn planar_feet_jacobian(mech: &Mechanism, tips: &[usize], q: &[f64]) -> DMatrix<f64> {
    let chains = &mech.chains;
    let mut kin = chains.new_data();
    chains.eval_positions(q, &mut kin);
    chains.eval_jacobians(&mut kin);
    DMatrix::from_fn(2 * tips.len(), chains.nq, |r, i| {
        kin.jac_at(tips[r / 2], r % 2, i)
    })
}

/// The Jacobian of the feet of the legs in `slots` of the spatial model
/// (3 rows per foot).
pub fn spatial_feet_jacobian(mech: &SpatialMechanism, slots: &[usize], q: &[f64]) -> DMatrix<f64> {
    let mut kin = SpatialKin::new(mech);
    kin.eval(mech, q);
    let mut g = DMatrix::zeros(3 * slots.len(), mech.layout().nq);
    for (r, &s) in slots.iter().enumerate() {
        for (i, c) in kin.contact_jacobian(mech, s, PointKind::Tip).iter() {
            for a in 0..3 {
                g[(3 * r + a, *i)] += c[a];
            }
        }
    }
    g
}

/// The fastest mode of the joints at one pose.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct JointMode {
    /// Its effective inertia `1/μ_max` (kg·m²).
    pub inertia: f64,
    /// The position in `joints` of the joint that moves most in it.
    pub joint: usize,
}

/// The smallest effective joint inertia of mass matrix `m` under the
/// constraints `g·q̈ = …` (rows of `g`; none for the free robot), the
/// joint angles at `joints` (indices into `q`): `1/μ_max` of the joint
/// block of `M⁻¹ − M⁻¹Gᵀ(G·M⁻¹Gᵀ)⁺G·M⁻¹`.
///
/// # Panics
/// When `m` is not symmetric positive definite (a mechanism's mass matrix
/// with positive masses and inertias always is).
pub fn fastest_mode(m: &DMatrix<f64>, g: &DMatrix<f64>, joints: &[usize]) -> JointMode {
    let n = m.nrows();
    assert_eq!(g.ncols(), n, "one constraint column per coordinate");
    let chol = m
        .clone()
        .cholesky()
        .expect("a mass matrix is positive definite");
    let mut minv = chol.inverse();
    if g.nrows() > 0 {
        let gm = g * &minv;
        // Redundant constraints (a singular G·M⁻¹Gᵀ) are harmless: the
        // pseudo-inverse projects on the constrained directions.
        let s = (&gm * g.transpose())
            .pseudo_inverse(1e-12)
            .expect("the tolerance is not negative");
        minv -= gm.transpose() * s * &gm;
    }
    let block = DMatrix::from_fn(joints.len(), joints.len(), |r, c| {
        0.5 * (minv[(joints[r], joints[c])] + minv[(joints[c], joints[r])])
    });
    let eig = block.symmetric_eigen();
    let top = eig.eigenvalues.imax();
    let v = eig.eigenvectors.column(top);
    JointMode {
        inertia: 1.0 / eig.eigenvalues[top],
        joint: v.iamax(),
    }
}

//! Kinetic and potential energy of the mechanism.

use fbd_dynamics::{BodySpec, FbdData, Mechanism};
use fbd_kinematics::planar::PlanarData;

/// Kinetic energy at `k` from central-difference body velocities
/// `(x[k+1] − x[k−1]) / 2Δt`.
pub fn kinetic_central(mech: &Mechanism, prev: &PlanarData, next: &PlanarData, dt: f64) -> f64 {
    mech.bodies
        .iter()
        .enumerate()
        .map(|(b, s)| {
            let a = FbdData::body_coords(mech, prev, b);
            let c = FbdData::body_coords(mech, next, b);
            let v = [
                (c[0] - a[0]) / (2.0 * dt),
                (c[1] - a[1]) / (2.0 * dt),
                (c[2] - a[2]) / (2.0 * dt),
            ];
            body_kinetic(s, v)
        })
        .sum()
}

/// Kinetic energy from generalised velocities `q̇` at the kinematics `kin`
/// (positions and Jacobians evaluated).
pub fn kinetic_exact(mech: &Mechanism, kin: &PlanarData, qdot: &[f64]) -> f64 {
    (0..mech.bodies.len())
        .map(|b| {
            let spec = &mech.bodies[b];
            let v = mech.chains.point_velocity(kin, spec.com, qdot);
            let w = mech.chains.angles[spec.angle].rate(qdot);
            body_kinetic(spec, [v[0], v[1], w])
        })
        .sum()
}

fn body_kinetic(s: &BodySpec, v: [f64; 3]) -> f64 {
    0.5 * s.mass * (v[0] * v[0] + v[1] * v[1]) + 0.5 * s.inertia * v[2] * v[2]
}

/// Gravitational potential energy `Σ m g y` at the kinematics `kin`.
pub fn potential(mech: &Mechanism, kin: &PlanarData) -> f64 {
    mech.bodies
        .iter()
        .map(|b| b.mass * mech.gravity * kin.pos[b.com][1])
        .sum()
}

//! Kinetic and potential energy, momenta and centre of mass of the planar
//! mechanism.

use fbd_dynamics::{BodySpec, FbdData, Mechanism};
use fbd_kinematics::planar::PlanarData;

/// The motion of the planar mechanism at `k` from its bodies' velocities:
/// what the record holds besides the potential energy.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Motion {
    /// Kinetic energy (J).
    pub kinetic: f64,
    /// Total linear momentum (kg·m/s; z = 0).
    pub momentum: [f64; 3],
    /// Total angular momentum about the origin (kg·m²/s; along Z).
    pub angular_momentum: [f64; 3],
    /// Centre of mass of all bodies at `kin` (m; z = 0).
    pub com: [f64; 3],
}

impl Motion {
    /// Adds body `s` at `p` (its centre of mass) moving at `v` (`ẋ, ẏ, ω`).
    #[inline]
    fn add(&mut self, s: &BodySpec, p: [f64; 2], v: [f64; 3]) {
        self.kinetic += body_kinetic(s, v);
        self.momentum[0] += s.mass * v[0];
        self.momentum[1] += s.mass * v[1];
        self.angular_momentum[2] += s.mass * (p[0] * v[1] - p[1] * v[0]) + s.inertia * v[2];
        self.com[0] += s.mass * p[0];
        self.com[1] += s.mass * p[1];
    }

    /// Divides the mass-weighted sum of the centres by the total mass.
    fn finish(mut self, mech: &Mechanism) -> Self {
        let m = mech.total_mass();
        if m > 0.0 {
            self.com[0] /= m;
            self.com[1] /= m;
        }
        self
    }
}

/// Kinetic energy at `k` from central-difference body velocities
/// `(x[k+1] − x[k−1]) / 2Δt`.
pub fn kinetic_central(mech: &Mechanism, prev: &PlanarData, next: &PlanarData, dt: f64) -> f64 {
    mech.bodies
        .iter()
        .enumerate()
        .map(|(b, s)| body_kinetic(s, central_velocity(mech, prev, next, b, dt)))
        .sum()
}

/// The motion at `k` (positions `kin`) from the central-difference body
/// velocities of [`kinetic_central`] (its kinetic energy, bit for bit).
pub fn motion_central(
    mech: &Mechanism,
    kin: &PlanarData,
    prev: &PlanarData,
    next: &PlanarData,
    dt: f64,
) -> Motion {
    let mut m = Motion::default();
    for (b, s) in mech.bodies.iter().enumerate() {
        m.add(s, kin.pos[s.com], central_velocity(mech, prev, next, b, dt));
    }
    m.finish(mech)
}

#[inline]
fn central_velocity(
    mech: &Mechanism,
    prev: &PlanarData,
    next: &PlanarData,
    b: usize,
    dt: f64,
) -> [f64; 3] {
    let a = FbdData::body_coords(mech, prev, b);
    let c = FbdData::body_coords(mech, next, b);
    [
        (c[0] - a[0]) / (2.0 * dt),
        (c[1] - a[1]) / (2.0 * dt),
        (c[2] - a[2]) / (2.0 * dt),
    ]
}

/// Kinetic energy from generalised velocities `q̇` at the kinematics `kin`
/// (positions and Jacobians evaluated).
pub fn kinetic_exact(mech: &Mechanism, kin: &PlanarData, qdot: &[f64]) -> f64 {
    motion_exact(mech, kin, qdot).kinetic
}

/// The motion from generalised velocities `q̇` at the kinematics `kin`
/// (positions and Jacobians evaluated).
pub fn motion_exact(mech: &Mechanism, kin: &PlanarData, qdot: &[f64]) -> Motion {
    let mut m = Motion::default();
    for spec in &mech.bodies {
        let v = mech.chains.point_velocity(kin, spec.com, qdot);
        let w = mech.chains.angles[spec.angle].rate(qdot);
        m.add(spec, kin.pos[spec.com], [v[0], v[1], w]);
    }
    m.finish(mech)
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

//! What a step of any model on the generic tree equations
//! ([`fbd_dynamics::tree`]: the paper's hexapod and every imported robot)
//! records from its solution, written once: each contact point's force,
//! each joint reaction's force and moment, and the step's energies and
//! momenta (the scheme's own, over the step k → k+1).

use fbd_dynamics::spatial::half_momentum_and_rotation;
use fbd_dynamics::tree::assemble::step_momentum;
use fbd_dynamics::tree::{TreeFbdData, TreeMechanism};
use fbd_kinematics::nalgebra::Vector3;

/// Contact point `c` at `q[k]` (where it touches the ground), and the
/// ground's force on it (inertial) with its normal component, from the
/// solution `z`.
#[inline]
pub fn contact_force(
    mech: &TreeMechanism,
    fbd: &TreeFbdData,
    z: &[f64],
    c: usize,
) -> ([f64; 3], [f64; 3], f64) {
    let dims = mech.dims();
    let p = fbd.kin.contact[mech.contacts[c].model_contact];
    let fl = [
        z[dims.contact_force(c, 0)],
        z[dims.contact_force(c, 1)],
        z[dims.contact_force(c, 2)],
    ];
    let [t1, n, t2] = fbd.contact[c].frame;
    (
        [p.x, p.y, p.z],
        std::array::from_fn(|i| fl[0] * t1[i] + fl[1] * n[i] + fl[2] * t2[i]),
        fl[1],
    )
}

/// Reaction `i`'s force on its child body at its first joint's origin
/// (the parent gets its opposite), and its moment about that point: the
/// constraint moments and its joints' actuator torques (a stop's moment,
/// along its joint's axis, comes on top).
#[inline]
pub fn reaction_wrench(
    mech: &TreeMechanism,
    fbd: &TreeFbdData,
    z: &[f64],
    i: usize,
) -> (Vector3<f64>, Vector3<f64>) {
    let re = &mech.reactions[i];
    let [d1, d2] = fbd.moment_dir[i];
    let mut m = z[mech.reaction_moment(i, 0)] * d1;
    if !re.compound {
        m += z[mech.reaction_moment(i, 1)] * d2;
    }
    for &j in re.joint_list() {
        m += fbd.torque[j] * fbd.kin.axis[j];
    }
    let f = mech.reaction_force(i, 0);
    (Vector3::new(z[f], z[f + 1], z[f + 2]), m)
}

/// The energies and momenta of a (sub)step of length `h`.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Momenta {
    /// Kinetic energy over the step (J, the scheme's).
    pub kinetic: f64,
    /// Gravitational potential energy, mean of k and k+1 (J).
    pub potential: f64,
    /// Total linear momentum over the step (kg·m/s).
    pub momentum: [f64; 3],
    /// Total angular momentum about the origin over the step (kg·m²/s).
    pub angular_momentum: [f64; 3],
    /// Centre of mass of the whole robot at `q[k]` (m).
    pub com: [f64; 3],
}

/// The step's energies and momenta; keeps every body's `L[k+½]` in
/// `fbd.l_carry`, the next step's `L[k−½]` when this step is accepted
/// whole.
pub fn momenta(mech: &TreeMechanism, fbd: &mut TreeFbdData, h: f64) -> Momenta {
    let g = mech.gravity;
    let (mut kinetic, mut potential) = (0.0, 0.0);
    let (mut p, mut hm, mut c) = (Vector3::zeros(), Vector3::zeros(), Vector3::zeros());
    for (b, body) in mech.bodies.iter().enumerate() {
        let mb = body.model_body;
        let (c0, c1) = (fbd.kin.com[mb], fbd.kin_next.com[mb]);
        let v = (c1 - c0) / h;
        let (l, psi) = momentum_over_step(mech, fbd, b, h);
        fbd.l_carry[b] = l;
        kinetic +=
            0.5 * body.mass * v.norm_squared() + 0.5 * psi.dot(&(body.inertia * psi)) / (h * h);
        potential += body.mass * g * 0.5 * (c0.y + c1.y);
        p += body.mass * v;
        hm += body.mass * c0.cross(&v) + l;
        c += body.mass * c0;
    }
    fbd.l_carry_dt = h;
    Momenta {
        kinetic,
        potential,
        momentum: p.into(),
        angular_momentum: hm.into(),
        com: (c / mech.total_mass()).into(),
    }
}

/// Every body's `L[k+½]` over the step, kept for the next step's `L[k−½]`
/// (as [`momenta`] keeps them), for a step without a record.
pub fn carry_momenta(mech: &TreeMechanism, fbd: &mut TreeFbdData, h: f64) {
    for b in 0..mech.bodies.len() {
        fbd.l_carry[b] = momentum_over_step(mech, fbd, b, h).0;
    }
    fbd.l_carry_dt = h;
}

/// Body `b`'s `L[k+½]` and rotation `ψ[k+½]` over the accepted (sub)step
/// of length `h`: those the last residual evaluation computed at the
/// accepted `q[k+1]` (the same values, bit for bit), or computed again.
#[inline]
fn momentum_over_step(
    mech: &TreeMechanism,
    fbd: &TreeFbdData,
    b: usize,
    h: f64,
) -> (Vector3<f64>, Vector3<f64>) {
    match step_momentum(fbd, b) {
        Some(v) if fbd.dt == h => v,
        _ => {
            let body = &mech.bodies[b];
            let mb = body.model_body;
            half_momentum_and_rotation(
                &fbd.kin.rotation[mb],
                &fbd.kin_next.rotation[mb],
                &body.inertia,
                h,
            )
        }
    }
}

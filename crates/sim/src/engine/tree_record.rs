//! The one record of every model, [`RobotRecord`]: the models on the
//! generic tree equations ([`fbd_dynamics::tree`]: the paper's hexapod and
//! every imported robot) and the planar model (its plane embedded in 3D,
//! filled by [`crate::step`]). What a step of a tree model records from
//! its solution is written once ([`make_record`]): each contact point's
//! force, each joint reaction's force and moment, each joint's torque,
//! rate and stop, and the step's energies and momenta (the scheme's own,
//! over the step k → k+1). A model's own view of it (the hexapod's legs,
//! [`crate::spatial::LegRow`]; the planar model's coordinates,
//! [`RobotRecord::plane_q`]) is read from it, not recorded apart.

use super::RunData;
use super::surface::SurfaceEngine;
use crate::record::LimitCode;
use fbd_contact::StateCode;
use fbd_dynamics::spatial::half_momentum_and_rotation;
use fbd_dynamics::tree::assemble::step_momentum;
use fbd_dynamics::tree::{TreeFbdData, TreeMechanism};
use fbd_kinematics::nalgebra::Vector3;

/// One contact point's row values.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RobotContactRow {
    /// Where it touches the ground at `q[k]` (a sphere's lowest point)
    /// (m, inertial).
    pub point: [f64; 3],
    /// State the point was solved in at step k.
    pub state: StateCode,
    /// Force of the ground on the point, inertial frame (N).
    pub force: [f64; 3],
    /// Normal component of that force (N, along the terrain normal).
    pub normal: f64,
    /// Its components along the contact frame's two tangents (N): a tree
    /// model's `t1`, `t2`; the planar model's terrain tangent
    /// `(1, ϱ′)/√(1+ϱ′²)` (its `fa`), then 0.
    pub tangential: [f64; 2],
}

/// Everything known about step `k` of a robot once it is solved: row `k`
/// of `trajectory.csv`. Sized from the model (allocated once, refilled
/// every step).
///
/// The planar model's record is its plane embedded in 3D: `q` holds
/// `(Rx, Ry, 0, 0, 0, φz)` then its joints ([`Self::plane_q`]), points and
/// forces have z = 0 (a contact's force is `fa·t + n·n̂` in the frame its
/// step solved, the terrain's at the anchor for ST2, under the point
/// otherwise; `fa` is its first tangential component), reaction `j` is
/// joint `j`'s (force of the parent on
/// the child at the joint, moment `axis_z·(τ + stop)` about Z), its
/// energies are those at k (kinetic from the central differences
/// `q[k−1]` → `q[k+1]`, the exact one from `q̇(0)` at k = 0; potential at
/// `q[k]`). Its step computes no joint rates, momenta or centre of mass:
/// `rate`, `momentum`, `angular_momentum` and `com` stay zero (its files
/// read none of them, and they would cost every step; a planar model's
/// rates are its simulator's readout, `Readout::qdot`).
///
/// A tree model's record handed out to be observed but not written
/// ([`crate::engine::run::run_in_written`]: `fbd run`'s plots and peaks
/// between its written rows) is filled except for `reaction_moment`,
/// `limit`, `stop`, `momentum`, `angular_momentum` and `com`, which keep
/// the values of the last whole record.
#[derive(Clone, Debug, PartialEq)]
pub struct RobotRecord {
    /// Step index k.
    pub step: usize,
    /// Time k·Δt (s).
    pub t: f64,
    /// `q[k]`: the root's `(Rx, Ry, Rz, φx, φy, φz)`, then every joint's
    /// angle (m, rad).
    pub q: Vec<f64>,
    /// Per contact point of the mechanism (model order).
    pub contacts: Vec<RobotContactRow>,
    /// Per reaction (`TreeMechanism::reactions`), the force at its first
    /// joint's origin on the child body (N, inertial; the parent gets its
    /// opposite).
    pub reaction_force: Vec<[f64; 3]>,
    /// Per reaction, the moment on the child body about that point:
    /// constraint moments, actuator torques and stop moments (N·m,
    /// inertial).
    pub reaction_moment: Vec<[f64; 3]>,
    /// Per model joint, its actuator torque at k (N·m).
    pub torque: Vec<f64>,
    /// Per model joint, its rate at k (rad/s, backward difference; the
    /// initial rate at k = 0; zero for the planar model).
    pub rate: Vec<f64>,
    /// Per model joint, its stop's state at k (free for joints without
    /// limits).
    pub limit: Vec<LimitCode>,
    /// Per model joint, its stop moment at k (N·m, along the joint axis on
    /// the child).
    pub stop: Vec<f64>,
    /// Kinetic energy over the step (J, the scheme's; the planar model's
    /// at k).
    pub kinetic: f64,
    /// Gravitational potential energy, mean of k and k+1 (J; the planar
    /// model's at k).
    pub potential: f64,
    /// Total linear momentum over the step k → k+1 (kg·m/s; zero for the
    /// planar model).
    pub momentum: [f64; 3],
    /// Total angular momentum about the origin over the step (kg·m²/s;
    /// zero for the planar model).
    pub angular_momentum: [f64; 3],
    /// Centre of mass of the whole robot at `q[k]` (m; zero for the planar
    /// model).
    pub com: [f64; 3],
    /// Newton iterations of this step (every state trial and substep).
    pub newton_iterations: usize,
    /// State combinations solved in this step.
    pub state_trials: usize,
}

/// Where the planar model's root coordinates `(Rx, Ry, φz)` are in a
/// record's `q` (`(Rx, Ry, Rz, φx, φy, φz)`, then the joints).
pub const PLANE_ROOT: [usize; 3] = [0, 1, 5];

/// Where the planar model's coordinate `i` (`Rx, Ry, φz`, then its joints)
/// is in a record's `q`.
pub const fn plane_q_index(i: usize) -> usize {
    if i < 3 { PLANE_ROOT[i] } else { i + 3 }
}

impl RobotRecord {
    /// A record sized for `mech` at `q0` (every value zero).
    pub fn new(mech: &TreeMechanism, q0: &[f64]) -> Self {
        let mut r = Self::sized(
            q0.len(),
            mech.contacts.len(),
            mech.reactions.len(),
            mech.model.joints.len(),
        );
        r.q.copy_from_slice(q0);
        r
    }

    /// A record of `nq` coordinates, `contacts` contact points,
    /// `reactions` reactions and `joints` joints, every value zero (states
    /// ST1, limits free).
    pub fn sized(nq: usize, contacts: usize, reactions: usize, joints: usize) -> Self {
        let (nr, nj) = (reactions, joints);
        Self {
            step: 0,
            t: 0.0,
            q: vec![0.0; nq],
            contacts: vec![
                RobotContactRow {
                    point: [0.0; 3],
                    state: StateCode::St1,
                    force: [0.0; 3],
                    normal: 0.0,
                    tangential: [0.0; 2],
                };
                contacts
            ],
            reaction_force: vec![[0.0; 3]; nr],
            reaction_moment: vec![[0.0; 3]; nr],
            torque: vec![0.0; nj],
            rate: vec![0.0; nj],
            limit: vec![LimitCode::Free; nj],
            stop: vec![0.0; nj],
            kinetic: 0.0,
            potential: 0.0,
            momentum: [0.0; 3],
            angular_momentum: [0.0; 3],
            com: [0.0; 3],
            newton_iterations: 0,
            state_trials: 0,
        }
    }

    /// A record of the planar model with `joints` joints and `contacts`
    /// contact points (its plane embedded: `q` of `6 + joints`
    /// coordinates, one reaction per joint), every value zero.
    pub fn planar(contacts: usize, joints: usize) -> Self {
        Self::sized(6 + joints, contacts, joints, joints)
    }

    /// The planar model's coordinates of this record's `q`: `(Rx, Ry, φz)`
    /// then its joints (the inverse of [`Self::set_plane_q`]).
    pub fn plane_q(&self) -> Vec<f64> {
        let mut q = Vec::with_capacity(self.q.len().saturating_sub(3));
        self.plane_q_into(&mut q);
        q
    }

    /// [`Self::plane_q`] into `out` (cleared first; no allocation once it
    /// has the room).
    pub fn plane_q_into(&self, out: &mut Vec<f64>) {
        out.clear();
        out.extend(PLANE_ROOT.iter().map(|&i| self.q[i]));
        out.extend_from_slice(&self.q[6..]);
    }

    /// Sets `q` from the planar model's coordinates `plane` (`Rx, Ry, φz`,
    /// then its joints): `(Rx, Ry, 0, 0, 0, φz)`, then the joints.
    #[inline]
    pub fn set_plane_q(&mut self, plane: &[f64]) {
        self.q[..6].copy_from_slice(&[plane[0], plane[1], 0.0, 0.0, 0.0, plane[2]]);
        self.q[6..].copy_from_slice(&plane[3..]);
    }
}

/// The rate `q̇_i[k]` of coordinate `i`: the backward difference
/// `(q_i[k] − q_i[k−1])/Δt`, the initial rate `q̇_i(0)` at k = 0 (the
/// joint controllers' rates and the record's, one rule).
#[inline]
pub fn coordinate_rate<M: super::Engine>(model: &M, data: &RunData<M>, i: usize) -> f64 {
    if data.k == 0 {
        model.qdot0()[i]
    } else {
        (data.q[i] - data.q_prev[i]) / model.dt()
    }
}

/// The number of root coordinates before the joint angles in `q`.
const ROOT_DOF: usize = 6;

/// Fills `data.record` for the solved (sub)step of length `h` of a model
/// on the tree equations: every model's, written once.
pub fn make_record<M>(
    model: &M,
    data: &mut RunData<M>,
    newton_iterations: usize,
    state_trials: usize,
    h: f64,
) where
    M: SurfaceEngine<Mech = TreeMechanism, Fbd = TreeFbdData, Record = RobotRecord>,
{
    let mech = model.mech();
    let dims = mech.dims();
    let dt = model.dt();
    let fbd = &data.fbd;
    let z = &data.z;
    let rec = &mut data.record;
    rec.step = data.k;
    rec.t = data.k as f64 * dt;
    rec.q.copy_from_slice(&data.q);
    rec.newton_iterations = newton_iterations;
    rec.state_trials = state_trials;
    for (c, row) in rec.contacts.iter_mut().enumerate() {
        let local;
        (row.point, row.force, local) = contact_force(mech, fbd, z, c);
        (row.normal, row.tangential) = (local[1], [local[0], local[2]]);
        row.state = data.trial[c].code();
    }
    rec.torque.copy_from_slice(&fbd.torque);
    // A record observed but not written leaves out the reaction moments,
    // the stops, the momenta and the centre of mass (see the type's docs).
    let whole = data.whole_record;
    for i in 0..mech.reactions.len() {
        if whole {
            let (f, m) = reaction_wrench(mech, fbd, z, i);
            rec.reaction_force[i] = f.into();
            rec.reaction_moment[i] = m.into();
        } else {
            rec.reaction_force[i] = reaction_force(mech, z, i).into();
        }
    }
    if whole {
        rec.limit.fill(LimitCode::Free);
        rec.stop.fill(0.0);
        for (l, lim) in mech.limits.iter().enumerate() {
            let stop = z[dims.limit_moment(l)];
            let m =
                Vector3::from(rec.reaction_moment[lim.reaction]) + stop * fbd.kin.axis[lim.joint];
            rec.reaction_moment[lim.reaction] = m.into();
            rec.limit[lim.joint] = LimitCode::of(&data.limit_trial[l]);
            rec.stop[lim.joint] = stop;
        }
    }
    for j in 0..rec.rate.len() {
        let r = coordinate_rate(model, data, ROOT_DOF + j);
        data.record.rate[j] = r;
    }
    let m = if whole {
        momenta(mech, &mut data.fbd, h)
    } else {
        momenta_of::<false>(mech, &mut data.fbd, h)
    };
    let rec = &mut data.record;
    rec.kinetic = m.kinetic;
    rec.potential = m.potential;
    if whole {
        rec.momentum = m.momentum;
        rec.angular_momentum = m.angular_momentum;
        rec.com = m.com;
    }
}

/// Contact point `c` at `q[k]` (where it touches the ground), and the
/// ground's force on it: inertial, and its components along the contact
/// frame `(t1, n, t2)`, from the solution `z`.
#[inline]
pub fn contact_force(
    mech: &TreeMechanism,
    fbd: &TreeFbdData,
    z: &[f64],
    c: usize,
) -> ([f64; 3], [f64; 3], [f64; 3]) {
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
        fl,
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
    (reaction_force(mech, z, i), m)
}

/// Reaction `i`'s force on its child body (as [`reaction_wrench`]'s).
#[inline]
pub fn reaction_force(mech: &TreeMechanism, z: &[f64], i: usize) -> Vector3<f64> {
    let f = mech.reaction_force(i, 0);
    Vector3::new(z[f], z[f + 1], z[f + 2])
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
    momenta_of::<true>(mech, fbd, h)
}

/// [`momenta`], its linear and angular momenta and centre of mass left
/// zero unless `WHOLE`: without them, the same kinetic and potential
/// energies (the same sums in the same order) and the same `L[k+½]` kept,
/// for a record observed but not written
/// ([`crate::engine::run::run_in_written`]).
#[inline]
fn momenta_of<const WHOLE: bool>(mech: &TreeMechanism, fbd: &mut TreeFbdData, h: f64) -> Momenta {
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
        if WHOLE {
            p += body.mass * v;
            hm += body.mass * c0.cross(&v) + l;
            c += body.mass * c0;
        }
    }
    fbd.l_carry_dt = h;
    let com = if WHOLE {
        (c / mech.total_mass()).into()
    } else {
        [0.0; 3]
    };
    Momenta {
        kinetic,
        potential,
        momentum: p.into(),
        angular_momentum: hm.into(),
        com,
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

//! Residual and analytic Jacobian of one time step of any robot model's
//! FBD equations ([`super::mechanism`] for the bodies, reactions and
//! layout). The equations are those of the one assembly of the plane and
//! space, [`crate::assembly`]; this module supplies the model's part
//! ([`FbdModel`] for [`TreeMechanism`]): the kinematics ([`TreeKin`]), the
//! joint reactions with their constraint moments, and, exactly as for the
//! spatial hexapod (the same functions: [`half_momentum`],
//! [`slip_direction`]), the Lie-group discretisation of Euler's equations
//! and the implicit slip direction of a sliding point.
//!
//! The stepping entry points: [`set_configuration`], [`set_previous`],
//! [`prepare_step`], [`eval`], [`pattern_key`], [`pattern`],
//! [`evaluate_next`], [`advance`].

use super::kin::{Columns, TreeKin};
use super::mechanism::TreeMechanism;
use crate::assemble::{History, JacobianSink, LimitEquation};
use crate::assembly::{self, At, ContactView, Dims, FbdModel, Reaction, RowState, Slip, StopView};
use crate::body::Wrench;
use crate::rows;
use crate::space::Space3;
use crate::spatial::equations::{
    BodyStep3, STOP_SPEED, SpatialContactEquation, half_momentum_and_rotation,
    half_momentum_derivative_and_rotation, half_momentum_value, slip_direction,
};
use fbd_contact::spatial::clearance;
use fbd_contact::{SpatialState, Surface};
use fbd_kinematics::nalgebra::{Matrix3, Vector3};

/// Mutable workspace of a [`TreeMechanism`]'s assembly (allocated once).
#[derive(Clone, Debug)]
pub struct TreeFbdData {
    /// Kinematics at `q[k−1]`.
    pub kin_prev: TreeKin,
    /// Kinematics at `q[k]`.
    pub kin: TreeKin,
    /// Kinematics at the current iterate of `q[k+1]`.
    pub kin_next: TreeKin,
    /// Per FBD body, the constants of this step.
    pub body: Vec<BodyStep3>,
    /// Per contact point, its equations in this step.
    pub contact: Vec<SpatialContactEquation>,
    /// Per stop (order of [`TreeMechanism::limits`]), its equation.
    pub limit: Vec<LimitEquation>,
    /// Actuator torque of every model joint at k (N·m, about its axis).
    pub torque: Vec<f64>,
    /// Time step (s).
    pub dt: f64,
    /// Scale of contact position rows `M/Δt²` (N/m).
    pub position_gain: f64,
    /// Scale of stop rows `(M/Δt²)·ℓ²` (N·m/rad).
    pub limit_gain: f64,
    /// Per reaction, the constraint-moment directions at k (a compound
    /// joint: `u1 × u2` normalised, the second unused; a single joint:
    /// `b1`, `b2 = u × b1` across its axis `u`).
    pub moment_dir: Vec<[Vector3<f64>; 2]>,
    /// Per reaction, [`FbdModel::reaction`] at k but for its actuator
    /// torque (zero here): the columns and bodies from the mechanism, the
    /// point and constraint-moment directions made by [`prepare_step`].
    reaction_k: Vec<Reaction<Space3>>,
    /// Per stop, its bodies and joint from the mechanism, in one place.
    stop_k: Vec<StopK>,
    /// Per FBD body, `L[k+½]` at the last evaluated iterate.
    pub l_next: Vec<Vector3<f64>>,
    /// Per FBD body, the rotation `ψ[k+½]` of `l_next`.
    psi_next: Vec<Vector3<f64>>,
    /// Per FBD body, whether `l_next` and `psi_next` are those of the
    /// evaluated `kin_next` over this step's `dt` ([`step_momentum`]).
    l_next_fresh: Vec<bool>,
    /// Per FBD body, the sum of applied forces and moments (about its CoM)
    /// at k of the last evaluation (N, N·m).
    pub wrench: Vec<Wrench<Space3>>,
    /// `L[k+½]` of every body at the accepted `q[k+1]` over a step of
    /// `l_carry_dt`, the next step's `L[k−½]` when `l_carry_valid`: a
    /// step accepted whole carries its momenta over, so that the next
    /// step's history is bit-for-bit the one it was solved with.
    pub l_carry: Vec<Vector3<f64>>,
    /// The step length of `l_carry`.
    pub l_carry_dt: f64,
    /// Whether `l_carry` holds the last accepted step's momenta.
    pub l_carry_valid: bool,
    /// `ε = STOP_SPEED·Δt` (m) of [`slip_direction`].
    pub slip_bias: f64,
    /// Per contact, the slip direction `ŝ` at the last evaluated iterate.
    pub slip_hat: Vec<[f64; 2]>,
    /// Per contact: the slide's friction keeps its reference direction.
    pub fixed_direction: Vec<bool>,
    /// Per contact: its fixed direction was released once in this step.
    pub released_direction: Vec<bool>,
    /// Per contact, `max(|w|, ε)` of [`slip_direction`] at the last
    /// evaluated iterate (m).
    pub slip_len: Vec<f64>,
    /// Per contact, the normal force at the last evaluated iterate (N).
    pub slip_n: Vec<f64>,
    /// Per contact, the branch of its complementarity rows at the last
    /// evaluated iterate.
    pub branch: Vec<rows::Branch>,
    /// Per contact, the branches fixed for this step's solves.
    pub frozen: Vec<Option<rows::Frozen>>,
    /// This step's solves use fixed states, not complementarity rows.
    pub fixed_states: bool,
    /// The branches the active-set fallback froze first this step.
    pub first_frozen: Vec<Option<rows::Frozen>>,
    /// Whether this step's active-set fallback has restarted.
    pub refrozen: bool,
    /// Per stop, whether its complementarity row is unloaded at the last
    /// evaluated iterate.
    pub limit_unloaded: Vec<bool>,
    rot_d: Vec<Matrix3<f64>>,
    /// The `q` `kin_next` was last evaluated at (NaN: none).
    kin_next_q: Vec<f64>,
    next_is_candidate: bool,
}

impl TreeFbdData {
    /// A workspace for `mech`.
    pub fn new(mech: &TreeMechanism) -> Self {
        let kin = TreeKin::new(&mech.model);
        let (nb, nc, nl) = (mech.bodies.len(), mech.contacts.len(), mech.limits.len());
        Self {
            kin_prev: kin.clone(),
            kin_next: kin.clone(),
            kin,
            body: vec![BodyStep3::default(); nb],
            contact: vec![SpatialContactEquation::default(); nc],
            limit: vec![LimitEquation::default(); nl],
            torque: vec![0.0; mech.model.joints.len()],
            dt: 0.0,
            position_gain: 0.0,
            limit_gain: 0.0,
            moment_dir: vec![[Vector3::zeros(); 2]; mech.reactions.len()],
            reaction_k: (0..mech.reactions.len())
                .map(|i| reaction_layout(mech, i))
                .collect(),
            stop_k: mech
                .limits
                .iter()
                .map(|lim| {
                    let re = &mech.reactions[lim.reaction];
                    StopK {
                        child: re.child,
                        parent: re.parent,
                        q_index: lim.q_index,
                        joint: lim.joint,
                    }
                })
                .collect(),
            l_next: vec![Vector3::zeros(); nb],
            psi_next: vec![Vector3::zeros(); nb],
            l_next_fresh: vec![false; nb],
            wrench: vec![Wrench::default(); nb],
            l_carry: vec![Vector3::zeros(); nb],
            l_carry_dt: 0.0,
            l_carry_valid: false,
            slip_bias: 0.0,
            slip_hat: vec![[0.0; 2]; nc],
            fixed_direction: vec![false; nc],
            released_direction: vec![false; nc],
            slip_len: vec![1.0; nc],
            slip_n: vec![0.0; nc],
            branch: vec![rows::Branch::default(); nc],
            frozen: vec![None; nc],
            fixed_states: false,
            first_frozen: vec![None; nc],
            refrozen: false,
            limit_unloaded: vec![false; nl],
            rot_d: vec![Matrix3::zeros(); nb],
            kin_next_q: vec![f64::NAN; mech.nq()],
            next_is_candidate: false,
        }
    }
}

/// Sets `q[k]` (at k = 0; afterwards [`advance`] does it).
pub fn set_configuration(mech: &TreeMechanism, data: &mut TreeFbdData, q: &[f64]) {
    data.kin.eval(&mech.model, q);
}

/// Sets `q[k−1]` (for a restart in substeps).
pub fn set_previous(mech: &TreeMechanism, data: &mut TreeFbdData, q: &[f64]) {
    data.kin_prev.eval(&mech.model, q);
}

/// Angular momentum `R·I·Rᵀ·ω` of FBD body `b` at `kin` for `ω`.
pub fn momentum(mech: &TreeMechanism, kin: &TreeKin, b: usize, w: &Vector3<f64>) -> Vector3<f64> {
    let body = &mech.bodies[b];
    let r = &kin.rotation[body.model_body];
    r * (body.inertia * (r.transpose() * w))
}

/// The constraint-moment directions of reaction `i` at `kin` (see
/// [`TreeFbdData::moment_dir`]). For a single joint, `b1` is the parent
/// link's direction from its frame origin to the joint (the upper link of
/// a knee) made perpendicular to the axis, or, where that is degenerate
/// (the joint at the parent's origin or the link along the axis), the
/// parent's frame axis most perpendicular to it.
fn moment_directions(mech: &TreeMechanism, kin: &TreeKin, i: usize) -> [Vector3<f64>; 2] {
    let re = &mech.reactions[i];
    let [j1, j2] = re.joints;
    if re.compound {
        return [
            kin.axis[j1].cross(&kin.axis[j2]).normalize(),
            Vector3::zeros(),
        ];
    }
    let u = kin.axis[j1];
    let parent = mech.model.joints[j1].parent;
    let link = kin.joint_origin[j1] - kin.origin[parent];
    let across = link - u * u.dot(&link);
    let b1 = if across.norm() > 1e-9 * (1.0 + link.norm()) {
        across.normalize()
    } else {
        let r = &kin.rotation[parent];
        let e = (0..3)
            .map(|k| Vector3::from(r.column(k)))
            .max_by(|a, b| a.cross(&u).norm().total_cmp(&b.cross(&u).norm()))
            .unwrap_or_else(Vector3::x);
        (e - u * u.dot(&e)).normalize()
    };
    [b1, u.cross(&b1)]
}

/// A stop's bodies (its reaction's), joint angle index and joint.
#[derive(Clone, Copy, Debug)]
struct StopK {
    child: usize,
    parent: usize,
    q_index: usize,
    joint: usize,
}

/// Reaction `i`'s bodies, force column and constraint-moment columns, its
/// point, directions and torque zero.
fn reaction_layout(mech: &TreeMechanism, i: usize) -> Reaction<Space3> {
    let re = &mech.reactions[i];
    let m1 = (mech.reaction_moment(i, 0), [0.0; 3]);
    Reaction {
        child: re.child,
        parent: re.parent,
        point: [0.0; 3],
        force_col: mech.reaction_force(i, 0),
        torque: [0.0; 3],
        moments: if re.compound {
            [m1, (0, [0.0; 3])]
        } else {
            [m1, (mech.reaction_moment(i, 1), [0.0; 3])]
        },
        n_moments: re.moments(),
    }
}

/// Stage "kinematics at k": every body's constants and the constraint
/// directions of this step, given `q[k]` (and `q[k−1]`) already set.
pub fn prepare_step(mech: &TreeMechanism, data: &mut TreeFbdData, history: History<'_>, dt: f64) {
    data.dt = dt;
    data.l_next_fresh.fill(false);
    data.slip_bias = STOP_SPEED * dt;
    let carried = data.l_carry_valid;
    data.l_carry_valid = false;
    data.position_gain = mech.total_mass() / (dt * dt);
    let l = mech.length_scale();
    data.limit_gain = data.position_gain * l * l;
    for (b, body) in mech.bodies.iter().enumerate() {
        let mb = body.model_body;
        let com_k = data.kin.com[mb];
        data.body[b] = match history {
            History::Previous => BodyStep3 {
                c_next: 1.0,
                b: (-2.0 * com_k + data.kin_prev.com[mb]).into(),
                ang: if carried && data.l_carry_dt == dt {
                    data.l_carry[b]
                } else {
                    half_momentum_value(
                        &data.kin_prev.rotation[mb],
                        &data.kin.rotation[mb],
                        &body.inertia,
                        dt,
                    )
                }
                .into(),
                com_k: com_k.into(),
            },
            History::Initial { qdot } => {
                let v = data.kin.com_jacobian(mb).apply(qdot);
                let w = data.kin.angular_jacobian(mb).apply(qdot);
                BodyStep3 {
                    c_next: 2.0,
                    b: (-2.0 * com_k - 2.0 * dt * v).into(),
                    ang: (2.0 * momentum(mech, &data.kin, b, &w)).into(),
                    com_k: com_k.into(),
                }
            }
        };
    }
    for (i, re) in mech.reactions.iter().enumerate() {
        let [d1, d2] = moment_directions(mech, &data.kin, i);
        data.moment_dir[i] = [d1, d2];
        let r = &mut data.reaction_k[i];
        r.point = data.kin.joint_origin[re.joints[0]].into();
        r.moments[0].1 = d1.into();
        if !re.compound {
            r.moments[1].1 = d2.into();
        }
    }
}

/// Evaluates the kinematics at a candidate `q[k+1]` into `kin_next` (after
/// the solve), so that [`advance`] can accept it.
pub fn evaluate_next(mech: &TreeMechanism, data: &mut TreeFbdData, q_next: &[f64]) {
    if data.kin_next_q != q_next {
        data.kin_next.eval(&mech.model, q_next);
        data.kin_next_q.copy_from_slice(q_next);
        data.l_next_fresh.fill(false);
    }
    data.next_is_candidate = true;
}

/// Accepts the candidate of [`evaluate_next`]: `q[k]` becomes the previous
/// configuration, `q[k+1]` the current one.
///
/// # Panics
/// If [`evaluate_next`] was not called since the last [`eval`].
pub fn advance(data: &mut TreeFbdData) {
    assert!(
        data.next_is_candidate,
        "advance needs evaluate_next at the accepted configuration"
    );
    std::mem::swap(&mut data.kin_prev, &mut data.kin);
    std::mem::swap(&mut data.kin, &mut data.kin_next);
    data.kin_next_q.fill(f64::NAN);
    data.l_next_fresh.fill(false);
    data.next_is_candidate = false;
}

/// `L[k+½]` of FBD body `b` ([`crate::spatial::half_momentum_and_rotation`])
/// and the rotation `ψ[k+½]` it is made of, over this step at the
/// evaluated `q[k+1]` (after [`evaluate_next`]), when the last evaluation
/// of the residual computed them there; `None` otherwise. Bit for bit the
/// values [`crate::spatial::half_momentum_and_rotation`] gives.
#[inline]
pub fn step_momentum(data: &TreeFbdData, b: usize) -> Option<(Vector3<f64>, Vector3<f64>)> {
    data.l_next_fresh[b].then(|| (data.l_next[b], data.psi_next[b]))
}

/// The sparsity key: contact state codes in base 4 (one code for a
/// complementarity point in contact), then one bit per stop.
pub fn pattern_key(data: &TreeFbdData) -> u64 {
    rows::pattern_key(
        data.contact.iter().map(|c| {
            let code = c.state.code();
            (!(c.complementarity && code != fbd_contact::StateCode::St1)).then_some(code)
        }),
        data.limit.iter().map(|l| l.state.is_at()),
    )
}

/// Pushes every structural `(row, col)` of the Jacobian for the current
/// states.
pub fn pattern(mech: &TreeMechanism, data: &TreeFbdData, entries: &mut Vec<(usize, usize)>) {
    assembly::pattern(mech, &Surface::default(), data, entries);
}

/// Residual `r(z)` and, through `jac`, the analytic Jacobian
/// ([`crate::assembly::eval`]).
pub fn eval<S: JacobianSink>(
    mech: &TreeMechanism,
    surface: &Surface,
    data: &mut TreeFbdData,
    z: &[f64],
    r: &mut [f64],
    jac: &mut S,
) {
    assembly::eval(mech, surface, data, z, r, jac);
}

/// Calls `f` for every column of `cols`, from one loop: one call site,
/// so that `f` (the assembly's entries) is inlined into it.
#[inline]
fn columns(cols: Columns<'_>, mut f: impl FnMut(usize, &[f64; 3])) {
    for (i, v) in cols.iter() {
        f(i, &[v.x, v.y, v.z]);
    }
}

/// Any robot's part of the assembly.
impl FbdModel for TreeMechanism {
    type S = Space3;
    type Data = TreeFbdData;
    type Ground = Surface;
    const IMPLICIT_SLIP: bool = true;

    fn dims(&self) -> Dims {
        TreeMechanism::dims(self)
    }

    #[inline]
    fn gravity(&self) -> f64 {
        self.gravity
    }

    #[inline]
    fn mass(&self, b: usize) -> f64 {
        self.bodies[b].mass
    }

    #[inline]
    fn rotation_projection(&self, _: usize) -> f64 {
        1.0
    }

    #[inline]
    fn gains(&self, data: &TreeFbdData) -> (f64, f64, f64) {
        (data.dt, data.position_gain, data.limit_gain)
    }

    fn kinematics_next(&self, data: &mut TreeFbdData, q: &[f64], _: bool) {
        if data.kin_next_q[..] != q[..] {
            data.kin_next.eval(&self.model, q);
            data.kin_next_q.copy_from_slice(q);
            data.l_next_fresh.fill(false);
        }
        data.next_is_candidate = false;
    }

    #[inline]
    fn body_step<'a>(&self, data: &'a TreeFbdData, b: usize) -> &'a BodyStep3 {
        &data.body[b]
    }

    #[inline]
    fn wrenches<'a>(&self, data: &'a mut TreeFbdData) -> &'a mut [Wrench<Space3>] {
        &mut data.wrench
    }

    #[inline]
    fn com_next(&self, data: &TreeFbdData, b: usize) -> [f64; 3] {
        data.kin_next.com[self.bodies[b].model_body].into()
    }

    /// `(c·L[k+½] − L[k−½])/Δt` ([`crate::spatial::half_momentum`]); with `jacobian`, its
    /// derivative for [`FbdModel::rotation_entries`].
    #[inline]
    fn angular_rate(&self, data: &mut TreeFbdData, b: usize, jacobian: bool) -> [f64; 3] {
        let bs = data.body[b];
        let body = &self.bodies[b];
        let mb = body.model_body;
        let (dt, inertia) = (data.dt, &body.inertia);
        let (r_k, r_next) = (&data.kin.rotation[mb], &data.kin_next.rotation[mb]);
        let (l_next, psi) = if jacobian {
            let (l, d, psi) = half_momentum_derivative_and_rotation(r_k, r_next, inertia, dt);
            data.rot_d[b] = d * (bs.c_next / dt);
            (l, psi)
        } else {
            half_momentum_and_rotation(r_k, r_next, inertia, dt)
        };
        data.l_next[b] = l_next;
        data.psi_next[b] = psi;
        data.l_next_fresh[b] = true;
        ((bs.c_next * l_next - Vector3::from(bs.ang)) / dt).into()
    }

    #[inline]
    fn reactions(&self) -> usize {
        self.reactions.len()
    }

    /// Reaction `i` at k: the force at its first joint's origin, its
    /// constraint moments ([`TreeFbdData::moment_dir`]), both kept by
    /// [`prepare_step`], and the actuator torques `Σ τ_j·u_j` of its joints
    /// (the torques as they are now).
    #[inline]
    fn reaction(&self, data: &TreeFbdData, i: usize) -> Reaction<Space3> {
        let mut torque = Vector3::zeros();
        for &j in self.reactions[i].joint_list() {
            torque += data.torque[j] * data.kin.axis[j];
        }
        Reaction {
            torque: torque.into(),
            ..data.reaction_k[i]
        }
    }

    #[inline]
    fn contact<'a>(&self, data: &'a TreeFbdData, c: usize) -> ContactView<'a, Space3> {
        let eq = &data.contact[c];
        ContactView {
            body: self.contacts[c].body,
            frame: eq.frame,
            state: match &eq.state {
                SpatialState::Free => RowState::Free,
                SpatialState::Stick { anchor } if eq.complementarity => RowState::Contact {
                    anchor: Some(anchor),
                    mu: eq.mu_static,
                    frozen: eq.frozen,
                },
                SpatialState::Slide { .. } if eq.complementarity => RowState::Contact {
                    anchor: None,
                    mu: eq.mu_dynamic,
                    frozen: eq.frozen,
                },
                SpatialState::Stick { anchor } => RowState::Stick(anchor),
                SpatialState::Slide { dir } => RowState::Slide(dir),
            },
            mu_dynamic: eq.mu_dynamic,
            regularization: eq.regularization,
        }
    }

    #[inline]
    fn contact_point(&self, data: &TreeFbdData, c: usize, at: At) -> [f64; 3] {
        let kin = match at {
            At::Now => &data.kin,
            At::Next => &data.kin_next,
        };
        kin.contact[self.contacts[c].model_contact].into()
    }

    #[inline]
    fn stop<'a>(&self, data: &'a TreeFbdData, l: usize) -> StopView<'a, Space3> {
        let stop = &data.stop_k[l];
        StopView {
            child: stop.child,
            parent: stop.parent,
            axis: data.kin.axis[stop.joint].into(),
            q_index: stop.q_index,
            equation: &data.limit[l],
        }
    }

    /// The step's own slip ([`slip_direction`]), or the reference direction
    /// of a slide that keeps it ([`TreeFbdData::fixed_direction`]).
    fn slide_direction(
        &self,
        data: &mut TreeFbdData,
        c: usize,
        p: &[f64; 3],
        dir: &[f64],
        normal: f64,
    ) -> [f64; 2] {
        let d = Vector3::from(*p) - data.kin.contact[self.contacts[c].model_contact];
        let [t1, _, t2] = data.contact[c].frame;
        let s = [
            d.x * t1[0] + d.y * t1[1] + d.z * t1[2],
            d.x * t2[0] + d.y * t2[1] + d.z * t2[2],
        ];
        let dir = [dir[0], dir[1]];
        let (u, len) = if data.fixed_direction[c] {
            (dir, f64::INFINITY)
        } else {
            slip_direction(s, dir, data.slip_bias)
        };
        data.slip_hat[c] = u;
        data.slip_len[c] = len;
        data.slip_n[c] = normal;
        u
    }

    #[inline]
    fn slip(&self, data: &TreeFbdData, c: usize) -> Slip {
        Slip {
            dir: data.slip_hat[c],
            len: data.slip_len[c],
            normal: data.slip_n[c],
            bias: data.slip_bias,
        }
    }

    #[inline]
    fn set_branch(&self, data: &mut TreeFbdData, c: usize, branch: rows::Branch) {
        if branch.sliding {
            data.slip_hat[c] = [-branch.dir[0], -branch.dir[1]];
        }
        data.branch[c] = branch;
    }

    #[inline]
    fn branch(&self, data: &TreeFbdData, c: usize) -> rows::Branch {
        data.branch[c]
    }

    #[inline]
    fn set_limit_unloaded(&self, data: &mut TreeFbdData, l: usize, unloaded: bool) {
        data.limit_unloaded[l] = unloaded;
    }

    #[inline]
    fn limit_unloaded(&self, data: &TreeFbdData, l: usize) -> bool {
        data.limit_unloaded[l]
    }

    #[inline]
    fn clearance(&self, surface: &Surface, p: &[f64; 3]) -> f64 {
        clearance(surface, *p)
    }

    #[inline]
    fn slope(&self, surface: &Surface, p: &[f64; 3]) -> [f64; 2] {
        surface.gradient(p[0], p[2])
    }

    #[inline]
    fn com_columns(&self, data: &TreeFbdData, b: usize, f: impl FnMut(usize, &[f64; 3])) {
        columns(data.kin_next.com_jacobian(self.bodies[b].model_body), f);
    }

    #[inline]
    fn contact_columns(&self, data: &TreeFbdData, c: usize, f: impl FnMut(usize, &[f64; 3])) {
        columns(
            data.kin_next
                .contact_jacobian(self.contacts[c].model_contact),
            f,
        );
    }

    /// `∂(c·L[k+½]/Δt)/∂q_i = D·ω_i`, `ω_i` the body's angular Jacobian
    /// column.
    fn rotation_entries<J: JacobianSink>(
        &self,
        data: &TreeFbdData,
        b: usize,
        row: usize,
        jac: &mut J,
    ) {
        let d = &data.rot_d[b];
        data.kin_next
            .angular_jacobian(self.bodies[b].model_body)
            .for_each(|i, w| {
                let col = d * w;
                for a in 0..3 {
                    jac.add(row + a, i, col[a]);
                }
            });
    }
}

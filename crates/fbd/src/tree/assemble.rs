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
//! [`prepare_step`], [`pattern_key`], [`evaluate_next`], [`advance`]; the
//! residual and its pattern are every model's ([`crate::assembly::eval`],
//! [`crate::assembly::pattern`]).

use super::kin::{Columns, TreeKin, same_bits};
use super::mechanism::TreeMechanism;
use crate::assemble::{History, JacobianSink};
use crate::assembly::{
    At, ContactView, Dims, FbdModel, Reaction, RowState, Slip, StepTerms, StopView,
};
use crate::rows;
use crate::space::Space3;
use crate::spatial::equations::{
    BodyStep3, STOP_SPEED, SpatialContactEquation, half_momentum_and_rotation,
    half_momentum_derivative_and_rotation, half_momentum_value, slip_direction,
};
use fbd_contact::spatial::clearance;
use fbd_contact::{SpatialState, Surface};
use fbd_kinematics::nalgebra::{Matrix3, Vector3};

/// Mutable workspace of a [`TreeMechanism`]'s assembly (allocated once);
/// it dereferences to what every model's step holds alike ([`StepTerms`]:
/// the kinematics at `q[k−1]`, `q[k]` and the iterate of `q[k+1]`, the
/// contact equations, each body's constants, the stops' equations, the
/// torques, `Δt` and the gains).
#[derive(Clone, Debug)]
pub struct TreeFbdData {
    /// What every model's step holds.
    pub terms: StepTerms<Space3, TreeKin, SpatialContactEquation>,
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
    /// The coordinates of `kin` and of `kin_next` and the step length, bit
    /// for bit, that the bodies marked in `l_kept` had their `l_next` and
    /// `psi_next` computed at (valid when `l_key_valid`): at a rest, where
    /// neither configuration changes from step to step, the momenta are
    /// taken from there ([`keep_momenta`]).
    l_key: Vec<f64>,
    l_key_valid: bool,
    l_kept: Vec<bool>,
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
}

crate::assembly::step_terms!(TreeFbdData, Space3, TreeKin, SpatialContactEquation);

impl TreeFbdData {
    /// A workspace for `mech`.
    pub fn new(mech: &TreeMechanism) -> Self {
        let (nb, nc, nl) = (mech.bodies.len(), mech.contacts.len(), mech.limits.len());
        Self {
            terms: StepTerms::new(
                TreeKin::new(&mech.model),
                mech.nq(),
                (mech.bodies.iter().map(|b| b.mass).collect(), mech.gravity),
                nc,
                nl,
                mech.model.joints.len(),
            ),
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
            l_key: vec![0.0; 2 * mech.nq() + 1],
            l_key_valid: false,
            l_kept: vec![false; nb],
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
    data.terms
        .set_dt(dt, mech.total_mass(), mech.length_scale());
    data.l_next_fresh.fill(false);
    data.slip_bias = STOP_SPEED * dt;
    let carried = data.l_carry_valid;
    data.l_carry_valid = false;
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
        let point = data.kin.joint_origin[re.joints[0]].into();
        let r = &mut data.reaction_k[i];
        r.point = point;
        r.moments[0].1 = d1.into();
        if !re.compound {
            r.moments[1].1 = d2.into();
        }
    }
}

/// Evaluates the kinematics at a candidate `q[k+1]` into `kin_next` (after
/// the solve), so that [`advance`] can accept it.
pub fn evaluate_next(mech: &TreeMechanism, data: &mut TreeFbdData, q_next: &[f64]) {
    if data
        .terms
        .evaluate_candidate(q_next, |kin, q| kin.eval(&mech.model, q))
    {
        data.l_next_fresh.fill(false);
    }
}

/// Accepts the candidate of [`evaluate_next`]: `q[k]` becomes the previous
/// configuration, `q[k+1]` the current one.
///
/// # Panics
/// If [`evaluate_next`] was not called since the last [`eval`].
pub fn advance(data: &mut TreeFbdData) {
    data.terms.accept_candidate();
    data.l_next_fresh.fill(false);
}

/// Keeps the bodies' `l_next` and `psi_next` (`l_kept`) while `kin`,
/// `kin_next` and the step length are those they were computed for, bit
/// for bit; forgets them otherwise. `L[k+½]` is a function of the two
/// rotations and `Δt` alone: a robot at rest, predicted at its last
/// configuration, evaluates the same pair every step.
fn keep_momenta(data: &mut TreeFbdData) {
    let (Some(now), Some(next)) = (
        data.terms.kin.evaluated_at(),
        data.terms.kin_next.evaluated_at(),
    ) else {
        data.l_key_valid = false;
        data.l_kept.fill(false);
        return;
    };
    let nq = now.len();
    let dt = data.terms.dt;
    let (key_now, rest) = data.l_key.split_at_mut(nq);
    let (key_next, key_dt) = rest.split_at_mut(nq);
    if data.l_key_valid
        && same_bits(key_now, now)
        && same_bits(key_next, next)
        && same_bits(key_dt, &[dt])
    {
        return;
    }
    key_now.copy_from_slice(now);
    key_next.copy_from_slice(next);
    key_dt[0] = dt;
    data.l_key_valid = true;
    data.l_kept.fill(false);
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
    type Kin = TreeKin;
    type Contact = SpatialContactEquation;
    type Ground = Surface;
    const IMPLICIT_SLIP: bool = true;

    fn dims(&self) -> Dims {
        TreeMechanism::dims(self)
    }

    #[inline]
    fn rotation_projection(&self, _: usize) -> f64 {
        1.0
    }

    fn kinematics_next(&self, data: &mut TreeFbdData, q: &[f64], _: bool) {
        if !data.next_at(q) {
            data.kin_next.eval(&self.model, q);
            data.l_next_fresh.fill(false);
        }
        data.terms.set_iterate(q);
        keep_momenta(data);
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
            // The same values as `half_momentum_and_rotation`, bit for bit.
            let (l, d, psi) = half_momentum_derivative_and_rotation(r_k, r_next, inertia, dt);
            data.rot_d[b] = d * (bs.c_next / dt);
            (l, psi)
        } else if data.l_kept[b] {
            (data.l_next[b], data.psi_next[b])
        } else {
            half_momentum_and_rotation(r_k, r_next, inertia, dt)
        };
        data.l_next[b] = l_next;
        data.psi_next[b] = psi;
        data.l_next_fresh[b] = true;
        data.l_kept[b] = true;
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
        data.kin_at(at).contact[self.contacts[c].model_contact].into()
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

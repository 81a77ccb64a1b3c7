//! One FBD assembly for the plane and for space: the residual of a step and
//! its analytic Jacobian, written once over [`Space`] and a model
//! ([`FbdModel`]) that supplies its geometry.
//!
//! The stages of an evaluation at an iterate `z = [q[k+1] | reactions |
//! contact forces | stop moments]`:
//!
//! 1. **kinematics** at `q[k+1]` ([`FbdModel::kinematics_next`]);
//! 2. **loads**: every body isolated, the sum of what acts on it at `k`
//!    ([`Wrench`]): gravity; every joint reaction ([`Reaction`]: force
//!    `F` at the joint point, constraint moments and actuator torques),
//!    `+` on its child and `−` on its parent; every contact force at its
//!    point; every stop moment, `+axis·λ` on the child and `−axis·λ` on the
//!    parent;
//! 3. **body rows**: `m·(c·x(q[k+1]) + b)/Δt² − ΣF` (linear) and
//!    `P·(D_ang − ΣM)` (rotation, [`FbdModel::angular_rate`]; `P` the
//!    body's row projection, the planar versor);
//! 4. **contact rows** and **stop rows** ([`crate::rows`]);
//! 5. the **Jacobian**: the force columns (constant within a step) and the
//!    `q[k+1]` columns, entry by entry through a [`JacobianSink`]; the same
//!    code declares the sparsity pattern ([`pattern`]), so the two cannot
//!    drift apart.
//!
//! The planar model ([`crate::Mechanism`], [`crate::assemble`]) and the
//! spatial hexapod ([`crate::spatial`]) implement [`FbdModel`]; what stays
//! theirs is only what differs in kind: their kinematics, the rotation
//! rows' discrete angular momentum (the plane: the central difference of
//! the angle; space: the Lie-group form on rotation matrices) and, in 3D,
//! the implicit slip direction of a sliding point.

use crate::assemble::{JacobianSink, LimitEquation};
use crate::body::{BodyStep, Wrench};
use crate::rows::{self, NORMAL};
use crate::space::Space;

/// Counts of one step's unknowns and equations, and where each block sits.
///
/// Unknowns: `[q[k+1] (nq) | joint reactions (reaction_unknowns) | contact
/// forces (LIN per point) | stop moments (1 per limit)]`; equations:
/// `[LIN + ANG per body | LIN per contact point | 1 per limit]`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Dims {
    /// Generalised coordinates.
    pub nq: usize,
    /// Unknowns of the joint reactions (forces and constraint moments).
    pub reaction_unknowns: usize,
    /// Bodies.
    pub bodies: usize,
    /// Contact points.
    pub contacts: usize,
    /// Joint limits.
    pub limits: usize,
    /// Linear components per force (2 or 3).
    pub lin: usize,
    /// Rotational components per moment (1 or 3).
    pub ang: usize,
}

impl Dims {
    /// Unknowns = equations.
    pub fn dim(&self) -> usize {
        self.nq + self.reaction_unknowns + self.lin * self.contacts + self.limits
    }
    /// First row of body `b` (`lin` linear rows, then `ang` rotation rows).
    pub fn body_row(&self, b: usize) -> usize {
        (self.lin + self.ang) * b
    }
    /// First row of contact `c`'s `lin` rows.
    pub fn contact_row(&self, c: usize) -> usize {
        (self.lin + self.ang) * self.bodies + self.lin * c
    }
    /// Row of limit `l`.
    pub fn limit_row(&self, l: usize) -> usize {
        self.contact_row(self.contacts) + l
    }
    /// First column of the joint reactions.
    pub fn reaction(&self) -> usize {
        self.nq
    }
    /// Column of contact `c`'s force component `m` (contact frame, the
    /// normal second).
    pub fn contact_force(&self, c: usize, m: usize) -> usize {
        self.nq + self.reaction_unknowns + self.lin * c + m
    }
    /// Column of limit `l`'s stop moment.
    pub fn limit_moment(&self, l: usize) -> usize {
        self.contact_force(self.contacts, 0) + l
    }
}

/// What a step's equations hold, alike for every model: the kinematics at
/// `q[k−1]`, `q[k]` and the iterate of `q[k+1]` (the model's kind `K`),
/// each contact point's equations (the model's kind `C`), each body's
/// constants of the step, each stop's equation, the joint torques, `Δt`
/// and the gains of the position rows, and each body's wrench at the last
/// evaluation. A model's workspace holds them and dereferences to them
/// ([`FbdModel::Data`]).
#[derive(Clone, Debug)]
pub struct StepTerms<S: Space, K, C> {
    /// Kinematics at `q[k−1]`.
    pub kin_prev: K,
    /// Kinematics at `q[k]`.
    pub kin: K,
    /// Kinematics at the current iterate of `q[k+1]`.
    pub kin_next: K,
    /// Per contact point, its equations in this step.
    pub contact: Vec<C>,
    /// Per body, the constants of this step.
    pub body: Vec<BodyStep<S>>,
    /// Per body, its mass (kg): the model's, copied here once.
    pub mass: Vec<f64>,
    /// Gravity (m/s², along −y): the model's.
    pub gravity: f64,
    /// Per stop (the model's order of its limits), its equation.
    pub limit: Vec<LimitEquation>,
    /// Actuator torque of every joint at k (N·m), positive towards larger
    /// joint angles.
    pub torque: Vec<f64>,
    /// Time step (s).
    pub dt: f64,
    /// Scale of contact position rows, `K = M/Δt²` (N/m; `M` the total
    /// mass).
    pub position_gain: f64,
    /// Scale of stop rows, `Kθ = K·ℓ²` (N·m/rad; `ℓ` the model's length
    /// scale).
    pub limit_gain: f64,
    /// Per body, the sum of applied forces and moments (about its centre
    /// of mass) at k of the last evaluation (N, N·m).
    pub wrench: Vec<Wrench<S>>,
    /// The `q[k+1]` `kin_next` was last evaluated at (NaN: none since the
    /// last accepted step).
    next_q: Vec<f64>,
    /// `kin_next` holds a candidate set by [`Self::evaluate_candidate`]
    /// (and no iterate since).
    next_is_candidate: bool,
}

impl<S: Space, K: Clone, C: Clone + Default> StepTerms<S, K, C> {
    /// Terms at the kinematics `kin` for `nq` coordinates, bodies of
    /// masses `mass` under `gravity`, `contacts` contact points, `limits`
    /// stops and `joints` joints.
    pub fn new(
        kin: K,
        nq: usize,
        (mass, gravity): (Vec<f64>, f64),
        contacts: usize,
        limits: usize,
        joints: usize,
    ) -> Self {
        let bodies = mass.len();
        Self {
            kin_prev: kin.clone(),
            kin_next: kin.clone(),
            kin,
            contact: vec![C::default(); contacts],
            body: vec![BodyStep::default(); bodies],
            mass,
            gravity,
            limit: vec![LimitEquation::default(); limits],
            torque: vec![0.0; joints],
            dt: 0.0,
            position_gain: 0.0,
            limit_gain: 0.0,
            wrench: vec![Wrench::default(); bodies],
            next_q: vec![f64::NAN; nq],
            next_is_candidate: false,
        }
    }
}

impl<S: Space, K, C> StepTerms<S, K, C> {
    /// A step of `dt` for a model of total mass `mass` and length scale
    /// `length`: `K = M/Δt²`, `Kθ = K·ℓ²`.
    pub fn set_dt(&mut self, dt: f64, mass: f64, length: f64) {
        self.dt = dt;
        self.position_gain = mass / (dt * dt);
        self.limit_gain = self.position_gain * length * length;
    }

    /// The kinematics at `q[k]` or at the iterate of `q[k+1]`.
    #[inline]
    pub fn kin_at(&self, at: At) -> &K {
        match at {
            At::Now => &self.kin,
            At::Next => &self.kin_next,
        }
    }

    /// Whether `kin_next` holds the kinematics at `q`.
    #[inline]
    pub fn next_at(&self, q: &[f64]) -> bool {
        self.next_q[..] == q[..]
    }

    /// `kin_next` now holds the kinematics at the iterate `q` (not a
    /// candidate).
    #[inline]
    pub fn set_iterate(&mut self, q: &[f64]) {
        self.next_q.copy_from_slice(q);
        self.next_is_candidate = false;
    }

    /// Makes the kinematics at a candidate `q[k+1]` (after the solve) the
    /// candidate that [`Self::accept_candidate`] accepts, evaluating them
    /// with `eval` unless `kin_next` holds them already (the solver's last
    /// evaluation is usually at its solution); `true` when it evaluated.
    pub fn evaluate_candidate(&mut self, q: &[f64], eval: impl FnOnce(&mut K, &[f64])) -> bool {
        let fresh = !self.next_at(q);
        if fresh {
            eval(&mut self.kin_next, q);
            self.next_q.copy_from_slice(q);
        }
        self.next_is_candidate = true;
        fresh
    }

    /// Accepts the candidate: `q[k]` becomes the previous configuration and
    /// `q[k+1]` the current one (its kinematics reused).
    ///
    /// # Panics
    /// If [`Self::evaluate_candidate`] was not called since the last
    /// iterate.
    pub fn accept_candidate(&mut self) {
        assert!(
            self.next_is_candidate,
            "advance needs evaluate_next at the accepted configuration"
        );
        std::mem::swap(&mut self.kin_prev, &mut self.kin);
        std::mem::swap(&mut self.kin, &mut self.kin_next);
        // `kin_next` now holds what `kin_prev` held.
        self.next_q.fill(f64::NAN);
        self.next_is_candidate = false;
    }
}

/// `Deref` and `DerefMut` of a model's workspace `$data` (with a field
/// `terms`) to its [`StepTerms`] in `$space` with kinematics `$kin` and
/// contact equations `$contact`.
macro_rules! step_terms {
    ($data:ty, $space:ty, $kin:ty, $contact:ty) => {
        impl std::ops::Deref for $data {
            type Target = $crate::assembly::StepTerms<$space, $kin, $contact>;
            fn deref(&self) -> &Self::Target {
                &self.terms
            }
        }
        impl std::ops::DerefMut for $data {
            fn deref_mut(&mut self) -> &mut Self::Target {
                &mut self.terms
            }
        }
    };
}
pub(crate) use step_terms;

/// What one joint exerts on its child body at step `k` (the opposite acts
/// on its parent).
#[derive(Clone, Copy, Debug)]
pub struct Reaction<S: Space> {
    /// The body the joint's force acts on with `+`.
    pub child: usize,
    /// The body it acts on with `−`.
    pub parent: usize,
    /// The joint point at `k` (m).
    pub point: S::Lin,
    /// First of the `LIN` columns of the force (inertial components, N).
    pub force_col: usize,
    /// The actuator moment on the child, known at `k` (N·m).
    pub torque: S::Ang,
    /// Constraint moments: `(column, unit direction)`, the first
    /// [`Self::n_moments`] in use (none in the plane; one at a hip of two
    /// axes, two at a knee in space).
    pub moments: [(usize, S::Ang); 2],
    /// Constraint moments in use.
    pub n_moments: usize,
}

/// The state of a contact point's rows in a step.
#[derive(Clone, Copy, Debug)]
pub enum RowState<'a> {
    /// ST1: no contact.
    Free,
    /// ST2: held at its anchor (inertial, `LIN` components).
    Stick(&'a [f64]),
    /// ST3: on the surface, sliding along the reference direction given by
    /// its tangential components (the plane: ±1).
    Slide(&'a [f64]),
    /// In contact, stick or slip and lift-off solved in the step
    /// ([`rows::complementarity_rows`], 3D): the friction coefficient `μ`
    /// and, for a sticking point, its anchor (inertial; the gap is measured
    /// along the frame's normal from it); `None` for a sliding point,
    /// referred to its own position at `k` (the gap is its clearance).
    Contact {
        /// The anchor of a point that sticks at the start of the search.
        anchor: Option<&'a [f64]>,
        /// μS with an anchor, μD without.
        mu: f64,
        /// Branches fixed for this solve (`None`: chosen by the iterate).
        frozen: Option<rows::Frozen>,
    },
}

/// A contact point's equations in a step.
#[derive(Clone, Copy, Debug)]
pub struct ContactView<'a, S: Space> {
    /// The body the point belongs to.
    pub body: usize,
    /// The contact frame the force unknowns are expressed in.
    pub frame: S::Frame,
    /// ST1 / ST2 / ST3.
    pub state: RowState<'a>,
    /// Dynamic friction coefficient μD (ST3).
    pub mu_dynamic: f64,
    /// Regularisation β of the position rows.
    pub regularization: f64,
}

/// A joint limit's stop in a step.
#[derive(Clone, Copy, Debug)]
pub struct StopView<'a, S: Space> {
    /// The joint's child body (the stop moment acts `+axis·λ` on it).
    pub child: usize,
    /// The joint's parent body (`−axis·λ`).
    pub parent: usize,
    /// The joint axis at `k`.
    pub axis: S::Ang,
    /// The joint angle's index in `q`.
    pub q_index: usize,
    /// Free or at an end.
    pub equation: &'a LimitEquation,
}

/// A sliding point's friction direction at the last evaluated iterate
/// (models with [`FbdModel::IMPLICIT_SLIP`]).
#[derive(Clone, Copy, Debug)]
pub struct Slip {
    /// Unit direction `ŝ` in the tangential components.
    pub dir: [f64; 2],
    /// `max(|w|, ε)` (m), infinite for a fixed direction.
    pub len: f64,
    /// The normal force `N` at the iterate (N).
    pub normal: f64,
    /// `ε` (m): below it the direction is regularised (linear in `w`).
    pub bias: f64,
}

/// Which configuration a point is taken at.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum At {
    /// `q[k]`: forces, arms and versors.
    Now,
    /// The iterate of `q[k+1]`: positions of the position rows.
    Next,
}

/// A mechanism the assembly can evaluate: its geometry at `k` and at the
/// iterate, read from its workspace `Data`.
pub trait FbdModel {
    /// The plane or space.
    type S: Space;
    /// The mutable workspace of the assembly: the model's own, holding the
    /// terms every model's equations hold alike ([`StepTerms`]).
    type Data: std::ops::DerefMut<Target = StepTerms<Self::S, Self::Kin, Self::Contact>>;
    /// The kinematics of a configuration.
    type Kin: 'static;
    /// A contact point's equations in a step.
    type Contact: 'static;
    /// The terrain.
    type Ground: ?Sized;
    /// Whether a sliding point's friction direction is the step's own slip,
    /// an implicit function of `q[k+1]` (space), rather than fixed for the
    /// step (the plane, where a slip has one direction: ±).
    const IMPLICIT_SLIP: bool;

    /// The layout of unknowns and equations.
    fn dims(&self) -> Dims;
    /// The sign/projection `P` of body `b`'s rotation rows (the planar
    /// versor, ±1; 1 in space).
    fn rotation_projection(&self, b: usize) -> f64;
    /// `Δt` (s), `K = M/Δt²` and `Kθ = K·ℓ²` of this step.
    #[inline]
    fn gains(&self, data: &Self::Data) -> (f64, f64, f64) {
        (data.dt, data.position_gain, data.limit_gain)
    }

    /// Stage 1: the kinematics at the iterate `q` (and its Jacobians when
    /// `jacobians`).
    fn kinematics_next(&self, data: &mut Self::Data, q: &[f64], jacobians: bool);
    /// Body `b`'s constants of this step.
    #[inline]
    fn body_step<'a>(&self, data: &'a Self::Data, b: usize) -> &'a BodyStep<Self::S> {
        &data.body[b]
    }
    /// The wrench accumulators, one per body.
    #[inline]
    fn wrenches<'a>(&self, data: &'a mut Self::Data) -> &'a mut [Wrench<Self::S>] {
        &mut data.wrench
    }
    /// Body `b`'s centre of mass at the iterate.
    fn com_next(&self, data: &Self::Data, b: usize) -> <Self::S as Space>::Lin;
    /// The discrete rate of change of body `b`'s angular momentum about
    /// its centre of mass over the step, at the iterate (N·m); with
    /// `jacobian`, also what [`Self::rotation_entries`] needs.
    fn angular_rate(
        &self,
        data: &mut Self::Data,
        b: usize,
        jacobian: bool,
    ) -> <Self::S as Space>::Ang;

    /// Joint reactions.
    fn reactions(&self) -> usize;
    /// Reaction `i` at `k`, actuator torques given the step's torques.
    fn reaction(&self, data: &Self::Data, i: usize) -> Reaction<Self::S>;
    /// Contact point `c`'s equations.
    fn contact<'a>(&self, data: &'a Self::Data, c: usize) -> ContactView<'a, Self::S>;
    /// Contact point `c`'s position at `k` or at the iterate.
    fn contact_point(&self, data: &Self::Data, c: usize, at: At) -> <Self::S as Space>::Lin;
    /// Limit `l`'s stop.
    fn stop<'a>(&self, data: &'a Self::Data, l: usize) -> StopView<'a, Self::S>;

    /// The friction direction of sliding point `c` (tangential components)
    /// at the iterate, `p` its position there, `dir` the slide's reference
    /// direction and `normal` the normal force at the iterate; a model with
    /// [`Self::IMPLICIT_SLIP`] keeps what [`Self::slip`] returns.
    fn slide_direction(
        &self,
        data: &mut Self::Data,
        c: usize,
        p: &<Self::S as Space>::Lin,
        dir: &[f64],
        normal: f64,
    ) -> [f64; 2];
    /// The slip kept by the last [`Self::slide_direction`] of point `c`.
    fn slip(&self, data: &Self::Data, c: usize) -> Slip;
    /// Keeps the branch of complementarity point `c` at the iterate
    /// ([`RowState::Contact`]; models without them ignore it).
    fn set_branch(&self, _data: &mut Self::Data, _c: usize, _branch: rows::Branch) {}
    /// Keeps whether complementarity stop `l` is unloaded at the iterate
    /// ([`rows::limit_row`]; models without them ignore it).
    fn set_limit_unloaded(&self, _data: &mut Self::Data, _l: usize, _unloaded: bool) {}
    /// What [`Self::set_limit_unloaded`] kept.
    fn limit_unloaded(&self, _data: &Self::Data, _l: usize) -> bool {
        false
    }
    /// The branch kept by [`Self::set_branch`].
    fn branch(&self, _data: &Self::Data, _c: usize) -> rows::Branch {
        rows::Branch::default()
    }
    /// The clearance `y − ϱ(x[, z])` of a point.
    fn clearance(&self, ground: &Self::Ground, p: &<Self::S as Space>::Lin) -> f64;
    /// The terrain's slope `(∂ϱ/∂x, ∂ϱ/∂z)` under a point.
    fn slope(&self, ground: &Self::Ground, p: &<Self::S as Space>::Lin) -> [f64; 2];

    /// Visits the columns `(i, ∂c_b/∂q_i)` of body `b`'s centre of mass at
    /// the iterate.
    fn com_columns(
        &self,
        data: &Self::Data,
        b: usize,
        f: impl FnMut(usize, &<Self::S as Space>::Lin),
    );
    /// Visits the columns `(i, ∂p/∂q_i)` of contact point `c` at the
    /// iterate.
    fn contact_columns(
        &self,
        data: &Self::Data,
        c: usize,
        f: impl FnMut(usize, &<Self::S as Space>::Lin),
    );
    /// The `q[k+1]` entries of body `b`'s rotation rows, from `row`.
    fn rotation_entries<J: JacobianSink>(
        &self,
        data: &Self::Data,
        b: usize,
        row: usize,
        jac: &mut J,
    );
}

/// The contact force in the inertial frame from its frame components.
#[inline]
fn frame_force<S: Space>(frame: &S::Frame, fl: &[f64]) -> S::Lin {
    let frame = frame.as_ref();
    let mut f = S::Lin::default();
    for (i, fi) in f.as_mut().iter_mut().enumerate() {
        let mut s = fl[0] * frame[0].as_ref()[i];
        for m in 1..S::LIN {
            s += fl[m] * frame[m].as_ref()[i];
        }
        *fi = s;
    }
    f
}

#[inline]
fn arm<S: Space>(p: &S::Lin, c: &S::Lin) -> S::Lin {
    let mut r = S::Lin::default();
    for (i, ri) in r.as_mut().iter_mut().enumerate() {
        *ri = p.as_ref()[i] - c.as_ref()[i];
    }
    r
}

/// `w += sgn·F` at arm `r`, plus the moment `m`: `M += sgn·(r × F + m)`.
#[inline]
fn apply<S: Space>(w: &mut Wrench<S>, sgn: f64, r: &S::Lin, f: &S::Lin, m: &S::Ang) {
    for i in 0..S::LIN {
        w.force.as_mut()[i] += sgn * f.as_ref()[i];
    }
    let rf = S::cross(r, f);
    for i in 0..S::ANG {
        w.moment.as_mut()[i] += sgn * (rf.as_ref()[i] + m.as_ref()[i]);
    }
}

/// Residual `r(z)` and, through `jac`, the analytic Jacobian.
pub fn eval<M: FbdModel, J: JacobianSink>(
    model: &M,
    ground: &M::Ground,
    data: &mut M::Data,
    z: &[f64],
    r: &mut [f64],
    jac: &mut J,
) {
    let dims = model.dims();
    assert_eq!(z.len(), dims.dim(), "unknown vector has the wrong length");
    assert_eq!(r.len(), dims.dim(), "residual vector has the wrong length");
    model.kinematics_next(data, &z[..dims.nq], J::ACTIVE);
    loads(model, &dims, data, z);
    body_rows(model, &dims, data, r, J::ACTIVE);
    contact_rows(model, &dims, ground, data, z, r);
    let limit_gain = model.gains(data).2;
    let lambdas = &z[dims.limit_moment(0)..][..dims.limits];
    let limit_rows = &mut r[dims.limit_row(0)..][..dims.limits];
    for (l, (&lambda, row)) in lambdas.iter().zip(limit_rows).enumerate() {
        let stop = model.stop(data, l);
        let (v, unloaded) = rows::limit_row(stop.equation, lambda, z[stop.q_index], limit_gain);
        *row = v;
        model.set_limit_unloaded(data, l, unloaded);
    }
    if J::ACTIVE {
        force_entries(model, &dims, data, jac);
        position_entries(model, &dims, ground, data, jac);
    }
}

/// Pushes every structural `(row, col)` of the Jacobian for the current
/// contact and limit states (`ground`: any terrain; it changes values,
/// not structure).
pub fn pattern<M: FbdModel>(
    model: &M,
    ground: &M::Ground,
    data: &M::Data,
    entries: &mut Vec<(usize, usize)>,
) {
    struct PatternSink<'a>(&'a mut Vec<(usize, usize)>);
    impl JacobianSink for PatternSink<'_> {
        const ACTIVE: bool = true;
        #[inline]
        fn add(&mut self, row: usize, col: usize, _: f64) {
            self.0.push((row, col));
        }
    }
    let dims = model.dims();
    let mut sink = PatternSink(entries);
    force_entries(model, &dims, data, &mut sink);
    position_entries(model, &dims, ground, data, &mut sink);
}

/// Stage 2: every body's wrench at `k`.
fn loads<M: FbdModel>(model: &M, dims: &Dims, data: &mut M::Data, z: &[f64]) {
    let gravity = data.gravity;
    for b in 0..dims.bodies {
        let mass = data.mass[b];
        let w = &mut model.wrenches(data)[b];
        *w = Wrench::default();
        w.force.as_mut()[1] = -mass * gravity;
    }
    for i in 0..model.reactions() {
        let re = model.reaction(data, i);
        let mut f = <M::S as Space>::Lin::default();
        f.as_mut()
            .copy_from_slice(&z[re.force_col..re.force_col + M::S::LIN]);
        let mut m = re.torque;
        // Both slots, the unused one skipped: no slice of a length known
        // only at run time, so that the reaction can stay in registers.
        for (k, &(col, dir)) in re.moments.iter().enumerate() {
            if k < re.n_moments {
                for (mi, di) in m.as_mut().iter_mut().zip(dir.as_ref()) {
                    *mi += z[col] * di;
                }
            }
        }
        for (b, sgn) in [(re.child, 1.0), (re.parent, -1.0)] {
            let r = arm::<M::S>(&re.point, &model.body_step(data, b).com_k);
            apply(&mut model.wrenches(data)[b], sgn, &r, &f, &m);
        }
    }
    // A free contact point's force and a free stop's moment are exact
    // zeros (singleton rows, `fbd_solver`): their contributions (±0)
    // would leave every sum as it is — an accumulator that starts at +0
    // never becomes −0, and adding ±0 to any other value returns it — so
    // they are skipped, with the same bits.
    for c in 0..dims.contacts {
        let col = dims.contact_force(c, 0);
        if z[col..col + M::S::LIN].iter().all(|&v| v == 0.0) {
            continue;
        }
        let view = model.contact(data, c);
        let f = frame_force::<M::S>(&view.frame, &z[col..col + M::S::LIN]);
        let body = view.body;
        let r = arm::<M::S>(
            &model.contact_point(data, c, At::Now),
            &model.body_step(data, body).com_k,
        );
        // No moment of its own: adding 0 leaves every sum as it was (an
        // accumulator that starts at +0 is never −0).
        let none = <M::S as Space>::Ang::default();
        apply(&mut model.wrenches(data)[body], 1.0, &r, &f, &none);
    }
    for l in 0..dims.limits {
        let lambda = z[dims.limit_moment(l)];
        if lambda == 0.0 {
            continue;
        }
        let stop = model.stop(data, l);
        let (child, parent, axis) = (stop.child, stop.parent, stop.axis);
        let w = model.wrenches(data);
        for i in 0..M::S::ANG {
            let m = lambda * axis.as_ref()[i];
            w[child].moment.as_mut()[i] += m;
            w[parent].moment.as_mut()[i] -= m;
        }
    }
}

/// Stage 3: every body's `LIN + ANG` Newton–Euler rows.
fn body_rows<M: FbdModel>(
    model: &M,
    dims: &Dims,
    data: &mut M::Data,
    r: &mut [f64],
    jacobian: bool,
) {
    let dt = model.gains(data).0;
    let inv_dt2 = 1.0 / (dt * dt);
    for b in 0..dims.bodies {
        let rate = model.angular_rate(data, b, jacobian);
        let x = model.com_next(data, b);
        let bs = *model.body_step(data, b);
        let mass = data.mass[b];
        let row = dims.body_row(b);
        let w = model.wrenches(data)[b];
        let (lin, ang) = r[row..row + M::S::LIN + M::S::ANG].split_at_mut(M::S::LIN);
        for (i, ri) in lin.iter_mut().enumerate() {
            *ri = mass * bs.acceleration(i, x.as_ref()[i], inv_dt2) - w.force.as_ref()[i];
        }
        let p = model.rotation_projection(b);
        for (i, ri) in ang.iter_mut().enumerate() {
            *ri = p * (rate.as_ref()[i] - w.moment.as_ref()[i]);
        }
    }
}

/// Stage 4: the contact rows ([`crate::rows`]).
fn contact_rows<M: FbdModel>(
    model: &M,
    dims: &Dims,
    ground: &M::Ground,
    data: &mut M::Data,
    z: &[f64],
    r: &mut [f64],
) {
    let k = model.gains(data).1;
    for c in 0..dims.contacts {
        let row = dims.contact_row(c);
        let col = dims.contact_force(c, 0);
        let fl = &z[col..col + M::S::LIN];
        let p = model.contact_point(data, c, At::Next);
        let view = model.contact(data, c);
        let out = &mut r[row..row + M::S::LIN];
        match view.state {
            RowState::Free => rows::free_rows(fl, out),
            RowState::Stick(anchor) => {
                let f = frame_force::<M::S>(&view.frame, fl);
                rows::stick_rows(k, p.as_ref(), anchor, view.regularization, f.as_ref(), out);
            }
            RowState::Slide(dir) => {
                let (mu, beta) = (view.mu_dynamic, view.regularization);
                let mut reference = [0.0; 2];
                reference[..dir.len()].copy_from_slice(dir);
                let u = model.slide_direction(data, c, &p, &reference[..dir.len()], fl[NORMAL]);
                let clearance = model.clearance(ground, &p);
                rows::slide_rows(fl, &u[..M::S::LIN - 1], mu, k, clearance, beta, out);
            }
            RowState::Contact { anchor, mu, frozen } => {
                let (t, gap) = contact_offsets::<M>(model, ground, data, c, &view, &p, anchor);
                let t = [k * t[0], k * t[1]];
                let beta = view.regularization;
                let branch = rows::complementarity_rows(fl, t, gap, mu, k, beta, frozen, out);
                model.set_branch(data, c, branch);
            }
        }
    }
}

/// A complementarity point's tangential offsets `(p[k+1] − r)·t_j` from
/// its reference `r` (the anchor, or the point at `k`) and its normal gap:
/// `(p[k+1] − a)·n` from an anchor, the clearance otherwise (m).
fn contact_offsets<M: FbdModel>(
    model: &M,
    ground: &M::Ground,
    data: &M::Data,
    c: usize,
    view: &ContactView<'_, M::S>,
    p: &<M::S as Space>::Lin,
    anchor: Option<&[f64]>,
) -> ([f64; 2], f64) {
    let frame = view.frame;
    let frame = frame.as_ref();
    let p = p.as_ref();
    let now = model.contact_point(data, c, At::Now);
    let reference = anchor.unwrap_or(now.as_ref());
    let mut t = [0.0; 2];
    let mut gap = 0.0;
    let mut j = 0;
    for (m, e) in frame.iter().enumerate() {
        let e = e.as_ref();
        let mut d = 0.0;
        for a in 0..M::S::LIN {
            d += (p[a] - reference[a]) * e[a];
        }
        if m == NORMAL {
            gap = d;
        } else if j < 2 {
            t[j] = d;
            j += 1;
        }
    }
    if anchor.is_none() {
        gap = model.clearance(ground, &{
            let mut q = <M::S as Space>::Lin::default();
            q.as_mut().copy_from_slice(p);
            q
        });
    }
    (t, gap)
}

/// A complementarity point's entries in its force column `m`
/// ([`rows::complementarity_rows`]): every structural entry of either
/// branch is written (zero where the branch has none), so that the
/// sparsity pattern does not depend on the branch.
fn contact_force_entries<J: JacobianSink>(
    jac: &mut J,
    crow: usize,
    col: usize,
    m: usize,
    beta: f64,
    b: rows::Branch,
) {
    // Tangential rows in the order of the frame, skipping the normal.
    const T: [usize; 2] = [0, 2];
    if m == NORMAL {
        jac.add(crow + NORMAL, col, if b.unloaded { 1.0 } else { beta });
        for (j, &t) in T.iter().enumerate() {
            let v = if b.sliding { -b.drho * b.dir[j] } else { 0.0 };
            jac.add(crow + t, col, v);
        }
        return;
    }
    let l = usize::from(m != 0);
    jac.add(crow + NORMAL, col, 0.0);
    for (j, &t) in T.iter().enumerate() {
        let delta = if j == l { 1.0 } else { 0.0 };
        let v = if b.sliding {
            delta - b.ratio * (delta - b.dir[j] * b.dir[l]) * (1.0 - beta)
        } else {
            beta * delta
        };
        jac.add(crow + t, col, v);
    }
}

/// Entries in the force columns (they do not depend on the iterate).
fn force_entries<M: FbdModel, J: JacobianSink>(
    model: &M,
    dims: &Dims,
    data: &M::Data,
    jac: &mut J,
) {
    let (lin, ang) = (M::S::LIN, M::S::ANG);
    for i in 0..model.reactions() {
        let re = model.reaction(data, i);
        for (b, sgn) in [(re.child, 1.0), (re.parent, -1.0)] {
            let row = dims.body_row(b);
            let r = arm::<M::S>(&re.point, &model.body_step(data, b).com_k);
            let scale = model.rotation_projection(b) * sgn;
            for a in 0..lin {
                jac.add(row + a, re.force_col + a, -sgn);
            }
            M::S::moment_arm_entries(jac, row + lin, re.force_col, &r, scale);
            for (k, &(col, dir)) in re.moments.iter().enumerate() {
                if k < re.n_moments {
                    for a in 0..ang {
                        jac.add(row + lin + a, col, -scale * dir.as_ref()[a]);
                    }
                }
            }
        }
    }
    for c in 0..dims.contacts {
        let view = model.contact(data, c);
        let r = arm::<M::S>(
            &model.contact_point(data, c, At::Now),
            &model.body_step(data, view.body).com_k,
        );
        let p = model.rotation_projection(view.body);
        let row = dims.body_row(view.body);
        let crow = dims.contact_row(c);
        let (beta, mu) = (view.regularization, view.mu_dynamic);
        let u = match view.state {
            RowState::Slide(_) => model.slip(data, c).dir,
            _ => [0.0; 2],
        };
        for (m, ev) in view.frame.as_ref().iter().enumerate() {
            let e = ev.as_ref();
            let col = dims.contact_force(c, m);
            let me = M::S::cross(&r, ev);
            for (a, ea) in e.iter().enumerate() {
                jac.add(row + a, col, -ea);
            }
            for a in 0..ang {
                jac.add(row + lin + a, col, -p * me.as_ref()[a]);
            }
            match view.state {
                RowState::Free => jac.add(crow + m, col, 1.0),
                RowState::Stick(_) => {
                    for (a, ea) in e.iter().enumerate() {
                        jac.add(crow + a, col, beta * ea);
                    }
                }
                RowState::Slide(_) if m == NORMAL => {
                    // Ft_i + u_j·μD·N: the tangential rows' N entries.
                    let mut j = 0;
                    for a in 0..lin {
                        if a == NORMAL {
                            jac.add(crow + a, col, beta);
                        } else {
                            jac.add(crow + a, col, u[j] * mu);
                            j += 1;
                        }
                    }
                }
                RowState::Slide(_) => jac.add(crow + m, col, 1.0),
                RowState::Contact { .. } => {
                    contact_force_entries(jac, crow, col, m, beta, model.branch(data, c));
                }
            }
        }
    }
    for l in 0..dims.limits {
        let stop = model.stop(data, l);
        let col = dims.limit_moment(l);
        let (pc, pp) = (
            model.rotation_projection(stop.child),
            model.rotation_projection(stop.parent),
        );
        for a in 0..ang {
            let axis = stop.axis.as_ref()[a];
            jac.add(dims.body_row(stop.child) + lin + a, col, -pc * axis);
            jac.add(dims.body_row(stop.parent) + lin + a, col, pp * axis);
        }
        jac.add(
            dims.limit_row(l),
            col,
            rows::limit_row_diagonal(stop.equation, model.limit_unloaded(data, l)),
        );
    }
}

/// Entries in the `q[k+1]` columns at the iterate: every body's second
/// difference, the contact position rows, the stops at an end.
fn position_entries<M: FbdModel, J: JacobianSink>(
    model: &M,
    dims: &Dims,
    ground: &M::Ground,
    data: &M::Data,
    jac: &mut J,
) {
    let lin = M::S::LIN;
    let (dt, k, limit_gain) = model.gains(data);
    let dt2 = dt * dt;
    for b in 0..dims.bodies {
        let row = dims.body_row(b);
        let g = data.mass[b] * model.body_step(data, b).c_next / dt2;
        model.com_columns(data, b, |i, v| {
            for a in 0..lin {
                jac.add(row + a, i, g * v.as_ref()[a]);
            }
        });
        model.rotation_entries(data, b, row + lin, jac);
    }
    for c in 0..dims.contacts {
        let row = dims.contact_row(c);
        let view = model.contact(data, c);
        match view.state {
            RowState::Free => {}
            RowState::Stick(_) => model.contact_columns(data, c, |i, v| {
                for a in 0..lin {
                    jac.add(row + a, i, k * v.as_ref()[a]);
                }
            }),
            RowState::Contact { anchor, .. } => {
                contact_position_entries(model, ground, data, c, row, k, anchor.is_some(), jac);
            }
            RowState::Slide(_) => {
                let p = model.contact_point(data, c, At::Next);
                let slope = model.slope(ground, &p);
                if M::IMPLICIT_SLIP {
                    // Friction rows: μ·N·∂ŝ/∂s·∂s/∂q, ∂ŝ/∂s = (I − ŝŝᵀ)/|w|
                    // (Coulomb) or I/ε (regularised, |w| < ε).
                    let frame = view.frame;
                    let frame = frame.as_ref();
                    let slip = model.slip(data, c);
                    let u = slip.dir;
                    let g = view.mu_dynamic * slip.normal / slip.len;
                    let p2 = if slip.len > slip.bias {
                        [
                            [1.0 - u[0] * u[0], -u[0] * u[1]],
                            [-u[1] * u[0], 1.0 - u[1] * u[1]],
                        ]
                    } else {
                        [[1.0, 0.0], [0.0, 1.0]]
                    };
                    // The tangential components (all but the normal).
                    let mut tangential = [0usize; 2];
                    for (j, a) in (0..lin).filter(|&a| a != NORMAL).enumerate() {
                        tangential[j] = a;
                    }
                    let nt = lin - 1;
                    model.contact_columns(data, c, |i, v| {
                        jac.add(row + NORMAL, i, k * M::S::clearance_rate(v, slope));
                        let v = v.as_ref();
                        let mut ds = [0.0; 2];
                        for (dj, &t) in ds.iter_mut().zip(&tangential[..nt]) {
                            let e = frame[t].as_ref();
                            let mut s = v[0] * e[0];
                            for a in 1..lin {
                                s += v[a] * e[a];
                            }
                            *dj = s;
                        }
                        for (j, &t) in tangential[..nt].iter().enumerate() {
                            let mut s = p2[j][0] * ds[0];
                            for l in 1..nt {
                                s += p2[j][l] * ds[l];
                            }
                            jac.add(row + t, i, g * s);
                        }
                    });
                } else {
                    model.contact_columns(data, c, |i, v| {
                        jac.add(row + NORMAL, i, k * M::S::clearance_rate(v, slope));
                    });
                }
            }
        }
    }
    for l in 0..dims.limits {
        let stop = model.stop(data, l);
        if stop.equation.state.is_at() {
            let unloaded = model.limit_unloaded(data, l);
            let v = rows::limit_row_angle(stop.equation, unloaded, limit_gain);
            jac.add(dims.limit_row(l), stop.q_index, v);
        }
    }
}

/// A complementarity point's entries in the `q[k+1]` columns
/// ([`rows::complementarity_rows`]; every structural entry of either
/// branch, as [`contact_force_entries`]).
#[allow(clippy::too_many_arguments)]
fn contact_position_entries<M: FbdModel, J: JacobianSink>(
    model: &M,
    ground: &M::Ground,
    data: &M::Data,
    c: usize,
    row: usize,
    k: f64,
    anchored: bool,
    jac: &mut J,
) {
    let view = model.contact(data, c);
    let frame = view.frame;
    let frame = frame.as_ref();
    let b = model.branch(data, c);
    let p = model.contact_point(data, c, At::Next);
    let slope = model.slope(ground, &p);
    let lin = M::S::LIN;
    model.contact_columns(data, c, |i, v| {
        let mut d = [0.0; 3];
        for (m, e) in frame.iter().enumerate().take(3) {
            let e = e.as_ref();
            d[m] = v.as_ref().iter().zip(e).take(lin).map(|(x, y)| x * y).sum();
        }
        let normal = if b.unloaded {
            0.0
        } else if anchored {
            k * d[NORMAL]
        } else {
            k * M::S::clearance_rate(v, slope)
        };
        jac.add(row + NORMAL, i, normal);
        let dt = [d[0], d[2]];
        for (j, &t) in [0usize, 2].iter().enumerate() {
            let value = if b.sliding {
                b.ratio
                    * k
                    * ((1.0 - b.dir[j] * b.dir[j]) * dt[j] - b.dir[j] * b.dir[1 - j] * dt[1 - j])
            } else {
                k * dt[j]
            };
            jac.add(row + t, i, value);
        }
    });
}

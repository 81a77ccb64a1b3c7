//! The contact machinery of every model that stands on a 3D surface: the
//! paper's hexapod ([`crate::spatial::SpatialModel`]) and any imported
//! robot ([`crate::robot::RobotSim`]), both on the generic tree assembly
//! [`fbd_dynamics::tree`]. One source for both:
//!
//! * the step's Newton system ([`SurfaceSystem`]) and its rows for the
//!   trial states ([`prepare_rows`]: contact frames and friction of the
//!   ground under each point, regularisation, convergence scales);
//! * a point's view of a solution ([`trial_of`]) and the law it breaks
//!   ([`contact_violation`]);
//! * the rigid placement of anchors ([`anchor_at_distance`]);
//! * the complementarity switches, the active-set fallback and the
//!   refinement of fixed slide directions ([`complementarity_switches`],
//!   [`newton_fallback`], [`refine_directions`]);
//! * the slide directions carried to the next step ([`advance_states`]).
//!
//! What the models differ in — their controller and record — stays
//! theirs ([`SurfaceEngine`]).
//!
//! Two things only a 3D slide needs:
//!
//! * Newton may fail on the implicit friction direction (a slide about to
//!   stop or turning fast: the direction's derivative is `μD·N/|s|`).
//!   Then the slides' directions are fixed at their reference directions
//!   and solved, and each fixed direction is moved to the slip the
//!   solution found and solved again, until the two agree to 1e-10 rad
//!   ([`refine_directions`]: a fixed-point iteration that reaches the
//!   implicit law's solution); if Newton fails even so, the slowest
//!   sliding point sticks under `p[k]` and the search goes on
//!   ([`newton_fallback`]). A slide never keeps an earlier step's
//!   direction: every written ST3 row has `Ft = −μD·N·ŝ` with `ŝ` the
//!   step's own unit slip (the law audit of [`crate::engine::search`]
//!   checks it, and rejects a solution whose refinement did not converge);
//! * on acceptance a sliding point's reference direction becomes the
//!   step's slip direction ([`advance_states`]).

use super::{Engine, Law, RunData, worst};
use crate::rules::{Sink, regularization};
use fbd_contact::spatial::{
    STOP_SPEED, clearance, frame, point_at_distance, project, under_along_normal,
};
use fbd_contact::{ContactMode, ContactParams, ContactTrial, Friction, SpatialState, SpatialTrial};
use fbd_contact::{StateCode, Surface};
use fbd_dynamics::assembly::{self, At, FbdModel};
use fbd_dynamics::rows::{self, Branch, Frozen};
use fbd_dynamics::space::Space3;
use fbd_dynamics::spatial::SpatialContactEquation;
use fbd_dynamics::tree::TreeFbdData;
use fbd_dynamics::{LimitEquation, LimitState, NoJacobian};
use fbd_solver::{NewtonSolver, NewtonSystem};

/// The fields of a 3D assembly's workspace that the contact machinery
/// reads and sets, borrowed together ([`SearchFields::search`]).
pub struct Search<'a> {
    /// Each contact point's equation for the trial state.
    pub contact: &'a mut [SpatialContactEquation],
    /// Each joint stop's equation.
    pub limit: &'a mut [LimitEquation],
    /// Branches of the complementarity rows at the last iterate.
    pub branch: &'a [Branch],
    /// Branches held fixed by the active-set fallback.
    pub frozen: &'a mut [Option<Frozen>],
    /// The first branches the fallback fixed in this step.
    pub first_frozen: &'a mut [Option<Frozen>],
    /// Whether the fallback solved its branches again from the start.
    pub refrozen: &'a mut bool,
    /// Whether the step fell back to fixed states.
    pub fixed_states: &'a mut bool,
    /// Per point, whether its slide direction is fixed.
    pub fixed_direction: &'a mut [bool],
    /// Per point, whether its fixed direction was released once.
    pub released_direction: &'a mut [bool],
}

/// Access to a 3D assembly workspace's contact fields (the generic
/// [`TreeFbdData`] of every robot, the paper's hexapod included).
pub trait SearchFields {
    /// The contact fields, borrowed together.
    fn search(&mut self) -> Search<'_>;
    /// Each contact point's equation.
    fn contact_equations(&self) -> &[SpatialContactEquation];
    /// Each joint stop's equation.
    fn limit_equations(&self) -> &[LimitEquation];
    /// Whether the step fell back to fixed states.
    fn fixed_states(&self) -> bool;
    /// Branches of the complementarity rows at the last iterate.
    fn branches(&self) -> &[Branch];
    /// Per point, the unit slip of the last iterate.
    fn slip_hat(&self) -> &[[f64; 2]];
    /// Per point, the slip length of the last iterate.
    fn slip_len(&self) -> &[f64];
    /// Per stop, whether it carried no load at the last iterate.
    fn limit_unloaded(&self) -> &[bool];
    /// The (sub)step length (s).
    fn step_length(&self) -> f64;
    /// The position gain turning lengths into forces (N/m).
    fn position_gain(&self) -> f64;
    /// The stop rows' gain (N/rad at the length scale).
    fn limit_gain(&self) -> f64;
    /// Marks the bodies' momenta `L[k+½]` as the next step's `L[k−½]`.
    fn set_carry_valid(&mut self);
}

impl SearchFields for TreeFbdData {
    fn search(&mut self) -> Search<'_> {
        Search {
            contact: &mut self.terms.contact,
            limit: &mut self.terms.limit,
            branch: &self.branch,
            frozen: &mut self.frozen,
            first_frozen: &mut self.first_frozen,
            refrozen: &mut self.refrozen,
            fixed_states: &mut self.fixed_states,
            fixed_direction: &mut self.fixed_direction,
            released_direction: &mut self.released_direction,
        }
    }
    fn contact_equations(&self) -> &[SpatialContactEquation] {
        &self.contact
    }
    fn limit_equations(&self) -> &[LimitEquation] {
        &self.limit
    }
    fn fixed_states(&self) -> bool {
        self.fixed_states
    }
    fn branches(&self) -> &[Branch] {
        &self.branch
    }
    fn slip_hat(&self) -> &[[f64; 2]] {
        &self.slip_hat
    }
    fn slip_len(&self) -> &[f64] {
        &self.slip_len
    }
    fn limit_unloaded(&self) -> &[bool] {
        &self.limit_unloaded
    }
    fn step_length(&self) -> f64 {
        self.dt
    }
    fn position_gain(&self) -> f64 {
        self.position_gain
    }
    fn limit_gain(&self) -> f64 {
        self.limit_gain
    }
    fn set_carry_valid(&mut self) {
        self.l_carry_valid = true;
    }
}

/// A model on a 3D surface: what the shared contact machinery needs
/// beyond [`Engine`].
pub trait SurfaceEngine:
    Engine<State = SpatialState, Trial = SpatialTrial, Ground = Surface, Fbd: SearchFields>
{
    /// The FBD assembly.
    type Mech: FbdModel<S = Space3, Data = Self::Fbd, Ground = Surface>;
    /// The model's assembly.
    fn mech(&self) -> &Self::Mech;
    /// Whether the points in contact solve stick/slip and lift-off in the
    /// step as a complementarity problem (the default of both models).
    fn complementarity_rows(&self) -> bool;
    /// Regularisation added to point `c`'s position rows (bumpers).
    fn bumper(&self, c: usize) -> f64;
    /// Total mass (kg).
    fn total_mass(&self) -> f64;
    /// Gravity (m/s², along −Y).
    fn gravity(&self) -> f64;
}

/// `impl SurfaceEngine for $model` of a model on the generic tree
/// equations, which holds its mechanism in `mech`, its complementarity
/// choice in `complementarity` and its points' bumpers in
/// `contact_bumper`.
macro_rules! tree_surface_engine {
    ($model:ty) => {
        impl $crate::engine::surface::SurfaceEngine for $model {
            type Mech = fbd_dynamics::tree::TreeMechanism;
            fn mech(&self) -> &fbd_dynamics::tree::TreeMechanism {
                &self.mech
            }
            fn complementarity_rows(&self) -> bool {
                self.complementarity
            }
            fn bumper(&self, c: usize) -> f64 {
                self.contact_bumper[c]
            }
            fn total_mass(&self) -> f64 {
                self.mech.total_mass()
            }
            fn gravity(&self) -> f64 {
                self.mech.gravity
            }
        }
    };
}
pub(crate) use tree_surface_engine;

/// The [`Engine`] items every model on a surface shares, written once:
/// expanded inside `impl Engine for …` of a [`SurfaceEngine`] on the
/// generic tree equations (`fbd_dynamics::tree`: its state, trial, ground
/// and workspace types; the stages `prepare_step`, `evaluate_next`,
/// `set_configuration`, `set_previous`, `advance` of
/// `fbd_dynamics::tree::assemble`; the stop rows' unknowns; the one record
/// of every robot, [`super::tree_record::RobotRecord`], and the momenta
/// carried by a step without a record) whose model holds its mechanism in
/// `self.mech`.
macro_rules! surface_stages {
    () => {
        type State = fbd_contact::SpatialState;
        type Trial = fbd_contact::SpatialTrial;
        type Ground = fbd_contact::Surface;
        type Fbd = fbd_dynamics::tree::TreeFbdData;
        type Record = $crate::engine::tree_record::RobotRecord;

        fn limit_moment_index(&self, l: usize) -> usize {
            self.mech.dims().limit_moment(l)
        }
        fn skip_record(&self, data: &mut $crate::engine::RunData<Self>, h: f64) {
            $crate::engine::tree_record::carry_momenta(&self.mech, &mut data.fbd, h);
        }
        fn kinematics(
            &self,
            data: &mut $crate::engine::RunData<Self>,
            history: fbd_dynamics::History<'_>,
            h: f64,
        ) {
            use fbd_dynamics::tree::assemble as asm;
            asm::prepare_step(&self.mech, &mut data.fbd, history, h);
            $crate::engine::surface::reset_search(&mut data.fbd);
        }
        fn solve(
            &self,
            data: &mut $crate::engine::RunData<Self>,
        ) -> Result<fbd_solver::NewtonReport, fbd_solver::SolverError> {
            let (mut sys, solver, z) = $crate::engine::surface::system(self, data);
            solver.solve(&mut sys, z)
        }
        fn evaluate_next(&self, data: &mut $crate::engine::RunData<Self>) {
            use fbd_dynamics::tree::assemble as asm;
            let nq = $crate::engine::Engine::nq(self);
            asm::evaluate_next(&self.mech, &mut data.fbd, &data.z[..nq]);
        }
        fn trial(
            &self,
            data: &$crate::engine::RunData<Self>,
            c: usize,
        ) -> fbd_contact::SpatialTrial {
            $crate::engine::surface::trial_of(self, data, c)
        }
        fn contact_violation(
            &self,
            data: &$crate::engine::RunData<Self>,
            state: &fbd_contact::SpatialState,
            t: &fbd_contact::SpatialTrial,
        ) -> (f64, $crate::engine::Law) {
            $crate::engine::surface::contact_violation(self, data, state, t)
        }
        fn limit_gain(&self, data: &$crate::engine::RunData<Self>) -> f64 {
            data.fbd.limit_gain
        }
        fn length_scale(&self, _data: &$crate::engine::RunData<Self>) -> f64 {
            self.mech.length_scale()
        }
        fn anchor_at_distance(
            &self,
            data: &$crate::engine::RunData<Self>,
            reference: usize,
            from: [f64; 3],
            c: usize,
        ) -> [f64; 3] {
            $crate::engine::surface::anchor_at_distance(self, data, reference, from, c)
        }
        fn newton_fallback(&self, data: &mut $crate::engine::RunData<Self>) -> bool {
            $crate::engine::surface::newton_fallback(self, data)
        }
        fn complementarity_switches(&self, data: &mut $crate::engine::RunData<Self>) -> bool {
            $crate::engine::surface::switches(self, data)
        }
        fn refine_directions(&self, data: &mut $crate::engine::RunData<Self>) -> bool {
            $crate::engine::surface::refine_directions(self, data)
        }
        fn set_previous(&self, data: &mut $crate::engine::RunData<Self>) {
            use fbd_dynamics::tree::assemble as asm;
            asm::set_previous(&self.mech, &mut data.fbd, &data.q_prev);
        }
        fn reset_kinematics(&self, data: &mut $crate::engine::RunData<Self>) {
            use fbd_dynamics::tree::assemble as asm;
            asm::set_configuration(&self.mech, &mut data.fbd, &data.grid_q);
            asm::set_previous(&self.mech, &mut data.fbd, &data.grid_q_prev);
        }
        fn make_record(
            &self,
            data: &mut $crate::engine::RunData<Self>,
            iterations: usize,
            trials: usize,
            h: f64,
        ) {
            $crate::engine::tree_record::make_record(self, data, iterations, trials, h);
        }
        fn add_to_record(record: &mut Self::Record, iterations: usize, trials: usize) {
            record.newton_iterations += iterations;
            record.state_trials += trials;
        }
        fn advance(&self, data: &mut $crate::engine::RunData<Self>) {
            use fbd_dynamics::tree::assemble as asm;
            $crate::engine::surface::advance_states(data);
            asm::advance(&mut data.fbd);
        }
        fn accepted_whole(&self, data: &mut $crate::engine::RunData<Self>) {
            data.fbd.l_carry_valid = true;
        }
    };
}
pub(crate) use surface_stages;

/// The largest scaled residual at which a crawl's kept iterate counts as
/// near a solution for [`NewtonSystem::abandon_crawl`]: its positions are
/// then within about `1e-3 · W·Δt²/m` of the solution's (`W` the weight,
/// `m` the lightest body's mass: under 1 µm on the default hexapod at
/// Δt = 1 ms), well inside [`ABANDON_DEPTH`].
pub const ABANDON_RESIDUAL: f64 = 1e-3;

/// How far below the surface (m) a free point of a crawl's kept iterate
/// must be for its touchdown to be certain ([`NewtonSystem::abandon_crawl`]):
/// 10 µm, ten times the iterate's uncertainty at [`ABANDON_RESIDUAL`]
/// (a point that strikes the ground at 1 m/s is 1 mm below it at the end
/// of a 1 ms step solved without its contact).
pub const ABANDON_DEPTH: f64 = 1e-5;

/// One step's equations on a surface as a [`NewtonSystem`].
pub struct SurfaceSystem<'a, A: FbdModel<S = Space3, Ground = Surface>> {
    mech: &'a A,
    surface: &'a Surface,
    fbd: &'a mut A::Data,
    scales: &'a [f64],
    weights: &'a [f64],
}

impl<A> NewtonSystem for SurfaceSystem<'_, A>
where
    A: FbdModel<S = Space3, Ground = Surface>,
    A::Data: SearchFields,
{
    fn dim(&self) -> usize {
        self.mech.dims().dim()
    }
    fn pattern_key(&self) -> u64 {
        rows::pattern_key(
            self.fbd.contact_equations().iter().map(|c| {
                let code = c.state.code();
                (!(c.complementarity && code != StateCode::St1)).then_some(code)
            }),
            self.fbd.limit_equations().iter().map(|l| l.state.is_at()),
        )
    }
    fn pattern(&self, entries: &mut Vec<(usize, usize)>) {
        assembly::pattern(self.mech, &Surface::default(), self.fbd, entries);
    }
    fn eval(&mut self, x: &[f64], r: &mut [f64], jac: Option<&mut fbd_solver::JacobianSink<'_>>) {
        match jac {
            Some(j) => assembly::eval(self.mech, self.surface, self.fbd, x, r, &mut Sink(j)),
            None => assembly::eval(self.mech, self.surface, self.fbd, x, r, &mut NoJacobian),
        }
    }
    fn residual_scale(&self, row: usize) -> f64 {
        self.scales[row]
    }
    fn residual_weight(&self, row: usize) -> f64 {
        self.weights[row]
    }
    /// A crawl is given up when its kept iterate is near a solution (a
    /// scaled residual of at most [`ABANDON_RESIDUAL`]) and has a free
    /// point more than [`ABANDON_DEPTH`] below the surface: the state
    /// search touches it down whatever the rest of the solution (see
    /// [`crate::engine::search`], "Touchdowns during a crawl").
    fn abandon_crawl(&mut self, x: &[f64], residual: f64) -> bool {
        if residual > ABANDON_RESIDUAL {
            return false;
        }
        let nq = self.mech.dims().nq;
        self.mech.kinematics_next(self.fbd, &x[..nq], false);
        let contacts = self.fbd.contact_equations();
        (0..contacts.len()).any(|c| {
            contacts[c].state == SpatialState::Free
                && clearance(self.surface, self.mech.contact_point(self.fbd, c, At::Next))
                    < -ABANDON_DEPTH
        })
    }
}

/// Point `c`'s position at `q[k]` (`At::Now`) or at the last iterate.
#[inline]
fn point<M: SurfaceEngine>(model: &M, data: &RunData<M>, c: usize, at: At) -> [f64; 3] {
    model.mech().contact_point(&data.fbd, c, at)
}

/// Whether this solve's points in contact use complementarity rows: the
/// model's choice, unless both the semismooth and the active-set solves of
/// this step have failed, when the step falls back to fixed states
/// searched by the switching rules (the rows of [`fbd_dynamics::rows`]
/// with the implicit slip direction), audited like every other.
pub fn complementarity<M: SurfaceEngine>(model: &M, data: &RunData<M>) -> bool {
    model.complementarity_rows() && !data.fbd.fixed_states()
}

/// The regularisation β for a (sub)step of length `h` (as the planar one).
fn beta(contact: &ContactParams, h: f64) -> f64 {
    regularization(contact.regularization, h)
}

/// Stage 4's system for the current trial states: each point's equation
/// (the ground's frame and friction under it, the regularisation), each
/// stop's, and the rows' convergence scales.
pub fn system<'a, M: SurfaceEngine>(
    model: &'a M,
    data: &'a mut RunData<M>,
) -> (
    SurfaceSystem<'a, M::Mech>,
    &'a mut NewtonSolver,
    &'a mut [f64],
) {
    prepare_rows(model, data);
    let sys = SurfaceSystem {
        mech: model.mech(),
        surface: model.ground(),
        fbd: &mut data.fbd,
        scales: &data.scales,
        weights: &data.weights,
    };
    (sys, &mut data.solver, &mut data.z)
}

/// Newton's parameters of every model on a 3D surface (the paper's
/// hexapod and every imported robot).
pub fn newton_params() -> fbd_solver::NewtonParams {
    fbd_solver::NewtonParams {
        chord_steps: crate::DEFAULT_CHORD_STEPS,
        // The planar engine's tolerance. The angular momentum of a free
        // robot drifts by the residual's moments: 1.8e-9 relative over
        // 2000 steps at this tolerance, 1e-10 at a tolerance of 1e-10
        // (`tests/spatial_flight.rs`), which costs 30 % more iterations on
        // a walk.
        residual_tol: crate::DEFAULT_TOLERANCE,
        // The complementarity rows are semismooth: near a point that just
        // starts or stops sliding, or lands while it slides, Newton's
        // iterates cross branches and converge linearly for a while, and a
        // step may have to be cut far down before the residual's max-norm
        // decreases.
        max_iterations: 50,
        max_backtracks: 30,
        // Renewing a stale factorisation when the solves since it have
        // cost more than 24 chord steps a renewal (the compiled LU made a
        // refactorisation of the hexapod's ~150 unknowns cheap enough):
        // the `bench/peer` walk takes 5,707 Newton iterations instead of
        // 7,657 and 9.8 % fewer instructions a step (callgrind; 8, 12 and
        // 16 within 1 % of it, 32 and 48 −9.3 % and −6.8 %). Standing is
        // unchanged, the height map −0.8 %, and 120 of the 1000
        // landings (`--shard 0/25`, `1/25`, `2/25`) −1.3 % in all: −2.4 %,
        // +3.4 % and −3.7 %, the spread of their chaotic paths.
        refactor_cost: 24.0,
        // A crawl at a kink of the contact rows: up to 5 whole steps
        // across it (`NewtonParams::watchdog`). Over the 1000 landings of
        // `examples/sweep_hexapod_landing_1000.toml`: 807 retried steps
        // in 529 runs → 142 in 130, 27 % less stepping time, the slowest
        // landing 1,897 → 3,017 steps/s (the `quick` build, `--jobs 2`);
        // 3, 4, 8 or 10 whole steps, or crawls of 1 or 3 steps, within
        // a few % of it on the first 200 (`--shard 0/10`, `1/10`). The
        // walk, standing and the height map never crawl: their paths are
        // the same.
        watchdog: 5,
        ..fbd_solver::NewtonParams::default()
    }
}

/// The equations of the trial states and their scales ([`system`]).
pub fn prepare_rows<M: SurfaceEngine>(model: &M, data: &mut RunData<M>) {
    let surface = model.ground();
    let b = beta(model.contact_params(), data.fbd.step_length());
    let ncp = complementarity(model, data);
    for c in 0..model.contacts() {
        let state = data.trial[c];
        let (x, z) = match state {
            SpatialState::Stick { anchor } => (anchor[0], anchor[2]),
            _ => {
                let p = point(model, data, c, At::Now);
                (p[0], p[2])
            }
        };
        let friction = model.friction_at([x, z]);
        let bumper = model.bumper(c);
        let search = data.fbd.search();
        search.contact[c] = SpatialContactEquation {
            state,
            frame: frame(surface, x, z),
            mu_dynamic: friction.mu_dynamic,
            regularization: b + bumper,
            mu_static: friction.mu_static,
            complementarity: ncp,
            frozen: search.frozen[c],
        };
    }
    let search = data.fbd.search();
    for (eq, &state) in search.limit.iter_mut().zip(&data.limit_trial) {
        *eq = LimitEquation {
            state,
            regularization: b,
            complementarity: ncp,
        };
    }
    row_scales(model, data);
}

/// Convergence scales: forces to `1e-9 ×` the weight with a round-off
/// floor, moments times the length scale, positions to `1e-12 m`-ish (as
/// the planar model's).
fn row_scales<M: SurfaceEngine>(model: &M, data: &mut RunData<M>) {
    let lay = model.mech().dims();
    let k = data.fbd.position_gain();
    let extent = data.q[0].abs().max(data.q[1].abs()).max(data.q[2].abs());
    let force = model.total_mass() * model.gravity().abs().max(1.0) + 1e-6 * k * (1.0 + extent);
    let moment = force * model.length_scale(data);
    let position = 1e-3 * k * (1.0 + extent);
    let ncp = complementarity(model, data);
    // Each row's scale and its weight `1 / scale` (the scaled norm's, read
    // at every iterate): three divisions a solve, not one per row and
    // iterate.
    let [f, m, p] = [force, moment, position].map(|s| (s, 1.0 / s));
    let (scales, weights) = (&mut data.scales, &mut data.weights);
    let mut set = |row: usize, (s, w): (f64, f64)| {
        scales[row] = s;
        weights[row] = w;
    };
    for b in 0..lay.bodies {
        let row = lay.body_row(b);
        for a in 0..3 {
            set(row + a, f);
            set(row + 3 + a, m);
        }
    }
    for c in 0..lay.contacts {
        let row = lay.contact_row(c);
        let s = match data.trial[c] {
            SpatialState::Free => [f; 3],
            _ if ncp => [f; 3],
            SpatialState::Stick { .. } => [p; 3],
            SpatialState::Slide { .. } => [f, p, f],
        };
        for (a, v) in s.into_iter().enumerate() {
            set(row + a, v);
        }
    }
    for l in 0..lay.limits {
        set(lay.limit_row(l), m);
    }
}

/// The trial of contact `c` from the last solution.
pub fn trial_of<M: SurfaceEngine>(model: &M, data: &RunData<M>, c: usize) -> SpatialTrial {
    let lay = model.mech().dims();
    SpatialTrial {
        p_k: point(model, data, c, At::Now),
        p_next: point(model, data, c, At::Next),
        ft: [
            data.z[lay.contact_force(c, 0)],
            data.z[lay.contact_force(c, 2)],
        ],
        n: data.z[lay.contact_force(c, 1)],
        frame: data.fbd.contact_equations()[c].frame,
        dt: data.fbd.step_length(),
    }
}

/// The resolution of a slip (m): the solver converges positions to about
/// 1e-12 m (the stick rows' convergence scale), so the direction of a slip
/// `s` is known to `δ/|s|` rad and the sliding law's direction is audited
/// to `μD·N·δ/|s|` beyond the law tolerance: exact for every slip longer
/// than a few nanometres a step, unresolvable (and not a law) for slides
/// that have all but stopped.
pub const SLIP_RESOLUTION: f64 = 1e-12;

/// How far (m) a sticking point without load may be from its contact
/// point, along the surface, and still be written as sticking: a resting
/// point without load stays ST2 at its contact point; one that moved
/// further slides (ST3 with no force).
pub const UNLOADED_STICK_DRIFT: f64 = 1e-9;

/// A joint stop without load is released (→ free) only once its joint ends
/// a step this far inside its range (rad): until then its complementarity
/// row lets the joint leave and return to the end without events.
pub const LIMIT_RELEASE_ANGLE: f64 = 1e-4;

/// A fixed friction direction agrees with the slip when they differ by
/// less than this angle (rad): the force error `μD·N·angle` is then far
/// below the law tolerance for any load the robot carries.
const DIRECTION_TOL: f64 = 1e-10;

/// [`Engine::contact_violation`]: how far a point's trial is from the law
/// of `state` (N), and the law it breaks most.
pub fn contact_violation<M: SurfaceEngine>(
    model: &M,
    data: &RunData<M>,
    state: &SpatialState,
    t: &SpatialTrial,
) -> (f64, Law) {
    let k = data.fbd.position_gain();
    let friction = model.friction_at([t.p_k[0], t.p_k[2]]);
    let (mu_s, mu_d) = (friction.mu_static, friction.mu_dynamic);
    let pull = (-t.n).max(0.0);
    let ft = t.ft[0].hypot(t.ft[1]);
    match *state {
        SpatialState::Free => {
            let depth =
                -clearance(model.ground(), t.p_next) - model.contact_params().penetration_tol;
            (k * depth.max(0.0), Law::Penetration)
        }
        SpatialState::Stick { .. } => worst([
            (pull, Law::Pull),
            ((ft - mu_s * t.n).max(0.0), Law::StaticCone),
        ]),
        SpatialState::Slide { dir } => {
            // Coulomb's sliding law with the step's own slip s:
            // Ft = −μD·N·s/|s|, whatever the reference direction `dir`
            // (a slide may turn, even back). A slip slower than the stop
            // speed has no direction: its slide has stopped, and the
            // deficit of |Ft| below μD·N (regularised direction) and the
            // turn back are the violation.
            let s = t.slip();
            let len = s[0].hypot(s[1]);
            let mdn = mu_d * t.n;
            let backwards = if len > STOP_SPEED * t.dt {
                0.0
            } else {
                k * (-(s[0] * dir[0] + s[1] * dir[1])).max(0.0)
            };
            let law = if len > STOP_SPEED * t.dt {
                let e = [t.ft[0] + mdn * s[0] / len, t.ft[1] + mdn * s[1] / len];
                let along = (ft - mdn).abs();
                // The slip's direction is known to δ/|s| rad, δ the
                // solver's resolution of positions (SLIP_RESOLUTION).
                let resolution = mdn.abs() * SLIP_RESOLUTION / len;
                let off = (e[0].hypot(e[1]) - resolution).max(0.0);
                if off > along {
                    (off, Law::SlideDirection)
                } else {
                    (along, Law::SlideMagnitude)
                }
            } else {
                ((ft - mdn).abs(), Law::SlideMagnitude)
            };
            worst([(pull, Law::Pull), (backwards, Law::SlideBackwards), law])
        }
    }
}

/// [`Engine::anchor_at_distance`]: the anchor of point `c`, which starts
/// sticking on the body of `reference` anchored at `from`: the point of
/// the ground at the two points' distance, on `c`'s side of `reference`.
pub fn anchor_at_distance<M: SurfaceEngine>(
    model: &M,
    data: &RunData<M>,
    reference: usize,
    from: [f64; 3],
    c: usize,
) -> [f64; 3] {
    let (p, r) = (
        point(model, data, c, At::Now),
        point(model, data, reference, At::Now),
    );
    let d = [p[0] - r[0], p[1] - r[1], p[2] - r[2]];
    let horizontal = d[0].hypot(d[2]);
    if horizontal > 1e-12 {
        let len = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        point_at_distance(
            model.ground(),
            from,
            len,
            [d[0] / horizontal, d[2] / horizontal],
        )
    } else {
        project(model.ground(), from)
    }
}

/// [`Engine::newton_fallback`]: with complementarity rows, the active-set
/// fallback ([`freeze_branches`]), then the same branches from the step's
/// start, then fixed states; with fixed states, fixed slide directions,
/// then the slowest slide stopped.
pub fn newton_fallback<M: SurfaceEngine>(model: &M, data: &mut RunData<M>) -> bool {
    if complementarity(model, data) {
        if freeze_branches(data) {
            return true;
        }
        let search = data.fbd.search();
        if !*search.refrozen {
            // The same frozen branches again, from the step's start (the
            // predictor) rather than the failed iterate.
            *search.refrozen = true;
            search.frozen.copy_from_slice(search.first_frozen);
            data.start_z.copy_from_slice(&data.origin_z);
            return true;
        }
        // The last resort of the step: fixed states, searched.
        *search.fixed_states = true;
        return true;
    }
    fix_slides(data) || stop_slowest_slide(model, data)
}

/// [`Engine::complementarity_switches`] where the model uses
/// complementarity rows.
pub fn switches<M: SurfaceEngine>(model: &M, data: &mut RunData<M>) -> bool {
    complementarity(model, data) && complementarity_switches(model, data)
}

/// The states of the points in contact read from the branches their
/// complementarity rows took at the solution
/// ([`fbd_dynamics::rows::complementarity_rows`]):
///
/// * a sticking point whose friction projection is active needs more than
///   μS·N: it slides (ST2 → ST3, opposite to the force it carries), and
///   the step is solved again with μD — `true`;
/// * a sliding point inside its disc has stopped: its rows were the stick
///   rows about `p[k]`, so it sticks there (ST3 → ST2, anchored on the
///   surface under `p[k]` along the normal) with `|Ft| ≤ μD·N ≤ μS·N`;
/// * a point without load (`N = 0`) that ends the step above the surface
///   by more than the penetration tolerance has left it (→ ST1, `F = 0`);
///   one that still touches stays ST2 at its contact point, or slides
///   (ST3, no force) if it moved along the surface;
///   a joint stop without load whose joint ends the step inside its range
///   by more than the limits' angle tolerance is free.
///
/// The last two are read off the solution, which already satisfies their
/// laws. Each switch marks the state left as seen, so that the search's
/// rule "a point that tried sticking and had to slide again keeps sliding"
/// bounds the switches of one step.
fn complementarity_switches<M: SurfaceEngine>(model: &M, data: &mut RunData<M>) -> bool {
    if unfreeze_wrong_branches(model, data) {
        return true;
    }
    let lay = model.mech().dims();
    // A stop without load whose joint has left the end is free (its row
    // was `λ = 0`, the free row).
    for l in 0..data.limit_trial.len() {
        if let LimitState::At { side, angle } = data.limit_trial[l] {
            let q = data.z[model.limit(l).q_index];
            if data.fbd.limit_unloaded()[l] && side.sign() * (q - angle) > LIMIT_RELEASE_ANGLE {
                data.limit_trial[l] = LimitState::Free;
                data.z[lay.limit_moment(l)] = 0.0;
            }
        }
    }
    let surface = model.ground();
    let tol = model.contact_params().penetration_tol;
    let mut again = false;
    for c in 0..data.trial.len() {
        let state = data.trial[c];
        if state == SpatialState::Free {
            continue;
        }
        let b = data.fbd.branches()[c];
        let t = trial_of(model, data, c);
        data.seen[c] |= 1 << (state.code() as u8);
        if b.unloaded && clearance(surface, t.p_next) > tol {
            data.trial[c] = SpatialState::Free;
            // Its force is zero to the solver's tolerance: exactly zero in
            // the free state's row.
            for m in 0..3 {
                data.z[lay.contact_force(c, m)] = 0.0;
            }
            continue;
        }
        if b.unloaded {
            // Touching without load: a sticking point still at its contact
            // point stays ST2 (a resting point without load writes no
            // events); one that moved along the surface slides (ST3, its
            // friction μD·0 = 0).
            if let SpatialState::Stick { anchor } = state {
                let s = t.slip_from(anchor);
                let len = s[0].hypot(s[1]);
                if len > UNLOADED_STICK_DRIFT {
                    data.trial[c] = SpatialState::Slide {
                        dir: [s[0] / len, s[1] / len],
                    };
                }
            }
            continue;
        }
        match state {
            SpatialState::Stick { .. } if b.sliding => {
                data.trial[c] = SpatialState::slide_against(t.ft);
                // The next solve starts from this solution with the
                // point's friction on its new disc, |Ft| = μD·N (sticking
                // may have needed many times more).
                let mu_d = model.friction_at(t.location()).mu_dynamic;
                let len = t.ft[0].hypot(t.ft[1]);
                if len > 0.0 {
                    let scale = (mu_d * t.n.max(0.0) / len).min(1.0);
                    data.z[lay.contact_force(c, 0)] *= scale;
                    data.z[lay.contact_force(c, 2)] *= scale;
                }
                again = true;
            }
            SpatialState::Slide { .. } if !b.sliding => {
                data.trial[c] = SpatialState::Stick {
                    anchor: under_along_normal(surface, t.p_k),
                };
            }
            _ => {}
        }
    }
    again
}

/// The active-set fallback of a complementarity solve that Newton could
/// not converge (a solution on a branch's boundary — a point that just
/// stops or just starts to slide — where semismooth Newton converges only
/// linearly): every point in contact keeps the branches of the last
/// iterate for the next solves of this step, which are smooth, and starts
/// from that iterate; [`unfreeze_wrong_branches`] corrects a branch the
/// solution contradicts. `false` when they were fixed already (the
/// fallback then solves the same branches once more from the step's
/// start, the predictor, before it searches fixed states: of the 1000
/// landings of `examples/sweep_hexapod_landing_1000.toml`, 997 complete
/// with the failed iterate's start alone, 989 with the step's start alone,
/// all 1000 with both).
fn freeze_branches<M: SurfaceEngine>(data: &mut RunData<M>) -> bool {
    let mut any = false;
    let search = data.fbd.search();
    for c in 0..data.trial.len() {
        if data.trial[c] != SpatialState::Free && search.frozen[c].is_none() {
            let b = search.branch[c];
            search.frozen[c] = Some(Frozen {
                unloaded: b.unloaded,
                sliding: b.sliding,
            });
            any = true;
        }
    }
    if any {
        search.first_frozen.copy_from_slice(search.frozen);
    }
    if any && data.z.iter().all(|v| v.is_finite()) {
        data.start_z.copy_from_slice(&data.z);
    }
    any
}

/// After a solve with fixed branches: a branch the solution contradicts by
/// more than the cycle tolerance (a slide inside its disc, a stick outside
/// it, an unloaded point below the surface, a negative load) is switched
/// (`true`: solve again). Within the tolerance both branches hold.
fn unfreeze_wrong_branches<M: SurfaceEngine>(model: &M, data: &mut RunData<M>) -> bool {
    let tol = model.cycle_tolerance();
    let mut again = false;
    let search = data.fbd.search();
    for c in 0..data.trial.len() {
        let Some(f) = search.frozen[c] else {
            continue;
        };
        if data.trial[c] == SpatialState::Free {
            continue;
        }
        let b = search.branch[c];
        let mut g = f;
        if f.sliding && b.excess < -tol || !f.sliding && b.excess > tol {
            g.sliding = !f.sliding;
        }
        if f.unloaded && b.held < -tol || !f.unloaded && b.normal < -tol {
            g.unloaded = !f.unloaded;
        }
        if g != f {
            search.frozen[c] = Some(g);
            again = true;
        }
    }
    again
}

/// Fixes the friction direction of every sliding point of the trial at
/// its reference direction; `false` if there was none to fix. The fixed
/// direction is then moved to the solution's slip until the two agree
/// ([`refine_directions`]): no row keeps a direction that is not its own.
fn fix_slides<M: SurfaceEngine>(data: &mut RunData<M>) -> bool {
    let mut any = false;
    let search = data.fbd.search();
    for (c, state) in data.trial.iter().enumerate() {
        if matches!(state, SpatialState::Slide { .. }) && !search.fixed_direction[c] {
            search.fixed_direction[c] = true;
            any = true;
        }
    }
    any
}

/// [`Engine::refine_directions`]: every sliding point whose friction
/// direction is fixed and whose slip (faster than the stop speed, not
/// turned back by 90° or more — the state machine stops those) points
/// elsewhere takes the slip's direction; `true` if any did.
pub fn refine_directions<M: SurfaceEngine>(model: &M, data: &mut RunData<M>) -> bool {
    let mut any = false;
    for c in 0..data.trial.len() {
        let SpatialState::Slide { dir } = data.trial[c] else {
            continue;
        };
        if !data.fbd.search().fixed_direction[c] {
            continue;
        }
        let s = trial_of(model, data, c).slip();
        let len = s[0].hypot(s[1]);
        if len <= STOP_SPEED * data.fbd.step_length() || s[0] * dir[0] + s[1] * dir[1] <= 0.0 {
            continue;
        }
        let u = [s[0] / len, s[1] / len];
        let change = (u[0] - dir[0]).hypot(u[1] - dir[1]);
        if change > DIRECTION_TOL {
            data.trial[c] = SpatialState::Slide { dir: u };
            // Close to the slip: the implicit law again, from this
            // solution (Newton's quadratic convergence instead of the
            // fixed point's linear one), once a step: a failure fixes it
            // again for good.
            let search = data.fbd.search();
            if change < 0.1 && !search.released_direction[c] {
                search.fixed_direction[c] = false;
                search.released_direction[c] = true;
            }
            any = true;
        }
    }
    any
}

/// Sticks the sliding point of the trial whose slip at the last evaluated
/// iterate is the smallest; `false` without sliding points.
fn stop_slowest_slide<M: SurfaceEngine>(model: &M, data: &mut RunData<M>) -> bool {
    let slip = data.fbd.slip_len();
    let slowest = (0..data.trial.len())
        .filter(|&c| matches!(data.trial[c], SpatialState::Slide { .. }))
        .min_by(|&a, &b| slip[a].total_cmp(&slip[b]));
    let Some(c) = slowest else {
        return false;
    };
    let p = point(model, data, c, At::Now);
    data.trial[c] = SpatialState::Stick {
        anchor: project(model.ground(), p),
    };
    true
}

/// The start of [`Engine::kinematics`] on a surface: no slide direction
/// fixed or released, no branch frozen, complementarity rows again.
pub fn reset_search<F: SearchFields>(fbd: &mut F) {
    let search = fbd.search();
    search.fixed_direction.fill(false);
    search.released_direction.fill(false);
    search.frozen.fill(None);
    *search.fixed_states = false;
    *search.refrozen = false;
}

/// [`Engine::advance`]'s state part: a slide's reference direction
/// follows its slip.
pub fn advance_states<M: SurfaceEngine>(data: &mut RunData<M>) {
    let slip = data.fbd.slip_hat();
    for (c, state) in data.states.iter_mut().enumerate() {
        if let SpatialState::Slide { dir } = state {
            *dir = slip[c];
        }
    }
}

/// The Coulomb friction at `at = (x, z)` on `surface` (its friction
/// patches; `friction` elsewhere).
pub fn friction_on(surface: &Surface, friction: &Friction, at: [f64; 2]) -> Friction {
    surface.friction_at(friction, at[0], at[1])
}

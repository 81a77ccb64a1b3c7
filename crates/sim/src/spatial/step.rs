//! The spatial model's stages of the staged step: [`SpatialModel`] as an
//! [`Engine`] of the generic step ([`crate::engine`]: the stages, the
//! state search with its cycle fallbacks and the retry in substeps are the
//! planar model's, one source).
//!
//! What is spatial here: the kinematics of the 13 bodies and the
//! constraint directions ([`fbd_dynamics::spatial::prepare_step`]), the 3D
//! assembly as a Newton system (contact equations in the surface frame
//! `(t1, n, t2)`), a contact point's trial and violation, the rigid
//! placement of anchors on one body in 3D, the record with its momenta.
//! Two things only a 3D slide needs:
//!
//! * Newton may fail on the implicit friction direction (a slide about to
//!   stop or turning fast: the direction's derivative is `μD·N/|s|`).
//!   Then the slides' directions are fixed at their reference directions
//!   and solved, and each fixed direction is moved to the slip the
//!   solution found and solved again, until the two agree to 1e-10 rad
//!   ([`Engine::refine_directions`]: a fixed-point iteration that reaches
//!   the implicit law's solution); if Newton fails even so, the slowest
//!   sliding point sticks under `p[k]` and the search goes on
//!   ([`Engine::newton_fallback`]). A slide never keeps an earlier step's
//!   direction: every written ST3 row has `Ft = −μD·N·ŝ` with `ŝ` the
//!   step's own unit slip (the law audit of [`crate::engine::search`]
//!   checks it, and rejects a solution whose refinement did not converge);
//! * on acceptance a sliding point's reference direction becomes the
//!   step's slip direction.

use super::control::{joint_rates, joint_torques};
use super::data::SpatialData;
use super::model::SpatialModel;
use crate::SimError;
use crate::engine::{Engine, Law, LimitInfo, Settings, worst};
use crate::record::LimitCode;
use crate::rules::{Sink, regularization};
use fbd_contact::spatial::{
    STOP_SPEED, clearance, frame, point_at_distance, project, under_along_normal,
};
use fbd_contact::{ContactMode, ContactTrial};
use fbd_contact::{Friction, SpatialState, SpatialTrial, Surface};
use fbd_dynamics::rows::Frozen;
use fbd_dynamics::spatial::{
    SpatialContactEquation, SpatialFbdData, SpatialMechanism, advance, eval, evaluate_next,
    half_momentum_and_rotation, pattern, pattern_key, prepare_step, set_previous,
};
use fbd_dynamics::{History, LimitEquation, LimitState, NoJacobian};
use fbd_kinematics::nalgebra::Vector3;
use fbd_solver::{NewtonReport, NewtonSolver, NewtonSystem, SolverError};

/// One spatial step's equations as a [`NewtonSystem`].
pub struct SpatialSystem<'a> {
    mech: &'a SpatialMechanism,
    surface: &'a fbd_contact::Surface,
    fbd: &'a mut SpatialFbdData,
    scales: &'a [f64],
}

impl NewtonSystem for SpatialSystem<'_> {
    fn dim(&self) -> usize {
        self.mech.layout().dim()
    }
    fn pattern_key(&self) -> u64 {
        pattern_key(self.fbd)
    }
    fn pattern(&self, entries: &mut Vec<(usize, usize)>) {
        pattern(self.mech, self.fbd, entries);
    }
    fn eval(&mut self, x: &[f64], r: &mut [f64], jac: Option<&mut fbd_solver::JacobianSink<'_>>) {
        match jac {
            Some(j) => eval(self.mech, self.surface, self.fbd, x, r, &mut Sink(j)),
            None => eval(self.mech, self.surface, self.fbd, x, r, &mut NoJacobian),
        }
    }
    fn residual_scale(&self, row: usize) -> f64 {
        self.scales[row]
    }
}

/// Solves step `data.k` (its record in `data.record`) and advances to
/// `k + 1`, retrying in substeps when the whole step cannot be solved
/// ([`crate::engine::step`]).
///
/// # Errors
/// A [`SimError`] naming the step and time.
pub fn step(model: &SpatialModel, data: &mut SpatialData) -> Result<(), SimError> {
    crate::engine::step::step(model, data)
}

impl Engine for SpatialModel {
    type State = SpatialState;
    type Trial = SpatialTrial;
    type Ground = Surface;
    type Fbd = SpatialFbdData;
    type Record = super::record::SpatialRecord;
    type Torques = Vec<[f64; 3]>;
    type ControlData = Option<Box<crate::gait::GaitData>>;

    fn settings(&self) -> Settings<'_, Surface> {
        Settings {
            dt: SpatialModel::dt(self),
            max_substeps: self.max_substeps,
            cycle_tolerance: self.cycle_tolerance,
            exact: true,
            qdot0: &self.params.qdot0,
            steps: self.steps,
            stride: self.params.stride,
            bodies: self.mech.bodies.len(),
            contacts: &self.mech.contacts,
            limits: self.mech.limits.len(),
            ground: &self.params.terrain,
            friction: &self.params.friction,
            contact: &self.params.contact,
            joint_limits: &self.params.joint_limits,
        }
    }
    fn limit(&self, l: usize) -> LimitInfo {
        let lim = &self.mech.limits[l];
        LimitInfo {
            q_index: lim.q_index,
            joint_index: lim.q_index,
            joint: lim.joint,
            leg: self.mech.legs[lim.slot],
        }
    }
    fn limit_name(&self, l: usize) -> String {
        let lim = &self.mech.limits[l];
        format!(
            "theta{}_{}",
            lim.joint.index() + 1,
            self.mech.legs[lim.slot]
        )
    }
    fn limit_moment_index(&self, l: usize) -> usize {
        self.mech.layout().limit_moment(l)
    }

    fn kinematics(&self, data: &mut SpatialData, history: History<'_>, h: f64) {
        prepare_step(&self.mech, &mut data.fbd, history, h);
        data.fbd.fixed_direction.fill(false);
        data.fbd.released_direction.fill(false);
        data.fbd.frozen.fill(None);
        data.fbd.fixed_states = false;
        data.fbd.refrozen = false;
    }
    fn torques(&self, data: &mut SpatialData) -> Result<(), SimError> {
        joint_torques(self, data)
    }
    fn solve(&self, data: &mut SpatialData) -> Result<NewtonReport, SolverError> {
        let (mut sys, solver, z) = system(self, data);
        solver.solve(&mut sys, z)
    }
    fn evaluate_next(&self, data: &mut SpatialData) {
        let nq = SpatialModel::nq(self);
        evaluate_next(&self.mech, &mut data.fbd, &data.z[..nq]);
    }
    fn trial(&self, data: &SpatialData, c: usize) -> SpatialTrial {
        trial_of(self, data, c)
    }
    fn friction_at(&self, at: [f64; 2]) -> Friction {
        self.params
            .terrain
            .friction_at(&self.params.friction, at[0], at[1])
    }
    fn contact_violation(
        &self,
        data: &SpatialData,
        state: &SpatialState,
        t: &SpatialTrial,
    ) -> (f64, Law) {
        let k = data.fbd.position_gain;
        let friction = self.friction_at([t.p_k[0], t.p_k[2]]);
        let (mu_s, mu_d) = (friction.mu_static, friction.mu_dynamic);
        let pull = (-t.n).max(0.0);
        let ft = t.ft[0].hypot(t.ft[1]);
        match *state {
            SpatialState::Free => {
                let depth = -clearance(&self.params.terrain, t.p_next)
                    - self.params.contact.penetration_tol;
                (k * depth.max(0.0), Law::Penetration)
            }
            SpatialState::Stick { .. } => worst([
                (pull, Law::Pull),
                ((ft - mu_s * t.n).max(0.0), Law::StaticCone),
            ]),
            SpatialState::Slide { dir } => {
                // Coulomb's sliding law with the step's own slip s:
                // Ft = −μD·N·s/|s|, whatever the reference direction `dir`
                // (a slide may turn, even back). A slip slower than the
                // stop speed has no direction: its slide has stopped, and
                // the deficit of |Ft| below μD·N (regularised direction)
                // and the turn back are the violation.
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
    fn limit_gain(&self, data: &SpatialData) -> f64 {
        data.fbd.limit_gain
    }
    fn length_scale(&self, _data: &SpatialData) -> f64 {
        self.mech.length_scale()
    }
    fn anchor_at_distance(
        &self,
        data: &SpatialData,
        reference: usize,
        from: [f64; 3],
        c: usize,
    ) -> [f64; 3] {
        let point = |c: usize| {
            let spec = &self.mech.contacts[c];
            data.fbd.kin.point(&self.mech, spec.point / 3, spec.kind)
        };
        let d = point(c) - point(reference);
        let horizontal = d.x.hypot(d.z);
        if horizontal > 1e-12 {
            point_at_distance(
                &self.params.terrain,
                from,
                d.norm(),
                [d.x / horizontal, d.z / horizontal],
            )
        } else {
            project(&self.params.terrain, from)
        }
    }
    fn newton_fallback(&self, data: &mut SpatialData) -> bool {
        if complementarity(self, data) {
            if freeze_branches(data) {
                return true;
            }
            if !data.fbd.refrozen {
                // The same frozen branches again, from the step's start
                // (the predictor) rather than the failed iterate.
                data.fbd.refrozen = true;
                data.fbd.frozen.copy_from_slice(&data.fbd.first_frozen);
                data.start_z.copy_from_slice(&data.origin_z);
                return true;
            }
            // The last resort of the step: fixed states, searched.
            data.fbd.fixed_states = true;
            return true;
        }
        fix_slides(data) || stop_slowest_slide(self, data)
    }
    fn complementarity_switches(&self, data: &mut SpatialData) -> bool {
        complementarity(self, data) && complementarity_switches(self, data)
    }
    fn refine_directions(&self, data: &mut SpatialData) -> bool {
        refine_directions(self, data)
    }
    fn set_previous(&self, data: &mut SpatialData) {
        set_previous(&self.mech, &mut data.fbd, &data.q_prev);
    }
    fn reset_kinematics(&self, data: &mut SpatialData) {
        data.fbd.kin.eval(&self.mech, &data.grid_q);
        set_previous(&self.mech, &mut data.fbd, &data.grid_q_prev);
    }
    fn make_record(&self, data: &mut SpatialData, iterations: usize, trials: usize, h: f64) {
        make_record(self, data, iterations, trials, h);
    }
    fn skip_record(&self, data: &mut SpatialData, h: f64) {
        carry_momenta(self, data, h);
    }
    fn add_to_record(record: &mut Self::Record, iterations: usize, trials: usize) {
        record.newton_iterations += iterations;
        record.state_trials += trials;
    }
    fn advance(&self, data: &mut SpatialData) {
        // A slide's reference direction follows its slip.
        for (c, state) in data.states.iter_mut().enumerate() {
            if let SpatialState::Slide { dir } = state {
                *dir = data.fbd.slip_hat[c];
            }
        }
        advance(&mut data.fbd);
    }
    fn accepted_whole(&self, data: &mut SpatialData) {
        data.fbd.l_carry_valid = true;
    }
}

/// [`Engine::complementarity_switches`]: the states of the points in
/// contact read from the branches their complementarity rows took at the
/// solution ([`fbd_dynamics::rows::complementarity_rows`]):
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
fn complementarity_switches(model: &SpatialModel, data: &mut SpatialData) -> bool {
    if unfreeze_wrong_branches(model, data) {
        return true;
    }

    // A stop without load whose joint has left the end is free (its row
    // was `λ = 0`, the free row).
    for l in 0..data.limit_trial.len() {
        if let LimitState::At { side, angle } = data.limit_trial[l] {
            let q = data.z[model.mech.limits[l].q_index];
            if data.fbd.limit_unloaded[l] && side.sign() * (q - angle) > LIMIT_RELEASE_ANGLE {
                data.limit_trial[l] = LimitState::Free;
                data.z[model.mech.layout().limit_moment(l)] = 0.0;
            }
        }
    }
    let surface = &model.params.terrain;
    let tol = model.params.contact.penetration_tol;
    let mut again = false;
    for c in 0..data.trial.len() {
        let state = data.trial[c];
        if state == SpatialState::Free {
            continue;
        }
        let b = data.fbd.branch[c];
        let t = trial_of(model, data, c);
        data.seen[c] |= 1 << (state.code() as u8);
        if b.unloaded && clearance(surface, t.p_next) > tol {
            data.trial[c] = SpatialState::Free;
            // Its force is zero to the solver's tolerance: exactly zero in
            // the free state's row.
            let lay = model.mech.layout();
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
                let lay = model.mech.layout();
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

/// Whether this solve's points in contact use complementarity rows: the
/// model's choice, unless both the semismooth and the active-set solves of
/// this step have failed, when the step falls back to fixed states
/// searched by the switching rules (the rows of [`fbd_dynamics::rows`]
/// with the implicit slip direction), audited like every other.
fn complementarity(model: &SpatialModel, data: &SpatialData) -> bool {
    model.complementarity && !data.fbd.fixed_states
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
fn freeze_branches(data: &mut SpatialData) -> bool {
    let mut any = false;
    for c in 0..data.trial.len() {
        if data.trial[c] != SpatialState::Free && data.fbd.frozen[c].is_none() {
            let b = data.fbd.branch[c];
            data.fbd.frozen[c] = Some(Frozen {
                unloaded: b.unloaded,
                sliding: b.sliding,
            });
            any = true;
        }
    }
    if any && data.z.iter().all(|v| v.is_finite()) {
        data.start_z.copy_from_slice(&data.z);
    }
    if any {
        data.fbd.first_frozen.copy_from_slice(&data.fbd.frozen);
    }
    any
}

/// After a solve with fixed branches: a branch the solution contradicts by
/// more than the cycle tolerance (a slide inside its disc, a stick outside
/// it, an unloaded point below the surface, a negative load) is switched
/// (`true`: solve again). Within the tolerance both branches hold.
fn unfreeze_wrong_branches(model: &SpatialModel, data: &mut SpatialData) -> bool {
    let tol = model.cycle_tolerance;
    let mut again = false;
    for c in 0..data.trial.len() {
        let Some(f) = data.fbd.frozen[c] else {
            continue;
        };
        if data.trial[c] == SpatialState::Free {
            continue;
        }
        let b = data.fbd.branch[c];
        let mut g = f;
        if f.sliding && b.excess < -tol || !f.sliding && b.excess > tol {
            g.sliding = !f.sliding;
        }
        if f.unloaded && b.held < -tol || !f.unloaded && b.normal < -tol {
            g.unloaded = !f.unloaded;
        }
        if g != f {
            data.fbd.frozen[c] = Some(g);
            again = true;
        }
    }
    again
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

/// The regularisation β for a (sub)step of length `h` (as the planar one).
fn beta(model: &SpatialModel, h: f64) -> f64 {
    regularization(model.params.contact.regularization, h)
}

/// Stage 4's system for the current trial states.
fn system<'a>(
    model: &'a SpatialModel,
    data: &'a mut SpatialData,
) -> (SpatialSystem<'a>, &'a mut NewtonSolver, &'a mut [f64]) {
    let surface = &model.params.terrain;
    let b = beta(model, data.fbd.dt);
    for (c, spec) in model.mech.contacts.iter().enumerate() {
        let state = data.trial[c];
        let (x, z) = match state {
            SpatialState::Stick { anchor } => (anchor[0], anchor[2]),
            _ => {
                let p = data.fbd.kin.point(&model.mech, spec.point / 3, spec.kind);
                (p.x, p.z)
            }
        };
        let friction = surface.friction_at(&model.params.friction, x, z);
        data.fbd.contact[c] = SpatialContactEquation {
            state,
            frame: frame(surface, x, z),
            mu_dynamic: friction.mu_dynamic,
            regularization: b + model.contact_bumper[c],
            mu_static: friction.mu_static,
            complementarity: complementarity(model, data),
            frozen: data.fbd.frozen[c],
        };
    }
    let ncp = complementarity(model, data);
    for (eq, &state) in data.fbd.limit.iter_mut().zip(&data.limit_trial) {
        *eq = LimitEquation {
            state,
            regularization: b,
            complementarity: ncp,
        };
    }
    row_scales(model, data);
    let sys = SpatialSystem {
        mech: &model.mech,
        surface,
        fbd: &mut data.fbd,
        scales: &data.scales,
    };
    (sys, &mut data.solver, &mut data.z)
}

/// Stage 4's system for the accepted states of `data` (for benchmarks,
/// which time the assembly and the factorisation apart).
pub fn system_for_bench<'a>(
    model: &'a SpatialModel,
    data: &'a mut SpatialData,
) -> SpatialSystem<'a> {
    data.trial.copy_from_slice(&data.states);
    data.limit_trial.copy_from_slice(&data.limit_states);
    system(model, data).0
}

/// Convergence scales: forces to `1e-9 ×` the weight with a round-off
/// floor, moments times the length scale, positions to `1e-12 m`-ish (as
/// the planar model's).
fn row_scales(model: &SpatialModel, data: &mut SpatialData) {
    let mech = &model.mech;
    let lay = mech.layout();
    let k = data.fbd.position_gain;
    let extent = data.q[0].abs().max(data.q[1].abs()).max(data.q[2].abs());
    let force = mech.total_mass() * mech.gravity.abs().max(1.0) + 1e-6 * k * (1.0 + extent);
    let moment = force * mech.length_scale();
    for b in 0..lay.bodies {
        let row = lay.body_row(b);
        data.scales[row..row + 3].fill(force);
        data.scales[row + 3..row + 6].fill(moment);
    }
    let position = 1e-3 * k * (1.0 + extent);
    for c in 0..lay.contacts {
        let row = lay.contact_row(c);
        let s = match data.trial[c] {
            SpatialState::Free => [force; 3],
            _ if complementarity(model, data) => [force; 3],
            SpatialState::Stick { .. } => [position; 3],
            SpatialState::Slide { .. } => [force, position, force],
        };
        data.scales[row..row + 3].copy_from_slice(&s);
    }
    for l in 0..lay.limits {
        data.scales[lay.limit_row(l)] = moment;
    }
}

/// Fixes the friction direction of every sliding point of the trial at
/// its reference direction; `false` if there was none to fix. The fixed
/// direction is then moved to the solution's slip until the two agree
/// ([`refine_directions`]): no row keeps a direction that is not its own.
fn fix_slides(data: &mut SpatialData) -> bool {
    let mut any = false;
    for (c, state) in data.trial.iter().enumerate() {
        if matches!(state, SpatialState::Slide { .. }) && !data.fbd.fixed_direction[c] {
            data.fbd.fixed_direction[c] = true;
            any = true;
        }
    }
    any
}

/// A fixed friction direction agrees with the slip when they differ by
/// less than this angle (rad): the force error `μD·N·angle` is then far
/// below the law tolerance for any load the robot carries.
const DIRECTION_TOL: f64 = 1e-10;

/// [`Engine::refine_directions`]: every sliding point whose friction
/// direction is fixed and whose slip (faster than the stop speed, not
/// turned back by 90° or more — the state machine stops those) points
/// elsewhere takes the slip's direction; `true` if any did.
fn refine_directions(model: &SpatialModel, data: &mut SpatialData) -> bool {
    let mut any = false;
    for c in 0..data.trial.len() {
        let SpatialState::Slide { dir } = data.trial[c] else {
            continue;
        };
        if !data.fbd.fixed_direction[c] {
            continue;
        }
        let s = trial_of(model, data, c).slip();
        let len = s[0].hypot(s[1]);
        if len <= STOP_SPEED * data.fbd.dt || s[0] * dir[0] + s[1] * dir[1] <= 0.0 {
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
            if change < 0.1 && !data.fbd.released_direction[c] {
                data.fbd.fixed_direction[c] = false;
                data.fbd.released_direction[c] = true;
            }
            any = true;
        }
    }
    any
}

/// Sticks the sliding point of the trial whose slip at the last evaluated
/// iterate is the smallest; `false` without sliding points.
fn stop_slowest_slide(model: &SpatialModel, data: &mut SpatialData) -> bool {
    let slowest = (0..data.trial.len())
        .filter(|&c| matches!(data.trial[c], SpatialState::Slide { .. }))
        .min_by(|&a, &b| data.fbd.slip_len[a].total_cmp(&data.fbd.slip_len[b]));
    let Some(c) = slowest else {
        return false;
    };
    let spec = &model.mech.contacts[c];
    let p = data.fbd.kin.point(&model.mech, spec.point / 3, spec.kind);
    data.trial[c] = SpatialState::Stick {
        anchor: project(&model.params.terrain, [p.x, p.y, p.z]),
    };
    true
}

/// The trial of contact `c` from the last solution.
fn trial_of(model: &SpatialModel, data: &SpatialData, c: usize) -> SpatialTrial {
    let mech = &model.mech;
    let lay = mech.layout();
    let spec = &mech.contacts[c];
    let (s, kind) = (spec.point / 3, spec.kind);
    let p_k = data.fbd.kin.point(mech, s, kind);
    let p_next = data.fbd.kin_next.point(mech, s, kind);
    SpatialTrial {
        p_k: [p_k.x, p_k.y, p_k.z],
        p_next: [p_next.x, p_next.y, p_next.z],
        ft: [
            data.z[lay.contact_force(c, 0)],
            data.z[lay.contact_force(c, 2)],
        ],
        n: data.z[lay.contact_force(c, 1)],
        frame: data.fbd.contact[c].frame,
        dt: data.fbd.dt,
    }
}

/// Fills `data.record` for the solved (sub)step of length `h`.
fn make_record(
    model: &SpatialModel,
    data: &mut SpatialData,
    newton_iterations: usize,
    state_trials: usize,
    h: f64,
) {
    let mech = &model.mech;
    let lay = mech.layout();
    let fbd = &data.fbd;
    let z = &data.z;
    let rec = &mut data.record;
    rec.step = data.k;
    rec.t = data.k as f64 * model.dt();
    rec.q.copy_from_slice(&data.q);
    rec.newton_iterations = newton_iterations;
    rec.state_trials = state_trials;
    for (c, spec) in mech.contacts.iter().enumerate() {
        let p = fbd.kin.point(mech, spec.point / 3, spec.kind);
        let eq = &fbd.contact[c];
        let fl = [
            z[lay.contact_force(c, 0)],
            z[lay.contact_force(c, 1)],
            z[lay.contact_force(c, 2)],
        ];
        let [t1, n, t2] = eq.frame;
        let row = &mut rec.contacts[c];
        row.point = [p.x, p.y, p.z];
        row.state = data.trial[c].code();
        row.force = std::array::from_fn(|i| fl[0] * t1[i] + fl[1] * n[i] + fl[2] * t2[i]);
        row.normal = fl[1];
    }
    for s in 0..lay.legs {
        let [z0, z1, z2] = fbd.axes[s];
        let tau = fbd.torque[s];
        let mut stop = [0.0; 3];
        let mut limit = [LimitCode::Free; 3];
        for (l, lim) in mech.limits.iter().enumerate() {
            if lim.slot == s {
                let j = lim.joint.index();
                stop[j] = z[lay.limit_moment(l)];
                limit[j] = LimitCode::of(&data.limit_trial[l]);
            }
        }
        let v = |i: usize| Vector3::new(z[i], z[i + 1], z[i + 2]);
        let hip_m = z[lay.hip_moment(s)] * fbd.hip_dir[s]
            + (tau[0] + stop[0]) * z0
            + (tau[1] + stop[1]) * z1;
        let [b1, b2] = fbd.knee_dir[s];
        let knee_m =
            z[lay.knee_moment(s, 0)] * b1 + z[lay.knee_moment(s, 1)] * b2 + (tau[2] + stop[2]) * z2;
        let row = &mut rec.legs[s];
        row.hip_force = v(lay.hip_force(s, 0)).into();
        row.hip_moment = hip_m.into();
        row.knee_force = v(lay.knee_force(s, 0)).into();
        row.knee_moment = knee_m.into();
        row.torque = tau;
        row.limit = limit;
    }
    // Rates need `data` immutably: a second pass.
    for s in 0..lay.legs {
        let r = joint_rates(model, data, s);
        data.record.legs[s].rate = r;
    }
    // Energies and momenta over the step k → k+1 (the scheme's own); the
    // momenta are the next step's L[k−½] when this step is accepted whole.
    let fbd = &mut data.fbd;
    let mut carry = std::mem::take(&mut fbd.l_carry);
    let g = model.params.gravity;
    let (mut kinetic, mut potential) = (0.0, 0.0);
    let (mut p, mut hmom) = (Vector3::zeros(), Vector3::zeros());
    for (b, body) in mech.bodies.iter().enumerate() {
        let (c0, c1) = (fbd.kin.com[b], fbd.kin_next.com[b]);
        let v = (c1 - c0) / h;
        let (l, psi) =
            half_momentum_and_rotation(&fbd.kin.rot[b], &fbd.kin_next.rot[b], &body.inertia, h);
        carry[b] = l;
        kinetic +=
            0.5 * body.mass * v.norm_squared() + 0.5 * psi.dot(&(body.inertia * psi)) / (h * h);
        potential += body.mass * g * 0.5 * (c0.y + c1.y);
        p += body.mass * v;
        hmom += body.mass * c0.cross(&v) + l;
    }
    fbd.l_carry = carry;
    fbd.l_carry_dt = h;
    let rec = &mut data.record;
    rec.kinetic = kinetic;
    rec.potential = potential;
    rec.momentum = p.into();
    rec.angular_momentum = hmom.into();
}

/// The bodies' momenta `L[k+½]` over the step, kept for the next step's
/// `L[k−½]` (as [`make_record`] keeps them), for a step without a record.
fn carry_momenta(model: &SpatialModel, data: &mut SpatialData, h: f64) {
    let fbd = &mut data.fbd;
    for (b, body) in model.mech.bodies.iter().enumerate() {
        let (l, _) =
            half_momentum_and_rotation(&fbd.kin.rot[b], &fbd.kin_next.rot[b], &body.inertia, h);
        fbd.l_carry[b] = l;
    }
    fbd.l_carry_dt = h;
}

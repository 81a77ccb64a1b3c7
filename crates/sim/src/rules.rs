//! The rules and constants the planar and the spatial steps share: one
//! source for each (the state search's limits, the contact rows'
//! regularisation at a (sub)step length, the joint-limit switches, the
//! parameter checks and the solver's Jacobian adapter).

use crate::SimError;
use fbd_dynamics::{JacobianSink, LimitState};
use fbd_kinematics::{Joint, JointLimits};

/// Most solves of one (sub)step's state search: a search that has not
/// settled by then is treated as a cycle (the step is retried in
/// substeps). The default experiment needs at most 6.
pub(crate) const MAX_STATE_TRIALS: usize = 64;

/// A joint whose trial angle is beyond an end by more than this (rad)
/// reaches the limit: far below any physical scale, above round-off.
pub(crate) const LIMIT_ANGLE_TOL: f64 = 1e-10;

/// The (sub)step length at which the contact and stop rows carry the
/// regularisation [`fbd_contact::ContactParams::regularization`] itself
/// (s): the default Δt.
pub(crate) const REGULARIZATION_DT: f64 = 0.01;

/// The regularisation β of the contact and stop rows for a (sub)step of
/// length `h`: `base · (0.01 s / h)²`, so that the compliance it stands
/// for, `β·h²/M` (m/N), is the same at every Δt (7.8e-14 m/N on the
/// default robot) instead of shrinking as `h²`. A compliance that shrinks
/// with `h²` makes the split of the forces of a statically indeterminate
/// set (a robot lying on six sticking points) round-off: at Δt = 1 ms one
/// ulp of a coordinate (1.1e-16 m) was 0.14 N of internal friction, enough
/// to make a lightly loaded foot at rest flip between sticking and sliding
/// every few steps. The fixed compliance is still far too stiff for its
/// spring to be resolved (its period on a 1.1 kg link is 2 µs): contacts
/// stay rigid and plastic.
#[inline]
pub(crate) fn regularization(base: f64, h: f64) -> f64 {
    let r = REGULARIZATION_DT / h;
    base * r * r
}

/// A free joint whose trial angle crosses an end of its range (by more
/// than [`LIMIT_ANGLE_TOL`]) is held at that end: the state to solve in.
#[inline]
pub(crate) fn limit_arrival(limits: &JointLimits, joint: Joint, angle: f64) -> Option<LimitState> {
    limits
        .violated(joint, angle - LIMIT_ANGLE_TOL)
        .and(limits.violated(joint, angle + LIMIT_ANGLE_TOL))
        .map(|side| LimitState::At {
            side,
            angle: limits.end(joint, side),
        })
}

/// How strongly a stop at `state` pulls its joint towards the end instead
/// of pushing it away, as a force at the length scale (N): `Some(pull)`
/// when it pulls by more than `force_tol` (the stop must release), the
/// switch's priority then `2e12 + pull`, as a lift-off's.
#[inline]
pub(crate) fn limit_release(
    state: &LimitState,
    moment: f64,
    length: f64,
    force_tol: f64,
) -> Option<f64> {
    let LimitState::At { side, .. } = state else {
        return None;
    };
    let push = side.sign() * moment / length;
    (push < -force_tol).then_some(2e12 - push)
}

/// `Ok` when `ok`, otherwise [`SimError::InvalidParameter`] naming `key`.
pub(crate) fn check(
    ok: bool,
    key: &str,
    what: &str,
    got: impl std::fmt::Display,
    expected: &str,
) -> Result<(), SimError> {
    if ok {
        Ok(())
    } else {
        Err(SimError::InvalidParameter {
            key: key.into(),
            what: what.into(),
            got: got.to_string(),
            expected: expected.into(),
        })
    }
}

/// `key` must be positive and finite.
pub(crate) fn positive(key: &str, v: f64) -> Result<(), SimError> {
    check(
        v.is_finite() && v > 0.0,
        key,
        "must be positive and finite",
        v,
        "a finite value > 0",
    )
}

/// Adapts the solver's sink to the assembly's sink trait.
pub(crate) struct Sink<'s, 'a>(pub(crate) &'s mut fbd_solver::JacobianSink<'a>);

impl JacobianSink for Sink<'_, '_> {
    const ACTIVE: bool = true;
    #[inline]
    fn add(&mut self, row: usize, col: usize, v: f64) {
        self.0.add(row, col, v);
    }
}

/// What [`step_loop`] ended with.
pub(crate) struct LoopEnd {
    /// Wall time inside `step` (s).
    pub wall: f64,
    /// The error that stopped the loop.
    pub error: Option<SimError>,
    /// `true` when `stop` ended it early.
    pub interrupted: bool,
}

/// The stepping loop of every run: `steps` calls of `step` on `data`,
/// `on_row` with the step's result after every `stride`-th, stopping at the
/// first error or before the next step once `stop` is set. The wall time
/// is the loop's minus the observer's: the clock is read around the loop
/// and around each written row only, not around every step.
pub(crate) fn step_loop<D, R>(
    data: &mut D,
    steps: usize,
    stride: usize,
    stop: &std::sync::atomic::AtomicBool,
    mut step: impl FnMut(&mut D) -> Result<R, SimError>,
    mut on_row: impl FnMut(&R, &D),
) -> LoopEnd {
    let stride = stride.max(1);
    let mut end = LoopEnd {
        wall: 0.0,
        error: None,
        interrupted: false,
    };
    let mut observer = std::time::Duration::ZERO;
    let start = std::time::Instant::now();
    for k in 0..steps {
        if stop.load(std::sync::atomic::Ordering::Relaxed) {
            end.interrupted = true;
            break;
        }
        match step(data) {
            Ok(r) => {
                if k % stride == 0 {
                    let t = std::time::Instant::now();
                    on_row(&r, data);
                    observer += t.elapsed();
                }
            }
            Err(e) => {
                end.error = Some(e);
                break;
            }
        }
    }
    end.wall = start.elapsed().saturating_sub(observer).as_secs_f64();
    end
}

/// Why one attempt at a step (whole or in substeps) failed; made into a
/// [`SimError`] only when every retry has failed (no allocation before).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Failure {
    Newton(fbd_solver::SolverError),
    Cycle { residual: f64 },
    NonFinite { residual: f64 },
}

impl Failure {
    /// The retry event's cause.
    pub(crate) fn cause(self) -> &'static str {
        match self {
            Failure::Newton(_) => "newton",
            Failure::Cycle { .. } => "cycle",
            Failure::NonFinite { .. } => "non-finite",
        }
    }

    /// The run's error for step `step` at `t`; `states` names the state
    /// combination of a cycle (called only then).
    pub(crate) fn error(self, step: usize, t: f64, states: impl FnOnce() -> String) -> SimError {
        match self {
            Failure::Newton(source) => SimError::Newton { step, t, source },
            Failure::Cycle { residual } => SimError::Cycling {
                step,
                t,
                states: states(),
                residual,
            },
            Failure::NonFinite { residual } => SimError::NonFinite { step, t, residual },
        }
    }
}

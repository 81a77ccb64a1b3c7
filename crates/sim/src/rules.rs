//! The rules and constants the planar and the spatial steps share: one
//! source for each (the state search's limits, the contact rows'
//! regularisation at a (sub)step length, the joint-limit switches, the
//! parameter checks and the solver's Jacobian adapter).

use crate::SimError;
use fbd_dynamics::{JacobianSink, LimitState};
use fbd_kinematics::LimitSide;
use fbd_kinematics::num::{Fixed, Num, Quote};

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
pub(crate) fn limit_arrival(range: [f64; 2], angle: f64) -> Option<LimitState> {
    let [lo, hi] = range;
    if angle + LIMIT_ANGLE_TOL < lo {
        Some(LimitState::At {
            side: LimitSide::Lower,
            angle: lo,
        })
    } else if angle - LIMIT_ANGLE_TOL > hi {
        Some(LimitState::At {
            side: LimitSide::Upper,
            angle: hi,
        })
    } else {
        None
    }
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
    got: impl Quote,
    expected: &str,
) -> Result<(), SimError> {
    if ok {
        Ok(())
    } else {
        Err(SimError::InvalidParameter {
            key: key.into(),
            what: what.into(),
            got: got.quote(),
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

/// A controller gain `key` (`control.kp`, `control.kd`): finite and not
/// negative.
pub(crate) fn gain(key: &str, v: f64) -> Result<(), SimError> {
    check(
        v.is_finite() && v >= 0.0,
        key,
        "must be finite and not negative",
        v,
        "a finite value ≥ 0",
    )
}

/// `[output] stride` of every model: at least 1.
pub(crate) fn stride(stride: usize) -> Result<(), SimError> {
    check(
        stride >= 1,
        "output.stride",
        "must be at least 1",
        stride,
        "an integer ≥ 1",
    )
}

/// The joint limits of the paper's models (`limits`: whether each range
/// `[min, max]` has `min < max`, and the ranges as written), named by
/// `key`.
pub(crate) fn joint_ranges(
    valid: bool,
    key: &str,
    limits: &impl std::fmt::Debug,
) -> Result<(), SimError> {
    check(
        valid,
        key,
        "joint limits must be ranges [min, max] with min < max",
        format!("{limits:?}"),
        "min < max",
    )
}

/// Coulomb friction's domain, `0 ≤ μD ≤ μS` (the 3D models' rule; the
/// error names `terrain.mu_dynamic`).
pub(crate) fn friction(f: &fbd_contact::Friction) -> Result<(), SimError> {
    f.validate().map_err(|e| SimError::InvalidParameter {
        key: "terrain.mu_dynamic".into(),
        what: e.to_string(),
        got: format!("μS = {}, μD = {}", Num(f.mu_static), Num(f.mu_dynamic)),
        expected: "0 ≤ μD ≤ μS".into(),
    })
}

/// Whether the explicit PD torques are stable on a joint of effective
/// inertia `I`: with `a = kp·Δt²/I` and `b = kd·Δt/I` (both ≥ 0), the
/// step `I·(θ[k+1] − 2θ[k] + θ[k−1])/Δt² = −kp·θ[k] − kd·(θ[k] − θ[k−1])/Δt`
/// has the characteristic polynomial `z² − (2 − a − b)·z + (1 − b)`, whose
/// roots lie in the closed unit disc if and only if `a + 2b ≤ 4`
/// (Jury: `|1 − b| ≤ 1`, `a ≥ 0`, `4 − a − 2b ≥ 0`; `a ≥ 0`, `b ≥ 0` make
/// the last one the only binding condition). At `a + 2b = 4` a root is
/// −1 (an undamped oscillation from one step to the next), beyond it
/// grows: stable means `a + 2b < 4`.
#[inline]
pub(crate) fn pd_stable(a: f64, b: f64) -> bool {
    a + 2.0 * b < 4.0
}

/// The smallest effective joint inertia (kg·m²) on which gains `kp`, `kd`
/// are stable at step `dt`: [`pd_stable`] holds on inertia `I > 0` if and
/// only if `I > (kp·Δt² + 2·kd·Δt)/4`.
#[inline]
pub(crate) fn pd_inertia_limit(kp: f64, kd: f64, dt: f64) -> f64 {
    0.25 * (kp * dt * dt + 2.0 * kd * dt)
}

/// The largest stable damping (N·m·s/rad) for stiffness `kp` on inertia
/// `inertia` at step `dt`: `2·I/Δt − kp·Δt/2` ([`pd_stable`]; negative
/// when `kp` alone is unstable).
#[inline]
pub(crate) fn pd_kd_limit(kp: f64, inertia: f64, dt: f64) -> f64 {
    2.0 * inertia / dt - 0.5 * kp * dt
}

/// The largest stable step (s) for gains `kp`, `kd` on inertia `inertia`:
/// the positive root of `kp·Δt² + 2·kd·Δt = 4·I` ([`pd_stable`]).
#[inline]
pub(crate) fn pd_dt_limit(kp: f64, kd: f64, inertia: f64) -> f64 {
    if kp > 0.0 {
        // (−kd + √(kd² + 4·kp·I))/kp, written without the cancellation.
        4.0 * inertia / (kd + (kd * kd + 4.0 * kp * inertia).sqrt())
    } else if kd > 0.0 {
        2.0 * inertia / kd
    } else {
        f64::INFINITY
    }
}

/// The stability rule of the explicit joint controller: `control.kd` (or
/// `control.kp`, when the stiffness alone breaks it) must keep
/// [`pd_stable`] on the smallest effective joint inertia `inertia`
/// (kg·m², [`crate::joint_inertia`]) at step `dt`; `joint` names the
/// joint that moves most in that fastest mode (e.g. `leg 3 θ2`).
pub(crate) fn pd_stability(
    kp: f64,
    kd: f64,
    inertia: f64,
    dt: f64,
    joint: &str,
) -> Result<(), SimError> {
    if pd_stable(kp * dt * dt / inertia, kd * dt / inertia) {
        return Ok(());
    }
    let kd_max = pd_kd_limit(kp, inertia, dt);
    let dt_max = pd_dt_limit(kp, kd, inertia);
    let why = format!(
        "makes the explicit joint torques unstable at time.dt = {} s: the fastest joint mode \
         ({joint}, effective inertia {inertia:.3e} kg·m²) needs kp·Δt²/I + 2·kd·Δt/I < 4",
        Num(dt)
    );
    if kd_max > 0.0 {
        check(
            false,
            "control.kd",
            &why,
            format!("{} N·m·s/rad", Num(kd)),
            &format!(
                "control.kd < {} N·m·s/rad: set control.kd below that, or time.dt below {dt_max:.3e} s",
                Fixed(kd_max, 4)
            ),
        )
    } else {
        check(
            false,
            "control.kp",
            &why,
            format!("{} N·m/rad", Num(kp)),
            &format!(
                "control.kp < {} N·m/rad (even with control.kd = 0): set control.kp below that, or time.dt below {dt_max:.3e} s",
                Fixed(4.0 * inertia / (dt * dt), 4)
            ),
        )
    }
}

/// Adapts the solver's sink to the assembly's sink trait.
pub(crate) struct Sink<'s, 'a>(pub(crate) &'s mut fbd_solver::JacobianSink<'a>);

impl JacobianSink for Sink<'_, '_> {
    const ACTIVE: bool = true;
    #[inline(always)]
    fn add(&mut self, row: usize, col: usize, v: f64) {
        self.0.add(row, col, v);
    }
}

/// Why one attempt at a step (whole or in substeps) failed; made into a
/// [`SimError`] only when every retry has failed (no allocation before).
#[derive(Clone, Copy, Debug)]
pub(crate) enum Failure {
    Newton(fbd_solver::SolverError),
    Cycle {
        residual: f64,
    },
    NonFinite {
        residual: f64,
    },
    /// The best solution found breaks a law (the law audit of
    /// [`crate::engine::search`]) at contact point (or, when `limit`, joint
    /// limit) `index` by `amount` newtons.
    Inexact {
        index: usize,
        limit: bool,
        law: crate::engine::Law,
        amount: f64,
    },
}

impl Failure {
    /// The retry event's cause.
    pub(crate) fn cause(self) -> &'static str {
        match self {
            Failure::Newton(_) => "newton",
            Failure::Cycle { .. } => "cycle",
            Failure::NonFinite { .. } => "non-finite",
            Failure::Inexact { .. } => "inexact",
        }
    }

    /// The run's error for step `step` at `t`, after trying down to
    /// `substeps` substeps; `states` names the state combination of a cycle
    /// and `name` a contact point or (`true`) joint limit (called only
    /// then).
    pub(crate) fn error(
        self,
        step: usize,
        t: f64,
        substeps: usize,
        states: impl FnOnce() -> String,
        name: impl FnOnce(usize, bool) -> String,
    ) -> SimError {
        match self {
            Failure::Inexact {
                index,
                limit,
                law,
                amount,
                ..
            } => SimError::Inexact {
                step,
                t,
                substeps,
                point: name(index, limit),
                law: law.describe().into(),
                amount,
                states: states(),
            },
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

#[cfg(test)]
mod tests {
    use super::{pd_dt_limit, pd_kd_limit, pd_stability, pd_stable};

    /// Largest root modulus of `z² − (2 − a − b)·z + (1 − b)`, the
    /// characteristic polynomial of the explicit PD on one joint.
    fn spectral_radius(a: f64, b: f64) -> f64 {
        let (p, q) = (-(2.0 - a - b), 1.0 - b);
        let disc = p * p - 4.0 * q;
        if disc >= 0.0 {
            let r = disc.sqrt();
            ((-p + r) / 2.0).abs().max(((-p - r) / 2.0).abs())
        } else {
            // Complex pair: |z|² = q.
            q.sqrt()
        }
    }

    /// The closed-form region against the roots over a grid of (a, b):
    /// inside (by a margin) no root leaves the unit disc, and with a > 0,
    /// b > 0 every root is strictly inside (the oscillation decays);
    /// outside (by a margin) a root is outside.
    #[test]
    fn closed_form_limit_matches_the_roots() {
        let mut inside = 0;
        let mut outside = 0;
        for i in 0..=400 {
            for j in 0..=300 {
                let (a, b) = (i as f64 * 0.0125, j as f64 * 0.01);
                let rho = spectral_radius(a, b);
                let margin = a + 2.0 * b - 4.0;
                if margin < -1e-9 {
                    assert!(pd_stable(a, b));
                    assert!(rho <= 1.0 + 1e-12, "a = {a}, b = {b}: ρ = {rho}");
                    if a > 0.0 && b > 0.0 {
                        assert!(rho < 1.0, "a = {a}, b = {b}: ρ = {rho}");
                    }
                    inside += 1;
                } else if margin > 1e-9 {
                    assert!(!pd_stable(a, b));
                    assert!(rho > 1.0, "a = {a}, b = {b}: ρ = {rho}");
                    outside += 1;
                }
            }
        }
        assert!(inside > 10_000 && outside > 10_000, "{inside} / {outside}");
    }

    /// The recurrence itself, iterated: just inside the limit an initial
    /// rate dies away, just outside it grows.
    #[test]
    fn the_recurrence_obeys_the_limit() {
        let (inertia, dt, kp) = (0.0105, 1e-3, 1000.0);
        let kd_max = pd_kd_limit(kp, inertia, dt);
        let run = |kd: f64| {
            let (mut prev, mut th) = (0.0, 1e-3);
            for _ in 0..20_000 {
                let tau = -kp * th - kd * (th - prev) / dt;
                let next = 2.0 * th - prev + dt * dt * tau / inertia;
                (prev, th) = (th, next);
            }
            th.abs().max(prev.abs())
        };
        assert!(run(0.99 * kd_max) < 1e-6, "{}", run(0.99 * kd_max));
        assert!(run(1.01 * kd_max) > 1.0, "{}", run(1.01 * kd_max));
        // The step limit is the same boundary.
        let kd = 25.0;
        let h = pd_dt_limit(kp, kd, inertia);
        let lhs = kp * h * h / inertia + 2.0 * kd * h / inertia;
        assert!((lhs - 4.0).abs() < 1e-12, "{lhs}");
        assert!((pd_dt_limit(0.0, kd, inertia) - 2.0 * inertia / kd).abs() < 1e-18);
    }

    /// The error names the key, the limit and the remedy.
    #[test]
    fn the_error_names_the_key_and_the_remedy() {
        assert!(pd_stability(1000.0, 15.0, 0.0105, 1e-3, "leg 1 θ2").is_ok());
        let e = pd_stability(1000.0, 30.0, 0.0105, 1e-3, "leg 1 θ2")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("control.kd: "), "{e}");
        assert!(
            e.contains("control.kd < 20.5000 N·m·s/rad: set control.kd below that"),
            "{e}"
        );
        assert!(e.contains("time.dt below 6.920e-4 s"), "{e}");
        assert!(!e.contains('\n'), "{e}");
        // A stiffness that alone is unstable names control.kp.
        let e = pd_stability(1e6, 0.0, 0.01, 1e-3, "leg 3 θ3")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("control.kp: "), "{e}");
        assert!(e.contains("control.kp < 40000.0000 N·m/rad"), "{e}");
        assert!(e.contains("set control.kp below that"), "{e}");
    }
}

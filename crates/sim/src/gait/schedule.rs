//! The gait schedule: which legs are in stance or swing at a time, and
//! when each lifts off and touches down.
//!
//! Leg `i` lifts off at `t_k = (k + φᵢ)·T` for `k = 0, 1, …` as long as
//! `t_k < walk_time`, swings for `(1 − β)·T`, and stands until its next
//! lift-off. Before its first lift-off every leg stands on its initial
//! foothold (start-up), and after its last swing on its last foothold
//! (stop). The schedule is a pure function of time: a step needs no
//! history.

use super::params::GaitParams;

/// A leg's phase at a time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LegPhase {
    /// Standing on the foothold reached by swing `last` (`None`: the
    /// initial foothold).
    Stance {
        /// Index `k` of the swing that placed the foot, if any.
        last: Option<usize>,
    },
    /// In swing `k` (from the foothold of swing `k − 1` to that of `k`),
    /// `u ∈ [0, 1)` the fraction of the swing done.
    Swing {
        /// Swing index.
        k: usize,
        /// Fraction of the swing done.
        u: f64,
    },
}

impl LegPhase {
    /// `true` in stance.
    pub fn is_stance(&self) -> bool {
        matches!(self, LegPhase::Stance { .. })
    }
}

/// Relative tolerance of the phase boundaries (fraction of a period or of
/// a swing).
pub const SNAP: f64 = 1e-9;

/// Lift-off time of swing `k` of leg `leg` (array index), s.
#[inline]
pub fn liftoff_time(p: &GaitParams, leg: usize, k: usize) -> f64 {
    (k as f64 + p.phases[leg]) * p.period
}

/// Touchdown time of swing `k` of leg `leg`, s.
#[inline]
pub fn touchdown_time(p: &GaitParams, leg: usize, k: usize) -> f64 {
    liftoff_time(p, leg, k) + p.swing_time()
}

/// Mid-stance time after swing `k`: touchdown plus half the stance,
/// `t_k + (1 − β)·T + β·T/2`, s.
#[inline]
pub fn mid_stance_time(p: &GaitParams, leg: usize, k: usize) -> f64 {
    touchdown_time(p, leg, k) + 0.5 * p.duty * p.period
}

/// Index of the last swing of `leg` (the last `k` with `t_k < walk_time`),
/// or `None` if it never lifts off.
#[inline]
pub fn last_swing(p: &GaitParams, leg: usize) -> Option<usize> {
    if !p.walking {
        return None;
    }
    let first = p.phases[leg] * p.period;
    if first >= p.walk_time {
        return None;
    }
    if p.walk_time.is_infinite() {
        return Some(usize::MAX);
    }
    let mut k = ((p.walk_time - first) / p.period).ceil() as usize;
    // Round-off at the boundary: make `t_k < walk_time` exact.
    while k > 0 && liftoff_time(p, leg, k) >= p.walk_time {
        k -= 1;
    }
    while liftoff_time(p, leg, k + 1) < p.walk_time {
        k += 1;
    }
    Some(k)
}

/// The phase of leg `leg` (array index) at time `t`.
#[inline]
pub fn phase(p: &GaitParams, leg: usize, t: f64) -> LegPhase {
    phase_with(p, leg, last_swing(p, leg), t)
}

/// [`phase`] with the leg's [`last_swing`] already known.
#[inline]
pub fn phase_with(p: &GaitParams, leg: usize, last: Option<usize>, t: f64) -> LegPhase {
    let Some(last) = last else {
        return LegPhase::Stance { last: None };
    };
    let since = t - p.phases[leg] * p.period;
    if since < 0.0 {
        return LegPhase::Stance { last: None };
    }
    // Times within `SNAP` (relative) of a lift-off or touchdown count as
    // that instant: `k·Δt` rarely equals `(k' + φ)·T` to the last bit.
    let k = ((since / p.period + SNAP).floor() as usize).min(last);
    let u = (t - liftoff_time(p, leg, k)) / p.swing_time();
    if (-SNAP..1.0 - SNAP).contains(&u) {
        LegPhase::Swing { k, u: u.max(0.0) }
    } else if u < 0.0 {
        // Round-off just before a lift-off: still standing after k − 1.
        LegPhase::Stance {
            last: k.checked_sub(1),
        }
    } else {
        LegPhase::Stance { last: Some(k) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gait::params::GaitKind;

    #[test]
    fn tripod_alternates() {
        let mut p = GaitParams::preset(GaitKind::Tripod);
        p.walk_time = 3.0;
        assert!(
            matches!(phase(&p, 0, 0.25), LegPhase::Swing { k: 0, u } if (u - 0.5).abs() < 1e-12)
        );
        assert_eq!(phase(&p, 1, 0.25), LegPhase::Stance { last: None });
        assert_eq!(phase(&p, 0, 0.75), LegPhase::Stance { last: Some(0) });
        assert!(matches!(phase(&p, 1, 0.75), LegPhase::Swing { k: 0, .. }));
        // Lift-offs at 0, 1, 2 (< 3): the last swing is k = 2.
        assert_eq!(last_swing(&p, 0), Some(2));
        assert_eq!(last_swing(&p, 1), Some(2));
        assert_eq!(phase(&p, 0, 10.0), LegPhase::Stance { last: Some(2) });
        p.walking = false;
        assert_eq!(phase(&p, 0, 0.25), LegPhase::Stance { last: None });
    }
}

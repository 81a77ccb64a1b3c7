//! Advice on a failed run: is the time step too large for the robot?

use fbd_kinematics::num::{Fixed, Num};
use fbd_sim::SimError;

use crate::{ConfigFile, PlanarConfig};

/// Steps per time scale below which a run-time failure is blamed on Δt:
/// `Δt ≤ τ/STEPS_PER_TIME_SCALE` is considered small enough.
pub const STEPS_PER_TIME_SCALE: f64 = 20.0;

/// Steps per time scale below which a run gets a warning before it
/// starts (`Δt > τ/WARN_STEPS_PER_TIME_SCALE`: ten times the step the
/// advice asks for, 0.1 s for the built-in robot).
pub const WARN_STEPS_PER_TIME_SCALE: f64 = 2.0;

impl<I> ConfigFile<I> {
    /// The robot's shortest natural time scale `τ = √(c/g)` (s): how fast
    /// a lower link of length `c` swings under gravity `g`. `None` without
    /// gravity.
    pub fn time_scale(&self) -> Option<f64> {
        let g = self.world.gravity;
        (g > 0.0).then(|| (self.leg.lower_length / g).sqrt())
    }

    /// A time step that resolves the motion: the largest 1, 2 or 5 × 10ⁿ s
    /// not above `τ / 20` ([`ConfigFile::time_scale`]); 0.01 s for the
    /// built-in robot.
    pub fn suggested_dt(&self) -> Option<f64> {
        let limit = self.time_scale()? / STEPS_PER_TIME_SCALE;
        let decade = 10f64.powf(limit.log10().floor());
        let m = [5.0, 2.0, 1.0]
            .into_iter()
            .find(|m| m * decade <= limit * (1.0 + 1e-12))
            .unwrap_or(1.0);
        // Round the product to a short decimal (5e-3, not 0.005000000001).
        format!("{:.1e}", m * decade).parse().ok()
    }

    /// A warning before a dynamic run whose Δt is far too large for the
    /// robot's motion (`Δt > τ/2`, [`WARN_STEPS_PER_TIME_SCALE`]): the
    /// steps would not resolve a swing or a touchdown. Names the value to
    /// use ([`ConfigFile::suggested_dt`]).
    pub fn dt_warning(&self) -> Option<String> {
        let tau = self.time_scale()?;
        let dt = self.time.dt;
        let suggested = self.suggested_dt()?;
        (dt > tau / WARN_STEPS_PER_TIME_SCALE).then(|| {
            format!(
                "warning: time.dt = {} s is far too large for this robot: its lower links swing under gravity on a time scale √(c/g) = {} s, which a step should resolve at least {STEPS_PER_TIME_SCALE} times (the run solves {} steps); try time.dt = {}",
                Num(dt),
                Fixed(tau, 3),
                (self.time.duration / dt).round() as u64 + 1,
                Num(suggested)
            )
        })
    }
}

impl PlanarConfig {
    /// One clause of advice for a run-time failure `e`, or `None`: when Δt
    /// is above [`PlanarConfig::suggested_dt`], says that Δt is likely too
    /// large and suggests that value.
    pub fn advice(&self, e: &SimError) -> Option<String> {
        e.step()?;
        let tau = self.time_scale()?;
        let dt = self.time.dt;
        let suggested = self.suggested_dt()?;
        (dt > tau / STEPS_PER_TIME_SCALE).then(|| {
            format!(
                "time.dt = {} s is likely too large: the lower links swing under gravity on a time scale √(c/g) = {} s, which a step should resolve at least {STEPS_PER_TIME_SCALE} times; try time.dt = {}",
                Num(dt),
                Fixed(tau, 3),
                Num(suggested)
            )
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn suggests_a_round_step_below_a_twentieth_of_the_time_scale() {
        let mut c = PlanarConfig::default();
        assert_eq!(c.suggested_dt(), Some(0.01));
        c.leg.lower_length = 0.1;
        // τ/20 = 0.00505: 5e-3.
        assert_eq!(c.suggested_dt(), Some(0.005));
        c.world.gravity = 0.0;
        assert_eq!(c.suggested_dt(), None);
    }

    #[test]
    fn advice_only_for_a_large_step() {
        let e = SimError::NonFinite {
            step: 3,
            t: 0.9,
            residual: 1.0,
        };
        let mut c = PlanarConfig::default();
        assert_eq!(c.advice(&e), None);
        c.time.dt = 0.3;
        let a = c.advice(&e).unwrap();
        assert!(a.contains("time.dt = 0.3 s is likely too large"), "{a}");
        assert!(a.ends_with("try time.dt = 0.01"), "{a}");
    }
}

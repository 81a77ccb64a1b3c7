//! `[solver]`: the settings of Newton's method a configuration may change,
//! for every model (the planar one, the hexapod in 3D, an imported robot).

use crate::SimError;
use crate::rules::check;
use fbd_solver::NewtonParams;

/// The chord steps every model takes by default
/// ([`NewtonParams::chord_steps`]): up to six steps in a row that reuse a
/// kept factorisation before a refactorisation.
pub const DEFAULT_CHORD_STEPS: usize = 6;

/// The most chord steps in a row `[solver] chord_steps` may allow.
pub const MAX_CHORD_STEPS: usize = 100;

/// Newton's convergence tolerance of every model by default
/// ([`NewtonParams::residual_tol`]): every row's residual at most `1e-9`
/// of its scale (a force row: of the robot's weight).
pub const DEFAULT_TOLERANCE: f64 = 1e-9;

/// The tightest tolerance `[solver] tolerance` may ask for: ten thousand
/// times the double's precision, about where the round-off of the FBD
/// equations' largest terms lies.
pub const MIN_TOLERANCE: f64 = 1e-12;

/// The loosest: the default. A solve also ends at a negligible Newton
/// step once its residual is within a thousand times the tolerance
/// ([`NewtonParams::step_residual_factor`]); at `1e-9` that is `1e-6` of
/// the weight, the law audit's tolerance (docs/reference.md, *Steps that
/// cannot be closed*), which a looser tolerance would exceed.
pub const MAX_TOLERANCE: f64 = DEFAULT_TOLERANCE;

/// Newton's settings of a run (`[solver]`), the same defaults for every
/// model; [`SolverSettings::apply`]d to the model's [`NewtonParams`] when
/// the model is built.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverSettings {
    /// `[solver] chord_steps`: how many chord steps in a row may reuse a
    /// kept factorisation ([`NewtonParams::chord_steps`]); `0` is full
    /// Newton (a factorisation at every iteration). Default
    /// [`DEFAULT_CHORD_STEPS`].
    pub chord_steps: usize,
    /// `[solver] tolerance`: the convergence tolerance on every row's
    /// residual relative to its scale ([`NewtonParams::residual_tol`]),
    /// from [`MIN_TOLERANCE`] to [`MAX_TOLERANCE`]. Default
    /// [`DEFAULT_TOLERANCE`].
    pub tolerance: f64,
}

impl Default for SolverSettings {
    fn default() -> Self {
        Self {
            chord_steps: DEFAULT_CHORD_STEPS,
            tolerance: DEFAULT_TOLERANCE,
        }
    }
}

impl SolverSettings {
    /// Checks the settings' domains; errors name the configuration key.
    pub fn validate(&self) -> Result<(), SimError> {
        check(
            self.chord_steps <= MAX_CHORD_STEPS,
            "solver.chord_steps",
            "is too large",
            self.chord_steps,
            &format!("an integer from 0 (full Newton) to {MAX_CHORD_STEPS}"),
        )?;
        check(
            (MIN_TOLERANCE..=MAX_TOLERANCE).contains(&self.tolerance),
            "solver.tolerance",
            &format!("must lie from {MIN_TOLERANCE:e} to {MAX_TOLERANCE:e} (the default)"),
            self.tolerance,
            &format!("a value in [{MIN_TOLERANCE:e}, {MAX_TOLERANCE:e}]"),
        )
    }

    /// Sets these settings in `p` (a model's parameters).
    pub fn apply(&self, p: &mut NewtonParams) {
        p.chord_steps = self.chord_steps;
        p.residual_tol = self.tolerance;
    }

    /// `p` with these settings applied.
    pub fn applied(&self, mut p: NewtonParams) -> NewtonParams {
        self.apply(&mut p);
        p
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_apply_and_their_domains_are_checked() {
        let mut p = NewtonParams {
            chord_steps: 3,
            residual_tol: 1e-10,
            ..NewtonParams::default()
        };
        let d = SolverSettings::default();
        d.validate().unwrap();
        d.apply(&mut p);
        assert_eq!(
            (p.chord_steps, p.residual_tol),
            (DEFAULT_CHORD_STEPS, DEFAULT_TOLERANCE)
        );
        let s = SolverSettings {
            chord_steps: 0,
            tolerance: 1e-11,
        };
        s.validate().unwrap();
        s.apply(&mut p);
        assert_eq!((p.chord_steps, p.residual_tol), (0, 1e-11));
        for bad in [
            SolverSettings {
                chord_steps: 101,
                ..d
            },
            SolverSettings {
                tolerance: 1e-8,
                ..d
            },
            SolverSettings {
                tolerance: 1e-13,
                ..d
            },
            SolverSettings {
                tolerance: f64::NAN,
                ..d
            },
        ] {
            let e = bad.validate().unwrap_err().to_string();
            assert!(e.starts_with("solver."), "{e}");
        }
    }
}

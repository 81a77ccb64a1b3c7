//! The interface a nonlinear system offers to [`crate::NewtonSolver`].

/// A square nonlinear system `r(x) = 0` with a sparse analytic Jacobian.
pub trait NewtonSystem {
    /// Number of unknowns (= number of equations).
    fn dim(&self) -> usize;

    /// Identifies the sparsity pattern: two calls returning the same key must
    /// describe the same pattern (the solver caches the symbolic factorisation
    /// by this key).
    fn pattern_key(&self) -> u64;

    /// Pushes every structurally non-zero `(row, col)` of the Jacobian
    /// (any order; duplicates allowed). Called once per new key.
    fn pattern(&self, entries: &mut Vec<(usize, usize)>);

    /// Evaluates the residual into `r` and, when `jac` is given, the Jacobian
    /// values through [`JacobianSink::add`] (every entry must lie in the
    /// pattern; contributions to the same entry are summed; the sink starts
    /// zeroed).
    fn eval(&mut self, x: &[f64], r: &mut [f64], jac: Option<&mut JacobianSink<'_>>);

    /// Residual entries are converged when `|r_i| ≤ residual_tol · scale_i`.
    /// Default: 1 for every row.
    fn residual_scale(&self, row: usize) -> f64 {
        let _ = row;
        1.0
    }

    /// `1 / residual_scale(row)`, the weight of the row in the scaled
    /// residual max-norm `max_i |r_i| · weight_i` (the solver evaluates it
    /// at every iterate; a system that keeps the reciprocals saves the
    /// divisions). Must equal `1.0 / self.residual_scale(row)`, which is
    /// the default.
    fn residual_weight(&self, row: usize) -> f64 {
        1.0 / self.residual_scale(row)
    }

    /// Called when a crawl's watchdog returns to its kept iterate `x`, of
    /// scaled residual max-norm `residual` ([`crate::NewtonParams::watchdog`]):
    /// `true` gives the solve up there ([`crate::SolverError::Abandoned`]),
    /// for a system whose equations are certain to change at `x` (a caller
    /// that solves again with other equations). Default: `false`.
    fn abandon_crawl(&mut self, x: &[f64], residual: f64) -> bool {
        let _ = (x, residual);
        false
    }
}

/// Write access to the Jacobian values of the current pattern.
pub struct JacobianSink<'a> {
    pub(crate) n: usize,
    pub(crate) slot: &'a [u32],
    pub(crate) values: &'a mut [f64],
}

impl JacobianSink<'_> {
    /// Adds `v` to entry `(row, col)`.
    ///
    /// # Panics
    /// If `(row, col)` is not in the pattern (a bug in the system).
    #[inline(always)]
    pub fn add(&mut self, row: usize, col: usize, v: f64) {
        let s = self.slot[row * self.n + col];
        // One check for both failures: an entry outside the pattern has
        // slot `u32::MAX`, beyond the values (fewer than `u32::MAX`: see
        // `Pattern::build` and `NewtonSolver::dense_jacobian`).
        match self.values.get_mut(s as usize) {
            Some(x) => *x += v,
            None => not_in_pattern(row, col),
        }
    }
}

#[cold]
#[inline(never)]
fn not_in_pattern(row: usize, col: usize) -> ! {
    panic!("Jacobian entry ({row}, {col}) is not in the declared pattern")
}

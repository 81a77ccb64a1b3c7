//! Errors reported by [`crate::NewtonSolver::solve`].

/// Why a Newton solve failed. Every message is a single line.
///
/// On error the unknowns hold the last accepted iterate (the one whose
/// residual was smallest so far), not a solution.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum SolverError {
    /// The Jacobian could not be factored.
    ///
    /// `equation` is the index of the unknown (Jacobian column, in the
    /// system's own numbering) at which elimination broke down: either faer
    /// found no structurally non-zero pivot for that column
    /// (`LuError::SymbolicSingular`, mapped back through the fill-reducing
    /// column permutation), or the factorisation produced a zero pivot, which
    /// shows up as a non-finite Newton step; then it is the first unknown
    /// whose step is NaN or infinite.
    #[error("singular Jacobian: elimination breaks down at unknown {equation}")]
    Singular {
        /// Index of the unknown (Jacobian column) at which elimination failed.
        equation: usize,
    },

    /// No convergence: either `max_iterations` Newton steps were taken, or
    /// the scaled residual max-norm did not decrease through all
    /// `max_backtracks` halvings of the step.
    #[error("Newton did not converge at iteration {iter} (scaled residual max-norm {residual:e})")]
    Diverged {
        /// Number of Newton steps accepted before giving up.
        iter: usize,
        /// Scaled residual max-norm `max_i |r_i| / scale_i` at the returned
        /// iterate.
        residual: f64,
    },

    /// A NaN or infinity appeared in the residual or Jacobian at the current
    /// iterate, or in every trial residual of a line search.
    #[error(
        "non-finite value (NaN or infinity) in residual, Jacobian or step at Newton iteration {iter}"
    )]
    NonFinite {
        /// Number of Newton steps accepted before the non-finite value
        /// appeared.
        iter: usize,
    },

    /// The system gave up a crawling solve ([`crate::NewtonSystem::abandon_crawl`]):
    /// at the kept iterate of a crawl, a change of the system's equations
    /// is already certain. The unknowns hold that iterate.
    #[error(
        "Newton gave up a crawl at iteration {iter} (scaled residual max-norm {residual:e}): the equations change"
    )]
    Abandoned {
        /// Number of Newton steps accepted before giving up.
        iter: usize,
        /// Scaled residual max-norm at the returned iterate.
        residual: f64,
    },
}

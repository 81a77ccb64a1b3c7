//! # fbd-solver
//!
//! Newton's method for square nonlinear systems `r(x) = 0` with a sparse
//! analytic Jacobian, factored by faer's sparse LU.
//!
//! * A system describes itself through [`NewtonSystem`]: its dimension, a
//!   *pattern key* (equal keys ⇔ equal sparsity patterns), the pattern, and an
//!   evaluation of residual and Jacobian values.
//! * [`NewtonSolver`] keeps, per pattern key, the CSC structure, a dense
//!   `(row, col) → slot` map and faer's symbolic LU (computed once per
//!   pattern; singleton rows are taken out of the LU and solved apart, see
//!   the `lu` module), and, per dimension, the numeric LU storage; a full Newton
//!   step refactors numerically into it, a chord step
//!   ([`NewtonParams::chord_steps`]) reuses the kept factorisation. After
//!   the first solve of a pattern, solving does not allocate.

mod compiled;
mod error;
mod lu;
mod newton;
mod system;

pub use error::SolverError;
pub use newton::{NewtonParams, NewtonReport, NewtonSolver};
pub use system::{JacobianSink, NewtonSystem};

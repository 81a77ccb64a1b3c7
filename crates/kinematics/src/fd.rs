//! The one finite-difference checker every analytic Jacobian in the workspace
//! is tested with.
//!
//! Central differences `(f(x + h·e_j) − f(x − h·e_j)) / 2h` are compared with
//! the analytic entry `J[i][j]` under a relative tolerance with an absolute
//! floor: `|J − FD| ≤ rel·max(|J|, |FD|) + abs`. The first failing entry is
//! reported with its `(i, j)`, both values and the tolerance, so a failing test
//! says which equation and which unknown disagree.

use std::fmt;

/// Tolerances of [`check_jacobian`].
#[derive(Clone, Copy, Debug)]
pub struct FdTolerance {
    /// Central-difference step. Default `1e-6` (near the optimum
    /// `ε^(1/3)` for `f64` on O(1) quantities).
    pub step: f64,
    /// Relative tolerance. Default `1e-6`.
    pub rel: f64,
    /// Absolute floor. Default `1e-7`.
    pub abs: f64,
}

impl Default for FdTolerance {
    fn default() -> Self {
        Self {
            step: 1e-6,
            rel: 1e-6,
            abs: 1e-7,
        }
    }
}

/// A Jacobian entry that disagrees with its central difference.
#[derive(Clone, Debug, PartialEq)]
pub struct FdMismatch {
    /// Output (row) index.
    pub i: usize,
    /// Input (column) index.
    pub j: usize,
    /// The analytic value.
    pub analytic: f64,
    /// The central-difference value.
    pub numeric: f64,
    /// The tolerance it failed.
    pub tolerance: f64,
}

impl fmt::Display for FdMismatch {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "Jacobian entry ({}, {}): analytic {:.12e} vs central difference {:.12e} (|diff| {:.3e} > tol {:.3e})",
            self.i,
            self.j,
            self.analytic,
            self.numeric,
            (self.analytic - self.numeric).abs(),
            self.tolerance
        )
    }
}

/// Checks an analytic Jacobian against central finite differences.
///
/// * `f(x, out)` evaluates the function (`out.len() == m`);
/// * `jac(i, j)` returns the analytic `∂f_i/∂x_j` at `x`;
/// * returns the first mismatch, scanning row-major.
pub fn check_jacobian(
    x: &[f64],
    m: usize,
    mut f: impl FnMut(&[f64], &mut [f64]),
    jac: impl Fn(usize, usize) -> f64,
    tol: FdTolerance,
) -> Result<(), FdMismatch> {
    let n = x.len();
    let mut xp = x.to_vec();
    let mut fp = vec![0.0; m];
    let mut fm = vec![0.0; m];
    let mut numeric = vec![0.0; m * n];
    for j in 0..n {
        let h = tol.step * (1.0 + x[j].abs());
        xp[j] = x[j] + h;
        f(&xp, &mut fp);
        xp[j] = x[j] - h;
        f(&xp, &mut fm);
        xp[j] = x[j];
        for i in 0..m {
            numeric[i * n + j] = (fp[i] - fm[i]) / (2.0 * h);
        }
    }
    for i in 0..m {
        for j in 0..n {
            let a = jac(i, j);
            let d = numeric[i * n + j];
            let tolerance = tol.rel * a.abs().max(d.abs()) + tol.abs;
            // Written negated so that a NaN on either side fails.
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            let fails = !((a - d).abs() <= tolerance);
            if fails {
                return Err(FdMismatch {
                    i,
                    j,
                    analytic: a,
                    numeric: d,
                    tolerance,
                });
            }
        }
    }
    Ok(())
}

/// Checks that a sparse Jacobian's declared structure covers every entry
/// it writes: `jac(i, j)` (an `m × n` matrix) is zero wherever `(i, j)` is
/// not among `entries` (the structural pattern, repeats allowed). Returns
/// the first non-zero entry outside it, row-major, as
/// `"entry (i, j) = v is not in the pattern"`.
pub fn check_pattern(
    m: usize,
    n: usize,
    entries: &[(usize, usize)],
    jac: impl Fn(usize, usize) -> f64,
) -> Result<(), String> {
    let mut declared = vec![false; m * n];
    for &(i, j) in entries {
        declared[i * n + j] = true;
    }
    for i in 0..m {
        for j in 0..n {
            let v = jac(i, j);
            if !declared[i * n + j] && v != 0.0 {
                return Err(format!("entry ({i}, {j}) = {v} is not in the pattern"));
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn accepts_a_correct_jacobian() {
        let x = [0.3f64, -1.2];
        let f = |x: &[f64], o: &mut [f64]| {
            o[0] = x[0].sin() * x[1];
            o[1] = x[1] * x[1];
        };
        let j = |i: usize, k: usize| match (i, k) {
            (0, 0) => x[0].cos() * x[1],
            (0, 1) => x[0].sin(),
            (1, 1) => 2.0 * x[1],
            _ => 0.0,
        };
        check_jacobian(&x, 2, f, j, FdTolerance::default()).unwrap();
    }

    #[test]
    fn reports_the_wrong_entry() {
        let x = [0.3f64, -1.2];
        let f = |x: &[f64], o: &mut [f64]| {
            o[0] = x[0].sin() * x[1];
            o[1] = x[1] * x[1];
        };
        // (1, 1) deliberately wrong by a factor 2.
        let j = |i: usize, k: usize| match (i, k) {
            (0, 0) => x[0].cos() * x[1],
            (0, 1) => x[0].sin(),
            (1, 1) => x[1],
            _ => 0.0,
        };
        let e = check_jacobian(&x, 2, f, j, FdTolerance::default()).unwrap_err();
        assert_eq!((e.i, e.j), (1, 1));
        assert!(e.to_string().contains("(1, 1)"));
    }

    #[test]
    fn reports_an_entry_outside_the_pattern() {
        let jac = |i: usize, j: usize| if (i, j) == (1, 0) { 2.5 } else { 0.0 };
        assert!(check_pattern(2, 2, &[(1, 0), (0, 1)], jac).is_ok());
        let e = check_pattern(2, 2, &[(0, 0), (0, 1)], jac).unwrap_err();
        assert_eq!(e, "entry (1, 0) = 2.5 is not in the pattern");
    }
}

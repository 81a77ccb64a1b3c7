//! The check of a step's analytic Jacobian, for every model ([`FbdModel`]):
//! the dense Jacobian written by [`crate::assembly::eval`], its entries
//! inside the declared pattern ([`crate::assembly::pattern`]) and equal to
//! the residual's central differences (`fbd_kinematics::fd`, the shared
//! checker). The tests of the planar, the hexapod's and any robot's
//! equations call it.

use crate::assemble::{JacobianSink, NoJacobian};
use crate::assembly::{FbdModel, eval, pattern};
use fbd_kinematics::fd::{FdTolerance, check_jacobian, check_pattern};

/// A sink writing a dense row-major `n × n` Jacobian.
struct Dense<'a> {
    n: usize,
    m: &'a mut [f64],
}

impl JacobianSink for Dense<'_> {
    const ACTIVE: bool = true;
    fn add(&mut self, r: usize, c: usize, v: f64) {
        self.m[r * self.n + c] += v;
    }
}

/// The analytic Jacobian of `model`'s step at `z` (dense, row-major),
/// evaluated into `data` (whose branches and slip directions then are
/// those of `z`).
pub fn dense_jacobian<M: FbdModel>(
    model: &M,
    ground: &M::Ground,
    data: &mut M::Data,
    z: &[f64],
) -> Vec<f64> {
    let n = z.len();
    let mut r = vec![0.0; n];
    let mut jac = vec![0.0; n * n];
    eval(
        model,
        ground,
        data,
        z,
        &mut r,
        &mut Dense { n, m: &mut jac },
    );
    jac
}

/// Whether `jac` ([`dense_jacobian`] at `z`, with `data` as it left it)
/// writes only declared entries and equals the residual's central
/// differences within `tol`; the first failure described otherwise.
///
/// # Errors
/// The entry outside the pattern, or the entry that differs.
pub fn check_step<M: FbdModel>(
    model: &M,
    ground: &M::Ground,
    data: &M::Data,
    z: &[f64],
    jac: &[f64],
    tol: FdTolerance,
) -> Result<(), String>
where
    M::Data: Clone,
{
    let n = z.len();
    let mut entries = Vec::new();
    pattern(model, ground, data, &mut entries);
    check_pattern(n, n, &entries, |i, j| jac[i * n + j])?;
    let mut work = data.clone();
    check_jacobian(
        z,
        n,
        |x, out| eval(model, ground, &mut work, x, out, &mut NoJacobian),
        |i, j| jac[i * n + j],
        tol,
    )
    .map_err(|e| e.to_string())
}

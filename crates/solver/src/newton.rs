//! Damped Newton iteration with a per-pattern cached sparse LU (faer).
//!
//! # Allocation behaviour
//!
//! The first solve of a pattern key allocates: the CSC structure, the dense
//! slot map, faer's symbolic LU (column approximate minimum degree ordering),
//! and, when the pattern needs more than any earlier one, the residual/step
//! vectors, the Jacobian value array, the `MemBuffer` scratch and faer's
//! numeric-LU storage. After that, solving a system with an already seen key
//! performs **no heap allocation** (checked by `tests/no_alloc.rs`).
//!
//! Two faer 0.24.4 details make this hold, and are relied upon here:
//!
//! * The symbolic analysis is forced to the *simplicial* LU
//!   ([`SupernodalThreshold::FORCE_SIMPLICIAL`]). faer's supernodal numeric
//!   LU allocates fresh per-supernode work vectors on every call
//!   (`contrib_work` in `factorize_supernodal_numeric_lu`), so it could never
//!   be allocation-free; for the 20–60 unknown, very sparse systems of this
//!   project the simplicial (left-looking, Gilbert–Peierls) LU is also the
//!   faster choice.
//! * faer's simplicial numeric LU stores `L`/`U` in `Vec`s that it grows
//!   on demand (`resize_vec`, never shrinking). Their fill depends on the
//!   numerical row pivoting, so a later refactorisation of the same pattern
//!   could need more room than the first one and would then allocate. To
//!   rule that out, when a pattern is registered the solver factors a fully
//!   dense `n × n` matrix once into that pattern's own [`NumericLu`]: any
//!   `n × n` factorisation needs at most the storage of the dense one, so
//!   every later refactorisation fits. (The simplicial numeric LU reads only
//!   the dimensions and the column permutation from the symbolic object, so
//!   this warm-up is valid.) Each pattern keeps its own [`NumericLu`]:
//!   faer's simplicial one cannot be reused for a smaller dimension.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::sparse::linalg::lu::{
    LuRef, LuSymbolicParams, NumericLu, SymbolicLu, factorize_symbolic_lu,
};
use faer::sparse::linalg::{LuError, SupernodalThreshold};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMatRef};
use faer::{Conj, MatMut, Par};

use crate::{JacobianSink, NewtonSystem, SolverError};

/// Tuning parameters of [`NewtonSolver`].
///
/// Convergence rule (checked at every iterate, including the initial guess):
///
/// 1. **Residual test** — converged when every row satisfies
///    `|r_i| ≤ residual_tol · residual_scale(i)`, i.e. the *scaled residual
///    max-norm* `‖r‖ = max_i |r_i| / residual_scale(i)` is `≤ residual_tol`.
/// 2. **Step test** (round-off floor) — otherwise, after the Newton step `Δx`
///    has been computed, the iterate is also accepted as converged when the
///    step is negligible, `|Δx_i| ≤ step_tol · (1 + |x_i|)` for every `i`,
///    **and** the residual is nearly converged, `‖r‖ ≤ step_residual_factor ·
///    residual_tol`. The step is then not applied. This catches iterates
///    whose residual cannot be pushed below `residual_tol` in floating point
///    (badly scaled rows) without ever reporting a stagnating iterate far
///    from a root as converged: a tiny step with a large residual is not
///    convergence (the line search then usually fails → `Diverged`).
/// 3. **Floor test** — when the line search cannot decrease the residual at
///    all and `‖r‖ ≤ step_residual_factor · residual_tol`, the iterate is at
///    the same round-off floor (e.g. poorly determined unknowns, whose steps
///    are never negligible, make the residual noisy) and is accepted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonParams {
    /// Maximum number of Newton steps before giving up with
    /// [`SolverError::Diverged`]. Default: `20`.
    pub max_iterations: usize,
    /// Tolerance on the scaled residual max-norm: converged when
    /// `|r_i| ≤ residual_tol · residual_scale(i)` for all rows.
    /// Default: `1e-9`.
    pub residual_tol: f64,
    /// Relative step tolerance of the step test: the step is negligible when
    /// `|Δx_i| ≤ step_tol · (1 + |x_i|)` for all unknowns. Default: `1e-12`.
    pub step_tol: f64,
    /// A negligible step counts as convergence only if the scaled residual
    /// max-norm is `≤ step_residual_factor · residual_tol`. Default: `1e3`.
    pub step_residual_factor: f64,
    /// Damped fallback: how many times the step may be halved while the
    /// scaled residual max-norm does not strictly decrease (a trial point
    /// with a non-finite residual counts as no decrease). `0` means pure
    /// Newton steps that must still decrease the residual. Default: `8`.
    pub max_backtracks: usize,
    /// **Chord start** (simplified Newton): when the pattern already holds a
    /// numeric LU from an earlier solve, first try up to this many steps
    /// `Δx = −J_old⁻¹ r(x)` with that stale factorisation (residual-only
    /// evaluations, no refactorisation). A chord step is kept only if it
    /// shrinks the scaled residual max-norm by at least
    /// [`Self::chord_contraction`]; otherwise — or when the steps run out —
    /// the solve continues with the full damped Newton iteration below from
    /// the last kept iterate. Convergence is still the residual test on the
    /// true residual (tolerances unchanged); chord steps count as iterations
    /// and in `max_iterations` only through the full-Newton part. `0`
    /// disables it. Default: `0`.
    pub chord_steps: usize,
    /// Required contraction of a chord step: `‖r(x + Δx)‖ ≤ chord_contraction
    /// · ‖r(x)‖`. Default: `0.1`.
    pub chord_contraction: f64,
}

impl Default for NewtonParams {
    fn default() -> Self {
        Self {
            max_iterations: 20,
            residual_tol: 1e-9,
            step_tol: 1e-12,
            step_residual_factor: 1e3,
            max_backtracks: 8,
            chord_steps: 0,
            chord_contraction: 0.1,
        }
    }
}

/// Outcome of a successful [`NewtonSolver::solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonReport {
    /// Newton steps applied to `x` (0 when the initial guess was converged).
    pub iterations: usize,
    /// Scaled residual max-norm `max_i |r_i| / residual_scale(i)` at the
    /// returned `x`.
    pub residual: f64,
    /// Numeric LU factorisations performed during this solve (without chord
    /// steps, see [`NewtonParams::chord_steps`]: equals `iterations`, plus
    /// one when the step test ended the solve).
    pub factorizations: usize,
}

/// Cached per-pattern data: CSC structure, dense slot map, symbolic LU.
struct Pattern {
    n: usize,
    col_ptr: Vec<usize>,
    row_idx: Vec<usize>,
    /// Dense `n × n` row-major map `(row, col) → index into the CSC values`,
    /// `u32::MAX` where the entry is not in the pattern.
    slot: Vec<u32>,
    symbolic: SymbolicLu<usize>,
    /// Numeric LU storage, reused by every refactorisation of this pattern.
    /// (One per pattern: faer 0.24.4's simplicial `NumericLu` cannot be
    /// reused for a smaller dimension, its `L`/`U` column pointer arrays
    /// never shrink and the triangular solves then fail an assertion.)
    numeric: NumericLu<usize, f64>,
    /// `numeric` holds the factorisation of a Jacobian of this pattern (not
    /// just the dense warm-up): usable for chord steps.
    factored: bool,
}

impl Pattern {
    fn build(n: usize, entries: &mut Vec<(usize, usize)>) -> Self {
        for &(row, col) in entries.iter() {
            assert!(
                row < n && col < n,
                "Jacobian pattern entry ({row}, {col}) is out of range for dimension {n}"
            );
        }
        // Column-major order, rows sorted within a column, no duplicates.
        entries.sort_unstable_by_key(|&(row, col)| (col, row));
        entries.dedup();
        let nnz = entries.len();
        assert!(
            nnz < u32::MAX as usize,
            "Jacobian pattern has too many entries ({nnz})"
        );

        let mut col_ptr = vec![0usize; n + 1];
        let mut row_idx = Vec::with_capacity(nnz);
        let mut slot = vec![u32::MAX; n * n];
        for (k, &(row, col)) in entries.iter().enumerate() {
            col_ptr[col + 1] += 1;
            row_idx.push(row);
            slot[row * n + col] = k as u32;
        }
        for j in 0..n {
            col_ptr[j + 1] += col_ptr[j];
        }

        let a = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
        let params = LuSymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
            ..Default::default()
        };
        let symbolic = factorize_symbolic_lu(a, params)
            .unwrap_or_else(|e| panic!("faer symbolic LU failed: {e:?}"));
        Self {
            n,
            col_ptr,
            row_idx,
            slot,
            symbolic,
            numeric: NumericLu::new(),
            factored: false,
        }
    }
}

/// Everything reused across solves (sized to the largest pattern seen).
struct Workspace {
    /// Jacobian values in CSC order of the current pattern.
    values: Vec<f64>,
    r: Vec<f64>,
    dx: Vec<f64>,
    x_trial: Vec<f64>,
    r_trial: Vec<f64>,
    mem: MemBuffer,
    mem_req: StackReq,
    numeric_factorizations: u64,
}

/// Newton solver with a cache of symbolic LU factorisations keyed by
/// [`NewtonSystem::pattern_key`].
///
/// Each iteration evaluates `r(x)` and the Jacobian `J(x)`, refactors `J`
/// numerically (reusing the symbolic analysis of its pattern), solves
/// `J Δx = −r` and takes the step with a backtracking line search on the
/// scaled residual max-norm (see [`NewtonParams`] for the convergence rule).
pub struct NewtonSolver {
    params: NewtonParams,
    /// `(pattern key, pattern)`, in registration order.
    patterns: Vec<(u64, Pattern)>,
    /// Pattern loaded by [`Self::load_jacobian`].
    loaded: Option<usize>,
    /// Reused buffer for [`NewtonSystem::pattern`].
    entries: Vec<(usize, usize)>,
    ws: Workspace,
    symbolic_factorizations: usize,
}

impl Default for NewtonSolver {
    fn default() -> Self {
        Self::new(NewtonParams::default())
    }
}

impl std::fmt::Debug for NewtonSolver {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("NewtonSolver")
            .field("params", &self.params)
            .field("cached_patterns", &self.patterns.len())
            .field("symbolic_factorizations", &self.symbolic_factorizations)
            .field("numeric_factorizations", &self.ws.numeric_factorizations)
            .finish_non_exhaustive()
    }
}

impl NewtonSolver {
    /// Creates a solver with the given parameters and an empty pattern cache.
    pub fn new(params: NewtonParams) -> Self {
        Self {
            params,
            patterns: Vec::new(),
            loaded: None,
            entries: Vec::new(),
            ws: Workspace {
                values: Vec::new(),
                r: Vec::new(),
                dx: Vec::new(),
                x_trial: Vec::new(),
                r_trial: Vec::new(),
                mem: MemBuffer::new(StackReq::EMPTY),
                mem_req: StackReq::EMPTY,
                numeric_factorizations: 0,
            },
            symbolic_factorizations: 0,
        }
    }

    /// The parameters in use.
    pub fn params(&self) -> &NewtonParams {
        &self.params
    }

    /// Mutable access to the parameters (take effect at the next solve).
    pub fn params_mut(&mut self) -> &mut NewtonParams {
        &mut self.params
    }

    /// Number of symbolic LU analyses ever performed (one per distinct
    /// pattern key seen).
    pub fn symbolic_factorizations(&self) -> usize {
        self.symbolic_factorizations
    }

    /// Number of numeric LU factorisations ever performed (excluding the
    /// one-off dense warm-up per new pattern).
    pub fn numeric_factorizations(&self) -> u64 {
        self.ws.numeric_factorizations
    }

    /// Number of pattern keys currently cached.
    pub fn cached_patterns(&self) -> usize {
        self.patterns.len()
    }

    /// Evaluates the residual into `r` and returns the Jacobian of `sys` at
    /// `x` as a dense row-major `n × n` matrix (`J[i * n + j]`; entries
    /// outside the declared pattern are 0).
    ///
    /// Allocates; meant for tests, e.g. checking a system's analytic
    /// Jacobian against finite differences.
    ///
    /// # Panics
    /// If `x` or `r` does not have length `sys.dim()`, or the system writes
    /// an entry outside its pattern.
    pub fn dense_jacobian<S: NewtonSystem>(sys: &mut S, x: &[f64], r: &mut [f64]) -> Vec<f64> {
        let n = sys.dim();
        assert!(x.len() == n && r.len() == n, "x and r must have length {n}");
        let mut entries = Vec::new();
        sys.pattern(&mut entries);
        let mut slot = vec![u32::MAX; n * n];
        for &(row, col) in &entries {
            assert!(
                row < n && col < n,
                "pattern entry ({row}, {col}) out of range"
            );
            slot[row * n + col] = (row * n + col) as u32;
        }
        let mut values = vec![0.0; n * n];
        r.fill(0.0);
        let mut sink = JacobianSink {
            n,
            slot: &slot,
            values: &mut values,
        };
        sys.eval(x, r, Some(&mut sink));
        values
    }

    /// Solves `sys(x) = 0` in place, starting from the guess in `x`.
    ///
    /// On success `x` holds the converged iterate. On error `x` holds the
    /// last accepted iterate.
    ///
    /// # Errors
    /// * [`SolverError::Singular`] — the Jacobian is structurally or
    ///   numerically singular at some iterate.
    /// * [`SolverError::Diverged`] — `max_iterations` reached, or the line
    ///   search could not decrease the scaled residual max-norm.
    /// * [`SolverError::NonFinite`] — NaN/∞ in the residual or Jacobian at
    ///   an iterate, or in every trial residual of a line search.
    ///
    /// # Panics
    /// If `x.len() != sys.dim()`, if a cached pattern key is reused with a
    /// different dimension, if the pattern has an out-of-range entry, or if
    /// the system writes a Jacobian entry outside its pattern.
    pub fn solve<S: NewtonSystem>(
        &mut self,
        sys: &mut S,
        x: &mut [f64],
    ) -> Result<NewtonReport, SolverError> {
        let n = sys.dim();
        assert_eq!(
            x.len(),
            n,
            "x has length {} but the system has dimension {n}",
            x.len()
        );
        if n == 0 {
            return Ok(NewtonReport {
                iterations: 0,
                residual: 0.0,
                factorizations: 0,
            });
        }
        let index = self.register(sys);
        let pattern = &mut self.patterns[index].1;
        self.ws.run(&self.params, pattern, sys, x)
    }

    /// Index in `self.patterns` of `sys`'s pattern, registered (symbolic LU,
    /// workspace growth) when its key is new.
    fn register<S: NewtonSystem>(&mut self, sys: &S) -> usize {
        let n = sys.dim();
        let key = sys.pattern_key();
        // A linear scan: a handful of patterns at most, cheaper than hashing.
        let index = match self.patterns.iter().position(|(k, _)| *k == key) {
            Some(i) => i,
            None => {
                self.entries.clear();
                sys.pattern(&mut self.entries);
                let mut pattern = Pattern::build(n, &mut self.entries);
                self.symbolic_factorizations += 1;
                self.ws.prepare(&mut pattern);
                self.patterns.push((key, pattern));
                self.patterns.len() - 1
            }
        };
        let pattern = &self.patterns[index].1;
        assert_eq!(
            pattern.n, n,
            "pattern key {key:#x} was registered with dimension {} but the system now has dimension {n}",
            pattern.n
        );
        index
    }

    /// **Benchmark / diagnostic hook** (one Newton iteration taken apart):
    /// evaluates the residual and the Jacobian of `sys` at `x` into the
    /// solver's workspace, registering the pattern first if its key is new.
    /// Follow with [`Self::factorize_loaded`]. Allocation-free once the
    /// pattern is cached.
    ///
    /// # Panics
    /// If `x.len() != sys.dim()` (and as [`Self::solve`]).
    pub fn load_jacobian<S: NewtonSystem>(&mut self, sys: &mut S, x: &[f64]) {
        let n = sys.dim();
        assert_eq!(
            x.len(),
            n,
            "x has length {} but the system has dimension {n}",
            x.len()
        );
        let index = self.register(sys);
        let pattern = &self.patterns[index].1;
        set_len(&mut self.ws.values, pattern.row_idx.len());
        set_len(&mut self.ws.r, n);
        Workspace::eval_with_jacobian(&mut self.ws.values, pattern, sys, x, &mut self.ws.r);
        self.loaded = Some(index);
    }

    /// **Benchmark / diagnostic hook**: the numeric LU of the Jacobian last
    /// loaded by [`Self::load_jacobian`] (the same call [`Self::solve`] makes
    /// each iteration: symbolic analysis reused, storage reused) and, when
    /// `dx` is given, the Newton step `J Δx = −r` into it. Does not count in
    /// [`Self::numeric_factorizations`].
    ///
    /// # Errors
    /// [`SolverError::Singular`] as [`Self::solve`].
    ///
    /// # Panics
    /// If nothing was loaded, or `dx` does not have the system's dimension.
    pub fn factorize_loaded(&mut self, dx: Option<&mut [f64]>) -> Result<(), SolverError> {
        let index = self
            .loaded
            .expect("factorize_loaded: call load_jacobian first");
        let pattern = &mut self.patterns[index].1;
        let mut dx = dx;
        if let Some(dx) = dx.as_deref_mut() {
            assert_eq!(dx.len(), pattern.n, "dx has the wrong length");
            for (d, &ri) in dx.iter_mut().zip(&self.ws.r) {
                *d = -ri;
            }
        }
        factor_and_solve(pattern, &self.ws.values, &mut self.ws.mem, dx)
    }
}

/// Scaled residual max-norm `max_i |r_i| / scale_i`; `None` if any entry is
/// not finite.
fn scaled_norm<S: NewtonSystem>(sys: &S, r: &[f64]) -> Option<f64> {
    let mut norm = 0.0f64;
    for (i, &ri) in r.iter().enumerate() {
        if !ri.is_finite() {
            return None;
        }
        norm = norm.max(ri.abs() / sys.residual_scale(i));
    }
    Some(norm)
}

/// Numeric LU of `values` (CSC order of `pattern`) into the pattern's own
/// storage, reusing its symbolic analysis; then, when `rhs` is given, solves
/// `J x = rhs` in place.
fn factor_and_solve(
    pattern: &mut Pattern,
    values: &[f64],
    mem: &mut MemBuffer,
    rhs: Option<&mut [f64]>,
) -> Result<(), SolverError> {
    let n = pattern.n;
    let Pattern {
        col_ptr,
        row_idx,
        symbolic,
        numeric,
        factored,
        ..
    } = pattern;
    *factored = false;
    let matrix = SparseColMatRef::new(
        SymbolicSparseColMatRef::new_checked(n, n, col_ptr, None, row_idx),
        values,
    );
    let lu = match symbolic.factorize_numeric_lu(
        numeric,
        matrix,
        Par::Seq,
        MemStack::new(mem),
        Default::default(),
    ) {
        Ok(lu) => lu,
        Err(LuError::SymbolicSingular { index }) => {
            let equation = symbolic.col_perm().arrays().0[index];
            return Err(SolverError::Singular { equation });
        }
        Err(LuError::Generic(e)) => panic!("faer numeric LU failed: {e:?}"),
    };
    *factored = true;
    if let Some(rhs) = rhs {
        lu.solve_in_place_with_conj(
            Conj::No,
            MatMut::from_column_major_slice_mut(rhs, n, 1),
            Par::Seq,
            MemStack::new(mem),
        );
    }
    Ok(())
}

fn set_len(v: &mut Vec<f64>, len: usize) {
    v.resize(len, 0.0);
}

impl Workspace {
    /// Grows the reusable storage for a newly registered pattern.
    fn prepare(&mut self, pattern: &mut Pattern) {
        let n = pattern.n;
        let nnz = pattern.row_idx.len();
        // Reserve, so that later switches between cached patterns never grow.
        self.values.reserve(nnz.saturating_sub(self.values.len()));
        for v in [
            &mut self.r,
            &mut self.dx,
            &mut self.x_trial,
            &mut self.r_trial,
        ] {
            v.reserve(n.saturating_sub(v.len()));
        }

        let sym = &pattern.symbolic;
        let req = sym
            .factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default())
            .or(sym.solve_in_place_scratch::<f64>(1, Par::Seq));
        let grown = self.mem_req.or(req);
        if grown != self.mem_req {
            self.mem_req = grown;
            self.mem = MemBuffer::new(grown);
        }

        {
            // Dense warm-up (see the module docs): grows faer's L/U storage to
            // the worst case for dimension n, so refactorisations never
            // allocate. Diagonally dominant, hence nonsingular.
            let col_ptr: Vec<usize> = (0..=n).map(|j| j * n).collect();
            let row_idx: Vec<usize> = (0..n * n).map(|k| k % n).collect();
            let values: Vec<f64> = (0..n * n)
                .map(|k| if k % n == k / n { 2.0 * n as f64 } else { 1.0 })
                .collect();
            let sym_dense = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
            let dense = SparseColMatRef::new(sym_dense, &values);
            let stack = MemStack::new(&mut self.mem);
            pattern
                .symbolic
                .factorize_numeric_lu(
                    &mut pattern.numeric,
                    dense,
                    Par::Seq,
                    stack,
                    Default::default(),
                )
                .unwrap_or_else(|e| panic!("faer dense warm-up LU failed: {e:?}"));
        }
    }

    /// Evaluates residual and Jacobian at `x` into `r` / `values`.
    fn eval_with_jacobian<S: NewtonSystem>(
        values: &mut [f64],
        pattern: &Pattern,
        sys: &mut S,
        x: &[f64],
        r: &mut [f64],
    ) {
        values.fill(0.0);
        r.fill(0.0);
        let mut sink = JacobianSink {
            n: pattern.n,
            slot: &pattern.slot,
            values,
        };
        sys.eval(x, r, Some(&mut sink));
    }

    fn run<S: NewtonSystem>(
        &mut self,
        params: &NewtonParams,
        pattern: &mut Pattern,
        sys: &mut S,
        x: &mut [f64],
    ) -> Result<NewtonReport, SolverError> {
        let n = pattern.n;
        let nnz = pattern.row_idx.len();
        set_len(&mut self.values, nnz);
        set_len(&mut self.r, n);
        set_len(&mut self.dx, n);
        set_len(&mut self.x_trial, n);
        set_len(&mut self.r_trial, n);

        // Every iteration factors once, so the number of numeric
        // factorisations in this solve is `iter` at the top of the loop.
        // Chord start with the pattern's last factorisation, see
        // `NewtonParams::chord_steps`.
        let mut chord = 0usize;
        if params.chord_steps > 0 && pattern.factored {
            self.r.fill(0.0);
            sys.eval(x, &mut self.r, None);
            if let Some(mut rnorm) = scaled_norm(sys, &self.r) {
                loop {
                    if rnorm <= params.residual_tol {
                        return Ok(NewtonReport {
                            iterations: chord,
                            residual: rnorm,
                            factorizations: 0,
                        });
                    }
                    if chord == params.chord_steps {
                        break;
                    }
                    for (d, &ri) in self.dx.iter_mut().zip(&self.r) {
                        *d = -ri;
                    }
                    // `numeric` is the output of `factorize_numeric_lu` for
                    // this pattern's `symbolic` (`factored`), as required.
                    LuRef::new_unchecked(&pattern.symbolic, &pattern.numeric)
                        .solve_in_place_with_conj(
                            Conj::No,
                            MatMut::from_column_major_slice_mut(&mut self.dx, n, 1),
                            Par::Seq,
                            MemStack::new(&mut self.mem),
                        );
                    for ((xt, &xi), &d) in self.x_trial.iter_mut().zip(x.iter()).zip(&self.dx) {
                        *xt = xi + d;
                    }
                    self.r_trial.fill(0.0);
                    sys.eval(&self.x_trial, &mut self.r_trial, None);
                    match scaled_norm(sys, &self.r_trial) {
                        Some(t) if t <= params.chord_contraction * rnorm => {
                            x.copy_from_slice(&self.x_trial);
                            std::mem::swap(&mut self.r, &mut self.r_trial);
                            chord += 1;
                            // At the observed contraction, would the chord
                            // reach the tolerance within its budget? If not,
                            // refactor now rather than spend the steps.
                            let rate = t / rnorm;
                            rnorm = t;
                            if rnorm > params.residual_tol {
                                let needed = (params.residual_tol / rnorm).ln() / rate.ln();
                                // Negated so that a NaN estimate also stops.
                                #[allow(clippy::neg_cmp_op_on_partial_ord)]
                                let hopeless = !(needed <= (params.chord_steps - chord) as f64);
                                if hopeless {
                                    break;
                                }
                            }
                        }
                        _ => break,
                    }
                }
            }
        }

        // Whether `r` / `values` hold residual and Jacobian at `x`.
        let mut have_jacobian = false;

        for iter in 0..=params.max_iterations {
            if !have_jacobian {
                Self::eval_with_jacobian(&mut self.values, pattern, sys, x, &mut self.r);
            }
            let Some(rnorm) = scaled_norm(sys, &self.r) else {
                return Err(SolverError::NonFinite { iter });
            };
            if rnorm <= params.residual_tol {
                return Ok(NewtonReport {
                    iterations: chord + iter,
                    residual: rnorm,
                    factorizations: iter,
                });
            }
            if iter == params.max_iterations {
                return Err(SolverError::Diverged {
                    iter,
                    residual: rnorm,
                });
            }
            if self.values.iter().any(|v| !v.is_finite()) {
                return Err(SolverError::NonFinite { iter });
            }

            // Factor J and solve J Δx = −r.
            for (d, &ri) in self.dx.iter_mut().zip(&self.r) {
                *d = -ri;
            }
            factor_and_solve(pattern, &self.values, &mut self.mem, Some(&mut self.dx))?;
            self.numeric_factorizations += 1;
            if let Some(equation) = self.dx.iter().position(|d| !d.is_finite()) {
                // A zero pivot: 1/0 propagated through the triangular solves.
                return Err(SolverError::Singular { equation });
            }

            // Step test (round-off floor), see `NewtonParams`.
            let negligible = self
                .dx
                .iter()
                .zip(x.iter())
                .all(|(d, xi)| d.abs() <= params.step_tol * (1.0 + xi.abs()));
            if negligible && rnorm <= params.step_residual_factor * params.residual_tol {
                return Ok(NewtonReport {
                    iterations: chord + iter,
                    residual: rnorm,
                    factorizations: iter + 1,
                });
            }

            // Backtracking line search on the scaled residual max-norm. The
            // full step is evaluated with the Jacobian (the factored values
            // are no longer needed), so an accepted full step — the usual
            // case near a root — costs one evaluation per iteration;
            // halved steps evaluate the residual only.
            let mut alpha = 1.0;
            let mut accepted = false;
            let mut any_finite = false;
            for k in 0..=params.max_backtracks {
                for ((xt, &xi), &d) in self.x_trial.iter_mut().zip(x.iter()).zip(&self.dx) {
                    *xt = xi + alpha * d;
                }
                if k == 0 {
                    Self::eval_with_jacobian(
                        &mut self.values,
                        pattern,
                        sys,
                        &self.x_trial,
                        &mut self.r_trial,
                    );
                } else {
                    self.r_trial.fill(0.0);
                    sys.eval(&self.x_trial, &mut self.r_trial, None);
                }
                if let Some(trial_norm) = scaled_norm(sys, &self.r_trial) {
                    any_finite = true;
                    if trial_norm < rnorm {
                        have_jacobian = k == 0;
                        accepted = true;
                        break;
                    }
                }
                alpha *= 0.5;
            }
            if !accepted && rnorm <= params.step_residual_factor * params.residual_tol {
                // No decrease is possible, and the residual is already within
                // the round-off allowance of the step test: the floor.
                return Ok(NewtonReport {
                    iterations: chord + iter,
                    residual: rnorm,
                    factorizations: iter + 1,
                });
            }
            if !accepted {
                return Err(if any_finite {
                    SolverError::Diverged {
                        iter,
                        residual: rnorm,
                    }
                } else {
                    SolverError::NonFinite { iter }
                });
            }
            x.copy_from_slice(&self.x_trial);
            std::mem::swap(&mut self.r, &mut self.r_trial);
        }
        unreachable!("the loop returns at iter == max_iterations")
    }
}

//! Damped Newton iteration with a per-pattern cached sparse LU (faer),
//! optionally with chord steps (a kept factorisation) between
//! refactorisations.
//!
//! # Allocation behaviour
//!
//! The first solve of a pattern key allocates: the CSC structure, the dense
//! slot map, faer's COLAMD ordering (column approximate minimum degree),
//! the pattern's numeric-LU storage (grown to the dense worst case, see
//! [`crate::lu`]), its compiled program, and, when the pattern needs more
//! than any earlier one, the residual/step vectors, the Jacobian value
//! array, the `MemBuffer` scratch and the compilation's scratch (kept, see
//! [`crate::compiled`]). After that, solving a system with an already seen key performs
//! **no heap allocation** (checked by `tests/no_alloc.rs`).

use faer::dyn_stack::{MemBuffer, StackReq};

use crate::compiled::CompileScratch;
use crate::lu::{FactorPath, Factors, Pattern};
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
    /// **Chord steps** (simplified Newton): how many steps in a row may
    /// reuse the pattern's last factorisation — kept from an earlier
    /// iterate of this solve or from an earlier solve — instead of
    /// factoring the Jacobian at the iterate. A chord step
    /// `Δx = −J_old⁻¹ r(x)` costs one residual evaluation and one pair of
    /// triangular solves. It is kept when it converged or contracted the
    /// scaled residual max-norm by [`Self::chord_contraction`] at least
    /// (else it is discarded); the next step refactors (a full Newton step
    /// at the iterate, then chord steps again with that factorisation) when
    /// it was discarded, when, at the observed contraction, the tolerance
    /// would not be reached within the remaining chord steps, or after a
    /// damped full step (far from the root).
    /// Convergence is still the residual test on the true residual
    /// (tolerances unchanged); `max_iterations` counts the full Newton
    /// steps. `0` disables chord steps: every step refactors (pure Newton).
    /// Default: `0`.
    pub chord_steps: usize,
    /// Contraction a chord step must reach to be kept (unless it
    /// converged), `‖r(x + Δx)‖ ≤ chord_contraction · ‖r(x)‖`; a kept step
    /// is followed by more chord steps only while they are on track (see
    /// [`Self::chord_steps`]). Default: `0.5`: a step that halves the
    /// residual is progress worth keeping, and the next chord step costs a
    /// sixth of a refactorisation (a residual and a solve against a
    /// Jacobian, its numeric LU, a residual and a solve). Measured on the
    /// `bench/peer` cases against `0.1` (instructions per step, callgrind):
    /// the moving flight −2 %, the robot hanging from its feet −4 %,
    /// standing −5 %, the hexapod walking −4 %; the passive fall's
    /// landings unchanged.
    pub chord_contraction: f64,
    /// **Renewal of the kept factorisation across solves**: the cost of a
    /// refactorisation in chord steps (its numeric LU and Jacobian, beyond
    /// the residual and the solve a chord step costs too). A kept
    /// factorisation grows staler from solve to solve, and the solves need
    /// more chord steps; a solve starts with a refactorisation (at the
    /// initial guess) when the previous solve needed more chord steps than
    /// the average cost per solve since the last factorisation,
    /// `(refactor_cost + chord steps since) / solves since` — the
    /// renewal rule that minimises the average cost per solve when the
    /// running cost grows — except after a solve of a single chord step,
    /// which no factorisation could make cheaper. `0` disables it (the
    /// factorisation is renewed only when a chord step contracts too
    /// little). Default: `0`.
    pub refactor_cost: f64,
    /// **The compiled LU** (`crate::compiled`): each pattern's numeric LU
    /// compiled, at its first factorisation, into a flat list of
    /// operations on faer's column ordering and a row order chosen on
    /// those values (threshold Markowitz pivoting); later factorisations
    /// run the list and re-verify each pivot (at least a thousandth of
    /// its column, `compiled::PIVOT_THRESHOLD`); a failed pivot is
    /// perturbed and the solves corrected to the exact system
    /// ([`NewtonSolver::lu_corrected`]); a new set of exact zeros (a
    /// complementarity branch switched) that cannot be factored so gets
    /// a program of its own; when none of that can be done, the
    /// factorisation falls back to faer's pivoting LU
    /// ([`NewtonSolver::lu_fallbacks`]). `false`: every factorisation by
    /// faer's pivoting LU, the reference path. Solutions agree to
    /// round-off. Default: `true`.
    pub compiled_lu: bool,
    /// **Bound of the pattern cache**: at most this many contact-state
    /// patterns keep their symbolic analysis, compiled program and
    /// bookkeeping; registering one more evicts the least recently used
    /// one (never the one loaded by [`NewtonSolver::load_jacobian`]),
    /// which is analysed again if its states come back
    /// ([`NewtonSolver::evicted_patterns`]). A pattern of the 3D hexapod
    /// with every contact point holds about 0.15 MB (its value map, the
    /// compiled program and its streams), and a contact-rich landing
    /// meets up to 211 patterns in 1.5 s (the 1000 runs of
    /// `examples/sweep_hexapod_landing_1000.toml`, none evicted): the
    /// bound keeps a long tumbling run's memory finite. `0`: unbounded.
    /// Default: `256`.
    pub max_patterns: usize,
    /// **The watchdog of a crawl**: how many full Newton steps may be
    /// taken whole, without the line search, once the iteration crawls
    /// ([`Self::crawl_steps`] full steps in a row cut to
    /// [`Self::crawl_step`] or less) and a whole step does not decrease the
    /// residual. The iterate before them is kept; the first of them whose
    /// residual is below its residual ends the watch (the iteration goes
    /// on from there, chord steps again allowed); when none is after this
    /// many, the iteration returns to the kept iterate and takes its damped
    /// step, and the watch may start again at the next step of the crawl.
    /// A solve that reaches [`Self::max_iterations`] while watching returns
    /// the kept iterate (the better one). Semismooth Newton on the
    /// contact rows' kinks (a point on the edge of its friction disc, the
    /// normal's `min`) crawls so: the whole step crosses a kink and
    /// raises the max-norm, and the line search cuts it to 1/128 and less
    /// for tens of iterations, each 0.2 % lower; the whole steps cross
    /// the kink and converge beyond it (see `docs/reference.md`, *Speed*).
    /// `0` disables it. Default: `0` (the 3D models take 5).
    pub watchdog: usize,
    /// Full steps in a row cut to [`Self::crawl_step`] or less that make
    /// a crawl (see [`Self::watchdog`]). Default: `2`.
    pub crawl_steps: usize,
    /// The step length (fraction of the Newton step) at or below which a
    /// damped full step is a step of a crawl (see [`Self::watchdog`]).
    /// Default: `1/16`: the 3D walk's damped steps, where its feet land,
    /// are longer, and its path is the same with the watchdog as without.
    pub crawl_step: f64,
    /// Whether the watchdog, returning to its kept iterate, asks the
    /// system whether to give the solve up there
    /// ([`crate::NewtonSystem::abandon_crawl`]; a system that never does
    /// answers `false`). Default: `true`.
    pub give_up_crawls: bool,
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
            chord_contraction: 0.5,
            refactor_cost: 0.0,
            compiled_lu: true,
            max_patterns: 256,
            watchdog: 0,
            crawl_steps: 2,
            crawl_step: 1.0 / 16.0,
            give_up_crawls: true,
        }
    }
}

/// Outcome of a successful [`NewtonSolver::solve`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NewtonReport {
    /// Newton steps applied to `x` (0 when the initial guess was converged),
    /// chord steps included.
    pub iterations: usize,
    /// Of [`Self::iterations`], the chord steps: steps with a factorisation
    /// kept from an earlier iterate or solve (see
    /// [`NewtonParams::chord_steps`]). The others are full Newton steps.
    pub chord_iterations: usize,
    /// Scaled residual max-norm `max_i |r_i| / residual_scale(i)` at the
    /// returned `x`.
    pub residual: f64,
    /// Numeric LU factorisations performed during this solve (without chord
    /// steps, see [`NewtonParams::chord_steps`]: equals `iterations`, plus
    /// one when the step test ended the solve; with them, one per full
    /// Newton step, plus one when the step test ended the solve).
    pub factorizations: usize,
}

/// Everything reused across solves (sized to the largest pattern seen).
struct Workspace {
    /// Jacobian values in CSC order of the current pattern.
    values: Vec<f64>,
    r: Vec<f64>,
    dx: Vec<f64>,
    x_trial: Vec<f64>,
    r_trial: Vec<f64>,
    /// The iterate and residual kept by the watchdog
    /// ([`NewtonParams::watchdog`]).
    x_kept: Vec<f64>,
    r_kept: Vec<f64>,
    mem: MemBuffer,
    mem_req: StackReq,
    /// Scratch of the compiled LU's compilations (grown to the largest
    /// reduced dimension compiled, see `CompileScratch`).
    compile: CompileScratch,
    numeric_factorizations: u64,
    /// Steps applied to the unknowns by every solve, chord steps included.
    steps_taken: u64,
    /// Of [`Self::steps_taken`], the chord steps.
    chord_steps_taken: u64,
    /// Factorisations by the compiled LU.
    compiled_factorizations: u64,
    /// Compiled factorisations abandoned for faer's (a pivot failed).
    lu_fallbacks: u64,
    /// Compiled factorisations with perturbed pivots, their solves
    /// corrected.
    lu_corrected: u64,
}

impl Clone for Workspace {
    /// The buffers' values (scratch; overwritten before use), a fresh
    /// scratch arena of the same size (faer's `MemBuffer` is not `Clone`)
    /// and an empty compilation scratch (grown by the clone's first
    /// compilation, which allocates its program anyway).
    fn clone(&self) -> Self {
        Self {
            values: self.values.clone(),
            r: self.r.clone(),
            dx: self.dx.clone(),
            x_trial: self.x_trial.clone(),
            r_trial: self.r_trial.clone(),
            x_kept: self.x_kept.clone(),
            r_kept: self.r_kept.clone(),
            mem: MemBuffer::new(self.mem_req),
            mem_req: self.mem_req,
            compile: CompileScratch::default(),
            numeric_factorizations: self.numeric_factorizations,
            steps_taken: self.steps_taken,
            chord_steps_taken: self.chord_steps_taken,
            compiled_factorizations: self.compiled_factorizations,
            lu_fallbacks: self.lu_fallbacks,
            lu_corrected: self.lu_corrected,
        }
    }
}

/// Newton solver with a cache of symbolic LU factorisations keyed by
/// [`NewtonSystem::pattern_key`].
///
/// Each iteration evaluates `r(x)` and the Jacobian `J(x)`, refactors `J`
/// numerically (reusing the symbolic analysis of its pattern), solves
/// `J Δx = −r` and takes the step with a backtracking line search on the
/// scaled residual max-norm (see [`NewtonParams`] for the convergence rule).
///
/// A clone carries the kept factorisations and their bookkeeping (what
/// the chord steps of the next solve use): a clone solves the next system
/// exactly as the original would (the stepping API's `state()`).
#[derive(Clone)]
pub struct NewtonSolver {
    params: NewtonParams,
    /// `(pattern key, pattern, last use)`: the cache, at most
    /// [`NewtonParams::max_patterns`] long.
    patterns: Vec<(u64, Pattern, u64)>,
    /// Registrations so far: the clock of `last use`.
    uses: u64,
    /// Index of the last pattern used (checked first).
    last: usize,
    /// Patterns built so far: the next pattern's id.
    built: usize,
    /// Patterns evicted from the cache.
    evicted: usize,
    /// Numeric LU storage, one per dimension met.
    factors: Vec<Factors>,
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
            uses: 0,
            last: 0,
            built: 0,
            evicted: 0,
            factors: Vec::new(),
            loaded: None,
            entries: Vec::new(),
            ws: Workspace {
                values: Vec::new(),
                r: Vec::new(),
                dx: Vec::new(),
                x_trial: Vec::new(),
                r_trial: Vec::new(),
                x_kept: Vec::new(),
                r_kept: Vec::new(),
                mem: MemBuffer::new(StackReq::EMPTY),
                mem_req: StackReq::EMPTY,
                compile: CompileScratch::default(),
                numeric_factorizations: 0,
                steps_taken: 0,
                chord_steps_taken: 0,
                compiled_factorizations: 0,
                lu_fallbacks: 0,
                lu_corrected: 0,
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

    /// Steps applied to the unknowns by every solve so far (full Newton
    /// steps and chord steps), those of failed solves (diverged,
    /// singular, given up) included: what a caller counts as the
    /// iterations a computation spent (a solve's
    /// [`NewtonReport::iterations`] covers only a solve that converged).
    pub fn steps_taken(&self) -> u64 {
        self.ws.steps_taken
    }

    /// Of [`Self::steps_taken`], the chord steps.
    pub fn chord_steps_taken(&self) -> u64 {
        self.ws.chord_steps_taken
    }

    /// Of [`Self::numeric_factorizations`], those done by the compiled LU
    /// (see [`NewtonParams::compiled_lu`]).
    pub fn compiled_factorizations(&self) -> u64 {
        self.ws.compiled_factorizations
    }

    /// Compiled factorisations abandoned because a pivot failed its check
    /// and could not be perturbed (each then factored by faer).
    pub fn lu_fallbacks(&self) -> u64 {
        self.ws.lu_fallbacks
    }

    /// Of [`Self::compiled_factorizations`], those whose failed pivots
    /// were perturbed and whose solves are corrected (see
    /// [`NewtonParams::compiled_lu`]).
    pub fn lu_corrected(&self) -> u64 {
        self.ws.lu_corrected
    }

    /// Patterns evicted from the cache so far
    /// ([`NewtonParams::max_patterns`]).
    pub fn evicted_patterns(&self) -> usize {
        self.evicted
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
        // Slots below `u32::MAX`, the mark of an entry outside the pattern.
        assert!(n * n < u32::MAX as usize, "dimension {n} too large");
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
                chord_iterations: 0,
                residual: 0.0,
                factorizations: 0,
            });
        }
        let index = self.register(sys);
        let pattern = &mut self.patterns[index].1;
        let factors = &mut self.factors[pattern.factors];
        self.ws.run(&self.params, pattern, factors, sys, x)
    }

    /// Index in `self.patterns` of `sys`'s pattern, registered (symbolic LU,
    /// workspace growth) when its key is new, in the place of the least
    /// recently used pattern when the cache is full.
    fn register<S: NewtonSystem>(&mut self, sys: &S) -> usize {
        let n = sys.dim();
        let key = sys.pattern_key();
        self.uses += 1;
        // The last pattern first, then a linear scan: cheaper than hashing
        // for the patterns a run meets.
        let found = if self.patterns.get(self.last).is_some_and(|p| p.0 == key) {
            Some(self.last)
        } else {
            self.patterns.iter().position(|p| p.0 == key)
        };
        let index = match found {
            Some(i) => i,
            None => {
                self.entries.clear();
                sys.pattern(&mut self.entries);
                self.ws.prepare(n, self.entries.len());
                let id = self.built;
                self.built += 1;
                let mut pattern = Pattern::build(id, n, &mut self.entries);
                let m = pattern.m;
                pattern.factors = match self.factors.iter().position(|f| f.dim() == m) {
                    Some(f) => f,
                    None => {
                        self.factors.push(Factors::new(m));
                        self.factors.len() - 1
                    }
                };
                self.symbolic_factorizations += 1;
                let max = self.params.max_patterns;
                let victim = (max > 0 && self.patterns.len() >= max)
                    .then(|| {
                        self.patterns
                            .iter()
                            .enumerate()
                            .filter(|&(i, _)| Some(i) != self.loaded)
                            .min_by_key(|(_, p)| p.2)
                            .map(|(i, _)| i)
                    })
                    .flatten();
                match victim {
                    Some(i) => {
                        self.patterns[i] = (key, pattern, 0);
                        self.evicted += 1;
                        i
                    }
                    None => {
                        self.patterns.push((key, pattern, 0));
                        self.patterns.len() - 1
                    }
                }
            }
        };
        self.patterns[index].2 = self.uses;
        self.last = index;
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
        set_len(&mut self.ws.values, pattern.nnz());
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
        let factors = &mut self.factors[pattern.factors];
        factors.factor(
            pattern,
            &self.ws.values,
            &mut self.ws.mem,
            &mut self.ws.compile,
            self.params.compiled_lu,
        )?;
        if let Some(dx) = dx {
            assert_eq!(dx.len(), pattern.n, "dx has the wrong length");
            negate(dx, &self.ws.r);
            factors.solve(pattern, dx);
        }
        Ok(())
    }

    /// **Benchmark / diagnostic hook** (the solve of a chord step): the
    /// Newton step `J Δx = −r` into `dx` for the residual last loaded by
    /// [`Self::load_jacobian`], with the last factorisation of its pattern
    /// (no refactorisation).
    ///
    /// # Panics
    /// If nothing was loaded, the pattern was never factored, or `dx` does
    /// not have the system's dimension.
    pub fn solve_loaded(&mut self, dx: &mut [f64]) {
        let index = self.loaded.expect("solve_loaded: call load_jacobian first");
        let pattern = &mut self.patterns[index].1;
        let factors = &mut self.factors[pattern.factors];
        assert!(
            factors.holds(pattern),
            "solve_loaded: no factorisation of the loaded pattern"
        );
        assert_eq!(dx.len(), pattern.n, "dx has the wrong length");
        negate(dx, &self.ws.r);
        factors.solve(pattern, dx);
    }
}

/// Scaled residual max-norm `max_i |r_i| / scale_i` (as `|r_i| · weight_i`);
/// `None` if any entry is not finite.
fn scaled_norm<S: NewtonSystem>(sys: &S, r: &[f64]) -> Option<f64> {
    let mut norm = 0.0f64;
    for (i, &ri) in r.iter().enumerate() {
        if !ri.is_finite() {
            return None;
        }
        // `norm.max(v)` without its NaN handling: `ri` is finite here.
        let v = ri.abs() * sys.residual_weight(i);
        if v > norm {
            norm = v;
        }
    }
    Some(norm)
}

fn set_len(v: &mut Vec<f64>, len: usize) {
    v.resize(len, 0.0);
}

/// `dx = −r`.
fn negate(dx: &mut [f64], r: &[f64]) {
    for (d, &ri) in dx.iter_mut().zip(r) {
        *d = -ri;
    }
}

/// `x_trial = x + alpha·dx`.
fn trial(x_trial: &mut [f64], x: &[f64], dx: &[f64], alpha: f64) {
    for ((xt, &xi), &d) in x_trial.iter_mut().zip(x).zip(dx) {
        *xt = xi + alpha * d;
    }
}

impl Workspace {
    /// Grows the reusable storage for a new pattern of dimension `n` with
    /// at most `nnz` entries.
    fn prepare(&mut self, n: usize, nnz: usize) {
        // Reserve, so that later switches between cached patterns never grow.
        self.values.reserve(nnz.saturating_sub(self.values.len()));
        for v in [
            &mut self.r,
            &mut self.dx,
            &mut self.x_trial,
            &mut self.r_trial,
            &mut self.x_kept,
            &mut self.r_kept,
        ] {
            v.reserve(n.saturating_sub(v.len()));
        }
        let grown = self.mem_req.or(Factors::scratch(n));
        if grown != self.mem_req {
            self.mem_req = grown;
            self.mem = MemBuffer::new(grown);
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

    /// Evaluates the residual alone at `x` into `r`.
    fn eval_residual<S: NewtonSystem>(sys: &mut S, x: &[f64], r: &mut [f64]) {
        r.fill(0.0);
        sys.eval(x, r, None);
    }

    fn run<S: NewtonSystem>(
        &mut self,
        params: &NewtonParams,
        pattern: &mut Pattern,
        factors: &mut Factors,
        sys: &mut S,
        x: &mut [f64],
    ) -> Result<NewtonReport, SolverError> {
        let mut run = 0;
        let result = self.iterate(params, pattern, factors, sys, x, &mut run);
        pattern.solved(run);
        result
    }

    /// The iteration of [`Self::run`]; `run` ends as the number of chord
    /// steps since the last factorisation.
    fn iterate<S: NewtonSystem>(
        &mut self,
        params: &NewtonParams,
        pattern: &mut Pattern,
        factors: &mut Factors,
        sys: &mut S,
        x: &mut [f64],
        run: &mut usize,
    ) -> Result<NewtonReport, SolverError> {
        let n = pattern.n;
        let nnz = pattern.nnz();
        set_len(&mut self.values, nnz);
        set_len(&mut self.r, n);
        set_len(&mut self.dx, n);
        set_len(&mut self.x_trial, n);
        set_len(&mut self.r_trial, n);
        set_len(&mut self.x_kept, n);
        set_len(&mut self.r_kept, n);
        // The watchdog (`NewtonParams::watchdog`): full steps in a row cut
        // to `crawl_step` or less, and, while watching, the kept iterate's
        // residual norm and the whole steps left.
        let mut crawl = 0usize;
        let mut watch: Option<(f64, usize)> = None;
        // The step right after a return to the kept iterate is damped.
        let mut damp = false;

        let chords = params.chord_steps > 0;
        // Full Newton steps and chord steps applied to `x`, factorisations.
        let (mut full, mut chord, mut factorizations) = (0usize, 0usize, 0usize);
        // Chord steps since the last factorisation (or the start).
        *run = 0;
        // Whether the pattern's factorisation may serve the next step.
        let mut usable = chords && factors.holds(pattern) && !pattern.renew(params.refactor_cost);
        // Whether `values` holds the Jacobian at `x` (`r` always holds the
        // residual at `x`).
        let mut have_jacobian = !usable;
        if have_jacobian {
            Self::eval_with_jacobian(&mut self.values, pattern, sys, x, &mut self.r);
        } else {
            Self::eval_residual(sys, x, &mut self.r);
        }
        let Some(mut rnorm) = scaled_norm(sys, &self.r) else {
            return Err(SolverError::NonFinite { iter: 0 });
        };

        loop {
            if rnorm <= params.residual_tol {
                return Ok(NewtonReport {
                    iterations: chord + full,
                    chord_iterations: chord,
                    residual: rnorm,
                    factorizations,
                });
            }
            if let Some((kept, left)) = watch {
                if rnorm < kept {
                    watch = None;
                } else if left == 0 {
                    // No whole step got below the kept iterate: back to it,
                    // for its damped step.
                    watch = None;
                    damp = true;
                    x.copy_from_slice(&self.x_kept);
                    self.r.copy_from_slice(&self.r_kept);
                    rnorm = kept;
                    have_jacobian = false;
                    usable = false;
                    if params.give_up_crawls && sys.abandon_crawl(x, rnorm) {
                        return Err(SolverError::Abandoned {
                            iter: full,
                            residual: rnorm,
                        });
                    }
                }
            }

            if usable && *run < params.chord_steps {
                // Chord step with the kept factorisation.
                negate(&mut self.dx, &self.r);
                factors.solve(pattern, &mut self.dx);
                usable = false;
                if self.dx.iter().all(|d| d.is_finite()) {
                    trial(&mut self.x_trial, x, &self.dx, 1.0);
                    Self::eval_residual(sys, &self.x_trial, &mut self.r_trial);
                    // Kept when it converged or contracted enough; else
                    // discarded, and the next step refactors at `x`.
                    if let Some(t) = scaled_norm(sys, &self.r_trial)
                        && (t <= params.residual_tol || t <= params.chord_contraction * rnorm)
                    {
                        x.copy_from_slice(&self.x_trial);
                        std::mem::swap(&mut self.r, &mut self.r_trial);
                        have_jacobian = false;
                        chord += 1;
                        self.steps_taken += 1;
                        self.chord_steps_taken += 1;
                        *run += 1;
                        pattern.chords_since += 1;
                        let rate = t / rnorm;
                        rnorm = t;
                        // Keep chord steps while, at the observed rate, they
                        // reach the tolerance within the steps left;
                        // otherwise refactor at the new iterate.
                        let needed = (params.residual_tol / rnorm).ln() / rate.ln();
                        // Negated so that a NaN estimate also refactors.
                        #[allow(clippy::neg_cmp_op_on_partial_ord)]
                        let on_track = rnorm <= params.residual_tol
                            || needed <= (params.chord_steps - *run) as f64;
                        usable = on_track;
                    }
                }
                continue;
            }

            // Full Newton step: factor J at x and solve J Δx = −r.
            if full == params.max_iterations {
                if let Some((kept, _)) = watch {
                    // The better iterate.
                    x.copy_from_slice(&self.x_kept);
                    rnorm = kept;
                }
                return Err(SolverError::Diverged {
                    iter: full,
                    residual: rnorm,
                });
            }
            if !have_jacobian {
                Self::eval_with_jacobian(&mut self.values, pattern, sys, x, &mut self.r);
                have_jacobian = true;
                let Some(norm) = scaled_norm(sys, &self.r) else {
                    return Err(SolverError::NonFinite { iter: full });
                };
                rnorm = norm;
            }
            if self.values.iter().any(|v| !v.is_finite()) {
                return Err(SolverError::NonFinite { iter: full });
            }
            negate(&mut self.dx, &self.r);
            let fp = factors.factor(
                pattern,
                &self.values,
                &mut self.mem,
                &mut self.compile,
                params.compiled_lu,
            )?;
            match fp {
                FactorPath::Compiled => self.compiled_factorizations += 1,
                FactorPath::Fallback => self.lu_fallbacks += 1,
                FactorPath::Corrected => {
                    self.compiled_factorizations += 1;
                    self.lu_corrected += 1;
                }
                FactorPath::Faer => {}
            }
            factorizations += 1;
            self.numeric_factorizations += 1;
            factors.solve(pattern, &mut self.dx);
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
                    iterations: chord + full,
                    chord_iterations: chord,
                    residual: rnorm,
                    factorizations,
                });
            }

            // Backtracking line search on the scaled residual max-norm.
            // Without chord steps the full step is evaluated with the
            // Jacobian (the factored values are no longer needed), so an
            // accepted full step — the usual case near a root — costs one
            // evaluation per iteration; with them the next step is a chord
            // step, which needs the residual only. Halved steps evaluate the
            // residual only.
            let mut alpha = 1.0;
            let mut accepted = None;
            let mut any_finite = false;
            for k in 0..=params.max_backtracks {
                trial(&mut self.x_trial, x, &self.dx, alpha);
                if k == 0 && !chords {
                    Self::eval_with_jacobian(
                        &mut self.values,
                        pattern,
                        sys,
                        &self.x_trial,
                        &mut self.r_trial,
                    );
                } else {
                    Self::eval_residual(sys, &self.x_trial, &mut self.r_trial);
                }
                if let Some(trial_norm) = scaled_norm(sys, &self.r_trial) {
                    any_finite = true;
                    // The watchdog's whole step (see `NewtonParams::watchdog`).
                    let crawling = params.watchdog > 0
                        && crawl >= params.crawl_steps.max(1)
                        && trial_norm >= rnorm;
                    if k == 0 && !damp && (watch.is_some() || crawling) {
                        watch = Some(match watch {
                            Some((kept, left)) => (kept, left - 1),
                            None => {
                                self.x_kept.copy_from_slice(x);
                                self.r_kept.copy_from_slice(&self.r);
                                (rnorm, params.watchdog - 1)
                            }
                        });
                        have_jacobian = false;
                        accepted = Some(trial_norm);
                        break;
                    }
                    if trial_norm < rnorm {
                        have_jacobian = k == 0 && !chords;
                        accepted = Some(trial_norm);
                        break;
                    }
                }
                alpha *= 0.5;
            }
            let Some(trial_norm) = accepted else {
                if rnorm <= params.step_residual_factor * params.residual_tol {
                    // No decrease is possible, and the residual is already
                    // within the round-off allowance of the step test: the
                    // floor.
                    return Ok(NewtonReport {
                        iterations: chord + full,
                        chord_iterations: chord,
                        residual: rnorm,
                        factorizations,
                    });
                }
                return Err(if any_finite {
                    SolverError::Diverged {
                        iter: full,
                        residual: rnorm,
                    }
                } else {
                    SolverError::NonFinite { iter: full }
                });
            };
            x.copy_from_slice(&self.x_trial);
            std::mem::swap(&mut self.r, &mut self.r_trial);
            rnorm = trial_norm;
            full += 1;
            self.steps_taken += 1;
            damp = false;
            crawl = if alpha <= params.crawl_step {
                crawl + 1
            } else {
                0
            };
            // A damped step: far from the root, where the Jacobian changes
            // fast; the next step refactors too, as does a watched one.
            usable = chords && alpha == 1.0 && watch.is_none();
            *run = 0;
        }
    }
}

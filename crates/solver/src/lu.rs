//! The sparse LU of one Jacobian pattern: its CSC structure, faer's
//! symbolic analysis (COLAMD column ordering), faer's simplicial numeric LU
//! with partial pivoting, and the triangular solves with those factors.
//!
//! # Why faer's simplicial LU, called directly
//!
//! * The symbolic analysis is forced to the *simplicial* LU
//!   ([`SupernodalThreshold::FORCE_SIMPLICIAL`]). faer 0.24.4's supernodal
//!   numeric LU allocates fresh per-supernode work vectors on every call
//!   (`contrib_work` in `factorize_supernodal_numeric_lu`), so it could
//!   never be allocation-free; on the 20–60 unknown, very sparse systems of
//!   this project the simplicial (left-looking, Gilbert–Peierls) LU is also
//!   the faster one (`cargo bench -p fbd-suite --bench factorization`).
//! * The numeric LU is faer's
//!   [`simplicial::factorize_simplicial_numeric_lu`], called on a
//!   [`SimplicialLu`] owned here, so that its `L` and `U` factors are at
//!   hand. The Newton step `J Δx = −r` is the row permutation, one sweep
//!   `w[i] −= v·w[j]` over `L`'s columns in faer's own storage, one over
//!   `U`'s, last column first, with each column's entries divided by its
//!   pivot (the only copy made after a factorisation: `U`'s values,
//!   scaled, [`Factors::factor`]), and the column permutation with the
//!   reciprocal pivots ([`Factors::solve`]) — the arithmetic of faer's
//!   `solve_in_place_with_conj`, without its per-column and generic
//!   multi-column machinery, which cost about twice as much on these sizes.
//!   It matters because a chord step (a step with a kept factorisation) is
//!   one residual and one solve, and most steps are chord steps.
//! * The pattern's structure is kept as faer's checked
//!   [`SymbolicSparseColMat`], so that a factorisation does not check it
//!   again.
//! * faer's simplicial numeric LU stores `L`/`U` in `Vec`s that it grows on
//!   demand (never shrinking). Their fill depends on the numerical row
//!   pivoting, so a later refactorisation of the same pattern could need
//!   more room than the first one and would then allocate. To rule that
//!   out, [`Factors::new`] factors a fully dense `n × n` matrix once into
//!   new storage: any `n × n` factorisation needs at most the storage of
//!   the dense one, so every later one fits. The storage is shared by the
//!   patterns of one dimension (the contact states of a run change the
//!   pattern, seldom the dimension), so that this warm-up — a dense LU
//!   through the sparse code, about 0.1 ms at 31 unknowns — is done once
//!   per dimension rather than once per pattern; it holds the last
//!   factorisation of one of them ([`Factors::holds`]). Storage is never
//!   shared across dimensions: a simplicial LU cannot be reused for a
//!   smaller one.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::perm::PermRef;
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::SupernodalThreshold;
use faer::sparse::linalg::lu::simplicial::{
    SimplicialLu, factorize_simplicial_numeric_lu, factorize_simplicial_numeric_lu_scratch,
};
use faer::sparse::linalg::lu::{LuSymbolicParams, SymbolicLu, factorize_symbolic_lu};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};

use crate::SolverError;

/// Cached per-pattern data: CSC structure, dense slot map, column ordering,
/// and the bookkeeping of its kept factorisation.
pub(crate) struct Pattern {
    /// Index of this pattern in the solver's cache (the owner id of
    /// [`Factors`]).
    id: usize,
    pub(crate) n: usize,
    /// Dense `n × n` row-major map `(row, col) → index into the CSC values`,
    /// `u32::MAX` where the entry is not in the pattern.
    pub(crate) slot: Vec<u32>,
    /// The CSC structure as faer's checked matrix structure, so that a
    /// factorisation does not check it again.
    structure: SymbolicSparseColMat<usize>,
    /// faer's symbolic LU: the fill-reducing column permutation.
    symbolic: SymbolicLu<usize>,
    /// Index of the numeric storage of this pattern's dimension.
    pub(crate) factors: usize,
    /// Solves ended since the last factorisation.
    solves_since: usize,
    /// Chord steps taken with the last factorisation.
    pub(crate) chords_since: usize,
    /// Chord steps of the last solve after its last factorisation.
    last_chords: usize,
}

impl Pattern {
    /// The CSC structure of `entries` (any order, duplicates allowed) and
    /// its symbolic analysis, as pattern `id` using numeric storage
    /// `factors`. Allocates.
    pub(crate) fn build(
        id: usize,
        n: usize,
        entries: &mut Vec<(usize, usize)>,
        factors: usize,
    ) -> Self {
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

        let structure = SymbolicSparseColMat::new_checked(n, n, col_ptr, None, row_idx);
        let a = structure.as_ref();
        let params = LuSymbolicParams {
            supernodal_flop_ratio_threshold: SupernodalThreshold::FORCE_SIMPLICIAL,
            ..Default::default()
        };
        let symbolic = factorize_symbolic_lu(a, params)
            .unwrap_or_else(|e| panic!("faer symbolic LU failed: {e:?}"));
        Self {
            id,
            n,
            slot,
            structure,
            symbolic,
            factors,
            solves_since: 0,
            chords_since: 0,
            last_chords: 0,
        }
    }

    /// Number of structural entries.
    pub(crate) fn nnz(&self) -> usize {
        self.structure.row_idx().len()
    }

    fn col_perm(&self) -> PermRef<'_, usize> {
        self.symbolic.col_perm()
    }

    /// Bookkeeping at the end of a solve that took `chords` chord steps
    /// after its last factorisation (see [`Self::renew`]).
    pub(crate) fn solved(&mut self, chords: usize) {
        self.solves_since += 1;
        self.last_chords = chords;
    }

    /// The renewal rule of `NewtonParams::refactor_cost` (`cost`, in chord
    /// steps; `0` never renews): whether the next solve should start with
    /// a refactorisation rather than chord steps with the kept one.
    pub(crate) fn renew(&self, cost: f64) -> bool {
        cost > 0.0
            && self.solves_since > 0
            && self.last_chords as f64 * self.solves_since as f64 > cost + self.chords_since as f64
    }
}

/// Numeric LU storage for the patterns of one dimension: faer's simplicial
/// `L`, `U` and row pivoting of the last factorisation, `U` scaled for the
/// solves, and the scratch of the solves.
pub(crate) struct Factors {
    n: usize,
    lu: SimplicialLu<usize, f64>,
    row_perm: Vec<usize>,
    row_perm_inv: Vec<usize>,
    /// `1 / U[j, j]` of the last factorisation.
    pivot_inv: Vec<f64>,
    /// `U`'s entries divided by their column's pivot, in the order of
    /// faer's storage of `U` (its diagonal entries unused).
    upper: Vec<f64>,
    /// Scratch of [`Self::solve`].
    work: Vec<f64>,
    /// The pattern whose factorisation this holds (none after the dense
    /// warm-up or a failed factorisation).
    owner: Option<usize>,
}

impl Factors {
    /// Scratch that [`Self::new`] and [`Self::factor`] need for dimension
    /// `n`.
    pub(crate) fn scratch(n: usize) -> StackReq {
        factorize_simplicial_numeric_lu_scratch::<usize, f64>(n, n)
    }

    /// Storage for dimension `n`, grown to that of a dense `n × n` LU (see
    /// the module docs). Allocates; `mem` must hold [`Self::scratch`].
    pub(crate) fn new(n: usize, mem: &mut MemBuffer) -> Self {
        let mut f = Self {
            n,
            lu: SimplicialLu::new(),
            row_perm: vec![0; n],
            row_perm_inv: vec![0; n],
            pivot_inv: vec![0.0; n],
            upper: Vec::with_capacity(n * (n + 1) / 2),
            work: vec![0.0; n],
            owner: None,
        };
        // Diagonally dominant, hence nonsingular.
        let col_ptr: Vec<usize> = (0..=n).map(|j| j * n).collect();
        let row_idx: Vec<usize> = (0..n * n).map(|k| k % n).collect();
        let values: Vec<f64> = (0..n * n)
            .map(|k| if k % n == k / n { 2.0 * n as f64 } else { 1.0 })
            .collect();
        let dense = SparseColMatRef::new(
            SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx),
            &values,
        );
        let identity: Vec<usize> = (0..n).collect();
        factorize_simplicial_numeric_lu(
            &mut f.row_perm,
            &mut f.row_perm_inv,
            &mut f.lu,
            dense,
            PermRef::new_checked(&identity, &identity, n),
            MemStack::new(mem),
        )
        .unwrap_or_else(|e| panic!("faer dense warm-up LU failed: {e:?}"));
        f
    }

    /// The dimension.
    pub(crate) fn dim(&self) -> usize {
        self.n
    }

    /// Whether this holds a factorisation of `pattern` (usable for chord
    /// steps).
    pub(crate) fn holds(&self, pattern: &Pattern) -> bool {
        self.owner == Some(pattern.id)
    }

    /// Numeric LU of `values` (CSC order of `pattern`), reusing its column
    /// ordering. `mem` must hold [`Self::scratch`]. Allocation-free.
    ///
    /// # Errors
    /// [`SolverError::Singular`] when faer finds no structurally non-zero
    /// pivot for a column. (A numerically zero pivot shows up as a
    /// non-finite solution of [`Self::solve`].)
    pub(crate) fn factor(
        &mut self,
        pattern: &mut Pattern,
        values: &[f64],
        mem: &mut MemBuffer,
    ) -> Result<(), SolverError> {
        let n = self.n;
        assert_eq!(pattern.n, n, "pattern and storage dimensions differ");
        self.owner = None;
        let matrix = SparseColMatRef::new(pattern.structure.as_ref(), values);
        match factorize_simplicial_numeric_lu(
            &mut self.row_perm,
            &mut self.row_perm_inv,
            &mut self.lu,
            matrix,
            pattern.col_perm(),
            MemStack::new(mem),
        ) {
            Ok(()) => {}
            Err(LuError::SymbolicSingular { index }) => {
                let equation = pattern.col_perm().arrays().0[index];
                return Err(SolverError::Singular { equation });
            }
            Err(LuError::Generic(e)) => panic!("faer numeric LU failed: {e:?}"),
        }
        // faer stores each column's diagonal of U last (the contract of its
        // own triangular solves).
        let u = self.lu.u_factor_unsorted();
        let (u_ptr, u_val) = (u.symbolic().col_ptr(), u.val());
        // At most the dense U's entries (see the module docs): no growth.
        self.upper.resize(u_val.len(), 0.0);
        for j in 0..n {
            let (start, diag) = (u_ptr[j], u_ptr[j + 1] - 1);
            let pivot_inv = u_val[diag].recip();
            self.pivot_inv[j] = pivot_inv;
            for (s, &v) in self.upper[start..diag].iter_mut().zip(&u_val[start..diag]) {
                *s = v * pivot_inv;
            }
        }
        self.owner = Some(pattern.id);
        pattern.solves_since = 0;
        pattern.chords_since = 0;
        Ok(())
    }

    /// Solves `J x = rhs` in place with the last factorisation
    /// `P·J·Q = L·U` (`P`: row pivoting, `Q`: `pattern`'s column ordering)
    /// of `pattern`'s Jacobian. A zero pivot gives non-finite entries. No
    /// allocation.
    ///
    /// # Panics
    /// If this does not hold a factorisation of `pattern`.
    pub(crate) fn solve(&mut self, pattern: &Pattern, rhs: &mut [f64]) {
        let n = self.n;
        assert!(self.holds(pattern), "no factorisation of this pattern");
        assert_eq!(rhs.len(), n, "right-hand side has the wrong length");
        let w = &mut self.work[..n];
        for (wi, &p) in w.iter_mut().zip(&self.row_perm) {
            *wi = rhs[p];
        }
        // L, column by column: w[j] is final when column j's updates start
        // (they come from the columns before it); faer stores each column's
        // unit diagonal first.
        let l = self.lu.l_factor_unsorted();
        let (l_ptr, l_row, l_val) = (l.symbolic().col_ptr(), l.symbolic().row_idx(), l.val());
        for j in 0..n {
            let wj = w[j];
            let (start, end) = (l_ptr[j] + 1, l_ptr[j + 1]);
            for (&i, &v) in l_row[start..end].iter().zip(&l_val[start..end]) {
                w[i] -= v * wj;
            }
        }
        // U D⁻¹, last column first: w[j] is final (unscaled) when column
        // j's updates start; faer stores each column's diagonal last.
        let u = self.lu.u_factor_unsorted();
        let (u_ptr, u_row) = (u.symbolic().col_ptr(), u.symbolic().row_idx());
        for j in (0..n).rev() {
            let wj = w[j];
            let (start, end) = (u_ptr[j], u_ptr[j + 1] - 1);
            for (&i, &v) in u_row[start..end].iter().zip(&self.upper[start..end]) {
                w[i] -= v * wj;
            }
        }
        let (col_fwd, _) = pattern.col_perm().arrays();
        for ((&c, &wj), &p) in col_fwd.iter().zip(w.iter()).zip(&self.pivot_inv) {
            rhs[c] = wj * p;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::linalg::lu::NumericLu;
    use faer::{Conj, MatMut, Par};

    /// A sparse, nonsymmetric test matrix with some zero diagonal entries
    /// (pivoting needed), as `(row, col, value)`.
    fn matrix(n: usize, seed: u64) -> Vec<(usize, usize, f64)> {
        let mut s = seed;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) * 2.0 - 1.0
        };
        let mut e = Vec::new();
        for i in 0..n {
            if i % 3 != 1 {
                e.push((i, i, 3.0 + next()));
            }
            e.push((i, (i + 1) % n, next()));
            e.push(((i + 2) % n, i, 2.0 + next()));
            e.push(((i * 7 + 3) % n, i, next()));
        }
        e
    }

    #[test]
    fn solve_matches_faer() {
        for (n, seed) in [(5, 1), (19, 2), (31, 3), (64, 4)] {
            let triplets = matrix(n, seed);
            let mut entries: Vec<(usize, usize)> = triplets.iter().map(|t| (t.0, t.1)).collect();
            let mut pattern = Pattern::build(0, n, &mut entries, 0);
            let mut values = vec![0.0; pattern.nnz()];
            for &(i, j, v) in &triplets {
                values[pattern.slot[i * n + j] as usize] += v;
            }
            let mut mem = MemBuffer::new(
                Factors::scratch(n).or(pattern
                    .symbolic
                    .solve_in_place_scratch::<f64>(1, Par::Seq)
                    .or(pattern
                        .symbolic
                        .factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()))),
            );
            let mut factors = Factors::new(n, &mut mem);
            factors
                .factor(&mut pattern, &values, &mut mem)
                .expect("nonsingular");
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
            let mut ours = b.clone();
            factors.solve(&pattern, &mut ours);

            let mut numeric = NumericLu::new();
            let a = SparseColMatRef::new(pattern.structure.as_ref(), &values[..]);
            let lu = pattern
                .symbolic
                .factorize_numeric_lu(
                    &mut numeric,
                    a,
                    Par::Seq,
                    MemStack::new(&mut mem),
                    Default::default(),
                )
                .expect("nonsingular");
            let mut theirs = b.clone();
            lu.solve_in_place_with_conj(
                Conj::No,
                MatMut::from_column_major_slice_mut(&mut theirs, n, 1),
                Par::Seq,
                MemStack::new(&mut mem),
            );
            // And the residual of ours.
            let mut r = b.clone();
            for &(i, j, v) in &triplets {
                r[i] -= v * ours[j];
            }
            for i in 0..n {
                assert!(
                    (ours[i] - theirs[i]).abs() <= 1e-12 * (1.0 + theirs[i].abs()),
                    "n = {n}, x[{i}]: ours {} faer {}",
                    ours[i],
                    theirs[i]
                );
                assert!(r[i].abs() < 1e-10, "n = {n}, residual[{i}] = {}", r[i]);
            }
        }
    }
}

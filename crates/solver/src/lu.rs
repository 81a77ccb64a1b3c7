//! The sparse LU of one Jacobian pattern: its CSC structure, faer's
//! COLAMD column ordering, faer's simplicial numeric LU with partial
//! pivoting, and the triangular solves with those factors.
//!
//! # Singleton rows
//!
//! A row whose Jacobian row has a single structural entry `J[i, j]` (a
//! free contact point's `F = 0`, a free joint stop's `λ = 0`) fixes its
//! unknown alone: `Δx_j = b_i / J[i, j]`. [`Pattern::build`] takes every
//! such row out of the LU, with its column, when no other singleton row
//! claims the same column (rows are taken in index order; a second
//! singleton row of a column stays in the LU, which then finds the
//! structural singularity as before). The LU is that of the *reduced*
//! pattern, the others rows and columns; a solve ([`Factors::solve`]) finds
//! the eliminated unknowns first, subtracts `J[k, j]·Δx_j` from the
//! right-hand side of every other row `k` with an entry in an eliminated
//! column, solves the reduced system and writes back the eliminated
//! unknowns. It is the same linear solve (the pivot of an eliminated row
//! is its only entry, exactly), with fewer columns for faer's LU to visit:
//! a free leg's rows and free stops make a third of a planar flight's
//! unknowns.
//!
//! The reduced pattern's column ordering is the full pattern's COLAMD
//! ordering with the eliminated columns left out (not a new COLAMD of the
//! reduced pattern): the reduced LU then follows the full one's elimination
//! order, whereas COLAMD's heuristics on the reduced pattern can find a
//! worse one (measured on a robot hanging from two sticking feet, free
//! stops eliminated: 14 % more instructions per factorisation and 8 % per
//! solve than the full order restricted, more than without the
//! elimination).
//!
//! The Jacobian values keep one array per pattern: the reduced pattern's
//! CSC values first (handed to faer as they are, no copy), then the pivots
//! of the eliminated rows, then the other entries of the eliminated columns
//! ([`Pattern::slot`] maps every `(row, col)` there). A factorisation
//! copies the eliminated rows' reciprocal pivots and the eliminated
//! columns' entries into the pattern, so that chord steps with the kept
//! factorisation never read values evaluated later.
//!
//! # Why faer's simplicial LU, called directly
//!
//! * The LU is faer's *simplicial* one, and its symbolic analysis faer's
//!   COLAMD ordering alone ([`colamd::order`] with the default parameters
//!   of faer's symbolic LU, whose column permutation it is: with the
//!   simplicial LU forced, `factorize_symbolic_lu` adds only an
//!   elimination tree and column counts, which the simplicial numeric LU
//!   does not use; calling COLAMD alone saved a third of the 84 M
//!   instructions of the 191 patterns of `bench/peer/hexapod_drop.toml`).
//!   faer 0.24.4's supernodal
//!   numeric LU allocates fresh per-supernode work vectors on every call
//!   (`contrib_work` in `factorize_supernodal_numeric_lu`), so it could
//!   never be allocation-free; on the 20–60 unknown, very sparse systems of
//!   this project the simplicial (left-looking, Gilbert–Peierls) LU is also
//!   the faster one (`cargo bench -p fbd-suite --bench factorization`).
//! * The numeric LU is faer's
//!   [`factorize_simplicial_numeric_lu`], called on a
//!   [`SimplicialLu`] owned here, so that its `L` and `U` factors are at
//!   hand. After each factorisation both factors are copied once into two
//!   streams of `(row, value)` entries in column runs ([`Stream`]), `L`'s
//!   below its unit diagonal column after column and `U`'s above its
//!   diagonal, divided by their column's pivot, last column first
//!   ([`Factors::factor`]). The Newton step `J Δx = −r` is then the row
//!   permutation, one pass `w[i] −= v·w[j]` over each stream (`w[j]` read
//!   once per column run), and the column permutation with the reciprocal
//!   pivots ([`Factors::solve`]) — the arithmetic of faer's
//!   `solve_in_place_with_conj` in the same order, without its per-column
//!   and generic multi-column machinery, which cost about twice as much on
//!   these sizes (a chord step's solve of the moving flight's 15 unknowns
//!   with one `(row, column, value)` stream per sweep: 2.5 k → 2.2 k
//!   instructions, for about 1.7 k more per factorisation; the column runs
//!   then saved another 3.5 % of the 3D drop's solve instructions). Each
//!   column's entries are cut into pieces: runs of at least
//!   [`SEGMENT_MIN`] consecutive rows are updated as contiguous slices
//!   (vectorised, no row index read), the others entry by entry — the same
//!   updates in the same order, bit for bit; on the hexapod walk of
//!   `bench/peer` the solves cost 20 % fewer instructions (166 M → 133 M
//!   for the 5 s walk, callgrind) and the whole run 3.6 % fewer.
//!   It matters because a chord step (a step with a kept factorisation) is
//!   one residual and one solve, and most steps are chord steps.
//! * The pattern's structure is kept as faer's checked
//!   [`SymbolicSparseColMat`], so that a factorisation does not check it
//!   again.
//! * faer's simplicial numeric LU stores `L`/`U` in `Vec`s that it grows on
//!   demand (never shrinking). Their fill depends on the numerical row
//!   pivoting, so a later refactorisation of the same pattern could need
//!   more room than the first one and would then allocate. To rule that
//!   out, new storage is grown to that of a dense `n × n` LU before faer's
//!   first factorisation into it ([`Factors::warm_up`]; a dimension whose
//!   patterns all factor by their compiled programs never pays it):
//!   any `n × n` factorisation needs at most the storage of the dense one
//!   (faer asks, at column `j`, for the entries so far plus the column's
//!   reach, both at most the dense LU's), so every later one fits. A dense
//!   LU through the sparse code costs `O(n³)`, 0.7–6 ms at 80–135
//!   unknowns — a third of `bench/peer/hexapod_drop.toml`'s run, whose 18
//!   contact points meet 49 reduced dimensions. Two triangular matrices
//!   make the same requests in `O(n²)`: a dense lower triangle whose last
//!   column is full (`L` as dense, and the full last column's request of
//!   `U`), then a dense upper triangle (`U` as dense), both diagonally
//!   dominant so that partial pivoting keeps the diagonal (only the full
//!   last column is updated by the others). `tests/no_alloc.rs` of this
//!   crate checks a re-pivoted refactorisation against it. The storage is
//!   shared by the
//!   patterns of one dimension (the contact states of a run change the
//!   pattern, seldom the dimension), so that this warm-up is done once per
//!   dimension rather than once per pattern; it holds the last
//!   factorisation of one of them ([`Factors::holds`]). Storage is never
//!   shared across dimensions: a simplicial LU cannot be reused for a
//!   smaller one.

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::perm::{Perm, PermRef};
use faer::sparse::linalg::LuError;
use faer::sparse::linalg::colamd;
use faer::sparse::linalg::lu::LuSymbolicParams;
use faer::sparse::linalg::lu::simplicial::{
    SimplicialLu, factorize_simplicial_numeric_lu, factorize_simplicial_numeric_lu_scratch,
};
use faer::sparse::{SparseColMatRef, SymbolicSparseColMat, SymbolicSparseColMatRef};

use crate::SolverError;
use crate::compiled::{CompileScratch, CompiledLu, MAX_PERTURBED};

/// Which path a factorisation took (see [`crate::compiled`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum FactorPath {
    /// The compiled program of the pattern.
    Compiled,
    /// faer's pivoting LU: the reference path, or the first factorisation
    /// of the pattern (which compiles it).
    Faer,
    /// faer's pivoting LU after a compiled pivot failed its check.
    Fallback,
    /// The compiled program with perturbed pivots, its solves corrected
    /// (see [`crate::compiled`], "Perturbed pivots").
    Corrected,
}

/// Cached per-pattern data: the reduced CSC structure (singleton rows
/// taken out, see the module docs), the dense slot map, the column
/// ordering, the eliminated rows, and the bookkeeping of its kept
/// factorisation.
#[derive(Clone)]
pub(crate) struct Pattern {
    /// Index of this pattern in the solver's cache (the owner id of
    /// [`Factors`]).
    id: usize,
    /// Dimension of the system.
    pub(crate) n: usize,
    /// Dimension of the reduced system (the LU's).
    pub(crate) m: usize,
    /// Dense `n × n` row-major map `(row, col) → index into the values`
    /// (reduced CSC values, then eliminated pivots, then eliminated
    /// columns' entries), `u32::MAX` where the entry is not in the pattern.
    pub(crate) slot: Vec<u32>,
    /// Length of the values.
    nnz: usize,
    /// The reduced CSC structure as faer's checked matrix structure, so
    /// that a factorisation does not check it again.
    structure: SymbolicSparseColMat<usize>,
    /// The reduced columns' ordering (the full COLAMD order restricted).
    col_perm: Perm<usize>,
    /// The full row of each reduced row.
    kept_rows: Vec<usize>,
    /// The full column of the reduced column in ordered position `c`.
    col_dst: Vec<usize>,
    /// Eliminated singleton rows: `(row, col)` of their only entry.
    singles: Vec<(usize, usize)>,
    /// Entries `(row k, singleton t)` of the eliminated columns in rows
    /// kept in the LU: `J[k, singles[t].1]`.
    couplings: Vec<(usize, usize)>,
    /// `1 / J[i, j]` of each eliminated row at the last factorisation.
    single_inv: Vec<f64>,
    /// The couplings' values at the last factorisation.
    coupling: Vec<f64>,
    /// Scratch of [`Factors::solve`]: the eliminated unknowns.
    single_x: Vec<f64>,
    /// Index of the numeric storage of this pattern's reduced dimension.
    pub(crate) factors: usize,
    /// Solves ended since the last factorisation.
    solves_since: usize,
    /// Chord steps taken with the last factorisation.
    pub(crate) chords_since: usize,
    /// Chord steps of the last solve after its last factorisation.
    last_chords: usize,
    /// The compiled numeric LUs of this pattern (empty until the first
    /// factorisation with the compiled path enabled; at most
    /// [`MAX_PROGRAMS`], see there).
    programs: Vec<Program>,
    /// Factorisations of this pattern by the compiled path: the clock of
    /// [`Program::last_use`].
    factorizations: u64,
    /// The zero signatures that fell back to faer's LU once, without a
    /// program of their own because the row choice found no pivot on
    /// their values (compiled on faer's rows at their second fallback).
    failed: Vec<u64>,
}

/// One compiled program of a pattern and its bookkeeping.
#[derive(Clone, Default)]
struct Program {
    /// The [`zero_signature`] of the values it was compiled on.
    zeros: u64,
    lu: CompiledLu,
    /// The factorisation of its pattern that last tried it (a clock of
    /// [`Pattern::factorizations`]): the least recently tried one after
    /// the first gives its place to a new set of zeros when
    /// [`MAX_PROGRAMS`] are kept.
    last_use: u64,
    /// Its fallbacks to faer's LU in a row (on its own set of zeros): at
    /// [`RECOMPILE_AFTER`] it is compiled again on the values it failed
    /// on, once.
    fails: u32,
    /// Whether it was compiled again so (then it stays).
    renewed: bool,
}

/// The most compiled programs one pattern keeps (see [`Factors::factor`]):
/// one per set of exact zeros among its values; a new set beyond them
/// takes the place of the least recently tried program (never the first,
/// which factors the sets of zeros without a program of their own).
pub(crate) const MAX_PROGRAMS: usize = 8;

/// A program that fell back to faer's LU on its own set of zeros this
/// many times in a row is compiled again on the values of the last
/// fallback (its row order chosen on those values), once (values that
/// alternate between two regimes would otherwise recompile it again and
/// again): a failed pivot that
/// passes — a cancellation to round-off for one iterate — costs one
/// fallback, while a row order that the values have left behind (on a
/// contact-rich landing, one program fell back 20 times, its
/// perturbed pivots' correction failing its accuracy check) is replaced.
pub(crate) const RECOMPILE_AFTER: u32 = 2;

/// A hash of which of `values` are exactly zero. A complementarity row
/// switches its branch inside one sparsity pattern by turning entries to
/// exact zeros (a lifted point's normal row becomes `N = 0`), and a row
/// order chosen on one such set of zeros fails pivots of another: on the
/// 3D drop of `bench/peer`, 830 of the 831 factorisations that left the
/// compiled program had other zeros than the values it was compiled on.
fn zero_signature(values: &[f64]) -> u64 {
    let mix = |h: u64, i: usize| {
        (h ^ (i as u64 + 1))
            .wrapping_mul(0x0100_0000_01B3)
            .rotate_left(17)
    };
    let mut h = 0x9E37_79B9_7F4A_7C15u64;
    // Most values are not zero: a block of eight without one is passed
    // by one test.
    let (blocks, rest) = values.as_chunks::<8>();
    for (b, block) in blocks.iter().enumerate() {
        if block.iter().fold(false, |z, &v| z | (v == 0.0)) {
            for (k, &v) in block.iter().enumerate() {
                if v == 0.0 {
                    h = mix(h, 8 * b + k);
                }
            }
        }
    }
    for (k, &v) in rest.iter().enumerate() {
        if v == 0.0 {
            h = mix(h, 8 * blocks.len() + k);
        }
    }
    h
}

/// Sorts `entries` (`(row, col)`, each below `n`, else it panics)
/// column-major, rows in order within a column, and removes the
/// duplicates: a stable counting sort by row, then by column, `O(len + n)`
/// (a comparison sort cost 0.3 M instructions a pattern on
/// `bench/peer/hexapod_drop.toml`, 1 600 entries of 150 unknowns).
fn sort_entries(n: usize, entries: &mut Vec<(usize, usize)>) {
    let mut start = vec![0usize; n + 1];
    let mut col_start = vec![0usize; n + 1];
    for &(row, col) in entries.iter() {
        assert!(
            row < n && col < n,
            "Jacobian pattern entry ({row}, {col}) is out of range for dimension {n}"
        );
        start[row + 1] += 1;
        col_start[col + 1] += 1;
    }
    let mut by_row = vec![(0, 0); entries.len()];
    for j in 0..n {
        start[j + 1] += start[j];
        col_start[j + 1] += col_start[j];
    }
    for &e in entries.iter() {
        by_row[start[e.0]] = e;
        start[e.0] += 1;
    }
    let mut start = col_start;
    for &e in &by_row {
        entries[start[e.1]] = e;
        start[e.1] += 1;
    }
    entries.dedup();
}

/// The COLAMD column ordering of `structure` (ordered position →
/// column), as faer's symbolic LU computes it with its default
/// parameters (`factorize_symbolic_lu` with a simplicial LU keeps it as
/// it is; the elimination tree and column counts it computes besides are
/// not used here).
fn colamd_order(structure: SymbolicSparseColMatRef<'_, usize>) -> Vec<usize> {
    let n = structure.ncols();
    let (mut fwd, mut inv) = (vec![0usize; n], vec![0usize; n]);
    let mut mem = MemBuffer::new(colamd::order_scratch::<usize>(
        n,
        n,
        structure.compute_nnz(),
    ));
    colamd::order(
        &mut fwd,
        &mut inv,
        structure,
        LuSymbolicParams::default().colamd_params,
        MemStack::new(&mut mem),
    )
    .unwrap_or_else(|e| panic!("faer COLAMD ordering failed: {e:?}"));
    fwd
}

impl Pattern {
    /// The structure of `entries` (any order, duplicates allowed), its
    /// singleton rows taken out and the column ordering of the rest, as
    /// pattern `id`; [`Self::factors`] is to be set by the caller (storage
    /// of dimension [`Self::m`]). Allocates.
    ///
    /// Linear in the entries and `n` but for COLAMD and the dense slot
    /// map's fill: on `bench/peer/hexapod_drop.toml` (191 patterns, 150
    /// unknowns, 1 600 entries), 207 M → 133 M instructions (callgrind) with
    /// the counting sort, faer's COLAMD alone and fewer passes over the
    /// entries; of those, COLAMD 58 M and the slot map's fill 17 M (a
    /// `rep stosb` that callgrind counts byte by byte: 90 kB a pattern, a few
    /// microseconds).
    pub(crate) fn build(id: usize, n: usize, entries: &mut Vec<(usize, usize)>) -> Self {
        // Column-major order, rows sorted within a column, no duplicates
        // (entries out of range panic).
        sort_entries(n, entries);
        let nnz = entries.len();
        assert!(
            nnz < u32::MAX as usize,
            "Jacobian pattern has too many entries ({nnz})"
        );

        // Singleton rows, in row order; a column is claimed once. (And
        // each column's entries: the full structure's column pointers.)
        let mut row_count = vec![0usize; n];
        let mut row_col = vec![0usize; n];
        let mut full_ptr = vec![0usize; n + 1];
        for &(row, col) in entries.iter() {
            row_count[row] += 1;
            row_col[row] = col;
            full_ptr[col + 1] += 1;
        }
        const NONE: usize = usize::MAX;
        let mut single_of_row = vec![NONE; n];
        let mut single_of_col = vec![NONE; n];
        let mut singles = Vec::new();
        for row in 0..n {
            let col = row_col[row];
            if row_count[row] == 1 && single_of_col[col] == NONE {
                single_of_row[row] = singles.len();
                single_of_col[col] = singles.len();
                singles.push((row, col));
            }
        }
        let kept_rows: Vec<usize> = (0..n).filter(|&r| single_of_row[r] == NONE).collect();
        let kept_cols: Vec<usize> = (0..n).filter(|&c| single_of_col[c] == NONE).collect();
        let m = kept_rows.len();
        let mut reduced_row = vec![NONE; n];
        for (r, &row) in kept_rows.iter().enumerate() {
            reduced_row[row] = r;
        }
        let mut reduced_col = vec![NONE; n];
        for (c, &col) in kept_cols.iter().enumerate() {
            reduced_col[col] = c;
        }
        // An eliminated column's entries other than its singleton's are
        // in kept rows (a second singleton row of the column is kept).
        let n_couplings: usize = singles.iter().map(|&(_, col)| full_ptr[col + 1] - 1).sum();
        let reduced_nnz = nnz - singles.len() - n_couplings;
        for j in 0..n {
            full_ptr[j + 1] += full_ptr[j];
        }

        // In one pass: the reduced CSC structure (entries stay in
        // column-major order), the slots, the full structure's rows.
        let mut col_ptr = vec![0usize; m + 1];
        let mut row_idx = Vec::with_capacity(reduced_nnz);
        let mut full_rows = Vec::with_capacity(nnz);
        let mut slot = vec![u32::MAX; n * n];
        let mut couplings = Vec::with_capacity(n_couplings);
        for &(row, col) in entries.iter() {
            full_rows.push(row);
            let s = if single_of_row[row] != NONE {
                reduced_nnz + single_of_row[row]
            } else if single_of_col[col] != NONE {
                couplings.push((row, single_of_col[col]));
                reduced_nnz + singles.len() + couplings.len() - 1
            } else {
                col_ptr[reduced_col[col] + 1] += 1;
                row_idx.push(reduced_row[row]);
                row_idx.len() - 1
            };
            slot[row * n + col] = s as u32;
        }
        debug_assert_eq!(row_idx.len(), reduced_nnz);
        for j in 0..m {
            col_ptr[j + 1] += col_ptr[j];
        }

        // The full pattern's COLAMD ordering, restricted to the kept
        // columns.
        let full = SymbolicSparseColMatRef::new_checked(n, n, &full_ptr, None, &full_rows);
        let full_order = colamd_order(full);
        let fwd: Vec<usize> = full_order
            .iter()
            .filter(|&&c| single_of_col[c] == NONE)
            .map(|&c| reduced_col[c])
            .collect();
        let mut inv = vec![0usize; m];
        for (p, &c) in fwd.iter().enumerate() {
            inv[c] = p;
        }
        let col_dst = fwd.iter().map(|&c| kept_cols[c]).collect();
        let col_perm = Perm::new_checked(fwd.into_boxed_slice(), inv.into_boxed_slice(), m);
        let structure = SymbolicSparseColMat::new_checked(m, m, col_ptr, None, row_idx);
        let s = singles.len();
        let c = couplings.len();
        Self {
            id,
            n,
            m,
            slot,
            nnz,
            structure,
            col_perm,
            kept_rows,
            col_dst,
            singles,
            couplings,
            single_inv: vec![0.0; s],
            coupling: vec![0.0; c],
            single_x: vec![0.0; s],
            factors: usize::MAX,
            solves_since: 0,
            chords_since: 0,
            last_chords: 0,
            programs: Vec::new(),
            factorizations: 0,
            failed: Vec::new(),
        }
    }

    /// Number of Jacobian values (structural entries).
    pub(crate) fn nnz(&self) -> usize {
        self.nnz
    }

    fn col_perm(&self) -> PermRef<'_, usize> {
        self.col_perm.as_ref()
    }

    /// Bookkeeping at the end of a solve that took `chords` chord steps
    /// after its last factorisation (see [`Self::renew`]).
    pub(crate) fn solved(&mut self, chords: usize) {
        self.solves_since += 1;
        self.last_chords = chords;
    }

    /// The renewal rule of `NewtonParams::refactor_cost` (`cost`, in chord
    /// steps; `0` never renews): whether the next solve should start with
    /// a refactorisation rather than chord steps with the kept one. Never
    /// after a solve of a single chord step: no solve takes fewer steps (a
    /// fresh factorisation still takes its Newton step), so a renewal
    /// could only add its cost.
    pub(crate) fn renew(&self, cost: f64) -> bool {
        cost > 0.0
            && self.solves_since > 0
            && self.last_chords > 1
            && self.last_chords as f64 * self.solves_since as f64 > cost + self.chords_since as f64
    }
}

/// A triangular sweep's entries `(row i, value v)` column after column in
/// the sweep's order: the sweep is `w[i] −= v·w[j]` for every entry of
/// column `j`, `w[j]` read once per column (it is final then: no entry of
/// column `j` has row `j`).
///
/// Each column's entries are cut into *pieces* ([`Piece`], made by
/// [`Self::seal`]): a run of at least [`SEGMENT_MIN`] entries whose rows
/// are consecutive (`row, row + 1, …`) is a *segment*, whose update
/// `w[row..row + len] −= v[..]·w[j]` works on contiguous memory with no
/// row index read per entry (the compiler vectorises it); the entries
/// between segments are updated one by one through their rows, and
/// consecutive such pieces — of one column or of several — are one piece
/// whose entries also read their own columns ([`MIXED`]). The fill of
/// the FBD systems' factors is largely made of such blocks: on the hexapod
/// walk of `bench/peer`, `U`'s 832 entries are 99 runs of consecutive
/// rows, `L`'s 611 are 320. Every entry gets the same update, in the same
/// order, as entry by entry: the results are the same bit for bit.
#[derive(Clone, Debug, Default)]
pub(crate) struct Stream<T> {
    /// The pieces, in the sweep's order (made by [`Self::seal`]).
    pub(crate) pieces: Vec<Piece>,
    /// `(column j, end)` of each column's entries as pushed:
    /// `entries[end of the previous..end]`; non-empty columns only.
    pub(crate) runs: Vec<(u32, u32)>,
    /// The entries' rows.
    pub(crate) rows: Vec<u32>,
    /// The entries' columns (read by the [`MIXED`] pieces).
    pub(crate) cols: Vec<u32>,
    /// The entries' values.
    pub(crate) vals: Vec<T>,
}

/// The shortest run of consecutive rows that [`Stream::seal`] makes a
/// segment: shorter runs cost more as segments (a loop set up per run)
/// than entry by entry (measured with callgrind on the hexapod walk's
/// sweeps: most of `L`'s runs are one or two entries long).
pub(crate) const SEGMENT_MIN: u32 = 6;

/// Marks a [`Piece`] of entries updated one by one through their rows.
const BY_ROW: u32 = u32::MAX;

/// Marks a [`Piece`] of entries of several columns, updated one by one
/// through their rows and columns (`w[j]` read per entry).
const MIXED: u32 = u32::MAX - 1;

/// One piece of a [`Stream`]: column `col`'s entries `start..end`; a
/// segment of rows `row..row + (end − start)`, or, with `row ==
/// BY_ROW`, entries with their own rows; with `row == MIXED`, the entries
/// `start..end` of one or more columns, each with its own row and column.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Piece {
    pub(crate) col: u32,
    pub(crate) row: u32,
    pub(crate) start: u32,
    pub(crate) end: u32,
}

impl<T> Stream<T> {
    /// Room for `entries` entries in all (and as many pieces and columns,
    /// the most they can make).
    pub(crate) fn with_capacity(entries: usize) -> Self {
        Self {
            pieces: Vec::with_capacity(entries),
            runs: Vec::with_capacity(entries),
            rows: Vec::with_capacity(entries),
            cols: Vec::with_capacity(entries),
            vals: Vec::with_capacity(entries),
        }
    }

    /// Reserves room for `entries` more entries (pieces, columns).
    pub(crate) fn reserve(&mut self, entries: usize) {
        self.pieces.reserve(entries);
        self.runs.reserve(entries);
        self.rows.reserve(entries);
        self.cols.reserve(entries);
        self.vals.reserve(entries);
    }

    /// The entries this can hold without allocating.
    pub(crate) fn capacity(&self) -> usize {
        self.pieces
            .capacity()
            .min(self.runs.capacity())
            .min(self.rows.capacity())
            .min(self.cols.capacity())
            .min(self.vals.capacity())
    }

    pub(crate) fn clear(&mut self) {
        self.pieces.clear();
        self.runs.clear();
        self.rows.clear();
        self.cols.clear();
        self.vals.clear();
    }

    /// Closes column `j`'s run: the entries pushed since the last run
    /// (directly into [`Self::rows`] and [`Self::vals`]) are column `j`'s,
    /// a run when there are any. The same as [`Self::push`] for each of
    /// them.
    pub(crate) fn end_run(&mut self, j: u32) {
        let end = self.rows.len() as u32;
        self.cols.resize(self.rows.len(), j);
        if self.runs.last().map_or(0, |&(_, e)| e) < end {
            self.runs.push((j, end));
        }
    }

    /// Appends entry `(i, v)` of column `j` (a column's entries must be
    /// pushed together); [`Self::seal`] after the last one.
    pub(crate) fn push(&mut self, i: u32, j: u32, v: T) {
        self.rows.push(i);
        self.cols.push(j);
        self.vals.push(v);
        let end = self.rows.len() as u32;
        match self.runs.last_mut() {
            Some((c, e)) if *c == j => *e = end,
            _ => self.runs.push((j, end)),
        }
    }

    /// Cuts the pushed entries into pieces (see the type's docs).
    pub(crate) fn seal(&mut self) {
        self.pieces.clear();
        let mut start = 0u32;
        for &(col, end) in &self.runs {
            // Entries `loose..i` wait to be a by-row piece.
            let mut loose = start;
            let mut i = start;
            while i < end {
                // The run of consecutive rows from `i`.
                let mut e = i + 1;
                while e < end && self.rows[e as usize] == self.rows[e as usize - 1] + 1 {
                    e += 1;
                }
                if e - i >= SEGMENT_MIN {
                    if loose < i {
                        self.pieces.push(Piece {
                            col,
                            row: BY_ROW,
                            start: loose,
                            end: i,
                        });
                    }
                    self.pieces.push(Piece {
                        col,
                        row: self.rows[i as usize],
                        start: i,
                        end: e,
                    });
                    loose = e;
                }
                i = e;
            }
            if loose < end {
                self.pieces.push(Piece {
                    col,
                    row: BY_ROW,
                    start: loose,
                    end,
                });
            }
            start = end;
        }
        self.merge_by_row();
    }

    /// Joins each run of two or more consecutive by-row pieces into one
    /// [`MIXED`] piece (the same entries in the same order): a piece's own
    /// cost (its column's `w[j]`, its range and kind, a loop set up) is
    /// more than that of reading each entry's `w[j]`, where columns are
    /// short (most of `L`'s runs are one or two entries long: [`SEGMENT_MIN`]).
    /// Measured with `valgrind --tool=cachegrind`: the planar moving
    /// flight of `bench/peer` 1.6 % fewer instructions, the hexapod walk
    /// 0.6 % (joining only pieces of at most 2 or 4 entries saves less;
    /// segments from 4 or 10 rows instead of [`SEGMENT_MIN`] cost more).
    fn merge_by_row(&mut self) {
        let by_row = |p: &Piece| p.row == BY_ROW;
        let mut out = 0;
        let mut i = 0;
        while i < self.pieces.len() {
            let mut e = i;
            while e < self.pieces.len() && by_row(&self.pieces[e]) {
                e += 1;
            }
            if e - i >= 2 {
                self.pieces[out] = Piece {
                    col: self.pieces[i].col,
                    row: MIXED,
                    start: self.pieces[i].start,
                    end: self.pieces[e - 1].end,
                };
                out += 1;
                i = e;
            } else {
                self.pieces[out] = self.pieces[i];
                out += 1;
                i += 1;
            }
        }
        self.pieces.truncate(out);
    }

    /// Each column's number and the range of its entries, in order.
    pub(crate) fn columns(&self) -> impl Iterator<Item = (u32, std::ops::Range<usize>)> + '_ {
        let mut start = 0;
        self.runs.iter().map(move |&(col, end)| {
            let range = start..end as usize;
            start = end as usize;
            (col, range)
        })
    }

    /// Clears this and gives it `other`'s entries and pieces, with the
    /// values `value(j, v)` of `other`'s (`j` the entry's column).
    pub(crate) fn map_from<U: Copy>(
        &mut self,
        other: &Stream<U>,
        mut value: impl FnMut(u32, U) -> T,
    ) {
        self.clear();
        self.pieces.extend_from_slice(&other.pieces);
        self.runs.extend_from_slice(&other.runs);
        self.rows.extend_from_slice(&other.rows);
        self.cols.extend_from_slice(&other.cols);
        let mut start = 0;
        for &(col, end) in &other.runs {
            self.vals.extend(
                other.vals[start..end as usize]
                    .iter()
                    .map(|&u| value(col, u)),
            );
            start = end as usize;
        }
    }
}

impl Stream<f64> {
    /// The sweep `w[i] −= v·w[j]` over every entry, in order.
    #[inline]
    fn sweep(&self, w: &mut [f64]) {
        for p in &self.pieces {
            let (start, end) = (p.start as usize, p.end as usize);
            let vals = &self.vals[start..end];
            if p.row == MIXED {
                for ((&i, &j), &v) in self.rows[start..end]
                    .iter()
                    .zip(&self.cols[start..end])
                    .zip(vals)
                {
                    w[i as usize] -= v * w[j as usize];
                }
                continue;
            }
            // Final when column `j`'s updates start (see `Factors::sweep`).
            let wj = w[p.col as usize];
            if p.row == BY_ROW {
                for (&i, &v) in self.rows[start..end].iter().zip(vals) {
                    w[i as usize] -= v * wj;
                }
            } else {
                let row = p.row as usize;
                for (x, &v) in w[row..row + vals.len()].iter_mut().zip(vals) {
                    *x -= v * wj;
                }
            }
        }
    }
}

/// Numeric LU storage for the reduced patterns of one dimension: faer's
/// simplicial `L`, `U` and row pivoting of the last factorisation, `U`
/// scaled for the solves, and the scratch of the solves.
#[derive(Clone)]
pub(crate) struct Factors {
    n: usize,
    lu: SimplicialLu<usize, f64>,
    row_perm: Vec<usize>,
    row_perm_inv: Vec<usize>,
    /// The full row of each pivot row (the owner's kept rows through the
    /// row pivoting).
    row_src: Vec<usize>,
    /// `1 / U[j, j]` of the last factorisation.
    pivot_inv: Vec<f64>,
    /// `L`'s entries below its unit diagonal, column after column: the
    /// forward sweep in one stream.
    lower: Stream<f64>,
    /// `U`'s entries above its diagonal divided by their column's pivot,
    /// last column first: the backward sweep in one stream.
    upper: Stream<f64>,
    /// Scratch of [`Self::solve`].
    work: Vec<f64>,
    /// The compiled factorisation's perturbed pivots `(position, δ)`
    /// (see [`crate::compiled`], "Perturbed pivots"); empty after faer's.
    perturbed: Vec<(u32, f64)>,
    /// `W = M⁻¹·E`, interleaved (`wood_stride`): the solution of each
    /// perturbed position's unit vector with the perturbed factors `M`.
    wood_w: Vec<f64>,
    /// Stride of `W`'s rows (interleaved: `wood_w[position·stride + a]`).
    wood_stride: usize,
    /// The inverse of the capacitance matrix `D⁻¹ − Eᵀ·W` (row-major).
    wood_c: Vec<f64>,
    /// Scratch of the capacitance inversion and of the accuracy check.
    wood_t: Vec<f64>,
    check_b: Vec<f64>,
    check_x: Vec<f64>,
    check_s: Vec<f64>,
    /// The compiled program's row order (`CompiledLu::choose_rows`).
    row_choice: Vec<usize>,
    /// The pattern whose factorisation this holds (none after the dense
    /// warm-up or a failed factorisation).
    owner: Option<usize>,
    /// Whether faer's storage was grown by [`Self::warm_up`] (at its
    /// first use: a dimension whose patterns all factor by their compiled
    /// programs never calls faer).
    warmed: bool,
}

impl Factors {
    /// Scratch that [`Self::new`] and [`Self::factor`] need for dimension
    /// `n`.
    pub(crate) fn scratch(n: usize) -> StackReq {
        factorize_simplicial_numeric_lu_scratch::<usize, f64>(n, n)
    }

    /// Storage for (reduced) dimension `n`; faer's is grown to that of a
    /// dense `n × n` LU by two triangular warm-ups at its first use
    /// ([`Self::warm_up`], see the module docs). Allocates.
    pub(crate) fn new(n: usize) -> Self {
        // The sweeps' streams index rows and columns as `u32`.
        assert!(u32::try_from(n).is_ok(), "dimension {n} beyond u32");
        Self {
            n,
            lu: SimplicialLu::new(),
            row_perm: vec![0; n],
            row_perm_inv: vec![0; n],
            row_src: vec![0; n],
            pivot_inv: vec![0.0; n],
            lower: Stream::with_capacity(n * n.saturating_sub(1) / 2),
            upper: Stream::with_capacity(n * n.saturating_sub(1) / 2),
            work: vec![0.0; n],
            perturbed: Vec::with_capacity(MAX_PERTURBED),
            wood_w: Vec::with_capacity((MAX_PERTURBED + 1) * n),
            wood_stride: 1,
            wood_c: Vec::with_capacity(MAX_PERTURBED * MAX_PERTURBED),
            wood_t: Vec::with_capacity(2 * MAX_PERTURBED * MAX_PERTURBED),
            check_b: vec![0.0; n],
            check_x: vec![0.0; n],
            check_s: vec![0.0; n],
            row_choice: Vec::with_capacity(n),
            owner: None,
            warmed: false,
        }
    }

    /// Factors `reduced` with program `index` of `pattern`: its
    /// factorisation, the sweeps' streams and, for perturbed pivots, the
    /// Woodbury correction and its check. The path taken, or `None` when a
    /// pivot could not be perturbed or the correction failed (the caller
    /// then falls back).
    fn run_program(
        &mut self,
        pattern: &mut Pattern,
        index: usize,
        reduced: &[f64],
    ) -> Option<FactorPath> {
        pattern.factorizations += 1;
        pattern.programs[index].last_use = pattern.factorizations;
        let program = &mut pattern.programs[index].lu;
        program
            .factor(reduced, &mut self.pivot_inv, &mut self.perturbed)
            .ok()?;
        for (s, &p) in self.row_src.iter_mut().zip(&program.row_perm) {
            *s = pattern.kept_rows[p];
        }
        // The sweeps' streams: fixed entries, this factorisation's
        // values (`U`'s divided by their column's pivot).
        self.lower.map_from(&program.lower, |_, s| program.value(s));
        let pivot_inv = &self.pivot_inv;
        self.upper.map_from(&program.upper, |j, s| {
            program.value(s) * pivot_inv[j as usize]
        });
        let fwd = pattern.col_perm.arrays().0;
        let ok = self.perturbed.is_empty()
            || self.woodbury(
                pattern.structure.col_ptr(),
                pattern.structure.row_idx(),
                reduced,
                &program.row_perm,
                fwd,
            );
        if !ok {
            return None;
        }
        self.owner = Some(pattern.id);
        pattern.solves_since = 0;
        pattern.chords_since = 0;
        pattern.programs[index].fails = 0;
        Some(if self.perturbed.is_empty() {
            FactorPath::Compiled
        } else {
            FactorPath::Corrected
        })
    }

    /// Compiles a program of `pattern` on `reduced`, values whose exact
    /// zeros have the signature `zeros`, and keeps it. The row order is
    /// chosen by threshold Markowitz on these values (less fill than
    /// faer's partial pivoting); where that finds no pivot, the row order
    /// of faer's factorisation of these values just made when `faer_rows`,
    /// else nothing is compiled. In place of program `replace`, else of a
    /// new one, or of the least recently tried but the first when
    /// [`MAX_PROGRAMS`] are kept. A new program allocates, as a pattern's
    /// registration does; a replaced one only when it outgrows its storage.
    fn add_program(
        &mut self,
        sc: &mut CompileScratch,
        pattern: &mut Pattern,
        reduced: &[f64],
        zeros: u64,
        faer_rows: bool,
        replace: Option<usize>,
    ) {
        let (col_ptr, row_idx) = (pattern.structure.col_ptr(), pattern.structure.row_idx());
        let fwd = pattern.col_perm.arrays().0;
        let rows = match CompiledLu::choose_rows(sc, col_ptr, row_idx, fwd, reduced) {
            Some(order) => {
                self.row_choice.clear();
                self.row_choice.extend_from_slice(order);
                &self.row_choice
            }
            None if faer_rows => &self.row_perm,
            None => return,
        };
        let stamp = pattern.factorizations;
        let place = match replace {
            Some(i) => i,
            None if pattern.programs.len() < MAX_PROGRAMS => {
                pattern.programs.push(Program::default());
                pattern.programs.len() - 1
            }
            // The least recently tried program after the first gives its
            // place.
            None => {
                pattern
                    .programs
                    .iter()
                    .enumerate()
                    .skip(1)
                    .min_by_key(|(_, p)| p.last_use)
                    .expect("MAX_PROGRAMS > 1")
                    .0
            }
        };
        // A program replaced is compiled again in its own storage (room
        // for one of twice its first size): the replacements of a long run
        // allocate only when a program outgrows it.
        let program = &mut pattern.programs[place];
        program.lu.compile(sc, col_ptr, row_idx, fwd, rows, true);
        program.zeros = zeros;
        program.last_use = stamp;
        program.fails = 0;
        program.renewed = replace.is_some();
    }

    /// Grows faer's storage to that of a dense `n × n` LU by two
    /// triangular warm-ups (see the module docs). Allocates.
    fn warm_up(&mut self, mem: &mut MemBuffer) {
        let n = self.n;
        // Two triangular warm-ups reach the storage of a dense LU at the
        // cost of O(n²) each (see the module docs): a dense lower triangle
        // with a full last column grows `L` (and the last column's request
        // of `U`), a dense upper triangle grows `U`. Diagonally dominant,
        // so partial pivoting keeps the diagonal.
        let identity: Vec<usize> = (0..n).collect();
        for lower in [true, false] {
            let mut col_ptr = Vec::with_capacity(n + 1);
            let mut row_idx = Vec::new();
            let mut values = Vec::new();
            col_ptr.push(0);
            for j in 0..n {
                let rows = if lower && j + 1 < n {
                    j..n
                } else if lower {
                    0..n
                } else {
                    0..j + 1
                };
                for i in rows {
                    row_idx.push(i);
                    values.push(if i == j { 2.0 * n as f64 } else { 1.0 });
                }
                col_ptr.push(row_idx.len());
            }
            let triangle = SparseColMatRef::new(
                SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx),
                &values,
            );
            factorize_simplicial_numeric_lu(
                &mut self.row_perm,
                &mut self.row_perm_inv,
                &mut self.lu,
                triangle,
                PermRef::new_checked(&identity, &identity, n),
                MemStack::new(mem),
            )
            .unwrap_or_else(|e| panic!("faer warm-up LU failed: {e:?}"));
        }
    }

    /// The (reduced) dimension.
    pub(crate) fn dim(&self) -> usize {
        self.n
    }

    /// Whether this holds a factorisation of `pattern` (usable for chord
    /// steps).
    pub(crate) fn holds(&self, pattern: &Pattern) -> bool {
        self.owner == Some(pattern.id)
    }

    /// Numeric LU of `values` (the layout of `pattern`'s slots), reusing its
    /// column ordering; the eliminated rows' pivots and columns are copied
    /// into `pattern`. `mem` must hold [`Self::scratch`]; `sc` is the
    /// scratch of a compilation (the pattern's first factorisation with
    /// `compiled`, or a new set of exact zeros that the first program
    /// cannot factor, which allocate the program, or a program's
    /// [`RECOMPILE_AFTER`]-th fallback in a row, which allocates only when
    /// the program outgrows its storage). Allocation-free otherwise.
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
        sc: &mut CompileScratch,
        compiled: bool,
    ) -> Result<FactorPath, SolverError> {
        let n = self.n;
        assert_eq!(pattern.m, n, "pattern and storage dimensions differ");
        self.owner = None;
        let reduced_nnz = pattern.structure.row_idx().len();
        let (reduced, eliminated) = values[..pattern.nnz].split_at(reduced_nnz);
        let (pivots, couplings) = eliminated.split_at(pattern.singles.len());
        for (p, &v) in pattern.single_inv.iter_mut().zip(pivots) {
            *p = v.recip();
        }
        pattern.coupling.copy_from_slice(couplings);
        let mut path = FactorPath::Faer;
        // The program compiled on values with these exact zeros, else the
        // pattern's first one.
        let zeros = if compiled && n > 0 {
            zero_signature(reduced)
        } else {
            0
        };
        if compiled && n > 0 && pattern.programs.is_empty() {
            // The pattern's first program, before any factorisation; where
            // the row choice finds no pivot, faer's LU below and its rows.
            self.add_program(sc, pattern, reduced, zeros, false, None);
        }
        let mut known = pattern.programs.iter().position(|p| p.zeros == zeros);
        if compiled && n > 0 && !pattern.programs.is_empty() {
            if let Some(path) = self.run_program(pattern, known.unwrap_or(0), reduced) {
                return Ok(path);
            }
            if known.is_none() && !pattern.failed.contains(&zeros) {
                // A set of zeros without a program of its own, which the
                // pattern's first program cannot factor: its own program,
                // compiled on these values at once: a compilation and a
                // factorisation with it cost less than faer's LU of the
                // same values (on the 3D drop of `bench/peer`, about 0.7 M
                // instructions for a compilation, 1.05 M for faer's LU;
                // docs/reference.md, *Speed*). Not for a set whose row
                // choice already found no pivot (`Pattern::failed`): its
                // second fallback compiles it on faer's rows.
                self.add_program(sc, pattern, reduced, zeros, false, None);
                known = pattern.programs.iter().position(|p| p.zeros == zeros);
                if let Some(path) = known.and_then(|i| self.run_program(pattern, i, reduced)) {
                    return Ok(path);
                }
            }
            path = FactorPath::Fallback;
        }
        self.perturbed.clear();
        if n > 0 && !self.warmed {
            self.warm_up(mem);
            self.warmed = true;
        }
        if n > 0 {
            let matrix = SparseColMatRef::new(pattern.structure.as_ref(), reduced);
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
                    let equation = pattern.col_dst[index];
                    return Err(SolverError::Singular { equation });
                }
                Err(LuError::Generic(e)) => panic!("faer numeric LU failed: {e:?}"),
            }
            for (s, &p) in self.row_src.iter_mut().zip(&self.row_perm) {
                *s = pattern.kept_rows[p];
            }
            // Both factors copied as the streams of the two sweeps
            // (`Self::solve`): faer stores each column's unit diagonal of
            // `L` first and its diagonal of `U` last (the contract of its
            // own triangular solves), and `U`'s entries are divided by
            // their column's pivot. At most the dense factors' entries (see
            // the module docs): no growth.
            let l = self.lu.l_factor_unsorted();
            let (l_ptr, l_row, l_val) = (l.symbolic().col_ptr(), l.symbolic().row_idx(), l.val());
            let u = self.lu.u_factor_unsorted();
            let (u_ptr, u_row, u_val) = (u.symbolic().col_ptr(), u.symbolic().row_idx(), u.val());
            self.lower.clear();
            self.upper.clear();
            for j in 0..n {
                let (start, end) = (l_ptr[j] + 1, l_ptr[j + 1]);
                for (&i, &v) in l_row[start..end].iter().zip(&l_val[start..end]) {
                    self.lower.push(i as u32, j as u32, v);
                }
                self.pivot_inv[j] = u_val[u_ptr[j + 1] - 1].recip();
            }
            for j in (0..n).rev() {
                let (start, diag) = (u_ptr[j], u_ptr[j + 1] - 1);
                let pivot_inv = self.pivot_inv[j];
                for (&i, &v) in u_row[start..diag].iter().zip(&u_val[start..diag]) {
                    self.upper.push(i as u32, j as u32, v * pivot_inv);
                }
            }
            self.lower.seal();
            self.upper.seal();
            // A set of zeros still without a program here is one whose
            // row choice found no pivot: it gets a program on faer's rows
            // at its second fallback (most pass once).
            let recurring = if path == FactorPath::Fallback && known.is_none() {
                match pattern.failed.iter().position(|&z| z == zeros) {
                    Some(i) => {
                        pattern.failed.swap_remove(i);
                        true
                    }
                    None => {
                        if pattern.failed.len() == 2 * MAX_PROGRAMS {
                            pattern.failed.remove(0);
                        }
                        pattern.failed.push(zeros);
                        false
                    }
                }
            } else {
                path == FactorPath::Faer
            };
            if compiled && known.is_none() && recurring {
                self.add_program(sc, pattern, reduced, zeros, true, None);
            }
            if let Some(i) = known.filter(|_| compiled && path == FactorPath::Fallback) {
                // A fallback of a known set of zeros keeps its program for
                // the next factorisation (a failed pivot then is mostly a
                // passing cancellation; recompiling at each such fallback
                // was measured dearer, 1.6 M instructions a time on the
                // hexapod walk) until it has failed `RECOMPILE_AFTER`
                // times in a row; then it is compiled again, once.
                let program = &mut pattern.programs[i];
                program.fails += 1;
                if program.fails >= RECOMPILE_AFTER && !program.renewed {
                    self.add_program(sc, pattern, reduced, zeros, true, Some(i));
                }
            }
        }
        self.owner = Some(pattern.id);
        pattern.solves_since = 0;
        pattern.chords_since = 0;
        Ok(path)
    }

    /// Solves `J x = rhs` in place with the last factorisation of
    /// `pattern`'s Jacobian: the eliminated rows' unknowns, their columns'
    /// contributions moved to the right-hand side, then the reduced system
    /// `P·J_r·Q = L·U` (`P`: row pivoting, `Q`: `pattern`'s column
    /// ordering). A zero pivot gives non-finite entries. No allocation.
    ///
    /// # Panics
    /// If this does not hold a factorisation of `pattern`.
    pub(crate) fn solve(&mut self, pattern: &mut Pattern, rhs: &mut [f64]) {
        let n = self.n;
        assert!(self.holds(pattern), "no factorisation of this pattern");
        assert_eq!(rhs.len(), pattern.n, "right-hand side has the wrong length");
        for ((x, &(i, _)), &p) in pattern
            .single_x
            .iter_mut()
            .zip(&pattern.singles)
            .zip(&pattern.single_inv)
        {
            *x = rhs[i] * p;
        }
        for (&(k, t), &c) in pattern.couplings.iter().zip(&pattern.coupling) {
            rhs[k] -= c * pattern.single_x[t];
        }
        if n > 0 {
            let w = &mut self.work[..n];
            for (wi, &p) in w.iter_mut().zip(&self.row_src) {
                *wi = rhs[p];
            }
            if self.perturbed.is_empty() {
                // The sweeps with the reciprocal pivots applied as the
                // solution is scattered (one pass fewer).
                Self::sweep_unscaled(&self.lower, &self.upper, w);
                for ((&c, &wj), &p) in pattern.col_dst.iter().zip(w.iter()).zip(&self.pivot_inv) {
                    rhs[c] = wj * p;
                }
            } else {
                Self::sweep(&self.lower, &self.upper, &self.pivot_inv, w);
                Self::correct(
                    &self.perturbed,
                    &self.wood_w,
                    self.wood_stride,
                    &self.wood_c,
                    w,
                );
                for (&c, &wj) in pattern.col_dst.iter().zip(w.iter()) {
                    rhs[c] = wj;
                }
            }
        }
        for (&x, &(_, j)) in pattern.single_x.iter().zip(&pattern.singles) {
            rhs[j] = x;
        }
    }
}

impl Factors {
    /// `w ← M⁻¹·w` in pivot positions with the factors' streams: `L`,
    /// column after column (`w[j]` is final when column `j`'s updates
    /// start, they come from the columns before it), then `U D⁻¹`, last
    /// column first (`w[j]` is final, unscaled, when column `j`'s updates
    /// start), then the reciprocal pivots.
    fn sweep(lower: &Stream<f64>, upper: &Stream<f64>, pivot_inv: &[f64], w: &mut [f64]) {
        Self::sweep_unscaled(lower, upper, w);
        for (wj, &p) in w.iter_mut().zip(pivot_inv) {
            *wj *= p;
        }
    }

    /// [`Self::sweep`] without the reciprocal pivots: `w ← U⁻¹·L⁻¹·w`
    /// scaled by the pivots, `(D·M⁻¹)·w`.
    fn sweep_unscaled(lower: &Stream<f64>, upper: &Stream<f64>, w: &mut [f64]) {
        lower.sweep(w);
        upper.sweep(w);
    }

    /// `w ← M⁻¹·w` for `c` right-hand sides at once, interleaved
    /// (`w[position·c + column]`): [`Self::sweep`] with each stream entry
    /// read once for all of them.
    fn sweep_many(
        lower: &Stream<f64>,
        upper: &Stream<f64>,
        pivot_inv: &[f64],
        w: &mut [f64],
        c: usize,
    ) {
        // `c` is the number of perturbed pivots plus one: a fixed width
        // per call up to `MAX_PERTURBED + 1`, so that each entry's row
        // update is unrolled (widths 10 to 17 by the general loop cost
        // the 3D drop of `bench/peer` 4.7 % more instructions in all:
        // 1,585.6 M against 1,514.9 M, `valgrind --tool=cachegrind`).
        match c {
            1 => Self::sweep_rows::<1>(lower, upper, w),
            2 => Self::sweep_rows::<2>(lower, upper, w),
            3 => Self::sweep_rows::<3>(lower, upper, w),
            4 => Self::sweep_rows::<4>(lower, upper, w),
            5 => Self::sweep_rows::<5>(lower, upper, w),
            6 => Self::sweep_rows::<6>(lower, upper, w),
            7 => Self::sweep_rows::<7>(lower, upper, w),
            8 => Self::sweep_rows::<8>(lower, upper, w),
            9 => Self::sweep_rows::<9>(lower, upper, w),
            10 => Self::sweep_rows::<10>(lower, upper, w),
            11 => Self::sweep_rows::<11>(lower, upper, w),
            12 => Self::sweep_rows::<12>(lower, upper, w),
            13 => Self::sweep_rows::<13>(lower, upper, w),
            14 => Self::sweep_rows::<14>(lower, upper, w),
            15 => Self::sweep_rows::<15>(lower, upper, w),
            16 => Self::sweep_rows::<16>(lower, upper, w),
            17 => Self::sweep_rows::<17>(lower, upper, w),
            _ => {
                for stream in [lower, upper] {
                    for (col, range) in stream.columns() {
                        let j = col as usize * c;
                        for (&i, &v) in stream.rows[range.clone()].iter().zip(&stream.vals[range]) {
                            let i = i as usize * c;
                            for k in 0..c {
                                w[i + k] -= v * w[j + k];
                            }
                        }
                    }
                }
            }
        }
        for (row, &p) in w.chunks_exact_mut(c).zip(pivot_inv) {
            for x in row {
                *x *= p;
            }
        }
    }

    /// The sweeps of [`Self::sweep_many`] for `C` right-hand sides: the
    /// same operations, column `j`'s `C` values read once for its run
    /// (final then, see [`Self::sweep`]).
    fn sweep_rows<const C: usize>(lower: &Stream<f64>, upper: &Stream<f64>, w: &mut [f64]) {
        let (rows, _) = w.as_chunks_mut::<C>();
        for stream in [lower, upper] {
            for (col, range) in stream.columns() {
                let src = rows[col as usize];
                for (&i, &v) in stream.rows[range.clone()].iter().zip(&stream.vals[range]) {
                    for (x, s) in rows[i as usize].iter_mut().zip(src) {
                        *x -= v * s;
                    }
                }
            }
        }
    }

    /// The Sherman–Morrison–Woodbury correction of a solve with perturbed
    /// factors (see [`crate::compiled`], "Perturbed pivots"): with
    /// `y = M⁻¹·b` in `w` (stride 1), `w ← y + W·C⁻¹·y[K]`, which is
    /// `B⁻¹·b` for `B = M − E·D·Eᵀ` (`W` interleaved with stride
    /// `stride ≥ r`). Nothing when no pivot was perturbed.
    fn correct(
        perturbed: &[(u32, f64)],
        wood_w: &[f64],
        stride: usize,
        wood_c: &[f64],
        w: &mut [f64],
    ) {
        let r = perturbed.len();
        if r == 0 {
            return;
        }
        let mut y = [0.0f64; MAX_PERTURBED];
        for (ya, &(k, _)) in y.iter_mut().zip(perturbed) {
            *ya = w[k as usize];
        }
        let mut z = [0.0f64; MAX_PERTURBED];
        for (b, zb) in z.iter_mut().enumerate().take(r) {
            *zb = (0..r).map(|a| wood_c[b * r + a] * y[a]).sum();
        }
        for (wi, row) in w.iter_mut().zip(wood_w.chunks_exact(stride)) {
            *wi += row[..r].iter().zip(&z).map(|(x, y)| x * y).sum::<f64>();
        }
    }

    /// Prepares the correction of a factorisation with perturbed pivots:
    /// `W = M⁻¹·E` and the inverse of the capacitance matrix
    /// `C = D⁻¹ − Eᵀ·W`, then an accuracy check of a solve against the
    /// reduced matrix (`col_ptr`, `row_idx`, `values`; `rows[i]`: reduced
    /// row of pivot position `i`, `fwd[k]`: reduced column of position
    /// `k`): its normwise backward error must be at most
    /// [`WOODBURY_CHECK`]. `W` and the check's right-hand side are swept
    /// together ([`Self::sweep_many`]). `false` (the caller factors with
    /// faer) when `C` is singular or the check fails. Allocation-free.
    fn woodbury(
        &mut self,
        col_ptr: &[usize],
        row_idx: &[usize],
        values: &[f64],
        rows: &[usize],
        fwd: &[usize],
    ) -> bool {
        let n = self.n;
        let r = self.perturbed.len();
        let c = r + 1;
        // The check's right-hand side: b = A·v for a known v.
        let b = &mut self.check_b;
        b.fill(0.0);
        for j in 0..n {
            let vj = 1.0 + j as f64 / n as f64;
            for (&i, &a) in row_idx[col_ptr[j]..col_ptr[j + 1]]
                .iter()
                .zip(&values[col_ptr[j]..col_ptr[j + 1]])
            {
                b[i] += a * vj;
            }
        }
        let w = &mut self.wood_w;
        w.clear();
        w.resize(c * n, 0.0);
        for (a, &(k, _)) in self.perturbed.iter().enumerate() {
            w[k as usize * c + a] = 1.0;
        }
        for (i, &p) in rows.iter().enumerate() {
            w[i * c + r] = b[p];
        }
        Self::sweep_many(&self.lower, &self.upper, &self.pivot_inv, w, c);
        // C inverted by Gauss–Jordan with partial pivoting on [C | I].
        let t = &mut self.wood_t;
        t.clear();
        t.resize(2 * r * r, 0.0);
        let cols = 2 * r;
        for (a, &(ka, da)) in self.perturbed.iter().enumerate() {
            for b in 0..r {
                t[a * cols + b] = -w[ka as usize * c + b];
            }
            t[a * cols + a] += da.recip();
            t[a * cols + r + a] = 1.0;
        }
        for col in 0..r {
            let p = (col..r)
                .max_by(|&i, &j| t[i * cols + col].abs().total_cmp(&t[j * cols + col].abs()))
                .unwrap_or(col);
            let pv = t[p * cols + col];
            if pv == 0.0 || !pv.is_finite() {
                return false;
            }
            if p != col {
                for j in 0..cols {
                    t.swap(p * cols + j, col * cols + j);
                }
            }
            let inv = pv.recip();
            for j in 0..cols {
                t[col * cols + j] *= inv;
            }
            for i in 0..r {
                if i != col {
                    let f = t[i * cols + col];
                    if f != 0.0 {
                        for j in 0..cols {
                            t[i * cols + j] -= f * t[col * cols + j];
                        }
                    }
                }
            }
        }
        self.wood_c.clear();
        for a in 0..r {
            self.wood_c
                .extend_from_slice(&t[a * cols + r..(a + 1) * cols]);
        }
        self.wood_stride = c;
        // The check: the solution of b, corrected, and its residual.
        let y = &mut self.work[..n];
        for (yi, row) in y.iter_mut().zip(w.chunks_exact(c)) {
            *yi = row[r];
        }
        Self::correct(&self.perturbed, w, c, &self.wood_c, y);
        let (x, s) = (&mut self.check_x, &mut self.check_s);
        for (&col, &yk) in fwd.iter().zip(y.iter()) {
            x[col] = yk;
        }
        s.fill(0.0);
        for j in 0..n {
            for (&i, &a) in row_idx[col_ptr[j]..col_ptr[j + 1]]
                .iter()
                .zip(&values[col_ptr[j]..col_ptr[j + 1]])
            {
                b[i] -= a * x[j];
                s[i] += (a * x[j]).abs();
            }
        }
        let residual = b.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let size = s.iter().fold(0.0f64, |m, v| m.max(*v));
        residual <= WOODBURY_CHECK * size
    }
}

/// The accuracy a solve with perturbed pivots must reach on its check
/// ([`Factors::woodbury`]): a normwise backward error
/// `max_i |b − A·x|_i ≤ 1e-9 · max_i Σ_j |a_ij·x_j|`, the solve of a
/// system within 1e-9 of the Jacobian entry by entry, as close as Newton's
/// residual tolerance (1e-9 of each row's scale) asks of its steps: Newton
/// converges on the true residual, so a step that solves its system to
/// that accuracy rather than to round-off costs at most an iteration, and
/// the solution is the same to the solver's tolerance. Measured on the
/// 1000 landings of `examples/sweep_hexapod_landing_1000.toml` (the
/// `quick` build, `--jobs 2`, stepping time summed over the runs, runs
/// alternating): 61.9–65.4 s at 1e-13 (this check before), 60.6 s at
/// 1e-11, 60.1 s at 1e-10, 58.5–59.5 s at 1e-9; all 1000 complete and
/// exact at each.
const WOODBURY_CHECK: f64 = 1e-9;

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::linalg::lu::{NumericLu, factorize_symbolic_lu};
    use faer::{Conj, MatMut, Par};

    /// New storage for `pattern` with its factorisation by faer's
    /// pivoting LU (the reference path).
    fn faer_factors(pattern: &mut Pattern, values: &[f64], mem: &mut MemBuffer) -> Factors {
        let mut factors = Factors::new(pattern.m);
        factors
            .factor(pattern, values, mem, &mut CompileScratch::default(), false)
            .expect("nonsingular");
        factors
    }

    /// A linear congruential generator from `seed` (the high bits of each
    /// state): the sweeps' tests' entries.
    fn lcg(seed: u64) -> impl FnMut() -> u64 {
        let mut s = seed;
        move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            s >> 33
        }
    }

    /// A stream's pieces hold every entry once, in order, segments only
    /// of consecutive rows and at least `SEGMENT_MIN` long, no two by-row
    /// pieces in a row (they are one mixed piece), and its sweep
    /// is the entry-by-entry sweep bit for bit (columns of every mix of
    /// runs: long, short, by themselves and between segments).
    #[test]
    fn pieces_sweep_as_entries_do() {
        let n = 40u32;
        let mut next = lcg(7);
        let mut stream = Stream::with_capacity((n * n) as usize);
        let mut entries = Vec::new();
        for j in 0..n - 1 {
            let mut i = j + 1;
            while i < n {
                if !next().is_multiple_of(3) {
                    let v = (next() % 1000) as f64 / 997.0 - 0.5;
                    stream.push(i, j, v);
                    entries.push((i, j, v));
                }
                i += 1 + next().is_multiple_of(4) as u32 * (1 + (next() % 3) as u32);
            }
        }
        stream.seal();
        let mut covered = vec![false; entries.len()];
        let mut last = 0;
        for p in &stream.pieces {
            assert_eq!(p.start, last, "pieces in order, none skipped");
            last = p.end;
            for e in p.start..p.end {
                let (i, j, _) = entries[e as usize];
                assert_eq!(j, stream.cols[e as usize]);
                if p.row != MIXED {
                    assert_eq!(j, p.col);
                }
                covered[e as usize] = true;
                if p.row != BY_ROW && p.row != MIXED {
                    assert!(p.end - p.start >= SEGMENT_MIN);
                    assert_eq!(i, p.row + (e - p.start), "a segment's rows follow");
                }
            }
        }
        assert!(covered.iter().all(|&c| c));
        // Consecutive by-row pieces are joined into mixed ones.
        assert!(stream.pieces.iter().any(|p| p.row == MIXED));
        assert!(stream.pieces.iter().any(|p| p.row < MIXED));
        assert!(
            !stream
                .pieces
                .windows(2)
                .any(|w| w[0].row == BY_ROW && w[1].row == BY_ROW)
        );
        let w0: Vec<f64> = (0..n).map(|i| 1.0 + (i as f64).sin()).collect();
        let mut by_entry = w0.clone();
        for &(i, j, v) in &entries {
            by_entry[i as usize] -= v * by_entry[j as usize];
        }
        let mut by_piece = w0;
        stream.sweep(&mut by_piece);
        for (a, b) in by_entry.iter().zip(&by_piece) {
            assert_eq!(a.to_bits(), b.to_bits());
        }
    }

    /// The sweeps of several right-hand sides at once (the Woodbury
    /// correction's, [`Factors::sweep_many`]) are those of each one alone,
    /// bit for bit, at every width up to `MAX_PERTURBED + 1` and beyond
    /// (the unrolled widths and the general loop).
    #[test]
    fn sweeps_of_many_right_hand_sides_are_each_ones_sweep() {
        let n = 30u32;
        let mut next = lcg(11);
        let mut lower = Stream::with_capacity((n * n) as usize);
        let mut upper = Stream::with_capacity((n * n) as usize);
        for j in 0..n - 1 {
            for i in j + 1..n {
                if next().is_multiple_of(3) {
                    lower.push(i, j, (next() % 1000) as f64 / 997.0 - 0.5);
                }
            }
        }
        // `U`, last column first, its entries above the diagonal.
        for j in (1..n).rev() {
            for i in 0..j {
                if next().is_multiple_of(3) {
                    upper.push(i, j, (next() % 1000) as f64 / 991.0 - 0.5);
                }
            }
        }
        lower.seal();
        upper.seal();
        let pivot_inv: Vec<f64> = (0..n).map(|i| 1.0 / (2.0 + (i as f64).cos())).collect();
        for c in 1..=MAX_PERTURBED + 3 {
            let columns: Vec<Vec<f64>> = (0..c)
                .map(|k| {
                    (0..n)
                        .map(|i| ((i as usize * 7 + k * 3) as f64).sin())
                        .collect()
                })
                .collect();
            let mut many: Vec<f64> = (0..n as usize * c).map(|x| columns[x % c][x / c]).collect();
            Factors::sweep_many(&lower, &upper, &pivot_inv, &mut many, c);
            for (k, col) in columns.iter().enumerate() {
                let mut one = col.clone();
                Factors::sweep(&lower, &upper, &pivot_inv, &mut one);
                for (i, x) in one.iter().enumerate() {
                    assert_eq!(
                        x.to_bits(),
                        many[i * c + k].to_bits(),
                        "width {c}, column {k}"
                    );
                }
            }
        }
    }

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

    /// [`matrix`] with singleton rows: every fifth row keeps only its
    /// diagonal entry (value 1 or 2.5).
    fn with_singletons(n: usize, seed: u64) -> Vec<(usize, usize, f64)> {
        let mut e: Vec<_> = matrix(n, seed)
            .into_iter()
            .filter(|&(i, _, _)| i % 5 != 0)
            .collect();
        for i in (0..n).step_by(5) {
            e.push((i, i, if i % 2 == 0 { 1.0 } else { 2.5 }));
        }
        e
    }

    #[test]
    fn solve_matches_faer() {
        let cases = [(5, 1), (19, 2), (31, 3), (64, 4)]
            .into_iter()
            .flat_map(|(n, seed)| [matrix(n, seed), with_singletons(n, seed)]);
        for triplets in cases {
            let n = 1 + triplets.iter().map(|t| t.0.max(t.1)).max().unwrap();
            let mut entries: Vec<(usize, usize)> = triplets.iter().map(|t| (t.0, t.1)).collect();
            let mut pattern = Pattern::build(0, n, &mut entries);
            let mut values = vec![0.0; pattern.nnz()];
            for &(i, j, v) in &triplets {
                values[pattern.slot[i * n + j] as usize] += v;
            }
            // faer's own LU of the full matrix, for comparison.
            let mut sorted: Vec<(usize, usize, f64)> = triplets.clone();
            sorted.sort_by_key(|&(i, j, _)| (j, i));
            let mut csc: Vec<(usize, usize, f64)> = Vec::new();
            for (i, j, v) in sorted {
                match csc.last_mut() {
                    Some(last) if (last.0, last.1) == (i, j) => last.2 += v,
                    _ => csc.push((i, j, v)),
                }
            }
            let mut col_ptr = vec![0usize; n + 1];
            for &(_, j, _) in &csc {
                col_ptr[j + 1] += 1;
            }
            for j in 0..n {
                col_ptr[j + 1] += col_ptr[j];
            }
            let row_idx: Vec<usize> = csc.iter().map(|t| t.0).collect();
            let full_values: Vec<f64> = csc.iter().map(|t| t.2).collect();
            let structure = SymbolicSparseColMatRef::new_checked(n, n, &col_ptr, None, &row_idx);
            let symbolic = factorize_symbolic_lu(structure, Default::default()).expect("symbolic");
            let mut mem =
                MemBuffer::new(Factors::scratch(n).or(
                    symbolic.solve_in_place_scratch::<f64>(1, Par::Seq).or(
                        symbolic.factorize_numeric_lu_scratch::<f64>(Par::Seq, Default::default()),
                    ),
                ));
            let mut factors = faer_factors(&mut pattern, &values, &mut mem);
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
            let mut ours = b.clone();
            factors.solve(&mut pattern, &mut ours);

            let mut numeric = NumericLu::new();
            let a = SparseColMatRef::new(structure, &full_values[..]);
            let lu = symbolic
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

    thread_local! {
        /// One compilation scratch per test, reused by all its patterns
        /// and dimensions (as a solver's is).
        static SCRATCH: std::cell::RefCell<CompileScratch> = Default::default();
    }

    /// Solution of `pattern`'s system with `values` and right-hand side
    /// `b`, through `factors` (compiled path or not), with its path.
    fn solve_with(
        factors: &mut Factors,
        pattern: &mut Pattern,
        values: &[f64],
        b: &[f64],
        mem: &mut MemBuffer,
        compiled: bool,
    ) -> (Vec<f64>, FactorPath) {
        let path = SCRATCH
            .with_borrow_mut(|sc| factors.factor(pattern, values, mem, sc, compiled))
            .expect("nonsingular");
        let mut x = b.to_vec();
        factors.solve(pattern, &mut x);
        (x, path)
    }

    /// A test system's dimension, pattern, scratch, storage and a
    /// right-hand side.
    fn setup(triplets: &[(usize, usize, f64)]) -> (usize, Pattern, MemBuffer, Factors, Vec<f64>) {
        let n = 1 + triplets.iter().map(|t| t.0.max(t.1)).max().unwrap();
        let mut entries: Vec<(usize, usize)> = triplets.iter().map(|t| (t.0, t.1)).collect();
        let pattern = Pattern::build(0, n, &mut entries);
        let mem = MemBuffer::new(Factors::scratch(n));
        let factors = Factors::new(pattern.m);
        let b = (0..n).map(|i| (i as f64 * 0.37).cos()).collect();
        (n, pattern, mem, factors, b)
    }

    #[test]
    fn compiled_lu_matches_faer() {
        let cases = [(5, 1), (19, 2), (31, 3), (64, 4), (150, 5)]
            .into_iter()
            .flat_map(|(n, seed)| [matrix(n, seed), with_singletons(n, seed)]);
        for triplets in cases {
            let (n, mut pattern, mut mem, mut factors, b) = setup(&triplets);
            // Values of the pattern, scaled per entry by `1 + eps·sin`.
            let (slot, nnz) = (pattern.slot.clone(), pattern.nnz());
            let values_at = |eps: f64| {
                let mut values = vec![0.0; nnz];
                for (k, &(i, j, v)) in triplets.iter().enumerate() {
                    values[slot[i * n + j] as usize] += v * (1.0 + eps * (k as f64).sin());
                }
                values
            };
            let first = values_at(0.0);
            first_compiles(&mut factors, &mut pattern, &first, &b, &mut mem);
            for eps in [0.0, 1e-3, 0.05] {
                let values = values_at(eps);
                let what = format!("n = {n}, eps = {eps}");
                let path = compiled_matches_faer(
                    &mut factors,
                    &mut pattern,
                    (&values, &b),
                    &mut mem,
                    1e-12,
                    &what,
                );
                assert_eq!(path, FactorPath::Compiled, "{what}");
            }
        }
    }

    #[test]
    fn a_failed_pivot_is_perturbed_and_corrected() {
        // [[a, 1], [1, 1]]: compiled on a = 2 (row 0 pivots first), then
        // a = 1e-4 fails the check (|a| < 0.001·1, `PIVOT_THRESHOLD`): the
        // pivot is perturbed to 1 and the solve corrected
        // (Sherman–Morrison), exactly.
        let n = 2;
        let mut entries = vec![(0, 0), (0, 1), (1, 0), (1, 1)];
        let mut pattern = Pattern::build(0, n, &mut entries);
        let slot = pattern.slot.clone();
        let values_for = |a: f64| {
            let mut v = vec![0.0; 4];
            for (i, j, x) in [(0, 0, a), (0, 1, 1.0), (1, 0, 1.0), (1, 1, 1.0)] {
                v[slot[i * n + j] as usize] = x;
            }
            v
        };
        let mut mem = MemBuffer::new(Factors::scratch(n));
        let mut factors = Factors::new(pattern.m);
        let b = [1.0, 2.0];
        let first = values_for(2.0);
        let (_, path) = solve_with(&mut factors, &mut pattern, &first, &b, &mut mem, true);
        assert_eq!(path, FactorPath::Compiled);
        let (x, path) = solve_with(&mut factors, &mut pattern, &first, &b, &mut mem, true);
        assert_eq!(path, FactorPath::Compiled);
        // 2x + y = 1, x + y = 2: x = −1, y = 3.
        assert!((x[0] + 1.0).abs() < 1e-15 && (x[1] - 3.0).abs() < 1e-15);
        let small = values_for(1e-4);
        let (x, path) = solve_with(&mut factors, &mut pattern, &small, &b, &mut mem, true);
        assert_eq!(path, FactorPath::Corrected);
        // a·x + y = 1, x + y = 2: x = 1/(1 − a), y = 2 − x.
        let exact = [1.0 / (1.0 - 1e-4), 2.0 - 1.0 / (1.0 - 1e-4)];
        assert!((x[0] - exact[0]).abs() < 1e-14 && (x[1] - exact[1]).abs() < 1e-14);
        // a = 5e-3 passes it (a two-hundredth of its column): no correction.
        let (x, path) = solve_with(
            &mut factors,
            &mut pattern,
            &values_for(5e-3),
            &b,
            &mut mem,
            true,
        );
        assert_eq!(path, FactorPath::Compiled);
        let exact = [1.0 / (1.0 - 5e-3), 2.0 - 1.0 / (1.0 - 5e-3)];
        assert!((x[0] - exact[0]).abs() < 1e-13 && (x[1] - exact[1]).abs() < 1e-13);
        // A zero pivot too.
        let (x, path) = solve_with(
            &mut factors,
            &mut pattern,
            &values_for(0.0),
            &b,
            &mut mem,
            true,
        );
        assert_eq!(path, FactorPath::Corrected);
        assert!((x[0] - 1.0).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15);
        // The program stays: the first values pass it as they are.
        let (x, path) = solve_with(&mut factors, &mut pattern, &first, &b, &mut mem, true);
        assert_eq!(path, FactorPath::Compiled);
        assert!((x[0] + 1.0).abs() < 1e-15 && (x[1] - 3.0).abs() < 1e-15);
        // a = 1: singular. The capacitance is zero: faer's LU (the
        // reference) finds the zero pivot, a non-finite solution.
        let (x, path) = solve_with(
            &mut factors,
            &mut pattern,
            &values_for(1.0),
            &b,
            &mut mem,
            true,
        );
        assert_eq!(path, FactorPath::Fallback);
        assert!(x.iter().any(|v| !v.is_finite()));
    }

    #[test]
    fn perturbed_pivots_match_faer() {
        // Each pattern compiled on one draw of values, then factored on
        // unrelated draws: the compiled row order fails pivots, which are
        // perturbed (up to MAX_PERTURBED) and the solves corrected; the
        // solutions equal faer's pivoting LU to round-off.
        let mut corrected = 0;
        for (n, seed) in [(19, 2), (31, 3), (64, 4), (150, 5)] {
            for triplets in [matrix(n, seed), with_singletons(n, seed)] {
                let (n, mut pattern, mut mem, mut factors, b) = setup(&triplets);
                let (slot, nnz) = (pattern.slot.clone(), pattern.nnz());
                let draw = |d: u64| {
                    let mut values = vec![0.0; nnz];
                    for (k, &(i, j, v)) in triplets.iter().enumerate() {
                        let x = ((k as u64 * 7919 + d * 104_729) as f64 * 0.618).sin();
                        values[slot[i * n + j] as usize] += v * x;
                    }
                    values
                };
                first_compiles(&mut factors, &mut pattern, &draw(0), &b, &mut mem);
                for d in 1..40 {
                    let values = draw(d);
                    let what = format!("n = {n}, draw {d}");
                    let path = compiled_matches_faer(
                        &mut factors,
                        &mut pattern,
                        (&values, &b),
                        &mut mem,
                        1e-9,
                        &what,
                    );
                    corrected += usize::from(path == FactorPath::Corrected);
                }
            }
        }
        assert!(corrected >= 20, "only {corrected} corrected factorisations");
    }

    /// Draw `d` of the values of `triplets` in `pattern`'s slots, each
    /// entry scaled by up to ±10 %, with the rows `lifted` turned into
    /// `x_i = 1` (their other entries exact zeros: a complementarity row
    /// switched branch).
    fn lifted_values(
        triplets: &[(usize, usize, f64)],
        pattern: &Pattern,
        n: usize,
        d: u64,
        lifted: impl Fn(usize) -> bool,
    ) -> Vec<f64> {
        let mut values = vec![0.0; pattern.nnz()];
        for (k, &(i, j, v)) in triplets.iter().enumerate() {
            let x = ((k as u64 * 7919 + d * 104_729) as f64 * 0.618).sin();
            let v = match (lifted(i), i == j) {
                (true, true) => 1.0,
                (true, false) => 0.0,
                (false, _) => v * (1.0 + 0.1 * x),
            };
            values[pattern.slot[i * n + j] as usize] += v;
        }
        values
    }

    #[test]
    fn each_set_of_exact_zeros_gets_its_program() {
        // A complementarity row switching branch inside one pattern: rows
        // become `x_i = c` (their other entries exact zeros), a third of
        // them here. The program compiled without those zeros fails more
        // pivots than it may perturb; that set of zeros then gets a
        // program of its own at once, compiled on its values (no
        // fallback to faer's LU), used from then on, and each solution
        // equals faer's to round-off (a corrected one: within its check's
        // backward error).
        let n = 150;
        let triplets = matrix(n, 5);
        let (n, mut pattern, mut mem, mut factors, b) = setup(&triplets);
        let draw = |d: u64, switched: bool, pattern: &Pattern| {
            lifted_values(&triplets, pattern, n, d, |i| switched && i % 3 == 0)
        };
        let mut paths = Vec::new();
        for d in 0..12 {
            let values = draw(d, d % 2 == 1, &pattern);
            let what = format!("draw {d}");
            paths.push(compiled_matches_faer(
                &mut factors,
                &mut pattern,
                (&values, &b),
                &mut mem,
                1e-9,
                &what,
            ));
        }
        assert_eq!(
            paths[0],
            FactorPath::Compiled,
            "the first factorisation compiles and runs the program"
        );
        assert_eq!(
            paths[1],
            FactorPath::Compiled,
            "other zeros get their own program at once"
        );
        for (d, path) in paths.iter().enumerate().skip(2) {
            assert_ne!(*path, FactorPath::Fallback, "draw {d}");
        }
        assert_eq!(pattern.programs.len(), 2, "one program a set of zeros");
    }

    /// The pattern's first factorisation compiles its program and runs it.
    fn first_compiles(
        factors: &mut Factors,
        pattern: &mut Pattern,
        values: &[f64],
        b: &[f64],
        mem: &mut MemBuffer,
    ) {
        let (_, path) = solve_with(factors, pattern, values, b, mem, true);
        assert_eq!(
            path,
            FactorPath::Compiled,
            "the first factorisation compiles and runs the program"
        );
    }

    /// The solution of `values` by the compiled path (its path returned)
    /// and by faer's LU (the reference path) agree to `tol` of the
    /// largest entry; a solve corrected for perturbed pivots is held to
    /// its check instead, a normwise backward error of at most
    /// [`WOODBURY_CHECK`] (its forward error is that times the system's
    /// condition).
    fn compiled_matches_faer(
        factors: &mut Factors,
        pattern: &mut Pattern,
        (values, b): (&[f64], &[f64]),
        mem: &mut MemBuffer,
        tol: f64,
        what: &str,
    ) -> FactorPath {
        let (ours, path) = solve_with(factors, pattern, values, b, mem, true);
        let (theirs, reference) = solve_with(factors, pattern, values, b, mem, false);
        assert_eq!(reference, FactorPath::Faer, "{what}");
        if path == FactorPath::Corrected {
            let error = backward_error(pattern, values, &ours, b);
            assert!(
                error <= 2.0 * WOODBURY_CHECK,
                "{what} ({path:?}): backward error {error:e}"
            );
            return path;
        }
        let scale = theirs.iter().fold(1.0f64, |m, v| m.max(v.abs()));
        for (i, (o, t)) in ours.iter().zip(&theirs).enumerate() {
            assert!(
                (o - t).abs() <= tol * scale,
                "{what} ({path:?}), x[{i}]: ours {o} faer {t}"
            );
        }
        path
    }

    /// `max_i |b − A·x|_i / max_i Σ_j |a_ij·x_j|` of the system whose
    /// values are `values` in `pattern`'s slots.
    fn backward_error(pattern: &Pattern, values: &[f64], x: &[f64], b: &[f64]) -> f64 {
        let n = pattern.n;
        let (mut residual, mut size) = (0.0f64, 0.0f64);
        for (i, &bi) in b.iter().enumerate().take(n) {
            let (mut r, mut s) = (bi, 0.0);
            for (j, xj) in x.iter().enumerate() {
                let slot = pattern.slot[i * n + j];
                if slot != u32::MAX {
                    let a = values[slot as usize] * xj;
                    r -= a;
                    s += a.abs();
                }
            }
            residual = residual.max(r.abs());
            size = size.max(s);
        }
        residual / size
    }

    #[test]
    fn more_sets_of_zeros_than_programs_take_the_least_recent_place() {
        // MAX_PROGRAMS + 3 sets of exact zeros (rows `x_i = 1`: every row
        // with a diagonal entry outside the set's block of 8 rows, modulo
        // the number of sets), each met twice in a row (compiled at its
        // first meeting, factored by its program at the second), then all
        // again: the first program (no zeros)
        // stays, the pattern never keeps more than MAX_PROGRAMS, and the
        // sets compiled last factor by their programs; every solution
        // equals faer's to round-off.
        let n = 96;
        let triplets = matrix(n, 6);
        let (n, mut pattern, mut mem, mut factors, b) = setup(&triplets);
        let sets = MAX_PROGRAMS + 3;
        let draw = |d: u64, set: Option<usize>, pattern: &Pattern| {
            lifted_values(&triplets, pattern, n, d, |i| {
                i % 3 != 1 && set.is_some_and(|s| (i / 8) % sets != s)
            })
        };
        let mut d = 0;
        let mut next = |set: Option<usize>, pattern: &mut Pattern, factors: &mut Factors| {
            d += 1;
            let what = format!("draw {d}, set {set:?}");
            let values = draw(d, set, pattern);
            compiled_matches_faer(factors, pattern, (&values, &b), &mut mem, 1e-9, &what)
        };
        assert_eq!(next(None, &mut pattern, &mut factors), FactorPath::Compiled);
        // Each program's storage once MAX_PROGRAMS are kept: a replaced
        // program is compiled again in it (no allocation).
        let storage = |pattern: &Pattern| -> Vec<*const u32> {
            pattern
                .programs
                .iter()
                .map(|p| p.lu.lower.vals.as_ptr())
                .collect()
        };
        let mut kept = None;
        for set in 0..sets {
            let programs = pattern.programs.len();
            for _ in 0..2 {
                assert_ne!(
                    next(Some(set), &mut pattern, &mut factors),
                    FactorPath::Fallback,
                    "set {set}"
                );
            }
            assert_eq!(
                pattern.programs.len(),
                (programs + 1).min(MAX_PROGRAMS),
                "set {set}: one program, compiled at its first meeting"
            );
            assert!(pattern.programs.len() <= MAX_PROGRAMS);
            if kept.is_none() && pattern.programs.len() == MAX_PROGRAMS {
                kept = Some(storage(&pattern));
            }
        }
        assert_eq!(pattern.programs.len(), MAX_PROGRAMS);
        assert_eq!(kept, Some(storage(&pattern)), "replaced in place");
        // The first program and the last MAX_PROGRAMS − 1 sets' remain.
        assert_ne!(next(None, &mut pattern, &mut factors), FactorPath::Fallback);
        for set in sets + 1 - MAX_PROGRAMS..sets {
            assert_ne!(
                next(Some(set), &mut pattern, &mut factors),
                FactorPath::Fallback,
                "set {set} kept its program"
            );
        }
    }

    #[test]
    fn a_program_that_keeps_failing_is_compiled_again() {
        // 2 × 2 blocks [[a, 1], [1, a]] compiled on a = 10 (diagonal
        // pivots), then factored on draws with a = 1e-12: each block's
        // first pivot fails, more than MAX_PERTURBED in all, and faer's LU
        // factors it. The second such fallback in a row compiles the
        // program again on those values (the other row first); the next
        // such draws factor by it.
        let n = 48;
        let mut triplets = Vec::new();
        for i in (0..n).step_by(2) {
            triplets.extend([
                (i, i, 10.0),
                (i, i + 1, 1.0),
                (i + 1, i, 1.0),
                (i + 1, i + 1, 10.0),
            ]);
        }
        let (n, mut pattern, mut mem, mut factors, b) = setup(&triplets);
        let (slot, nnz) = (pattern.slot.clone(), pattern.nnz());
        let draw = |d: u64, small: bool| {
            let mut values = vec![0.0; nnz];
            for (k, &(i, j, v)) in triplets.iter().enumerate() {
                let x = 1.0 + 0.1 * ((k as u64 * 7919 + d * 104_729) as f64 * 0.618).sin();
                let v = if i == j && small { 1e-12 * x } else { v * x };
                values[slot[i * n + j] as usize] = v;
            }
            values
        };
        let mut path = |d: u64, small: bool, pattern: &mut Pattern, factors: &mut Factors| {
            let what = format!("draw {d}, small diagonal {small}");
            compiled_matches_faer(
                factors,
                pattern,
                (&draw(d, small), &b),
                &mut mem,
                1e-9,
                &what,
            )
        };
        assert_eq!(
            path(0, false, &mut pattern, &mut factors),
            FactorPath::Compiled
        );
        assert_eq!(
            path(1, true, &mut pattern, &mut factors),
            FactorPath::Fallback
        );
        assert_eq!(pattern.programs.len(), 1, "one set of zeros: one program");
        assert_eq!(
            path(2, true, &mut pattern, &mut factors),
            FactorPath::Fallback,
            "the second fallback in a row compiles it again"
        );
        for d in 3..6 {
            assert_ne!(
                path(d, true, &mut pattern, &mut factors),
                FactorPath::Fallback
            );
        }
        assert_eq!(pattern.programs.len(), 1);
    }

    /// The renewal rule's bookkeeping: once a solve costs more chord steps
    /// than the average per solve since the factorisation, renewal
    /// included, the next solve renews it — unless that solve took a single
    /// chord step, the fewest a solve can take when the guess is not the
    /// solution (a robot standing still: most solves take none).
    #[test]
    fn a_single_chord_step_never_renews() {
        let mut entries = vec![(0, 0), (1, 1)];
        let mut pattern = Pattern::build(0, 2, &mut entries);
        assert!(!pattern.renew(4.0), "no solve since the factorisation");
        for _ in 0..10 {
            pattern.solved(0);
        }
        // One chord step after ten solves without: 1·11 > 4 + 1, but no
        // factorisation could have saved it.
        pattern.chords_since += 1;
        pattern.solved(1);
        assert!(!pattern.renew(4.0), "renewed after a single chord step");
        // A solve of two: 2·12 > 4 + 3, renew; not with the rule off.
        pattern.chords_since += 2;
        pattern.solved(2);
        assert!(pattern.renew(4.0));
        assert!(!pattern.renew(0.0));
        // Fresh, two chord steps a solve: 2·1 ≤ 4 + 2, then 2·2 ≤ 4 + 4,
        // then 2·3 ≤ 4 + 6: the average cost never falls below two.
        let mut fresh = Pattern::build(0, 2, &mut vec![(0, 0), (1, 1)]);
        for _ in 0..3 {
            fresh.chords_since += 2;
            fresh.solved(2);
            assert!(!fresh.renew(4.0));
        }
        // A solve of four tips it: 4·4 > 4 + 10.
        fresh.chords_since += 4;
        fresh.solved(4);
        assert!(fresh.renew(4.0));
    }

    #[test]
    fn singleton_rows_leave_the_lu() {
        let n = 19;
        let triplets = with_singletons(n, 2);
        let mut entries: Vec<(usize, usize)> = triplets.iter().map(|t| (t.0, t.1)).collect();
        let pattern = Pattern::build(0, n, &mut entries);
        // Rows 0, 5, 10, 15.
        assert_eq!(pattern.singles, [(0, 0), (5, 5), (10, 10), (15, 15)]);
        assert_eq!(pattern.m, n - 4);
        // Two singleton rows in one column: the second stays in the LU.
        let mut clash = vec![(0, 0), (1, 0), (1, 1), (2, 1), (2, 2)];
        let pattern = Pattern::build(0, 3, &mut clash);
        assert_eq!(pattern.singles, [(0, 0)]);
        assert_eq!(pattern.m, 2);
    }

    #[test]
    fn every_row_a_singleton() {
        let n = 4;
        let mut entries: Vec<(usize, usize)> = (0..n).map(|i| (i, (i + 1) % n)).collect();
        let mut pattern = Pattern::build(0, n, &mut entries);
        assert_eq!(pattern.m, 0);
        let mut values = vec![0.0; pattern.nnz()];
        for i in 0..n {
            values[pattern.slot[i * n + (i + 1) % n] as usize] = (i + 1) as f64;
        }
        let mut mem = MemBuffer::new(Factors::scratch(1));
        let mut factors = faer_factors(&mut pattern, &values, &mut mem);
        let mut x = vec![1.0, 2.0, 3.0, 4.0];
        factors.solve(&mut pattern, &mut x);
        // Row i: (i + 1)·x[i + 1] = b[i].
        assert_eq!(x, [4.0 / 4.0, 1.0 / 1.0, 2.0 / 2.0, 3.0 / 3.0]);
    }
}

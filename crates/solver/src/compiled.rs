//! The numeric LU of one reduced pattern compiled into a flat list of
//! operations: no symbolic work, no pivot search, no per-column dispatch
//! at a factorisation.
//!
//! # What is compiled
//!
//! faer's COLAMD gives the column ordering `Q` (see [`crate::lu`]); the
//! values of the pattern's first factorisation give a
//! row order `P`, by threshold Markowitz pivoting along `Q`
//! ([`CompiledLu::choose_rows`]: among the rows whose entry is at least a
//! tenth of the column's largest, the one of least fill; faer's partial
//! pivoting, which takes the largest entry, filled the factors more: the
//! hexapod walk's solves cost 15 % less with this order). With both fixed,
//! the fill of `P·A·Q = L·U` is a property of the pattern alone, found once
//! by a symbolic elimination ([`CompiledLu::compile`]): every entry of `L`
//! and `U` gets a slot in one dense-free value array, and the elimination
//! becomes
//!
//! * a copy of the Jacobian's values (CSC order) into the first slots,
//!   in one block, and zeros into the fill-in's;
//! * for each pivot `k`, in order: the pivot check, the scaling of `L`'s
//!   column `k` by `1/u_kk`, and the rank-one update
//!   `a_ij −= l_ik·u_kj` of every `(i, j)` of `L`'s column `k` times `U`'s
//!   row `k`, whose target slots are one precomputed stream.
//!
//! The result is copied into the streams of the
//! triangular sweeps ([`crate::lu::Factors`]), whose entries are fixed at
//! compile time too.
//!
//! # The cost of a compilation
//!
//! The row choice and the compilation work on one scratch per solver
//! ([`CompileScratch`], kept between compilations): dense `m × m` arrays
//! (the row choice's values, the compilation's slots) restored only where
//! they were set, and the structure as bit sets of each row's columns and
//! each column's rows (64 a word), so that both visit the structure and
//! its fill, not the `m²` positions, and find each column's rows in order
//! without a sort. The compilation takes the structure the row choice's
//! elimination left (the same elimination, the same fill) when it
//! compiles that row order, and runs a symbolic elimination of its own
//! only for another one (faer's rows). On `bench/peer/hexapod_drop.toml`
//! (238 compilations of reduced dimension 78–138, 8.4 k updates each on
//! average), callgrind: the row choice 157 M → 85 M instructions, the
//! compilation 190 M → 81 M (both, `Factors::add_program`, 348 M →
//! 166 M), with dense passes over the `m²` positions and the dense arrays
//! allocated, zeroed and freed at each compilation before.
//!
//! # Numerically safe pivots
//!
//! The row order was chosen on the values of the pattern's first
//! factorisation; later Jacobians of the same pattern have other values. Each pivot is therefore re-verified against threshold
//! partial pivoting: `|u_kk| ≥ PIVOT_THRESHOLD · max_i |l_ik·u_kk|` over
//! its column (the largest entry a partial pivoting could have chosen),
//! and `u_kk ≠ 0`.
//!
//! # Perturbed pivots
//!
//! A pivot that fails its check is not a reason to leave the program: on
//! the contact-rich hexapod most failures are a single entry cancelling to
//! round-off, or an exact zero where a complementarity branch switched. The
//! failed pivot is replaced by `±max(column, row)` (its sign kept; `1`
//! when both are empty), the largest entry of its column below it or of its
//! row right of it, which bounds that column of `L` by one (static
//! pivoting, as in SuperLU_DIST's GESP). Up to [`MAX_PERTURBED`] pivots of
//! one factorisation may be replaced. The factors are then exactly those
//! of `M = B + E·D·Eᵀ`, `B = P·A·Q` the system, `D` the changes `δ_k` and
//! `E` the unit columns of their positions, and every solve is corrected
//! by the Sherman–Morrison–Woodbury formula to `B⁻¹`:
//!
//! ```text
//! B⁻¹·b = y + W·C⁻¹·Eᵀ·y,   y = M⁻¹·b,   W = M⁻¹·E,   C = D⁻¹ − Eᵀ·W
//! ```
//!
//! `W` (one sweep of the factors for all its columns) and `C⁻¹` (`r × r`,
//! Gauss–Jordan with partial pivoting) are computed once per
//! factorisation; a solve adds `r` dot products. Each such factorisation is
//! checked once: the solve of `A·v` for a known `v` must have a normwise
//! backward error `max_i |b − A·x|_i ≤ 1e-9 · max_i Σ_j |a_ij·x_j|`
//! (Newton's residual tolerance: see `WOODBURY_CHECK` in [`crate::lu`]). When
//! `C` is singular, the check fails, a pivot is structurally zero or not
//! finite, or more than [`MAX_PERTURBED`] pivots fail, the caller factors
//! with faer's pivoting LU (the reference path) and counts the fallback;
//! the program stays for the next factorisation, and is compiled again on
//! the values of its second fallback in a row (`RECOMPILE_AFTER`: its row
//! order no longer fits the values). A pattern keeps one program per set
//! of exact zeros among its values (a complementarity branch switched
//! inside the pattern): a set that the pattern's first program cannot
//! factor gets its own program at once, compiled on those values, before
//! any fallback ([`crate::lu`]'s `zero_signature`; at its second fallback
//! until 2026-11-29); beyond `MAX_PROGRAMS` a new set
//! takes the place of the least recently tried program but the first,
//! compiled again in its storage.
//! Results equal faer's to round-off (different order of the same sums),
//! not bit for bit; those of a corrected factorisation to its check's
//! backward error.
//! Measured on the first 100 runs of
//! `examples/sweep_hexapod_landing_1000.toml` (stride 1, 2 cores): 9 in
//! 10 fallbacks avoided, the sweep's wall time 14 s → 12 s; the hexapod
//! walk of `bench/peer`, 932 M → 869 M instructions.

use crate::lu::Stream;

/// The threshold of the pivot check: a pivot at least a thousandth of the
/// largest entry of its column, which bounds `L`'s entries by 1000.
/// Measured (fallbacks / factorisations, `bench/peer`): the moving planar
/// flight 483 / 6353 at 0.1, 139 / 6384 at 0.01, 17 / 6350 at 0.001; the
/// hexapod walk 54, 40 and 38 of 186 (its failed pivots are cancellations
/// to round-off, `1e-5` against `3e6`, which no threshold accepts). From
/// 0.01 to 0.001 (2026-11-28, `valgrind --tool=cachegrind`, `quick`
/// build): the 3D drop of `bench/peer` 1,157 M → 1,106 M instructions
/// (of its 969 factorisations 411 clean, 521 corrected and 37 by faer's
/// LU, against 326, 588 and 55), 40 of
/// the 1000 landings of `examples/sweep_hexapod_landing_1000.toml`
/// (`--shard 0/25`) 31.09 G → 30.29 G, the walk and the moving flight
/// −0.4 % and −0.7 %, standing and the passive fall the same; the 1000
/// landings 56.7–59.3 s → 54.6–55.4 s of stepping (`--jobs 2`, two sweeps
/// each, alternating), their Newton iterations within 0.1 %. The first 100
/// of those landings (`samples = 100`, `--jobs 2`, two sweeps each): 5.09–
/// 5.44 s at 0.001, 5.32–5.53 s at 0.003, 5.17–5.37 s at 0.0003,
/// 5.47–5.63 s at 0.01.
pub const PIVOT_THRESHOLD: f64 = 0.001;

/// The threshold of the row choice at compilation
/// ([`CompiledLu::choose_rows`]): a pivot at least a tenth of its column's
/// largest entry (UMFPACK's default for threshold partial pivoting), a
/// margin of a hundred over the check of later factorisations
/// ([`PIVOT_THRESHOLD`]). A hundredth or 0.3 instead: those 100 landings
/// in 5.83 and 5.75 s, against 5.44 s (one sweep each, the same session).
pub const ROW_CHOICE_THRESHOLD: f64 = 0.1;

/// The most pivots of one factorisation that may be perturbed
/// (see the module docs, "Perturbed pivots"); one more falls back to
/// faer's pivoting LU. Measured on the 1000 landings of
/// `examples/sweep_hexapod_landing_1000.toml` (`quick` build, 2 jobs, the
/// stepping time summed over the runs): 8 → 64.1 s, 12 → 60.9 s, 16 →
/// 60.1 s, 20 → 59.7 s, 24 → 60.3 s, all 1000 complete; on the 3D drop
/// of `bench/peer` (a single landing, its time that of its few impact
/// steps) 215 fallbacks for too many failed pivots at 8, 70 at 16 (and 51
/// corrections failing their accuracy check, 12 at 8), the run 10 %
/// faster; at 20 and above its impact steps took other paths, 75 % slower.
pub const MAX_PERTURBED: usize = 16;

/// A compiled numeric LU of one reduced pattern with a fixed row order.
#[derive(Clone, Default)]
pub(crate) struct CompiledLu {
    /// Dimension.
    m: usize,
    /// Number of values of the reduced CSC structure: value `e` has slot
    /// `e`, the fill-in the slots after them.
    values: usize,
    /// Slot of pivot `k`.
    pivot: Vec<u32>,
    /// `L`'s column `k` below the diagonal: `l_slots[l_ptr[k]..l_ptr[k+1]]`.
    l_ptr: Vec<u32>,
    l_slots: Vec<u32>,
    /// `U`'s row `k` right of the diagonal: `u_slots[u_ptr[k]..u_ptr[k+1]]`.
    u_ptr: Vec<u32>,
    u_slots: Vec<u32>,
    /// The targets of the rank-one updates, pivot after pivot, `L`'s rows
    /// outer, `U`'s columns inner.
    updates: Vec<u32>,
    /// Number of slots.
    slots: usize,
    /// The value array.
    a: Vec<f64>,
    /// Scratch of [`Self::factor`]: `U`'s row `k` right of the diagonal,
    /// the values (as long as the longest row).
    u_row: Vec<f64>,
    /// The pivot row order: reduced row of pivot position `i`.
    pub(crate) row_perm: Vec<usize>,
    /// The forward sweep's stream of slots, `L`'s columns in order.
    pub(crate) lower: Stream<u32>,
    /// The backward sweep's stream of slots, `U`'s columns last first,
    /// entries above the diagonal.
    pub(crate) upper: Stream<u32>,
}

/// Scratch of [`CompiledLu::choose_rows`] and [`CompiledLu::compile`],
/// kept between compilations (one per solver, grown to the largest
/// dimension `m` met): two dense `m × m` arrays, restored after each use
/// at the entries it set (the filled structure, not all `m²`), and the
/// structure as bit sets of each row's columns and each column's rows
/// (`2·m·⌈m/64⌉` words, cleared at each use). About `12·m²` bytes: 220 kB
/// at `m = 135`.
#[derive(Default)]
pub(crate) struct CompileScratch {
    /// [`CompiledLu::choose_rows`]: the dense elimination's values, `0.0`
    /// outside the structure between uses.
    dense: Vec<f64>,
    /// [`CompiledLu::compile`]: the slot of each position of `P·A·Q`,
    /// `u32::MAX` outside the structure between uses.
    slot: Vec<u32>,
    /// Words of a row's (column's) bit set: `⌈m/64⌉`.
    words: usize,
    /// The structure: row `i`'s columns, bits of
    /// `row_bits[i·words..(i+1)·words]`; column `j`'s rows the same in
    /// `col_bits`.
    row_bits: Vec<u64>,
    col_bits: Vec<u64>,
    /// [`CompiledLu::choose_rows`]: the rows taken, a bit set.
    used: Vec<u64>,
    /// [`CompiledLu::compile`]: pivot positions of rows and columns.
    row_pos: Vec<usize>,
    col_pos: Vec<usize>,
    /// The current pivot's rows left below it ([`CompiledLu::choose_rows`])
    /// and its columns right of it (and their values in
    /// [`CompiledLu::choose_rows`]).
    rows: Vec<usize>,
    cols: Vec<u32>,
    pivot_row: Vec<f64>,
    /// [`CompiledLu::choose_rows`]: the pivot row's bit set.
    pivot_bits: Vec<u64>,
    /// [`CompiledLu::choose_rows`]: the order, and whether the bit sets
    /// hold the structure of its elimination (which
    /// [`CompiledLu::compile`] with that order then takes).
    order: Vec<usize>,
    chosen: bool,
    /// [`CompiledLu::compile`]: the rows' bit sets being permuted.
    spare: Vec<u64>,
    /// Entries of each row right of the current column (the Markowitz
    /// row count).
    count: Vec<usize>,
}

impl CompileScratch {
    /// Empty bit sets for dimension `m`.
    fn clear_bits(&mut self, m: usize) {
        self.words = m.div_ceil(64);
        for bits in [&mut self.row_bits, &mut self.col_bits] {
            bits.clear();
            bits.resize(m * self.words, 0);
        }
    }

    /// The structure of the LU of the reduced structure (`col_ptr`,
    /// `row_idx`) in the pivot positions [`Self::row_pos`],
    /// [`Self::col_pos`] of dimension `m`, into the bit sets: the values',
    /// then the fill of a symbolic elimination, pivot after pivot. Pivot
    /// `k`'s column and row are final when it is reached (only earlier
    /// pivots fill them), and stay so; each of its rows below the
    /// diagonal takes its row's columns right of it (64 columns a word),
    /// the new ones the fill.
    fn symbolic(&mut self, m: usize, col_ptr: &[usize], row_idx: &[usize]) {
        self.clear_bits(m);
        let w = self.words;
        for j in 0..m {
            let c = self.col_pos[j];
            for &r in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                let i = self.row_pos[r];
                set(&mut self.row_bits, i * w, c);
                set(&mut self.col_bits, c * w, i);
            }
        }
        for k in 0..m {
            let (row_head, row_tail) = self.row_bits.split_at_mut((k + 1) * w);
            let (col_head, col_tail) = self.col_bits.split_at_mut((k + 1) * w);
            let pivot = &row_head[k * w..];
            for i in bits(&col_head[k * w..], k + 1) {
                let row = &mut row_tail[(i - k - 1) * w..(i - k) * w];
                merge(row, pivot, k + 1, |j| {
                    set(col_tail, (j - k - 1) * w, i);
                });
            }
        }
    }

    /// The structure left by [`CompiledLu::choose_rows`] (rows as given)
    /// with its rows in pivot order ([`Self::order`]): row `i`'s bit set
    /// is that of row `order[i]`; the columns' sets cleared (to be
    /// rebuilt).
    fn permute_rows(&mut self) {
        let w = self.words;
        self.spare.clear();
        for &r in &self.order {
            self.spare
                .extend_from_slice(&self.row_bits[r * w..(r + 1) * w]);
        }
        std::mem::swap(&mut self.spare, &mut self.row_bits);
        self.col_bits.fill(0);
    }
}

/// The number of set bits of `words` from bit `from` on.
fn count(words: &[u64], from: usize) -> usize {
    let first = from / 64;
    words
        .iter()
        .enumerate()
        .skip(first)
        .map(|(w, &x)| {
            let x = if w == first {
                x & (u64::MAX << (from % 64))
            } else {
                x
            };
            x.count_ones() as usize
        })
        .sum()
}

/// The set bits of `words` from bit `from` on, in order.
fn bits(words: &[u64], from: usize) -> Bits<'_> {
    let index = from / 64;
    let word = words
        .get(index)
        .map_or(0, |&w| w & (u64::MAX << (from % 64)));
    Bits { words, index, word }
}

/// Iterator of [`bits`].
struct Bits<'a> {
    words: &'a [u64],
    index: usize,
    word: u64,
}

impl Iterator for Bits<'_> {
    type Item = usize;

    #[inline]
    fn next(&mut self) -> Option<usize> {
        while self.word == 0 {
            self.index += 1;
            self.word = *self.words.get(self.index)?;
        }
        let bit = self.word.trailing_zeros() as usize;
        self.word &= self.word - 1;
        Some(self.index * 64 + bit)
    }
}

/// Sets in `row` the bits of `pivot` from bit `from` on, calling `fill`
/// with each bit newly set (in order).
#[inline]
fn merge(row: &mut [u64], pivot: &[u64], from: usize, mut fill: impl FnMut(usize)) {
    let first = from / 64;
    let mut mask = u64::MAX << (from % 64);
    for (w, (r, &p)) in row.iter_mut().zip(pivot).enumerate().skip(first) {
        let p = p & mask;
        mask = u64::MAX;
        let mut new = p & !*r;
        *r |= p;
        while new != 0 {
            fill(w * 64 + new.trailing_zeros() as usize);
            new &= new - 1;
        }
    }
}

/// Rows `a` and `b` (different) of the row-major `d` of `m` columns.
fn two_rows(d: &mut [f64], m: usize, a: usize, b: usize) -> (&mut [f64], &mut [f64]) {
    if a < b {
        let (x, y) = d.split_at_mut(b * m);
        (&mut x[a * m..(a + 1) * m], &mut y[..m])
    } else {
        let (x, y) = d.split_at_mut(a * m);
        (&mut y[..m], &mut x[b * m..(b + 1) * m])
    }
}

/// Sets bit `i` of the bit set starting at word `start` of `words`.
#[inline]
fn set(words: &mut [u64], start: usize, i: usize) {
    words[start + i / 64] |= 1 << (i % 64);
}

/// The row choice's rule at one column ([`CompiledLu::choose_rows`]):
/// among the candidate `rows` (ascending) whose entry `value(r)` is at
/// least [`ROW_CHOICE_THRESHOLD`] of the column's largest, `column`, the
/// one with the fewest entries right of the column (`count`), ties to the
/// larger entry, then to the first. `None` when the column is empty, zero
/// or not finite.
fn pick_row(
    rows: &[usize],
    value: impl Fn(usize) -> f64,
    count: &[usize],
    column: f64,
) -> Option<usize> {
    if !(column > 0.0 && column.is_finite()) {
        return None;
    }
    let mut best: Option<(usize, usize, f64)> = None;
    for &r in rows {
        let v = value(r).abs();
        if v < ROW_CHOICE_THRESHOLD * column {
            continue;
        }
        let c = count[r];
        if best.is_none_or(|(_, bc, b)| c < bc || (c == bc && v > b)) {
            best = Some((r, c, v));
        }
    }
    best.map(|(r, _, _)| r)
}

/// A pivot failed its check: factor with faer instead.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct PivotFailed;

impl CompiledLu {
    /// Compiles the LU of the `m × m` reduced structure (`col_ptr`,
    /// `row_idx`, CSC) with column order `fwd` (ordered position →
    /// column) and row order `row_perm` (pivot position → row), reusing
    /// this value's storage and the scratch `sc`. The first compilation
    /// allocates, with room for programs of twice its size; a later one (a
    /// fallback's new row order) only when `grow`, else it returns `false`
    /// and leaves the program as it was when the new one does not fit.
    pub(crate) fn compile(
        &mut self,
        sc: &mut CompileScratch,
        col_ptr: &[usize],
        row_idx: &[usize],
        fwd: &[usize],
        row_perm: &[usize],
        grow: bool,
    ) -> bool {
        let m = fwd.len();
        assert!(u32::try_from(m * m).is_ok(), "dimension {m} beyond u32");
        let first = !self.is_compiled() || self.m != m;
        if sc.slot.len() < m * m {
            sc.slot.resize(m * m, u32::MAX);
        }
        debug_assert!(sc.slot.iter().all(|&s| s == u32::MAX));
        sc.row_pos.resize(m, 0);
        sc.col_pos.resize(m, 0);
        for (i, &r) in row_perm.iter().enumerate() {
            sc.row_pos[r] = i;
        }
        for (c, &j) in fwd.iter().enumerate() {
            sc.col_pos[j] = c;
        }
        let chosen = sc.chosen && sc.order == row_perm;
        if chosen {
            // The structure of the row choice's elimination along this
            // order: the same fill, its rows in pivot order (the columns'
            // sets rebuilt below).
            sc.permute_rows();
        } else {
            sc.symbolic(m, col_ptr, row_idx);
        }
        sc.chosen = false;
        let fits = self.compile_with(sc, m, col_ptr, row_idx, chosen, first, grow);
        if fits {
            self.row_perm.clear();
            self.row_perm.extend_from_slice(row_perm);
        } else {
            // The slot map back to `u32::MAX` where it was set, the
            // structure (a program's emission does it as it reads them).
            let w = sc.words;
            for (i, row) in sc.row_bits.chunks_exact(w.max(1)).take(m).enumerate() {
                for j in bits(row, 0) {
                    sc.slot[i * m + j] = u32::MAX;
                }
            }
        }
        debug_assert!(sc.slot.iter().all(|&s| s == u32::MAX));
        fits
    }

    /// [`Self::compile`] once the scratch holds the pivot positions of the
    /// rows and columns and the rows' bit sets of the structure, the
    /// columns' too unless `rebuild`.
    #[allow(clippy::too_many_arguments)]
    fn compile_with(
        &mut self,
        sc: &mut CompileScratch,
        m: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        rebuild: bool,
        first: bool,
        grow: bool,
    ) -> bool {
        let w = sc.words;
        let slot = &mut sc.slot;
        // The values' slots, in their CSC order (a factorisation copies
        // them in one block), then the fill's, row-major.
        let mut slots = 0u32;
        for j in 0..m {
            let c = sc.col_pos[j];
            for &r in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                slot[sc.row_pos[r] * m + c] = slots;
                slots += 1;
            }
        }
        self.values = slots as usize;
        // In one pass over the structure, row-major: the columns' bit sets
        // when rebuilt, and pivot `k`'s rows of `L` (below the diagonal)
        // and columns of `U` (right of it) counted.
        sc.count.clear();
        sc.count.resize(2 * m, 0);
        let (l_count, u_count) = sc.count.split_at_mut(m);
        for (i, row) in sc.row_bits.chunks_exact(w.max(1)).take(m).enumerate() {
            let target = &mut slot[i * m..(i + 1) * m];
            for j in bits(row, 0) {
                if rebuild {
                    set(&mut sc.col_bits, j * w, i);
                }
                if target[j] == u32::MAX {
                    target[j] = slots;
                    slots += 1;
                }
                if j < i {
                    l_count[j] += 1;
                }
            }
            u_count[i] = count(row, i + 1);
        }
        let n_l: usize = l_count.iter().sum();
        let n_u: usize = u_count.iter().sum();
        let n_upd: usize = l_count.iter().zip(u_count.iter()).map(|(l, u)| l * u).sum();
        let n_slots = slots as usize;
        if first {
            // Room for a later row order's program of up to twice the size.
            let dense = m * m;
            self.a.reserve(2 * n_slots.min(dense));
            self.l_slots.reserve(2 * n_l.min(dense));
            self.lower.reserve(2 * n_l.min(dense));
            self.u_slots.reserve(2 * n_u.min(dense));
            self.upper.reserve(2 * n_u.min(dense));
            self.updates.reserve(2 * n_upd.min(dense * m));
            self.pivot.reserve(m);
            self.l_ptr.reserve(m + 1);
            self.u_ptr.reserve(m + 1);
            self.u_row.reserve(m);
            self.row_perm.reserve(m);
        } else if !grow
            && (n_slots > self.a.capacity()
                || n_l > self.l_slots.capacity().min(self.lower.capacity())
                || n_u > self.u_slots.capacity().min(self.upper.capacity())
                || n_upd > self.updates.capacity())
        {
            return false;
        }
        self.m = m;
        self.slots = n_slots;
        self.pivot.clear();
        self.l_ptr.clear();
        self.l_slots.clear();
        self.u_ptr.clear();
        self.u_slots.clear();
        self.updates.clear();
        self.l_ptr.push(0);
        self.u_ptr.push(0);
        self.lower.clear();
        for k in 0..m {
            // A structurally zero pivot gets no slot: it never verifies,
            // faer reports the singularity.
            // Each position of the structure is read for the last time
            // where it is emitted (a pivot here, `L` below, `U` with the
            // backward sweep's stream), and its slot cleared there.
            self.pivot.push(slot[k * m + k]);
            slot[k * m + k] = u32::MAX;
            sc.cols.clear();
            sc.cols
                .extend(bits(&sc.row_bits[k * w..(k + 1) * w], k + 1).map(|j| j as u32));
            let pivot_row = &slot[k * m..(k + 1) * m];
            self.u_slots
                .extend(sc.cols.iter().map(|&j| pivot_row[j as usize]));
            for i in bits(&sc.col_bits[k * w..(k + 1) * w], k + 1) {
                let target = &slot[i * m..(i + 1) * m];
                let s = target[k];
                self.l_slots.push(s);
                self.updates
                    .extend(sc.cols.iter().map(|&j| target[j as usize]));
                self.lower.rows.push(i as u32);
                self.lower.vals.push(s);
                slot[i * m + k] = u32::MAX;
            }
            self.lower.end_run(k as u32);
            self.l_ptr.push(self.l_slots.len() as u32);
            self.u_ptr.push(self.u_slots.len() as u32);
        }
        // `U` above the diagonal, last column first, each column's rows in
        // order.
        self.upper.clear();
        for j in (0..m).rev() {
            for i in bits(&sc.col_bits[j * w..(j + 1) * w], 0).take_while(|&i| i < j) {
                self.upper.rows.push(i as u32);
                self.upper
                    .vals
                    .push(std::mem::replace(&mut slot[i * m + j], u32::MAX));
            }
            self.upper.end_run(j as u32);
        }
        self.lower.seal();
        self.upper.seal();
        self.a.clear();
        self.a.resize(self.slots, 0.0);
        let widest = self.u_ptr.windows(2).map(|p| p[1] - p[0]).max();
        self.u_row.clear();
        self.u_row.resize(widest.unwrap_or(0) as usize, 0.0);
        true
    }

    /// A row order for the compiled program chosen on `values` (the
    /// reduced CSC values) by threshold Markowitz pivoting along the column
    /// order `fwd`: at each column, among the rows whose entry is at least
    /// [`ROW_CHOICE_THRESHOLD`] of the column's largest, the one with the
    /// fewest entries right of the column (the least fill; ties to the
    /// larger entry, then to the first row). An elimination of the first
    /// values on the dense array of the scratch `sc` that visits only the
    /// structure (each column's rows left and the pivot row's columns from
    /// their bit sets, the LU's own updates; kept rows counted as they
    /// fill), once per compilation. `None` when a column has no usable
    /// entry (faer's order is then used). Writes the order into the
    /// scratch; allocation-free once the scratch has this dimension.
    pub(crate) fn choose_rows<'s>(
        sc: &'s mut CompileScratch,
        col_ptr: &[usize],
        row_idx: &[usize],
        fwd: &[usize],
        values: &[f64],
    ) -> Option<&'s [usize]> {
        let m = fwd.len();
        if sc.dense.len() < m * m {
            sc.dense.resize(m * m, 0.0);
        }
        debug_assert!(sc.dense.iter().all(|&v| v.to_bits() == 0));
        sc.clear_bits(m);
        let found = Self::eliminate(sc, m, col_ptr, row_idx, fwd, values);
        sc.chosen = found;
        // The dense values back to zero where they were set: the
        // structure.
        let w = sc.words;
        for (r, row) in sc.row_bits.chunks_exact(w.max(1)).take(m).enumerate() {
            for c in bits(row, 0) {
                sc.dense[r * m + c] = 0.0;
            }
        }
        debug_assert!(sc.dense.iter().all(|&v| v.to_bits() == 0));
        found.then_some(&sc.order[..])
    }

    /// The elimination of [`Self::choose_rows`] into `sc.order`, once the
    /// scratch has empty bit sets; `false` when a column has no usable
    /// entry.
    fn eliminate(
        sc: &mut CompileScratch,
        m: usize,
        col_ptr: &[usize],
        row_idx: &[usize],
        fwd: &[usize],
        values: &[f64],
    ) -> bool {
        let w = sc.words;
        sc.used.clear();
        sc.used.resize(w, 0);
        sc.order.clear();
        sc.count.clear();
        sc.count.resize(m, 0);
        let (d, count) = (&mut sc.dense, &mut sc.count);
        // Rows as given, columns in order: d[r·m + c].
        for (c, &j) in fwd.iter().enumerate() {
            for (&r, &v) in row_idx[col_ptr[j]..col_ptr[j + 1]]
                .iter()
                .zip(&values[col_ptr[j]..col_ptr[j + 1]])
            {
                d[r * m + c] = v;
                count[r] += 1;
                set(&mut sc.row_bits, r * w, c);
                set(&mut sc.col_bits, c * w, r);
            }
        }
        for k in 0..m {
            // The rows left with an entry in column k, in order (the
            // column is final: only earlier pivots fill it); `count`
            // becomes each row's entries right of it.
            sc.rows.clear();
            let mut column = 0.0f64;
            for (x, (&c, &u)) in sc.col_bits[k * w..(k + 1) * w]
                .iter()
                .zip(&sc.used)
                .enumerate()
            {
                let mut b = c & !u;
                while b != 0 {
                    let r = x * 64 + b.trailing_zeros() as usize;
                    b &= b - 1;
                    sc.rows.push(r);
                    count[r] -= 1;
                    column = column.max(d[r * m + k].abs());
                }
            }
            let Some(p) = pick_row(&sc.rows, |r| d[r * m + k], count, column) else {
                return false;
            };
            set(&mut sc.used, 0, p);
            sc.order.push(p);
            // The pivot row's columns right of k and their values (the
            // updates of step k change other rows only).
            let pivot = &sc.row_bits[p * w..(p + 1) * w];
            sc.cols.clear();
            sc.pivot_row.clear();
            for j in bits(pivot, k + 1) {
                sc.cols.push(j as u32);
                sc.pivot_row.push(d[p * m + j]);
            }
            sc.pivot_bits.clear();
            sc.pivot_bits.extend_from_slice(pivot);
            let inv = d[p * m + k].recip();
            // The other rows, two at a time (the pivot row's values read
            // once for both; each entry takes the same operations).
            sc.rows.retain(|&i| i != p);
            let (pairs, last) = sc.rows.as_chunks::<2>();
            for &[i1, i2] in pairs {
                let (t1, t2) = two_rows(d, m, i1, i2);
                let (l1, l2) = (t1[k] * inv, t2[k] * inv);
                for (&j, &u) in sc.cols.iter().zip(&sc.pivot_row) {
                    t1[j as usize] -= l1 * u;
                    t2[j as usize] -= l2 * u;
                }
            }
            if let [i] = *last {
                let target = &mut d[i * m..(i + 1) * m];
                let l = target[k] * inv;
                for (&j, &u) in sc.cols.iter().zip(&sc.pivot_row) {
                    target[j as usize] -= l * u;
                }
            }
            for &i in &sc.rows {
                let col_bits = &mut sc.col_bits;
                let count_i = &mut count[i];
                merge(
                    &mut sc.row_bits[i * w..(i + 1) * w],
                    &sc.pivot_bits,
                    k + 1,
                    |j| {
                        *count_i += 1;
                        set(col_bits, j * w, i);
                    },
                );
            }
        }
        true
    }

    /// Whether a program has been compiled.
    pub(crate) fn is_compiled(&self) -> bool {
        self.pivot.len() == self.m && self.l_ptr.len() == self.m + 1
    }

    /// The numeric LU of `values` (the reduced CSC values): the factors
    /// into the slots, `1/u_kk` into `pivot_inv`. A pivot that fails its
    /// check is replaced by `±` the largest entry of its column or row
    /// (see the module docs, "Perturbed pivots"), up to
    /// [`MAX_PERTURBED`] of them, each recorded in `perturbed` as
    /// `(position, δ)`: the factors are then those of the matrix plus
    /// `δ` at each of those diagonal positions. Allocation-free when
    /// `perturbed` has room for [`MAX_PERTURBED`].
    ///
    /// # Errors
    /// [`PivotFailed`] on a structurally zero or non-finite pivot, or a
    /// failed pivot beyond [`MAX_PERTURBED`].
    pub(crate) fn factor(
        &mut self,
        values: &[f64],
        pivot_inv: &mut [f64],
        perturbed: &mut Vec<(u32, f64)>,
    ) -> Result<(), PivotFailed> {
        perturbed.clear();
        let a = &mut self.a[..self.slots];
        let (given, fill) = a.split_at_mut(self.values);
        given.copy_from_slice(&values[..self.values]);
        fill.fill(0.0);
        let mut t = 0usize;
        for (k, (&ps, inv_k)) in self.pivot.iter().zip(pivot_inv.iter_mut()).enumerate() {
            if ps == u32::MAX {
                return Err(PivotFailed);
            }
            let mut p = a[ps as usize];
            let ls = &self.l_slots[self.l_ptr[k] as usize..self.l_ptr[k + 1] as usize];
            let us = &self.u_slots[self.u_ptr[k] as usize..self.u_ptr[k + 1] as usize];
            let mut column = 0.0f64;
            for &s in ls {
                let v = a[s as usize].abs();
                if v > column {
                    column = v;
                }
            }
            // Negated so that a NaN pivot fails too.
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            let bad = !(p.abs() >= PIVOT_THRESHOLD * column) || p == 0.0;
            if bad {
                if !(p.is_finite() && column.is_finite()) || perturbed.len() == MAX_PERTURBED {
                    return Err(PivotFailed);
                }
                let row = us.iter().fold(0.0f64, |m, &s| m.max(a[s as usize].abs()));
                let size = column.max(row);
                if !size.is_finite() {
                    return Err(PivotFailed);
                }
                let target = if size > 0.0 { size } else { 1.0 };
                let new = if p < 0.0 { -target } else { target };
                perturbed.push((k as u32, new - p));
                p = new;
                a[ps as usize] = p;
            }
            let inv = p.recip();
            *inv_k = inv;
            let w = us.len();
            let updates = &self.updates[t..t + ls.len() * w];
            t += updates.len();
            if w == 0 {
                for &s in ls {
                    a[s as usize] *= inv;
                }
                continue;
            }
            // `U`'s row `k` read once: the updates of pivot `k` target
            // rows below it only.
            let u_row = &mut self.u_row[..w];
            for (x, &s) in u_row.iter_mut().zip(us) {
                *x = a[s as usize];
            }
            // Four, then two rows of `L` at a time, each value of the row
            // of `U` read once for all (their targets differ: other rows).
            let (quads, ls) = ls.as_chunks::<4>();
            let (quad_updates, updates) = updates.split_at(quads.len() * 4 * w);
            for (&[s1, s2, s3, s4], targets) in quads.iter().zip(quad_updates.chunks_exact(4 * w)) {
                let l1 = a[s1 as usize] * inv;
                a[s1 as usize] = l1;
                let l2 = a[s2 as usize] * inv;
                a[s2 as usize] = l2;
                let l3 = a[s3 as usize] * inv;
                a[s3 as usize] = l3;
                let l4 = a[s4 as usize] * inv;
                a[s4 as usize] = l4;
                let (t1, t) = targets.split_at(w);
                let (t2, t) = t.split_at(w);
                let (t3, t4) = t.split_at(w);
                for ((((&d1, &d2), &d3), &d4), &u) in
                    t1.iter().zip(t2).zip(t3).zip(t4).zip(u_row.iter())
                {
                    a[d1 as usize] -= l1 * u;
                    a[d2 as usize] -= l2 * u;
                    a[d3 as usize] -= l3 * u;
                    a[d4 as usize] -= l4 * u;
                }
            }
            let (pairs, last) = ls.as_chunks::<2>();
            let (pair_updates, last_updates) = updates.split_at(pairs.len() * 2 * w);
            for (&[s1, s2], targets) in pairs.iter().zip(pair_updates.chunks_exact(2 * w)) {
                let l1 = a[s1 as usize] * inv;
                a[s1 as usize] = l1;
                let l2 = a[s2 as usize] * inv;
                a[s2 as usize] = l2;
                let (t1, t2) = targets.split_at(w);
                for ((&d1, &d2), &u) in t1.iter().zip(t2).zip(u_row.iter()) {
                    a[d1 as usize] -= l1 * u;
                    a[d2 as usize] -= l2 * u;
                }
            }
            if let [s] = *last {
                let l = a[s as usize] * inv;
                a[s as usize] = l;
                for (&d, &u) in last_updates.iter().zip(u_row.iter()) {
                    a[d as usize] -= l * u;
                }
            }
        }
        Ok(())
    }

    /// The value of slot `s` of the last factorisation.
    #[inline]
    pub(crate) fn value(&self, s: u32) -> f64 {
        self.a[s as usize]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The program of the dense compilation this module had before its
    /// scratch was kept (symbolic elimination on a dense `m × m` boolean
    /// matrix): values, slots, pivots, `L`'s and `U`'s slots, updates and
    /// the two streams.
    #[derive(Debug, PartialEq)]
    struct Program {
        values: usize,
        slots: usize,
        pivot: Vec<u32>,
        l_ptr: Vec<u32>,
        l_slots: Vec<u32>,
        u_ptr: Vec<u32>,
        u_slots: Vec<u32>,
        updates: Vec<u32>,
        lower: Runs,
        upper: Runs,
    }

    /// A stream's runs, entries (rows, slots) and pieces.
    type Runs = (Vec<(u32, u32)>, Vec<u32>, Vec<u32>, Vec<crate::lu::Piece>);

    fn runs(s: &Stream<u32>) -> Runs {
        (
            s.runs.clone(),
            s.rows.clone(),
            s.vals.clone(),
            s.pieces.clone(),
        )
    }

    fn program(lu: &CompiledLu) -> Program {
        Program {
            values: lu.values,
            slots: lu.slots,
            pivot: lu.pivot.clone(),
            l_ptr: lu.l_ptr.clone(),
            l_slots: lu.l_slots.clone(),
            u_ptr: lu.u_ptr.clone(),
            u_slots: lu.u_slots.clone(),
            updates: lu.updates.clone(),
            lower: runs(&lu.lower),
            upper: runs(&lu.upper),
        }
    }

    fn dense_compile(
        col_ptr: &[usize],
        row_idx: &[usize],
        fwd: &[usize],
        rows: &[usize],
    ) -> Program {
        let m = fwd.len();
        let (mut row_pos, mut col_pos) = (vec![0; m], vec![0; m]);
        for (i, &r) in rows.iter().enumerate() {
            row_pos[r] = i;
        }
        for (c, &j) in fwd.iter().enumerate() {
            col_pos[j] = c;
        }
        let mut nz = vec![false; m * m];
        for j in 0..m {
            for &r in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                nz[row_pos[r] * m + col_pos[j]] = true;
            }
        }
        let mut pivots = Vec::new();
        for k in 0..m {
            let rows: Vec<usize> = (k + 1..m).filter(|&i| nz[i * m + k]).collect();
            let cols: Vec<usize> = (k + 1..m).filter(|&j| nz[k * m + j]).collect();
            for &i in &rows {
                for &j in &cols {
                    nz[i * m + j] = true;
                }
            }
            pivots.push((rows, cols));
        }
        let mut slot = vec![u32::MAX; m * m];
        let mut slots = 0u32;
        for j in 0..m {
            for &r in &row_idx[col_ptr[j]..col_ptr[j + 1]] {
                slot[row_pos[r] * m + col_pos[j]] = slots;
                slots += 1;
            }
        }
        let values = slots as usize;
        for (s, &z) in slot.iter_mut().zip(&nz) {
            if z && *s == u32::MAX {
                *s = slots;
                slots += 1;
            }
        }
        let mut p = Program {
            values,
            slots: slots as usize,
            pivot: Vec::new(),
            l_ptr: vec![0],
            l_slots: Vec::new(),
            u_ptr: vec![0],
            u_slots: Vec::new(),
            updates: Vec::new(),
            lower: Default::default(),
            upper: Default::default(),
        };
        let mut lower = Stream::default();
        for (k, (rows, cols)) in pivots.iter().enumerate() {
            p.pivot.push(slot[k * m + k]);
            p.l_slots.extend(rows.iter().map(|&i| slot[i * m + k]));
            p.u_slots.extend(cols.iter().map(|&j| slot[k * m + j]));
            for &i in rows {
                p.updates.extend(cols.iter().map(|&j| slot[i * m + j]));
                lower.push(i as u32, k as u32, slot[i * m + k]);
            }
            p.l_ptr.push(p.l_slots.len() as u32);
            p.u_ptr.push(p.u_slots.len() as u32);
        }
        let mut upper = Stream::default();
        for j in (0..m).rev() {
            for i in 0..j {
                if nz[i * m + j] {
                    upper.push(i as u32, j as u32, slot[i * m + j]);
                }
            }
        }
        lower.seal();
        upper.seal();
        p.lower = runs(&lower);
        p.upper = runs(&upper);
        p
    }

    /// The row choice on dense arrays, as this module made it before.
    fn dense_rows(
        col_ptr: &[usize],
        row_idx: &[usize],
        fwd: &[usize],
        values: &[f64],
    ) -> Option<Vec<usize>> {
        let m = fwd.len();
        let (mut d, mut nz) = (vec![0.0; m * m], vec![false; m * m]);
        let (mut used, mut count, mut order) = (vec![false; m], vec![0usize; m], Vec::new());
        for (c, &j) in fwd.iter().enumerate() {
            for e in col_ptr[j]..col_ptr[j + 1] {
                let r = row_idx[e];
                d[r * m + c] = values[e];
                nz[r * m + c] = true;
                count[r] += 1;
            }
        }
        for k in 0..m {
            let mut rows = Vec::new();
            let mut column = 0.0f64;
            for r in 0..m {
                if !used[r] && nz[r * m + k] {
                    rows.push(r);
                    count[r] -= 1;
                    column = column.max(d[r * m + k].abs());
                }
            }
            let p = pick_row(&rows, |r| d[r * m + k], &count, column)?;
            used[p] = true;
            order.push(p);
            let cols: Vec<usize> = (k + 1..m).filter(|&j| nz[p * m + j]).collect();
            let inv = d[p * m + k].recip();
            for &i in &rows {
                if i == p {
                    continue;
                }
                let l = d[i * m + k] * inv;
                for &j in &cols {
                    d[i * m + j] -= l * d[p * m + j];
                    if !nz[i * m + j] {
                        nz[i * m + j] = true;
                        count[i] += 1;
                    }
                }
            }
        }
        Some(order)
    }

    /// A sparse `m × m` CSC structure with values (a diagonal with some
    /// entries left out, a few entries a column, ties of values), and a
    /// column order.
    fn case(m: usize, seed: u64) -> (Vec<usize>, Vec<usize>, Vec<f64>, Vec<usize>) {
        let mut s = seed;
        let mut next = move || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 33) as usize
        };
        let (mut col_ptr, mut row_idx, mut values) = (vec![0], Vec::new(), Vec::new());
        for j in 0..m {
            let mut rows: Vec<usize> = (0..3).map(|_| next() % m).collect();
            if next() % 4 != 0 {
                rows.push(j);
            }
            rows.sort_unstable();
            rows.dedup();
            for r in rows {
                row_idx.push(r);
                // Few distinct magnitudes: ties of the row choice.
                values.push([1.0, -2.0, 0.5, 2.0][next() % 4]);
            }
            col_ptr.push(row_idx.len());
        }
        let mut fwd: Vec<usize> = (0..m).collect();
        for i in (1..m).rev() {
            fwd.swap(i, next() % (i + 1));
        }
        (col_ptr, row_idx, values, fwd)
    }

    #[test]
    fn programs_and_row_choices_equal_the_dense_ones() {
        // One scratch for every case and dimension (one word of bits and
        // several), as a solver keeps it.
        let mut sc = CompileScratch::default();
        let (mut chosen, mut symbolic) = (0, 0);
        for (m, seed) in [
            (1, 1),
            (5, 2),
            (19, 3),
            (63, 4),
            (64, 5),
            (65, 6),
            (130, 7),
            (40, 8),
            (200, 9),
        ] {
            let (col_ptr, row_idx, values, fwd) = case(m, seed);
            let dense = dense_rows(&col_ptr, &row_idx, &fwd, &values);
            let ours = CompiledLu::choose_rows(&mut sc, &col_ptr, &row_idx, &fwd, &values)
                .map(<[usize]>::to_vec);
            assert_eq!(ours, dense, "m = {m}: the row choice");
            // The chosen order (compiled from the row choice's structure)
            // and others (a symbolic elimination of their own).
            let reverse: Vec<usize> = (0..m).rev().collect();
            let orders = dense.iter().cloned().chain([reverse]);
            for rows in orders {
                let mut lu = CompiledLu::default();
                if ours.as_deref() == Some(&rows[..]) {
                    CompiledLu::choose_rows(&mut sc, &col_ptr, &row_idx, &fwd, &values);
                    chosen += 1;
                } else {
                    symbolic += 1;
                }
                assert!(lu.compile(&mut sc, &col_ptr, &row_idx, &fwd, &rows, true));
                assert_eq!(
                    program(&lu),
                    dense_compile(&col_ptr, &row_idx, &fwd, &rows),
                    "m = {m}"
                );
                assert_eq!(lu.row_perm, rows);
            }
        }
        assert!(
            chosen >= 3 && symbolic >= 6,
            "{chosen} chosen, {symbolic} symbolic"
        );
    }
}

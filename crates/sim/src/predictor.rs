//! The predictor of a step's unknowns from the accepted steps before it:
//! the starting guess of Newton's method (stage 3 of a step), shared by
//! the planar and the spatial engines.
//!
//! Each unknown is extrapolated one step ahead by the polynomial through
//! its last values: `q[k+1]` through `q[k−p..k]`, `p` = 0 (the last
//! configuration) to [`MAX_Q_ORDER`], and the forces through the last
//! solutions, `p` = 0 (the last solution) to [`MAX_FORCE_ORDER`]. The
//! order is the one that would have predicted the last accepted step best
//! (the smallest largest error over the coordinates, over the forces; ties
//! take the lower order, except that `q`'s order 0 must predict strictly
//! better than every higher one): a high order has the smaller truncation
//! error on a smooth motion and the larger round-off, which wins when the
//! motion is a polynomial — the discrete free fall, which every order from
//! 2 predicts exactly. The order is at most the number of accepted steps
//! solved in the current contact and joint-limit states (one more for
//! `q`): an impact changes the velocity and the contact forces, and the
//! steps before it are no history of the motion after it.
//!
//! `q`'s order 0 is a robot at rest: its coordinates only jitter by
//! round-off from step to step, and every extrapolation of a higher order
//! adds a multiple of that jitter (the more, the higher the order) to the
//! first residual, which then misses the tolerance on a position row.
//! Held at its last configuration, the standing hexapod of `bench/peer`
//! solves every step after t = 0.515 s with the prediction alone (416
//! Newton iterations in 5001 steps instead of 677), and from step 517 on
//! it repeats, bit for bit, an exact equilibrium of the discrete
//! equations. Ties keep the higher order, as at the first step, where the
//! history before it is a fiction at rest. Once every difference of order 1 and more is `+0` (the robot exactly
//! at rest), recording the newest values again would change no bit:
//! [`Predictor::record`] then compares them and leaves the histories as
//! they are.
//!
//! The better the prediction, the fewer Newton iterations: at Δt = 1 ms a
//! moving robot's cubic prediction of `q` is off by ~1e-9 (rad, m) and the
//! quintic by ~1e-11, i.e. one chord step instead of two or three
//! (`fbd_solver::NewtonParams::chord_steps`). Orders up to 7 for `q` and
//! 5 for the forces (up from 5 and 3) cut the Newton iterations of the
//! peer cases further (`bench/peer`: the robot hanging from its feet,
//! 2.36 → 1.82 per step over 20 s; the moving flight, 0.92 → 0.87 over
//! 100 s and 1.26 → 1.03 over its first 10 s); the selection keeps a lower
//! order wherever the higher one predicted worse. The result of a step does not depend on the
//! predictor beyond the solver's tolerance.
//!
//! An unknown pinned to zero — a free contact point's force, a free
//! joint stop's moment: singleton rows whose solution is exactly `+0` —
//! has a history of zeros, which records to zeros: [`Predictor::record`]
//! skips such an unknown (its differences, all `+0`, stay as they are),
//! with the same result bit for bit.
//!
//! No allocation after [`Predictor::new`].

/// Highest order of the extrapolation of `q` (it uses `q[k−7..k]`).
pub const MAX_Q_ORDER: usize = 7;

/// Highest order of the extrapolation of the forces (the last six
/// solutions).
pub const MAX_FORCE_ORDER: usize = 5;

/// The histories of the accepted steps and the orders they select.
#[derive(Clone, Debug)]
pub struct Predictor {
    /// Number of coordinates `q` at the front of the unknowns.
    nq: usize,
    /// Per coordinate, its backward differences at the newest step,
    /// `∇ʲq_i[k]` for `j = 0..=MAX_Q_ORDER` (the higher ones meaningful
    /// only as far as `steps` and `smooth` allow).
    q: Vec<[f64; MAX_Q_ORDER + 1]>,
    /// Per force (the unknowns after `q`), the backward differences of its
    /// solutions at the newest step.
    f: Vec<[f64; MAX_FORCE_ORDER + 1]>,
    /// Per force, `true` when its differences are all `+0` (a history of
    /// zeros, skipped by `record`: see the module docs).
    f_zero: Vec<bool>,
    /// Accepted steps recorded (`k`).
    steps: usize,
    /// How many recorded steps before the newest were solved in the
    /// newest one's states, without a retry in substeps.
    smooth: usize,
    /// The orders (of `q`, of the forces) that would have predicted the
    /// newest step best.
    orders: [usize; 2],
    /// Every history is at rest: its differences of order 1 and more are
    /// all `+0`, bit for bit (see [`Predictor::record`]).
    rest: bool,
}

impl Predictor {
    /// A predictor at step 0: configuration `q0` (`q[0]`, the first `nq`
    /// unknowns) and unknowns `z0` (`q0` and the initial forces).
    pub fn new(q0: &[f64], z0: &[f64]) -> Self {
        assert!(q0.len() <= z0.len(), "more coordinates than unknowns");
        let nq = q0.len();
        Self {
            nq,
            q: q0.iter().map(|&v| differences_of(v)).collect(),
            f: z0[nq..].iter().map(|&v| differences_of(v)).collect(),
            f_zero: z0[nq..].iter().map(|v| v.to_bits() == 0).collect(),
            steps: 0,
            smooth: 0,
            orders: [1, 0],
            rest: false,
        }
    }

    /// The extrapolation orders the next [`Self::predict`] uses: `q`'s
    /// (0 to [`MAX_Q_ORDER`]) and the forces' (0 to [`MAX_FORCE_ORDER`]).
    pub fn orders(&self) -> [usize; 2] {
        let [q, f] = self.orders;
        [
            q.min(self.smooth + 1).min(self.steps),
            f.min(self.smooth).min(self.steps),
        ]
    }

    /// Writes the prediction of the next step's unknowns into `z`.
    ///
    /// # Panics
    /// If no step was recorded yet (at k = 0 the initial velocities give
    /// the prediction), or `z` has the wrong length.
    pub fn predict(&self, z: &mut [f64]) {
        assert!(self.steps > 0, "the predictor needs an accepted step");
        assert_eq!(
            z.len(),
            self.nq + self.f.len(),
            "unknowns of the wrong length"
        );
        let [q_order, f_order] = self.orders();
        let (zq, zf) = z.split_at_mut(self.nq);
        extrapolate(&self.q, q_order, zq);
        extrapolate(&self.f, f_order, zf);
    }

    /// Records an accepted step: its unknowns `z` (`q[k+1]` first) and
    /// whether it was solved in the same contact and joint-limit states as
    /// the step before (`false` also for a step solved in substeps).
    ///
    /// # Panics
    /// If `z` has the wrong length.
    pub fn record(&mut self, z: &[f64], same_states: bool) {
        assert_eq!(
            z.len(),
            self.nq + self.f.len(),
            "unknowns of the wrong length"
        );
        let (zq, zf) = z.split_at(self.nq);
        if self.rest && self.newest_are(zq, zf) {
            // A history at rest recording its newest values again: every
            // difference stays `+0` (`v − v`) and every order predicted
            // them exactly, so the ties give `q` order 1 (order 0 must win
            // strictly) and the forces order 0 — what recording them
            // would give, bit for bit, without the pass over the histories
            // (a robot at rest, module docs; `f_zero` may stay `false` for
            // a force at rest at `+0`, which only skips less).
            self.orders = [1, 0];
        } else {
            let q_err = record_history(&mut self.q, zq);
            let moving = argmin(&q_err[1..]) + 1;
            let f_err = record_forces(&mut self.f, &mut self.f_zero, zf);
            self.orders = [
                // Order 0 only when it predicted strictly best (module docs).
                if q_err[0] < q_err[moving] { 0 } else { moving },
                argmin(&f_err),
            ];
            // Exactly at rest only where every error is zero: checked there
            // alone (a zero error may be a `−0` difference).
            self.rest = q_err.iter().chain(&f_err).all(|&e| e == 0.0)
                && at_rest(&self.q)
                && at_rest(&self.f);
        }
        self.smooth = if same_states {
            (self.smooth + 1).min(MAX_Q_ORDER - 1)
        } else {
            0
        };
        self.steps += 1;
    }

    /// Whether `zq` and `zf` are the newest recorded values, bit for bit
    /// (and finite: `v − v` is `+0`).
    fn newest_are(&self, zq: &[f64], zf: &[f64]) -> bool {
        let same = |h: &[f64], v: f64| v.is_finite() && h[0].to_bits() == v.to_bits();
        self.q.iter().zip(zq).all(|(d, &v)| same(d, v))
            && self.f.iter().zip(zf).all(|(d, &v)| same(d, v))
    }
}

/// Whether every history's differences of order 1 and more are `+0`.
fn at_rest<const N: usize>(hist: &[[f64; N]]) -> bool {
    hist.iter().all(|d| d[1..].iter().all(|x| x.to_bits() == 0))
}

/// The backward differences of a history that is `v` at every step.
fn differences_of<const N: usize>(v: f64) -> [f64; N] {
    let mut d = [0.0; N];
    d[0] = v;
    d
}

/// The extrapolations one step ahead of order `p` (below `N`) from the
/// backward differences `hist` at the newest step, into `z`: Newton's form
/// `d[0] + Σ_{1≤j≤p} d[j]` for each unknown, in which the differences of
/// close values are exact and their small sum is added to `d[0]` last, so
/// that it rounds about once.
///
/// The order is the same for every unknown of a prediction: it selects a
/// loop compiled for it ([`extrapolate_order`]), with no test per term.
fn extrapolate<const N: usize>(hist: &[[f64; N]], p: usize, z: &mut [f64]) {
    const { assert!(N <= 8, "a loop per order up to 7") };
    assert!(p < N, "order {p} beyond the history");
    match p {
        0 => extrapolate_order::<N, 0>(hist, z),
        1 => extrapolate_order::<N, 1>(hist, z),
        2 => extrapolate_order::<N, 2>(hist, z),
        3 => extrapolate_order::<N, 3>(hist, z),
        4 => extrapolate_order::<N, 4>(hist, z),
        5 => extrapolate_order::<N, 5>(hist, z),
        6 => extrapolate_order::<N, 6>(hist, z),
        _ => extrapolate_order::<N, 7>(hist, z),
    }
}

/// [`extrapolate`] of order `P` (`P < N`): the sum of `d[1..=P]` from the
/// empty sum and in order, the additions of `d[1..=P].iter().sum()`, in a
/// fixed-length loop the compiler unrolls.
#[inline]
fn extrapolate_order<const N: usize, const P: usize>(hist: &[[f64; N]], z: &mut [f64]) {
    for (zi, d) in z.iter_mut().zip(hist) {
        let mut sum: f64 = std::iter::empty::<f64>().sum();
        for &dj in d.iter().skip(1).take(P) {
            sum += dj;
        }
        *zi = d[0] + sum;
    }
}

/// Records `values` as the newest step of the histories whose backward
/// differences are `hist` (`∇ʲv[k]` → `∇ʲv[k+1] = ∇ʲ⁻¹v[k+1] −
/// ∇ʲ⁻¹v[k]`), and returns, for each extrapolation order `p`, the largest
/// error with which it would have predicted them, `|∇ᵖ⁺¹v[k+1]|` (for
/// the highest order, `∇ᴺv[k+1]` is computed but not stored).
fn record_history<const N: usize>(hist: &mut [[f64; N]], values: &[f64]) -> [f64; N] {
    let mut err = [0.0f64; N];
    for (d, &v) in hist.iter_mut().zip(values) {
        record_one(d, v, &mut err);
    }
    err
}

/// Records `v` as the newest value of the history with backward
/// differences `d`, raising each `err[p]` to `|∇ᵖ⁺¹v[k+1]|`.
#[inline]
fn record_one<const N: usize>(d: &mut [f64; N], v: f64, err: &mut [f64; N]) {
    let mut new = v;
    for (dj, e) in d.iter_mut().zip(err.iter_mut()) {
        let old = *dj;
        *dj = new;
        new -= old;
        // `e.max(|new|)` without its NaN handling (`e` is never NaN;
        // a NaN `new` leaves it, as `max` would).
        let a = new.abs();
        if a > *e {
            *e = a;
        }
    }
}

/// [`record_history`] for the forces, skipping every force whose history
/// and new value are `+0` (recording it would leave its differences `+0`
/// and add no error), and keeping `zero` (every difference `+0`) up to
/// date.
fn record_forces<const N: usize>(
    hist: &mut [[f64; N]],
    zero: &mut [bool],
    values: &[f64],
) -> [f64; N] {
    let mut err = [0.0f64; N];
    for ((d, z), &v) in hist.iter_mut().zip(zero.iter_mut()).zip(values) {
        let pinned = v.to_bits() == 0;
        if pinned && *z {
            continue;
        }
        record_one(d, v, &mut err);
        *z = pinned && d.iter().all(|x| x.to_bits() == 0);
    }
    err
}

/// Index of the smallest value, the first one on ties (NaN never wins).
fn argmin(v: &[f64]) -> usize {
    let mut best = 0;
    for (i, &x) in v.iter().enumerate() {
        if x < v[best] {
            best = i;
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The extrapolations of every order one step ahead of the history
    /// `v` (newest first), through the predictor's own functions: the
    /// values recorded oldest first, then extrapolated.
    fn extrapolations<const N: usize>(v: &[f64; N]) -> [f64; N] {
        let mut hist = [differences_of::<N>(v[N - 1])];
        for &x in v[..N - 1].iter().rev() {
            record_history(&mut hist, &[x]);
        }
        std::array::from_fn(|p| {
            let mut z = [0.0];
            extrapolate(&hist, p, &mut z);
            z[0]
        })
    }

    #[test]
    fn extrapolations_are_exact_for_polynomials_of_their_order() {
        // v(t) = 1 + 2t − t² + 0.5t³ − 0.1t⁴ + 0.01t⁵ sampled at t = 0, −1, …
        let f =
            |t: f64| 1.0 + 2.0 * t - t * t + 0.5 * t.powi(3) - 0.1 * t.powi(4) + 0.01 * t.powi(5);
        let v: [f64; 6] = std::array::from_fn(|j| f(-(j as f64)));
        let e = extrapolations(&v);
        assert!(
            (e[5] - f(1.0)).abs() < 1e-12,
            "quintic: {} vs {}",
            e[5],
            f(1.0)
        );
        // Lower orders are exact for lower-degree polynomials.
        for p in 0..6 {
            let g = |t: f64| {
                (0..=p)
                    .map(|d| (d as f64 + 1.0) * t.powi(d as i32))
                    .sum::<f64>()
            };
            let v: [f64; 6] = std::array::from_fn(|j| g(-(j as f64)));
            let e = extrapolations(&v);
            for (order, ep) in e.iter().enumerate().skip(p) {
                assert!(
                    (ep - g(1.0)).abs() < 1e-9,
                    "degree {p}, order {order}: {ep} vs {}",
                    g(1.0)
                );
            }
        }
    }

    #[test]
    fn a_history_at_rest_holds_the_last_configuration() {
        // Coordinates that only jitter by round-off about a rest (as a
        // standing robot's): order 0 predicted best, and is selected.
        let jitter = [0.0, 3e-16, -2e-16, 1e-16, -3e-16, 2e-16, 0.0, -1e-16];
        let z = |k: usize| vec![0.35 + jitter[k % 8], -0.4 - jitter[(k + 3) % 8], 50.0];
        let mut p = Predictor::new(&z(0)[..2], &z(0));
        for k in 1..12 {
            p.record(&z(k), true);
        }
        assert_eq!(p.orders()[0], 0);
        let mut next = vec![0.0; 3];
        p.predict(&mut next);
        assert_eq!(next[..2], z(11)[..2]);
        // A tie (the first step, from a history at rest) keeps order 1,
        // and a motion never selects order 0.
        let moving = |k: usize| vec![0.1 * k as f64, 2.0, 50.0];
        let mut p = Predictor::new(&moving(0)[..2], &moving(0));
        p.record(&moving(1), true);
        assert_eq!(p.orders()[0], 1);
        for k in 2..12 {
            p.record(&moving(k), true);
            assert_ne!(p.orders()[0], 0, "step {k}");
        }
    }

    #[test]
    fn a_history_at_rest_is_not_recorded_again_and_predicts_the_same() {
        // Moving, then exactly at rest (a force `−0`, one pinned `+0`),
        // then moving again: the predictor that skips recording at rest
        // holds what recording gives, bit for bit, at every step.
        let z = |k: usize| {
            let t = k.min(12) as f64 + k.saturating_sub(30) as f64;
            vec![0.3 + 0.01 * t * t, -0.2 + 0.1 * t, 50.0 - t, -0.0, 0.0]
        };
        let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
        let hist = |p: &Predictor| {
            let mut v: Vec<u64> = p.q.iter().flatten().map(|x| x.to_bits()).collect();
            v.extend(p.f.iter().flatten().map(|x| x.to_bits()));
            v
        };
        let mut fast = Predictor::new(&z(0)[..2], &z(0));
        let mut full = fast.clone();
        let mut skipped = 0;
        for k in 1..40 {
            if fast.rest {
                skipped += 1;
            }
            fast.record(&z(k), k % 7 != 0);
            full.rest = false;
            full.record(&z(k), k % 7 != 0);
            assert_eq!(hist(&fast), hist(&full), "step {k}");
            assert_eq!(fast.orders(), full.orders(), "step {k}");
            let (mut a, mut b) = (vec![0.0; 5], vec![0.0; 5]);
            fast.predict(&mut a);
            full.predict(&mut b);
            assert_eq!(bits(&a), bits(&b), "step {k}");
        }
        assert!(skipped >= 8, "{skipped} records skipped at rest");
        assert!(!fast.rest);
    }

    #[test]
    fn the_order_follows_the_history() {
        // A smooth non-polynomial motion: after a few steps the highest
        // order predicts best and is selected; a broken history resets it.
        let q = |k: usize| [(0.1 * k as f64).sin(), 0.5 * k as f64];
        let z = |k: usize| {
            let [a, b] = q(k);
            vec![a, b, (0.07 * k as f64).cos()]
        };
        let mut p = Predictor::new(&q(0), &z(0));
        for k in 1..12 {
            p.record(&z(k), true);
        }
        assert_eq!(p.orders(), [MAX_Q_ORDER, MAX_FORCE_ORDER]);
        let mut next = vec![0.0; 3];
        p.predict(&mut next);
        let exact = z(12);
        assert!((next[0] - exact[0]).abs() < 1e-4, "{next:?} vs {exact:?}");
        assert!((next[1] - exact[1]).abs() < 1e-12, "{next:?} vs {exact:?}");
        assert!((next[2] - exact[2]).abs() < 1e-4, "{next:?} vs {exact:?}");
        p.record(&z(12), false);
        assert_eq!(p.orders(), [1, 0]);
        p.record(&z(13), true);
        assert_eq!(p.orders()[0], 2);
    }
}

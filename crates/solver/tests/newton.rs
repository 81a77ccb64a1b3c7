//! Behavioural tests of `NewtonSolver`: convergence, pattern caching, and
//! each error variant.

mod common;

use common::{Cubic, Small, TrigChain};
use fbd_kinematics::fd::{FdTolerance, check_jacobian};
use fbd_solver::{NewtonParams, NewtonSolver, NewtonSystem, SolverError};

fn root10() -> Vec<f64> {
    (0..10)
        .map(|i| 0.8 * ((i as f64) * 0.7 + 0.3).sin())
        .collect()
}

#[test]
fn trig_chain_jacobian_matches_finite_differences() {
    let mut sys = TrigChain::with_root(&root10(), 1);
    let x: Vec<f64> = (0..10).map(|i| 0.3 * (i as f64) - 1.1).collect();
    let mut r = vec![0.0; 10];
    let dense = NewtonSolver::dense_jacobian(&mut sys, &x, &mut r);
    let b = sys.b.clone();
    check_jacobian(
        &x,
        10,
        |x, out| {
            TrigChain::f(x, out);
            for (o, bi) in out.iter_mut().zip(&b) {
                *o -= bi;
            }
        },
        |i, j| dense[i * 10 + j],
        FdTolerance::default(),
    )
    .unwrap_or_else(|m| panic!("{m}"));
}

#[test]
fn trig_chain_converges_quadratically() {
    let root = root10();
    let mut sys = TrigChain::with_root(&root, 1);
    let mut x = vec![0.0; 10];
    let mut solver = NewtonSolver::default();
    let report = solver.solve(&mut sys, &mut x).expect("converges");

    assert!(report.residual <= 1e-9, "{report:?}");
    assert!(report.iterations <= 6, "too many iterations: {report:?}");
    assert_eq!(report.factorizations, report.iterations);
    for (xi, ri) in x.iter().zip(&root) {
        assert!((xi - ri).abs() < 1e-9, "x = {x:?}, root = {root:?}");
    }

    // Quadratic convergence: once in the asymptotic regime, the residual
    // max-norm at iterate k+1 is bounded by C·(residual at k)².
    let h = sys.history.as_slice();
    assert_eq!(
        h.len(),
        report.iterations + 1,
        "one Jacobian per iterate: {h:?}"
    );
    let tail: Vec<_> = h.windows(2).filter(|w| w[0] < 1e-2 && w[1] > 0.0).collect();
    assert!(!tail.is_empty(), "history {h:?}");
    for w in tail {
        assert!(w[1] <= 10.0 * w[0] * w[0], "not quadratic: {h:?}");
    }

    // Solving again from the root takes no step at all.
    let report = solver.solve(&mut sys, &mut x).expect("converged");
    assert_eq!(report.iterations, 0);
    assert_eq!(report.factorizations, 0);
}

#[test]
fn two_pattern_keys_give_exactly_two_symbolic_factorizations() {
    let root = root10();
    let mut chain = TrigChain::with_root(&root, 0xC4A1);
    let mut cubic = Cubic {
        c: vec![1.0, -2.0, 0.5, 3.0, 0.0, -1.0, 2.0],
        key: 0xC0B1C,
    };
    let mut solver = NewtonSolver::default();
    let mut total_iterations = 0u64;
    for k in 0..25 {
        let shifted: Vec<f64> = root.iter().map(|r| r + 0.01 * k as f64).collect();
        chain.retarget(&shifted);
        let mut x = vec![0.0; 10];
        let rep = solver.solve(&mut chain, &mut x).expect("chain converges");
        total_iterations += rep.factorizations as u64;

        cubic.c[0] = 1.0 + 0.1 * k as f64;
        let mut y = vec![0.0; 7];
        let rep = solver.solve(&mut cubic, &mut y).expect("cubic converges");
        total_iterations += rep.factorizations as u64;
        let mut r = vec![0.0; 7];
        cubic.eval(&y, &mut r, None);
        assert!(r.iter().all(|v| v.abs() <= 1e-9), "{r:?}");
    }
    assert_eq!(solver.symbolic_factorizations(), 2);
    assert_eq!(solver.cached_patterns(), 2);
    assert_eq!(solver.numeric_factorizations(), total_iterations);
}

#[test]
fn structurally_singular_system_is_reported() {
    // Unknown 2 appears in no equation: column 2 of J is structurally empty.
    let mut sys = Small {
        n: 3,
        key: 7,
        entries: vec![(0, 0), (0, 1), (1, 0), (1, 1), (2, 0)],
        f: |x: &[f64], r: &mut [f64], j: &mut dyn FnMut(usize, usize, f64)| {
            r[0] = x[0] + x[1] - 1.0;
            r[1] = x[0] - x[1];
            r[2] = x[0] * x[0] - 4.0;
            j(0, 0, 1.0);
            j(0, 1, 1.0);
            j(1, 0, 1.0);
            j(1, 1, -1.0);
            j(2, 0, 2.0 * x[0]);
        },
    };
    let mut x = vec![1.0; 3];
    let err = NewtonSolver::default().solve(&mut sys, &mut x).unwrap_err();
    assert_eq!(err, SolverError::Singular { equation: 2 }, "{err}");
}

#[test]
fn numerically_singular_jacobian_is_reported() {
    // Structurally fine, but the two rows are parallel: a zero pivot.
    let mut sys = Small {
        n: 2,
        key: 8,
        entries: vec![(0, 0), (0, 1), (1, 0), (1, 1)],
        f: |x: &[f64], r: &mut [f64], j: &mut dyn FnMut(usize, usize, f64)| {
            r[0] = x[0] + x[1] - 1.0;
            r[1] = 2.0 * x[0] + 2.0 * x[1] - 3.0;
            j(0, 0, 1.0);
            j(0, 1, 1.0);
            j(1, 0, 2.0);
            j(1, 1, 2.0);
        },
    };
    let mut x = vec![0.0; 2];
    let err = NewtonSolver::default().solve(&mut sys, &mut x).unwrap_err();
    assert!(
        matches!(err, SolverError::Singular { equation } if equation < 2),
        "{err}"
    );
}

#[test]
fn system_without_real_root_diverges() {
    // Row 1 is x1² + 1 = 0: no real root. Row 0 is fine.
    let mut sys = Small {
        n: 2,
        key: 9,
        entries: vec![(0, 0), (1, 1)],
        f: |x: &[f64], r: &mut [f64], j: &mut dyn FnMut(usize, usize, f64)| {
            r[0] = x[0] - 1.0;
            r[1] = x[1] * x[1] + 1.0;
            j(0, 0, 1.0);
            j(1, 1, 2.0 * x[1]);
        },
    };
    let mut x = vec![0.0, 0.5];
    let err = NewtonSolver::default().solve(&mut sys, &mut x).unwrap_err();
    let SolverError::Diverged { iter, residual } = err else {
        panic!("expected Diverged, got {err:?}");
    };
    assert!(residual >= 1.0, "{err}");
    assert!(iter <= 20);
    let msg = err.to_string();
    assert!(msg.contains(&format!("iteration {iter}")), "{msg}");
    assert!(!msg.contains('\n'));
    // x holds the last accepted iterate, whose residual is the reported one.
    assert!(((x[1] * x[1] + 1.0) - residual).abs() <= 1e-12);

    // With no line search budget and few iterations the same system hits
    // the iteration limit or the line-search failure at once.
    let mut solver = NewtonSolver::new(NewtonParams {
        max_iterations: 3,
        ..NewtonParams::default()
    });
    let mut x = vec![0.0, 0.5];
    assert!(matches!(
        solver.solve(&mut sys, &mut x),
        Err(SolverError::Diverged { iter, .. }) if iter <= 3
    ));
}

#[test]
fn a_residual_at_its_noise_floor_is_accepted_but_not_one_far_from_it() {
    // r = x − 1 ± ε (the sign of x − 1): |r| ≥ ε everywhere, so with
    // ε = 2e-9 the residual cannot be pushed below residual_tol = 1e-9, and
    // the Newton steps (~ε) are never "negligible" (step_tol = 1e-12): only
    // the floor test — no decrease possible, ‖r‖ ≤ step_residual_factor·tol —
    // accepts it. Without that test this is `Diverged`.
    let noisy = |level: f64| Small {
        n: 1,
        key: 11,
        entries: vec![(0, 0)],
        f: move |x: &[f64], r: &mut [f64], j: &mut dyn FnMut(usize, usize, f64)| {
            let e = x[0] - 1.0;
            r[0] = e + if e >= 0.0 { level } else { -level };
            j(0, 0, 1.0);
        },
    };
    let mut x = vec![0.0];
    let report = NewtonSolver::default()
        .solve(&mut noisy(2e-9), &mut x)
        .expect("a residual at the round-off floor is converged");
    assert!(
        report.residual >= 2e-9 && report.residual <= 1e-6,
        "{report:?}"
    );
    assert!((x[0] - 1.0).abs() < 1e-8);
    // The same floor at 1e-3 is far above the allowance: diverged.
    let mut x = vec![0.0];
    let err = NewtonSolver::default()
        .solve(&mut noisy(1e-3), &mut x)
        .unwrap_err();
    assert!(matches!(err, SolverError::Diverged { .. }), "{err}");
}

#[test]
fn iteration_limit_reports_diverged_at_max_iterations() {
    // Converges, but needs more than one step.
    let mut sys = TrigChain::with_root(&root10(), 1);
    let mut solver = NewtonSolver::new(NewtonParams {
        max_iterations: 1,
        ..NewtonParams::default()
    });
    let mut x = vec![0.0; 10];
    let err = solver.solve(&mut sys, &mut x).unwrap_err();
    assert!(
        matches!(err, SolverError::Diverged { iter: 1, .. }),
        "{err}"
    );
    assert!(err.to_string().contains("iteration 1 "), "{err}");
}

#[test]
fn nan_residual_is_non_finite() {
    let mut sys = Small {
        n: 1,
        key: 10,
        entries: vec![(0, 0)],
        f: |x: &[f64], r: &mut [f64], j: &mut dyn FnMut(usize, usize, f64)| {
            r[0] = x[0].sqrt() - 2.0;
            j(0, 0, 0.5 / x[0].sqrt());
        },
    };
    let mut x = vec![-1.0];
    let err = NewtonSolver::default().solve(&mut sys, &mut x).unwrap_err();
    assert_eq!(err, SolverError::NonFinite { iter: 0 });
    assert!(!err.to_string().contains('\n'));
}

#[test]
fn nan_in_every_trial_point_is_non_finite() {
    // r = sqrt(x) + 1 is finite for x ≥ 0 only. From x = 1e-6 the Newton
    // step is −0.002, and even after 8 halvings x + α·Δx < 0 (NaN).
    let mut sys = Small {
        n: 1,
        key: 12,
        entries: vec![(0, 0)],
        f: |x: &[f64], r: &mut [f64], j: &mut dyn FnMut(usize, usize, f64)| {
            r[0] = (x[0]).sqrt() + 1.0;
            j(0, 0, 0.5 / x[0].sqrt());
        },
    };
    let mut x = vec![1e-6];
    let err = NewtonSolver::default().solve(&mut sys, &mut x).unwrap_err();
    assert_eq!(err, SolverError::NonFinite { iter: 0 }, "{err}");
}

#[test]
fn line_search_recovers_from_nan_full_step() {
    // r = ln x: from x = 3 the full Newton step lands at x < 0 (NaN); one
    // halving lands inside the domain and the solve converges.
    let mut sys = Small {
        n: 1,
        key: 11,
        entries: vec![(0, 0)],
        f: |x: &[f64], r: &mut [f64], j: &mut dyn FnMut(usize, usize, f64)| {
            r[0] = x[0].ln();
            j(0, 0, 1.0 / x[0]);
        },
    };
    let mut x = vec![3.0];
    let rep = NewtonSolver::default()
        .solve(&mut sys, &mut x)
        .expect("converges");
    assert!((x[0] - 1.0).abs() < 1e-9, "{x:?} {rep:?}");
}

#[test]
fn residual_scale_is_honoured() {
    // Row 0 is in units 1e6 times larger than row 1; with a scale of 1e6 the
    // tolerance applies to both rows consistently.
    struct Scaled;
    impl NewtonSystem for Scaled {
        fn dim(&self) -> usize {
            2
        }
        fn pattern_key(&self) -> u64 {
            13
        }
        fn pattern(&self, e: &mut Vec<(usize, usize)>) {
            e.extend([(0, 0), (0, 1), (1, 1)]);
        }
        fn eval(
            &mut self,
            x: &[f64],
            r: &mut [f64],
            jac: Option<&mut fbd_solver::JacobianSink<'_>>,
        ) {
            r[0] = 1e6 * (x[0] * x[0] - 2.0 + 0.0 * x[1]);
            r[1] = x[1].exp() - 2.0;
            if let Some(j) = jac {
                j.add(0, 0, 2e6 * x[0]);
                j.add(0, 1, 0.0);
                j.add(1, 1, x[1].exp());
            }
        }
        fn residual_scale(&self, row: usize) -> f64 {
            if row == 0 { 1e6 } else { 1.0 }
        }
    }
    let mut x = vec![1.0, 0.0];
    let rep = NewtonSolver::default()
        .solve(&mut Scaled, &mut x)
        .expect("converges");
    assert!(rep.residual <= 1e-9);
    assert!((x[0] - 2f64.sqrt()).abs() < 1e-9 && (x[1] - 2f64.ln()).abs() < 1e-9);
}

#[test]
fn error_messages_are_one_line() {
    for e in [
        SolverError::Singular { equation: 3 },
        SolverError::Diverged {
            iter: 20,
            residual: 0.5,
        },
        SolverError::NonFinite { iter: 4 },
        SolverError::Abandoned {
            iter: 7,
            residual: 1e-4,
        },
    ] {
        let m = e.to_string();
        assert!(!m.is_empty() && !m.contains('\n'), "{m}");
    }
    assert!(
        SolverError::Diverged {
            iter: 20,
            residual: 0.5
        }
        .to_string()
        .contains("iteration 20")
    );
}

/// Chord steps (`NewtonParams::chord_steps`): along a sequence of nearby
/// problems most steps reuse the kept factorisation, every solve still
/// meets the tolerance on the true residual, and the report counts chord
/// and full steps and factorisations consistently.
#[test]
fn chord_steps_reuse_the_factorisation_and_converge() {
    let root = root10();
    let mut sys = TrigChain::with_root(&root, 1);
    let mut solver = NewtonSolver::new(NewtonParams {
        chord_steps: 6,
        ..NewtonParams::default()
    });
    let mut x = vec![0.0; 10];
    let first = solver.solve(&mut sys, &mut x).expect("converges");
    assert_eq!(
        first.chord_iterations,
        first.iterations - first.factorizations.min(first.iterations)
    );
    let (mut chords, mut fulls, mut lus) = (0, 0, 0);
    for k in 1..=100 {
        let target: Vec<f64> = root.iter().map(|r| r + 0.002 * k as f64).collect();
        sys.retarget(&target);
        let rep = solver.solve(&mut sys, &mut x).expect("converges");
        assert!(rep.residual <= 1e-9, "{rep:?}");
        for (xi, ti) in x.iter().zip(&target) {
            assert!((xi - ti).abs() < 1e-8, "step {k}: {x:?} vs {target:?}");
        }
        assert!(rep.chord_iterations <= rep.iterations);
        // A full step factors once; the step test may add one.
        let full = rep.iterations - rep.chord_iterations;
        assert!(
            rep.factorizations >= full && rep.factorizations <= full + 1,
            "{rep:?}"
        );
        chords += rep.chord_iterations;
        fulls += full;
        lus += rep.factorizations;
    }
    assert!(chords > 3 * fulls, "chord {chords}, full {fulls}");
    assert!(lus < 40, "{lus} factorisations in 100 solves");
}

/// The renewal rule (`NewtonParams::refactor_cost`): when the kept
/// factorisation has grown stale the next solve starts with one; without
/// the rule (cost 0) the same sequence refactors less often.
#[test]
fn the_renewal_rule_refactors_a_stale_factorisation() {
    let root = root10();
    let run = |cost: f64| {
        let mut sys = TrigChain::with_root(&root, 1);
        let mut solver = NewtonSolver::new(NewtonParams {
            chord_steps: 20,
            chord_contraction: 0.9,
            refactor_cost: cost,
            ..NewtonParams::default()
        });
        let mut x = vec![0.0; 10];
        let (mut chords, mut lus) = (0, 0);
        for k in 0..60 {
            let target: Vec<f64> = root.iter().map(|r| r + 0.02 * k as f64).collect();
            sys.retarget(&target);
            let rep = solver.solve(&mut sys, &mut x).expect("converges");
            assert!(rep.residual <= 1e-9);
            chords += rep.chord_iterations;
            lus += rep.factorizations;
        }
        (chords, lus)
    };
    let (chords_off, lus_off) = run(0.0);
    let (chords_on, lus_on) = run(2.0);
    assert!(
        lus_on > lus_off,
        "renewal: {lus_on} vs {lus_off} factorisations"
    );
    assert!(
        chords_on < chords_off,
        "renewal: {chords_on} vs {chords_off} chord steps"
    );
}

#[test]
fn the_pattern_cache_is_bounded_and_evicts_the_least_recently_used() {
    // Three patterns (keys 1, 2, 3; the cubic's tridiagonal pattern at
    // three sizes) through a cache of two: the third evicts the least
    // recently used, which is analysed again when it comes back; every
    // solve converges to the same root as with an unbounded cache.
    let cubic = |n: usize, key: u64| Cubic {
        c: (0..n).map(|i| 1.0 + 0.3 * i as f64).collect(),
        key,
    };
    let solve = |solver: &mut NewtonSolver, n: usize, key: u64| {
        let mut sys = cubic(n, key);
        let mut x = vec![0.0; n];
        solver.solve(&mut sys, &mut x).expect("converges");
        x
    };
    let mut unbounded = NewtonSolver::new(NewtonParams {
        max_patterns: 0,
        ..NewtonParams::default()
    });
    let mut bounded = NewtonSolver::new(NewtonParams {
        max_patterns: 2,
        ..NewtonParams::default()
    });
    for (n, key) in [(5, 1), (6, 2), (5, 1), (7, 3), (6, 2), (5, 1), (7, 3)] {
        let a = solve(&mut unbounded, n, key);
        let b = solve(&mut bounded, n, key);
        for (p, q) in a.iter().zip(&b) {
            assert!((p - q).abs() <= 1e-12, "key {key}: {a:?} vs {b:?}");
        }
        assert!(bounded.cached_patterns() <= 2);
    }
    assert_eq!(unbounded.cached_patterns(), 3);
    assert_eq!(unbounded.symbolic_factorizations(), 3);
    assert_eq!(unbounded.evicted_patterns(), 0);
    // 1, 2 | 1 hit | 3 evicts 2 | 2 evicts 1 | 1 evicts 3 | 3 evicts 2.
    assert_eq!(bounded.evicted_patterns(), 4);
    assert_eq!(bounded.symbolic_factorizations(), 6);
}

/// The linear complementarity problem `min(x, A·x + b) = 0` (two
/// unknowns), semismooth like the contact rows: row `i` is `x_i` where
/// `x_i ≤ y_i` and `y_i = (A·x + b)_i` beyond.
struct Lcp {
    a: [[f64; 2]; 2],
    b: [f64; 2],
}

impl Lcp {
    fn y(&self, x: &[f64]) -> [f64; 2] {
        std::array::from_fn(|i| self.a[i][0] * x[0] + self.a[i][1] * x[1] + self.b[i])
    }
}

impl NewtonSystem for Lcp {
    fn dim(&self) -> usize {
        2
    }
    fn pattern_key(&self) -> u64 {
        0
    }
    fn pattern(&self, e: &mut Vec<(usize, usize)>) {
        e.extend([(0, 0), (0, 1), (1, 0), (1, 1)]);
    }
    fn eval(&mut self, x: &[f64], r: &mut [f64], jac: Option<&mut fbd_solver::JacobianSink<'_>>) {
        let y = self.y(x);
        let mut jac = jac;
        for i in 0..2 {
            let identity = x[i] <= y[i];
            r[i] = if identity { x[i] } else { y[i] };
            if let Some(j) = jac.as_deref_mut() {
                for k in 0..2 {
                    let v = if identity {
                        f64::from(u8::from(i == k))
                    } else {
                        self.a[i][k]
                    };
                    j.add(i, k, v);
                }
            }
        }
    }
}

/// An [`Lcp`] whose damped Newton iteration from [`KINKED_START`] stalls at
/// a kink.
fn kinked_lcp() -> Lcp {
    Lcp {
        a: [
            [0.13787289283264367, -0.4426848543133972],
            [1.017486474381074, -1.3066112595978296],
        ],
        b: [-0.4116867936057472, 1.827518567008105],
    }
}

/// The start of [`kinked_lcp`]'s stalling iteration.
const KINKED_START: [f64; 2] = [-0.1430663804640684, 1.337560930857414];

/// A semismooth system whose damped Newton iteration stalls at a kink (the
/// line search finds no decrease below a step of 1/256 after two steps cut
/// to 1/16 or less) converges with the watchdog's whole steps, to the
/// complementarity solution.
#[test]
fn the_watchdog_takes_a_crawl_across_its_kink() {
    let (lcp, x0) = (kinked_lcp, KINKED_START);
    let mut x = x0.to_vec();
    let plain = NewtonSolver::default().solve(&mut lcp(), &mut x);
    assert!(
        matches!(plain, Err(SolverError::Diverged { .. })),
        "{plain:?}"
    );
    let mut x = x0.to_vec();
    let params = NewtonParams {
        watchdog: 5,
        ..NewtonParams::default()
    };
    let rep = NewtonSolver::new(params)
        .solve(&mut lcp(), &mut x)
        .expect("the watchdog crosses the kink");
    assert!(rep.iterations <= 10, "{rep:?}");
    let y = lcp().y(&x);
    for i in 0..2 {
        assert!(x[i] >= -1e-9 && y[i] >= -1e-9, "x {x:?}, y {y:?}");
        assert!(x[i].min(y[i]).abs() <= 1e-9, "x {x:?}, y {y:?}");
    }
}

/// [`Lcp`] that gives up every crawl its watchdog returns from, keeping
/// the iterate and residual it was handed.
struct GivingUp {
    lcp: Lcp,
    handed: Option<(Vec<f64>, f64)>,
}

impl NewtonSystem for GivingUp {
    fn dim(&self) -> usize {
        self.lcp.dim()
    }
    fn pattern_key(&self) -> u64 {
        self.lcp.pattern_key()
    }
    fn pattern(&self, e: &mut Vec<(usize, usize)>) {
        self.lcp.pattern(e)
    }
    fn eval(&mut self, x: &[f64], r: &mut [f64], jac: Option<&mut fbd_solver::JacobianSink<'_>>) {
        self.lcp.eval(x, r, jac)
    }
    fn abandon_crawl(&mut self, x: &[f64], residual: f64) -> bool {
        self.handed = Some((x.to_vec(), residual));
        true
    }
}

/// A crawl whose watchdog returns to its kept iterate is given up when the
/// system asks (`NewtonSystem::abandon_crawl`): the solve returns
/// `Abandoned` with the unknowns at that kept iterate, whose residual is
/// the one handed to the system; a system that does not ask goes on with
/// the damped step (here to the line search's failure, one whole step a
/// watch being too few for this kink).
#[test]
fn a_crawl_is_given_up_at_its_kept_iterate_when_the_system_asks() {
    let (lcp, x0) = (kinked_lcp, KINKED_START);
    // One whole step a watch: too few to cross this kink.
    let params = NewtonParams {
        watchdog: 1,
        max_iterations: 100,
        ..NewtonParams::default()
    };
    let mut sys = GivingUp {
        lcp: lcp(),
        handed: None,
    };
    let mut x = x0.to_vec();
    let out = NewtonSolver::new(params).solve(&mut sys, &mut x);
    let Err(SolverError::Abandoned { residual, .. }) = out else {
        panic!("not given up: {out:?}");
    };
    let (kept, handed) = sys.handed.expect("the system was asked");
    assert_eq!(x, kept, "the unknowns hold the kept iterate");
    assert_eq!(residual, handed);
    let mut r = [0.0; 2];
    lcp().eval(&x, &mut r, None);
    assert_eq!(residual, r[0].abs().max(r[1].abs()));
    assert!(residual > NewtonParams::default().residual_tol);
    // Not asked to give up, the same iteration goes on past that point.
    let mut x = x0.to_vec();
    let out = NewtonSolver::new(params).solve(&mut lcp(), &mut x);
    assert!(
        matches!(out, Err(SolverError::Diverged { iter, .. }) if iter > 0),
        "{out:?}"
    );
    assert_ne!(x, kept);
}

/// `NewtonSolver::steps_taken` counts every step applied to the unknowns
/// (`chord_steps_taken` its chord steps): a converged solve's
/// `NewtonReport::iterations`, and the steps of a solve that failed — here
/// one cut off by the iteration limit after its chord steps — which no
/// report carries.
#[test]
fn steps_taken_counts_the_steps_of_failed_solves_too() {
    let root = root10();
    let mut sys = TrigChain::with_root(&root, 1);
    let params = NewtonParams {
        chord_steps: 6,
        ..NewtonParams::default()
    };
    let mut solver = NewtonSolver::new(params);
    let mut x = vec![0.0; 10];
    let first = solver.solve(&mut sys, &mut x).expect("converges");
    assert_eq!(solver.steps_taken(), first.iterations as u64);
    assert_eq!(solver.chord_steps_taken(), first.chord_iterations as u64);
    // A far target, one full step allowed: the kept factorisation's chord
    // steps, then the full step, then the limit.
    let far: Vec<f64> = root.iter().map(|r| r + 3.0).collect();
    sys.retarget(&far);
    solver.params_mut().max_iterations = 1;
    let before = (solver.steps_taken(), solver.chord_steps_taken());
    let err = solver.solve(&mut sys, &mut x).unwrap_err();
    let SolverError::Diverged { iter, .. } = err else {
        panic!("{err}");
    };
    assert_eq!(iter, 1, "one full step");
    let failed = solver.steps_taken() - before.0;
    let chords = solver.chord_steps_taken() - before.1;
    assert!(chords >= 1, "the kept factorisation was tried: {chords}");
    assert_eq!(
        failed,
        iter as u64 + chords,
        "every step of the failed solve"
    );
    // Converging from there adds its report's steps.
    solver.params_mut().max_iterations = 20;
    let before = solver.steps_taken();
    let rep = solver.solve(&mut sys, &mut x).expect("converges");
    assert_eq!(solver.steps_taken() - before, rep.iterations as u64);
}

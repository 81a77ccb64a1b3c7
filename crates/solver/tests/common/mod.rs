//! Test systems shared by the solver's integration tests.
#![allow(dead_code)]

use fbd_solver::{JacobianSink, NewtonSystem};

/// Residual max-norms recorded at every Jacobian evaluation (i.e. at every
/// Newton iterate), without allocating.
#[derive(Debug, Clone, Copy)]
pub struct History {
    pub norms: [f64; 64],
    pub len: usize,
}

impl History {
    pub const fn new() -> Self {
        Self {
            norms: [0.0; 64],
            len: 0,
        }
    }
    pub fn clear(&mut self) {
        self.len = 0;
    }
    pub fn push(&mut self, r: &[f64]) {
        if self.len < self.norms.len() {
            self.norms[self.len] = r.iter().fold(0.0f64, |m, v| m.max(v.abs()));
            self.len += 1;
        }
    }
    pub fn as_slice(&self) -> &[f64] {
        &self.norms[..self.len]
    }
}

/// A chain of coupled trigonometric equations with a known root:
///
/// `f_i(x) = 2 x_i + sin x_i + 0.5 cos x_{i-1} − 0.4 sin x_{i+1} + 0.1 x_i x_{i+1}`
/// and `r_i = f_i(x) − f_i(x*)`, with tridiagonal Jacobian pattern.
#[derive(Debug, Clone)]
pub struct TrigChain {
    pub n: usize,
    pub key: u64,
    pub b: Vec<f64>,
    pub history: History,
}

impl TrigChain {
    pub fn f(x: &[f64], out: &mut [f64]) {
        let n = x.len();
        for i in 0..n {
            let mut v = 2.0 * x[i] + x[i].sin();
            if i > 0 {
                v += 0.5 * x[i - 1].cos();
            }
            if i + 1 < n {
                v += -0.4 * x[i + 1].sin() + 0.1 * x[i] * x[i + 1];
            }
            out[i] = v;
        }
    }

    pub fn with_root(root: &[f64], key: u64) -> Self {
        let mut b = vec![0.0; root.len()];
        Self::f(root, &mut b);
        Self {
            n: root.len(),
            key,
            b,
            history: History::new(),
        }
    }

    /// Re-targets the system to a new root (same pattern), without allocating.
    pub fn retarget(&mut self, root: &[f64]) {
        Self::f(root, &mut self.b);
    }

    pub fn jac(x: &[f64], i: usize, j: usize) -> f64 {
        let n = x.len();
        if j == i {
            let mut v = 2.0 + x[i].cos();
            if i + 1 < n {
                v += 0.1 * x[i + 1];
            }
            v
        } else if j + 1 == i {
            -0.5 * x[j].sin()
        } else if j == i + 1 {
            -0.4 * x[j].cos() + 0.1 * x[i]
        } else {
            0.0
        }
    }
}

impl NewtonSystem for TrigChain {
    fn dim(&self) -> usize {
        self.n
    }
    fn pattern_key(&self) -> u64 {
        self.key
    }
    fn pattern(&self, entries: &mut Vec<(usize, usize)>) {
        for i in 0..self.n {
            entries.push((i, i));
            if i > 0 {
                entries.push((i, i - 1));
            }
            if i + 1 < self.n {
                entries.push((i, i + 1));
            }
        }
    }
    fn eval(&mut self, x: &[f64], r: &mut [f64], jac: Option<&mut JacobianSink<'_>>) {
        Self::f(x, r);
        for (ri, bi) in r.iter_mut().zip(&self.b) {
            *ri -= bi;
        }
        if let Some(jac) = jac {
            self.history.push(r);
            for i in 0..self.n {
                let lo = i.saturating_sub(1);
                let hi = (i + 1).min(self.n - 1);
                for j in lo..=hi {
                    jac.add(i, j, Self::jac(x, i, j));
                }
            }
        }
    }
}

/// `r_i = x_i³ + 3 x_i − x_{i−1} − x_{i+1} − c_i` (a second, different
/// tridiagonal pattern when `n` differs; distinct key).
#[derive(Debug, Clone)]
pub struct Cubic {
    pub c: Vec<f64>,
    pub key: u64,
}

impl NewtonSystem for Cubic {
    fn dim(&self) -> usize {
        self.c.len()
    }
    fn pattern_key(&self) -> u64 {
        self.key
    }
    fn pattern(&self, entries: &mut Vec<(usize, usize)>) {
        let n = self.c.len();
        for i in 0..n {
            entries.push((i, i));
            if i > 0 {
                entries.push((i, i - 1));
                entries.push((i - 1, i));
            }
        }
    }
    fn eval(&mut self, x: &[f64], r: &mut [f64], mut jac: Option<&mut JacobianSink<'_>>) {
        let n = self.c.len();
        for i in 0..n {
            let mut v = x[i] * x[i] * x[i] + 3.0 * x[i] - self.c[i];
            if i > 0 {
                v -= x[i - 1];
            }
            if i + 1 < n {
                v -= x[i + 1];
            }
            r[i] = v;
            if let Some(jac) = jac.as_deref_mut() {
                jac.add(i, i, 3.0 * x[i] * x[i] + 3.0);
                if i > 0 {
                    jac.add(i, i - 1, -1.0);
                }
                if i + 1 < n {
                    jac.add(i, i + 1, -1.0);
                }
            }
        }
    }
}

/// A small system given by closures over a 2- or 3-vector, for error cases.
pub struct Small<F> {
    pub n: usize,
    pub key: u64,
    pub entries: Vec<(usize, usize)>,
    /// `f(x, r, jac)`; `jac` receives `(row, col, value)`.
    pub f: F,
}

impl<F> NewtonSystem for Small<F>
where
    F: FnMut(&[f64], &mut [f64], &mut dyn FnMut(usize, usize, f64)),
{
    fn dim(&self) -> usize {
        self.n
    }
    fn pattern_key(&self) -> u64 {
        self.key
    }
    fn pattern(&self, entries: &mut Vec<(usize, usize)>) {
        entries.extend_from_slice(&self.entries);
    }
    fn eval(&mut self, x: &[f64], r: &mut [f64], jac: Option<&mut JacobianSink<'_>>) {
        match jac {
            Some(jac) => (self.f)(x, r, &mut |i, j, v| jac.add(i, j, v)),
            None => (self.f)(x, r, &mut |_, _, _| {}),
        }
    }
}

/// Linear `r_i = Σ_j a_ij x_j − b_i` on an *arrow* pattern (diagonal plus a
/// dense row 0 and column 0). With a strong diagonal, partial pivoting stays
/// on the diagonal and `L`/`U` have no fill; with `weak_diagonal` it must
/// pivot on row 0 early, which fills `L`/`U` (same pattern, more storage:
/// faer 0.24.4's simplicial LU grows its vectors for it).
#[derive(Debug, Clone)]
pub struct Pivoting {
    pub n: usize,
    pub entries: Vec<(usize, usize)>,
    pub weak_diagonal: bool,
    pub b: Vec<f64>,
}

impl Pivoting {
    pub fn new(n: usize) -> Self {
        let mut entries = Vec::new();
        for i in 0..n {
            entries.push((i, i));
            if i > 0 {
                entries.push((0, i));
                entries.push((i, 0));
            }
        }
        Self {
            n,
            entries,
            weak_diagonal: false,
            b: (0..n).map(|i| (i as f64 * 0.37).sin()).collect(),
        }
    }

    pub fn a(&self, i: usize, j: usize) -> f64 {
        let h = 1.0 + 0.01 * (i + j) as f64;
        match (i == j, self.weak_diagonal) {
            (true, false) => 100.0,
            (true, true) => 1e-3,
            (false, _) => h,
        }
    }
}

impl NewtonSystem for Pivoting {
    fn dim(&self) -> usize {
        self.n
    }
    fn pattern_key(&self) -> u64 {
        0x0917_0000 + self.n as u64
    }
    fn pattern(&self, entries: &mut Vec<(usize, usize)>) {
        entries.extend_from_slice(&self.entries);
    }
    fn eval(&mut self, x: &[f64], r: &mut [f64], mut jac: Option<&mut JacobianSink<'_>>) {
        for (ri, bi) in r.iter_mut().zip(&self.b) {
            *ri = -bi;
        }
        for k in 0..self.entries.len() {
            let (i, j) = self.entries[k];
            let a = self.a(i, j);
            r[i] += a * x[j];
            if let Some(jac) = jac.as_deref_mut() {
                jac.add(i, j, a);
            }
        }
    }
}

//! A height map `y = ϱ(x, z)` sampled on a regular grid (a heightfield
//! file or a generated terrain), interpolated by bicubic Hermite patches.
//!
//! **Layout.** `nrow × ncol` heights; row `i` lies at
//! `x = x_min + i·Δx` and column `j` at `z = z_min + j·Δz`: rows run along
//! +X, columns along +Z (`Δx = x_extent/(nrow − 1)`,
//! `Δz = z_extent/(ncol − 1)`).
//!
//! **Interpolation.** In every cell the height is the bicubic Hermite
//! patch through the four corner heights `ϱ`, slopes `ϱx`, `ϱz` and twists
//! `ϱxz`, the node derivatives taken by central differences of the samples
//! (one-sided on the border). Neighbouring patches share their edge's
//! values and first derivatives, so the surface is C¹: its normal is
//! continuous (the Newton iteration and the friction cone need it). Every
//! difference is exact for a plane and the Hermite basis reproduces the
//! cubics, so a grid sampled from a plane *is* that plane. Gradient and
//! Hessian are the analytic derivatives of the patch.
//!
//! **Rounding.** A feature sharper than one cell (a stair's riser, a
//! stone's edge) is rounded over one cell: its radius is the grid spacing.
//!
//! **Edges.** Outside the grid the height of the nearest border point
//! continues horizontally (coordinates clamped to the grid): the surface
//! stays continuous, and its slope across the border drops to zero there
//! (a kink where the border slopes: keep the robot inside the grid).

/// A height map on a regular grid (see the module docs).
#[derive(Clone, Debug, PartialEq)]
pub struct HeightGrid {
    nrow: usize,
    ncol: usize,
    x_min: f64,
    z_min: f64,
    dx: f64,
    dz: f64,
    /// Heights, row-major (`[i·ncol + j]`).
    h: Vec<f64>,
    /// Node derivatives `(ϱx·Δx, ϱz·Δz, ϱxz·Δx·Δz)`, row-major.
    d: Vec<[f64; 3]>,
}

/// What is wrong with a grid's data (the caller names the file and key).
#[derive(Clone, Debug, PartialEq)]
pub enum GridIssue {
    /// Fewer than 2 rows or 2 columns.
    TooSmall {
        /// Rows.
        nrow: usize,
        /// Columns.
        ncol: usize,
    },
    /// `heights.len() ≠ nrow·ncol`.
    WrongSize {
        /// Expected values.
        expected: usize,
        /// Values given.
        got: usize,
    },
    /// A height is NaN or infinite.
    NotFinite {
        /// Row.
        row: usize,
        /// Column.
        col: usize,
    },
    /// An extent is not positive and finite.
    Extent {
        /// `0` for x, `1` for z.
        axis: usize,
        /// The value.
        got: f64,
    },
}

impl std::fmt::Display for GridIssue {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            GridIssue::TooSmall { nrow, ncol } => {
                write!(f, "a {nrow}×{ncol} grid is too small (at least 2×2)")
            }
            GridIssue::WrongSize { expected, got } => {
                write!(f, "holds {got} heights, expected {expected}")
            }
            GridIssue::NotFinite { row, col } => {
                write!(f, "height at row {row}, column {col} is not finite")
            }
            GridIssue::Extent { axis, got } => write!(
                f,
                "{} extent {got} must be positive and finite",
                ["x", "z"][*axis]
            ),
        }
    }
}

/// Hermite basis on `[0, 1]`: values `(h00, h10, h01, h11)` and their
/// first and second derivatives.
#[inline]
fn basis(t: f64) -> [[f64; 4]; 3] {
    let t2 = t * t;
    let t3 = t2 * t;
    [
        [
            2.0 * t3 - 3.0 * t2 + 1.0,
            t3 - 2.0 * t2 + t,
            -2.0 * t3 + 3.0 * t2,
            t3 - t2,
        ],
        [
            6.0 * t2 - 6.0 * t,
            3.0 * t2 - 4.0 * t + 1.0,
            -6.0 * t2 + 6.0 * t,
            3.0 * t2 - 2.0 * t,
        ],
        [
            12.0 * t - 6.0,
            6.0 * t - 4.0,
            -12.0 * t + 6.0,
            6.0 * t - 2.0,
        ],
    ]
}

impl HeightGrid {
    /// A grid of `nrow × ncol` `heights` (row-major, rows along +X) over
    /// `size = [x_extent, z_extent]` centred on `center = [x, z]`.
    pub fn new(
        nrow: usize,
        ncol: usize,
        heights: Vec<f64>,
        size: [f64; 2],
        center: [f64; 2],
    ) -> Result<Self, GridIssue> {
        if nrow < 2 || ncol < 2 {
            return Err(GridIssue::TooSmall { nrow, ncol });
        }
        if heights.len() != nrow * ncol {
            return Err(GridIssue::WrongSize {
                expected: nrow * ncol,
                got: heights.len(),
            });
        }
        for (axis, &e) in size.iter().enumerate() {
            if !(e.is_finite() && e > 0.0) {
                return Err(GridIssue::Extent { axis, got: e });
            }
        }
        if let Some(k) = heights.iter().position(|h| !h.is_finite()) {
            return Err(GridIssue::NotFinite {
                row: k / ncol,
                col: k % ncol,
            });
        }
        let mut g = Self {
            nrow,
            ncol,
            x_min: center[0] - 0.5 * size[0],
            z_min: center[1] - 0.5 * size[1],
            dx: size[0] / (nrow - 1) as f64,
            dz: size[1] / (ncol - 1) as f64,
            h: heights,
            d: Vec::new(),
        };
        g.derivatives();
        Ok(g)
    }

    /// A grid sampling `f(x, z)` at `nrow × ncol` nodes over `size` centred
    /// on `center`.
    pub fn sample(
        nrow: usize,
        ncol: usize,
        size: [f64; 2],
        center: [f64; 2],
        f: impl Fn(f64, f64) -> f64,
    ) -> Result<Self, GridIssue> {
        let (x0, z0) = (center[0] - 0.5 * size[0], center[1] - 0.5 * size[1]);
        let (dx, dz) = (
            size[0] / (nrow.max(2) - 1) as f64,
            size[1] / (ncol.max(2) - 1) as f64,
        );
        let mut h = Vec::with_capacity(nrow * ncol);
        for i in 0..nrow {
            for j in 0..ncol {
                h.push(f(x0 + i as f64 * dx, z0 + j as f64 * dz));
            }
        }
        Self::new(nrow, ncol, h, size, center)
    }

    /// Node derivatives by central differences (one-sided on the border),
    /// scaled by the spacing.
    fn derivatives(&mut self) {
        let (nr, nc) = (self.nrow, self.ncol);
        let h = &self.h;
        // Difference of `v` along an index, in units of the spacing.
        let diff = |lo: f64, hi: f64, span: usize| (hi - lo) / span as f64;
        let at = |i: usize, j: usize| h[i * nc + j];
        let dx_of = |i: usize, j: usize| {
            let (a, b) = (i.saturating_sub(1), (i + 1).min(nr - 1));
            diff(at(a, j), at(b, j), b - a)
        };
        let dz_of = |i: usize, j: usize| {
            let (a, b) = (j.saturating_sub(1), (j + 1).min(nc - 1));
            diff(at(i, a), at(i, b), b - a)
        };
        let mut d = Vec::with_capacity(nr * nc);
        for i in 0..nr {
            for j in 0..nc {
                let (a, b) = (i.saturating_sub(1), (i + 1).min(nr - 1));
                let twist = diff(dz_of(a, j), dz_of(b, j), b - a);
                d.push([dx_of(i, j), dz_of(i, j), twist]);
            }
        }
        self.d = d;
    }

    /// Rows (along +X).
    pub fn nrow(&self) -> usize {
        self.nrow
    }

    /// Columns (along +Z).
    pub fn ncol(&self) -> usize {
        self.ncol
    }

    /// The sample heights, row-major.
    pub fn heights(&self) -> &[f64] {
        &self.h
    }

    /// `[x_min, x_max, z_min, z_max]` (m).
    pub fn bounds(&self) -> [f64; 4] {
        [
            self.x_min,
            self.x_min + self.dx * (self.nrow - 1) as f64,
            self.z_min,
            self.z_min + self.dz * (self.ncol - 1) as f64,
        ]
    }

    /// Grid spacing `[Δx, Δz]` (m).
    pub fn spacing(&self) -> [f64; 2] {
        [self.dx, self.dz]
    }

    /// Lowest and highest sample (m).
    pub fn range(&self) -> [f64; 2] {
        self.h
            .iter()
            .fold([f64::INFINITY, f64::NEG_INFINITY], |[lo, hi], &v| {
                [lo.min(v), hi.max(v)]
            })
    }

    /// Cell index and local coordinate in `[0, 1]` along one axis;
    /// `clamped` when the coordinate lay outside the grid.
    #[inline]
    fn locate(v: f64, v_min: f64, step: f64, n: usize) -> (usize, f64, bool) {
        let s = (v - v_min) / step;
        let last = (n - 1) as f64;
        let (s, clamped) = if s < 0.0 {
            (0.0, true)
        } else if s > last {
            (last, true)
        } else {
            (s, false)
        };
        let i = (s.floor() as usize).min(n - 2);
        (i, s - i as f64, clamped)
    }

    /// `(ϱ, [ϱx, ϱz], [ϱxx, ϱxz, ϱzz])` at `(x, z)`.
    pub fn eval(&self, x: f64, z: f64) -> (f64, [f64; 2], [f64; 3]) {
        let (i, u, cx) = Self::locate(x, self.x_min, self.dx, self.nrow);
        let (j, v, cz) = Self::locate(z, self.z_min, self.dz, self.ncol);
        let (bu, bv) = (basis(u), basis(v));
        let nc = self.ncol;
        let mut out = [0.0; 6]; // f, fu, fv, fuu, fuv, fvv
        for (a, ia) in [(0usize, i), (1, i + 1)] {
            for (b, jb) in [(0usize, j), (1, j + 1)] {
                let k = ia * nc + jb;
                let (f, [fx, fz, fxz]) = (self.h[k], self.d[k]);
                // Basis index: value 0/2 (corner 0/1), slope 1/3.
                let (pv, ps) = (2 * a, 2 * a + 1);
                let (qv, qs) = (2 * b, 2 * b + 1);
                let w = |du: usize, dv: usize| {
                    f * bu[du][pv] * bv[dv][qv]
                        + fx * bu[du][ps] * bv[dv][qv]
                        + fz * bu[du][pv] * bv[dv][qs]
                        + fxz * bu[du][ps] * bv[dv][qs]
                };
                out[0] += w(0, 0);
                out[1] += w(1, 0);
                out[2] += w(0, 1);
                out[3] += w(2, 0);
                out[4] += w(1, 1);
                out[5] += w(0, 2);
            }
        }
        let (kx, kz) = (if cx { 0.0 } else { 1.0 }, if cz { 0.0 } else { 1.0 });
        let (ix, iz) = (1.0 / self.dx, 1.0 / self.dz);
        (
            out[0],
            [kx * out[1] * ix, kz * out[2] * iz],
            [
                kx * out[3] * ix * ix,
                kx * kz * out[4] * ix * iz,
                kz * out[5] * iz * iz,
            ],
        )
    }

    /// `ϱ(x, z)` (m).
    #[inline]
    pub fn height(&self, x: f64, z: f64) -> f64 {
        self.eval(x, z).0
    }

    /// The grid smoothed by three passes of a box filter of half-width
    /// `radius` (m) along each axis (an approximate Gaussian of standard
    /// deviation `radius`): the ground a walking body follows.
    pub fn smoothed(&self, radius: f64) -> Self {
        let (nr, nc) = (self.nrow, self.ncol);
        let wr = (radius / self.dx).round().max(0.0) as usize;
        let wc = (radius / self.dz).round().max(0.0) as usize;
        let mut h = self.h.clone();
        let mut tmp = vec![0.0; h.len()];
        for _ in 0..3 {
            for i in 0..nr {
                for j in 0..nc {
                    let (a, b) = (i.saturating_sub(wr), (i + wr).min(nr - 1));
                    let s: f64 = (a..=b).map(|r| h[r * nc + j]).sum();
                    tmp[i * nc + j] = s / (b - a + 1) as f64;
                }
            }
            for i in 0..nr {
                for j in 0..nc {
                    let (a, b) = (j.saturating_sub(wc), (j + wc).min(nc - 1));
                    let s: f64 = (a..=b).map(|c| tmp[i * nc + c]).sum();
                    h[i * nc + j] = s / (b - a + 1) as f64;
                }
            }
        }
        let mut g = Self {
            h,
            d: Vec::new(),
            ..self.clone()
        };
        g.derivatives();
        g
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn plane(x: f64, z: f64) -> f64 {
        0.1 + 0.3 * x - 0.2 * z
    }

    #[test]
    fn a_plane_is_reproduced_exactly() {
        let g = HeightGrid::sample(7, 5, [1.2, 0.8], [0.1, -0.2], plane).unwrap();
        for &(x, z) in &[(0.0, 0.0), (-0.43, 0.17), (0.6, -0.55), (0.1234, -0.3)] {
            let (h, [gx, gz], [hxx, hxz, hzz]) = g.eval(x, z);
            assert!((h - plane(x, z)).abs() < 1e-14, "{h} vs {}", plane(x, z));
            assert!((gx - 0.3).abs() < 1e-13 && (gz + 0.2).abs() < 1e-13);
            assert!(hxx.abs() < 1e-12 && hxz.abs() < 1e-12 && hzz.abs() < 1e-12);
        }
    }

    #[test]
    fn derivatives_match_differences_and_normal_is_continuous() {
        let f = |x: f64, z: f64| 0.03 * (5.0 * x).sin() * (3.0 * z + 0.4).cos() + 0.1 * x * z;
        let g = HeightGrid::sample(21, 17, [2.0, 1.6], [0.0, 0.0], f).unwrap();
        let e = 1e-6;
        for &(x, z) in &[(0.013, 0.021), (-0.52, 0.33), (0.71, -0.61)] {
            let (_, [gx, gz], [hxx, hxz, hzz]) = g.eval(x, z);
            let fx = (g.height(x + e, z) - g.height(x - e, z)) / (2.0 * e);
            let fz = (g.height(x, z + e) - g.height(x, z - e)) / (2.0 * e);
            assert!((gx - fx).abs() < 1e-7 && (gz - fz).abs() < 1e-7);
            let gxx = (g.eval(x + e, z).1[0] - g.eval(x - e, z).1[0]) / (2.0 * e);
            let gxz = (g.eval(x, z + e).1[0] - g.eval(x, z - e).1[0]) / (2.0 * e);
            let gzz = (g.eval(x, z + e).1[1] - g.eval(x, z - e).1[1]) / (2.0 * e);
            assert!(
                (hxx - gxx).abs() < 1e-5 && (hxz - gxz).abs() < 1e-5,
                "{hxx} {gxx} {hxz} {gxz}"
            );
            assert!((hzz - gzz).abs() < 1e-5);
        }
        // Across a cell edge (x = 0.0 + k·0.1) the gradient is continuous.
        let xe = -1.0 + 0.1 * 7.0;
        let (a, b) = (g.eval(xe - 1e-12, 0.2).1, g.eval(xe + 1e-12, 0.2).1);
        assert!((a[0] - b[0]).abs() < 1e-9 && (a[1] - b[1]).abs() < 1e-9);
        // It interpolates the samples.
        assert!((g.height(-1.0 + 0.1 * 3.0, -0.8 + 0.1 * 4.0) - f(-0.7, -0.4)).abs() < 1e-12);
    }

    #[test]
    fn outside_the_grid_the_border_continues_flat() {
        let g = HeightGrid::sample(5, 5, [1.0, 1.0], [0.0, 0.0], plane).unwrap();
        assert!((g.height(3.0, 0.1) - plane(0.5, 0.1)).abs() < 1e-14);
        assert_eq!(g.eval(3.0, 0.1).1[0], 0.0);
        assert!((g.eval(3.0, 0.1).1[1] + 0.2).abs() < 1e-13);
    }

    #[test]
    fn bad_grids_are_refused() {
        assert_eq!(
            HeightGrid::new(1, 3, vec![0.0; 3], [1.0, 1.0], [0.0, 0.0]),
            Err(GridIssue::TooSmall { nrow: 1, ncol: 3 })
        );
        assert!(matches!(
            HeightGrid::new(2, 3, vec![0.0; 5], [1.0, 1.0], [0.0, 0.0]),
            Err(GridIssue::WrongSize { .. })
        ));
        let mut h = vec![0.0; 6];
        h[4] = f64::NAN;
        assert_eq!(
            HeightGrid::new(2, 3, h, [1.0, 1.0], [0.0, 0.0]),
            Err(GridIssue::NotFinite { row: 1, col: 1 })
        );
        assert!(matches!(
            HeightGrid::new(2, 2, vec![0.0; 4], [0.0, 1.0], [0.0, 0.0]),
            Err(GridIssue::Extent { axis: 0, .. })
        ));
    }
}

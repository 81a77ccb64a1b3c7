//! Generated terrains, sampled on a [`HeightGrid`]: smooth random ground,
//! stairs, stepping stones, pyramids and 2D sines. Every generator is a
//! pure function of its parameters (the random ones of their `seed`, through
//! SplitMix64, whose output is fixed by its definition and so cannot change
//! with a dependency's version): the same parameters give the same grid,
//! bit for bit.
//!
//! Sharp features (a riser, a stone's edge, a pyramid's ridge) are rounded
//! with the radius `edge_radius`: a step of height `h` becomes the C¹ ramp
//! `h·(3t² − 2t³)`, `t = (d + r)/(2r)` over `|d| ≤ r` of the signed distance
//! `d` to the edge, and a ridge `|u|` becomes `√(u² + r²) − r`. The grid then
//! interpolates the samples (its own rounding is one cell: keep
//! `resolution ≤ edge_radius`).

use crate::grid::{GridIssue, HeightGrid};

/// The generated kinds and their parameters (m; angles in radians).
#[derive(Clone, Debug, PartialEq)]
pub enum Generator {
    /// Smooth random ground: 64 cosine waves of wavelengths between 0.7 and
    /// 1.4 `wavelength`, random directions and phases, scaled so that the
    /// grid's heights span exactly `height ± amplitude`.
    Random {
        /// Half the peak-to-peak height (m).
        amplitude: f64,
        /// Typical wavelength (m).
        wavelength: f64,
        /// Seed.
        seed: u64,
    },
    /// A staircase climbing along `heading` (rad from +X towards −Z, as a
    /// robot's yaw): `steps` risers of height `riser`, `tread` apart, the
    /// first through `origin`; flat below the first and above the last.
    Stairs {
        /// Run of each step (m).
        tread: f64,
        /// Rise of each step (m; negative descends).
        riser: f64,
        /// Climbing direction (rad).
        heading: f64,
        /// Number of risers.
        steps: u32,
        /// A point `[x, z]` of the first riser.
        origin: [f64; 2],
    },
    /// Square stepping stones of side `stone` on a lattice of pitch
    /// `stone + gap` centred on the grid's centre; their tops at `height`
    /// (plus a random offset within `±amplitude` per stone), the ground
    /// between them `depth` below `height`.
    Stones {
        /// Side of a stone (m).
        stone: f64,
        /// Gap between stones (m).
        gap: f64,
        /// Depth of the gaps (m).
        depth: f64,
        /// Random variation of the tops (m).
        amplitude: f64,
        /// Seed.
        seed: u64,
    },
    /// Square pyramids of height `amplitude` on a lattice of pitch
    /// `wavelength` centred on the grid's centre.
    Pyramids {
        /// Height of a pyramid (m; negative: pits).
        amplitude: f64,
        /// Side of a pyramid's base (m).
        wavelength: f64,
    },
    /// `amplitude·sin(2πx/λ)·sin(2πz/λ)` (an egg-crate).
    Sines {
        /// Amplitude (m).
        amplitude: f64,
        /// Wavelength λ along X and Z (m).
        wavelength: f64,
    },
}

/// SplitMix64 (Steele, Lea, Flood 2014): a tiny deterministic generator
/// whose stream is fixed by its definition (the generated terrains and the
/// random sweeps of `fbd sweep` draw from it).
#[derive(Clone, Debug)]
pub struct SplitMix(pub u64);

impl SplitMix {
    /// The next 64 random bits.
    pub fn next_u64(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in `[0, 1)`.
    pub fn unit(&mut self) -> f64 {
        (self.next_u64() >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The C¹ step `0 → 1` over `d ∈ [−r, r]` (a Heaviside step for `r = 0`).
#[inline]
pub fn ramp(d: f64, r: f64) -> f64 {
    if d <= -r {
        0.0
    } else if d >= r {
        1.0
    } else {
        let t = (d + r) / (2.0 * r);
        t * t * (3.0 - 2.0 * t)
    }
}

/// `|u|` rounded with radius `r`: `√(u² + r²) − r`.
#[inline]
fn soft_abs(u: f64, r: f64) -> f64 {
    (u * u + r * r).sqrt() - r
}

/// `u` wrapped into `[−p/2, p/2)`.
#[inline]
fn wrap(u: f64, p: f64) -> f64 {
    u - p * (u / p).round()
}

/// Sampling of a generated terrain.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sampling {
    /// `[x_extent, z_extent]` (m).
    pub size: [f64; 2],
    /// Centre `[x, z]` (m).
    pub center: [f64; 2],
    /// Grid spacing (m).
    pub resolution: f64,
    /// Rounding radius of sharp features (m).
    pub edge_radius: f64,
    /// Reference height (m).
    pub height: f64,
}

impl Generator {
    /// The terrain sampled on a grid.
    pub fn grid(&self, s: &Sampling) -> Result<HeightGrid, GridIssue> {
        for (axis, &e) in s.size.iter().enumerate() {
            if !(e.is_finite() && e > 0.0) {
                return Err(GridIssue::Extent { axis, got: e });
            }
        }
        let n = |e: f64| (e / s.resolution).round().max(1.0) as usize + 1;
        let (nrow, ncol) = (n(s.size[0]), n(s.size[1]));
        let (r, h0, [cx, cz]) = (s.edge_radius, s.height, s.center);
        match self {
            Generator::Random {
                amplitude,
                wavelength,
                seed,
            } => {
                let mut rng = SplitMix(*seed);
                let waves: Vec<[f64; 3]> = (0..64)
                    .map(|_| {
                        let k = std::f64::consts::TAU / (wavelength * (0.7 + 0.7 * rng.unit()));
                        let a = std::f64::consts::TAU * rng.unit();
                        let phase = std::f64::consts::TAU * rng.unit();
                        [k * a.cos(), k * a.sin(), phase]
                    })
                    .collect();
                let raw = |x: f64, z: f64| -> f64 {
                    waves
                        .iter()
                        .map(|w| (w[0] * (x - cx) + w[1] * (z - cz) + w[2]).cos())
                        .sum()
                };
                let g = HeightGrid::sample(nrow, ncol, s.size, s.center, raw)?;
                let [lo, hi] = g.range();
                let (mid, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
                let k = if half > 0.0 { amplitude / half } else { 0.0 };
                let h = g.heights().iter().map(|v| h0 + k * (v - mid)).collect();
                HeightGrid::new(nrow, ncol, h, s.size, s.center)
            }
            Generator::Stairs {
                tread,
                riser,
                heading,
                steps,
                origin,
            } => {
                let (sn, cs) = heading.sin_cos();
                HeightGrid::sample(nrow, ncol, s.size, s.center, |x, z| {
                    let d = (x - origin[0]) * cs - (z - origin[1]) * sn;
                    h0 + riser
                        * (0..*steps)
                            .map(|i| ramp(d - i as f64 * tread, r))
                            .sum::<f64>()
                })
            }
            Generator::Stones {
                stone,
                gap,
                depth,
                amplitude,
                seed,
            } => {
                let p = stone + gap;
                let top = |m: f64, n: f64| -> f64 {
                    if *amplitude == 0.0 {
                        return 0.0;
                    }
                    // One reproducible draw per stone, from its lattice index.
                    let key = (m as i64 as u64).wrapping_mul(0x1_0000_0001) ^ (n as i64 as u64);
                    let mut rng = SplitMix(seed ^ key.wrapping_mul(0x9E37_79B9_7F4A_7C15));
                    amplitude * (2.0 * rng.unit() - 1.0)
                };
                HeightGrid::sample(nrow, ncol, s.size, s.center, |x, z| {
                    let (u, v) = (x - cx, z - cz);
                    let (m, n) = ((u / p).round(), (v / p).round());
                    let (du, dv) = (wrap(u, p), wrap(v, p));
                    let inside = ramp(0.5 * stone - du.abs(), r) * ramp(0.5 * stone - dv.abs(), r);
                    h0 - depth + inside * (depth + top(m, n))
                })
            }
            Generator::Pyramids {
                amplitude,
                wavelength,
            } => HeightGrid::sample(nrow, ncol, s.size, s.center, |x, z| {
                let (a, b) = (
                    soft_abs(wrap(x - cx, *wavelength), r),
                    soft_abs(wrap(z - cz, *wavelength), r),
                );
                let m = 0.5 * (a + b + soft_abs(a - b, r));
                h0 + amplitude * (1.0 - 2.0 * m / wavelength).max(0.0)
            }),
            Generator::Sines {
                amplitude,
                wavelength,
            } => {
                let w = std::f64::consts::TAU / wavelength;
                HeightGrid::sample(nrow, ncol, s.size, s.center, |x, z| {
                    h0 + amplitude * (w * (x - cx)).sin() * (w * (z - cz)).sin()
                })
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sampling() -> Sampling {
        Sampling {
            size: [1.0, 0.8],
            center: [0.2, 0.0],
            resolution: 0.01,
            edge_radius: 0.01,
            height: 0.05,
        }
    }

    #[test]
    fn random_terrain_is_reproducible_and_spans_its_amplitude() {
        let g = Generator::Random {
            amplitude: 0.03,
            wavelength: 0.3,
            seed: 7,
        };
        let a = g.grid(&sampling()).unwrap();
        assert_eq!(a, g.grid(&sampling()).unwrap());
        let [lo, hi] = a.range();
        assert!(
            (lo - 0.02).abs() < 1e-12 && (hi - 0.08).abs() < 1e-12,
            "{lo} {hi}"
        );
        let other = Generator::Random {
            amplitude: 0.03,
            wavelength: 0.3,
            seed: 8,
        };
        assert_ne!(a, other.grid(&sampling()).unwrap());
    }

    #[test]
    fn stairs_climb_their_risers() {
        let g = Generator::Stairs {
            tread: 0.2,
            riser: 0.05,
            heading: 0.0,
            steps: 3,
            origin: [0.0, 0.0],
        }
        .grid(&sampling())
        .unwrap();
        assert!((g.height(-0.1, 0.1) - 0.05).abs() < 1e-12);
        assert!((g.height(0.1, 0.1) - 0.10).abs() < 1e-12);
        assert!((g.height(0.3, -0.2) - 0.15).abs() < 1e-12);
        assert!((g.height(0.55, 0.3) - 0.20).abs() < 1e-12);
        // Half-way up the rounded riser.
        assert!((g.height(0.2, 0.0) - 0.125).abs() < 1e-12);
    }

    #[test]
    fn stones_stand_above_their_gaps() {
        let g = Generator::Stones {
            stone: 0.2,
            gap: 0.1,
            depth: 0.1,
            amplitude: 0.0,
            seed: 1,
        }
        .grid(&sampling())
        .unwrap();
        assert!((g.height(0.2, 0.0) - 0.05).abs() < 1e-12);
        assert!((g.height(0.35, 0.0) + 0.05).abs() < 1e-12);
    }
}

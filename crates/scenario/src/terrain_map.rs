//! `[terrain]` height maps (heightfield files and generated terrains) and
//! friction patches (`[[terrain.patch]]`).
//!
//! Heightfield files ([`read_heights`]), by extension: `.png` (8- or 16-bit
//! grayscale; black is `elevation[0]`, white `elevation[1]`), `.npy` (a 2D
//! NumPy array of float64 heights in metres, C or Fortran order), `.csv`
//! (one grid row per line, comma-separated heights in metres; blank lines
//! and `#` comments skipped), anything else MuJoCo's binary hfield
//! (little-endian int32 nrow, int32 ncol, nrow·ncol float32, normalised to
//! `elevation` as MuJoCo does). Row `i` of the file lies at
//! `x = center.x − size.x/2 + i·size.x/(nrow − 1)`, column `j` at
//! `z = center.z − size.z/2 + j·size.z/(ncol − 1)`: rows along +X, columns
//! along +Z (for a PNG: image rows top to bottom along +X, pixels left to
//! right along +Z).

use std::io::Cursor;
use std::path::Path;

use fbd_contact::{
    Friction, FrictionPatch, Generator, GridIssue, HeightGrid, Sampling, Surface, Terrain,
};
use serde::{Deserialize, Serialize};

use super::{ConfigError, TerrainConfig, TerrainKind};

/// Default extent `[x, z]` (m) of a generated terrain.
pub const DEFAULT_SIZE: [f64; 2] = [3.0, 3.0];
/// Default grid spacing (m) of a generated terrain.
pub const DEFAULT_RESOLUTION: f64 = 0.01;
/// Default rounding radius (m) of a generated terrain's sharp features.
pub const DEFAULT_EDGE_RADIUS: f64 = 0.01;

/// One `[[terrain.patch]]`: a rectangle with its own friction.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PatchConfig {
    /// `[x_min, x_max]` (m).
    pub x: Vec<f64>,
    /// `[z_min, z_max]` (m).
    pub z: Vec<f64>,
    /// Static friction coefficient μS.
    pub mu_static: f64,
    /// Dynamic friction coefficient μD (`0 ≤ μD ≤ μS`).
    pub mu_dynamic: f64,
}

/// A `[min, max]` pair with `min ≤ max` (`strict`: `min < max`).
fn range(file: &str, key: &str, v: &[f64], strict: bool) -> Result<[f64; 2], ConfigError> {
    match v {
        [a, b] if a.is_finite() && b.is_finite() && (a < b || (!strict && a == b)) => Ok([*a, *b]),
        _ => Err(ConfigError::semantic(
            file,
            key,
            "must be a finite range [min, max]",
            format!("{v:?}"),
            if strict {
                "2 finite numbers, min < max"
            } else {
                "2 finite numbers, min ≤ max"
            },
        )),
    }
}

/// A finite pair.
fn pair(file: &str, key: &str, v: &[f64]) -> Result<[f64; 2], ConfigError> {
    match v {
        [a, b] if a.is_finite() && b.is_finite() => Ok([*a, *b]),
        _ => Err(ConfigError::semantic(
            file,
            key,
            "must be 2 finite numbers",
            format!("{v:?}"),
            "[x, z]",
        )),
    }
}

/// A positive finite value.
fn positive(file: &str, key: &str, v: f64) -> Result<f64, ConfigError> {
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(ConfigError::semantic(
            file,
            key,
            "must be positive and finite",
            v,
            "a finite value > 0",
        ))
    }
}

/// A finite value.
fn finite(file: &str, key: &str, v: f64) -> Result<f64, ConfigError> {
    if v.is_finite() {
        Ok(v)
    } else {
        Err(ConfigError::semantic(
            file,
            key,
            "must be finite",
            v,
            "a finite value",
        ))
    }
}

/// `true` for the kinds that are a height map.
pub fn is_map(kind: TerrainKind) -> bool {
    matches!(
        kind,
        TerrainKind::Heightfield
            | TerrainKind::Random
            | TerrainKind::Stairs
            | TerrainKind::Stones
            | TerrainKind::Pyramids
            | TerrainKind::Sines
    )
}

/// Heights read from a file: `nrow × ncol` row-major values and whether
/// they are to be scaled to `elevation` (images, MuJoCo binary) or are
/// metres (NumPy, CSV).
pub struct FileHeights {
    /// Rows (along +X).
    pub nrow: usize,
    /// Columns (along +Z).
    pub ncol: usize,
    /// Values, row-major.
    pub values: Vec<f64>,
    /// `Some((lo, hi))`: the values span `[lo, hi]` and map to
    /// `elevation` (`lo` → `elevation[0]`).
    pub scale: Option<[f64; 2]>,
}

/// Reads a heightfield file (see the module docs); `Err` says what is
/// wrong, without the file name.
pub fn read_heights(path: &Path) -> Result<FileHeights, String> {
    let bytes = std::fs::read(path).map_err(|e| match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".to_owned(),
        _ => format!("cannot read it: {e}"),
    })?;
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    match ext.as_str() {
        "png" => read_png(bytes),
        "npy" => read_npy(&bytes),
        "csv" | "txt" => read_csv(&bytes),
        _ => read_mujoco(&bytes),
    }
}

fn read_png(bytes: Vec<u8>) -> Result<FileHeights, String> {
    let bad = |e: png::DecodingError| format!("not a readable PNG: {e}");
    let mut reader = png::Decoder::new(Cursor::new(bytes))
        .read_info()
        .map_err(bad)?;
    let size = reader
        .output_buffer_size()
        .ok_or("a PNG too large to decode")?;
    let mut buf = vec![0u8; size];
    let info = reader.next_frame(&mut buf).map_err(bad)?;
    let (w, h) = (info.width as usize, info.height as usize);
    let max = match (info.color_type, info.bit_depth) {
        (png::ColorType::Grayscale, png::BitDepth::Eight) => 255.0,
        (png::ColorType::Grayscale, png::BitDepth::Sixteen) => 65535.0,
        (c, d) => {
            return Err(format!(
                "a {c:?} PNG of {d:?} bits; a grayscale PNG of 8 or 16 bits is needed"
            ));
        }
    };
    let mut values = Vec::with_capacity(w * h);
    for r in 0..h {
        let line = &buf[r * info.line_size..(r + 1) * info.line_size];
        for c in 0..w {
            values.push(if max > 255.0 {
                f64::from(u16::from_be_bytes([line[2 * c], line[2 * c + 1]]))
            } else {
                f64::from(line[c])
            });
        }
    }
    Ok(FileHeights {
        nrow: h,
        ncol: w,
        values,
        scale: Some([0.0, max]),
    })
}

/// A NumPy `.npy` of a 2D float64 array (format versions 1 to 3). A
/// parser of its few-line header: the format is fixed and the crates that
/// read it bring a numeric array library this crate does not need.
fn read_npy(bytes: &[u8]) -> Result<FileHeights, String> {
    let bad = |what: &str| format!("not a 2D float64 .npy: {what}");
    if bytes.len() < 10 || &bytes[..6] != b"\x93NUMPY" {
        return Err(bad("no NumPy magic string"));
    }
    let (len, start) = match bytes[6] {
        1 => (usize::from(u16::from_le_bytes([bytes[8], bytes[9]])), 10),
        2 | 3 if bytes.len() >= 12 => (
            u32::from_le_bytes([bytes[8], bytes[9], bytes[10], bytes[11]]) as usize,
            12,
        ),
        v => return Err(bad(&format!("format version {v}"))),
    };
    let header = bytes
        .get(start..start + len)
        .and_then(|h| std::str::from_utf8(h).ok())
        .ok_or_else(|| bad("truncated header"))?;
    let value = |key: &str| -> Option<&str> {
        let at = header.find(&format!("'{key}'"))? + key.len() + 2;
        let rest = header[at..].trim_start().strip_prefix(':')?.trim_start();
        Some(rest)
    };
    let descr = value("descr").ok_or_else(|| bad("no descr"))?;
    if !(descr.starts_with("'<f8'") || descr.starts_with("'=f8'")) {
        return Err(bad(&format!(
            "dtype {}",
            descr.split(',').next().unwrap_or("")
        )));
    }
    let fortran = value("fortran_order")
        .ok_or_else(|| bad("no fortran_order"))?
        .starts_with("True");
    let shape = value("shape").ok_or_else(|| bad("no shape"))?;
    let inner = shape
        .strip_prefix('(')
        .and_then(|s| s.split(')').next())
        .ok_or_else(|| bad("unreadable shape"))?;
    let dims: Vec<usize> = inner
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .map(|s| s.parse::<usize>().map_err(|_| bad("unreadable shape")))
        .collect::<Result<_, _>>()?;
    let [nrow, ncol] = dims[..] else {
        return Err(bad(&format!("shape {dims:?}, expected (nrow, ncol)")));
    };
    let data = &bytes[start + len..];
    if data.len() != 8 * nrow * ncol {
        return Err(format!(
            "holds {} bytes of data, expected {} for shape ({nrow}, {ncol})",
            data.len(),
            8 * nrow * ncol
        ));
    }
    let raw: Vec<f64> = data
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().unwrap_or([0; 8])))
        .collect();
    let values = if fortran {
        let mut v = vec![0.0; raw.len()];
        for i in 0..nrow {
            for j in 0..ncol {
                v[i * ncol + j] = raw[j * nrow + i];
            }
        }
        v
    } else {
        raw
    };
    Ok(FileHeights {
        nrow,
        ncol,
        values,
        scale: None,
    })
}

fn read_csv(bytes: &[u8]) -> Result<FileHeights, String> {
    let text = std::str::from_utf8(bytes).map_err(|_| "not UTF-8 text".to_owned())?;
    let mut values = Vec::new();
    let (mut nrow, mut ncol) = (0, 0);
    for (n, line) in text.lines().enumerate() {
        let line = line.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        let row: Vec<f64> = line
            .split(',')
            .map(|f| f.trim().parse::<f64>())
            .collect::<Result<_, _>>()
            .map_err(|_| format!("line {}: not a row of numbers", n + 1))?;
        if nrow == 0 {
            ncol = row.len();
        } else if row.len() != ncol {
            return Err(format!(
                "line {}: {} values, the first row has {ncol}",
                n + 1,
                row.len()
            ));
        }
        values.extend(row);
        nrow += 1;
    }
    Ok(FileHeights {
        nrow,
        ncol,
        values,
        scale: None,
    })
}

fn read_mujoco(bytes: &[u8]) -> Result<FileHeights, String> {
    if bytes.len() < 8 {
        return Err("not a MuJoCo hfield: shorter than its 8-byte header".into());
    }
    let int = |k: usize| i32::from_le_bytes([bytes[k], bytes[k + 1], bytes[k + 2], bytes[k + 3]]);
    let (nr, nc) = (int(0), int(4));
    if nr < 1 || nc < 1 {
        return Err(format!("not a MuJoCo hfield: nrow = {nr}, ncol = {nc}"));
    }
    let (nrow, ncol) = (nr as usize, nc as usize);
    let data = &bytes[8..];
    if data.len() != 4 * nrow * ncol {
        return Err(format!(
            "holds {} bytes of data, expected {} for nrow = {nrow}, ncol = {ncol}",
            data.len(),
            4 * nrow * ncol
        ));
    }
    let values: Vec<f64> = data
        .chunks_exact(4)
        .map(|c| f64::from(f32::from_le_bytes([c[0], c[1], c[2], c[3]])))
        .collect();
    let [lo, hi] = values
        .iter()
        .fold([f64::INFINITY, f64::NEG_INFINITY], |[a, b], &v| {
            [a.min(v), b.max(v)]
        });
    Ok(FileHeights {
        nrow,
        ncol,
        values,
        scale: Some([lo, hi]),
    })
}

impl TerrainConfig {
    /// The friction patches, validated: `x`, `z` ranges, `0 ≤ μD ≤ μS`.
    pub fn patches(&self, file: &str) -> Result<Vec<FrictionPatch>, ConfigError> {
        self.patch
            .iter()
            .enumerate()
            .map(|(i, p)| {
                let key = |k: &str| format!("terrain.patch[{i}].{k}");
                let friction = Friction {
                    mu_static: p.mu_static,
                    mu_dynamic: p.mu_dynamic,
                };
                if !(p.mu_static.is_finite() && p.mu_static >= 0.0) {
                    return Err(ConfigError::semantic(
                        file,
                        &key("mu_static"),
                        "must be finite and ≥ 0",
                        p.mu_static,
                        "0 ≤ mu_static",
                    ));
                }
                if friction.validate().is_err() {
                    return Err(ConfigError::semantic(
                        file,
                        &key("mu_dynamic"),
                        "must satisfy 0 ≤ mu_dynamic ≤ mu_static",
                        p.mu_dynamic,
                        &format!("0 ≤ mu_dynamic ≤ {}", p.mu_static),
                    ));
                }
                Ok(FrictionPatch {
                    x: range(file, &key("x"), &p.x, false)?,
                    z: range(file, &key("z"), &p.z, false)?,
                    friction,
                })
            })
            .collect()
    }

    /// The 3D surface: the height map, or the profile extruded along Z;
    /// with the friction patches.
    pub fn surface(&self) -> Surface {
        let s = match &self.map {
            Some(s) => s.clone(),
            None => Surface::new(self.terrain(), 0.0),
        };
        s.with_patches(self.patches("").unwrap_or_default())
    }

    /// The planar model's section `z = 0` of a height map: the profile
    /// through the map's heights at its rows (`None` for the other kinds).
    pub(crate) fn map_section(&self) -> Option<Terrain> {
        let g = self.map.as_ref()?.grid()?;
        let [x0, x1, ..] = g.bounds();
        let n = g.nrow();
        Some(Terrain::Profile {
            points: (0..n)
                .map(|i| {
                    let x = x0 + (x1 - x0) * i as f64 / (n - 1) as f64;
                    [x, g.height(x, 0.0)]
                })
                .collect(),
        })
    }

    /// Builds the height map of `kind = "heightfield"` and the generated
    /// kinds into the configuration (a heightfield `file` relative to the
    /// directory of `config_file`, rewritten as an absolute path so that the
    /// configuration written back repeats the run). Errors name
    /// `terrain.<key>` and, for a file, the file.
    pub fn load_map(&mut self, config_file: &str) -> Result<(), ConfigError> {
        self.map = None;
        if !is_map(self.kind) {
            return Ok(());
        }
        let f = config_file;
        let size = match &self.size {
            Some(v) => pair(f, "terrain.size", v)?,
            None if self.kind == TerrainKind::Heightfield => {
                return Err(ConfigError::semantic(
                    f,
                    "terrain.size",
                    "is required for kind = \"heightfield\"",
                    "nothing",
                    "[x_extent, z_extent] (m)",
                ));
            }
            None => DEFAULT_SIZE,
        };
        for (axis, e) in size.iter().enumerate() {
            if *e <= 0.0 {
                return Err(ConfigError::semantic(
                    f,
                    "terrain.size",
                    &format!("the {} extent must be positive", ["x", "z"][axis]),
                    format!("{size:?}"),
                    "[x_extent, z_extent] > 0 (m)",
                ));
            }
        }
        let center = match &self.center {
            Some(v) => pair(f, "terrain.center", v)?,
            None => [0.0, 0.0],
        };
        let grid = if self.kind == TerrainKind::Heightfield {
            self.read_file(f, size, center)?
        } else {
            self.generate(f, size, center)?
        };
        self.map = Some(Surface::from_grid(grid));
        Ok(())
    }

    fn read_file(
        &mut self,
        f: &str,
        size: [f64; 2],
        center: [f64; 2],
    ) -> Result<HeightGrid, ConfigError> {
        let Some(name) = self.file.clone() else {
            return Err(ConfigError::semantic(
                f,
                "terrain.file",
                "is required for kind = \"heightfield\"",
                "nothing",
                "a .png, .npy, .csv or MuJoCo binary hfield file",
            ));
        };
        let path = Path::new(f).parent().unwrap_or(Path::new("")).join(&name);
        let shown = path.display().to_string();
        let fail = |what: String| {
            ConfigError::semantic(
                f,
                "terrain.file",
                &format!("{shown}: {what}"),
                &name,
                "a heightfield file (docs/reference.md)",
            )
        };
        let h = read_heights(&path).map_err(fail)?;
        let values = match h.scale {
            Some([lo, hi]) => {
                let Some(e) = &self.elevation else {
                    return Err(ConfigError::semantic(
                        f,
                        "terrain.elevation",
                        &format!("is required for the image or MuJoCo heightfield {shown}"),
                        "nothing",
                        "[min, max] (m): the heights of black and white",
                    ));
                };
                let [e0, e1] = range(f, "terrain.elevation", e, false)?;
                let k = if hi > lo { (e1 - e0) / (hi - lo) } else { 0.0 };
                h.values.iter().map(|v| e0 + k * (v - lo)).collect()
            }
            None => {
                if self.elevation.is_some() {
                    return Err(ConfigError::semantic(
                        f,
                        "terrain.elevation",
                        &format!("is not used by {shown}, whose heights are metres"),
                        "a value",
                        "no elevation for .npy and .csv heightfields",
                    ));
                }
                h.values
            }
        };
        let grid = HeightGrid::new(h.nrow, h.ncol, values, size, center).map_err(|e| match e {
            GridIssue::Extent { .. } => ConfigError::semantic(
                f,
                "terrain.size",
                &e.to_string(),
                format!("{size:?}"),
                "[x_extent, z_extent] > 0 (m)",
            ),
            e => fail(e.to_string()),
        })?;
        // Absolute, so that the configuration written elsewhere still finds it.
        if let Ok(abs) = std::fs::canonicalize(&path) {
            self.file = Some(abs.display().to_string());
        }
        Ok(grid)
    }

    fn generate(
        &self,
        f: &str,
        size: [f64; 2],
        center: [f64; 2],
    ) -> Result<HeightGrid, ConfigError> {
        let need = |key: &str, v: Option<f64>| -> Result<f64, ConfigError> {
            let v = v.ok_or_else(|| {
                ConfigError::semantic(
                    f,
                    &format!("terrain.{key}"),
                    "is required for this kind",
                    "nothing",
                    "a value",
                )
            })?;
            finite(f, &format!("terrain.{key}"), v)
        };
        let resolution = positive(
            f,
            "terrain.resolution",
            self.resolution.unwrap_or(DEFAULT_RESOLUTION),
        )?;
        let cells = (size[0] / resolution + 1.0) * (size[1] / resolution + 1.0);
        if cells > 4e6 {
            return Err(ConfigError::semantic(
                f,
                "terrain.resolution",
                "gives a grid of more than 4 million points",
                resolution,
                "a coarser spacing or a smaller terrain.size",
            ));
        }
        let edge_radius = self.edge_radius.unwrap_or(DEFAULT_EDGE_RADIUS);
        if !(edge_radius.is_finite() && edge_radius >= 0.0) {
            return Err(ConfigError::semantic(
                f,
                "terrain.edge_radius",
                "must be finite and ≥ 0",
                edge_radius,
                "a radius (m)",
            ));
        }
        let seed = self.seed.unwrap_or(0);
        let generator = match self.kind {
            TerrainKind::Random => Generator::Random {
                amplitude: need("amplitude", self.amplitude)?,
                wavelength: positive(
                    f,
                    "terrain.wavelength",
                    need("wavelength", self.wavelength)?,
                )?,
                seed,
            },
            TerrainKind::Stairs => Generator::Stairs {
                tread: positive(f, "terrain.tread", need("tread", self.tread)?)?,
                riser: need("riser", self.riser)?,
                heading: finite(f, "terrain.heading_deg", self.heading_deg.unwrap_or(0.0))?
                    .to_radians(),
                steps: self.count.unwrap_or(3),
                origin: match &self.origin {
                    Some(v) => pair(f, "terrain.origin", v)?,
                    None => center,
                },
            },
            TerrainKind::Stones => Generator::Stones {
                stone: positive(f, "terrain.stone", need("stone", self.stone)?)?,
                gap: need("gap", self.gap)?.max(0.0),
                depth: need("depth", self.depth)?,
                amplitude: finite(f, "terrain.amplitude", self.amplitude.unwrap_or(0.0))?,
                seed,
            },
            TerrainKind::Pyramids => Generator::Pyramids {
                amplitude: need("amplitude", self.amplitude)?,
                wavelength: positive(
                    f,
                    "terrain.wavelength",
                    need("wavelength", self.wavelength)?,
                )?,
            },
            TerrainKind::Sines => Generator::Sines {
                amplitude: need("amplitude", self.amplitude)?,
                wavelength: positive(
                    f,
                    "terrain.wavelength",
                    need("wavelength", self.wavelength)?,
                )?,
            },
            k => {
                return Err(ConfigError::semantic(
                    f,
                    "terrain.kind",
                    "is not a generated kind",
                    format!("{k:?}"),
                    "random, stairs, stones, pyramids or sines",
                ));
            }
        };
        generator
            .grid(&Sampling {
                size,
                center,
                resolution,
                edge_radius,
                height: self.height,
            })
            .map_err(|e| {
                ConfigError::semantic(
                    f,
                    "terrain.size",
                    &e.to_string(),
                    format!("{size:?}"),
                    "[x_extent, z_extent] > 0 (m)",
                )
            })
    }
}

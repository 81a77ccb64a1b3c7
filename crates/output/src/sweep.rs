//! `fbd sweep SWEEP.toml`: many runs of one base configuration with some
//! dotted keys varied, on every core, with progress, resumable and
//! shardable across the machines of a cluster; `fbd sweep merge` joins the
//! shards. See `docs/sweep.md`.
//!
//! Layout of the output directory:
//! * `runs/<index>/` — exactly the files of `fbd run runs/<index>/config.toml`
//!   (only `wall_seconds`/`steps_per_second` of `summary.json` differ from
//!   run to run), plus an empty `.done` marker written after every other
//!   file, so that `--resume` never takes a half-written run for a finished
//!   one.
//! * `index.csv` — one row per finished run, sorted by index ([`COLUMNS`]).
//! * `sweep.json` — the sweep definition, the total number of runs, the
//!   shard and the varied values of every run (what `merge` checks).
//! * `sweep.svg` — a column of `index.csv` against the varied keys.
//!
//! Random mode uses splitmix64 (Steele, Lea & Flood 2014) seeded with
//! `seed`: for run 0, 1, … and, within a run, for each varied key in the
//! order of the file, one 64-bit draw `u` gives
//! `min + (max − min)·(u >> 11)/2⁵³`, uniform in `[min, max)`. The
//! sequence depends only on the seed, so every shard draws the same runs.

use std::collections::BTreeMap;
use std::io::{IsTerminal, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use crate::OutputError;
use crate::config::{self, Config, Override};
use crate::output::count;

/// The fixed columns of `index.csv` after `run, status` and the varied
/// keys.
pub const COLUMNS: [&str; 12] = [
    "touchdown3",
    "touchdown4",
    "slip3",
    "slip4",
    "peak_n3",
    "peak_n4",
    "peak_fa3",
    "peak_fa4",
    "peak_joint_force",
    "steps",
    "wall_seconds",
    "error",
];

/// The fixed columns of `index.csv` of a hexapod sweep (the kinematic
/// gait), after `run, status` and the varied keys: the body's path length,
/// net displacement, mean speed and heading change, the smallest
/// stability margin and when, the largest joint rate and acceleration
/// over all joints, the number of lift-offs, then as for the planar model.
pub const HEXAPOD_COLUMNS: [&str; 12] = [
    "distance",
    "displacement",
    "mean_speed",
    "heading_change_deg",
    "min_margin",
    "min_margin_t",
    "max_joint_rate",
    "max_joint_acceleration",
    "liftoffs",
    "steps",
    "wall_seconds",
    "error",
];

/// The fixed columns of `index.csv` of a sweep of the hexapod's 3D FBD
/// dynamics, after `run, status` and the varied keys: the horizontal
/// distance the body moved and its final height (m), the largest joint
/// torque (N·m) and foot normal force (N), the first touchdown of any foot
/// (s), the number of slip events of the feet (a foot entering ST3), of
/// all events (`events.csv`), the Newton iterations and steps per second
/// of the run, then as for the planar model but `error`; then the run's
/// own audit of every step: the largest violation of a contact law or a
/// body's balance over all steps (N, `max_law_violation` of
/// `summary.json`), the steps solved again in substeps and the substeps
/// they took (so that a strided or Parquet sweep still shows per run that
/// every row is exact), then `error`.
pub const DYNAMIC_COLUMNS: [&str; 15] = [
    "distance",
    "final_height",
    "peak_torque",
    "peak_foot_n",
    "first_touchdown",
    "foot_slips",
    "events",
    "newton_iterations",
    "steps_per_second",
    "steps",
    "wall_seconds",
    "max_law_violation",
    "retried_steps",
    "substeps",
    "error",
];

/// Which model a sweep runs, and so which columns `index.csv` has.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum IndexKind {
    /// The planar dynamics: [`COLUMNS`].
    #[default]
    Planar,
    /// The hexapod's kinematic gait: [`HEXAPOD_COLUMNS`].
    Hexapod,
    /// The hexapod's 3D FBD dynamics: [`DYNAMIC_COLUMNS`].
    Dynamic,
}

impl IndexKind {
    /// The fixed columns of `index.csv` (`error` last).
    pub fn columns(self) -> &'static [&'static str] {
        match self {
            IndexKind::Planar => &COLUMNS,
            IndexKind::Hexapod => &HEXAPOD_COLUMNS,
            IndexKind::Dynamic => &DYNAMIC_COLUMNS,
        }
    }

    fn of(config: &Config) -> Self {
        match config {
            Config::Planar(_) => IndexKind::Planar,
            Config::Hexapod(h) if h.is_dynamic() => IndexKind::Dynamic,
            Config::Hexapod(_) => IndexKind::Hexapod,
        }
    }
}

/// Columns `--plot` accepts: `touchdown`, the first touchdown of either
/// tip (the default; `distance` for a hexapod sweep), and the numeric
/// columns of `index.csv` (all of [`COLUMNS`], [`HEXAPOD_COLUMNS`] and
/// [`DYNAMIC_COLUMNS`] but `error`), each once.
pub fn plot_columns() -> impl Iterator<Item = &'static str> {
    let mut seen: Vec<&'static str> = vec!["touchdown"];
    for c in COLUMNS
        .iter()
        .chain(&HEXAPOD_COLUMNS)
        .chain(&DYNAMIC_COLUMNS)
    {
        if *c != "error" && !seen.contains(c) {
            seen.push(c);
        }
    }
    seen.into_iter()
}

/// Marker written in a run directory after all its files.
const DONE: &str = ".done";

/// What `fbd sweep` was asked (the command line's `fbd_cli::sweep::SweepArgs`
/// converts into it; the Python package builds it).
#[derive(Clone, Debug)]
pub struct SweepArgs {
    /// `fbd sweep merge DIR... --out DIR`.
    pub command: Option<SweepCommand>,
    /// The sweep file (TOML: base, mode, samples, seed, [vary], [set],
    /// [derive]; docs/sweep.md).
    pub sweep: Option<PathBuf>,
    /// Output directory, created if needed.
    pub out: PathBuf,
    /// Runs at a time (default: every core).
    pub jobs: Option<usize>,
    /// Run only the indices with `index % N == I` (0 ≤ I < N).
    pub shard: Option<String>,
    /// Skip runs whose directory holds a finished run with status ok.
    pub resume: bool,
    /// Column of index.csv plotted in sweep.svg (touchdown: the first
    /// touchdown of either tip).
    pub plot: String,
    /// Write each run's viewer.html (some 0.8 MB a run; off by default:
    /// `fbd view runs/<i>` writes one later).
    pub viewer: bool,
    /// Write each run's plots (*.svg; off by default).
    pub plots: bool,
}

/// Subcommands of `fbd sweep`.
#[derive(Clone, Debug)]
pub enum SweepCommand {
    /// Combine shard directories into one (runs/<i>, one index.csv) and
    /// report missing runs.
    Merge(MergeArgs),
}

/// Arguments of `fbd sweep merge`.
#[derive(Clone, Debug)]
pub struct MergeArgs {
    /// Shard output directories.
    pub dirs: Vec<PathBuf>,
    /// The merged directory, created if needed.
    pub out: PathBuf,
    /// Column plotted in the merged sweep.svg.
    pub plot: String,
}

/// How the varied values combine into runs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Mode {
    /// Cartesian product, the first key varying slowest.
    #[default]
    Grid,
    /// The i-th value of every list (equal lengths).
    Zip,
    /// `samples` draws, uniform in each key's `{ min, max }`.
    Random,
}

/// A `[vary]` table in the order of the file.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Vary(pub Vec<(String, toml::Value)>);

impl<'de> Deserialize<'de> for Vary {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> serde::de::Visitor<'de> for V {
            type Value = Vary;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("a table of dotted configuration keys")
            }
            fn visit_map<A: serde::de::MapAccess<'de>>(self, mut m: A) -> Result<Vary, A::Error> {
                // The deserializer may visit keys sorted: restore the
                // order of the file from the spans.
                let mut v = Vec::new();
                while let Some((k, val)) = m.next_entry::<String, toml::Spanned<toml::Value>>()? {
                    v.push((val.span().start, k, val.into_inner()));
                }
                v.sort_by_key(|e| e.0);
                let v = v.into_iter().map(|(_, k, val)| (k, val)).collect();
                Ok(Vary(v))
            }
        }
        d.deserialize_map(V)
    }
}

/// The sweep file.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SweepFile {
    /// Base configuration, relative to the sweep file; none = built-in
    /// default.
    pub base: Option<String>,
    /// grid | zip | random.
    #[serde(default)]
    pub mode: Mode,
    /// Number of runs (random only).
    pub samples: Option<usize>,
    /// PRNG seed (random only, default 0).
    pub seed: Option<u64>,
    /// Dotted keys and their values.
    #[serde(default)]
    pub vary: Vary,
    /// Dotted keys set to one value in every run, in every mode (e.g.
    /// `"output.stride" = 10`): applied before the varied and derived
    /// keys, not columns of `index.csv`, no random draws.
    #[serde(default, skip_serializing_if = "Vary::is_empty")]
    pub set: Vary,
    /// Keys computed from varied ones: `"key" = { from = "varied.key",
    /// scale = X }` sets `key` to `X ×` the run's value of `varied.key`
    /// (e.g. μD = 0.75·μS).
    #[serde(default, skip_serializing_if = "Vary::is_empty")]
    pub derive: Vary,
}

impl Vary {
    /// `true` when no key is listed.
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }
}

fn as_f64(v: &toml::Value) -> Option<f64> {
    match v {
        toml::Value::Float(f) => Some(*f),
        toml::Value::Integer(i) => Some(*i as f64),
        _ => None,
    }
}

/// A varied value as written in `index.csv`: floats always with a decimal
/// point, arrays as `[0.0, 0.5]`.
pub fn format_value(v: &toml::Value) -> String {
    match v {
        toml::Value::Float(f) => format!("{f:?}"),
        toml::Value::Integer(i) => i.to_string(),
        toml::Value::String(s) => s.clone(),
        toml::Value::Boolean(b) => b.to_string(),
        toml::Value::Array(a) => {
            let items: Vec<String> = a.iter().map(format_value).collect();
            format!("[{}]", items.join(", "))
        }
        other => other.to_string(),
    }
}

/// Expands the sweep into the values of every run: the varied keys, then
/// the derived ones (`[derive]`, see [`SweepFile::derive`]).
pub fn expand(s: &SweepFile, file: &str) -> Result<Vec<Vec<toml::Value>>, String> {
    let mut runs = expand_vary(s, file)?;
    let keys = &s.vary.0;
    for (k, v) in &s.derive.0 {
        let rule = v.as_table().and_then(|t| {
            let from = t.get("from")?.as_str()?;
            let scale = as_f64(t.get("scale")?)?;
            (t.len() == 2 && scale.is_finite()).then_some((from, scale))
        });
        let Some((from, scale)) = rule else {
            return Err(format!(
                "{file}: derive.\"{k}\": expected {{ from = \"varied.key\", scale = X }} with a finite X"
            ));
        };
        let Some(i) = keys.iter().position(|(vk, _)| vk == from) else {
            return Err(format!(
                "{file}: derive.\"{k}\": from = \"{from}\" is not a key of [vary]"
            ));
        };
        if keys.iter().any(|(vk, _)| vk == k) {
            return Err(format!("{file}: derive.\"{k}\": the key is also in [vary]"));
        }
        for run in &mut runs {
            let Some(x) = as_f64(&run[i]) else {
                return Err(format!(
                    "{file}: derive.\"{k}\": vary.\"{from}\" has a value that is not a number ({})",
                    format_value(&run[i])
                ));
            };
            run.push(toml::Value::Float(scale * x));
        }
    }
    Ok(runs)
}

/// The most runs one sweep file may plan. Every run's configuration is
/// built and checked before the first run starts (in every shard): 100,000
/// landings of `examples/sweep_hexapod_landing_1000.toml`'s base take
/// about 250 MB and 9 s to plan, so a million take some 2.5 GB and a
/// minute and a half. A grid of five 200-value lists (3.2e11 runs) or
/// `samples = 1e9` asked for more memory than a machine has and stopped
/// with an allocation failure; now it is a one-line error.
pub const MAX_RUNS: usize = 1_000_000;

/// The one-line error of a sweep beyond [`MAX_RUNS`].
fn too_many(file: &str, what: String) -> String {
    format!(
        "{file}: {what}: more runs than one sweep file may plan ({}); split it into several files (other values, or other seeds)",
        MAX_RUNS
    )
}

fn expand_vary(s: &SweepFile, file: &str) -> Result<Vec<Vec<toml::Value>>, String> {
    let keys = &s.vary.0;
    let bad = |msg: String| format!("{file}: {msg}");
    if keys.is_empty() {
        return Err(bad("[vary] names no key".into()));
    }
    if s.mode != Mode::Random && (s.samples.is_some() || s.seed.is_some()) {
        return Err(bad(
            "`samples` and `seed` apply to mode = \"random\" only".into()
        ));
    }
    let lists = || -> Result<Vec<&Vec<toml::Value>>, String> {
        keys.iter()
            .map(|(k, v)| match v {
                toml::Value::Array(a) if !a.is_empty() => Ok(a),
                _ => Err(bad(format!(
                    "vary.\"{k}\": expected a non-empty list of values (mode = \"{}\")",
                    mode_str(s.mode)
                ))),
            })
            .collect()
    };
    match s.mode {
        Mode::Grid => {
            let lists = lists()?;
            let total = lists
                .iter()
                .try_fold(1usize, |n, l| n.checked_mul(l.len()))
                .filter(|&n| n <= MAX_RUNS)
                .ok_or_else(|| {
                    let lengths: Vec<String> = lists.iter().map(|l| l.len().to_string()).collect();
                    too_many(
                        file,
                        format!("mode = \"grid\" of {} values", lengths.join(" × ")),
                    )
                })?;
            Ok((0..total)
                .map(|mut i| {
                    let mut row = vec![toml::Value::Boolean(false); lists.len()];
                    for (slot, l) in row.iter_mut().zip(&lists).rev() {
                        *slot = l[i % l.len()].clone();
                        i /= l.len();
                    }
                    row
                })
                .collect())
        }
        Mode::Zip => {
            let lists = lists()?;
            let n = lists[0].len();
            if let Some((k, l)) = keys.iter().zip(&lists).find(|(_, l)| l.len() != n) {
                return Err(bad(format!(
                    "vary.\"{}\": {} values, but vary.\"{}\" has {n} (mode = \"zip\" needs equal lengths)",
                    k.0,
                    l.len(),
                    keys[0].0
                )));
            }
            Ok((0..n)
                .map(|i| lists.iter().map(|l| l[i].clone()).collect())
                .collect())
        }
        Mode::Random => {
            let samples = s
                .samples
                .ok_or_else(|| bad("mode = \"random\" needs `samples`".into()))?;
            if samples == 0 {
                return Err(bad("samples = 0: mode = \"random\" needs at least 1".into()));
            }
            if samples > MAX_RUNS {
                return Err(too_many(file, format!("samples = {samples}")));
            }
            // Each key: `{ min = X, max = Y }` (a number) or `{ min = [..],
            // max = [..] }` (an array, one draw per component in order).
            let mut ranges: Vec<(Vec<(f64, f64)>, bool)> = Vec::new();
            for (k, v) in keys {
                let range = v.as_table().filter(|t| t.len() == 2).and_then(|t| {
                    let (lo, hi) = (t.get("min")?, t.get("max")?);
                    match (lo, hi) {
                        (toml::Value::Array(lo), toml::Value::Array(hi))
                            if lo.len() == hi.len() && !lo.is_empty() =>
                        {
                            let pairs: Option<Vec<(f64, f64)>> = lo
                                .iter()
                                .zip(hi)
                                .map(|(a, b)| Some((as_f64(a)?, as_f64(b)?)))
                                .collect();
                            Some((pairs?, true))
                        }
                        _ => Some((vec![(as_f64(lo)?, as_f64(hi)?)], false)),
                    }
                });
                match range {
                    Some((pairs, array))
                        if pairs
                            .iter()
                            .all(|(lo, hi)| lo.is_finite() && hi.is_finite() && lo <= hi) =>
                    {
                        ranges.push((pairs, array));
                    }
                    _ => {
                        return Err(bad(format!(
                            "vary.\"{k}\": expected {{ min = X, max = Y }} with finite X <= Y, or arrays of equal length (mode = \"random\")"
                        )));
                    }
                }
            }
            let mut rng = fbd_contact::SplitMix(s.seed.unwrap_or(0));
            Ok((0..samples)
                .map(|_| {
                    ranges
                        .iter()
                        .map(|(pairs, array)| {
                            let mut draws: Vec<toml::Value> = pairs
                                .iter()
                                .map(|(lo, hi)| toml::Value::Float(lo + (hi - lo) * rng.unit()))
                                .collect();
                            if *array {
                                toml::Value::Array(draws)
                            } else {
                                draws.remove(0)
                            }
                        })
                        .collect()
                })
                .collect())
        }
    }
}

fn mode_str(m: Mode) -> &'static str {
    match m {
        Mode::Grid => "grid",
        Mode::Zip => "zip",
        Mode::Random => "random",
    }
}

/// `DIR/sweep.json`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SweepJson {
    /// The sweep file as given.
    pub sweep_file: String,
    /// The definition (base resolved relative to the sweep file).
    pub definition: serde_json::Value,
    /// The varied keys, in order.
    pub keys: Vec<String>,
    /// Number of runs of the whole sweep (all shards).
    pub total_runs: usize,
    /// `[I, N]` of this directory's shard; `null` for a whole sweep or a
    /// merge.
    pub shard: Option<[usize; 2]>,
    /// The varied values of every run (as in index.csv), by index.
    pub runs: Vec<Vec<String>>,
}

/// One row of `index.csv`.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Row {
    /// Global run index.
    pub run: usize,
    /// "ok", "error" or "interrupted".
    pub status: String,
    /// The varied values, formatted ([`format_value`]).
    pub values: Vec<String>,
    /// The numeric columns of `kind` ([`COLUMNS`] `touchdown3` …
    /// `wall_seconds`, or [`HEXAPOD_COLUMNS`]), `None` = empty (missing
    /// entries too).
    pub numbers: Vec<Option<f64>>,
    /// Which columns `numbers` holds.
    pub kind: IndexKind,
    /// The error message ("" when ok).
    pub error: String,
}

impl Row {
    /// A plotted column of this row (see [`plot_columns`]).
    pub fn column(&self, name: &str) -> Option<f64> {
        if name == "touchdown" {
            let n = |i: usize| self.numbers.get(i).copied().flatten();
            return match (n(0), n(1)) {
                (Some(a), Some(b)) => Some(a.min(b)),
                (a, b) => a.or(b),
            };
        }
        let cols = self.kind.columns();
        cols[..cols.len() - 1]
            .iter()
            .position(|c| *c == name)
            .and_then(|i| self.numbers.get(i).copied().flatten())
    }
}

fn fmt_num(v: Option<f64>) -> String {
    v.map(|x| x.to_string()).unwrap_or_default()
}

/// Removes `DIR/runs/<i>` for every `i ≥ total`: the runs of an earlier,
/// larger sweep into the same directory, which would otherwise sit beside
/// this sweep's runs looking current.
fn remove_stale_runs(dir: &Path, total: usize) -> Result<(), OutputError> {
    let Ok(entries) = std::fs::read_dir(dir.join("runs")) else {
        return Ok(());
    };
    for e in entries.flatten() {
        let path = e.path();
        let stale = e
            .file_name()
            .to_str()
            .and_then(|n| {
                n.parse::<usize>()
                    .ok()
                    .filter(|i| *i >= total && i.to_string() == n)
            })
            .is_some();
        if stale && path.is_dir() {
            std::fs::remove_dir_all(&path).map_err(|err| {
                OutputError::io(
                    format!(
                        "{}: cannot remove the run of an earlier sweep",
                        path.display()
                    ),
                    &err,
                )
            })?;
        }
    }
    Ok(())
}

/// Writes `index.csv` (rows sorted by run) with the columns of `kind`.
pub fn write_index(
    dir: &Path,
    keys: &[String],
    kind: IndexKind,
    rows: &[Row],
) -> Result<(), OutputError> {
    let mut rows: Vec<&Row> = rows.iter().collect();
    rows.sort_by_key(|r| r.run);
    let mut w = csv::Writer::from_writer(Vec::new());
    let io = |e: csv::Error| OutputError::Io(format!("index.csv: {e}"));
    let mut header = vec!["run".to_owned(), "status".to_owned()];
    header.extend(keys.iter().cloned());
    header.extend(kind.columns().iter().map(|s| (*s).to_owned()));
    w.write_record(&header).map_err(io)?;
    for r in rows {
        let mut rec = vec![r.run.to_string(), r.status.clone()];
        rec.extend(r.values.iter().cloned());
        let cols = kind.columns();
        rec.extend((0..cols.len() - 1).map(|i| {
            let v = r.numbers.get(i).copied().flatten();
            if i == 9 {
                v.map(|s| (s as u64).to_string()).unwrap_or_default()
            } else {
                fmt_num(v)
            }
        }));
        rec.push(r.error.clone());
        w.write_record(&rec).map_err(io)?;
    }
    let bytes = w
        .into_inner()
        .map_err(|e| OutputError::Io(format!("index.csv: {e}")))?;
    crate::output::write_file(dir, "index.csv", &bytes).map(drop)
}

/// Reads `index.csv` back (for `merge`): its rows and which columns it
/// has.
pub fn read_index(path: &Path, nkeys: usize) -> Result<(IndexKind, Vec<Row>), OutputError> {
    let mut r = csv::Reader::from_path(path)
        .map_err(|e| OutputError::Io(format!("{}: {e}", path.display())))?;
    let kind = match r.headers() {
        Ok(h) if h.get(3 + nkeys) == Some(DYNAMIC_COLUMNS[1]) => IndexKind::Dynamic,
        Ok(h) if h.get(2 + nkeys) == Some(HEXAPOD_COLUMNS[0]) => IndexKind::Hexapod,
        _ => IndexKind::Planar,
    };
    let mut rows = Vec::new();
    for rec in r.records() {
        let rec = rec.map_err(|e| OutputError::Io(format!("{}: {e}", path.display())))?;
        let bad = || OutputError::Io(format!("{}: malformed row", path.display()));
        let ncols = kind.columns().len();
        if rec.len() != 2 + nkeys + ncols {
            return Err(bad());
        }
        let mut numbers = vec![None; ncols - 1];
        for (i, n) in numbers.iter_mut().enumerate() {
            let s = &rec[2 + nkeys + i];
            *n = if s.is_empty() {
                None
            } else {
                Some(s.parse().map_err(|_| bad())?)
            };
        }
        rows.push(Row {
            run: rec[0].parse().map_err(|_| bad())?,
            status: rec[1].to_owned(),
            values: (0..nkeys).map(|i| rec[2 + i].to_owned()).collect(),
            numbers,
            kind,
            error: rec[2 + nkeys + ncols - 1].to_owned(),
        });
    }
    Ok((kind, rows))
}

/// The row of a finished run, from its `summary.json`.
fn row_from_summary(dir: &Path, run: usize, values: Vec<String>) -> Option<Row> {
    let text = std::fs::read_to_string(dir.join("summary.json")).ok()?;
    let s: serde_json::Value = serde_json::from_str(&text).ok()?;
    let num = |v: &serde_json::Value| v.as_f64();
    if s["model"] == "hexapod" && s["run"] == "dynamic" {
        return Some(dynamic_row(&s, run, values));
    }
    if s["model"] == "robot" {
        return Some(robot_row(&s, run, values));
    }
    if s["model"] == "hexapod" {
        let liftoffs = s["events"]
            .as_array()
            .map(|e| e.iter().filter(|e| e["event"] == "liftoff").count() as f64);
        return Some(Row {
            run,
            status: s["status"].as_str().unwrap_or("error").to_owned(),
            values,
            numbers: vec![
                num(&s["distance"]),
                num(&s["displacement"]),
                num(&s["mean_speed"]),
                num(&s["heading_change_deg"]),
                num(&s["min_margin"]["value"]),
                num(&s["min_margin"]["t"]),
                num(&s["peak_joint_rate_max"]),
                num(&s["peak_joint_acceleration_max"]),
                liftoffs,
                num(&s["steps"]),
                num(&s["wall_seconds"]),
            ],
            kind: IndexKind::Hexapod,
            error: s["error"].as_str().unwrap_or("").replace('\n', " "),
        });
    }
    let numbers = vec![
        num(&s["first_touchdown"]["leg3"]),
        num(&s["first_touchdown"]["leg4"]),
        num(&s["first_slip"]["leg3"]),
        num(&s["first_slip"]["leg4"]),
        num(&s["peak_contact_force"]["tip3"]["n"]),
        num(&s["peak_contact_force"]["tip4"]["n"]),
        num(&s["peak_contact_force"]["tip3"]["fa"]),
        num(&s["peak_contact_force"]["tip4"]["fa"]),
        num(&s["peak_joint_force_max"]),
        num(&s["steps"]),
        num(&s["wall_seconds"]),
    ];
    Some(Row {
        run,
        status: s["status"].as_str().unwrap_or("error").to_owned(),
        values,
        numbers,
        kind: IndexKind::Planar,
        error: s["error"].as_str().unwrap_or("").replace('\n', " "),
    })
}

/// The row of a finished dynamic hexapod run, from its `summary.json`
/// ([`DYNAMIC_COLUMNS`]).
fn dynamic_row(s: &serde_json::Value, run: usize, values: Vec<String>) -> Row {
    let events = s["events"].as_array();
    let foot_slips = events.map(|e| {
        e.iter()
            .filter(|e| e["point"] == "tip" && e["to"] == "ST3" && e["from"] != "ST3")
            .count() as f64
    });
    // The earliest touchdown of any foot; the largest normal force of any
    // foot (the knees and hips are contact points too, but not feet).
    let first_touchdown = s["first_touchdown"].as_object().and_then(|m| {
        m.values()
            .filter_map(serde_json::Value::as_f64)
            .reduce(f64::min)
    });
    // The feet are the `{leg, kind: tip}` points of the model's legs.
    let tip = fbd_dynamics::PointKind::Tip.as_str();
    let peak_foot_n = s["legs"].as_array().and_then(|legs| {
        legs.iter()
            .filter_map(serde_json::Value::as_u64)
            .filter_map(|n| s["peak_contact_force"][format!("{tip}{n}")]["n"].as_f64())
            .reduce(f64::max)
    });
    dynamic_columns(s, run, values, peak_foot_n, first_touchdown, foot_slips)
}

/// A row of [`DYNAMIC_COLUMNS`] from a dynamic run's `summary.json` and
/// the values the models count their own way: the largest foot normal
/// force, the first touchdown, the slips of the feet.
fn dynamic_columns(
    s: &serde_json::Value,
    run: usize,
    values: Vec<String>,
    peak_foot_n: Option<f64>,
    first_touchdown: Option<f64>,
    foot_slips: Option<f64>,
) -> Row {
    let num = |v: &serde_json::Value| v.as_f64();
    Row {
        run,
        status: s["status"].as_str().unwrap_or("error").to_owned(),
        values,
        numbers: vec![
            num(&s["distance"]),
            num(&s["final_height"]),
            num(&s["peak_torque_max"]),
            peak_foot_n,
            first_touchdown,
            foot_slips,
            s["events"].as_array().map(|e| e.len() as f64),
            num(&s["newton_iterations"]),
            num(&s["steps_per_second"]),
            num(&s["steps"]),
            num(&s["wall_seconds"]),
            num(&s["max_law_violation"]),
            num(&s["retried_steps"]),
            num(&s["substeps"]),
        ],
        kind: IndexKind::Dynamic,
        error: s["error"].as_str().unwrap_or("").replace('\n', " "),
    }
}

/// The row of a finished run of an imported robot, from its
/// `summary.json`: the dynamic hexapod's columns ([`DYNAMIC_COLUMNS`]),
/// every contact point counted as a foot.
fn robot_row(s: &serde_json::Value, run: usize, values: Vec<String>) -> Row {
    let events = s["events"].as_array();
    let contacts: Vec<&str> = s["contact_points"]
        .as_array()
        .map(|a| a.iter().filter_map(serde_json::Value::as_str).collect())
        .unwrap_or_default();
    let slips = events.map(|e| {
        e.iter()
            .filter(|e| {
                e["point"].as_str().is_some_and(|p| contacts.contains(&p))
                    && e["to"] == "ST3"
                    && e["from"] != "ST3"
            })
            .count() as f64
    });
    let first_touchdown = s["first_touchdown"].as_object().and_then(|m| {
        m.values()
            .filter_map(serde_json::Value::as_f64)
            .reduce(f64::min)
    });
    dynamic_columns(
        s,
        run,
        values,
        s["peak_normal_force"].as_f64(),
        first_touchdown,
        slips,
    )
}

/// A finished run with status ok whose config.toml is the one planned
/// (so `--resume` after editing the sweep file reruns what changed).
fn is_done_ok(dir: &Path, run: usize, config: &RunConfig) -> Option<Row> {
    if !dir.join(DONE).is_file()
        || std::fs::read(dir.join("config.toml")).ok()? != config.to_toml().as_bytes()
    {
        return None;
    }
    row_from_summary(dir, run, Vec::new()).filter(|r| r.status == "ok")
}

fn parse_shard(s: &str) -> Result<(usize, usize), OutputError> {
    let bad = || {
        OutputError::Usage(format!(
            "--shard {s}: expected I/N with 0 <= I < N, e.g. 0/8"
        ))
    };
    let (i, n) = s.split_once('/').ok_or_else(bad)?;
    let (i, n): (usize, usize) = (
        i.trim().parse().map_err(|_| bad())?,
        n.trim().parse().map_err(|_| bad())?,
    );
    if n == 0 || i >= n {
        return Err(bad());
    }
    Ok((i, n))
}

/// One run's complete configuration: the planar model or the hexapod
/// ([`Config`]), or an imported robot.
#[derive(Clone, Debug)]
pub enum RunConfig {
    /// `model = "planar"` or `"hexapod"`.
    Model(Config),
    /// `model = "robot"`.
    Robot(Box<config::robot::LoadedRobot>),
}

impl RunConfig {
    /// The complete configuration as TOML (`config.toml` of the run).
    pub fn to_toml(&self) -> String {
        match self {
            RunConfig::Model(c) => c.to_toml(),
            RunConfig::Robot(r) => r.config.to_toml(),
        }
    }

    /// The columns of `index.csv` it gives (a robot's are the dynamic
    /// hexapod's).
    pub fn kind(&self) -> IndexKind {
        match self {
            RunConfig::Model(c) => IndexKind::of(c),
            RunConfig::Robot(_) => IndexKind::Dynamic,
        }
    }

    /// Whether the run writes `viewer.html` and the plots.
    fn set_outputs(&mut self, viewer: bool, plots: bool) {
        match self {
            RunConfig::Model(c) => {
                let output = match c {
                    Config::Planar(p) => &mut p.output,
                    Config::Hexapod(h) => &mut h.output,
                };
                output.viewer = viewer;
                output.plots = plots;
            }
            RunConfig::Robot(r) => {
                r.config.output.viewer = viewer;
                r.config.output.plots = plots;
            }
        }
    }
}

/// A loaded, validated sweep: the configuration of every run.
pub struct Plan {
    /// The sweep file's definition.
    pub file: SweepFile,
    /// Varied keys in order.
    pub keys: Vec<String>,
    /// Per run: the varied values.
    pub values: Vec<Vec<toml::Value>>,
    /// Per run: the complete configuration.
    pub configs: Vec<RunConfig>,
    /// Per run: its trajectory file as planned (rows, columns, format),
    /// for the sweep's size warning.
    pub trajectories: Vec<crate::output::TrajectorySize>,
}

/// Reads the sweep file, expands it and validates every run's
/// configuration (errors name the run and the key).
pub fn plan(path: &Path) -> Result<Plan, OutputError> {
    let name = path.display().to_string();
    let text = config::read_text(path)?;
    let mut file: SweepFile = toml::from_str(&text)
        .map_err(|e| OutputError::Usage(config::syntax_error(&name, &text, &e).to_string()))?;
    let values = expand(&file, &name).map_err(OutputError::Usage)?;
    for (k, _) in &file.set.0 {
        for (table, list) in [("vary", &file.vary), ("derive", &file.derive)] {
            if list.0.iter().any(|(o, _)| o == k) {
                return Err(OutputError::Usage(format!(
                    "{name}: set.\"{k}\": the key is also in [{table}]"
                )));
            }
        }
    }
    let set: Vec<Override> = file
        .set
        .0
        .iter()
        .map(|(k, v)| Override::new(k.clone(), v.clone()))
        .collect();
    let keys: Vec<String> = file
        .vary
        .0
        .iter()
        .chain(&file.derive.0)
        .map(|(k, _)| k.clone())
        .collect();
    let (base_text, base_name) = match &file.base {
        Some(b) => {
            let p = path.parent().unwrap_or(Path::new("")).join(b);
            let t = config::read_text(&p).map_err(|e| match e {
                config::ConfigError::Unreadable { file, what } => config::ConfigError::Unreadable {
                    file,
                    what: format!("{what} (the base of {name})"),
                },
                other => other,
            })?;
            // Record the resolved base so sweep.json is self-describing.
            file.base = Some(p.display().to_string());
            (t, p.display().to_string())
        }
        None => (String::new(), "the built-in default".to_owned()),
    };
    if config::robot::is_robot(&base_text) {
        return plan_robot(file, keys, values, set, &base_text, &base_name, &name);
    }
    // The [set] keys alone on the base: an unknown key or a value of the
    // wrong type is named once (a value out of range, which may depend on
    // the varied keys, is reported per run below).
    for i in 0..set.len() {
        if let Err(config::ConfigError::Override { key, message, .. }) =
            config::parse_str(&base_text, &base_name, &set[..=i])
        {
            return Err(set_error(&name, &key, &message));
        }
    }
    let mut configs = Vec::with_capacity(values.len());
    let mut trajectories = Vec::with_capacity(values.len());
    for (i, vals) in values.iter().enumerate() {
        let overrides = run_overrides(&set, &keys, vals);
        let fail =
            |e: String| OutputError::Usage(format!("{}: {e}", run_label(&name, i, &keys, vals)));
        let c = config::parse_str(&base_text, &base_name, &overrides)
            .map_err(|e| fail(e.to_string()))?;
        let size = |steps: usize, columns: usize, output: &fbd_scenario::OutputConfig| {
            let stride = output.stride.max(1);
            crate::output::TrajectorySize {
                rows: steps.div_ceil(stride),
                columns,
                stride,
                format: output.format,
                hexapod: matches!(c, Config::Hexapod(_)),
            }
        };
        trajectories.push(match &c {
            Config::Planar(p) => {
                let m = p.model(&base_name).map_err(|e| fail(e.to_string()))?;
                let columns = crate::output::ContactSlots::of(&m.mech.contacts)
                    .columns()
                    .len();
                size(m.steps, columns, &p.output)
            }
            Config::Hexapod(h) if h.is_dynamic() => {
                let m = h
                    .spatial_model(&base_name)
                    .map_err(|e| fail(e.to_string()))?;
                let params = h
                    .spatial_params(&base_name)
                    .map_err(|e| fail(e.to_string()))?;
                let columns = crate::spatial::columns(&crate::spatial::Layout::of(&params)).len();
                size(m.steps, columns, &h.output)
            }
            Config::Hexapod(h) => {
                let m = h.gait_model(&base_name).map_err(|e| fail(e.to_string()))?;
                size(m.steps, crate::hexapod::columns().len(), &h.output)
            }
        });
        configs.push(RunConfig::Model(c));
    }
    Ok(Plan {
        file,
        keys,
        values,
        configs,
        trajectories,
    })
}

/// The overrides of one run: the `[set]` keys, then the varied ones with
/// their values.
fn run_overrides(set: &[Override], keys: &[String], vals: &[toml::Value]) -> Vec<Override> {
    set.iter()
        .cloned()
        .chain(
            keys.iter()
                .zip(vals)
                .map(|(k, v)| Override::new(k.clone(), v.clone())),
        )
        .collect()
}

/// `SWEEP: run i (key = value, …)`, how errors name a run.
fn run_label(name: &str, i: usize, keys: &[String], vals: &[toml::Value]) -> String {
    let what = keys
        .iter()
        .zip(vals)
        .map(|(k, v)| format!("{k} = {}", format_value(v)))
        .collect::<Vec<_>>()
        .join(", ");
    format!("{name}: run {i} ({what})")
}

/// A `[set]` key the base cannot take.
fn set_error(name: &str, key: &str, message: &str) -> OutputError {
    OutputError::Usage(format!(
        "{name}: set.\"{key}\": {}",
        message.replace('\n', " ")
    ))
}

/// [`plan`] of a sweep whose base is an imported robot: every run's
/// overrides set in the base's table, its robot loaded and its simulator
/// built (errors name the run and the key).
fn plan_robot(
    file: SweepFile,
    keys: Vec<String>,
    values: Vec<Vec<toml::Value>>,
    set: Vec<Override>,
    base_text: &str,
    base_name: &str,
    name: &str,
) -> Result<Plan, OutputError> {
    let base_path = Path::new(base_name);
    for i in 0..set.len() {
        if let Err(e) = config::robot::load_with_overrides(base_text, base_path, &set[..=i]) {
            let message = match e {
                config::ConfigError::Override { message, .. } => message,
                other => other.to_string(),
            };
            return Err(set_error(name, &set[i].key, &message));
        }
    }
    let mut configs = Vec::with_capacity(values.len());
    let mut trajectories = Vec::with_capacity(values.len());
    for (i, vals) in values.iter().enumerate() {
        let overrides = run_overrides(&set, &keys, vals);
        let fail =
            |e: String| OutputError::Usage(format!("{}: {e}", run_label(name, i, &keys, vals)));
        let robot = config::robot::load_with_overrides(base_text, base_path, &overrides)
            .map_err(|e| fail(e.to_string()))?;
        let sim = robot.sim().map_err(|e| fail(e.to_string()))?;
        let stride = robot.config.output.stride.max(1);
        trajectories.push(crate::output::TrajectorySize {
            rows: sim.steps.div_ceil(stride),
            columns: crate::robot_run::plan(&robot, &sim).names.len(),
            stride,
            format: robot.config.output.format,
            hexapod: true,
        });
        configs.push(RunConfig::Robot(Box::new(robot)));
    }
    Ok(Plan {
        file,
        keys,
        values,
        configs,
        trajectories,
    })
}

/// Progress on stderr: an indicatif bar on a terminal, otherwise a line
/// every 10 % or every 5 s.
struct Progress {
    bar: Option<indicatif::ProgressBar>,
    total: usize,
    done: usize,
    failed: usize,
    start: Instant,
    last_line: Instant,
    last_decile: usize,
}

impl Progress {
    fn new(total: usize) -> Self {
        let bar = std::io::stderr().is_terminal().then(|| {
            let b = indicatif::ProgressBar::new(total as u64);
            if let Ok(style) = indicatif::ProgressStyle::with_template(
                "{bar:40} {pos}/{len} runs  {msg}  elapsed {elapsed}  ETA {eta}",
            ) {
                b.set_style(style);
            }
            b.set_message("0 failed");
            b
        });
        Self {
            bar,
            total,
            done: 0,
            failed: 0,
            start: Instant::now(),
            last_line: Instant::now(),
            last_decile: 0,
        }
    }

    fn tick(&mut self, ok: bool) {
        self.done += 1;
        self.failed += usize::from(!ok);
        if let Some(b) = &self.bar {
            b.set_message(format!("{} failed", self.failed));
            b.inc(1);
            return;
        }
        let decile = self.done * 10 / self.total.max(1);
        let now = Instant::now();
        if decile > self.last_decile
            || now.duration_since(self.last_line) >= Duration::from_secs(5)
            || self.done == self.total
        {
            self.last_decile = decile;
            self.last_line = now;
            let el = now.duration_since(self.start).as_secs_f64();
            let eta = el / self.done as f64 * (self.total - self.done) as f64;
            eprintln!(
                "sweep: {}/{} runs, {} failed, {el:.1} s elapsed, ETA {eta:.0} s",
                self.done, self.total, self.failed
            );
        }
    }

    fn finish(&self) {
        if let Some(b) = &self.bar {
            b.finish();
        }
    }
}

/// Runs one sweep entry into `dir`: config.toml first, then `fbd run` of
/// it (so the files are those of `fbd run dir/config.toml`), then `.done`.
fn run_one(dir: &Path, config: &RunConfig, run: usize, values: Vec<String>) -> Row {
    let fail = |msg: String| Row {
        run,
        status: "error".into(),
        values: values.clone(),
        error: msg.replace('\n', " "),
        kind: config.kind(),
        ..Row::default()
    };
    if dir.exists()
        && let Err(e) = std::fs::remove_dir_all(dir)
    {
        return fail(format!(
            "{}: cannot clear: {}",
            dir.display(),
            config::os_message(&e)
        ));
    }
    if let Err(e) = crate::output::prepare_dir(dir)
        .and_then(|()| crate::output::write_file(dir, "config.toml", config.to_toml().as_bytes()))
    {
        return fail(e.to_string());
    }
    let cfg = dir.join("config.toml");
    let result =
        std::panic::catch_unwind(|| crate::run::run_command(Some(&cfg), dir, &mut std::io::sink()));
    let err = match result {
        Ok(Ok(())) => None,
        Ok(Err(e)) => Some(e.to_string()),
        Err(_) => Some("internal error (panic)".to_owned()),
    };
    let row = match row_from_summary(dir, run, values.clone()) {
        Some(mut r) => {
            if let Some(e) = err {
                // An interrupted run keeps its status (`--resume` reruns it).
                if r.status != "interrupted" {
                    r.status = "error".into();
                }
                if r.error.is_empty() {
                    r.error = e.replace('\n', " ");
                }
            }
            r
        }
        None => fail(err.unwrap_or_else(|| "summary.json missing".into())),
    };
    if let Err(e) = std::fs::write(dir.join(DONE), b"") {
        return fail(format!(
            "{}: {}",
            dir.join(DONE).display(),
            config::os_message(&e)
        ));
    }
    row
}

fn write_json(dir: &Path, name: &str, v: &impl Serialize) -> Result<(), OutputError> {
    let j = serde_json::to_string_pretty(v).map_err(|e| OutputError::Io(format!("{name}: {e}")))?;
    crate::output::write_file(dir, name, format!("{j}\n").as_bytes()).map(drop)
}

/// Writes `sweep.svg`, or says why not on `out`.
fn write_plot(
    dir: &Path,
    keys: &[String],
    rows: &[Row],
    column: &str,
    out: &mut dyn Write,
) -> Result<(), OutputError> {
    match crate::sweep_plot::sweep_svg(keys, rows, column) {
        Ok(svg) => crate::output::write_file(dir, "sweep.svg", svg.as_bytes()).map(drop),
        Err(why) => writeln!(out, "sweep.svg not written: {why}").map_err(OutputError::stdout),
    }
}

/// The plotted column: `distance` for the default `touchdown` of a
/// hexapod sweep (no touchdowns of the planar tips).
fn default_plot(kind: IndexKind, column: &str) -> &str {
    if kind != IndexKind::Planar && column == "touchdown" {
        "distance"
    } else {
        column
    }
}

fn check_plot_column(c: &str) -> Result<(), OutputError> {
    if plot_columns().any(|p| p == c) {
        Ok(())
    } else {
        Err(OutputError::Usage(format!(
            "--plot {c}: unknown column (expected one of {})",
            plot_columns().collect::<Vec<_>>().join(", ")
        )))
    }
}

/// `fbd sweep …` and `fbd sweep merge …`.
pub fn sweep_command(a: SweepArgs, out: &mut dyn Write) -> Result<(), OutputError> {
    if let Some(SweepCommand::Merge(m)) = a.command {
        return merge_command(&m, out);
    }
    let Some(path) = a.sweep.as_deref() else {
        return Err(OutputError::Usage(
            "fbd sweep: missing the SWEEP file".into(),
        ));
    };
    check_plot_column(&a.plot)?;
    let (shard_i, shard_n) = a.shard.as_deref().map_or(Ok((0, 1)), parse_shard)?;
    let jobs = match a.jobs {
        Some(0) => return Err(OutputError::Usage("--jobs 0: expected at least 1".into())),
        Some(j) => j,
        None => std::thread::available_parallelism().map_or(1, |n| n.get()),
    };
    let mut plan = plan(path)?;
    for c in &mut plan.configs {
        c.set_outputs(a.viewer, a.plots);
    }
    let total = plan.configs.len();
    // Before anything is written: a sweep larger than LARGE_SWEEP says so
    // once, with what would shrink it (this shard's runs).
    let planned: Vec<crate::output::TrajectorySize> = plan
        .trajectories
        .iter()
        .enumerate()
        .filter(|(i, _)| i % shard_n == shard_i)
        .map(|(_, t)| *t)
        .collect();
    if let Some(w) = crate::output::sweep_size_warning(&planned, a.viewer, a.plots) {
        eprintln!("{w}");
    }
    let dir = &a.out;
    crate::output::prepare_dir(dir)?;
    crate::output::prepare_dir(&dir.join("runs"))?;
    let formatted: Vec<Vec<String>> = plan
        .values
        .iter()
        .map(|v| v.iter().map(format_value).collect())
        .collect();
    write_json(
        dir,
        "sweep.json",
        &SweepJson {
            sweep_file: path.display().to_string(),
            definition: serde_json::to_value(&plan.file)
                .map_err(|e| OutputError::Io(format!("sweep.json: {e}")))?,
            keys: plan.keys.clone(),
            total_runs: total,
            shard: a.shard.as_ref().map(|_| [shard_i, shard_n]),
            runs: formatted.clone(),
        },
    )?;

    let mine: Vec<usize> = (0..total).filter(|i| i % shard_n == shard_i).collect();
    let mut rows: Vec<Row> = Vec::new();
    let mut todo = Vec::new();
    for &i in &mine {
        let rd = dir.join("runs").join(i.to_string());
        match a
            .resume
            .then(|| is_done_ok(&rd, i, &plan.configs[i]))
            .flatten()
        {
            Some(mut r) => {
                r.values = formatted[i].clone();
                rows.push(r);
            }
            None => todo.push(i),
        }
    }
    let skipped = rows.len();
    // Set by SIGINT/SIGTERM: workers take no new run, and the runs in
    // progress stop at their next step with status "interrupted".
    let stop: &AtomicBool = crate::interrupt::flag();
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.min(todo.len().max(1)))
        .build()
        .map_err(|e| OutputError::Io(format!("thread pool: {e}")))?;
    let next = AtomicUsize::new(0);
    let results = Mutex::new(Vec::with_capacity(todo.len()));
    let progress = Mutex::new(Progress::new(todo.len()));
    pool.scope(|s| {
        for _ in 0..pool.current_num_threads() {
            s.spawn(|_| {
                loop {
                    if stop.load(Ordering::SeqCst) {
                        break;
                    }
                    let k = next.fetch_add(1, Ordering::SeqCst);
                    let Some(&i) = todo.get(k) else { break };
                    let rd = dir.join("runs").join(i.to_string());
                    let row = run_one(&rd, &plan.configs[i], i, formatted[i].clone());
                    let ok = row.status == "ok";
                    if let Ok(mut r) = results.lock() {
                        r.push(row);
                    }
                    if let Ok(mut p) = progress.lock() {
                        p.tick(ok);
                    }
                }
            });
        }
    });
    if let Ok(p) = progress.lock() {
        p.finish();
    }
    let ran = results.into_inner().unwrap_or_default();
    let ran_n = ran.len();
    rows.extend(ran);
    rows.sort_by_key(|r| r.run);
    let kind = plan
        .configs
        .first()
        .map_or(IndexKind::Planar, RunConfig::kind);
    remove_stale_runs(dir, total)?;
    write_index(dir, &plan.keys, kind, &rows)?;
    write_plot(dir, &plan.keys, &rows, default_plot(kind, &a.plot), out)?;

    let failed: Vec<usize> = rows
        .iter()
        .filter(|r| r.status != "ok")
        .map(|r| r.run)
        .collect();
    let shard_txt = if shard_n > 1 {
        format!(
            ", shard {shard_i}/{shard_n}: {}",
            count(mine.len(), "run", "runs")
        )
    } else {
        String::new()
    };
    let written = dir_bytes(dir);
    writeln!(
        out,
        "sweep: {}{shard_txt}; ran {ran_n}, skipped {skipped} finished; {} ok, {} failed\nfiles in {}: index.csv sweep.json sweep.svg runs/ ({}{})",
        count(total, "run", "runs"),
        rows.len() - failed.len(),
        failed.len(),
        dir.display(),
        human_bytes(written),
        if a.viewer || a.plots {
            ""
        } else {
            "; per-run viewers and plots with --viewer, --plots"
        }
    )
    .map_err(OutputError::stdout)?;
    let interrupted = stop.load(Ordering::SeqCst);
    if interrupted {
        let stopped = rows.iter().filter(|r| r.status == "interrupted").count();
        return Err(OutputError::Interrupted(format!(
            "interrupted: {} of {} finished, {stopped} stopped part-way (status \"interrupted\" in index.csv), {} not started; `--resume` continues",
            rows.len() - stopped,
            count(mine.len(), "run", "runs"),
            mine.len() - rows.len()
        )));
    }
    if !failed.is_empty() {
        let list: Vec<String> = failed.iter().take(10).map(ToString::to_string).collect();
        return Err(OutputError::Simulation(format!(
            "{} of {} failed ({} {}{}); see the error column of {}",
            failed.len(),
            count(rows.len(), "run", "runs"),
            if failed.len() == 1 { "run" } else { "runs" },
            list.join(", "),
            if failed.len() > 10 { ", …" } else { "" },
            dir.join("index.csv").display()
        )));
    }
    Ok(())
}

/// Bytes of the files under `dir` (what the sweep directory holds).
pub fn dir_bytes(dir: &Path) -> u64 {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return 0;
    };
    entries
        .flatten()
        .map(|e| match e.file_type() {
            Ok(t) if t.is_dir() => dir_bytes(&e.path()),
            Ok(t) if t.is_file() => e.metadata().map_or(0, |m| m.len()),
            _ => 0,
        })
        .sum()
}

/// `bytes` as `812 kB`, `95.3 MB`, `1.90 GB` (powers of 1000).
pub fn human_bytes(bytes: u64) -> String {
    let b = bytes as f64;
    if b < 1e6 {
        format!("{:.0} kB", b / 1e3)
    } else if b < 1e9 {
        format!("{:.1} MB", b / 1e6)
    } else {
        format!("{:.2} GB", b / 1e9)
    }
}

fn copy_dir(from: &Path, to: &Path) -> std::io::Result<()> {
    std::fs::create_dir_all(to)?;
    for e in std::fs::read_dir(from)? {
        let e = e?;
        let dest = to.join(e.file_name());
        if e.file_type()?.is_dir() {
            copy_dir(&e.path(), &dest)?;
        } else {
            std::fs::copy(e.path(), dest)?;
        }
    }
    Ok(())
}

/// `fbd sweep merge DIR... --out DIR`.
pub fn merge_command(m: &MergeArgs, out: &mut dyn Write) -> Result<(), OutputError> {
    check_plot_column(&m.plot)?;
    let mut first: Option<SweepJson> = None;
    let mut rows: BTreeMap<usize, Row> = BTreeMap::new();
    let mut sources: BTreeMap<usize, PathBuf> = BTreeMap::new();
    let mut kind = IndexKind::Planar;
    for d in &m.dirs {
        let p = d.join("sweep.json");
        if !d.is_dir() {
            return Err(OutputError::Config(config::ConfigError::Unreadable {
                file: d.display().to_string(),
                what: "no such directory".into(),
            }));
        }
        let text = config::read_text(&p).map_err(|e| match e {
            config::ConfigError::Unreadable { file, what } => config::ConfigError::Unreadable {
                file,
                what: format!("{what} (not an output directory of `fbd sweep`)"),
            },
            other => other,
        })?;
        let j: SweepJson = serde_json::from_str(&text)
            .map_err(|e| OutputError::Io(format!("{}: {e}", p.display())))?;
        match &first {
            None => first = Some(j.clone()),
            Some(f) => {
                if f.total_runs != j.total_runs || f.keys != j.keys || f.runs != j.runs {
                    return Err(OutputError::Usage(format!(
                        "{}: not a shard of the same sweep as {}",
                        d.display(),
                        m.dirs[0].display()
                    )));
                }
            }
        }
        let idx = d.join("index.csv");
        if !idx.exists() {
            continue;
        }
        let (k, runs) = read_index(&idx, j.keys.len())?;
        kind = k;
        for r in runs {
            sources.insert(r.run, d.clone());
            rows.insert(r.run, r);
        }
    }
    let Some(mut j) = first else {
        return Err(OutputError::Usage("merge: no directory given".into()));
    };
    crate::output::prepare_dir(&m.out)?;
    crate::output::prepare_dir(&m.out.join("runs"))?;
    let same = |a: &Path, b: &Path| match (a.canonicalize(), b.canonicalize()) {
        (Ok(x), Ok(y)) => x == y,
        _ => false,
    };
    for (run, src) in &sources {
        if same(src, &m.out) {
            continue;
        }
        let from = src.join("runs").join(run.to_string());
        let to = m.out.join("runs").join(run.to_string());
        if to.exists() {
            std::fs::remove_dir_all(&to).map_err(|e| OutputError::io(to.display(), &e))?;
        }
        copy_dir(&from, &to).map_err(|e| OutputError::io(from.display(), &e))?;
    }
    let rows: Vec<Row> = rows.into_values().collect();
    j.shard = None;
    write_json(&m.out, "sweep.json", &j)?;
    write_index(&m.out, &j.keys, kind, &rows)?;
    write_plot(&m.out, &j.keys, &rows, default_plot(kind, &m.plot), out)?;
    let missing: Vec<usize> = (0..j.total_runs)
        .filter(|i| rows.binary_search_by_key(i, |r| r.run).is_err())
        .collect();
    let failed = rows.iter().filter(|r| r.status != "ok").count();
    writeln!(
        out,
        "merged {} of {} from {} into {} ({failed} failed, {} missing)",
        rows.len(),
        count(j.total_runs, "run", "runs"),
        count(m.dirs.len(), "directory", "directories"),
        m.out.display(),
        missing.len()
    )
    .map_err(OutputError::stdout)?;
    if !missing.is_empty() {
        let list: Vec<String> = missing.iter().take(20).map(ToString::to_string).collect();
        return Err(OutputError::Simulation(format!(
            "{} of {} missing: {}{} (run their shards again with --resume)",
            missing.len(),
            count(j.total_runs, "run", "runs"),
            list.join(", "),
            if missing.len() > 20 { ", …" } else { "" }
        )));
    }
    Ok(())
}

//! `viewer.html`: one self-contained page that animates a run in the
//! browser, offline (no network, no server).
//!
//! The Rust side computes everything that is drawn — every point of the
//! robot at every frame with `fbd_kinematics`, the contact and joint force
//! vectors, the contact states, the centre of mass, the time series — and
//! embeds it as JSON in the page ([`Scene`]); the page's own script
//! (`crates/output/assets/viewer.js`) only draws, with three.js (vendored at a
//! pinned version, `crates/output/assets/three.min.js`, MIT licence in
//! `crates/output/assets/THREE_LICENSE`) inlined into the page.
//!
//! * [`planar`] fills a scene from the planar model's step records, during
//!   `fbd run` or from `trajectory.csv` in `fbd view DIR` (side view);
//! * [`robot`] fills the one 3D scene, of every 3D model: the frames of a
//!   [`fbd_robot::RobotModel`] ([`robot::RobotFrames`]: base pose and joint
//!   angles, each contact point's state and ground force), its bodies drawn
//!   as capsules from joint to joint with `fbd_robot`'s forward kinematics,
//!   and what a model adds to that drawing as data ([`robot::Decor`]:
//!   points fixed in bodies, the root's outline, labels, a heading arrow,
//!   the support polygon, joint-force arrows, its panels);
//! * [`hexapod`] adapts the hexapod's runs (a kinematic gait, a dynamic 3D
//!   FBD run, or their `trajectory.csv`) to it: the hexapod is the robot
//!   model built from its D-H parameters (`fbd_robot::dh::hexapod`) with
//!   the hexapod's decor (body hexagon, leg numbers, heading, feet, forces);
//! * [`view`] is `fbd view DIR`.
//!
//! Long runs are decimated to at most [`MAX_FRAMES`] frames: every k-th
//! row, the last row, and every row at which a contact state changes (the
//! event frames, at most [`MAX_FRAMES`]/2 of them).

pub mod hexapod;
pub mod planar;
pub mod robot;
pub mod view;

use std::path::{Path, PathBuf};

use serde::Serialize;

use crate::OutputError;
use crate::output;

/// Most frames a page holds (see the module docs for which are kept).
pub const MAX_FRAMES: usize = 2000;

/// three.js r159, `build/three.min.js` of the npm package `three@0.159.0`:
/// the last release that ships a classic (UMD) build, which can be inlined
/// in a `<script>` of a page opened from `file://` (an inline module script
/// cannot import another `file://` module).
const THREE_JS: &str = include_str!("../../assets/three.min.js");
/// The page's own script: draws a [`Scene`].
const VIEWER_JS: &str = include_str!("../../assets/viewer.js");
/// The page's style sheet.
const VIEWER_CSS: &str = include_str!("../../assets/viewer.css");
/// three.js's licence, kept in the page beside the library.
const THREE_LICENSE: &str = include_str!("../../assets/THREE_LICENSE");

/// How a scene is viewed: `"planar"` (orthographic side view of the XY
/// plane) or `"robot"` (3D, orbiting camera: every 3D model, the hexapod
/// included).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SceneKind {
    /// The planar two-leg model (the default).
    #[default]
    Planar,
    /// A 3D robot model (an imported URDF/MJCF robot, the hexapod): its
    /// bodies drawn as capsules ([`robot`]).
    Robot,
}

/// A drawn segment between two points; `group` picks the colour (0 body,
/// then one per leg).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Line {
    /// First point index.
    pub a: usize,
    /// Second point index.
    pub b: usize,
    /// Colour group.
    pub group: usize,
}

/// A named point of the layout that carries a force or a state.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Marker {
    /// Name, e.g. `tip3` or `hip4`.
    pub name: String,
    /// Point index.
    pub point: usize,
}

/// The ground.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum TerrainView {
    /// The profile `y = ϱ(x)` sampled as `[x0, y0, x1, y1, …]`; the 3D
    /// view extrudes it along Z.
    Profile {
        /// Flattened samples (m).
        xy: Vec<f64>,
    },
    /// Heights `y = ϱ(x, z)` on an `n × n` grid over `[x0, x1] × [z0, z1]`,
    /// row by row (z outer, x inner) (3D).
    Grid {
        /// Grid corners (m).
        x0: f64,
        /// Grid corners (m).
        x1: f64,
        /// Grid corners (m).
        z0: f64,
        /// Grid corners (m).
        z1: f64,
        /// Samples per side.
        n: usize,
        /// Heights (m).
        y: Vec<f64>,
    },
    /// No ground (the default).
    #[default]
    None,
}

/// One curve of a time-series panel, one value per frame.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Curve {
    /// Legend label.
    pub label: String,
    /// Values (NaN written as null).
    pub v: Vec<Option<f64>>,
}

/// A time-series panel under the 3D view.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Panel {
    /// Title with the unit, e.g. `Normal forces (N)`.
    pub title: String,
    /// Its curves.
    pub curves: Vec<Curve>,
}

/// A contact event, drawn on the time axis of every panel.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct EventMark {
    /// Time (s).
    pub t: f64,
    /// Frame index at or after `t`.
    pub frame: usize,
    /// e.g. `leg 4 tip ST1→ST2`.
    pub label: String,
}

/// Everything the page draws. The default is an empty planar scene.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct Scene {
    /// Planar or 3D.
    pub model: SceneKind,
    /// Page title.
    pub title: String,
    /// Names of the drawn points.
    pub points: Vec<String>,
    /// Segments between them.
    pub lines: Vec<Line>,
    /// Contact points (coloured by state, with force arrows).
    pub contacts: Vec<Marker>,
    /// Joints (with joint-force arrows).
    pub joints: Vec<Marker>,
    /// Points whose path is drawn (the feet).
    pub trails: Vec<usize>,
    /// Contact indices around the body, in order, whose stance members form
    /// the support polygon (the hexapod's feet; empty for the planar model).
    pub ring: Vec<usize>,
    /// The ground.
    pub terrain: TerrainView,
    /// Friction patches `[x_min, x_max, z_min, z_max, μS, μD]` (m), drawn
    /// on the ground.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub patches: Vec<[f64; 6]>,
    /// Rows of the run (`trajectory.csv`).
    pub rows: usize,
    /// Row index of each frame.
    pub row: Vec<usize>,
    /// Time of each frame (s).
    pub t: Vec<f64>,
    /// Per frame: every point, `[x, y, z, x, y, z, …]` (m).
    pub p: Vec<Vec<f64>>,
    /// Per frame: one digit per contact, its state (1, 2, 3 for ST1–ST3).
    pub state: Vec<String>,
    /// Per frame: contact forces on the robot, `[x, y, z, …]` (N).
    pub fc: Vec<Vec<f64>>,
    /// Per frame: joint forces (parent on child), `[x, y, z, …]` (N).
    pub fj: Vec<Vec<f64>>,
    /// Per frame: centre of mass `[x, y, z]` (m).
    pub com: Vec<[f64; 3]>,
    /// Contact events.
    pub events: Vec<EventMark>,
    /// Rows of the run's `events.csv` (contact, joint-limit, retried-step
    /// and t = 0 events: the header's count; `events` marks the contact
    /// changes among them).
    pub event_rows: usize,
    /// Time-series panels.
    pub panels: Vec<Panel>,
    /// A dynamic run: contact states ST1/ST2/ST3 and force arrows
    /// (written only when true).
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub dynamic: bool,
}

/// Rounds to 6 significant decimals of a metre / newton scale (1e-6): the
/// page needs no more and the JSON stays compact.
pub(crate) fn round(x: f64) -> f64 {
    if x.is_finite() {
        let r = (x * 1e6).round() / 1e6;
        if r == 0.0 { 0.0 } else { r }
    } else {
        0.0
    }
}

/// The profile of `terrain` over the x-range of the frames' points
/// (`p`, `[x, y, z, …]` per frame), widened by half of it plus 1 m.
pub(crate) fn terrain_view(terrain: &fbd_contact::Terrain, p: &[Vec<f64>]) -> TerrainView {
    /// Samples of the terrain profile.
    const TERRAIN_SAMPLES: usize = 400;
    if !terrain.exists() {
        return TerrainView::None;
    }
    let (lo, hi) = p
        .iter()
        .flat_map(|p| p.chunks(3).map(|c| c[0]))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (-1.0, 1.0) };
    let pad = 1.0 + 0.5 * (hi - lo);
    let (a, b) = (lo - pad, hi + pad);
    let mut xy = Vec::with_capacity(2 * (TERRAIN_SAMPLES + 1));
    for i in 0..=TERRAIN_SAMPLES {
        let x = a + (b - a) * i as f64 / TERRAIN_SAMPLES as f64;
        let y = terrain.height(x);
        if y.is_finite() {
            xy.extend([round(x), round(y)]);
        }
    }
    TerrainView::Profile { xy }
}

/// Samples per side of a [`TerrainView::Grid`] (121 on a height map, to
/// draw its bumps and edges).
const GRID_SAMPLES: usize = 61;

/// The friction patches of the scene (see [`Scene::patches`]).
pub(crate) fn patch_views(patches: &[fbd_contact::FrictionPatch]) -> Vec<[f64; 6]> {
    patches
        .iter()
        .map(|p| {
            [
                p.x[0],
                p.x[1],
                p.z[0],
                p.z[1],
                p.friction.mu_static,
                p.friction.mu_dynamic,
            ]
            .map(round)
        })
        .collect()
}

/// The surface `y = ϱ(x, z)` over the x–z range of the frames' points
/// (`p`, `[x, y, z, …]` per frame), widened by 0.6 m on every side.
pub(crate) fn surface_view(surface: &fbd_contact::Surface, p: &[Vec<f64>]) -> TerrainView {
    if !surface.exists() {
        return TerrainView::None;
    }
    let mut lo = [f64::INFINITY; 2];
    let mut hi = [f64::NEG_INFINITY; 2];
    for c in p.iter().flat_map(|p| p.chunks(3)) {
        for (k, v) in [c[0], c[2]].into_iter().enumerate() {
            lo[k] = lo[k].min(v);
            hi[k] = hi[k].max(v);
        }
    }
    if lo[0] > hi[0] {
        (lo, hi) = ([-1.0; 2], [1.0; 2]);
    }
    // A square grid: the longer side sets the spacing.
    let half = 0.5 * (hi[0] - lo[0]).max(hi[1] - lo[1]) + 0.6;
    let (cx, cz) = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]));
    let (x0, x1, z0, z1) = (cx - half, cx + half, cz - half, cz + half);
    let n = if surface.grid().is_some() {
        2 * GRID_SAMPLES - 1
    } else {
        GRID_SAMPLES
    };
    let at = |a: f64, b: f64, i: usize| a + (b - a) * i as f64 / (n - 1) as f64;
    let mut y = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let h = surface.height(at(x0, x1, i), at(z0, z1, j));
            y.push(round(if h.is_finite() { h } else { 0.0 }));
        }
    }
    TerrainView::Grid {
        x0: round(x0),
        x1: round(x1),
        z0: round(z0),
        z1: round(z1),
        n,
        y,
    }
}

/// A time rounded to the nanosecond: `k·Δt` computed in floating point
/// and the decimal read back from `trajectory.csv` give the same value.
pub(crate) fn round_time(t: f64) -> f64 {
    if t.is_finite() {
        (t * 1e9).round() / 1e9
    } else {
        0.0
    }
}

/// A finite value, rounded, or `None`.
pub(crate) fn value(x: f64) -> Option<f64> {
    x.is_finite().then(|| round(x))
}

/// Which rows become frames: every `every`-th row, every row where
/// `changed` is true (up to [`MAX_FRAMES`]/2 of them), and the last row.
#[derive(Clone, Debug)]
pub struct Decimator {
    every: usize,
    events_kept: usize,
}

impl Decimator {
    /// For a run of `rows` rows.
    pub fn new(rows: usize) -> Self {
        let every = if rows <= MAX_FRAMES {
            1
        } else {
            rows.div_ceil(MAX_FRAMES / 2 - 1)
        };
        Self {
            every,
            events_kept: 0,
        }
    }

    /// Whether row `row` is a frame; `changed` when a contact state changed
    /// at it, `last` for the final row.
    pub fn keep(&mut self, row: usize, changed: bool, last: bool) -> bool {
        if row.is_multiple_of(self.every) || last {
            return true;
        }
        if changed && self.events_kept < MAX_FRAMES / 2 {
            self.events_kept += 1;
            return true;
        }
        false
    }
}

/// The frame index at or after time `t` (the last frame if none).
pub(crate) fn frame_at(t_frames: &[f64], t: f64) -> usize {
    let i = t_frames.partition_point(|&x| x < t - 1e-12);
    i.min(t_frames.len().saturating_sub(1))
}

/// Escapes `</` so that embedded text cannot close the `<script>` element.
fn script_safe(s: &str) -> String {
    s.replace("</", "<\\/")
}

/// The complete page for `scene`.
pub fn render(scene: &Scene) -> Result<String, OutputError> {
    render_json(scene, &scene.title)
}

/// The complete page for any serializable scene: a [`Scene`], or one with
/// fields of its own beside a flattened [`Scene`] (a robot's
/// [`robot::RobotScene`]), titled `title`.
pub fn render_json<S: Serialize>(scene: &S, title: &str) -> Result<String, OutputError> {
    let json = serde_json::to_string(scene)
        .map_err(|e| OutputError::Io(format!("viewer.html: cannot encode the scene: {e}")))?;
    let title = title
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;");
    let mut page = String::with_capacity(THREE_JS.len() + json.len() + VIEWER_JS.len() + 4096);
    page.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
    page.push_str(&format!("<title>fbd viewer — {title}</title>\n"));
    page.push_str("<style>\n");
    page.push_str(VIEWER_CSS);
    page.push_str("</style>\n</head>\n<body>\n");
    page.push_str(BODY_HTML);
    page.push_str("<script>\n/*\nthree.js r159 (npm three@0.159.0, build/three.min.js)\n");
    page.push_str(&THREE_LICENSE.replace("*/", "* /"));
    page.push_str("*/\n");
    page.push_str(&script_safe(THREE_JS));
    page.push_str("\n</script>\n<script id=\"fbd-scene\" type=\"application/json\">");
    page.push_str(&script_safe(&json));
    page.push_str("</script>\n<script>\n");
    page.push_str(&script_safe(VIEWER_JS));
    page.push_str("\n</script>\n</body>\n</html>\n");
    Ok(page)
}

/// The page's markup: the 3D view, the controls, the panels.
const BODY_HTML: &str = r#"<header><h1 id="title">fbd viewer</h1><span id="info"></span></header>
<main>
<div id="view"><canvas id="canvas3d"></canvas><div id="legend"></div><div id="overlay"></div></div>
<div id="controls">
<button id="play" title="play / pause (space)">▶ play</button>
<button id="step-back" title="previous frame (←)">◀|</button>
<button id="step" title="next frame (→)">|▶</button>
<input id="slider" type="range" min="0" max="0" value="0" step="1" aria-label="time">
<span id="time">t = 0 s</span>
<label>speed <select id="speed"><option>0.1</option><option>0.25</option><option>0.5</option><option selected>1</option><option>2</option><option>4</option></select>×</label>
<label><input id="show-contact" type="checkbox" checked> contact forces</label>
<label><input id="show-joint" type="checkbox"> joint forces</label>
<label><input id="show-trails" type="checkbox" checked> trails</label>
<label><input id="follow" type="checkbox" checked> follow</label>
</div>
<div id="panels"></div>
</main>
"#;

/// The page title of a run of `model` (e.g. `hexapod, 3D dynamics`): the
/// model, never the output folder, and the same for `fbd run` and `fbd
/// view` of its folder (which repeats the page byte for byte); `_source`
/// (the configuration's name) is not in it for that reason.
pub fn title_of(_source: &str, model: &str) -> String {
    model.to_owned()
}

/// Writes `dir/viewer.html` all-or-nothing.
pub fn write(dir: &Path, scene: &Scene) -> Result<PathBuf, OutputError> {
    let page = render(scene)?;
    output::write_file(dir, "viewer.html", page.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decimator_keeps_all_rows_of_a_short_run() {
        let mut d = Decimator::new(MAX_FRAMES);
        let kept = (0..MAX_FRAMES)
            .filter(|&r| d.keep(r, false, r + 1 == MAX_FRAMES))
            .count();
        assert_eq!(kept, MAX_FRAMES);
    }

    #[test]
    fn decimator_bounds_long_runs_and_keeps_events() {
        let rows = 600_001;
        let mut d = Decimator::new(rows);
        let events = [12_345, 300_001, 599_999];
        let kept: Vec<usize> = (0..rows)
            .filter(|&r| d.keep(r, events.contains(&r), r + 1 == rows))
            .collect();
        assert!(kept.len() <= MAX_FRAMES, "{} frames", kept.len());
        assert!(kept.len() >= MAX_FRAMES / 2 - 1, "{} frames", kept.len());
        for e in events {
            assert!(kept.binary_search(&e).is_ok(), "event row {e} dropped");
        }
        assert_eq!(kept.last(), Some(&(rows - 1)));
    }

    #[test]
    fn embedded_text_cannot_close_the_script() {
        assert_eq!(script_safe("a</script>b"), "a<\\/script>b");
    }
}

//! The SVG plots of `fbd run`: the two graphs of the paper's Fig. 7
//! (`tips.svg`: tip positions versus time; `forces.svg`: contact forces of
//! every point that ever touched), `joints.svg` (joint angles),
//! `torques.svg` (actuator torques, when any), `energy.svg` (kinetic,
//! potential, total) and a Fig. 6-like drawing of the structure at regular
//! instants (`stance.svg`).
//!
//! How the curves are drawn:
//!
//! * every step of the run is recorded ([`PlotRecorder`]), reduced on the
//!   fly to the first, smallest, largest and last value of each of
//!   [`COLUMNS`] time columns ([`MinMax`]): a 600 000-step run plots in a
//!   few thousand points per curve and keeps its peaks;
//! * a curve is one SVG polyline; a dashed curve carries
//!   `stroke-dasharray` (never one element per dash), and its legend
//!   sample is dashed the same way;
//! * the legend sits beside the plot, never over a curve; curves that
//!   coincide stay visible (solid and dashed alternate, later curves on
//!   top);
//! * every contact-event line is labelled (leg, point, new state) at the
//!   top of the plot; events closer than a few pixels share a label.

use fbd_contact::{StateCode, Terrain};
use fbd_dynamics::{ContactSpec, PointKind};
use fbd_sim::{Event, RobotRecord};

use crate::output::{ContactSlots, PLANAR_LEGS};
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;
use plotters::style::text_anchor::{HPos, Pos, VPos};

/// The structure at one instant (inertial x, y in metres).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Stance {
    /// Time (s).
    pub t: f64,
    /// Hips of legs 3 and 4.
    pub hip: [[f64; 2]; 2],
    /// Knees of legs 3 and 4.
    pub knee: [[f64; 2]; 2],
    /// Tips of legs 3 and 4.
    pub tip: [[f64; 2]; 2],
}

/// One curve: `(t, value)` points in time order; a NaN value breaks the
/// line.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Trace {
    /// Legend label.
    pub label: String,
    /// The points.
    pub pts: Vec<(f64, f64)>,
}

/// A contact event drawn as a labelled vertical line.
#[derive(Clone, Debug, PartialEq)]
pub struct EventMark {
    /// Time (s).
    pub t: f64,
    /// Short label, e.g. `4 tip ST2`.
    pub label: String,
}

impl EventMark {
    /// The mark of a contact event: leg, point and new state.
    pub fn of(e: &Event) -> Self {
        Self {
            t: e.t,
            label: format!("{} {} {}", e.leg, e.point, e.to.as_str()),
        }
    }
}

/// Everything the plots show.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlotData {
    /// Tip positions: tip 3 x, tip 3 y, tip 4 x, tip 4 y (m).
    pub tips: Vec<Trace>,
    /// Normal force of every contact point that ever touched (N).
    pub normal: Vec<Trace>,
    /// Tangential force of the same points, same order (N).
    pub tangential: Vec<Trace>,
    /// The leg and kind of the same points, same order (their colours).
    pub points: Vec<(usize, PointKind)>,
    /// Joint angles θ2₃, θ3₃, θ2₄, θ3₄ (degrees).
    pub joints: Vec<Trace>,
    /// Joint torques, hip 3, knee 3, hip 4, knee 4 (N·m); empty when every
    /// torque is zero (a passive run).
    pub torques: Vec<Trace>,
    /// Kinetic, potential and total energy (J).
    pub energy: Vec<Trace>,
    /// Contact events.
    pub events: Vec<EventMark>,
    /// Snapshots of the structure.
    pub stances: Vec<Stance>,
    /// The ground.
    pub terrain: Option<Terrain>,
}

/// Time columns of the min/max reduction of every curve (a little more
/// than the plot's width in pixels).
pub const COLUMNS: usize = 1000;

/// The time columns of a run from `t0` to `t1`: [`COLUMNS`] equal spans.
/// A recorder of several curves finds a step's column once
/// ([`Self::of`]) and hands it to each curve ([`MinMax::push_at`]).
#[derive(Clone, Copy, Debug)]
pub struct Columns {
    t0: f64,
    per_second: f64,
}

impl Columns {
    /// For times from `t0` to `t1`.
    pub fn new(t0: f64, t1: f64) -> Self {
        let span = if t1 > t0 { t1 - t0 } else { 1.0 };
        Self {
            t0,
            per_second: COLUMNS as f64 / span,
        }
    }

    /// The column of time `t`: `⌊(t − t0)·COLUMNS / span⌋`. The floor is
    /// taken by truncation and a correction below zero (exactly
    /// `f64::floor` for every value in `i64`'s range) rather than by a
    /// libm call: it runs for every recorded step.
    #[inline]
    pub fn of(&self, t: f64) -> i64 {
        let x = (t - self.t0) * self.per_second;
        let c = x as i64;
        if (c as f64) > x { c - 1 } else { c }
    }
}

/// Reduces a curve on the fly to at most four points per time column: the
/// first, the smallest, the largest and the last value, in time order. A
/// non-finite value breaks the line.
#[derive(Clone, Debug)]
pub struct MinMax {
    columns: Columns,
    column: Option<i64>,
    first: (f64, f64),
    lo: (f64, f64),
    hi: (f64, f64),
    last: (f64, f64),
    out: Vec<(f64, f64)>,
}

impl MinMax {
    /// For times from `t0` to `t1`.
    pub fn new(t0: f64, t1: f64) -> Self {
        Self {
            columns: Columns::new(t0, t1),
            column: None,
            first: (0.0, 0.0),
            lo: (0.0, 0.0),
            hi: (0.0, 0.0),
            last: (0.0, 0.0),
            out: Vec::with_capacity(4 * COLUMNS + 8),
        }
    }

    /// Adds the value `v` at time `t` (times increasing).
    pub fn push(&mut self, t: f64, v: f64) {
        self.push_at(self.columns.of(t), t, v);
    }

    /// [`Self::push`] with `t`'s column `c` already found
    /// ([`Columns::of`] of the same `t0`, `t1`). The common case, a finite
    /// value in the current column, is two compares whose branches are seldom
    /// taken (a new extreme); the branches cost half what selects of the
    /// `(t, v)` pairs did.
    #[inline]
    pub fn push_at(&mut self, c: i64, t: f64, v: f64) {
        if !v.is_finite() {
            self.missing(t);
            return;
        }
        if self.column == Some(c) {
            // Strict comparisons: the earliest extreme is kept.
            if v < self.lo.1 {
                self.lo = (t, v);
            }
            if v > self.hi.1 {
                self.hi = (t, v);
            }
            self.last = (t, v);
        } else {
            self.flush();
            self.column = Some(c);
            self.first = (t, v);
            self.lo = (t, v);
            self.hi = (t, v);
            self.last = (t, v);
        }
    }

    /// A non-finite value at `t`: the line breaks.
    #[cold]
    fn missing(&mut self, t: f64) {
        self.flush();
        if self.out.last().is_some_and(|p| p.1.is_finite()) {
            self.out.push((t, f64::NAN));
        }
    }

    fn flush(&mut self) {
        if self.column.take().is_none() {
            return;
        }
        let (a, b) = if self.lo.0 <= self.hi.0 {
            (self.lo, self.hi)
        } else {
            (self.hi, self.lo)
        };
        for p in [self.first, a, b, self.last] {
            if self.out.last() != Some(&p) {
                self.out.push(p);
            }
        }
    }

    /// The reduced curve.
    pub fn finish(mut self) -> Vec<(f64, f64)> {
        self.flush();
        self.out
    }
}

/// Gathers the curves of a planar run step by step (every step, not only
/// the rows of `trajectory.csv`).
pub struct PlotRecorder {
    /// The time columns of every curve below.
    columns: Columns,
    names: Vec<String>,
    points: Vec<(usize, PointKind)>,
    tips: [Option<usize>; 2],
    touched: Vec<bool>,
    tip: [MinMax; 4],
    normal: Vec<MinMax>,
    tangential: Vec<MinMax>,
    joints: [MinMax; 4],
    torques: [MinMax; 4],
    torque_used: bool,
    energy: [MinMax; 3],
}

impl PlotRecorder {
    /// For a run from `t = 0` to `t_end` of a model whose contact points
    /// are `contacts` (record order); the tips are found by `{leg, kind}`
    /// ([`ContactSlots`]).
    pub fn new(contacts: &[ContactSpec], t_end: f64) -> Self {
        let m = || MinMax::new(0.0, t_end);
        Self {
            columns: Columns::new(0.0, t_end),
            names: contacts.iter().map(|c| c.name.clone()).collect(),
            points: contacts.iter().map(|c| (c.leg, c.kind)).collect(),
            tips: ContactSlots::of(contacts).tips,
            touched: vec![false; contacts.len()],
            tip: std::array::from_fn(|_| m()),
            normal: contacts.iter().map(|_| m()).collect(),
            tangential: contacts.iter().map(|_| m()).collect(),
            joints: std::array::from_fn(|_| m()),
            torques: std::array::from_fn(|_| m()),
            torque_used: false,
            energy: std::array::from_fn(|_| m()),
        }
    }

    /// Adds one step.
    ///
    /// Runs for every step of the run, inside the stepping loop: the step's
    /// time column is found once for all the curves ([`Columns::of`]), and
    /// nothing is looked up by name or allocated.
    pub fn push(&mut self, r: &RobotRecord) {
        let t = r.t;
        let col = self.columns.of(t);
        for (leg, c) in self.tips.iter().enumerate() {
            let p = c.map_or([f64::NAN; 2], |c| {
                let p = r.contacts[c].point;
                [p[0], p[1]]
            });
            self.tip[2 * leg].push_at(col, t, p[0]);
            self.tip[2 * leg + 1].push_at(col, t, p[1]);
        }
        let rows = self
            .touched
            .iter_mut()
            .zip(&mut self.normal)
            .zip(&mut self.tangential)
            .zip(&r.contacts);
        for (((touched, normal), tangential), row) in rows {
            *touched |= row.state != StateCode::St1;
            normal.push_at(col, t, row.normal);
            tangential.push_at(col, t, row.tangential[0]);
        }
        // The joints after the root (`Rx, Ry, Rz, φx, φy, φz`).
        for (m, q) in self.joints.iter_mut().zip(&r.q[6..]) {
            m.push_at(col, t, q.to_degrees());
        }
        for (m, &tau) in self.torques.iter_mut().zip(&r.torque) {
            m.push_at(col, t, tau);
            self.torque_used |= tau != 0.0;
        }
        self.energy[0].push_at(col, t, r.kinetic);
        self.energy[1].push_at(col, t, r.potential);
        self.energy[2].push_at(col, t, r.kinetic + r.potential);
    }

    /// The plot data; `stances` and `terrain` come from the caller.
    pub fn finish(
        self,
        events: &[Event],
        stances: Vec<Stance>,
        terrain: Option<Terrain>,
    ) -> PlotData {
        let traces = |labels: &[&str], ms: Vec<MinMax>| -> Vec<Trace> {
            labels
                .iter()
                .zip(ms)
                .map(|(l, m)| Trace {
                    label: (*l).to_owned(),
                    pts: m.finish(),
                })
                .collect()
        };
        let mut normal = Vec::new();
        let mut tangential = Vec::new();
        let mut points = Vec::new();
        for ((((name, point), n), fa), touched) in self
            .names
            .iter()
            .zip(&self.points)
            .zip(self.normal)
            .zip(self.tangential)
            .zip(&self.touched)
        {
            if *touched {
                points.push(*point);
                normal.push(Trace {
                    label: format!("n {name}"),
                    pts: n.finish(),
                });
                tangential.push(Trace {
                    label: format!("fa {name}"),
                    pts: fa.finish(),
                });
            }
        }
        PlotData {
            tips: traces(&["tip3 x", "tip3 y", "tip4 x", "tip4 y"], self.tip.into()),
            normal,
            tangential,
            points,
            joints: traces(
                &["θ2 leg 3", "θ3 leg 3", "θ2 leg 4", "θ3 leg 4"],
                self.joints.into(),
            ),
            torques: if self.torque_used {
                traces(&["hip 3", "knee 3", "hip 4", "knee 4"], self.torques.into())
            } else {
                Vec::new()
            },
            energy: traces(&["kinetic", "potential", "total"], self.energy.into()),
            events: events.iter().map(EventMark::of).collect(),
            stances,
            terrain,
        }
    }
}

pub(crate) type PlotResult<T> = Result<T, String>;

pub(crate) fn err<E: std::fmt::Debug>(e: E) -> String {
    format!("plotting failed: {e:?}")
}

const LEG3: RGBColor = RGBColor(31, 119, 180);
const LEG3_LIGHT: RGBColor = RGBColor(120, 180, 230);
const LEG4: RGBColor = RGBColor(214, 39, 40);
const LEG4_LIGHT: RGBColor = RGBColor(245, 140, 60);
const EVENT: RGBColor = RGBColor(150, 150, 150);
const GROUND: RGBColor = RGBColor(120, 85, 45);
/// Colours of the contact points in `forces.svg`, by kind and leg
/// (tip, knee, hip × leg 3, leg 4).
const POINT_COLORS: [[RGBColor; 2]; 3] = [
    [LEG3, LEG4],
    [RGBColor(44, 160, 44), RGBColor(148, 103, 189)],
    [RGBColor(140, 86, 75), RGBColor(227, 119, 194)],
];
/// A palette for anything else (also the lines of `sweep.svg`).
pub const PALETTE: [RGBColor; 8] = [
    RGBColor(31, 119, 180),
    RGBColor(214, 39, 40),
    RGBColor(44, 160, 44),
    RGBColor(255, 127, 14),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(23, 190, 207),
];
/// Dash pattern of dashed curves and of event lines (px).
const DASH: &str = "9 5";
/// Dash length of interleaved dashed curves (px).
const DASH_ON: usize = 7;
const EVENT_DASH: &str = "4 4";
/// Samples of the terrain profile drawn in `stance.svg`.
const TERRAIN_SAMPLES: usize = 400;
/// Width of the legend column beside a chart (px).
pub(crate) const LEGEND_WIDTH: u32 = 190;

/// The legend box every chart draws, upper right.
pub(crate) fn draw_legend<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
) -> Result<(), String> {
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::UpperRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK)
        .draw()
        .map_err(err)
}

/// A legend marker: a short horizontal line in `color`.
pub(crate) fn legend_line(
    color: RGBColor,
    width: u32,
) -> impl Fn((i32, i32)) -> PathElement<(i32, i32)> {
    move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], color.stroke_width(width))
}

/// Tick label without `-0` and with no more digits than needed.
pub(crate) fn tick(v: &f64) -> String {
    let v = if v.abs() < 1e-12 { 0.0 } else { *v };
    let s = format!("{v:.6}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    s.to_owned()
}

/// Tick label of an axis spanning `span`, less than 1e-3: three
/// significant digits in scientific notation (`-1.25e-8`), so that the
/// ticks stay distinct; 0 for rounding noise (below 1e-6 of the span).
pub(crate) fn tick_small(v: f64, span: f64) -> String {
    if v.abs() <= 1e-6 * span {
        "0".to_owned()
    } else {
        format!("{v:.2e}")
    }
}

/// Finite min/max of `values`, widened when degenerate; `(0, 1)` when
/// nothing is finite.
pub(crate) fn range<'a>(values: impl IntoIterator<Item = &'a f64>) -> (f64, f64) {
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    for &v in values {
        if v.is_finite() {
            lo = lo.min(v);
            hi = hi.max(v);
        }
    }
    if lo > hi {
        return (0.0, 1.0);
    }
    let pad = if hi > lo {
        0.05 * (hi - lo)
    } else {
        0.5 * lo.abs().max(1e-3)
    };
    (lo - pad, hi + pad)
}

/// How a curve is drawn.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Style {
    /// Colour.
    pub color: RGBColor,
    /// Stroke width (px).
    pub width: u32,
    /// Dashed (`stroke-dasharray`, see [`dash`]).
    pub dashed: bool,
}

/// The SVG attribute text plotters writes for a stroke of `color`, `width`.
fn stroke_attr(color: RGBColor, width: u32) -> String {
    format!(
        "stroke=\"#{:02X}{:02X}{:02X}\" stroke-width=\"{width}\"",
        color.0, color.1, color.2
    )
}

/// Makes every stroke of `(color, width)` dashed with `pattern`: one
/// element per curve, whatever its length. Each dashed style's colour
/// and width are unique in its chart.
fn dash(svg: &mut String, color: RGBColor, width: u32, pattern: &str) {
    let a = stroke_attr(color, width);
    let b = format!("{a} stroke-dasharray=\"{pattern}\"");
    *svg = svg.replace(&a, &b);
}

/// A legend entry in the column beside the chart.
pub(crate) struct Entry {
    /// Text.
    pub label: String,
    /// Its line sample.
    pub style: Style,
}

/// Draws the legend entries in `area`, top-down.
pub(crate) fn side_legend<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    entries: &[Entry],
) -> PlotResult<()> {
    let font = ("sans-serif", 13).into_font().color(&BLACK);
    for (i, e) in entries.iter().enumerate() {
        let y = 50 + 20 * i as i32;
        area.draw(&PathElement::new(
            vec![(6, y), (40, y)],
            e.style.color.stroke_width(e.style.width),
        ))
        .map_err(err)?;
        area.draw(&Text::new(
            e.label.clone(),
            (46, y),
            font.pos(Pos::new(HPos::Left, VPos::Center)),
        ))
        .map_err(err)?;
    }
    Ok(())
}

/// Draws `pts` as one polyline per run of finite points, without the
/// points that change nothing on screen: one landing on the pixel of the
/// previous point kept, or inside a horizontal stretch.
fn draw_trace<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    pts: &[(f64, f64)],
    style: Style,
) -> PlotResult<()> {
    for run in pts.split(|p| !(p.0.is_finite() && p.1.is_finite())) {
        let mut kept: Vec<((f64, f64), (i32, i32))> = Vec::with_capacity(run.len());
        for &p in run {
            let px = chart.backend_coord(&p);
            match kept.as_slice() {
                [.., (_, last)] if *last == px => continue,
                [.., (_, a), (_, b)] if a.1 == b.1 && b.1 == px.1 => {
                    let n = kept.len();
                    kept[n - 1] = (p, px);
                }
                _ => kept.push((p, px)),
            }
        }
        if kept.is_empty() {
            continue;
        }
        chart
            .draw_series(LineSeries::new(
                kept.into_iter().map(|k| k.0),
                style.color.stroke_width(style.width),
            ))
            .map_err(err)?;
    }
    Ok(())
}

/// Events closer than this (pixels) share one label: a rotated label of
/// the 11 px font is about 13 px wide.
const EVENT_GROUP_PX: i32 = 14;

/// Draws the event lines and their labels (rotated, at the top; events
/// within [`EVENT_GROUP_PX`] share one label, the first event's followed
/// by `+N` for the N others, as the legend says).
fn draw_events<'a, DB: DrawingBackend + 'a>(
    chart: &mut ChartContext<'a, DB, Cartesian2d<RangedCoordf64, RangedCoordf64>>,
    events: &[EventMark],
    y: (f64, f64),
) -> PlotResult<()> {
    let (x0, x1) = {
        let r = chart.x_range();
        (r.start, r.end)
    };
    let mut groups: Vec<(i32, f64, Vec<&str>)> = Vec::new();
    for e in events.iter().filter(|e| e.t >= x0 && e.t <= x1) {
        let px = chart.backend_coord(&(e.t, y.1)).0;
        match groups.last_mut() {
            Some(g) if (px - g.0).abs() < EVENT_GROUP_PX => {
                if !g.2.contains(&e.label.as_str()) {
                    g.2.push(&e.label);
                }
            }
            _ => groups.push((px, e.t, vec![&e.label])),
        }
    }
    let font = ("sans-serif", 11)
        .into_font()
        .transform(FontTransform::Rotate270)
        .color(&RGBColor(90, 90, 90));
    for (_, t, labels) in &groups {
        chart
            .draw_series(LineSeries::new(
                [(*t, y.0), (*t, y.1)],
                EVENT.stroke_width(1),
            ))
            .map_err(err)?;
        let text = match labels.as_slice() {
            [a] => (*a).to_owned(),
            [a, rest @ ..] => format!("{a} +{}", rest.len()),
            [] => String::new(),
        };
        let (px, py) = chart.backend_coord(&(*t, y.1));
        chart
            .plotting_area()
            .strip_coord_spec()
            .draw(&Text::new(
                text,
                (
                    px + 2 - chart.plotting_area().get_base_pixel().0,
                    py + 4 - chart.plotting_area().get_base_pixel().1,
                ),
                font.pos(Pos::new(HPos::Right, VPos::Top)),
            ))
            .map_err(err)?;
    }
    Ok(())
}

/// One chart of [`stacked_time_chart`]: caption, y-axis description and
/// its curves.
pub(crate) type ChartSpec<'a> = (&'a str, &'a str, &'a [(&'a Trace, Style)]);

/// A chart of curves against time, legend beside it, events labelled.
pub(crate) fn time_chart(
    title: &str,
    y_desc: &str,
    series: &[(&Trace, Style)],
    events: &[EventMark],
    t_range: (f64, f64),
) -> PlotResult<String> {
    stacked_time_chart(None, &[(title, y_desc, series)], events, t_range)
}

/// Charts of curves against one time axis, stacked top to bottom (each
/// `(caption, y_desc, series)` 540 px high, the `title` above them all
/// when given), one legend beside them listing every series, events
/// labelled on every chart. Dashed styles must be unique over all charts.
pub(crate) fn stacked_time_chart(
    title: Option<&str>,
    panels: &[ChartSpec<'_>],
    events: &[EventMark],
    t_range: (f64, f64),
) -> PlotResult<String> {
    const PANEL_HEIGHT: u32 = 540;
    const TITLE_HEIGHT: u32 = 40;
    let mut buf = String::new();
    let head = if title.is_some() { TITLE_HEIGHT } else { 0 };
    let height = head + PANEL_HEIGHT * panels.len().max(1) as u32;
    {
        let root =
            SVGBackend::with_string(&mut buf, (960 + LEGEND_WIDTH, height)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let body = match title {
            Some(title) => {
                let (top, body) = root.split_vertically(head);
                top.draw(&Text::new(
                    title.to_owned(),
                    (480, (head / 2) as i32),
                    ("sans-serif", 24)
                        .into_font()
                        .color(&BLACK)
                        .pos(Pos::new(HPos::Center, VPos::Center)),
                ))
                .map_err(err)?;
                body
            }
            None => root.clone(),
        };
        let (left, right) = body.split_horizontally(960);
        let areas = left.split_evenly((panels.len().max(1), 1));
        for ((caption, y_desc, series), area) in panels.iter().zip(&areas) {
            time_panel(area, caption, y_desc, series, events, t_range)?;
        }
        // One entry per label and style (a curve of the same leg in each
        // chart is listed once).
        let mut entries: Vec<Entry> = Vec::new();
        for (t, s) in panels.iter().flat_map(|p| p.2.iter()) {
            if !entries.iter().any(|e| e.label == t.label && e.style == *s) {
                entries.push(Entry {
                    label: t.label.clone(),
                    style: *s,
                });
            }
        }
        if !events.is_empty() {
            entries.push(Entry {
                label: "event (+N: N more there)".into(),
                style: Style {
                    color: EVENT,
                    width: 1,
                    dashed: true,
                },
            });
        }
        side_legend(&right, &entries)?;
        root.present().map_err(err)?;
    }
    // Dashed curves interleave their dashes (a dash of each in turn), so
    // that coinciding dashed curves all show.
    let dashed: Vec<Style> = panels
        .iter()
        .flat_map(|p| p.2.iter())
        .filter(|s| s.1.dashed)
        .map(|s| s.1)
        .collect();
    let phases = dashed.len().clamp(1, 3);
    for (j, s) in dashed.iter().enumerate() {
        let pattern = if phases == 1 {
            DASH.to_owned()
        } else {
            format!(
                "{DASH_ON} {}\" stroke-dashoffset=\"{}",
                DASH_ON * (phases - 1),
                DASH_ON * (j % phases)
            )
        };
        dash(&mut buf, s.color, s.width, &pattern);
    }
    dash(&mut buf, EVENT, 1, EVENT_DASH);
    Ok(buf)
}

/// One chart of [`stacked_time_chart`] in `area`.
fn time_panel<DB: DrawingBackend>(
    area: &DrawingArea<DB, plotters::coord::Shift>,
    caption: &str,
    y_desc: &str,
    series: &[(&Trace, Style)],
    events: &[EventMark],
    t_range: (f64, f64),
) -> PlotResult<()> {
    let (y0, y1) = range(series.iter().flat_map(|s| s.0.pts.iter().map(|p| &p.1)));
    // Room above the curves for the event labels.
    let y1 = if events.is_empty() {
        y1
    } else {
        y1 + 0.18 * (y1 - y0)
    };
    let mut chart = ChartBuilder::on(area)
        .caption(caption, ("sans-serif", 22))
        .margin(14)
        .x_label_area_size(48)
        .y_label_area_size(70)
        .build_cartesian_2d(t_range.0..t_range.1, y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .y_desc(y_desc)
        .x_label_formatter(&tick)
        .y_label_formatter(&|v: &f64| {
            if y1 - y0 < 1e-3 {
                tick_small(*v, y1 - y0)
            } else {
                tick(v)
            }
        })
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(err)?;
    draw_events(&mut chart, events, (y0, y1))?;
    // Solid curves first, dashed ones on top: coinciding curves show
    // both colours.
    for (trace, style) in series.iter().filter(|s| !s.1.dashed) {
        draw_trace(&mut chart, &trace.pts, *style)?;
    }
    for (trace, style) in series.iter().filter(|s| s.1.dashed) {
        draw_trace(&mut chart, &trace.pts, *style)?;
    }
    Ok(())
}

/// The time axis: from the first to the last point of any curve.
fn time_range(d: &PlotData) -> (f64, f64) {
    let ts = d
        .tips
        .iter()
        .chain(&d.energy)
        .chain(&d.joints)
        .flat_map(|t| t.pts.iter().map(|p| &p.0));
    let (lo, hi) = ts.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &t| {
        (a.min(t), b.max(t))
    });
    if lo < hi { (lo, hi) } else { (0.0, 1.0) }
}

/// Solid `strong` for the first of each pair, dashed `light` for the
/// second: `[(a, solid), (b, dashed)]` per leg.
fn paired(traces: &[Trace]) -> Vec<(&Trace, Style)> {
    let colors = [LEG3, LEG3_LIGHT, LEG4, LEG4_LIGHT];
    traces
        .iter()
        .zip(colors)
        .enumerate()
        .map(|(i, (t, color))| {
            (
                t,
                Style {
                    color,
                    width: 2,
                    dashed: i % 2 == 1,
                },
            )
        })
        .collect()
}

/// `tips.svg`: x and y of both tips versus time (Fig. 7, graph 1).
pub fn tips_svg(d: &PlotData) -> PlotResult<String> {
    time_chart(
        "Tip positions of legs 3 and 4 (inertial frame)",
        "position (m)",
        &paired(&d.tips),
        &d.events,
        time_range(d),
    )
}

/// The colour of a contact point by its `{leg, kind}` ([`POINT_COLORS`]);
/// `PALETTE[fallback]` for a point of another leg or none.
fn point_color(point: Option<&(usize, PointKind)>, fallback: usize) -> RGBColor {
    let colors = point.and_then(|&(leg, kind)| {
        let l = PLANAR_LEGS.iter().position(|&n| n == leg)?;
        let k = match kind {
            PointKind::Tip => 0,
            PointKind::Knee => 1,
            PointKind::Hip => 2,
        };
        Some(POINT_COLORS[k][l])
    });
    colors.unwrap_or(PALETTE[fallback % PALETTE.len()])
}

/// `color` mixed with white by `f` (0 = unchanged).
fn lighter(c: RGBColor, f: f64) -> RGBColor {
    let m = |v: u8| (f64::from(v) + f * (255.0 - f64::from(v))).round() as u8;
    RGBColor(m(c.0), m(c.1), m(c.2))
}

/// `forces.svg`: normal (solid) and tangential (dashed, lighter) force of
/// every contact point that ever touched (Fig. 7, graph 2).
pub fn forces_svg(d: &PlotData) -> PlotResult<String> {
    let mut series = Vec::new();
    for (i, (n, fa)) in d.normal.iter().zip(&d.tangential).enumerate() {
        let c = point_color(d.points.get(i), i);
        series.push((
            n,
            Style {
                color: c,
                width: 2,
                dashed: false,
            },
        ));
        series.push((
            fa,
            Style {
                color: lighter(c, 0.45),
                width: 2,
                dashed: true,
            },
        ));
    }
    // An impact's peak would flatten every other force: the axis is
    // clipped at three times the 95th percentile of the forces (rounded
    // up to 1, 2 or 5 × 10ⁿ N) when the peak is beyond 1.5 times that, and
    // the title gives the peak.
    let mut mags: Vec<f64> = series
        .iter()
        .flat_map(|(t, _)| t.pts.iter().map(|p| p.1.abs()))
        .filter(|v| v.is_finite() && *v > 0.0)
        .collect();
    mags.sort_by(f64::total_cmp);
    let peak = series
        .iter()
        .flat_map(|(t, _)| t.pts.iter().map(move |p| (p.1.abs(), p.0, &t.label)))
        .filter(|p| p.0.is_finite())
        .max_by(|a, b| a.0.total_cmp(&b.0));
    let clip = mags
        .get((mags.len().saturating_sub(1) * 95) / 100)
        .map(|q| round_up_125(3.0 * q));
    let title = "Contact forces: normal n (solid), tangential fa (dashed)";
    match (clip, peak) {
        (Some(clip), Some((p, t, label))) if p > 1.5 * clip => {
            let clipped: Vec<Trace> = series
                .iter()
                .map(|(tr, _)| Trace {
                    label: tr.label.clone(),
                    pts: tr
                        .pts
                        .iter()
                        .map(|&(x, v)| (x, v.clamp(-clip, clip)))
                        .collect(),
                })
                .collect();
            let styled: Vec<(&Trace, Style)> =
                clipped.iter().zip(series.iter().map(|s| s.1)).collect();
            time_chart(
                &format!(
                    "{title}; axis clipped at ±{clip} N: peak {p:.0} N ({label}, t = {} s)",
                    tick(&t)
                ),
                "force (N)",
                &styled,
                &d.events,
                time_range(d),
            )
        }
        _ => time_chart(title, "force (N)", &series, &d.events, time_range(d)),
    }
}

/// The smallest 1, 2 or 5 × 10ⁿ at or above `x` (> 0).
fn round_up_125(x: f64) -> f64 {
    let e = 10f64.powf(x.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * e)
        .find(|v| *v >= x * (1.0 - 1e-12))
        .unwrap_or(10.0 * e)
}

/// `joints.svg`: the joint angles of legs 3 and 4.
pub fn joints_svg(d: &PlotData) -> PlotResult<String> {
    time_chart(
        "Joint angles of legs 3 and 4",
        "angle (°)",
        &paired(&d.joints),
        &d.events,
        time_range(d),
    )
}

/// `torques.svg`: the actuator torques; `None` for a passive run.
pub fn torques_svg(d: &PlotData) -> Option<PlotResult<String>> {
    (!d.torques.is_empty()).then(|| {
        time_chart(
            "Joint torques (hips solid, knees dashed)",
            "torque (N·m)",
            &paired(&d.torques),
            &d.events,
            time_range(d),
        )
    })
}

/// `energy.svg`: kinetic, potential and total mechanical energy.
pub fn energy_svg(d: &PlotData) -> PlotResult<String> {
    let styles = [
        Style {
            color: RGBColor(255, 127, 14),
            width: 2,
            dashed: false,
        },
        Style {
            color: LEG3,
            width: 2,
            dashed: false,
        },
        Style {
            color: BLACK,
            width: 2,
            dashed: true,
        },
    ];
    let series: Vec<(&Trace, Style)> = d.energy.iter().zip(styles).collect();
    time_chart(
        "Mechanical energy",
        "energy (J)",
        &series,
        &d.events,
        time_range(d),
    )
}

/// `stance.svg`: the body segment hip3–hip4 and both legs drawn at each
/// snapshot over the terrain, equal scales on both axes (Fig. 6); the
/// legend gives each snapshot's time.
pub fn stance_svg(d: &PlotData) -> PlotResult<String> {
    let xs = d
        .stances
        .iter()
        .flat_map(|s| [s.hip, s.knee, s.tip])
        .flat_map(|p| [p[0][0], p[1][0]]);
    let ys = d
        .stances
        .iter()
        .flat_map(|s| [s.hip, s.knee, s.tip])
        .flat_map(|p| [p[0][1], p[1][1]]);
    let xs: Vec<f64> = xs.collect();
    let mut ys: Vec<f64> = ys.collect();
    // The terrain profile y = ϱ(x), sampled across the plotted range.
    let ground = d.terrain.as_ref().filter(|t| t.exists());
    let profile = |a: f64, b: f64| -> Vec<(f64, f64)> {
        let t = ground.expect("profile of an existing terrain");
        (0..=TERRAIN_SAMPLES)
            .map(|i| a + (b - a) * i as f64 / TERRAIN_SAMPLES as f64)
            .map(|x| (x, t.height(x)))
            .filter(|p| p.1.is_finite())
            .collect()
    };
    let (mut x0, mut x1) = range(&xs);
    if ground.is_some() {
        ys.extend(profile(x0, x1).into_iter().map(|p| p.1));
    }
    let (mut y0, mut y1) = range(&ys);
    // Margins, label areas and caption of the chart below (pixels).
    let (margin, xl, yl, caption) = (16.0, 48.0, 70.0, 40.0);
    let width = 1000.0;
    let pw = width - 2.0 * margin - yl;
    let ph = (pw * (y1 - y0) / (x1 - x0)).clamp(250.0, 900.0);
    let height =
        (ph + 2.0 * margin + xl + caption).max(60.0 + 20.0 * (d.stances.len() as f64 + 3.0));
    // Equal aspect: widen the tighter range to the plot area's ratio.
    let ph_eff = height - 2.0 * margin - xl - caption;
    let scale = (pw / (x1 - x0)).min(ph_eff / (y1 - y0));
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (hx, hy) = (0.5 * pw / scale, 0.5 * ph_eff / scale);
    (x0, x1, y0, y1) = (cx - hx, cx + hx, cy - hy, cy + hy);

    let n = d.stances.len().max(2) - 1;
    // From light to dark as time goes on.
    // (the first at 75 % white, never white itself)
    let mix = |i: usize, c: RGBColor| {
        let f = i as f64 / n as f64;
        lighter(c, 0.75 * (1.0 - f))
    };
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(
            &mut buf,
            (width as u32 + LEGEND_WIDTH, height.round() as u32),
        )
        .into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let (left, right) = root.split_horizontally(width as u32);
        let title = match (d.stances.first(), d.stances.last()) {
            (Some(a), Some(b)) => format!(
                "Positions of the structure, t = {:.3} s (light) to {:.3} s (dark)",
                a.t, b.t
            ),
            _ => "Positions of the structure".to_owned(),
        };
        let mut chart = ChartBuilder::on(&left)
            .caption(title, ("sans-serif", 22))
            .margin(margin as u32)
            .x_label_area_size(xl as u32)
            .y_label_area_size(yl as u32)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("x (m)")
            .y_desc("y (m)")
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(err)?;
        let mut entries = Vec::new();
        if ground.is_some() {
            chart
                .draw_series(LineSeries::new(profile(x0, x1), GROUND.stroke_width(3)))
                .map_err(err)?;
            entries.push(Entry {
                label: "terrain".into(),
                style: Style {
                    color: GROUND,
                    width: 3,
                    dashed: false,
                },
            });
        }
        for (i, s) in d.stances.iter().enumerate() {
            let ok = |p: [f64; 2]| p[0].is_finite() && p[1].is_finite();
            let body = [s.hip[0], s.hip[1]];
            if body.iter().all(|p| ok(*p)) {
                chart
                    .draw_series(LineSeries::new(
                        body.map(|p| (p[0], p[1])),
                        mix(i, RGBColor(20, 20, 20)).stroke_width(4),
                    ))
                    .map_err(err)?;
            }
            for (leg, color) in [(0, LEG3), (1, LEG4)] {
                let pts = [s.hip[leg], s.knee[leg], s.tip[leg]];
                if pts.iter().all(|p| ok(*p)) {
                    let style = mix(i, color).stroke_width(2);
                    chart
                        .draw_series(LineSeries::new(pts.map(|p| (p[0], p[1])), style))
                        .map_err(err)?;
                    chart
                        .draw_series(
                            pts.iter()
                                .map(|p| Circle::new((p[0], p[1]), 3, mix(i, color).filled())),
                        )
                        .map_err(err)?;
                }
            }
        }
        for (label, color) in [("leg 3", LEG3), ("leg 4", LEG4)] {
            entries.push(Entry {
                label: label.into(),
                style: Style {
                    color,
                    width: 2,
                    dashed: false,
                },
            });
        }
        for (i, s) in d.stances.iter().enumerate() {
            entries.push(Entry {
                label: format!("body at t = {:.3} s", s.t),
                style: Style {
                    color: mix(i, RGBColor(20, 20, 20)),
                    width: 4,
                    dashed: false,
                },
            });
        }
        side_legend(&right, &entries)?;
        root.present().map_err(err)?;
    }
    Ok(buf)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn trace(label: &str, pts: Vec<(f64, f64)>) -> Trace {
        Trace {
            label: label.into(),
            pts,
        }
    }

    #[test]
    fn an_impact_clips_the_force_axis_and_the_title_gives_the_peak() {
        // 50 N at rest for 100 samples, a 1780 N spike at 0.36 s.
        let n: Vec<(f64, f64)> = (0..100)
            .map(|k| (k as f64 * 0.01, if k == 36 { 1780.0 } else { 50.0 }))
            .collect();
        let d = PlotData {
            normal: vec![trace("n hip4", n.clone())],
            tangential: vec![trace("fa hip4", n.iter().map(|p| (p.0, 0.0)).collect())],
            tips: vec![trace("tip", n.iter().map(|p| (p.0, 0.0)).collect())],
            points: vec![(4, PointKind::Hip)],
            ..PlotData::default()
        };
        let svg = forces_svg(&d).unwrap();
        assert!(
            svg.contains("axis clipped at ±200 N: peak 1780 N (n hip4, t = 0.36 s)"),
            "{}",
            &svg[..svg.len().min(2000)]
        );
        // The y axis ends near the clip, not at the peak: no 1500 tick.
        assert!(!svg.contains(">1500<"), "the axis still reaches the peak");
    }

    #[test]
    fn close_events_share_one_label_with_a_count() {
        let events: Vec<EventMark> = (0..9)
            .map(|k| EventMark {
                t: 0.5 + 1e-4 * k as f64,
                label: format!("{} tip ST2", k + 1),
            })
            .collect();
        let d = PlotData {
            tips: vec![trace("tip", vec![(0.0, 0.0), (1.0, 1.0)])],
            events,
            ..PlotData::default()
        };
        let svg = tips_svg(&d).unwrap();
        assert!(svg.contains("1 tip ST2 +8"), "no grouped label");
        assert!(!svg.contains("2 tip ST2"), "a second label drawn");
        assert!(
            svg.contains("event (+N: N more there)"),
            "the legend does not explain +N"
        );
    }

    #[test]
    fn min_max_keeps_the_extremes_of_every_column() {
        let steps = 600_000;
        let mut m = MinMax::new(0.0, 6.0);
        let mut peak = (0.0, f64::NEG_INFINITY);
        let mut trough = (0.0, f64::INFINITY);
        for k in 0..=steps {
            let t = k as f64 * 1e-5;
            // A fast oscillation with one spike.
            let v = (t * 377.0).sin() + if k == 123_457 { 5.0 } else { 0.0 };
            if v > peak.1 {
                peak = (t, v);
            }
            if v < trough.1 {
                trough = (t, v);
            }
            m.push(t, v);
        }
        let pts = m.finish();
        assert!(pts.len() <= 4 * COLUMNS + 4, "{} points", pts.len());
        assert!(pts.contains(&peak), "the spike {peak:?} was dropped");
        assert!(pts.contains(&trough), "the trough {trough:?} was dropped");
        assert!(
            pts.windows(2).all(|w| w[0].0 <= w[1].0),
            "not in time order"
        );
        assert_eq!(pts.first().map(|p| p.0), Some(0.0));
        assert_eq!(pts.last().map(|p| p.0), Some(steps as f64 * 1e-5));
    }

    #[test]
    fn plots_of_a_600000_step_run_stay_small() {
        let tips: Vec<ContactSpec> = PLANAR_LEGS
            .iter()
            .map(|&leg| ContactSpec {
                name: format!("tip{leg}"),
                leg,
                kind: PointKind::Tip,
                body: 0,
                point: 0,
            })
            .collect();
        let steps = 600_000;
        let dt = 1e-5;
        let mut rec = PlotRecorder::new(&tips, (steps - 1) as f64 * dt);
        let mut r = RobotRecord::planar(2, 4);
        for k in 0..steps {
            let t = k as f64 * dt;
            r.step = k;
            r.t = t;
            let w = (t * 300.0).sin();
            r.contacts[0].point = [0.1 * w, 0.2 + 0.01 * (t * 7000.0).sin(), 0.0];
            r.contacts[1].point = [-0.1 * w, 0.2 - 0.01 * w, 0.0];
            r.q[6] = w;
            r.contacts[0].normal = 50.0 + 20.0 * w;
            r.contacts[0].tangential[0] = 5.0 * w;
            r.contacts[0].state = StateCode::St2;
            r.kinetic = w * w;
            r.potential = 1.0 - w * w;
            rec.push(&r);
        }
        let d = rec.finish(&[], Vec::new(), None);
        for (name, svg) in [
            ("tips.svg", tips_svg(&d)),
            ("forces.svg", forces_svg(&d)),
            ("joints.svg", joints_svg(&d)),
            ("energy.svg", energy_svg(&d)),
        ] {
            let len = svg.unwrap().len();
            assert!(len < 300_000, "{name}: {len} bytes");
        }
        // Only the point that touched is in forces.svg.
        assert_eq!(d.normal.len(), 1);
        assert_eq!(d.normal[0].label, "n tip3");
        assert_eq!(d.points, [(3, PointKind::Tip)]);
        assert_eq!(point_color(d.points.first(), 5), LEG3);
        assert!(torques_svg(&d).is_none());
    }

    #[test]
    fn event_lines_are_labelled() {
        let trace = Trace {
            label: "a".into(),
            pts: vec![(0.0, 0.0), (1.0, 1.0)],
        };
        let style = Style {
            color: LEG3,
            width: 2,
            dashed: false,
        };
        let events = [
            EventMark {
                t: 0.2,
                label: "4 tip ST2".into(),
            },
            EventMark {
                t: 0.7,
                label: "3 hip ST3".into(),
            },
        ];
        let svg = time_chart("t", "y (m)", &[(&trace, style)], &events, (0.0, 1.0)).unwrap();
        assert!(
            svg.contains("4 tip ST2") && svg.contains("3 hip ST3"),
            "{svg}"
        );
        let attr = format!(
            "{} stroke-dasharray=\"{EVENT_DASH}\"",
            stroke_attr(EVENT, 1)
        );
        // Two event lines and the legend sample.
        assert_eq!(svg.matches(&attr).count(), 3);
    }

    #[test]
    fn min_max_breaks_the_line_at_missing_values() {
        let mut m = MinMax::new(0.0, 1.0);
        for k in 0..10 {
            let t = k as f64 / 10.0;
            m.push(t, if k == 5 { f64::NAN } else { t });
        }
        let pts = m.finish();
        assert_eq!(pts.iter().filter(|p| p.1.is_nan()).count(), 1);
    }

    #[test]
    fn dashed_curves_are_one_element_with_a_dash_pattern() {
        let trace = Trace {
            label: "a".into(),
            pts: (0..500)
                .map(|k| (k as f64, (k as f64 * 0.1).sin()))
                .collect(),
        };
        let style = Style {
            color: LEG3_LIGHT,
            width: 2,
            dashed: true,
        };
        let svg = time_chart("t", "y (m)", &[(&trace, style)], &[], (0.0, 500.0)).unwrap();
        let attr = format!("{} stroke-dasharray=\"{DASH}\"", stroke_attr(LEG3_LIGHT, 2));
        // The curve and its legend sample.
        assert_eq!(svg.matches(&attr).count(), 2, "{svg}");
    }
}

//! The SVG plots of `fbd run`: the two graphs of the paper's Fig. 7
//! (`tips.svg`: tip positions versus time; `forces.svg`: contact forces
//! versus time) and a Fig. 6-like drawing of the structure at regular
//! instants (`stance.svg`).

use fbd_contact::Terrain;
use plotters::coord::types::RangedCoordf64;
use plotters::prelude::*;

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

/// Everything the plots show.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PlotData {
    /// Sample times (s).
    pub t: Vec<f64>,
    /// Tip positions: `tip[leg][axis]` with leg 0 = leg 3, 1 = leg 4, axis
    /// 0 = x, 1 = y (m).
    pub tip: [[Vec<f64>; 2]; 2],
    /// Tangential force on tips 3 and 4 (N).
    pub fa: [Vec<f64>; 2],
    /// Normal force on tips 3 and 4 (N).
    pub n: [Vec<f64>; 2],
    /// Contact event times (s).
    pub events: Vec<f64>,
    /// Snapshots of the structure.
    pub stances: Vec<Stance>,
    /// The ground.
    pub terrain: Option<Terrain>,
}

type PlotResult<T> = Result<T, String>;

pub(crate) fn err<E: std::fmt::Debug>(e: E) -> String {
    format!("plotting failed: {e:?}")
}

const LEG3: RGBColor = RGBColor(31, 119, 180);
const LEG3_LIGHT: RGBColor = RGBColor(120, 180, 230);
const LEG4: RGBColor = RGBColor(214, 39, 40);
const LEG4_LIGHT: RGBColor = RGBColor(245, 140, 60);
const EVENT: RGBColor = RGBColor(150, 150, 150);
const GROUND: RGBColor = RGBColor(120, 85, 45);
/// Samples of the terrain profile drawn in `stance.svg`.
const TERRAIN_SAMPLES: usize = 400;

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

struct Series<'a> {
    label: &'a str,
    values: &'a [f64],
    color: RGBColor,
    dashed: bool,
}

fn time_chart(
    title: &str,
    y_desc: &str,
    t: &[f64],
    series: &[Series<'_>],
    events: &[f64],
) -> PlotResult<String> {
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (960, 540)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let (x0, x1) = range(t);
        let (y0, y1) = range(series.iter().flat_map(|s| s.values.iter()));
        let mut chart = ChartBuilder::on(&root)
            .caption(title, ("sans-serif", 22))
            .margin(14)
            .x_label_area_size(48)
            .y_label_area_size(70)
            .build_cartesian_2d(x0..x1, y0..y1)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc(y_desc)
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(err)?;
        for (i, &te) in events.iter().enumerate() {
            let s = chart
                .draw_series(DashedLineSeries::new(
                    [(te, y0), (te, y1)],
                    4,
                    4,
                    EVENT.stroke_width(1),
                ))
                .map_err(err)?;
            if i == 0 {
                s.label("contact event").legend(|(x, y)| {
                    PathElement::new(vec![(x, y), (x + 20, y)], EVENT.stroke_width(1))
                });
            }
        }
        for s in series {
            let points = t
                .iter()
                .zip(s.values)
                .filter(|(a, b)| a.is_finite() && b.is_finite())
                .map(|(a, b)| (*a, *b));
            let color = s.color;
            let style = color.stroke_width(2);
            let drawn = if s.dashed {
                chart
                    .draw_series(DashedLineSeries::new(points, 8, 5, style))
                    .map_err(err)?
            } else {
                chart
                    .draw_series(LineSeries::new(points, style))
                    .map_err(err)?
            };
            drawn.label(s.label).legend(legend_line(color, 2));
        }
        draw_legend(&mut chart)?;
        root.present().map_err(err)?;
    }
    Ok(buf)
}

/// `tips.svg`: x and y of both tips versus time (Fig. 7, graph 1).
pub fn tips_svg(d: &PlotData) -> PlotResult<String> {
    let series = [
        Series {
            label: "tip3 x",
            values: &d.tip[0][0],
            color: LEG3,
            dashed: false,
        },
        Series {
            label: "tip3 y",
            values: &d.tip[0][1],
            color: LEG3_LIGHT,
            dashed: true,
        },
        Series {
            label: "tip4 x",
            values: &d.tip[1][0],
            color: LEG4,
            dashed: false,
        },
        Series {
            label: "tip4 y",
            values: &d.tip[1][1],
            color: LEG4_LIGHT,
            dashed: true,
        },
    ];
    time_chart(
        "Tip positions of legs 3 and 4 (inertial frame)",
        "position (m)",
        &d.t,
        &series,
        &d.events,
    )
}

/// `forces.svg`: tangential and normal force on both tips versus time
/// (Fig. 7, graph 2).
pub fn forces_svg(d: &PlotData) -> PlotResult<String> {
    let series = [
        Series {
            label: "n3 (normal)",
            values: &d.n[0],
            color: LEG3,
            dashed: false,
        },
        Series {
            label: "fa3 (tangential)",
            values: &d.fa[0],
            color: LEG3_LIGHT,
            dashed: true,
        },
        Series {
            label: "n4 (normal)",
            values: &d.n[1],
            color: LEG4,
            dashed: false,
        },
        Series {
            label: "fa4 (tangential)",
            values: &d.fa[1],
            color: LEG4_LIGHT,
            dashed: true,
        },
    ];
    time_chart(
        "Contact forces on the tips of legs 3 and 4",
        "force (N)",
        &d.t,
        &series,
        &d.events,
    )
}

/// `stance.svg`: the body segment hip3–hip4 and both legs drawn at each
/// snapshot over the terrain, equal scales on both axes (Fig. 6).
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
    let height = ph + 2.0 * margin + xl + caption;
    // Equal aspect: widen the tighter range to the plot area's ratio.
    let scale = (pw / (x1 - x0)).min(ph / (y1 - y0));
    let (cx, cy) = (0.5 * (x0 + x1), 0.5 * (y0 + y1));
    let (hx, hy) = (0.5 * pw / scale, 0.5 * ph / scale);
    (x0, x1, y0, y1) = (cx - hx, cx + hx, cy - hy, cy + hy);

    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (width as u32, height.round() as u32))
            .into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let title = match (d.stances.first(), d.stances.last()) {
            (Some(a), Some(b)) => format!(
                "Positions of the structure, t = {:.3} s (light) to {:.3} s (dark)",
                a.t, b.t
            ),
            _ => "Positions of the structure".to_owned(),
        };
        let mut chart = ChartBuilder::on(&root)
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
        if ground.is_some() {
            chart
                .draw_series(LineSeries::new(profile(x0, x1), GROUND.stroke_width(3)))
                .map_err(err)?
                .label("terrain")
                .legend(legend_line(GROUND, 3));
        }
        let n = d.stances.len().max(2) - 1;
        for (i, s) in d.stances.iter().enumerate() {
            // From light to dark as time goes on.
            let f = i as f64 / n as f64;
            let shade = |c: u8| (255.0 - f * (255.0 - f64::from(c))).round() as u8;
            let mix = |c: RGBColor| RGBColor(shade(c.0), shade(c.1), shade(c.2));
            let ok = |p: [f64; 2]| p[0].is_finite() && p[1].is_finite();
            let body = [s.hip[0], s.hip[1]];
            if body.iter().all(|p| ok(*p)) {
                chart
                    .draw_series(LineSeries::new(
                        body.map(|p| (p[0], p[1])),
                        mix(RGBColor(20, 20, 20)).stroke_width(4),
                    ))
                    .map_err(err)?;
            }
            for (leg, color) in [(0, LEG3), (1, LEG4)] {
                let pts = [s.hip[leg], s.knee[leg], s.tip[leg]];
                if pts.iter().all(|p| ok(*p)) {
                    let style = mix(color).stroke_width(2);
                    chart
                        .draw_series(LineSeries::new(pts.map(|p| (p[0], p[1])), style))
                        .map_err(err)?;
                    chart
                        .draw_series(
                            pts.iter()
                                .map(|p| Circle::new((p[0], p[1]), 3, mix(color).filled())),
                        )
                        .map_err(err)?;
                }
            }
        }
        for (label, color) in [("leg 3", LEG3), ("leg 4", LEG4)] {
            chart
                .draw_series(std::iter::empty::<Circle<(f64, f64), i32>>())
                .map_err(err)?
                .label(label)
                .legend(legend_line(color, 2));
        }
        draw_legend(&mut chart)?;
        root.present().map_err(err)?;
    }
    Ok(buf)
}

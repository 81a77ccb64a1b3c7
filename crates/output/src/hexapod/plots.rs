//! The plots of a hexapod run: `gait.svg` (the gait diagram: a bar per leg,
//! black in stance), `footprints.svg` (top view: body path, footholds,
//! support polygons and the centre of mass at a few instants) and
//! `joints.svg` (joint angles versus time; on a height map also each foot's
//! height against the terrain under it).

use fbd_sim::gait::stability::convex_hull;
use fbd_sim::gait::{GaitData, GaitModel, LEGS};
use plotters::prelude::*;

use crate::plot::{PALETTE, draw_legend, err, legend_line, range, tick};

/// Most samples kept per plotted curve.
const SAMPLES: usize = 4000;
/// Support polygons drawn in `footprints.svg`.
const POLYGONS: usize = 8;

/// One colour per leg: the first six of the plots' palette.
fn leg_color(leg: usize) -> RGBColor {
    PALETTE[leg % PALETTE.len()]
}

/// A support polygon at one instant.
#[derive(Clone, Debug, PartialEq)]
pub struct Support {
    /// Time (s).
    pub t: f64,
    /// Hull vertices `(x, z)` (m).
    pub hull: Vec<[f64; 2]>,
    /// Projected centre of mass `(x, z)` (m).
    pub com: [f64; 2],
}

/// What the hexapod plots need, gathered step by step.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct GaitPlotData {
    every: usize,
    snapshot_every: usize,
    /// Sample times (s).
    pub t: Vec<f64>,
    /// Joint angles `theta[joint][leg]` (deg) at the sample times.
    pub theta: [[Vec<f64>; LEGS]; 3],
    /// Stance intervals per leg `[start, end]` (s), every step.
    pub stance: [Vec<[f64; 2]>; LEGS],
    /// Body centre `(x, z)` at the sample times.
    pub path: Vec<[f64; 2]>,
    /// Touchdown footholds `(x, z)` per leg (and the initial feet).
    pub footholds: [Vec<[f64; 2]>; LEGS],
    /// Support polygons at a few instants.
    pub supports: Vec<Support>,
    /// On a height map: per leg, the foot's height and the terrain's under
    /// it (m) at the sample times (drawn as a fourth panel of
    /// `joints.svg`); empty on the profile kinds.
    pub heights: [[Vec<f64>; 2]; LEGS],
    surface: Option<fbd_contact::Surface>,
    last_t: f64,
    was_stance: [bool; LEGS],
}

impl GaitPlotData {
    /// Sized for `model`'s run.
    pub fn new(model: &GaitModel) -> Self {
        let steps = model.steps.max(1);
        let every = steps.div_ceil(SAMPLES).max(1);
        Self {
            every,
            snapshot_every: steps.div_ceil(POLYGONS).max(1),
            surface: model
                .surface
                .grid()
                .is_some()
                .then(|| model.surface.clone()),
            ..Self::default()
        }
    }

    /// Records one step.
    pub fn push(&mut self, d: &GaitData) {
        let stance = d.stance();
        for (leg, &down) in stance.iter().enumerate() {
            let s = &mut self.stance[leg];
            if down {
                if d.step > 0 && self.was_stance[leg] {
                    if let Some(last) = s.last_mut() {
                        last[1] = d.t;
                    }
                } else {
                    s.push([d.t, d.t]);
                    self.footholds[leg].push([d.feet[leg].x, d.feet[leg].z]);
                }
            }
        }
        self.was_stance = stance;
        if d.step.is_multiple_of(self.every) {
            self.sample(d);
        }
        if d.step.is_multiple_of(self.snapshot_every) {
            let feet: Vec<[f64; 2]> = (0..LEGS)
                .filter(|&i| stance[i])
                .map(|i| [d.feet[i].x, d.feet[i].z])
                .collect();
            let mut hull = [[0.0; 2]; 2 * LEGS];
            let n = convex_hull(&feet, &mut hull);
            self.supports.push(Support {
                t: d.t,
                hull: hull[..n].to_vec(),
                com: [d.com.x, d.com.z],
            });
        }
        self.last_t = d.t;
    }

    fn sample(&mut self, d: &GaitData) {
        self.t.push(d.t);
        for (j, per_leg) in self.theta.iter_mut().enumerate() {
            for (leg, v) in per_leg.iter_mut().enumerate() {
                v.push(d.legs[leg].theta[j].to_degrees());
            }
        }
        self.path.push([d.body.position.x, d.body.position.z]);
        if let Some(s) = &self.surface {
            for (leg, [foot, ground]) in self.heights.iter_mut().enumerate() {
                let f = d.feet[leg];
                foot.push(f.y);
                ground.push(s.height(f.x, f.z));
            }
        }
    }
}

type PlotResult = Result<String, String>;

/// `gait.svg`: the classic gait diagram, a bar per leg (leg 1 on top),
/// black while the foot is on the ground.
pub fn gait_svg(d: &GaitPlotData) -> PlotResult {
    let mut buf = String::new();
    {
        let root = SVGBackend::with_string(&mut buf, (960, 360)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let t1 = if d.last_t > 0.0 { d.last_t } else { 1.0 };
        let mut chart = ChartBuilder::on(&root)
            .caption("Gait diagram (black: stance)", ("sans-serif", 22))
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(60)
            .build_cartesian_2d(0.0..t1, 0.0..LEGS as f64)
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("time (s)")
            .y_desc("leg")
            .x_label_formatter(&tick)
            .y_labels(LEGS * 2 + 1)
            .y_label_formatter(&|v: &f64| {
                let r = LEGS as f64 - v;
                if (r - r.floor() - 0.5).abs() < 1e-9 {
                    format!("{}", r.ceil() as usize)
                } else {
                    String::new()
                }
            })
            .disable_y_mesh()
            .draw()
            .map_err(err)?;
        for leg in 0..LEGS {
            let y0 = (LEGS - 1 - leg) as f64 + 0.15;
            let y1 = y0 + 0.7;
            chart
                .draw_series(std::iter::once(Rectangle::new(
                    [(0.0, y0), (t1, y1)],
                    BLACK.stroke_width(1),
                )))
                .map_err(err)?;
            chart
                .draw_series(
                    d.stance[leg].iter().map(|s| {
                        Rectangle::new([(s[0], y0), (s[1].max(s[0]), y1)], BLACK.filled())
                    }),
                )
                .map_err(err)?;
        }
        root.present().map_err(err)?;
    }
    Ok(buf)
}

/// `footprints.svg`: top view (x to the right, z downwards so that the
/// robot's initial forward −z points up the page): body path, footholds of
/// every leg, support polygons and the projected centre of mass at a few
/// instants.
pub fn footprints_svg(d: &GaitPlotData) -> PlotResult {
    let mut buf = String::new();
    {
        let (w, h) = (800u32, 800u32);
        let root = SVGBackend::with_string(&mut buf, (w, h)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let xs = d
            .path
            .iter()
            .map(|p| &p[0])
            .chain(d.footholds.iter().flatten().map(|p| &p[0]));
        let zs = d
            .path
            .iter()
            .map(|p| &p[1])
            .chain(d.footholds.iter().flatten().map(|p| &p[1]));
        let (x0, x1) = range(xs);
        let (z0, z1) = range(zs);
        // Equal scales: widen the narrower range.
        let half = 0.5 * (x1 - x0).max(z1 - z0);
        let (cx, cz) = (0.5 * (x0 + x1), 0.5 * (z0 + z1));
        let mut chart = ChartBuilder::on(&root)
            .caption("Footprints, top view", ("sans-serif", 22))
            .margin(14)
            .x_label_area_size(44)
            .y_label_area_size(60)
            .build_cartesian_2d(cx - half..cx + half, (cz + half)..(cz - half))
            .map_err(err)?;
        chart
            .configure_mesh()
            .x_desc("x (m)")
            .y_desc("z (m)")
            .x_label_formatter(&tick)
            .y_label_formatter(&tick)
            .light_line_style(WHITE.mix(0.0))
            .draw()
            .map_err(err)?;
        for (i, s) in d.supports.iter().enumerate() {
            if s.hull.len() >= 2 {
                let mut pts: Vec<(f64, f64)> = s.hull.iter().map(|p| (p[0], p[1])).collect();
                pts.push(pts[0]);
                let style = RGBColor(120, 120, 120).stroke_width(1);
                let drawn = chart
                    .draw_series(LineSeries::new(pts, style))
                    .map_err(err)?;
                if i == 0 {
                    drawn
                        .label("support polygon")
                        .legend(legend_line(RGBColor(120, 120, 120), 1));
                }
            }
            let drawn = chart
                .draw_series(std::iter::once(Cross::new(
                    (s.com[0], s.com[1]),
                    5,
                    BLACK.stroke_width(2),
                )))
                .map_err(err)?;
            if i == 0 {
                drawn
                    .label("centre of mass")
                    .legend(|(x, y)| Cross::new((x + 10, y), 5, BLACK.stroke_width(2)));
            }
        }
        chart
            .draw_series(LineSeries::new(
                d.path.iter().map(|p| (p[0], p[1])),
                BLACK.stroke_width(2),
            ))
            .map_err(err)?
            .label("body path")
            .legend(legend_line(BLACK, 2));
        for (leg, f) in d.footholds.iter().enumerate() {
            let c = leg_color(leg);
            chart
                .draw_series(f.iter().map(|p| Circle::new((p[0], p[1]), 3, c.filled())))
                .map_err(err)?
                .label(format!("foot {}", leg + 1))
                .legend(move |(x, y)| Circle::new((x + 10, y), 3, c.filled()));
        }
        draw_legend(&mut chart)?;
        root.present().map_err(err)?;
    }
    Ok(buf)
}

/// `joints.svg`: θ1, θ2, θ3 of every leg versus time (deg), one panel per
/// joint.
pub fn joints_svg(d: &GaitPlotData) -> PlotResult {
    let mut buf = String::new();
    {
        let n = if d.heights[0][0].is_empty() { 3 } else { 4 };
        let root = SVGBackend::with_string(&mut buf, (960, 300 * n as u32)).into_drawing_area();
        root.fill(&WHITE).map_err(err)?;
        let panels = root.split_evenly((n, 1));
        let (t0, t1) = range(d.t.iter());
        if n == 4 {
            heights_panel(d, &panels[3], (t0, t1))?;
        }
        for (j, panel) in panels.iter().take(3).enumerate() {
            let (y0, y1) = range(d.theta[j].iter().flatten());
            let mut chart = ChartBuilder::on(panel)
                .caption(format!("θ{} (deg)", j + 1), ("sans-serif", 20))
                .margin(10)
                .x_label_area_size(36)
                .y_label_area_size(60)
                .build_cartesian_2d(t0..t1, y0..y1)
                .map_err(err)?;
            chart
                .configure_mesh()
                .x_desc("time (s)")
                .x_label_formatter(&tick)
                .y_label_formatter(&tick)
                .light_line_style(WHITE.mix(0.0))
                .draw()
                .map_err(err)?;
            for (leg, c) in (0..LEGS).map(|leg| (leg, leg_color(leg))) {
                chart
                    .draw_series(LineSeries::new(
                        d.t.iter().zip(&d.theta[j][leg]).map(|(a, b)| (*a, *b)),
                        c.stroke_width(2),
                    ))
                    .map_err(err)?
                    .label(format!("leg {}", leg + 1))
                    .legend(legend_line(c, 2));
            }
            draw_legend(&mut chart)?;
        }
        root.present().map_err(err)?;
    }
    Ok(buf)
}

/// The fourth panel of `joints.svg` on a height map: each foot's height
/// (solid) and the terrain's under it (dashed), in the leg's colour.
fn heights_panel<DB: DrawingBackend>(
    d: &GaitPlotData,
    panel: &DrawingArea<DB, plotters::coord::Shift>,
    (t0, t1): (f64, f64),
) -> Result<(), String> {
    let (y0, y1) = range(d.heights.iter().flatten().flatten());
    let mut chart = ChartBuilder::on(panel)
        .caption(
            "foot heights (solid) and the terrain under each foot (dashed) (m)",
            ("sans-serif", 20),
        )
        .margin(10)
        .x_label_area_size(36)
        .y_label_area_size(60)
        .build_cartesian_2d(t0..t1, y0..y1)
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("time (s)")
        .x_label_formatter(&tick)
        .y_label_formatter(&tick)
        .light_line_style(WHITE.mix(0.0))
        .draw()
        .map_err(err)?;
    for (leg, [foot, ground]) in d.heights.iter().enumerate() {
        let c = leg_color(leg);
        chart
            .draw_series(LineSeries::new(
                d.t.iter().zip(foot).map(|(a, b)| (*a, *b)),
                c.stroke_width(2),
            ))
            .map_err(err)?
            .label(format!("leg {}", leg + 1))
            .legend(legend_line(c, 2));
        chart
            .draw_series(DashedLineSeries::new(
                d.t.iter().zip(ground).map(|(a, b)| (*a, *b)),
                4,
                3,
                c.stroke_width(1),
            ))
            .map_err(err)?;
    }
    draw_legend(&mut chart)
}

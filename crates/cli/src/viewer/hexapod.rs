//! The hexapod's scene: body hexagon, hips, knees and feet of the six legs
//! from the 24 coordinates with [`fbd_kinematics::hexapod::forward`], the
//! feet coloured stance (ST2) or swing (ST1), the support polygon of the
//! stance feet, the centre of mass; panels of body height, joint angles and
//! the stability margin.
//!
//! A gait run (or the 3D dynamics, once they exist) fills one
//! [`HexFrame`] per row of its `trajectory.csv` and calls
//! [`HexapodScene::push`], then [`HexapodScene::finish`] and
//! [`super::write`]; `fbd view DIR` does the same from the CSV.

use fbd_contact::Surface;
use fbd_kinematics::body::{GAMMA_DEG, LEG_COUNT};
use fbd_kinematics::hexapod::{HexapodConfig, HexapodData, HexapodModel, NQ, forward};

use super::{
    Curve, Decimator, EventMark, Line, Marker, Panel, Scene, SceneKind, round, round_time,
    surface_view, value,
};

/// One row of a hexapod run.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HexFrame {
    /// Time (s).
    pub t: f64,
    /// `(Rx, Ry, Rz, φx, φy, φz, θ1₁, θ2₁, θ3₁, …, θ3₆)` (m, rad).
    pub q: [f64; NQ],
    /// Whether each foot (leg number − 1) is on the ground.
    pub stance: [bool; LEG_COUNT],
    /// Centre of mass (m).
    pub com: [f64; 3],
    /// Stability margin (m), when the run computes one.
    pub margin: Option<f64>,
}

impl HexFrame {
    /// The frame of one step of a kinematic gait run.
    pub fn of_gait(d: &fbd_sim::gait::GaitData) -> Self {
        let mut q = [0.0; NQ];
        let b = &d.body;
        q[..6].copy_from_slice(&[
            b.position.x,
            b.position.y,
            b.position.z,
            b.phi.x,
            b.phi.y,
            b.phi.z,
        ]);
        for (leg, l) in d.legs.iter().enumerate() {
            q[6 + 3 * leg..9 + 3 * leg].copy_from_slice(&l.theta);
        }
        Self {
            t: d.t,
            q,
            stance: d.stance(),
            com: [d.com.x, d.com.y, d.com.z],
            margin: d.margin.is_finite().then_some(d.margin),
        }
    }
}

/// Points per leg in the layout: hip, knee, foot.
const PER_LEG: usize = 3;
/// Index of leg `leg`'s first point (the hip): after the body centre and
/// the six hexagon corners.
const fn leg_point(leg: usize, k: usize) -> usize {
    1 + LEG_COUNT + PER_LEG * leg + k
}

/// Builds the scene of a hexapod run row by row.
pub struct HexapodScene {
    model: HexapodModel,
    surface: Surface,
    data: HexapodData,
    decimator: Decimator,
    rows_planned: usize,
    rows: usize,
    last_stance: Option<[bool; LEG_COUNT]>,
    /// The last row pushed, when it is not a frame (kept by `finish`).
    pending: Option<(usize, HexFrame)>,
    scene: Scene,
    height: Vec<Option<f64>>,
    theta2: [Vec<Option<f64>>; LEG_COUNT],
    theta3: [Vec<Option<f64>>; LEG_COUNT],
    margin: Vec<Option<f64>>,
    any_margin: bool,
}

impl HexapodScene {
    /// A scene of `model` over `surface`, expecting about `rows_planned`
    /// rows (the last pushed row is always kept).
    pub fn new(model: HexapodModel, surface: Surface, rows_planned: usize, title: &str) -> Self {
        let mut points = vec!["body".to_owned()];
        points.extend((1..=LEG_COUNT).map(|k| format!("corner{k}")));
        let mut lines: Vec<Line> = (0..LEG_COUNT)
            .map(|k| Line {
                a: 1 + k,
                b: 1 + (k + 1) % LEG_COUNT,
                group: 0,
            })
            .collect();
        for leg in 0..LEG_COUNT {
            let n = leg + 1;
            points.extend([format!("hip{n}"), format!("knee{n}"), format!("foot{n}")]);
            lines.push(Line {
                a: leg_point(leg, 0),
                b: leg_point(leg, 1),
                group: n,
            });
            lines.push(Line {
                a: leg_point(leg, 1),
                b: leg_point(leg, 2),
                group: n,
            });
        }
        let contacts: Vec<Marker> = (0..LEG_COUNT)
            .map(|leg| Marker {
                name: format!("foot{}", leg + 1),
                point: leg_point(leg, 2),
            })
            .collect();
        // The feet around the body, by mounting angle γ.
        let mut ring: Vec<usize> = (0..LEG_COUNT).collect();
        ring.sort_by(|&a, &b| GAMMA_DEG[a].total_cmp(&GAMMA_DEG[b]));
        let scene = Scene {
            model: SceneKind::Hexapod,
            title: title.to_owned(),
            points,
            lines,
            trails: contacts.iter().map(|c| c.point).collect(),
            contacts,
            joints: Vec::new(),
            ring,
            ..Scene::default()
        };
        Self {
            model,
            surface,
            data: HexapodData::new(),
            decimator: Decimator::new(rows_planned),
            rows_planned,
            rows: 0,
            last_stance: None,
            pending: None,
            scene,
            height: Vec::new(),
            theta2: Default::default(),
            theta3: Default::default(),
            margin: Vec::new(),
            any_margin: false,
        }
    }

    /// Adds the next row.
    pub fn push(&mut self, f: &HexFrame) {
        let row = self.rows;
        self.rows += 1;
        let changed = self.last_stance.is_some_and(|s| s != f.stance);
        self.last_stance = Some(f.stance);
        let last = row + 1 >= self.rows_planned;
        if self.decimator.keep(row, changed, last) {
            self.frame(row, f);
            self.pending = None;
        } else {
            self.pending = Some((row, *f));
        }
    }

    fn frame(&mut self, row: usize, f: &HexFrame) {
        forward(&self.model, &HexapodConfig::from_q(&f.q), &mut self.data);
        let d = &self.data;
        let e_x = d.rotation.column(0);
        let e_z = d.rotation.column(2);
        let side = self.model.side();
        let mut p = Vec::with_capacity(3 * (1 + LEG_COUNT * (1 + PER_LEG)));
        p.extend(d.body_com.iter().map(|v| round(*v)));
        // Hexagon corners, in the order of the mounting angles: the hips
        // sit at the middle of the sides (distance d = L·cos 30° at γ), the
        // corners at L, γ + 30°.
        for &leg in &self.scene.ring {
            let a = (GAMMA_DEG[leg] + 30.0).to_radians();
            let c = d.body_com + side * (a.cos() * e_x - a.sin() * e_z);
            p.extend(c.iter().map(|v| round(*v)));
        }
        for l in &d.legs {
            for v in [l.hip, l.knee, l.tip] {
                p.extend(v.iter().map(|x| round(*x)));
            }
        }
        let s = &mut self.scene;
        s.row.push(row);
        s.t.push(round_time(f.t));
        s.p.push(p);
        s.state.push(
            f.stance
                .iter()
                .map(|&on| if on { '2' } else { '1' })
                .collect(),
        );
        s.fc.push(vec![0.0; 3 * LEG_COUNT]);
        s.fj.push(Vec::new());
        s.com.push(f.com.map(round));
        self.height.push(value(f.q[1]));
        for leg in 0..LEG_COUNT {
            self.theta2[leg].push(value(f.q[6 + 3 * leg + 1].to_degrees()));
            self.theta3[leg].push(value(f.q[6 + 3 * leg + 2].to_degrees()));
        }
        self.any_margin |= f.margin.is_some();
        self.margin.push(f.margin.and_then(value));
    }

    /// Completes the scene: terrain, stance events, panels.
    pub fn finish(mut self) -> Scene {
        if let Some((row, f)) = self.pending.take() {
            self.frame(row, &f);
        }
        let mut s = std::mem::take(&mut self.scene);
        s.rows = self.rows;
        s.terrain = surface_view(&self.surface, &s.p);
        for k in 1..s.state.len() {
            let (a, b) = (s.state[k - 1].as_bytes(), s.state[k].as_bytes());
            for leg in 0..LEG_COUNT.min(a.len()).min(b.len()) {
                if a[leg] != b[leg] {
                    let what = if b[leg] == b'2' {
                        "touchdown"
                    } else {
                        "lift-off"
                    };
                    s.events.push(EventMark {
                        t: s.t[k],
                        frame: k,
                        label: format!("leg {} {what}", leg + 1),
                    });
                }
            }
        }
        s.panels.push(Panel {
            title: "Body height Ry (m)".into(),
            curves: vec![Curve {
                label: "Ry".into(),
                v: std::mem::take(&mut self.height),
            }],
        });
        for (title, sym, series) in [
            ("Hip-lift angles θ2 (°)", "θ2", &mut self.theta2),
            ("Knee angles θ3 (°)", "θ3", &mut self.theta3),
        ] {
            s.panels.push(Panel {
                title: title.into(),
                curves: series
                    .iter_mut()
                    .enumerate()
                    .map(|(leg, v)| Curve {
                        label: format!("{sym} leg {}", leg + 1),
                        v: std::mem::take(v),
                    })
                    .collect(),
            });
        }
        if self.any_margin {
            s.panels.push(Panel {
                title: "Stability margin (m)".into(),
                curves: vec![Curve {
                    label: "margin".into(),
                    v: std::mem::take(&mut self.margin),
                }],
            });
        }
        s
    }
}

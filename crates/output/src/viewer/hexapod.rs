//! The hexapod's scene: body hexagon, hips, knees and feet of the legs
//! from the 24 coordinates with [`fbd_kinematics::hexapod::forward`], the
//! feet coloured by state, the support polygon of the feet on the ground,
//! the centre of mass; panels of body height, joint angles and the
//! stability margin.
//!
//! A kinematic gait run colours the feet stance (ST2) or swing (ST1). A
//! dynamic (3D FBD) run ([`HexapodScene::dynamic`], frames carrying
//! [`HexDynamics`]) draws only the model's legs, colours each foot (and
//! each knee and hip contact point) ST1/ST2/ST3, draws the ground force on
//! each and the hip and knee forces as arrows, and adds panels of the
//! feet's normal forces and the knee torques.
//!
//! A run fills one [`HexFrame`] per row of its `trajectory.csv` and calls
//! [`HexapodScene::push`], then [`HexapodScene::finish`] and
//! [`super::write`]; `fbd view DIR` does the same from the CSV.

use fbd_contact::{StateCode, Surface};
use fbd_dynamics::PointKind;
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
    /// Contact states and forces of a dynamic run.
    pub dynamics: Option<HexDynamics>,
}

/// What a dynamic run adds to a frame, indexed by leg number − 1 (legs
/// outside the model are left at their defaults).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HexDynamics {
    /// State of each foot.
    pub state: [StateCode; LEG_COUNT],
    /// Force of the ground on each foot, inertial (N).
    pub foot_force: [[f64; 3]; LEG_COUNT],
    /// Normal component of that force (N).
    pub normal: [f64; LEG_COUNT],
    /// Force of the body on the upper link at each hip (N).
    pub hip_force: [[f64; 3]; LEG_COUNT],
    /// Force of the upper on the lower link at each knee (N).
    pub knee_force: [[f64; 3]; LEG_COUNT],
    /// Actuator torques `(τ1, τ2, τ3)` of each leg (N·m).
    pub torque: [[f64; 3]; LEG_COUNT],
    /// State and ground force (N, inertial) of each leg's knee (`[0]`) and
    /// hip (`[1]`) contact point, when the model has them.
    pub points: [[(StateCode, [f64; 3]); 2]; LEG_COUNT],
}

impl Default for HexDynamics {
    fn default() -> Self {
        Self {
            state: [StateCode::St1; LEG_COUNT],
            foot_force: [[0.0; 3]; LEG_COUNT],
            normal: [0.0; LEG_COUNT],
            hip_force: [[0.0; 3]; LEG_COUNT],
            knee_force: [[0.0; 3]; LEG_COUNT],
            torque: [[0.0; 3]; LEG_COUNT],
            points: [[(StateCode::St1, [0.0; 3]); 2]; LEG_COUNT],
        }
    }
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
            dynamics: None,
        }
    }
}

/// Points per leg in the layout: hip, knee, foot.
const PER_LEG: usize = 3;
/// Index of point `k` (hip, knee, foot) of the `slot`-th drawn leg: after
/// the body centre and the six hexagon corners.
const fn leg_point(slot: usize, k: usize) -> usize {
    1 + LEG_COUNT + PER_LEG * slot + k
}

/// Builds the scene of a hexapod run row by row.
pub struct HexapodScene {
    model: HexapodModel,
    /// The drawn legs (leg number − 1), increasing.
    legs: Vec<usize>,
    /// The knee and hip contact points drawn after the feet: (leg number
    /// − 1, 0 knee / 1 hip).
    extras: Vec<(usize, usize)>,
    /// The event label of each contact, e.g. `leg 4 foot`.
    labels: Vec<String>,
    dynamic: bool,
    surface: Surface,
    data: HexapodData,
    decimator: Decimator,
    rows_planned: usize,
    rows: usize,
    last_state: Option<String>,
    /// The last row pushed, when it is not a frame (kept by `finish`).
    pending: Option<(usize, HexFrame)>,
    scene: Scene,
    height: Vec<Option<f64>>,
    theta2: [Vec<Option<f64>>; LEG_COUNT],
    theta3: [Vec<Option<f64>>; LEG_COUNT],
    margin: Vec<Option<f64>>,
    any_margin: bool,
    normal: [Vec<Option<f64>>; LEG_COUNT],
    tau3: [Vec<Option<f64>>; LEG_COUNT],
}

impl HexapodScene {
    /// A scene of `model` over `surface`, expecting about `rows_planned`
    /// rows (the last pushed row is always kept).
    pub fn new(model: HexapodModel, surface: Surface, rows_planned: usize, title: &str) -> Self {
        let legs: Vec<usize> = (1..=LEG_COUNT).collect();
        Self::with_legs(model, surface, &legs, &[], false, rows_planned, title)
    }

    /// The scene of a dynamic (3D FBD) run of the legs `legs` (numbers
    /// 1–6) with the knee and hip contact points `points` (`(leg, kind)`):
    /// feet and points coloured ST1/ST2/ST3, ground and joint forces as
    /// arrows.
    pub fn dynamic(
        model: HexapodModel,
        surface: Surface,
        legs: &[usize],
        points: &[(usize, PointKind)],
        rows_planned: usize,
        title: &str,
    ) -> Self {
        Self::with_legs(model, surface, legs, points, true, rows_planned, title)
    }

    fn with_legs(
        model: HexapodModel,
        surface: Surface,
        leg_numbers: &[usize],
        contact_points: &[(usize, PointKind)],
        dynamic: bool,
        rows_planned: usize,
        title: &str,
    ) -> Self {
        let mut legs: Vec<usize> = leg_numbers
            .iter()
            .filter(|&&n| (1..=LEG_COUNT).contains(&n))
            .map(|n| n - 1)
            .collect();
        legs.sort_unstable();
        legs.dedup();
        let mut points = vec!["body".to_owned()];
        points.extend((1..=LEG_COUNT).map(|k| format!("corner{k}")));
        let mut lines: Vec<Line> = (0..LEG_COUNT)
            .map(|k| Line {
                a: 1 + k,
                b: 1 + (k + 1) % LEG_COUNT,
                group: 0,
            })
            .collect();
        for (slot, &leg) in legs.iter().enumerate() {
            let n = leg + 1;
            points.extend([format!("hip{n}"), format!("knee{n}"), format!("foot{n}")]);
            lines.push(Line {
                a: leg_point(slot, 0),
                b: leg_point(slot, 1),
                group: n,
            });
            lines.push(Line {
                a: leg_point(slot, 1),
                b: leg_point(slot, 2),
                group: n,
            });
        }
        let mut contacts: Vec<Marker> = legs
            .iter()
            .enumerate()
            .map(|(slot, leg)| Marker {
                name: format!("foot{}", leg + 1),
                point: leg_point(slot, 2),
            })
            .collect();
        let mut labels: Vec<String> = legs
            .iter()
            .map(|leg| format!("leg {} foot", leg + 1))
            .collect();
        // Knee and hip contact points of a dynamic run, after the feet.
        let mut extras = Vec::new();
        for &(n, kind) in contact_points {
            let (k, name) = match kind {
                PointKind::Knee => (0, "knee"),
                PointKind::Hip => (1, "hip"),
                PointKind::Tip => continue,
            };
            let Some(slot) = legs.iter().position(|&l| l + 1 == n) else {
                continue;
            };
            extras.push((n - 1, k));
            contacts.push(Marker {
                name: format!("{name}point{n}"),
                point: leg_point(slot, [1, 0][k]),
            });
            labels.push(format!("leg {n} {name}"));
        }
        // Joint-force arrows of a dynamic run: every hip and knee.
        let joints: Vec<Marker> = if dynamic {
            legs.iter()
                .enumerate()
                .flat_map(|(slot, leg)| {
                    [("hip", 0), ("knee", 1)].map(|(name, k)| Marker {
                        name: format!("{name}{}", leg + 1),
                        point: leg_point(slot, k),
                    })
                })
                .collect()
        } else {
            Vec::new()
        };
        // The feet around the body, by mounting angle γ.
        let mut ring: Vec<usize> = (0..legs.len()).collect();
        ring.sort_by(|&a, &b| GAMMA_DEG[legs[a]].total_cmp(&GAMMA_DEG[legs[b]]));
        let scene = Scene {
            model: SceneKind::Hexapod,
            title: title.to_owned(),
            points,
            lines,
            trails: contacts.iter().take(legs.len()).map(|c| c.point).collect(),
            contacts,
            joints,
            ring,
            dynamic,
            ..Scene::default()
        };
        Self {
            model,
            legs,
            extras,
            labels,
            dynamic,
            surface,
            data: HexapodData::new(),
            decimator: Decimator::new(rows_planned),
            rows_planned,
            rows: 0,
            last_state: None,
            pending: None,
            scene,
            height: Vec::new(),
            theta2: Default::default(),
            theta3: Default::default(),
            margin: Vec::new(),
            any_margin: false,
            normal: Default::default(),
            tau3: Default::default(),
        }
    }

    /// The state of each contact in frame `f`, one digit each (feet,
    /// then the knee and hip points): ST1/ST2/ST3 from a dynamic run, swing
    /// (1) or stance (2) from a kinematic one.
    fn states(&self, f: &HexFrame) -> String {
        let digit = |s: StateCode| match s {
            StateCode::St1 => '1',
            StateCode::St2 => '2',
            StateCode::St3 => '3',
        };
        let d = f.dynamics.unwrap_or_default();
        let feet = self.legs.iter().map(|&leg| match &f.dynamics {
            Some(d) => digit(d.state[leg]),
            None if f.stance[leg] => '2',
            None => '1',
        });
        feet.chain(
            self.extras
                .iter()
                .map(|&(leg, k)| digit(d.points[leg][k].0)),
        )
        .collect()
    }

    /// Adds the next row.
    pub fn push(&mut self, f: &HexFrame) {
        let row = self.rows;
        self.rows += 1;
        let state = self.states(f);
        let changed = self.last_state.as_ref().is_some_and(|s| *s != state);
        self.last_state = Some(state);
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
        for &leg in &self.legs {
            let l = &d.legs[leg];
            for v in [l.hip, l.knee, l.tip] {
                p.extend(v.iter().map(|x| round(*x)));
            }
        }
        let state = self.states(f);
        let s = &mut self.scene;
        s.row.push(row);
        s.t.push(round_time(f.t));
        s.p.push(p);
        s.state.push(state);
        let dynamics = f.dynamics.unwrap_or_default();
        s.fc.push(
            self.legs
                .iter()
                .map(|&leg| dynamics.foot_force[leg])
                .chain(
                    self.extras
                        .iter()
                        .map(|&(leg, k)| dynamics.points[leg][k].1),
                )
                .flat_map(|v| v.map(round))
                .collect(),
        );
        s.fj.push(if self.dynamic {
            self.legs
                .iter()
                .flat_map(|&leg| {
                    [dynamics.hip_force[leg], dynamics.knee_force[leg]]
                        .into_iter()
                        .flat_map(|v| v.map(round))
                })
                .collect()
        } else {
            Vec::new()
        });
        s.com.push(f.com.map(round));
        self.height.push(value(f.q[1]));
        for &leg in &self.legs {
            self.theta2[leg].push(value(f.q[6 + 3 * leg + 1].to_degrees()));
            self.theta3[leg].push(value(f.q[6 + 3 * leg + 2].to_degrees()));
            if self.dynamic {
                self.normal[leg].push(value(dynamics.normal[leg]));
                self.tau3[leg].push(value(dynamics.torque[leg][2]));
            }
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
        s.patches = super::patch_views(self.surface.patches());
        for k in 1..s.state.len() {
            let (a, b) = (s.state[k - 1].as_bytes(), s.state[k].as_bytes());
            for slot in 0..self.labels.len().min(a.len()).min(b.len()) {
                if a[slot] != b[slot] {
                    let what = &self.labels[slot];
                    let label = if self.dynamic {
                        let st = |c: u8| format!("ST{}", c as char);
                        format!("{what} {}→{}", st(a[slot]), st(b[slot]))
                    } else if b[slot] == b'2' {
                        format!("leg {} touchdown", self.legs[slot] + 1)
                    } else {
                        format!("leg {} lift-off", self.legs[slot] + 1)
                    };
                    s.events.push(EventMark {
                        t: s.t[k],
                        frame: k,
                        label,
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
        let mut series = vec![
            ("Hip-lift angles θ2 (°)", "θ2", &mut self.theta2),
            ("Knee angles θ3 (°)", "θ3", &mut self.theta3),
        ];
        if self.dynamic {
            series.insert(0, ("Normal forces of the feet (N)", "n", &mut self.normal));
            series.push(("Knee torques τ3 (N·m)", "τ3", &mut self.tau3));
        }
        for (title, sym, series) in series {
            s.panels.push(Panel {
                title: title.into(),
                curves: self
                    .legs
                    .iter()
                    .map(|&leg| Curve {
                        label: format!("{sym} leg {}", leg + 1),
                        v: std::mem::take(&mut series[leg]),
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

//! The planar model's scene: every frame's points from `q` with
//! [`fbd_kinematics::planar::PlanarChains`], the contact forces as vectors
//! along the terrain's tangent and normal, the joint forces, the centre of
//! mass of all bodies; panels of normal forces, joint angles, torques and
//! energy.
//!
//! Feed it the rows of `trajectory.csv` in order ([`PlanarScene::push`]),
//! then [`PlanarScene::finish`].

use fbd_contact::{StateCode, Terrain};
use fbd_kinematics::planar::PlanarData;
use fbd_sim::{Event, Model, RobotRecord};

use super::{
    Curve, Decimator, EventMark, Line, Marker, Panel, Scene, SceneKind, frame_at, round,
    round_time, terrain_view, value,
};

fn digit(s: StateCode) -> char {
    match s {
        StateCode::St1 => '1',
        StateCode::St2 => '2',
        StateCode::St3 => '3',
    }
}

/// Builds the scene of a planar run row by row.
pub struct PlanarScene<'a> {
    model: &'a Model,
    kin: PlanarData,
    decimator: Decimator,
    rows_planned: usize,
    rows: usize,
    /// Contact states of the previous row (empty before the first; no
    /// allocation per row).
    last_state: Vec<StateCode>,
    /// The last row pushed, when it is not a frame (kept by `finish`).
    pending: Option<usize>,
    /// The record of that row (a buffer reused from row to row).
    pending_record: Option<RobotRecord>,
    /// The planar model's coordinates of a frame's record
    /// ([`RobotRecord::plane_q_into`]; a buffer).
    q: Vec<f64>,
    /// Indices into the chains' points of the drawn points, in order.
    drawn: Vec<usize>,
    touched: Vec<bool>,
    torques_used: bool,
    scene: Scene,
    // Per-frame series (filled with the frames).
    n: Vec<Vec<Option<f64>>>,
    angles: [Vec<Option<f64>>; 4],
    torque: [Vec<Option<f64>>; 4],
    energy: [Vec<Option<f64>>; 3],
}

impl<'a> PlanarScene<'a> {
    /// A scene for `model`, expecting about `rows_planned` rows (used to
    /// choose the decimation; the last pushed row is always kept).
    pub fn new(model: &'a Model, rows_planned: usize, title: &str) -> Self {
        let chains = &model.mech.chains;
        let ix = &model.index;
        // Drawn points: body centre, then per leg hip, knee, tip and the
        // links' centres of mass.
        let mut drawn = vec![ix.body_com];
        let mut names = vec!["body".to_owned()];
        let mut lines = Vec::new();
        for leg in 0..2 {
            let base = drawn.len();
            let n = leg + 3;
            for (p, name) in [
                (ix.hip[leg], format!("hip{n}")),
                (ix.knee[leg], format!("knee{n}")),
                (ix.tip[leg], format!("tip{n}")),
                (ix.upper_com[leg], format!("upper_com{n}")),
                (ix.lower_com[leg], format!("lower_com{n}")),
            ] {
                drawn.push(p);
                names.push(name);
            }
            lines.push(Line {
                a: base,
                b: base + 1,
                group: leg + 1,
            });
            lines.push(Line {
                a: base + 1,
                b: base + 2,
                group: leg + 1,
            });
        }
        // The body: hip 3 – centre – hip 4.
        lines.insert(
            0,
            Line {
                a: 1,
                b: 6,
                group: 0,
            },
        );
        let index_of = |chain_point: usize| drawn.iter().position(|&d| d == chain_point);
        let contacts: Vec<Marker> = model
            .mech
            .contacts
            .iter()
            .map(|c| Marker {
                name: c.name.clone(),
                point: index_of(c.point).expect("contact points are drawn"),
            })
            .collect();
        let joints: Vec<Marker> = model
            .mech
            .joints
            .iter()
            .map(|j| Marker {
                name: j.name.clone(),
                point: index_of(j.point).expect("joints are drawn"),
            })
            .collect();
        let trails = vec![
            index_of(ix.tip[0]).unwrap_or(3),
            index_of(ix.tip[1]).unwrap_or(8),
        ];
        let ncontacts = contacts.len();
        let scene = Scene {
            model: SceneKind::Planar,
            title: title.to_owned(),
            points: names,
            lines,
            contacts,
            joints,
            trails,
            ring: Vec::new(),
            dynamic: false,
            terrain: Default::default(),
            patches: Vec::new(),
            rows: 0,
            row: Vec::new(),
            t: Vec::new(),
            p: Vec::new(),
            state: Vec::new(),
            fc: Vec::new(),
            fj: Vec::new(),
            com: Vec::new(),
            events: Vec::new(),
            event_rows: 0,
            panels: Vec::new(),
        };
        Self {
            model,
            kin: chains.new_data(),
            decimator: Decimator::new(rows_planned),
            rows_planned,
            rows: 0,
            last_state: Vec::with_capacity(ncontacts),
            pending: None,
            pending_record: None,
            q: Vec::new(),
            drawn,
            touched: vec![false; ncontacts],
            torques_used: false,
            scene,
            n: vec![Vec::new(); ncontacts],
            angles: Default::default(),
            torque: Default::default(),
            energy: Default::default(),
        }
    }

    /// Adds the next row of `trajectory.csv`.
    pub fn push(&mut self, r: &RobotRecord) {
        let row = self.rows;
        self.rows += 1;
        let nc = self.scene.contacts.len();
        let states = || r.contacts[..nc].iter().map(|c| c.state);
        for (c, s) in states().enumerate() {
            self.touched[c] |= s != StateCode::St1;
        }
        self.torques_used |= r.torque.iter().any(|t| *t != 0.0);
        let changed = !self.last_state.is_empty() && !self.last_state.iter().copied().eq(states());
        let last = row + 1 >= self.rows_planned;
        let keep = self.decimator.keep(row, changed, last);
        self.last_state.clear();
        self.last_state.extend(states());
        if keep {
            self.frame(row, r);
            self.pending = None;
        } else {
            self.pending = Some(row);
            match &mut self.pending_record {
                Some(p) => p.clone_from(r),
                None => self.pending_record = Some(r.clone()),
            }
        }
    }

    fn frame(&mut self, row: usize, r: &RobotRecord) {
        let nc = self.scene.contacts.len();
        let state: String = r.contacts[..nc].iter().map(|c| digit(c.state)).collect();
        let chains = &self.model.mech.chains;
        r.plane_q_into(&mut self.q);
        chains.eval_positions(&self.q, &mut self.kin);
        let pos = &self.kin.pos;
        let s = &mut self.scene;
        s.row.push(row);
        s.t.push(round_time(r.t));
        s.p.push(
            self.drawn
                .iter()
                .flat_map(|&i| [round(pos[i][0]), round(pos[i][1]), 0.0])
                .collect(),
        );
        s.state.push(state);
        let terrain: &Terrain = &self.model.params.terrain;
        let mut fc = Vec::with_capacity(3 * s.contacts.len());
        for (c, spec) in self.model.mech.contacts.iter().enumerate() {
            let x = pos[spec.point][0];
            let (tan, nor) = if terrain.exists() {
                terrain.frame(x)
            } else {
                ([1.0, 0.0], [0.0, 1.0])
            };
            let (fa, n) = (r.contacts[c].tangential[0], r.contacts[c].normal);
            let f = [fa * tan[0] + n * nor[0], fa * tan[1] + n * nor[1]];
            fc.extend([round(f[0]), round(f[1]), 0.0]);
            self.n[c].push(value(n));
        }
        s.fc.push(fc);
        s.fj.push(
            r.reaction_force[..s.joints.len()]
                .iter()
                .flat_map(|f| [round(f[0]), round(f[1]), 0.0])
                .collect(),
        );
        let (mut m, mut cx, mut cy) = (0.0, 0.0, 0.0);
        for b in &self.model.mech.bodies {
            m += b.mass;
            cx += b.mass * pos[b.com][0];
            cy += b.mass * pos[b.com][1];
        }
        let m = if m > 0.0 { m } else { 1.0 };
        s.com.push([round(cx / m), round(cy / m), 0.0]);
        for (k, a) in self.angles.iter_mut().enumerate() {
            a.push(value(self.q[3 + k].to_degrees()));
        }
        for (k, a) in self.torque.iter_mut().enumerate() {
            a.push(value(r.torque[k]));
        }
        self.energy[0].push(value(r.kinetic));
        self.energy[1].push(value(r.potential));
        self.energy[2].push(value(r.kinetic + r.potential));
    }

    /// Completes the scene: terrain, events, panels.
    pub fn finish(mut self, events: &[Event]) -> Scene {
        if let (Some(row), Some(r)) = (self.pending.take(), self.pending_record.take()) {
            self.frame(row, &r);
        }
        let mut s = std::mem::take(&mut self.scene);
        s.rows = self.rows;
        s.events = events
            .iter()
            .map(|e| EventMark {
                t: round_time(e.t),
                frame: frame_at(&s.t, round_time(e.t)),
                label: format!(
                    "leg {} {} {}→{}",
                    e.leg,
                    e.point,
                    e.from.as_str(),
                    e.to.as_str()
                ),
            })
            .collect();
        s.terrain = terrain_view(&self.model.params.terrain, &s.p);
        s.patches = super::patch_views(&self.model.params.patches);
        let names: Vec<String> = s.contacts.iter().map(|c| c.name.clone()).collect();
        s.panels.push(Panel {
            title: "Normal contact forces (N)".into(),
            curves: names
                .iter()
                .zip(std::mem::take(&mut self.n))
                .zip(&self.touched)
                .filter(|(_, t)| **t)
                .map(|((name, v), _)| Curve {
                    label: format!("n {name}"),
                    v,
                })
                .collect(),
        });
        let [a0, a1, a2, a3] = std::mem::take(&mut self.angles);
        s.panels.push(Panel {
            title: "Joint angles (°)".into(),
            curves: ["θ2 leg 3", "θ3 leg 3", "θ2 leg 4", "θ3 leg 4"]
                .iter()
                .zip([a0, a1, a2, a3])
                .map(|(l, v)| Curve {
                    label: (*l).to_owned(),
                    v,
                })
                .collect(),
        });
        if self.torques_used {
            let [t0, t1, t2, t3] = std::mem::take(&mut self.torque);
            s.panels.push(Panel {
                title: "Joint torques (N·m)".into(),
                curves: ["hip 3", "knee 3", "hip 4", "knee 4"]
                    .iter()
                    .zip([t0, t1, t2, t3])
                    .map(|(l, v)| Curve {
                        label: (*l).to_owned(),
                        v,
                    })
                    .collect(),
            });
        }
        let [e0, e1, e2] = std::mem::take(&mut self.energy);
        s.panels.push(Panel {
            title: "Energy (J)".into(),
            curves: ["kinetic", "potential", "total"]
                .iter()
                .zip([e0, e1, e2])
                .map(|(l, v)| Curve {
                    label: (*l).to_owned(),
                    v,
                })
                .collect(),
        });
        s
    }
}

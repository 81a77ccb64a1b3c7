//! The hexapod's runs in the one 3D scene ([`super::robot`]): a kinematic
//! gait run or a dynamic (3D FBD) run is drawn as the generic robot model
//! of the hexapod built from its D-H parameters ([`fbd_robot::dh::hexapod`],
//! the model the 3D simulator steps), with `fbd_robot`'s forward
//! kinematics, as every imported robot. This module only adapts: it builds
//! that model and the hexapod's [`Decor`] (what the scene adds to the
//! robot's drawing), and turns a run's rows into the generic [`Row`]s.
//!
//! The hexapod's decor: the body hexagon (`corner1`…`corner6`, points fixed
//! in the body at the side length `L` from its centre, at the mounting
//! angles γ + 30°: the hips sit at the middle of the sides) as the root's
//! outline, filled with the plate; the leg numbers beside the hips (joint
//! `theta1_n`); a heading arrow from the body's centre to its front vertex
//! `corner2` (between legs 1 and 2, the body's −z); each leg in its own
//! colour (group = leg number); the feet's trails and the support polygon
//! of the feet on the ground; the panels of the body height, θ2 and θ3 of
//! every leg and
//!
//! * a kinematic gait ([`HexapodView::gait`]): the feet `tip1`…`tip6` as
//!   contact points, swing (1) or stance (2), the run's centre of mass, the
//!   stability margin's panel (when the run has one);
//! * a dynamic run ([`HexapodView::dynamic`]): the model's legs, its feet
//!   and, when they are contact points, its knees and hips coloured
//!   ST1/ST2/ST3 with the ground force on each (the feet first, then leg by
//!   leg knee and hip: the model's contact points in that order), the hip
//!   and knee forces as joint-force arrows, the model's centre of mass, the
//!   panels of the feet's normal forces and the knee torques. A foot that
//!   is not a contact point is drawn as a point fixed in the lower link.
//!
//! A run pushes one row per row of its `trajectory.csv`
//! ([`HexapodView::push_gait`], [`HexapodView::push_dynamic`]), then
//! [`HexapodView::write`]; `fbd view DIR` does the same from the CSV
//! ([`super::view`]), and writes the same page byte for byte.

use std::path::{Path, PathBuf};

use fbd_contact::{StateCode, Surface};
use fbd_dynamics::PointKind;
use fbd_kinematics::body::{GAMMA_DEG, LEG_COUNT};
use fbd_kinematics::hexapod::HexapodModel;
use fbd_robot::RobotModel;
use fbd_robot::dh::{HexapodLayout, HexapodMasses};
use fbd_robot::nalgebra::Vector3;
use fbd_sim::spatial::SpatialParams;

use super::robot::{Decor, FixedPoint, Label, PanelPlan, RobotFrames, RobotScene, Row, Series};
use crate::OutputError;

/// A hexapod run's viewer: the generic robot scene of its D-H model.
#[derive(Clone, Debug)]
pub struct HexapodView {
    frames: RobotFrames,
    /// The model's legs (numbers 1–6), increasing.
    legs: Vec<usize>,
    /// The contact points in the scene's order: leg number and kind.
    contacts: Vec<(usize, PointKind)>,
    /// Row buffers.
    states: Vec<u8>,
    forces: Vec<[f64; 3]>,
    joint_forces: Vec<[f64; 3]>,
    values: Vec<f64>,
}

/// What a dynamic run gives for one leg of the model, in a row.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct LegValues {
    /// Normal force of the ground on the foot (N; 0 when the foot is not
    /// a contact point).
    pub normal: f64,
    /// Force of the body on the upper link at the hip (N, inertial).
    pub hip_force: [f64; 3],
    /// Force of the upper on the lower link at the knee (N, inertial).
    pub knee_force: [f64; 3],
    /// Actuator torques `(τ1, τ2, τ3)` (N·m).
    pub torque: [f64; 3],
}

/// The leg number and kind of a hexapod contact point's name (`tip3`,
/// `knee3`, `hip3`).
fn point_of(name: &str) -> Option<(usize, PointKind)> {
    let stem = name.trim_end_matches(|c: char| c.is_ascii_digit());
    let n = name[stem.len()..].parse().ok()?;
    let kind = PointKind::ALL.into_iter().find(|k| k.as_str() == stem)?;
    Some((n, kind))
}

impl HexapodView {
    /// The viewer of a kinematic gait run of the hexapod `kin` (all six
    /// legs) over `surface`, of `rows` rows (decimated as they come,
    /// [`RobotFrames::with_rows_planned`]).
    pub fn gait(kin: &HexapodModel, surface: Surface, rows: usize, title: &str) -> Self {
        let layout = HexapodLayout {
            tips: true,
            knees: false,
            hips: false,
            ..HexapodLayout::default()
        };
        let model = fbd_robot::dh::hexapod(kin, &HexapodMasses::default(), &layout);
        Self::of(model, kin, surface, (rows, title), false)
    }

    /// The viewer of a dynamic (3D FBD) run of `params`, of `rows` rows:
    /// the model of [`SpatialParams::robot_model`], its terrain.
    pub fn dynamic(params: &SpatialParams, rows: usize, title: &str) -> Self {
        Self::of(
            params.robot_model(),
            &params.kinematic_model(),
            params.terrain.clone(),
            (rows, title),
            true,
        )
    }

    fn of(
        mut model: RobotModel,
        kin: &HexapodModel,
        surface: Surface,
        (rows, title): (usize, &str),
        dynamic: bool,
    ) -> Self {
        // The contact points in the scene's order: the feet, then leg by
        // leg the knee and the hip.
        model.contacts.sort_by_key(|c| match point_of(&c.name) {
            Some((n, PointKind::Tip)) => (0, n, 0),
            Some((n, PointKind::Knee)) => (1, n, 0),
            Some((n, PointKind::Hip)) => (1, n, 1),
            None => (2, 0, 0),
        });
        let contacts: Vec<(usize, PointKind)> = model
            .contacts
            .iter()
            .map(|c| point_of(&c.name).unwrap_or((0, PointKind::Tip)))
            .collect();
        let legs: Vec<usize> = (1..=LEG_COUNT)
            .filter(|n| model.joint_index(&format!("theta1_{n}")).is_some())
            .collect();
        let joint = |name: String| model.joint_index(&name).unwrap_or(0);
        // The body hexagon, by mounting angle.
        let mut by_angle: Vec<usize> = (0..LEG_COUNT).collect();
        by_angle.sort_by(|&a, &b| GAMMA_DEG[a].total_cmp(&GAMMA_DEG[b]));
        let side = kin.side();
        let mut fixed: Vec<FixedPoint> = by_angle
            .iter()
            .enumerate()
            .map(|(k, &leg)| {
                let a = (GAMMA_DEG[leg] + 30.0).to_radians();
                FixedPoint {
                    name: format!("corner{}", k + 1),
                    body: 0,
                    position: side * Vector3::new(a.cos(), 0.0, -a.sin()),
                }
            })
            .collect();
        let outline = fixed.iter().map(|f| f.name.clone()).collect();
        // Feet that are not contact points: fixed in the lower link.
        for &n in &legs {
            if !contacts.contains(&(n, PointKind::Tip))
                && let Some(body) = model.body_index(&format!("lower{n}"))
            {
                fixed.push(FixedPoint {
                    name: format!("tip{n}"),
                    body,
                    position: Vector3::new(kin.leg().c, 0.0, 0.0),
                });
            }
        }
        // The feet that are contact points around the body: the support
        // polygon.
        let mut ring: Vec<usize> = (0..contacts.len())
            .filter(|&k| contacts[k].1 == PointKind::Tip)
            .collect();
        ring.sort_by(|&a, &b| {
            GAMMA_DEG[contacts[a].0 - 1].total_cmp(&GAMMA_DEG[contacts[b].0 - 1])
        });
        let per_leg = |title: &str, sym: &str, s: &dyn Fn(usize, usize) -> Series| PanelPlan {
            title: title.into(),
            curves: legs
                .iter()
                .enumerate()
                .map(|(slot, &n)| (format!("{sym} leg {n}"), s(slot, n)))
                .collect(),
            optional: false,
        };
        let angle =
            |j: usize| move |_: usize, n: usize| Series::Angle(joint(format!("theta{j}_{n}")));
        let mut panels = vec![PanelPlan {
            title: "Body height Ry (m)".into(),
            curves: vec![("Ry".into(), Series::BaseHeight)],
            optional: false,
        }];
        if dynamic {
            panels.push(per_leg("Normal forces of the feet (N)", "n", &|s, _| {
                Series::Value(s)
            }));
        }
        panels.push(per_leg("Hip-lift angles θ2 (°)", "θ2", &angle(2)));
        panels.push(per_leg("Knee angles θ3 (°)", "θ3", &angle(3)));
        let nl = legs.len();
        if dynamic {
            panels.push(per_leg("Knee torques τ3 (N·m)", "τ3", &|s, _| {
                Series::Value(nl + s)
            }));
        } else {
            panels.push(PanelPlan {
                title: "Stability margin (m)".into(),
                curves: vec![("margin".into(), Series::Value(0))],
                optional: true,
            });
        }
        let decor = Decor {
            fixed,
            outline,
            labels: legs
                .iter()
                .map(|&n| Label {
                    text: n.to_string(),
                    point: format!("theta1_{n}"),
                    group: n,
                })
                .collect(),
            heading: Some("corner2".into()),
            trails: Some(legs.iter().map(|n| format!("tip{n}")).collect()),
            ring,
            joint_forces: if dynamic {
                legs.iter()
                    .flat_map(|&n| {
                        [
                            (format!("hip{n}"), joint(format!("theta1_{n}"))),
                            (format!("knee{n}"), joint(format!("theta3_{n}"))),
                        ]
                    })
                    .collect()
            } else {
                Vec::new()
            },
            contact_labels: contacts
                .iter()
                .map(|&(n, kind)| {
                    let what = match kind {
                        PointKind::Tip => "foot",
                        PointKind::Knee => "knee",
                        PointKind::Hip => "hip",
                    };
                    format!("leg {n} {what}")
                })
                .collect(),
            kinematic: !dynamic,
            limb_groups: legs.clone(),
            panels: Some(panels),
            values: if dynamic { 2 * nl } else { 1 },
        };
        let mut frames = RobotFrames::with_decor(&model, true, decor)
            .with_title(title)
            .with_rows_planned(rows);
        if surface.exists() {
            frames = frames.with_surface(surface);
        }
        let nc = contacts.len();
        Self {
            frames,
            contacts,
            states: vec![1; nc],
            forces: vec![[0.0; 3]; nc],
            joint_forces: vec![[0.0; 3]; 2 * legs.len()],
            values: Vec::with_capacity(2 * legs.len()),
            legs,
        }
    }

    /// The model's legs (numbers 1–6), increasing: the order of
    /// [`HexapodView::push_dynamic`]'s `legs`.
    pub fn legs(&self) -> &[usize] {
        &self.legs
    }

    /// The scene's contact points, leg number and kind: the order of
    /// [`HexapodView::push_dynamic`]'s `contacts`.
    pub fn contacts(&self) -> &[(usize, PointKind)] {
        &self.contacts
    }

    /// Adds a row of a kinematic gait run: `q = (rx, ry, rz, φx, φy, φz,
    /// θ1₁, θ2₁, θ3₁, …, θ3₆)`, whether each foot (leg number − 1) is on
    /// the ground, the centre of mass, the stability margin when the run
    /// computes one.
    pub fn push_gait(
        &mut self,
        t: f64,
        q: &[f64],
        stance: &[bool; LEG_COUNT],
        com: [f64; 3],
        margin: Option<f64>,
    ) {
        for (s, &(n, _)) in self.states.iter_mut().zip(&self.contacts) {
            *s = if stance.get(n.wrapping_sub(1)) == Some(&true) {
                2
            } else {
                1
            };
        }
        let margin = [margin.unwrap_or(f64::NAN)];
        self.frames.push_row(&Row {
            t,
            q,
            contacts: Some((&self.states, &self.forces)),
            com: Some(com),
            values: &margin,
            ..Row::default()
        });
    }

    /// Adds a row of a kinematic gait run from its step's data.
    pub fn push_gait_data(&mut self, d: &fbd_sim::gait::GaitData) {
        let b = &d.body;
        let mut q = Vec::with_capacity(6 + 3 * LEG_COUNT);
        q.extend([
            b.position.x,
            b.position.y,
            b.position.z,
            b.phi.x,
            b.phi.y,
            b.phi.z,
        ]);
        for l in &d.legs {
            q.extend(l.theta);
        }
        let margin = d.margin.is_finite().then_some(d.margin);
        self.push_gait(d.t, &q, &d.stance(), [d.com.x, d.com.y, d.com.z], margin);
    }

    /// Adds a row of a dynamic run: the model's `q` (`6 + 3·legs`), each
    /// contact point's state and ground force (in [`HexapodView::contacts`]'
    /// order) and each leg's values (in [`HexapodView::legs`]' order).
    pub fn push_dynamic(
        &mut self,
        t: f64,
        q: &[f64],
        contacts: &[(StateCode, [f64; 3])],
        legs: &[LegValues],
    ) {
        self.states.clear();
        self.forces.clear();
        for &(s, f) in contacts {
            self.states.push(s as u8 + 1);
            self.forces.push(f);
        }
        self.joint_forces.clear();
        self.values.clear();
        for l in legs {
            self.joint_forces.extend([l.hip_force, l.knee_force]);
        }
        self.values.extend(legs.iter().map(|l| l.normal));
        self.values.extend(legs.iter().map(|l| l.torque[2]));
        self.frames.push_row(&Row {
            t,
            q,
            contacts: Some((&self.states, &self.forces)),
            joint_forces: &self.joint_forces,
            com: None,
            values: &self.values,
        });
    }

    /// The rows of the run's `events.csv`, counted in the page's header.
    pub fn set_event_rows(&mut self, rows: usize) {
        self.frames.set_event_rows(rows);
    }

    /// The complete scene ([`RobotFrames::finish`]).
    pub fn finish(self) -> Result<RobotScene, OutputError> {
        self.frames.finish()
    }

    /// Writes `out_dir/viewer.html` all-or-nothing; returns its path.
    pub fn write(self, out_dir: &Path) -> Result<PathBuf, OutputError> {
        self.frames.write(out_dir)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gait_scene_is_the_robot_scene_of_the_dh_model_with_the_hexapod_decor() {
        let kin = HexapodModel::default();
        let mut v = HexapodView::gait(&kin, Surface::default(), 2, "hexapod");
        let mut q = vec![0.0; 24];
        q[1] = 0.5;
        for leg in 0..6 {
            q[6 + 3 * leg + 2] = 250f64.to_radians();
        }
        let stance = [true, false, true, false, true, false];
        v.push_gait(0.0, &q, &stance, [0.0, 0.5, 0.0], Some(0.1));
        v.push_gait(0.1, &q, &[true; 6], [0.0, 0.5, 0.0], Some(0.1));
        let s = v.finish().unwrap();
        assert_eq!(s.scene.model, super::super::SceneKind::Robot);
        assert_eq!(s.plate.len(), 6);
        assert_eq!(s.labels.len(), 6);
        assert_eq!(s.state_names, ["swing", "stance"]);
        assert!(!s.scene.dynamic);
        assert_eq!(s.scene.state, ["212121", "222222"]);
        assert_eq!(s.scene.ring.len(), 6);
        let events: Vec<&str> = s.scene.events.iter().map(|e| e.label.as_str()).collect();
        assert_eq!(
            events,
            [
                "leg 2 foot swing→stance",
                "leg 4 foot swing→stance",
                "leg 6 foot swing→stance"
            ]
        );
        // The heading arrow points to corner2, the body's front (−z).
        let p = &s.scene.p[0];
        let h = s.heading.unwrap();
        assert!(
            p[3 * h + 2] < -0.2 && p[3 * h].abs() < 1e-9,
            "{:?}",
            &p[3 * h..3 * h + 3]
        );
        let titles: Vec<&str> = s.scene.panels.iter().map(|p| p.title.as_str()).collect();
        assert_eq!(
            titles,
            [
                "Body height Ry (m)",
                "Hip-lift angles θ2 (°)",
                "Knee angles θ3 (°)",
                "Stability margin (m)"
            ]
        );
    }

    #[test]
    fn a_dynamic_scene_orders_feet_first_and_draws_feet_that_are_not_contact_points() {
        let mut p = SpatialParams {
            legs: vec![3, 4],
            ..SpatialParams::default()
        };
        let v = HexapodView::dynamic(&p, 1, "hexapod");
        assert_eq!(v.legs(), [3, 4]);
        assert_eq!(
            v.contacts(),
            [
                (3, PointKind::Tip),
                (4, PointKind::Tip),
                (3, PointKind::Knee),
                (3, PointKind::Hip),
                (4, PointKind::Knee),
                (4, PointKind::Hip)
            ]
        );
        p.contact_points.tips = false;
        let mut v = HexapodView::dynamic(&p, 1, "hexapod");
        assert!(v.contacts().iter().all(|c| c.1 != PointKind::Tip));
        let mut q = vec![0.0, 0.6, 0.0, 0.0, 0.0, 0.0];
        q.extend([0.0, 0.0, 4.3, 0.0, 0.0, 4.3]);
        let nc = v.contacts().len();
        v.push_dynamic(
            0.0,
            &q,
            &vec![(StateCode::St1, [0.0; 3]); nc],
            &[LegValues::default(); 2],
        );
        let s = v.finish().unwrap();
        assert!(s.scene.points.iter().any(|p| p == "tip3"));
        assert!(s.scene.ring.is_empty());
        assert_eq!(s.scene.joints.len(), 4);
        assert_eq!(s.scene.fj[0].len(), 12);
    }
}

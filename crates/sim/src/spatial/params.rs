//! Physical and numerical parameters of a 3D (spatial) hexapod run, in SI
//! units and radians. `fbd-scenario` fills them from a TOML configuration
//! (degrees there).

use crate::gait::GaitModel;
use fbd_contact::{ContactParams, Friction, Surface};
use fbd_dynamics::mechanism::ContactPoints;
use fbd_kinematics::JointLimits;

/// A joint-space target trajectory of one leg, `(θ1, θ2, θ3)` (rad).
pub type LegTrajectory3 = crate::control::LegTrajectory<3>;

/// The joint controller of a spatial run: torques at step `k` computed
/// explicitly from `q[k]` and `q[k−1]`, `τ = kp·(θ* − θ) + kd·(θ̇* − θ̇)`,
/// clamped to `±torque_limit`.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum SpatialControl {
    /// Passive joints: no torque.
    #[default]
    None,
    /// PD regulation to fixed joint angles (`θ̇* = 0`).
    Pd {
        /// Stiffness (N·m/rad), ≥ 0.
        kp: f64,
        /// Damping (N·m·s/rad), ≥ 0.
        kd: f64,
        /// Saturation `|τ| ≤ limit` (N·m), > 0; `None` for no limit.
        torque_limit: Option<f64>,
        /// `(θ1, θ2, θ3)` targets (rad), one per leg of the model, in the
        /// order of [`SpatialParams::legs`].
        target: Vec<[f64; 3]>,
    },
    /// PD tracking of a piecewise-linear joint trajectory per leg
    /// (`θ̇*` = the trajectory's slope).
    Trajectory {
        /// Stiffness (N·m/rad), ≥ 0.
        kp: f64,
        /// Damping (N·m·s/rad), ≥ 0.
        kd: f64,
        /// Saturation `|τ| ≤ limit` (N·m), > 0; `None` for no limit.
        torque_limit: Option<f64>,
        /// One trajectory per leg of the model, order of
        /// [`SpatialParams::legs`].
        legs: Vec<LegTrajectory3>,
    },
    /// Tracking of the kinematic gait generator's joint angles and rates
    /// (feed-forward rates + PD): `θ*`, `θ̇*` of step `k` of `gait`.
    Gait {
        /// Stiffness (N·m/rad), ≥ 0.
        kp: f64,
        /// Damping (N·m·s/rad), ≥ 0.
        kd: f64,
        /// Saturation `|τ| ≤ limit` (N·m), > 0; `None` for no limit.
        torque_limit: Option<f64>,
        /// The kinematic gait (same Δt and duration as the run; all six
        /// legs).
        gait: Box<GaitModel>,
    },
}

/// The gains and torque limit of a [`SpatialControl`] place (`&` or
/// `&mut`), `(kp, kd, torque_limit)`; `None` for passive joints.
macro_rules! control_gains {
    ($control:expr) => {
        match $control {
            SpatialControl::None => None,
            SpatialControl::Pd {
                kp,
                kd,
                torque_limit,
                ..
            }
            | SpatialControl::Trajectory {
                kp,
                kd,
                torque_limit,
                ..
            }
            | SpatialControl::Gait {
                kp,
                kd,
                torque_limit,
                ..
            } => Some((kp, kd, torque_limit)),
        }
    };
}

impl SpatialControl {
    /// The controller's gains and torque limit, `(kp, kd, torque_limit)`;
    /// `None` for passive joints.
    pub fn gains(&self) -> Option<(f64, f64, Option<f64>)> {
        control_gains!(self).map(|(kp, kd, limit)| (*kp, *kd, *limit))
    }

    /// [`Self::gains`] to change in place.
    pub fn gains_mut(&mut self) -> Option<(&mut f64, &mut f64, &mut Option<f64>)> {
        control_gains!(self)
    }
}

/// Everything that defines a spatial (3D) simulation of the hexapod.
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialParams {
    /// Time step Δt (s). Default 0.001.
    pub dt: f64,
    /// Simulated duration (s); `round(duration/dt) + 1` rows. Default 1.0.
    pub duration: f64,
    /// Gravitational acceleration (m/s², along −Y). Default 9.81.
    pub gravity: f64,
    /// Central body mass (kg). Default 10.0.
    pub body_mass: f64,
    /// Central body inertia tensor about its centre of mass in the body
    /// frame, `[Ixx, Iyy, Izz, Ixy, Ixz, Iyz]` (kg·m²). Default: a thin
    /// uniform hexagonal plate of side `L` in the body's x–z plane,
    /// `Ixx = Izz = 5/16·m·L²`, `Iyy = 5/8·m·L²` (0.195, 0.391, 0.195).
    pub body_inertia: [f64; 6],
    /// Side `L` of the hexagonal body (m). Default 0.25.
    pub side: f64,
    /// Upper link length `a` (m). Default 0.2.
    pub upper_length: f64,
    /// Upper link mass (kg). Default 0.3.
    pub upper_mass: f64,
    /// Upper link radius (m): inertia about the link's own axis
    /// `m·r²/2`. Default 0.02.
    pub upper_radius: f64,
    /// Upper link inertia about an axis through its centre of mass
    /// perpendicular to the link (kg·m²). Default: the solid cylinder
    /// `m·(3r² + a²)/12`.
    pub upper_inertia: f64,
    /// Upper link centre of mass, fraction of `a` from the hip. Default 0.5.
    pub upper_com: f64,
    /// Lower link length `c` (m). Default 0.42.
    pub lower_length: f64,
    /// Lower link mass (kg). Default 1.1.
    pub lower_mass: f64,
    /// Lower link radius (m). Default 0.015.
    pub lower_radius: f64,
    /// Lower link transverse inertia about its centre of mass (kg·m²).
    /// Default: the solid cylinder `m·(3r² + c²)/12`.
    pub lower_inertia: f64,
    /// Lower link centre of mass, fraction of `c` from the knee. Default 0.75.
    pub lower_com: f64,
    /// Leg numbers (1–6) that the model has, increasing. Default all six;
    /// `[3, 4]` is the planar model's pair.
    pub legs: Vec<usize>,
    /// Joint limits of θ1, θ2, θ3 (one-sided stops). Default
    /// [`JointLimits::default`].
    pub joint_limits: JointLimits,
    /// Initial generalised coordinates (m, rad):
    /// `(Rx, Ry, Rz, φx, φy, φz, θ1, θ2, θ3 of each leg in `legs`)`.
    pub q0: Vec<f64>,
    /// Initial generalised velocities (m/s, rad/s), same layout; the body's
    /// angular velocity enters as `φ̇ = E(φ)⁻¹·ω`.
    pub qdot0: Vec<f64>,
    /// Terrain surface `y = ϱ(x, z)`. Default flat ground at y = 0.
    pub terrain: Surface,
    /// Soil friction. Default μS = 0.4, μD = 0.3.
    pub friction: Friction,
    /// Which points of each leg can touch the terrain. Default tips, knees
    /// and hips.
    pub contact_points: ContactPoints,
    /// Switching tolerances and regularisation of the contact rows.
    pub contact: ContactParams,
    /// Joint controller. Default passive.
    pub control: SpatialControl,
    /// Write every `stride`-th step. Default 1.
    pub stride: usize,
    /// Newton's settings (`[solver]`). Default
    /// [`crate::SolverSettings::default`]: 6 chord steps, tolerance 1e-9.
    pub solver: crate::SolverSettings,
}

/// `[Ixx, Iyy, Izz]` of a thin uniform hexagonal plate of side `side` and
/// mass `m` lying in the body's x–z plane.
pub fn hexagon_inertia(m: f64, side: f64) -> [f64; 6] {
    let i = 5.0 / 16.0 * m * side * side;
    [i, 2.0 * i, i, 0.0, 0.0, 0.0]
}

impl Default for SpatialParams {
    fn default() -> Self {
        let (upper_mass, upper_radius, upper_length) = (0.3, 0.02, 0.2);
        let (lower_mass, lower_radius, lower_length) = (1.1, 0.015, 0.42);
        let cyl = |m: f64, r: f64, l: f64| m * (3.0 * r * r + l * l) / 12.0;
        Self {
            dt: 0.001,
            duration: 1.0,
            gravity: 9.81,
            body_mass: 10.0,
            body_inertia: hexagon_inertia(10.0, 0.25),
            side: 0.25,
            upper_length,
            upper_mass,
            upper_radius,
            upper_inertia: cyl(upper_mass, upper_radius, upper_length),
            upper_com: 0.5,
            lower_length,
            lower_mass,
            lower_radius,
            lower_inertia: cyl(lower_mass, lower_radius, lower_length),
            lower_com: 0.75,
            legs: (1..=6).collect(),
            joint_limits: JointLimits::default(),
            q0: default_q0(),
            qdot0: vec![0.0; 24],
            terrain: Surface::default(),
            friction: Friction::default(),
            contact_points: ContactPoints::default(),
            contact: ContactParams::default(),
            control: SpatialControl::None,
            stride: 1,
            solver: crate::SolverSettings::default(),
        }
    }
}

/// The default initial state: body 0.6 m up, level; every leg
/// `(θ1, θ2, θ3) = (0°, 0°, 250°)`.
pub fn default_q0() -> Vec<f64> {
    let mut q = vec![0.0; 24];
    q[1] = 0.6;
    for leg in 0..6 {
        q[6 + 3 * leg + 2] = 250f64.to_radians();
    }
    q
}

impl SpatialParams {
    /// The kinematic model (D-H geometry and link centres of mass) of
    /// these parameters: the one source of the hexapod's geometry for the
    /// dynamics, the outputs and the tests.
    pub fn kinematic_model(&self) -> fbd_kinematics::hexapod::HexapodModel {
        fbd_kinematics::hexapod::HexapodModel::new(
            self.side,
            fbd_kinematics::leg::LegGeometry {
                a: self.upper_length,
                c: self.lower_length,
            },
            self.upper_com,
            self.lower_com,
        )
    }

    /// The hexapod of these parameters as a generic [`fbd_robot::RobotModel`],
    /// built from its D-H parameters ([`fbd_robot::dh::hexapod`]): the same
    /// geometry, masses, inertias, legs, joint limits and contact points.
    /// [`super::SpatialModel`] steps it on the generic FBD equations of
    /// `fbd_dynamics::tree`, as every imported robot.
    pub fn robot_model(&self) -> fbd_robot::RobotModel {
        use fbd_robot::JointLimits as Range;
        use fbd_robot::dh::{HexapodLayout, HexapodMasses, hexapod};
        let masses = HexapodMasses {
            body_mass: self.body_mass,
            body_inertia: self.body_inertia,
            upper_mass: self.upper_mass,
            upper_radius: self.upper_radius,
            upper_inertia: self.upper_inertia,
            lower_mass: self.lower_mass,
            lower_radius: self.lower_radius,
            lower_inertia: self.lower_inertia,
        };
        let l = &self.joint_limits;
        // An open range is a continuous joint (no stop).
        let limit = |[lower, upper]: [f64; 2]| {
            (lower.is_finite() || upper.is_finite()).then_some(Range { lower, upper })
        };
        let layout = HexapodLayout {
            legs: self.legs.clone(),
            limits: [limit(l.theta1), limit(l.theta2), limit(l.theta3)],
            tips: self.contact_points.tips,
            knees: self.contact_points.knees,
            hips: self.contact_points.hips,
        };
        hexapod(&self.kinematic_model(), &masses, &layout)
    }

    /// The spatial twin of a planar run: legs 3 and 4 only, θ1 = 0, the
    /// planar initial state in the X–Y plane, the same masses (the body's
    /// inertia isotropic with the planar value about Z, each link's
    /// transverse inertia the planar one), terrain (profile along X),
    /// friction, contact points, joint limits and step. Its motion stays
    /// in the plane and must reproduce the planar engine's (the two engines
    /// check each other). A planar PD or trajectory controller becomes the
    /// same controller with θ1 held at 0.
    pub fn planar_twin(p: &crate::PlanarParams) -> Self {
        let mut q0 = vec![0.0; 12];
        let mut qdot0 = vec![0.0; 12];
        // Planar q = (Rx, Ry, φz, θ2₃, θ3₃, θ2₄, θ3₄).
        let map = [(0, 0), (1, 1), (2, 5), (3, 7), (4, 8), (5, 10), (6, 11)];
        for (from, to) in map {
            q0[to] = p.q0[from];
            qdot0[to] = p.qdot0[from];
        }
        let three = |t: [f64; 2]| [0.0, t[0], t[1]];
        let control = match &p.control {
            crate::Control::None => SpatialControl::None,
            crate::Control::Pd {
                kp,
                kd,
                torque_limit,
                target,
            } => SpatialControl::Pd {
                kp: *kp,
                kd: *kd,
                torque_limit: *torque_limit,
                target: target.iter().map(|t| three(*t)).collect(),
            },
            crate::Control::Trajectory {
                kp,
                kd,
                torque_limit,
                legs,
            } => SpatialControl::Trajectory {
                kp: *kp,
                kd: *kd,
                torque_limit: *torque_limit,
                legs: legs
                    .iter()
                    .map(|l| LegTrajectory3 {
                        times: l.times.clone(),
                        targets: l.targets.iter().map(|t| three(*t)).collect(),
                    })
                    .collect(),
            },
        };
        Self {
            dt: p.dt,
            duration: p.duration,
            gravity: p.gravity,
            body_mass: p.body_mass,
            body_inertia: [
                p.body_inertia,
                p.body_inertia,
                p.body_inertia,
                0.0,
                0.0,
                0.0,
            ],
            side: p.side,
            upper_length: p.upper_length,
            upper_mass: p.upper_mass,
            upper_inertia: p.upper_inertia,
            upper_com: p.upper_com,
            lower_length: p.lower_length,
            lower_mass: p.lower_mass,
            lower_inertia: p.lower_inertia,
            lower_com: p.lower_com,
            legs: vec![3, 4],
            joint_limits: p.joint_limits,
            q0,
            qdot0,
            terrain: Surface::new(p.terrain.clone(), 0.0).with_patches(p.patches.clone()),
            friction: p.friction,
            contact_points: p.contact_points,
            control,
            stride: p.stride,
            solver: p.solver,
            ..Self::default()
        }
    }
}

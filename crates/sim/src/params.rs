//! Physical and numerical parameters of a planar run, in SI units and
//! radians. The CLI fills them from a TOML configuration (degrees there).

use crate::control::Control;
use fbd_contact::{Friction, FrictionPatch, Terrain};
use fbd_dynamics::mechanism::ContactPoints;
use fbd_kinematics::JointLimits;

/// Everything that defines a planar simulation.
#[derive(Clone, Debug, PartialEq)]
pub struct PlanarParams {
    /// Time step Δt (s). Default 0.01, the paper's §6 value.
    pub dt: f64,
    /// Simulated duration (s); the run solves `round(duration/dt) + 1` steps
    /// so that the output covers `[0, duration]`. Default 1.0: touchdown,
    /// sticking and sliding of both feet, the body and knees landing, and
    /// the robot at rest on the ground (all points sticking from 0.73 s).
    pub duration: f64,
    /// Gravitational acceleration (m/s²). Default 9.81.
    pub gravity: f64,
    /// Central body mass (kg). Default 10.0 (chosen, with the other masses,
    /// so that the paper's reported events come out: see the README).
    pub body_mass: f64,
    /// Central body inertia about Z through R (kg·m²). Default 0.3.
    pub body_inertia: f64,
    /// Side `L` of the hexagonal body; hips at `d = L·cos(π/6)` (m).
    /// Default 0.25 (the docs/reference.md test geometry).
    pub side: f64,
    /// Upper link length `a` (m). Default 0.2.
    pub upper_length: f64,
    /// Upper link mass (kg). Default 0.3.
    pub upper_mass: f64,
    /// Upper link inertia about its centre of mass (kg·m²). Default: the
    /// uniform rod `m·a²/12`.
    pub upper_inertia: f64,
    /// Upper link centre of mass, fraction of `a` from the hip. Default 0.5.
    pub upper_com: f64,
    /// Lower link length `c` (m). Default 0.42.
    pub lower_length: f64,
    /// Lower link mass (kg). Default 1.1 (a heavy foot).
    pub lower_mass: f64,
    /// Lower link inertia about its centre of mass (kg·m²). Default: the
    /// uniform rod `m·c²/12`.
    pub lower_inertia: f64,
    /// Lower link centre of mass, fraction of `c` from the knee. Default 0.75
    /// (towards the foot).
    pub lower_com: f64,
    /// Joint limits of θ2 and θ3 (θ1 is unused by the planar model), one-sided
    /// constraints of the dynamics. Default [`JointLimits::default`]: they
    /// keep a collapsing leg from folding flat; [`JointLimits::none`]
    /// switches them off.
    pub joint_limits: JointLimits,
    /// Initial generalised coordinates `(Rx, Ry, φz, θ2₃, θ3₃, θ2₄, θ3₄)`
    /// (m, rad). Default: the paper's §6 table, `(0, 0.6, 0, 0, 245°, 0, 255°)`.
    pub q0: [f64; 7],
    /// Initial generalised velocities (m/s, rad/s). Default zero.
    pub qdot0: [f64; 7],
    /// Terrain. Default flat ground at y = 0.
    pub terrain: Terrain,
    /// Soil friction. Default μS = 0.4, μD = 0.3 (paper §6).
    pub friction: Friction,
    /// Friction patches along the line `z = 0` (the last listed wins;
    /// [`Self::friction`] elsewhere). Default none.
    pub patches: Vec<FrictionPatch>,
    /// Which points can touch the terrain. Default: tips, knees and hips.
    pub contact_points: ContactPoints,
    /// Write every `stride`-th step. Default 1.
    pub stride: usize,
    /// Joint controller. Default [`Control::None`] (passive joints).
    pub control: Control,
    /// Newton's settings (`[solver]`). Default
    /// [`crate::SolverSettings::default`]: 6 chord steps, tolerance 1e-9.
    pub solver: crate::SolverSettings,
}

impl Default for PlanarParams {
    fn default() -> Self {
        let upper_mass = 0.3;
        let upper_length = 0.2;
        let lower_mass = 1.1;
        let lower_length = 0.42;
        Self {
            dt: 0.01,
            duration: 1.0,
            gravity: 9.81,
            body_mass: 10.0,
            body_inertia: 0.3,
            side: 0.25,
            upper_length,
            upper_mass,
            upper_inertia: upper_mass * upper_length * upper_length / 12.0,
            upper_com: 0.5,
            lower_length,
            lower_mass,
            lower_inertia: lower_mass * lower_length * lower_length / 12.0,
            lower_com: 0.75,
            joint_limits: JointLimits::default(),
            q0: [
                0.0,
                0.6,
                0.0,
                0.0,
                245f64.to_radians(),
                0.0,
                255f64.to_radians(),
            ],
            qdot0: [0.0; 7],
            terrain: Terrain::Flat { height: 0.0 },
            friction: Friction::default(),
            patches: Vec::new(),
            contact_points: ContactPoints::default(),
            stride: 1,
            solver: crate::SolverSettings::default(),
            control: Control::None,
        }
    }
}

impl PlanarParams {
    /// The planar model of these parameters as an instance of the generic
    /// robot model in the plane (`fbd_robot::dh::planar`: its D-H rows of
    /// legs 3 and 4 at θ1 = 0, the masses and inertias about `Z`), which
    /// the planar engine steps (`fbd_dynamics::Mechanism::in_plane`).
    pub fn robot_model(&self) -> fbd_robot::RobotModel {
        fbd_robot::dh::planar(
            &self.geometry(),
            &fbd_robot::dh::PlanarMasses {
                body_mass: self.body_mass,
                body_inertia: self.body_inertia,
                upper_mass: self.upper_mass,
                upper_inertia: self.upper_inertia,
                lower_mass: self.lower_mass,
                lower_inertia: self.lower_inertia,
            },
        )
    }

    /// The two-leg geometry: `d = side·cos 30°` from the body centre to
    /// each hip, the link lengths and their centres of mass.
    pub fn geometry(&self) -> fbd_kinematics::planar::PlanarGeometry {
        fbd_kinematics::planar::PlanarGeometry {
            d: self.side * (std::f64::consts::PI / 6.0).cos(),
            a: self.upper_length,
            c: self.lower_length,
            upper_com: self.upper_com,
            lower_com: self.lower_com,
        }
    }

    /// Height (m) of the lowest contact point of the initial configuration
    /// above the terrain under it (negative when below).
    pub fn lowest_clearance(&self) -> f64 {
        let (chains, ix) = fbd_kinematics::planar::PlanarChains::two_leg(&self.geometry());
        let mut kin = chains.new_data();
        chains.eval_positions(&self.q0, &mut kin);
        let cp = self.contact_points;
        [(cp.tips, ix.tip), (cp.knees, ix.knee), (cp.hips, ix.hip)]
            .into_iter()
            .filter(|(on, _)| *on)
            .flat_map(|(_, pts)| pts)
            .map(|p| self.terrain.clearance(kin.pos[p]))
            .fold(f64::INFINITY, f64::min)
    }

    /// Moves the initial body height `Ry` so that the lowest contact point
    /// is `height` (m) above the terrain: a drop from that height.
    pub fn set_drop_height(&mut self, height: f64) {
        // Exact on flat ground; on other terrains the lowest point's
        // terrain height changes with nothing but Ry only when it moves
        // sideways, which a vertical shift does not do.
        self.q0[1] += height - self.lowest_clearance();
    }
}

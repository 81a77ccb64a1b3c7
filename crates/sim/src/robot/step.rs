//! A robot's stages of the staged step: [`RobotSim`] as an [`Engine`] of
//! the generic step ([`crate::engine`]) and a [`SurfaceEngine`] (the 3D
//! contact machinery shared with the hexapod, [`crate::engine::surface`]).
//! What is the robot's here: its controller ([`super::control`]), its
//! joint limits by name and its friction on the ground it is given; the
//! equations ([`fbd_dynamics::tree`]) and the record
//! ([`crate::engine::tree_record`]) are every robot's.

use super::control::joint_torques;
use super::data::RobotData;
use super::model::RobotSim;
use crate::SimError;
use crate::engine::surface;
use crate::engine::{Engine, LimitInfo, Settings};
use fbd_contact::{Friction, Surface};
use fbd_kinematics::Joint;

/// Solves step `data.k` (its record in `data.record`) and advances to
/// `k + 1`, retrying in substeps when the whole step cannot be solved
/// ([`crate::engine::step`]).
///
/// # Errors
/// A [`SimError`] naming the step and time.
pub fn step(model: &RobotSim, data: &mut RobotData) -> Result<(), SimError> {
    crate::engine::step::step(model, data)
}

crate::engine::surface::tree_surface_engine!(RobotSim);

impl Engine for RobotSim {
    type Torques = Vec<f64>;
    type ControlData = Option<Box<super::control::GaitWork>>;

    fn settings(&self) -> Settings<'_, Surface> {
        Settings {
            dt: self.params.dt,
            max_substeps: self.max_substeps,
            cycle_tolerance: self.cycle_tolerance,
            exact: true,
            qdot0: &self.params.qdot0,
            steps: self.steps,
            stride: self.params.stride,
            bodies: self.mech.bodies.len(),
            contacts: &self.contact_specs,
            limits: self.mech.limits.len(),
            ground: self.params.terrain.as_ref().unwrap_or(&self.no_ground),
            friction: &self.params.friction,
            contact: &self.params.contact,
        }
    }
    fn limit(&self, l: usize) -> LimitInfo {
        let lim = &self.mech.limits[l];
        LimitInfo {
            q_index: lim.q_index,
            joint_index: lim.joint,
            joint: Joint::Theta1,
            leg: 0,
            range: lim.range,
        }
    }
    fn limit_name(&self, l: usize) -> String {
        self.mech.model.joints[self.mech.limits[l].joint]
            .name
            .clone()
    }
    crate::engine::surface::surface_stages!();
    fn torques(&self, data: &mut RobotData) -> Result<(), SimError> {
        joint_torques(self, data)
    }
    fn friction_at(&self, at: [f64; 2]) -> Friction {
        match &self.params.terrain {
            Some(s) => surface::friction_on(s, &self.params.friction, at),
            None => self.params.friction,
        }
    }
}

//! The spatial model's stages of the staged step: [`SpatialModel`] as an
//! [`Engine`] of the generic step ([`crate::engine`]: the stages, the
//! state search with its cycle fallbacks and the retry in substeps are the
//! planar model's, one source) and a [`SurfaceEngine`] (the 3D contact
//! machinery of [`crate::engine::surface`], shared with every imported
//! robot).
//!
//! The hexapod's equations and record are every robot's (the generic tree
//! assembly, [`fbd_dynamics::tree`], on its D-H instance, and
//! [`crate::engine::tree_record`]); what is the hexapod's here: its
//! controller and its joint limits by leg.

use super::control::joint_torques;
use super::data::SpatialData;
use super::model::SpatialModel;
use crate::SimError;
use crate::engine::surface::{self, SurfaceSystem};
use crate::engine::{Engine, LimitInfo, Settings};
use fbd_contact::{Friction, Surface};
use fbd_dynamics::tree::TreeMechanism;

pub use crate::engine::surface::{LIMIT_RELEASE_ANGLE, SLIP_RESOLUTION, UNLOADED_STICK_DRIFT};

/// One spatial step's equations as a [`fbd_solver::NewtonSystem`].
pub type SpatialSystem<'a> = SurfaceSystem<'a, TreeMechanism>;

/// Solves step `data.k` (its record in `data.record`) and advances to
/// `k + 1`, retrying in substeps when the whole step cannot be solved
/// ([`crate::engine::step`]).
///
/// # Errors
/// A [`SimError`] naming the step and time.
pub fn step(model: &SpatialModel, data: &mut SpatialData) -> Result<(), SimError> {
    crate::engine::step::step(model, data)
}

crate::engine::surface::tree_surface_engine!(SpatialModel);

impl Engine for SpatialModel {
    type Torques = Vec<[f64; 3]>;
    type ControlData = Option<Box<crate::gait::GaitData>>;

    fn settings(&self) -> Settings<'_, Surface> {
        Settings {
            dt: SpatialModel::dt(self),
            max_substeps: self.max_substeps,
            cycle_tolerance: self.cycle_tolerance,
            exact: true,
            qdot0: &self.params.qdot0,
            steps: self.steps,
            stride: self.params.stride,
            bodies: self.mech.bodies.len(),
            contacts: &self.contacts,
            limits: self.mech.limits.len(),
            ground: &self.params.terrain,
            friction: &self.params.friction,
            contact: &self.params.contact,
        }
    }
    fn limit(&self, l: usize) -> LimitInfo {
        let lim = &self.limits[l];
        LimitInfo {
            q_index: lim.q_index,
            joint_index: lim.q_index,
            joint: lim.joint,
            leg: self.legs[lim.slot],
            range: self.params.joint_limits.range(lim.joint),
        }
    }
    fn limit_name(&self, l: usize) -> String {
        let lim = &self.limits[l];
        format!("theta{}_{}", lim.joint.index() + 1, self.legs[lim.slot])
    }
    crate::engine::surface::surface_stages!();
    fn torques(&self, data: &mut SpatialData) -> Result<(), SimError> {
        joint_torques(self, data)
    }
    fn friction_at(&self, at: [f64; 2]) -> Friction {
        surface::friction_on(&self.params.terrain, &self.params.friction, at)
    }
}

/// Stage 4's system for the accepted states of `data` (for benchmarks,
/// which time the assembly and the factorisation apart).
pub fn system_for_bench<'a>(
    model: &'a SpatialModel,
    data: &'a mut SpatialData,
) -> SpatialSystem<'a> {
    data.trial.copy_from_slice(&data.states);
    data.limit_trial.copy_from_slice(&data.limit_states);
    surface::system(model, data).0
}

//! # fbd-contact
//!
//! The foot–soil interaction of the paper (§5.4, docs/reference.md): a rigid terrain
//! `y = ϱ(x)` with its local tangent and normal ([`terrain`]), and the
//! three-state contact machine ST1 (no contact), ST2 (contact without
//! sliding), ST3 (contact with sliding) with every switching rule
//! ([`mode`]), written once for the plane and 3D ([`machine`]).
//!
//! The crate is pure logic: it decides which equations a contact point
//! contributes; `fbd-dynamics` assembles them and `fbd-sim` re-solves a step
//! until the states are consistent.

pub mod error;
pub mod generate;
pub mod grid;
pub mod machine;
pub mod mode;
pub mod patch;
pub mod spatial;
pub mod surface;
pub mod terrain;

pub use error::ContactError;
pub use generate::{Generator, Sampling, SplitMix};
pub use grid::{GridIssue, HeightGrid};
pub use machine::{ContactMode, ContactTrial, switch};
pub use mode::{ContactParams, ContactState, Friction, StateCode, Trial, transition};
pub use patch::{FrictionPatch, friction_at};
pub use spatial::{SpatialState, SpatialTrial, transition_spatial};
pub use surface::Surface;
pub use terrain::{STEP_RAMP, Terrain, TerrainIssue};

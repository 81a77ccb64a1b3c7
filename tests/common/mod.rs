//! Shared helpers of the workspace-level tests.
#![allow(dead_code)]

pub mod gait;
pub mod harness;
pub mod physics;
pub mod readme;
pub mod spatial;
pub mod strategies;

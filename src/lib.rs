//! # fbd-suite
//!
//! Umbrella of the fbd workspace: re-exports every library crate, and owns
//! the workspace-level integration tests (`tests/`) and criterion benchmarks
//! (`benches/`).

pub use fbd_contact as contact;
pub use fbd_dynamics as dynamics;
pub use fbd_kinematics as kinematics;
pub use fbd_sim as sim;
pub use fbd_solver as solver;

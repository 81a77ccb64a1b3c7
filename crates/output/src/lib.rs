//! # fbd-output
//!
//! The runs of the simulator and every file they write, for the command
//! line (`fbd-cli`) and the Python package alike (docs/reference.md): the
//! `fbd run` drivers writing `trajectory.csv`, `events.csv`,
//! `summary.json`, `config.toml` and the plots ([`run`], [`output`],
//! [`plot`]; a kinematic hexapod run in [`hexapod`], a dynamic one in
//! [`spatial`], an imported robot in [`robot_run`]; the trajectory of
//! every model on the tree equations in [`tree`]), the Parquet output
//! ([`columnar`]), the viewer page ([`viewer`]), sweeps ([`sweep`],
//! [`sweep_plot`]) and the answers of `fbd kinematics` / `fbd inverse`
//! ([`kinematics`]). Nothing here parses a command line; every failure is
//! an [`OutputError`].

pub mod columnar;
/// The configuration: the `fbd-scenario` crate.
pub use fbd_scenario as config;
pub mod driver;
pub mod error;
pub mod hexapod;
pub mod interrupt;
pub mod kinematics;
pub mod output;
pub mod plot;
pub mod robot_run;
pub mod run;
pub mod spatial;
pub mod steptime;
pub mod sweep;
pub mod sweep_plot;
pub mod tree;
pub mod viewer;

pub use config::{Config, ConfigError, Override};
pub use error::OutputError;

//! # fbd-python
//!
//! The native module `fbd._fbd` of the Python package `fbd`: loading a
//! configuration from a path, a TOML string or a dict ([`config`]), whole
//! runs with every trajectory column ([`run`]; a dynamic hexapod in
//! [`spatial`], its kinematic gait in [`hexapod`], an imported robot in
//! [`robot`]), the step-wise
//! [`simulator::Simulator`], sweeps ([`sweep`]) and kinematics
//! ([`kinematics`]). The Python layer (`python/fbd/__init__.py`) wraps the
//! raw results in classes and defines the exceptions this module raises.
//!
//! Every simulation releases the GIL. No panic crosses into Python: the
//! entry points catch them and raise `RuntimeError` instead.

mod columns;
mod config;
mod errors;
mod hexapod;
mod kinematics;
mod observe;
mod robot;
mod run;
mod simulator;
mod spatial;
mod sweep;

use pyo3::prelude::*;

/// The native part of the `fbd` package.
#[pymodule]
fn _fbd(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(run::run, m)?)?;
    m.add_function(wrap_pyfunction!(sweep::sweep, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::kinematics_json, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::inverse_json, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::inverse_motion, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::planar_fk, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::hexapod_fk, m)?)?;
    m.add_function(wrap_pyfunction!(kinematics::leg_ik, m)?)?;
    m.add_function(wrap_pyfunction!(config::config_toml, m)?)?;
    m.add_class::<simulator::Simulator>()?;
    m.add_class::<simulator::SimulatorState>()?;
    m.add_function(wrap_pyfunction!(simulator::step_many, m)?)?;
    m.add_function(wrap_pyfunction!(simulator::observe_many, m)?)?;
    m.add_function(wrap_pyfunction!(simulator::set_pd_targets_many, m)?)?;
    m.add_function(wrap_pyfunction!(simulator::simulators_many, m)?)?;
    m.add_function(wrap_pyfunction!(simulator::_state_from_log, m)?)?;
    m.add_function(wrap_pyfunction!(simulator::_simulator_from_state, m)?)?;
    m.add(
        "TRAJECTORY_SPEC_COLUMNS",
        fbd_output::output::SPEC_COLUMNS.to_vec(),
    )?;
    Ok(())
}

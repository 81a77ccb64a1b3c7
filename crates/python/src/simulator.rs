//! `Simulator(config)`: the planar model, the 24-DOF hexapod or an
//! imported robot (`model = "robot"`) stepped
//! from Python, one Δt at a time, with the configured controller, the
//! caller's joint torques, or PD targets tracked inside Rust
//! ([`fbd_sim::simulator`]); its state saved, restored, copied and
//! pickled; many simulators stepped at once on Rust threads
//! ([`step_many`]).

use fbd_output::config::robot::LoadedRobot;
use fbd_sim::robot::RobotSim;
use fbd_sim::simulator::{Action, PdTargets, Readout, SimState, Simulator as Core};
use fbd_sim::spatial::SpatialModel;
use fbd_sim::{Model, SimError};
use numpy::ndarray::{Array2, Array3};
use numpy::{PyArray1, PyArray2, PyArray3, PyArrayMethods, PyReadonlyArray2};
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict, PyList, PyString};
use rayon::prelude::*;

use crate::errors::{config_error, guard, simulation_error};
use crate::observe::state_code;

/// What a Newton failure after the caller's own torques most often means.
const EXTERNAL_TORQUE_HINT: &str = "; the torques given to step() are applied explicitly: \
     a feedback law with gains kp, kd is stable only while kp·Δt²/I + 2·kd·Δt/I < 4 \
     (I: the effective joint inertia, about 1e-2 kg·m² for the default legs), so lower \
     the gains or time.dt, or track targets inside the step with set_pd_targets()";

/// The stepped model: planar, the hexapod, or an imported robot (with
/// its loaded configuration: names, events).
#[derive(Clone)]
enum Plant {
    Planar(Box<Model>),
    Hexapod(Box<SpatialModel>),
    Robot(Box<RobotSim>, Box<LoadedRobot>),
}

/// A simulator of any model.
enum Sim {
    Planar(Box<Core<Model>>),
    Hexapod(Box<Core<SpatialModel>>),
    Robot(Box<Core<RobotSim>>),
}

/// A saved state of any model.
#[derive(Clone)]
enum Saved {
    Planar(Box<SimState<Model>>),
    Hexapod(Box<SimState<SpatialModel>>),
    Robot(Box<SimState<RobotSim>>),
}

impl Sim {
    fn new(plant: &Plant) -> Self {
        match plant {
            Plant::Planar(m) => Sim::Planar(Box::new(Core::new((**m).clone()))),
            Plant::Hexapod(m) => Sim::Hexapod(Box::new(Core::new((**m).clone()))),
            Plant::Robot(m, _) => Sim::Robot(Box::new(Core::new((**m).clone()))),
        }
    }
    fn step(&mut self, action: &Action<'_>) -> Result<(), SimError> {
        match self {
            Sim::Planar(s) => s.step(action),
            Sim::Hexapod(s) => s.step(action),
            Sim::Robot(s) => s.step(action),
        }
    }
    fn readout(&self, out: &mut Readout) {
        match self {
            Sim::Planar(s) => s.readout_into(out),
            Sim::Hexapod(s) => s.readout_into(out),
            Sim::Robot(s) => s.readout_into(out),
        }
    }
    fn k(&self) -> usize {
        match self {
            Sim::Planar(s) => s.k(),
            Sim::Hexapod(s) => s.k(),
            Sim::Robot(s) => s.k(),
        }
    }
    fn q(&self) -> &[f64] {
        match self {
            Sim::Planar(s) => s.q(),
            Sim::Hexapod(s) => s.q(),
            Sim::Robot(s) => s.q(),
        }
    }
    fn qdot(&self) -> Vec<f64> {
        let mut v = vec![0.0; self.q().len()];
        match self {
            Sim::Planar(s) => s.qdot(&mut v),
            Sim::Hexapod(s) => s.qdot(&mut v),
            Sim::Robot(s) => s.qdot(&mut v),
        }
        v
    }
    fn joints(&self) -> usize {
        match self {
            Sim::Planar(s) => s.joints(),
            Sim::Hexapod(s) => s.joints(),
            Sim::Robot(s) => s.joints(),
        }
    }
    fn state(&self) -> Saved {
        match self {
            Sim::Planar(s) => Saved::Planar(Box::new(s.state())),
            Sim::Hexapod(s) => Saved::Hexapod(Box::new(s.state())),
            Sim::Robot(s) => Saved::Robot(Box::new(s.state())),
        }
    }
    fn set_state(&mut self, saved: &Saved) -> bool {
        match (self, saved) {
            (Sim::Planar(s), Saved::Planar(v)) => s.set_state(v),
            (Sim::Hexapod(s), Saved::Hexapod(v)) => s.set_state(v),
            (Sim::Robot(s), Saved::Robot(v)) => s.set_state(v),
            _ => return false,
        }
        true
    }
    fn copy(&self, plant: &Plant) -> Self {
        let mut s = Sim::new(plant);
        s.set_state(&self.state());
        s
    }
}

/// One entry of the log of what a simulator was stepped with since its
/// initial state: a pickled state is the configuration and this log,
/// replayed when it is restored (stepping is deterministic: the replay is
/// the run, bit for bit).
#[derive(Clone, Debug, PartialEq)]
enum Logged {
    Controller,
    Torques(Vec<f64>),
    Pd(PdTargets),
}

/// The action of one call and how many steps it was held.
#[derive(Clone, Debug, PartialEq)]
struct LogEntry {
    action: Logged,
    steps: usize,
}

/// Appends `steps` steps of `action` to `log` (merged with the last entry
/// when the same).
fn log_push(log: &mut Vec<LogEntry>, action: &Logged, steps: usize) {
    if steps == 0 {
        return;
    }
    match log.last_mut() {
        Some(last) if last.action == *action => last.steps += steps,
        _ => log.push(LogEntry {
            action: action.clone(),
            steps,
        }),
    }
}

/// The log as little-endian f64s: per entry `kind, steps, n` then the
/// values (torques; or kp, kd, targets, rates and the limit, NaN for none).
fn log_bytes(log: &[LogEntry]) -> Vec<u8> {
    let mut v: Vec<f64> = Vec::new();
    for e in log {
        match &e.action {
            Logged::Controller => v.extend([0.0, e.steps as f64, 0.0]),
            Logged::Torques(t) => {
                v.extend([1.0, e.steps as f64, t.len() as f64]);
                v.extend(t);
            }
            Logged::Pd(p) => {
                v.extend([2.0, e.steps as f64, p.kp.len() as f64]);
                for x in [&p.kp, &p.kd, &p.position, &p.velocity] {
                    v.extend(x);
                }
                v.push(p.torque_limit.unwrap_or(f64::NAN));
            }
        }
    }
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// The inverse of [`log_bytes`].
fn log_from_bytes(b: &[u8]) -> Option<Vec<LogEntry>> {
    if !b.len().is_multiple_of(8) {
        return None;
    }
    let v: Vec<f64> = b
        .chunks_exact(8)
        .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
        .collect();
    let mut log = Vec::new();
    let mut i = 0;
    while i < v.len() {
        let (kind, steps, n) = (v[i], *v.get(i + 1)? as usize, *v.get(i + 2)? as usize);
        i += 3;
        let mut take = |m: usize| -> Option<Vec<f64>> {
            let s = v.get(i..i + m)?.to_vec();
            i += m;
            Some(s)
        };
        let action = match kind as u8 {
            0 => Logged::Controller,
            1 => Logged::Torques(take(n)?),
            2 => {
                let (kp, kd, position, velocity) = (take(n)?, take(n)?, take(n)?, take(n)?);
                let l = take(1)?[0];
                Logged::Pd(PdTargets {
                    kp,
                    kd,
                    torque_limit: (!l.is_nan()).then_some(l),
                    position,
                    velocity,
                })
            }
            _ => return None,
        };
        log.push(LogEntry { action, steps });
    }
    Some(log)
}

/// A saved state of a `Simulator` (`Simulator.get_state()`): restored with
/// `Simulator.set_state(state)`, bit for bit. Picklable: the pickle holds
/// the configuration and the actions applied since the initial state,
/// which `set_state` replays in Rust (the GIL released) when the state
/// comes from a pickle.
#[pyclass(module = "fbd._fbd", name = "SimulatorState", frozen)]
pub struct SimulatorState {
    /// The complete configuration (TOML).
    config: String,
    /// Steps solved at this state.
    k: usize,
    /// The in-memory state (`None` after unpickling).
    saved: Option<Saved>,
    log: Vec<LogEntry>,
}

#[pymethods]
impl SimulatorState {
    /// Steps solved at this state.
    #[getter]
    fn k(&self) -> usize {
        self.k
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        let py = slf.py();
        let s = slf.get();
        let f = py.import("fbd._fbd")?.getattr("_state_from_log")?;
        let args = (s.config.clone(), s.k, PyBytes::new(py, &log_bytes(&s.log)));
        (f, args).into_pyobject(py).map(|t| t.into_any())
    }

    fn __repr__(&self) -> String {
        format!("<fbd.SimulatorState k={}>", self.k)
    }
}

/// Rebuilds a pickled [`SimulatorState`].
#[pyfunction]
pub fn _state_from_log(config: String, k: usize, log: &[u8]) -> PyResult<SimulatorState> {
    let log = log_from_bytes(log).ok_or_else(|| PyValueError::new_err("corrupt SimulatorState"))?;
    Ok(SimulatorState {
        config,
        k,
        saved: None,
        log,
    })
}

/// The planar model, the 24-DOF hexapod or an imported robot stepped one
/// Δt at a time, for controllers written in Python. `config` is a configuration as for
/// `fbd.run` (None, a path, TOML text or a dict). See the reference
/// (docs/reference.md, "fbd.Simulator") for every attribute.
#[pyclass(module = "fbd._fbd")]
pub struct Simulator {
    plant: Plant,
    sim: Sim,
    source: String,
    /// The complete configuration (TOML), for pickles.
    config: String,
    contacts: Vec<String>,
    coordinates: Vec<String>,
    joint_names: Vec<String>,
    pd: Option<PdTargets>,
    log: Vec<LogEntry>,
    readout: Readout,
    /// The error that stopped the simulation (steps refuse until reset).
    failed: Option<SimError>,
}

/// Coordinate names: `trajectory.csv`'s.
fn coordinate_names(plant: &Plant) -> Vec<String> {
    match plant {
        Plant::Planar(_) => [
            "rx", "ry", "phi_z", "theta2_3", "theta3_3", "theta2_4", "theta3_4",
        ]
        .map(String::from)
        .to_vec(),
        Plant::Hexapod(m) => {
            let mut v: Vec<String> = ["rx", "ry", "rz", "phi_x", "phi_y", "phi_z"]
                .map(String::from)
                .to_vec();
            for leg in &m.legs {
                for j in 1..=3 {
                    v.push(format!("theta{j}_{leg}"));
                }
            }
            v
        }
        Plant::Robot(_, r) => {
            let mut v: Vec<String> = fbd_output::config::robot::MOTION_BASE_COLUMNS
                .map(String::from)
                .to_vec();
            v.extend(r.model.joints.iter().map(|j| j.name.clone()));
            v
        }
    }
}

impl Simulator {
    fn build(plant: Plant, source: String, config: String) -> Self {
        let sim = Sim::new(&plant);
        let contacts = match &plant {
            Plant::Planar(m) => m.mech.contacts.iter().map(|c| c.name.clone()).collect(),
            Plant::Hexapod(m) => m.mech.contacts.iter().map(|c| c.name.clone()).collect(),
            Plant::Robot(m, _) => m.mech.contacts.iter().map(|c| c.name.clone()).collect(),
        };
        let coordinates = coordinate_names(&plant);
        let joint_names = match &sim {
            Sim::Planar(s) => s.model().joint_indices_names(&coordinates),
            Sim::Hexapod(s) => s.model().joint_indices_names(&coordinates),
            Sim::Robot(s) => s.model().joint_indices_names(&coordinates),
        };
        let mut s = Self {
            plant,
            sim,
            source,
            config,
            contacts,
            coordinates,
            joint_names,
            pd: None,
            log: Vec::new(),
            readout: Readout::default(),
            failed: None,
        };
        s.refresh();
        s
    }

    fn refresh(&mut self) {
        self.sim.readout(&mut self.readout);
    }

    fn dt_(&self) -> f64 {
        match &self.plant {
            Plant::Planar(m) => m.dt(),
            Plant::Hexapod(m) => m.dt(),
            Plant::Robot(m, _) => m.params.dt,
        }
    }
    /// Sets PD targets `position` with gains `kp`, `kd` (numbers or one
    /// per joint), `rates` (default 0) and `torque_limit`, each checked
    /// (`set_pd_targets`, `set_pd_targets_many`).
    fn pd_targets_of(
        &mut self,
        position: Vec<f64>,
        kp: &Bound<'_, PyAny>,
        kd: &Bound<'_, PyAny>,
        rates: Option<&Bound<'_, PyAny>>,
        torque_limit: Option<f64>,
    ) -> PyResult<()> {
        let kp = self.vector(kp, "kp")?;
        let kd = self.vector(kd, "kd")?;
        let velocity = match rates {
            Some(r) if !r.is_none() => self.vector(r, "rates")?,
            _ => vec![0.0; position.len()],
        };
        if let Some(l) = torque_limit
            && !(l.is_finite() && l > 0.0)
        {
            return Err(PyValueError::new_err(format!(
                "torque_limit: must be positive and finite, got {l}"
            )));
        }
        for (name, v) in [("kp", &kp), ("kd", &kd)] {
            if v.iter().any(|x| !(x.is_finite() && *x >= 0.0)) {
                return Err(PyValueError::new_err(format!(
                    "{name}: must be finite and ≥ 0"
                )));
            }
        }
        if position.iter().chain(&velocity).any(|x| !x.is_finite()) {
            return Err(PyValueError::new_err("targets and rates must be finite"));
        }
        self.pd = Some(PdTargets {
            kp,
            kd,
            torque_limit,
            position,
            velocity,
        });
        Ok(())
    }

    fn vector(&self, v: &Bound<'_, PyAny>, what: &str) -> PyResult<Vec<f64>> {
        let n = self.sim.joints();
        let names = match &self.plant {
            Plant::Planar(_) => "hip3, knee3, hip4, knee4".to_owned(),
            Plant::Hexapod(_) => "θ1, θ2, θ3 of leg 1, then leg 2, …".to_owned(),
            Plant::Robot(..) => "the joints of joint_names in order".to_owned(),
        };
        let kind = if what == "torques" {
            "joint torques"
        } else {
            "values, one per joint"
        };
        let bad = || {
            PyValueError::new_err(format!(
                "{what}: expected a sequence of {n} numbers ({names}){}",
                if what == "torques" { " or None" } else { "" }
            ))
        };
        let v: Vec<f64> = if let Ok(a) = v.cast::<PyArray1<f64>>() {
            a.readonly()
                .as_slice()
                .map(<[f64]>::to_vec)
                .map_err(|_| bad())?
        } else if what != "torques"
            && (v.is_instance_of::<pyo3::types::PyFloat>()
                || v.is_instance_of::<pyo3::types::PyInt>())
        {
            vec![v.extract::<f64>()?; n]
        } else {
            v.extract::<Vec<f64>>().map_err(|_| bad())?
        };
        if v.len() != n {
            return Err(PyValueError::new_err(format!(
                "{what}: expected {n} {kind} ({names}), got {}",
                v.len()
            )));
        }
        if what == "torques"
            && let Some(e) = nonfinite_torque(&v)
        {
            return Err(PyValueError::new_err(e));
        }
        Ok(v)
    }

    fn fail_error(&self, py: Python<'_>, e: &SimError, torques_given: bool) -> PyErr {
        let hint = if torques_given && matches!(e, SimError::Newton { .. }) {
            EXTERNAL_TORQUE_HINT
        } else {
            ""
        };
        let msg = format!("{e} ({}){hint}", self.source);
        simulation_error(
            py,
            &msg,
            e.step(),
            e.step().map(|k| k as f64 * self.dt_()),
            None,
        )
    }

    /// Runs `steps` steps of `action` on `sim` (no GIL needed); the steps
    /// done and the error that stopped them.
    fn advance(sim: &mut Sim, action: &Action<'_>, steps: usize) -> (usize, Option<SimError>) {
        for i in 0..steps {
            match std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| sim.step(action))) {
                Ok(Ok(())) => {}
                Ok(Err(e)) => return (i, Some(e)),
                Err(_) => {
                    let k = sim.k();
                    return (
                        i,
                        Some(SimError::NonFinite {
                            step: k,
                            t: f64::NAN,
                            residual: f64::NAN,
                        }),
                    );
                }
            }
        }
        (steps, None)
    }

    /// The action of a call: torques, else the PD targets, else the
    /// configured controller.
    fn action_of(&self, torques: Option<Vec<f64>>) -> Logged {
        match (torques, &self.pd) {
            (Some(t), _) => Logged::Torques(t),
            (None, Some(p)) => Logged::Pd(p.clone()),
            (None, None) => Logged::Controller,
        }
    }

    /// After `done` steps of `action` and maybe an error: the log, the
    /// readouts, the failure.
    fn finish(
        &mut self,
        py: Python<'_>,
        action: &Logged,
        done: usize,
        error: Option<SimError>,
    ) -> PyResult<()> {
        log_push(&mut self.log, action, done);
        self.refresh();
        match error {
            None => Ok(()),
            Some(e) => {
                let err = self.fail_error(py, &e, matches!(action, Logged::Torques(_)));
                self.failed = Some(e);
                Err(err)
            }
        }
    }

    fn check_failed(&self, py: Python<'_>) -> PyResult<()> {
        if let Some(e) = &self.failed {
            let msg = format!(
                "{e} ({}; call reset() or set_state() to go on)",
                self.source
            );
            return Err(simulation_error(
                py,
                &msg,
                e.step(),
                e.step().map(|k| k as f64 * self.dt_()),
                None,
            ));
        }
        Ok(())
    }

    fn arr3<'py>(&self, py: Python<'py>, rows: &[[f64; 3]]) -> Bound<'py, PyArray2<f64>> {
        let a = Array2::from_shape_fn((rows.len(), 3), |(i, j)| rows[i][j]);
        PyArray2::from_owned_array(py, a)
    }
}

/// Joint names from the coordinate names.
trait JointNames {
    fn joint_indices_names(&self, coordinates: &[String]) -> Vec<String>;
}

impl<M: fbd_sim::Plant> JointNames for M {
    fn joint_indices_names(&self, coordinates: &[String]) -> Vec<String> {
        self.joint_indices()
            .iter()
            .map(|&i| coordinates[i].clone())
            .collect()
    }
}

fn action_ref(a: &Logged) -> Action<'_> {
    match a {
        Logged::Controller => Action::Controller,
        Logged::Torques(t) => Action::Torques(t),
        Logged::Pd(p) => Action::Pd(p),
    }
}

#[pymethods]
impl Simulator {
    #[new]
    #[pyo3(signature = (config=None))]
    fn new(py: Python<'_>, config: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        guard(|| {
            let prepared = prepare(py, config)?;
            assemble(prepared).map_err(|f| f.into_err(py))
        })
    }

    /// Advances `steps` steps (one by default) with the GIL released:
    /// with `torques` (one per joint, held for the `steps` steps) when
    /// given, else with the PD targets of `set_pd_targets`, else with the
    /// configured controller.
    #[pyo3(signature = (torques=None, steps=1))]
    fn step(
        &mut self,
        py: Python<'_>,
        torques: Option<&Bound<'_, PyAny>>,
        steps: usize,
    ) -> PyResult<()> {
        let torques = match torques {
            Some(t) if !t.is_none() => Some(self.vector(t, "torques")?),
            _ => None,
        };
        self.check_failed(py)?;
        let action = self.action_of(torques);
        let sim = &mut self.sim;
        let mut done = 0;
        let mut error = None;
        let mut interrupt = None;
        py.detach(|| {
            let a = action_ref(&action);
            while done < steps {
                let chunk = (steps - done).min(crate::run::SIGNAL_CHECK);
                let (d, e) = Self::advance(sim, &a, chunk);
                done += d;
                if e.is_some() {
                    error = e;
                    return;
                }
                if done < steps
                    && let Err(e) = Python::attach(|py| py.check_signals())
                {
                    interrupt = Some(e);
                    return;
                }
            }
        });
        self.finish(py, &action, done, error)?;
        match interrupt {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// PD targets tracked inside Rust by `step()` without torques:
    /// `τ = kp·(θ* − θ[k]) + kd·(θ̇* − θ̇[k])`, clamped to `±torque_limit`,
    /// the law of `[control] kind = "pd"`. `kp`, `kd` are numbers or one
    /// value per joint; `targets` (rad) and `rates` (rad/s, default 0) one
    /// per joint (`joint_names`).
    #[pyo3(signature = (targets, kp, kd, rates=None, torque_limit=None))]
    fn set_pd_targets(
        &mut self,
        targets: &Bound<'_, PyAny>,
        kp: &Bound<'_, PyAny>,
        kd: &Bound<'_, PyAny>,
        rates: Option<&Bound<'_, PyAny>>,
        torque_limit: Option<f64>,
    ) -> PyResult<()> {
        let position = self.vector(targets, "targets")?;
        self.pd_targets_of(position, kp, kd, rates, torque_limit)
    }

    /// Stops PD tracking: `step()` without torques uses the configured
    /// controller again.
    fn clear_pd_targets(&mut self) {
        self.pd = None;
    }

    /// The PD targets in use (`targets`, `rates`, `kp`, `kd`,
    /// `torque_limit`), or None.
    #[getter]
    fn pd_targets<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        let Some(p) = &self.pd else { return Ok(None) };
        let d = PyDict::new(py);
        d.set_item("targets", PyArray1::from_slice(py, &p.position))?;
        d.set_item("rates", PyArray1::from_slice(py, &p.velocity))?;
        d.set_item("kp", PyArray1::from_slice(py, &p.kp))?;
        d.set_item("kd", PyArray1::from_slice(py, &p.kd))?;
        d.set_item("torque_limit", p.torque_limit)?;
        Ok(Some(d))
    }

    /// Back to the initial state of the configuration (PD targets kept).
    fn reset(&mut self) {
        self.sim = Sim::new(&self.plant);
        self.log.clear();
        self.failed = None;
        self.refresh();
    }

    /// The current state, for `set_state` (bit-identical stepping after
    /// it); picklable.
    fn get_state(&self) -> SimulatorState {
        SimulatorState {
            config: self.config.clone(),
            k: self.sim.k(),
            saved: Some(self.sim.state()),
            log: self.log.clone(),
        }
    }

    /// Back to a state of `get_state()` of a simulator of the same
    /// configuration (a pickled state is replayed from the initial state
    /// with the GIL released).
    fn set_state(&mut self, py: Python<'_>, state: &Bound<'_, SimulatorState>) -> PyResult<()> {
        let s = state.get();
        if s.config != self.config {
            return Err(PyValueError::new_err(
                "set_state: the state is of a simulator of another configuration",
            ));
        }
        match &s.saved {
            Some(saved) => {
                if !self.sim.set_state(saved) {
                    return Err(PyValueError::new_err(
                        "set_state: a state of the other model",
                    ));
                }
            }
            None => {
                let mut sim = Sim::new(&self.plant);
                let log = s.log.clone();
                let error = py.detach(|| {
                    for e in &log {
                        let (_, err) = Self::advance(&mut sim, &action_ref(&e.action), e.steps);
                        if err.is_some() {
                            return err;
                        }
                    }
                    None
                });
                if let Some(e) = error {
                    return Err(PyRuntimeError::new_err(format!(
                        "set_state: replaying the pickled state failed: {e}"
                    )));
                }
                self.sim = sim;
            }
        }
        self.log.clone_from(&s.log);
        self.failed = None;
        self.refresh();
        Ok(())
    }

    /// An independent simulator in the same state (PD targets included).
    fn copy(&self) -> Self {
        Self {
            plant: self.plant.clone(),
            sim: self.sim.copy(&self.plant),
            source: self.source.clone(),
            config: self.config.clone(),
            contacts: self.contacts.clone(),
            coordinates: self.coordinates.clone(),
            joint_names: self.joint_names.clone(),
            pd: self.pd.clone(),
            log: self.log.clone(),
            readout: self.readout.clone(),
            failed: None,
        }
    }

    fn __copy__(&self) -> Self {
        self.copy()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Self {
        self.copy()
    }

    /// Pickles as the configuration, the PD targets and the state.
    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyAny>> {
        let py = slf.py();
        let s = slf.borrow();
        let f = py.import("fbd._fbd")?.getattr("_simulator_from_state")?;
        let pd = s.pd.as_ref().map(|p| {
            PyBytes::new(
                py,
                &log_bytes(&[LogEntry {
                    action: Logged::Pd(p.clone()),
                    steps: 1,
                }]),
            )
        });
        let args = (
            s.config.clone(),
            s.source.clone(),
            Bound::new(py, s.get_state())?,
            pd,
        );
        (f, args).into_pyobject(py).map(|t| t.into_any())
    }

    /// `"planar"`, `"hexapod"` or `"robot"`.
    #[getter]
    fn model(&self) -> &'static str {
        match &self.plant {
            Plant::Planar(_) => "planar",
            Plant::Hexapod(_) => "hexapod",
            Plant::Robot(..) => "robot",
        }
    }

    /// The imported robot's name (from its description), None for the
    /// paper's models.
    #[getter]
    fn robot_name(&self) -> Option<String> {
        match &self.plant {
            Plant::Robot(_, r) => Some(r.model.name.clone()),
            _ => None,
        }
    }

    /// Names of the bodies of `observe()`'s `body_*` rows for an imported
    /// robot (every body of the model, the root first); empty for the
    /// paper's models.
    #[getter]
    fn body_names(&self) -> Vec<String> {
        match &self.plant {
            Plant::Robot(_, r) => r.model.bodies.iter().map(|b| b.name.clone()).collect(),
            _ => Vec::new(),
        }
    }

    /// Names of an imported robot's joint reactions, the rows of
    /// `joint_forces` and `observe()`'s `reaction_*` (each named by its
    /// first joint, as the `<joint>_fx` columns of `trajectory.csv`);
    /// empty for the paper's models.
    #[getter]
    fn reaction_names(&self) -> Vec<String> {
        match &self.plant {
            Plant::Robot(m, r) => m
                .mech
                .reactions
                .iter()
                .map(|x| r.model.joints[x.joints[0]].name.clone())
                .collect(),
            _ => Vec::new(),
        }
    }

    /// An imported robot's configured controller (`[control]`):
    /// `{"kind": "none" | "pd" | "trajectory" | "gait", "kp", "kd"}` (arrays per
    /// joint, N·m/rad and N·m·s/rad; empty for `"none"`), `"torque_limit"`
    /// (N·m or None) and for `"pd"` its `"targets"` (rad); None for the
    /// paper's models.
    #[getter]
    fn control<'py>(&self, py: Python<'py>) -> PyResult<Option<Bound<'py, PyDict>>> {
        use fbd_sim::robot::RobotControl;
        let Plant::Robot(m, _) = &self.plant else {
            return Ok(None);
        };
        let d = PyDict::new(py);
        let (kind, kp, kd, limit): (&str, &[f64], &[f64], Option<f64>) = match &m.params.control {
            RobotControl::None => ("none", &[], &[], None),
            RobotControl::Pd {
                kp,
                kd,
                target,
                torque_limit,
            } => {
                d.set_item("targets", PyArray1::from_slice(py, target))?;
                ("pd", kp, kd, *torque_limit)
            }
            RobotControl::Trajectory {
                kp,
                kd,
                torque_limit,
                ..
            } => ("trajectory", kp, kd, *torque_limit),
            RobotControl::Gait {
                kp,
                kd,
                torque_limit,
                ..
            } => ("gait", kp, kd, *torque_limit),
        };
        d.set_item("kind", kind)?;
        d.set_item("kp", PyArray1::from_slice(py, kp))?;
        d.set_item("kd", PyArray1::from_slice(py, kd))?;
        d.set_item("torque_limit", limit)?;
        Ok(Some(d))
    }

    /// An imported robot's smallest effective joint inertia (kg·m²) of the
    /// free robot at `q0` and the joint that moves most in that mode: the
    /// `I` of fbd's PD stability rule `kp·Δt²/I + 2·kd·Δt/I < 4`
    /// (docs/reference.md, the PD stability rule); None for the paper's
    /// models or a robot without joints.
    #[getter]
    fn joint_inertia(&self) -> Option<(f64, String)> {
        let Plant::Robot(m, r) = &self.plant else {
            return None;
        };
        let nj = r.model.joints.len();
        if nj == 0 {
            return None;
        }
        let mass = fbd_sim::robot::mass_matrix(&r.model, &m.params.q0);
        let joints: Vec<usize> = (6..6 + nj).collect();
        let none = fbd_kinematics::nalgebra::DMatrix::zeros(0, mass.ncols());
        let mode = fbd_sim::joint_inertia::fastest_mode(&mass, &none, &joints);
        Some((mode.inertia, r.model.joints[mode.joint].name.clone()))
    }

    /// Effort limit of each joint from an imported robot's description
    /// (N·m, NaN for none), in `joint_names` order; None for the paper's
    /// models.
    #[getter]
    fn effort_limits<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyArray1<f64>>> {
        match &self.plant {
            Plant::Robot(m, _) => Some(PyArray1::from_vec(
                py,
                m.effort.iter().map(|e| e.unwrap_or(f64::NAN)).collect(),
            )),
            _ => None,
        }
    }

    /// Time of the current state `q` (s): `k·Δt`.
    #[getter]
    fn t(&self) -> f64 {
        self.sim.k() as f64 * self.dt_()
    }

    /// Steps solved so far (`k`; the current state is `q[k]`).
    #[getter]
    fn k(&self) -> usize {
        self.sim.k()
    }

    /// Time step Δt (s).
    #[getter]
    fn dt(&self) -> f64 {
        self.dt_()
    }

    /// Steps of the configured duration: `round(duration/dt) + 1`.
    #[getter]
    fn steps(&self) -> usize {
        match &self.plant {
            Plant::Planar(m) => m.steps,
            Plant::Hexapod(m) => m.steps,
            Plant::Robot(m, _) => m.steps,
        }
    }

    /// Whether the current state is at or past the configured duration
    /// (`k ≥ steps − 1`): stepping goes on, the duration only bounds
    /// `fbd.run`.
    #[getter]
    fn past_duration(&self) -> bool {
        self.sim.k() + 1 >= self.steps()
    }

    /// `q[k]` (m, rad), a new array: the planar model's `(Rx, Ry, φz, θ2₃,
    /// θ3₃, θ2₄, θ3₄)`, the hexapod's 24 coordinates in the order of
    /// `fbd.hexapod_fk`, an imported robot's root `(R, φ)` then its joint
    /// angles in model order (`coordinate_names`).
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, self.sim.q())
    }

    /// The backward difference `(q[k] − q[k−1])/Δt`, the initial velocity
    /// at `k = 0`: the rate the PD law uses.
    #[getter]
    fn qdot<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.sim.qdot())
    }

    /// The initial configuration `q[0]` (m, rad).
    #[getter]
    fn q0<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        match &self.plant {
            Plant::Planar(m) => PyArray1::from_slice(py, &m.params.q0),
            Plant::Hexapod(m) => PyArray1::from_slice(py, &m.params.q0),
            Plant::Robot(m, _) => PyArray1::from_slice(py, &m.params.q0),
        }
    }

    /// Names of the coordinates of `q` (`trajectory.csv`'s columns).
    #[getter]
    fn coordinate_names(&self) -> Vec<String> {
        self.coordinates.clone()
    }

    /// Names of the actuated joints, the order of torques and targets: the
    /// planar `theta2_3, theta3_3, theta2_4, theta3_4` (hip3, knee3, hip4,
    /// knee4); the hexapod's `theta1_1, theta2_1, theta3_1, theta1_2, …`;
    /// an imported robot's joint names in model order.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.joint_names.clone()
    }

    /// Names of the contact points, e.g. `["tip3", "tip4", ...]`.
    #[getter]
    fn contact_points(&self) -> Vec<String> {
        self.contacts.clone()
    }

    /// State of each contact point at the last solved step: 1 (ST1, free),
    /// 2 (ST2, sticking), 3 (ST3, sliding); the initial states before the
    /// first step.
    #[getter]
    fn contact_states<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<u8>> {
        let codes: Vec<u8> = self
            .readout
            .contacts
            .iter()
            .map(|c| state_code(c.state))
            .collect();
        PyArray1::from_vec(py, codes)
    }

    /// Contact forces at the last solved step (N; zeros before the first):
    /// the planar model's `(Fa, N)` along the terrain tangent and normal,
    /// shape `(points, 2)`; the hexapod's force of the ground on each point
    /// in the inertial frame, shape `(points, 3)`.
    #[getter]
    fn contact_forces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        if let Sim::Planar(s) = &self.sim {
            let r = &s.data().record;
            let n = self.contacts.len();
            let a = Array2::from_shape_fn((n, 2), |(c, j)| {
                let row = &r.contacts[c];
                if j == 0 {
                    row.tangential[0]
                } else {
                    row.normal
                }
            });
            return PyArray2::from_owned_array(py, a);
        }
        let f: Vec<[f64; 3]> = self.readout.contacts.iter().map(|c| c.force).collect();
        self.arr3(py, &f)
    }

    /// Inertial positions of the contact points (m): the planar model's at
    /// the last solved step (`(points, 2)`; at `q[0]` before the first),
    /// the hexapod's at `q[k]` (`(points, 3)`).
    #[getter]
    fn contact_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        if let Sim::Planar(s) = &self.sim {
            let n = self.contacts.len();
            let d = s.data();
            let a = Array2::from_shape_fn((n, 2), |(c, j)| {
                if d.k == 0 {
                    d.fbd.kin.pos[s.model().mech.contacts[c].point][j]
                } else {
                    d.record.contacts[c].point[j]
                }
            });
            return PyArray2::from_owned_array(py, a);
        }
        let p: Vec<[f64; 3]> = self.readout.contacts.iter().map(|c| c.position).collect();
        self.arr3(py, &p)
    }

    /// Joint forces at the last solved step (N, parent on child, inertial
    /// frame): the planar hip3, knee3, hip4, knee4 `(Fx, Fy)`, shape
    /// `(4, 2)`; the hexapod's hip and knee of each leg, shape
    /// `(legs, 2, 3)`; an imported robot's reactions (`reaction_names`),
    /// shape `(reactions, 3)`.
    #[getter]
    fn joint_forces<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        if let Sim::Robot(_) = &self.sim {
            let f: Vec<[f64; 3]> = self.readout.reactions.iter().map(|r| r.force).collect();
            return self.arr3(py, &f).into_any();
        }
        if let Sim::Planar(s) = &self.sim {
            let r = &s.data().record;
            let f = &r.reaction_force;
            let a = Array2::from_shape_fn((f.len(), 2), |(j, i)| f[j][i]);
            return PyArray2::from_owned_array(py, a).into_any();
        }
        let legs = &self.readout.legs;
        let a = Array3::from_shape_fn((legs.len(), 2, 3), |(l, h, i)| {
            if h == 0 {
                legs[l].hip_force[i]
            } else {
                legs[l].knee_force[i]
            }
        });
        PyArray3::from_owned_array(py, a).into_any()
    }

    /// Joint torques applied at the last solved step (N·m), one per joint
    /// (`joint_names`).
    #[getter]
    fn joint_torques<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.readout.joints.iter().map(|j| j.torque).collect())
    }

    /// Kinetic and potential energy at the last solved step (J), None
    /// before the first.
    #[getter]
    fn energy(&self) -> Option<(f64, f64)> {
        (self.sim.k() > 0).then_some((self.readout.kinetic, self.readout.potential))
    }

    /// Every readout as NumPy arrays, a dict (names and layouts in
    /// docs/reference.md, "fbd.Simulator observations").
    fn observe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        crate::observe::observe(py, &self.readout)
    }

    /// Events so far, as `fbd.run` lists them: contact, joint-limit and
    /// retried-step events, dicts (`t`, `step`, `leg`, `point`, `from`,
    /// `to`).
    #[getter]
    fn events<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let dt = self.dt_();
        match &self.sim {
            Sim::Planar(s) => {
                let d = s.data();
                crate::run::events(py, &d.events, &d.limit_events, &d.retries, dt)
            }
            Sim::Hexapod(s) => {
                let d = s.data();
                crate::run::events(py, &d.events, &d.limit_events, &d.retries, dt)
            }
            Sim::Robot(s) => {
                let Plant::Robot(_, robot) = &self.plant else {
                    return Ok(PyList::empty(py));
                };
                let d = s.data();
                let run = fbd_sim::RunSummary {
                    events: d.events.clone(),
                    limit_events: d.limit_events.clone(),
                    retries: d.retries.clone(),
                    ..Default::default()
                };
                crate::robot::events(py, robot, s.model(), &run)
            }
        }
    }

    fn __repr__(&self) -> String {
        format!(
            "Simulator({}, {}, k={}, t={})",
            self.model(),
            self.source,
            self.sim.k(),
            self.t()
        )
    }
}

/// Rebuilds a pickled [`Simulator`].
#[pyfunction]
#[pyo3(signature = (config, source, state, pd=None))]
pub fn _simulator_from_state(
    py: Python<'_>,
    config: String,
    source: String,
    state: &Bound<'_, SimulatorState>,
    pd: Option<&[u8]>,
) -> PyResult<Simulator> {
    let text = PyString::new(py, &config);
    let mut sim = Simulator::new(py, Some(text.as_any()))?;
    sim.source = source;
    sim.set_state(py, state)?;
    if let Some(b) = pd
        && let Some(LogEntry {
            action: Logged::Pd(p),
            ..
        }) = log_from_bytes(b).and_then(|l| l.into_iter().next())
    {
        sim.pd = Some(p);
    }
    Ok(sim)
}

/// A configuration read with the GIL (a dict or a string is Python's),
/// not yet built into a model.
enum Prepared {
    /// Loaded and validated.
    Ready(Ready),
    /// A dict as TOML text, parsed by [`assemble`]; `true` for a robot's.
    Dict(String, bool),
}

/// A loaded and validated configuration.
enum Ready {
    Robot(Box<fbd_output::config::robot::LoadedRobot>, String, bool),
    Loaded(Box<crate::config::Loaded>),
}

/// Why a prepared configuration could not be built, turned into the
/// Python exception with the GIL ([`Failure::into_err`]).
enum Failure {
    Config(fbd_output::ConfigError, bool),
    Usage(String),
}

impl Failure {
    fn into_err(self, py: Python<'_>) -> PyErr {
        match self {
            Failure::Config(e, from_text) => config_error(py, &e, from_text),
            Failure::Usage(m) => {
                crate::errors::cli_error(py, &fbd_output::OutputError::Usage(m), true)
            }
        }
    }
}

/// Loads `config` (None, a path, TOML text or a dict) for a simulator.
fn prepare(py: Python<'_>, config: Option<&Bound<'_, PyAny>>) -> PyResult<Prepared> {
    if let Some((text, robot)) = crate::config::dict_text(config)? {
        return Ok(Prepared::Dict(text, robot));
    }
    if let Some(robot) = crate::config::load_robot(py, config)? {
        let (source, from_text) = crate::config::robot_source(config);
        return Ok(Prepared::Ready(Ready::Robot(
            Box::new(robot),
            source,
            from_text,
        )));
    }
    Ok(Prepared::Ready(Ready::Loaded(Box::new(
        crate::config::load(py, config)?,
    ))))
}

/// Parses a prepared dict's text (as `load` and `load_robot` would).
fn parse(prepared: Prepared) -> Result<Ready, Failure> {
    let source = crate::config::DICT_SOURCE;
    Ok(match prepared {
        Prepared::Ready(ready) => ready,
        Prepared::Dict(text, true) => {
            let robot = fbd_output::config::robot::load_str(&text, std::path::Path::new(source))
                .map_err(|e| Failure::Config(e, false))?;
            Ready::Robot(Box::new(robot), source.to_owned(), false)
        }
        Prepared::Dict(text, false) => {
            let config = fbd_scenario::parse_str(&text, source, &[])
                .map_err(|e| Failure::Config(e, false))?;
            Ready::Loaded(Box::new(crate::config::Loaded {
                config,
                source: source.to_owned(),
                from_text: false,
            }))
        }
    })
}

/// Builds the model and simulator of a prepared configuration (no GIL
/// needed: [`simulators_many`] builds many on Rust threads).
fn assemble(prepared: Prepared) -> Result<Simulator, Failure> {
    let loaded = match parse(prepared)? {
        Ready::Robot(robot, source, from_text) => {
            let model = robot.sim().map_err(|e| {
                Failure::Config(
                    fbd_output::ConfigError::Semantic {
                        file: source.clone(),
                        message: e.to_string(),
                    },
                    from_text,
                )
            })?;
            let text = robot.config.to_toml();
            let plant = Plant::Robot(Box::new(model), robot);
            return Ok(Simulator::build(plant, source, text));
        }
        Ready::Loaded(loaded) => loaded,
    };
    let text = loaded.config.to_toml();
    let plant = match &loaded.config {
        fbd_scenario::Config::Planar(c) => Plant::Planar(Box::new(
            c.model(&loaded.source)
                .map_err(|e| Failure::Config(e, loaded.from_text))?,
        )),
        fbd_scenario::Config::Hexapod(h) => {
            if !h.is_dynamic() {
                return Err(Failure::Usage(format!(
                    "{}: model = \"hexapod\" with a kinematic gait (dynamics = \"kinematic\"): Simulator steps the 3D dynamics; fbd.run(config) runs the kinematic gait",
                    loaded.source
                )));
            }
            let params = h
                .spatial_params(&loaded.source)
                .map_err(|e| Failure::Config(e, loaded.from_text))?;
            let model = SpatialModel::new(&params)
                .map_err(|e| Failure::Usage(format!("{}: {e}", loaded.source)))?;
            Plant::Hexapod(Box::new(model))
        }
    };
    Ok(Simulator::build(plant, loaded.source, text))
}

/// `simulators_many(configs)`: a `Simulator` per configuration of the
/// list (each as `Simulator(config)` builds it, bit for bit), the
/// configurations read one after the other and the models built on Rust
/// threads (rayon; the GIL released). The first configuration that fails
/// raises its error, as `Simulator(config)` would. The vector
/// environments reset their sub-environments through it.
#[pyfunction]
pub fn simulators_many(py: Python<'_>, configs: &Bound<'_, PyList>) -> PyResult<Vec<Simulator>> {
    guard(|| {
        let prepared: Vec<Prepared> = configs
            .iter()
            .map(|c| prepare(py, Some(&c)))
            .collect::<PyResult<_>>()?;
        let built: Vec<Result<Simulator, Failure>> =
            py.detach(|| prepared.into_par_iter().map(assemble).collect());
        built
            .into_iter()
            .map(|r| r.map_err(|f| f.into_err(py)))
            .collect()
    })
}

/// The simulators of a Python list, borrowed.
fn borrow_all<'py>(sims: &Bound<'py, PyList>) -> PyResult<Vec<PyRef<'py, Simulator>>> {
    sims.iter()
        .map(|s| -> PyResult<PyRef<'py, Simulator>> {
            let b = s.cast_into::<Simulator>()?;
            Ok(b.try_borrow()?)
        })
        .collect()
}

/// `observe_many(sims, names=None)`: the readouts of `observe()` of every
/// simulator of the list, each field stacked into one array with a
/// leading axis of `len(sims)` (scalars such as `t` give shape
/// `(len(sims),)`), a dict of the fields `names` (default: every one).
/// The simulators must be of one model (each field of one shape). Row i
/// equals `sims[i].observe()[name]`, bit for bit.
#[pyfunction]
#[pyo3(signature = (sims, names=None))]
pub fn observe_many<'py>(
    py: Python<'py>,
    sims: &Bound<'py, PyList>,
    names: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyDict>> {
    let refs = borrow_all(sims)?;
    let readouts: Vec<&Readout> = refs.iter().map(|r| &r.readout).collect();
    crate::observe::observe_many(py, &readouts, names)
}

/// `set_pd_targets_many(sims, targets, kp, kd, torque_limit=None)`: row i
/// of `targets` (shape `(len(sims), joints)`, rad) as the PD targets of
/// simulator i, with the gains `kp`, `kd` (numbers or one per joint) and
/// `torque_limit` shared by all, exactly as `sims[i].set_pd_targets(
/// targets[i], kp, kd, torque_limit=torque_limit)` would (rates 0).
#[pyfunction]
#[pyo3(signature = (sims, targets, kp, kd, torque_limit=None))]
pub fn set_pd_targets_many<'py>(
    sims: &Bound<'py, PyList>,
    targets: PyReadonlyArray2<'py, f64>,
    kp: &Bound<'py, PyAny>,
    kd: &Bound<'py, PyAny>,
    torque_limit: Option<f64>,
) -> PyResult<()> {
    let t = targets.as_array();
    if t.nrows() != sims.len() {
        return Err(PyValueError::new_err(format!(
            "targets: expected {} rows, one per simulator, got {}",
            sims.len(),
            t.nrows()
        )));
    }
    for (i, s) in sims.iter().enumerate() {
        let b = s.cast_into::<Simulator>()?;
        let mut sim = b.try_borrow_mut()?;
        let row: Vec<f64> = t.row(i).to_vec();
        if row.len() != sim.sim.joints() {
            return Err(PyValueError::new_err(format!(
                "targets: expected {} columns, one per joint",
                sim.sim.joints()
            )));
        }
        sim.pd_targets_of(row, kp, kd, None, torque_limit)?;
    }
    Ok(())
}

/// Torques given to a step must be numbers: the message of a NaN or an
/// infinity, naming the joint's index (it would fail the step as "a
/// non-finite value in the residual").
fn nonfinite_torque(v: &[f64]) -> Option<String> {
    let j = v.iter().position(|x| !x.is_finite())?;
    Some(format!(
        "torques: must be finite (got {} at index {j})",
        v[j]
    ))
}

/// `step_many(sims, torques=None, steps=1)`: steps every simulator of the
/// list `steps` steps on Rust threads (rayon; the GIL released): with row
/// i of `torques` (shape `(len(sims), joints)`) for simulator i when given,
/// else with its PD targets or its configured controller, exactly as
/// `sims[i].step(torques[i], steps)` would. Returns one entry per
/// simulator: None, or the `SimulationError` that stopped it (not
/// raised).
#[pyfunction]
#[pyo3(signature = (sims, torques=None, steps=1))]
pub fn step_many<'py>(
    py: Python<'py>,
    sims: &Bound<'py, PyList>,
    torques: Option<PyReadonlyArray2<'py, f64>>,
    steps: usize,
) -> PyResult<Vec<Option<PyErr>>> {
    let mut refs: Vec<PyRefMut<'py, Simulator>> = sims
        .iter()
        .map(|s| -> PyResult<PyRefMut<'py, Simulator>> {
            let b = s.cast_into::<Simulator>()?;
            Ok(b.try_borrow_mut()?)
        })
        .collect::<PyResult<_>>()?;
    let n = refs.len();
    let mut actions = Vec::with_capacity(n);
    let tau = torques.as_ref().map(|t| t.as_array());
    if let Some(t) = &tau
        && t.nrows() != n
    {
        return Err(PyValueError::new_err(format!(
            "torques: expected {n} rows, one per simulator, got {}",
            t.nrows()
        )));
    }
    for (i, s) in refs.iter().enumerate() {
        s.check_failed(py)?;
        let row = match &tau {
            Some(t) => {
                let row: Vec<f64> = t.row(i).to_vec();
                if row.len() != s.sim.joints() {
                    return Err(PyValueError::new_err(format!(
                        "torques: expected {} columns, one per joint",
                        s.sim.joints()
                    )));
                }
                if let Some(e) = nonfinite_torque(&row) {
                    return Err(PyValueError::new_err(format!("row {i}: {e}")));
                }
                Some(row)
            }
            None => None,
        };
        actions.push(s.action_of(row));
    }
    let mut cores: Vec<&mut Sim> = refs.iter_mut().map(|r| &mut r.sim).collect();
    let outcome: Vec<(usize, Option<SimError>)> = py.detach(|| {
        cores
            .par_iter_mut()
            .zip(&actions)
            .map(|(sim, a)| Simulator::advance(sim, &action_ref(a), steps))
            .collect()
    });
    let mut errors = Vec::with_capacity(n);
    for ((s, a), (done, e)) in refs.iter_mut().zip(&actions).zip(outcome) {
        errors.push(s.finish(py, a, done, e).err());
    }
    Ok(errors)
}

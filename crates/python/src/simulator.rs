//! `Simulator(config)`: the planar model stepped from Python, one Δt at a
//! time, with the configured controller or the caller's joint torques.

use fbd_sim::{Data, Model, SimError, StepRecord};
use numpy::ndarray::Array2;
use numpy::{PyArray1, PyArray2, PyArrayMethods};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyList;

use crate::errors::{config_error, guard, simulation_error};

/// What a Newton failure after the caller's own torques most often means.
const EXTERNAL_TORQUE_HINT: &str = "; the torques given to step() are applied explicitly: \
     a feedback law with gains kp, kd is stable only while kp·Δt²/I + 2·kd·Δt/I < 4 \
     (I: the effective joint inertia, about 1e-2 kg·m² for the default legs), so lower \
     the gains or time.dt";

/// The planar model stepped one Δt at a time, for controllers written in
/// Python. `config` is a configuration as for `fbd.run` (None, a path, TOML
/// text or a dict).
///
/// `step(torques=None, steps=1)` solves steps with the given joint torques
/// (N·m: hip3, knee3, hip4, knee4, applied as given) or the configured
/// controller; `q`, `qdot` (the backward difference the built-in PD uses),
/// `t`, `k` are the current state; `contact_states`, `contact_forces`,
/// `joint_forces`, `joint_torques` those of the step solved last; `events`,
/// `reset()`. The GIL is released while stepping.
///
/// The configured duration only sets `steps` (what `fbd.run` solves):
/// `step()` goes on past it, `t` growing, until the caller stops; the
/// property `past_duration` says whether `k` has reached `steps - 1`.
#[pyclass(module = "fbd._fbd")]
pub struct Simulator {
    model: Model,
    data: Data,
    source: String,
    contacts: Vec<String>,
    /// The record of the step solved last (a copy: a failed step's retries
    /// overwrite `data.record`), `None` before the first or after `reset()`.
    last: Option<StepRecord>,
    /// The error that stopped the simulation (steps refuse until reset).
    failed: Option<SimError>,
}

impl Simulator {
    /// The record of the step solved last.
    fn last(&self) -> Option<&StepRecord> {
        self.last.as_ref()
    }

    fn torques_from(&self, torques: &Bound<'_, PyAny>) -> PyResult<Vec<f64>> {
        let n = self.data.fbd.torque.len();
        let mut tau = vec![0.0; n];
        let fill = |tau: &mut [f64], v: &[f64]| -> PyResult<()> {
            if v.len() != n {
                return Err(PyValueError::new_err(format!(
                    "torques: expected {n} joint torques (hip3, knee3, hip4, knee4), got {}",
                    v.len()
                )));
            }
            tau.copy_from_slice(v);
            Ok(())
        };
        if let Ok(a) = torques.cast::<PyArray1<f64>>() {
            let ro = a.readonly();
            if let Ok(s) = ro.as_slice() {
                fill(&mut tau, s)?;
                return Ok(tau);
            }
        }
        let v: Vec<f64> = torques.extract().map_err(|_| {
            PyValueError::new_err(
                "torques: expected a sequence of 4 numbers (hip3, knee3, hip4, knee4) or None",
            )
        })?;
        fill(&mut tau, &v)?;
        Ok(tau)
    }
}

#[pymethods]
impl Simulator {
    #[new]
    #[pyo3(signature = (config=None))]
    fn new(py: Python<'_>, config: Option<&Bound<'_, PyAny>>) -> PyResult<Self> {
        guard(|| {
            let loaded = crate::config::load(py, config)?;
            let model = match &loaded.config {
                fbd_scenario::Config::Planar(c) => c
                    .model(&loaded.source)
                    .map_err(|e| config_error(py, &e, loaded.from_text))?,
                fbd_scenario::Config::Hexapod(_) => {
                    return Err(crate::errors::cli_error(
                        py,
                        &fbd_cli::CliError::Usage(format!(
                            "{}: model = \"hexapod\": Simulator steps the planar model only; fbd.run(config) runs the hexapod (its 3D dynamics or its kinematic gait)",
                            loaded.source
                        )),
                        true,
                    ));
                }
            };
            let data = Data::new(&model);
            let contacts = model.mech.contacts.iter().map(|c| c.name.clone()).collect();
            Ok(Self {
                model,
                data,
                source: loaded.source,
                contacts,
                last: None,
                failed: None,
            })
        })
    }

    /// Advances `steps` steps (one by default) with the GIL released.
    #[pyo3(signature = (torques=None, steps=1))]
    fn step(
        &mut self,
        py: Python<'_>,
        torques: Option<&Bound<'_, PyAny>>,
        steps: usize,
    ) -> PyResult<()> {
        let external = match torques {
            Some(t) if !t.is_none() => Some(self.torques_from(t)?),
            _ => None,
        };
        if let Some(e) = &self.failed {
            return Err(simulation_error(
                py,
                &format!("{e} ({}; call reset() to start again)", self.source),
                e.step(),
                e.step().map(|k| k as f64 * self.model.dt()),
                None,
            ));
        }
        let torques_given = external.is_some();
        self.data.external_torque = external;
        let (model, data) = (&self.model, &mut self.data);
        let last = &mut self.last;
        let result = py.detach(|| {
            std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                for i in 1..=steps {
                    let r = fbd_sim::step(model, data)?;
                    match last {
                        Some(l) => l.clone_from(r),
                        None => *last = Some(r.clone()),
                    }
                    // Ctrl-C between steps of a long call.
                    if i.is_multiple_of(crate::run::SIGNAL_CHECK)
                        && i < steps
                        && let Err(e) = Python::attach(|py| py.check_signals())
                    {
                        return Ok(Some(e));
                    }
                }
                Ok::<_, SimError>(None)
            }))
        });
        self.data.external_torque = None;
        match result {
            Ok(Ok(None)) => Ok(()),
            Ok(Ok(Some(interrupt))) => Err(interrupt),
            Ok(Err(e)) => {
                let hint = if torques_given && matches!(e, SimError::Newton { .. }) {
                    EXTERNAL_TORQUE_HINT
                } else {
                    ""
                };
                let msg = format!("{e} ({}){hint}", self.source);
                let (k, t) = (e.step(), e.step().map(|k| k as f64 * self.model.dt()));
                self.failed = Some(e);
                Err(simulation_error(py, &msg, k, t, None))
            }
            Err(_) => {
                let e = SimError::NonFinite {
                    step: self.data.k,
                    t: self.data.time(&self.model),
                    residual: f64::NAN,
                };
                self.failed = Some(e);
                Err(pyo3::exceptions::PyRuntimeError::new_err(
                    "fbd internal error during a step (call reset() to start again)",
                ))
            }
        }
    }

    /// Back to the initial state of the configuration.
    fn reset(&mut self) {
        self.data = Data::new(&self.model);
        self.last = None;
        self.failed = None;
    }

    /// Time of the current state `q` (s): `k·Δt`.
    #[getter]
    fn t(&self) -> f64 {
        self.data.time(&self.model)
    }

    /// Steps solved so far (`k`; the current state is `q[k]`).
    #[getter]
    fn k(&self) -> usize {
        self.data.k
    }

    /// Time step Δt (s).
    #[getter]
    fn dt(&self) -> f64 {
        self.model.dt()
    }

    /// Steps of the configured duration: `round(duration/dt) + 1`.
    #[getter]
    fn steps(&self) -> usize {
        self.model.steps
    }

    /// Whether the current state is at or past the configured duration
    /// (`k ≥ steps − 1`): stepping goes on, the duration only bounds
    /// `fbd.run`.
    #[getter]
    fn past_duration(&self) -> bool {
        self.data.k + 1 >= self.model.steps
    }

    /// `q[k] = (Rx, Ry, φz, θ2₃, θ3₃, θ2₄, θ3₄)` (m, rad), a new array.
    #[getter]
    fn q<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.data.q)
    }

    /// The backward difference `(q[k] − q[k−1])/Δt`, the initial velocity
    /// at `k = 0`: the rate the built-in PD controller uses.
    #[getter]
    fn qdot<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        let dt = self.model.dt();
        let mut v = [0.0; 7];
        for (i, v) in v.iter_mut().enumerate() {
            *v = if self.data.k == 0 {
                self.model.params.qdot0[i]
            } else {
                (self.data.q[i] - self.data.q_prev[i]) / dt
            };
        }
        PyArray1::from_slice(py, &v[..self.data.q.len().min(7)])
    }

    /// The initial configuration `q[0]` (m, rad).
    #[getter]
    fn q0<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_slice(py, &self.model.params.q0)
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
            .data
            .states
            .iter()
            .map(|s| match s.code() {
                fbd_contact::StateCode::St1 => 1,
                fbd_contact::StateCode::St2 => 2,
                fbd_contact::StateCode::St3 => 3,
            })
            .collect();
        PyArray1::from_vec(py, codes)
    }

    /// Contact forces `(Fa, N)` of each point at the last solved step (N),
    /// shape `(points, 2)`: along the terrain tangent and normal; zeros
    /// before the first step.
    #[getter]
    fn contact_forces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let n = self.contacts.len();
        let a = Array2::from_shape_fn((n, 2), |(c, j)| {
            self.last()
                .map_or(0.0, |r| if j == 0 { r.fa[c] } else { r.n[c] })
        });
        PyArray2::from_owned_array(py, a)
    }

    /// Inertial positions of the contact points at the last solved step
    /// (m), shape `(points, 2)`; at `q[0]` before the first step.
    #[getter]
    fn contact_positions<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let n = self.contacts.len();
        let a = Array2::from_shape_fn((n, 2), |(c, j)| match self.last() {
            Some(r) => r.point[c][j],
            None => self.data.fbd.kin.pos[self.model.mech.contacts[c].point][j],
        });
        PyArray2::from_owned_array(py, a)
    }

    /// Joint forces `(Fx, Fy)` of hip3, knee3, hip4, knee4 at the last
    /// solved step (N, parent on child, inertial frame), shape `(4, 2)`.
    #[getter]
    fn joint_forces<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray2<f64>> {
        let joints = self.data.fbd.torque.len();
        let a = Array2::from_shape_fn((joints, 2), |(j, i)| {
            self.last().map_or(0.0, |r| r.joint_force[j][i])
        });
        PyArray2::from_owned_array(py, a)
    }

    /// Joint torques applied at the last solved step (N·m): hip3, knee3,
    /// hip4, knee4.
    #[getter]
    fn joint_torques<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        match self.last() {
            Some(r) => PyArray1::from_slice(py, &r.torque),
            None => PyArray1::from_vec(py, vec![0.0; self.data.fbd.torque.len()]),
        }
    }

    /// Kinetic and potential energy at the last solved step (J).
    #[getter]
    fn energy(&self) -> Option<(f64, f64)> {
        self.last().map(|r| (r.kinetic, r.potential))
    }

    /// Events so far, as `fbd.run` lists them: contact, joint-limit and
    /// retried-step events, dicts (`t`, `step`, `leg`, `point`, `from`,
    /// `to`).
    #[getter]
    fn events<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyList>> {
        let d = &self.data;
        crate::run::events(py, &d.events, &d.limit_events, &d.retries, self.model.dt())
    }

    fn __repr__(&self) -> String {
        format!(
            "Simulator({}, k={}, t={})",
            self.source,
            self.data.k,
            self.data.time(&self.model)
        )
    }
}

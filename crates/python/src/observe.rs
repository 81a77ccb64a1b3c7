//! The readouts of `Simulator.observe()` as named fields, one source for
//! the dict of one simulator and for `observe_many`, which stacks the
//! fields of many simulators into arrays with a leading axis (the vector
//! environments read a whole batch in one call).

use fbd_sim::simulator::Readout;
use numpy::PyArrayDyn;
use numpy::ndarray::{ArrayD, IxDyn};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// Every field of `observe()`, in the dict's order (layouts in
/// docs/reference.md, "fbd.Simulator observations").
pub(crate) const NAMES: [&str; 26] = [
    "t",
    "k",
    "q",
    "qdot",
    "body_position",
    "body_rotation",
    "body_velocity",
    "body_angular_velocity",
    "joint_angle",
    "joint_rate",
    "joint_torque",
    "leg",
    "hip_force",
    "hip_moment",
    "knee_force",
    "knee_moment",
    "contact_position",
    "contact_state",
    "contact_force",
    "contact_normal_force",
    "contact_normal",
    "contact_slip_velocity",
    "reaction_force",
    "reaction_moment",
    "kinetic",
    "potential",
];

/// One field's values: its shape (empty for a scalar) and its entries in
/// row-major order, of NumPy's dtype `float64`, `int64` or `uint8`.
pub(crate) enum Values {
    F64(Vec<f64>),
    I64(Vec<i64>),
    U8(Vec<u8>),
}

/// A field of a readout.
pub(crate) struct Field {
    pub shape: Vec<usize>,
    pub values: Values,
}

fn scalar(v: f64) -> Field {
    Field {
        shape: Vec::new(),
        values: Values::F64(vec![v]),
    }
}

fn vector(v: Vec<f64>) -> Field {
    Field {
        shape: vec![v.len()],
        values: Values::F64(v),
    }
}

/// Rows of three, shape `(n, 3)`.
fn rows3<T>(items: &[T], f: impl Fn(&T) -> [f64; 3]) -> Field {
    Field {
        shape: vec![items.len(), 3],
        values: Values::F64(items.iter().flat_map(&f).collect()),
    }
}

/// The contact-state code of the Python API: 1 no contact, 2 sticking,
/// 3 sliding.
pub(crate) fn state_code(c: fbd_contact::StateCode) -> u8 {
    match c {
        fbd_contact::StateCode::St1 => 1,
        fbd_contact::StateCode::St2 => 2,
        fbd_contact::StateCode::St3 => 3,
    }
}

/// Field `name` of `r`, None for a name not in [`NAMES`].
pub(crate) fn field(r: &Readout, name: &str) -> Option<Field> {
    let b = &r.bodies;
    let j = &r.joints;
    let l = &r.legs;
    let c = &r.contacts;
    let x = &r.reactions;
    Some(match name {
        "t" => scalar(r.t),
        "k" => Field {
            shape: Vec::new(),
            values: Values::I64(vec![r.k as i64]),
        },
        "q" => vector(r.q.clone()),
        "qdot" => vector(r.qdot.clone()),
        "body_position" => rows3(b, |b| b.position),
        "body_rotation" => Field {
            shape: vec![b.len(), 3, 3],
            values: Values::F64(b.iter().flat_map(|b| b.rotation.concat()).collect()),
        },
        "body_velocity" => rows3(b, |b| b.velocity),
        "body_angular_velocity" => rows3(b, |b| b.angular_velocity),
        "joint_angle" => vector(j.iter().map(|j| j.angle).collect()),
        "joint_rate" => vector(j.iter().map(|j| j.rate).collect()),
        "joint_torque" => vector(j.iter().map(|j| j.torque).collect()),
        "leg" => Field {
            shape: vec![l.len()],
            values: Values::I64(l.iter().map(|l| l.leg as i64).collect()),
        },
        "hip_force" => rows3(l, |l| l.hip_force),
        "hip_moment" => rows3(l, |l| l.hip_moment),
        "knee_force" => rows3(l, |l| l.knee_force),
        "knee_moment" => rows3(l, |l| l.knee_moment),
        "contact_position" => rows3(c, |c| c.position),
        "contact_state" => Field {
            shape: vec![c.len()],
            values: Values::U8(c.iter().map(|c| state_code(c.state)).collect()),
        },
        "contact_force" => rows3(c, |c| c.force),
        "contact_normal_force" => vector(c.iter().map(|c| c.normal_force).collect()),
        "contact_normal" => rows3(c, |c| c.normal),
        "contact_slip_velocity" => rows3(c, |c| c.slip_velocity),
        "reaction_force" => rows3(x, |x| x.force),
        "reaction_moment" => rows3(x, |x| x.moment),
        "kinetic" => scalar(r.kinetic),
        "potential" => scalar(r.potential),
        _ => return None,
    })
}

fn array<'py, T: numpy::Element>(
    py: Python<'py>,
    shape: &[usize],
    v: Vec<T>,
) -> PyResult<Bound<'py, PyAny>> {
    let a = ArrayD::from_shape_vec(IxDyn(shape), v)
        .map_err(|e| PyValueError::new_err(format!("observation shape: {e}")))?;
    Ok(PyArrayDyn::from_owned_array(py, a).into_any())
}

/// `f` as Python sees it in `observe()`: a float or int for a scalar, an
/// array otherwise.
fn to_py<'py>(py: Python<'py>, f: Field) -> PyResult<Bound<'py, PyAny>> {
    if f.shape.is_empty() {
        return Ok(match f.values {
            Values::F64(v) => v[0].into_pyobject(py)?.into_any(),
            Values::I64(v) => v[0].into_pyobject(py)?.into_any(),
            Values::U8(v) => v[0].into_pyobject(py)?.into_any(),
        });
    }
    match f.values {
        Values::F64(v) => array(py, &f.shape, v),
        Values::I64(v) => array(py, &f.shape, v),
        Values::U8(v) => array(py, &f.shape, v),
    }
}

/// The dict of `Simulator.observe()`.
pub(crate) fn observe<'py>(py: Python<'py>, r: &Readout) -> PyResult<Bound<'py, PyDict>> {
    let d = PyDict::new(py);
    for name in NAMES {
        if let Some(f) = field(r, name) {
            d.set_item(name, to_py(py, f)?)?;
        }
    }
    Ok(d)
}

/// The fields `names` (default: every one) of `readouts`, each stacked
/// into one array with a leading axis of `readouts.len()`: scalars give
/// shape `(n,)`, arrays `(n, ...)`. The readouts must agree on each
/// field's shape (simulators of one model).
pub(crate) fn observe_many<'py>(
    py: Python<'py>,
    readouts: &[&Readout],
    names: Option<Vec<String>>,
) -> PyResult<Bound<'py, PyDict>> {
    let names: Vec<String> = names.unwrap_or_else(|| NAMES.iter().map(|s| s.to_string()).collect());
    let d = PyDict::new(py);
    for name in &names {
        let mut shape: Option<Vec<usize>> = None;
        let mut stacked: Option<Values> = None;
        for (i, r) in readouts.iter().enumerate() {
            let f = field(r, name).ok_or_else(|| {
                PyValueError::new_err(format!(
                    "observe_many: no field {name:?}; the fields are {}",
                    NAMES.join(", ")
                ))
            })?;
            match &shape {
                None => shape = Some(f.shape.clone()),
                Some(s) if *s != f.shape => {
                    return Err(PyValueError::new_err(format!(
                        "observe_many: field {name:?} has shape {s:?} in simulator 0 and {:?} in simulator {i} (simulators of one model only)",
                        f.shape
                    )));
                }
                Some(_) => {}
            }
            stacked = Some(match (stacked, f.values) {
                (None, v) => v,
                (Some(Values::F64(mut a)), Values::F64(b)) => {
                    a.extend(b);
                    Values::F64(a)
                }
                (Some(Values::I64(mut a)), Values::I64(b)) => {
                    a.extend(b);
                    Values::I64(a)
                }
                (Some(Values::U8(mut a)), Values::U8(b)) => {
                    a.extend(b);
                    Values::U8(a)
                }
                _ => {
                    return Err(PyValueError::new_err(format!(
                        "observe_many: field {name:?} changed its type between simulators"
                    )));
                }
            });
        }
        let mut full = vec![readouts.len()];
        full.extend(shape.unwrap_or_default());
        let value = match stacked {
            Some(Values::F64(v)) => array(py, &full, v)?,
            Some(Values::I64(v)) => array(py, &full, v)?,
            Some(Values::U8(v)) => array(py, &full, v)?,
            None => array::<f64>(py, &full, Vec::new())?,
        };
        d.set_item(name, value)?;
    }
    Ok(d)
}

//! Kinematics: the JSON of `fbd kinematics`, planar and hexapod forward
//! kinematics and leg inverse kinematics on NumPy arrays.

use fbd_kinematics::hexapod::{self, HexapodData, HexapodModel, forward};
use fbd_kinematics::ik::{self, KneeBranch};
use fbd_kinematics::leg::LegGeometry;
use fbd_kinematics::nalgebra::Vector3;
use fbd_kinematics::planar::PlanarGeometry;
use fbd_scenario::{Config, ConfigFile};
use numpy::ndarray::{Array2, Array3};
use numpy::{PyArray2, PyArray3, PyReadonlyArray2};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use crate::errors::guard;

/// Body side, link lengths and centres of mass of a configuration.
struct Geometry {
    side: f64,
    a: f64,
    c: f64,
    upper_com: f64,
    lower_com: f64,
}

fn geometry_of<I>(f: &ConfigFile<I>) -> Geometry {
    Geometry {
        side: f.body.side,
        a: f.leg.upper_length,
        c: f.leg.lower_length,
        upper_com: f.leg.upper_com,
        lower_com: f.leg.lower_com,
    }
}

fn geometry(py: Python<'_>, config: Option<&Bound<'_, PyAny>>) -> PyResult<Geometry> {
    Ok(match crate::config::load(py, config)?.config {
        Config::Planar(c) => geometry_of(&c),
        Config::Hexapod(h) => geometry_of(&h),
    })
}

fn hexapod_model(g: &Geometry) -> HexapodModel {
    HexapodModel::new(
        g.side,
        LegGeometry { a: g.a, c: g.c },
        g.upper_com,
        g.lower_com,
    )
}

fn check_width(name: &str, q: &PyReadonlyArray2<'_, f64>, width: usize) -> PyResult<()> {
    let got = q.as_array().ncols();
    if got != width {
        return Err(PyValueError::new_err(format!(
            "{name}: expected {width} columns, got {got}"
        )));
    }
    Ok(())
}

/// `kinematics_json(config) -> str`: the JSON `fbd kinematics` prints.
#[pyfunction]
#[pyo3(signature = (config=None))]
pub fn kinematics_json(py: Python<'_>, config: Option<&Bound<'_, PyAny>>) -> PyResult<String> {
    guard(|| {
        if let Some(robot) = crate::config::load_robot(py, config)? {
            return serde_json::to_string(&robot.kinematics())
                .map_err(|e| PyValueError::new_err(e.to_string()));
        }
        let loaded = crate::config::load(py, config)?;
        Ok(fbd_output::kinematics::initial_kinematics(&loaded.config).to_json())
    })
}

/// The robot of `config`, or the error saying that only an imported
/// robot has inverse dynamics.
fn robot_of(
    py: Python<'_>,
    config: Option<&Bound<'_, PyAny>>,
) -> PyResult<fbd_scenario::robot::LoadedRobot> {
    crate::config::load_robot(py, config)?.ok_or_else(|| {
        PyValueError::new_err(
            "inverse: takes a model = \"robot\" configuration (an imported URDF or MJCF robot)",
        )
    })
}

/// `inverse_json(config) -> str`: `fbd inverse CONFIG` (the state's
/// inverse dynamics by the FBD method) as JSON.
#[pyfunction]
pub fn inverse_json(py: Python<'_>, config: &Bound<'_, PyAny>) -> PyResult<String> {
    guard(|| {
        serde_json::to_string(&robot_of(py, Some(config))?.inverse())
            .map_err(|e| PyValueError::new_err(e.to_string()))
    })
}

/// `inverse_motion(config, columns, values) -> (names, table)`: `fbd
/// inverse CONFIG --motion` of the motion with these column names and
/// values (shape `(N, len(columns))`).
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn inverse_motion<'py>(
    py: Python<'py>,
    config: &Bound<'py, PyAny>,
    columns: Vec<String>,
    values: PyReadonlyArray2<'py, f64>,
) -> PyResult<(Vec<String>, Bound<'py, PyArray2<f64>>)> {
    guard(|| {
        let robot = robot_of(py, Some(config))?;
        check_width("motion", &values, columns.len())?;
        // The same reader as the CLI's (one set of rules): the values as
        // CSV, each written exactly (shortest round-trip decimals).
        let v = values.as_array();
        let mut text = columns.join(",");
        text.push('\n');
        for row in v.rows() {
            let cells: Vec<String> = row.iter().map(|x| format!("{x}")).collect();
            text.push_str(&cells.join(","));
            text.push('\n');
        }
        let motion = robot
            .read_motion(&text, "<motion>")
            .map_err(|e| crate::errors::config_error(py, &e, false))?;
        let rows = robot.inverse_along(&motion);
        let names = robot.inverse_columns();
        let mut out = Array2::<f64>::zeros((rows.len(), names.len()));
        for (i, r) in rows.iter().enumerate() {
            for (j, x) in r.iter().enumerate() {
                out[(i, j)] = *x;
            }
        }
        Ok((names, PyArray2::from_owned_array(py, out)))
    })
}

/// `planar_fk(q, config=None) -> (hip, knee, tip)`: for `q` of shape
/// `(N, 7)`, three arrays of shape `(N, 2, 2)`: legs 3 and 4, `(x, y)`.
#[pyfunction]
#[pyo3(signature = (q, config=None))]
#[allow(clippy::type_complexity)]
pub fn planar_fk<'py>(
    py: Python<'py>,
    q: PyReadonlyArray2<'py, f64>,
    config: Option<&Bound<'py, PyAny>>,
) -> PyResult<(
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray3<f64>>,
)> {
    guard(|| {
        check_width("q", &q, fbd_kinematics::planar::NQ)?;
        let g = geometry(py, config)?;
        let pg = PlanarGeometry {
            d: g.side * (std::f64::consts::PI / 6.0).cos(),
            a: g.a,
            c: g.c,
            upper_com: g.upper_com,
            lower_com: g.lower_com,
        };
        let (chains, ix) = fbd_kinematics::planar::PlanarChains::two_leg(&pg);
        let mut data = chains.new_data();
        let q = q.as_array();
        let n = q.nrows();
        let mut out = [
            Array3::<f64>::zeros((n, 2, 2)),
            Array3::<f64>::zeros((n, 2, 2)),
            Array3::<f64>::zeros((n, 2, 2)),
        ];
        let mut row = [0.0; 7];
        for (r, qr) in q.rows().into_iter().enumerate() {
            for (dst, src) in row.iter_mut().zip(qr.iter()) {
                *dst = *src;
            }
            chains.eval_positions(&row, &mut data);
            for leg in 0..2 {
                for (k, idx) in [ix.hip[leg], ix.knee[leg], ix.tip[leg]]
                    .into_iter()
                    .enumerate()
                {
                    out[k][[r, leg, 0]] = data.pos[idx][0];
                    out[k][[r, leg, 1]] = data.pos[idx][1];
                }
            }
        }
        let [h, k, t] = out;
        Ok((
            PyArray3::from_owned_array(py, h),
            PyArray3::from_owned_array(py, k),
            PyArray3::from_owned_array(py, t),
        ))
    })
}

/// `hexapod_fk(q, config=None) -> (hip, knee, tip)`: for the 24-DOF
/// coordinates `q` of shape `(N, 24)` — `(Rx, Ry, Rz, φx, φy, φz)` then
/// `(θ1, θ2, θ3)` of legs 1–6, m and rad — three arrays `(N, 6, 3)`.
#[pyfunction]
#[pyo3(signature = (q, config=None))]
#[allow(clippy::type_complexity)]
pub fn hexapod_fk<'py>(
    py: Python<'py>,
    q: PyReadonlyArray2<'py, f64>,
    config: Option<&Bound<'py, PyAny>>,
) -> PyResult<(
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray3<f64>>,
    Bound<'py, PyArray3<f64>>,
)> {
    guard(|| {
        check_width("q", &q, hexapod::NQ)?;
        let model = hexapod_model(&geometry(py, config)?);
        let mut data = HexapodData::new();
        let q = q.as_array();
        let n = q.nrows();
        let mut out = [
            Array3::<f64>::zeros((n, 6, 3)),
            Array3::<f64>::zeros((n, 6, 3)),
            Array3::<f64>::zeros((n, 6, 3)),
        ];
        let mut row = [0.0; hexapod::NQ];
        for (r, qr) in q.rows().into_iter().enumerate() {
            for (dst, src) in row.iter_mut().zip(qr.iter()) {
                *dst = *src;
            }
            forward(&model, &hexapod::HexapodConfig::from_q(&row), &mut data);
            for (leg, l) in data.legs.iter().enumerate() {
                for (k, p) in [l.hip, l.knee, l.tip].into_iter().enumerate() {
                    for i in 0..3 {
                        out[k][[r, leg, i]] = p[i];
                    }
                }
            }
        }
        let [h, k, t] = out;
        Ok((
            PyArray3::from_owned_array(py, h),
            PyArray3::from_owned_array(py, k),
            PyArray3::from_owned_array(py, t),
        ))
    })
}

/// `leg_ik(targets, config=None, leg=None, knee="up") -> angles`: the
/// joint angles `(θ1, θ2, θ3)` (rad, shape `(N, 3)`) placing the tip at
/// each row of `targets` `(N, 3)`: in the leg base frame (eq. 1) when `leg`
/// is None, else in body coordinates for hexapod leg `leg` (1–6). `knee`:
/// `"up"` (θ3 in [π, 2π]) or `"down"` (θ3 in [0, π]). An unreachable
/// target raises `ValueError` naming its row.
#[pyfunction]
#[pyo3(signature = (targets, config=None, leg=None, knee="up"))]
pub fn leg_ik<'py>(
    py: Python<'py>,
    targets: PyReadonlyArray2<'py, f64>,
    config: Option<&Bound<'py, PyAny>>,
    leg: Option<usize>,
    knee: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    guard(|| {
        check_width("targets", &targets, 3)?;
        let branch = match knee {
            "up" => KneeBranch::Up,
            "down" => KneeBranch::Down,
            other => {
                return Err(PyValueError::new_err(format!(
                    "knee: expected \"up\" or \"down\", got {other:?}"
                )));
            }
        };
        if let Some(l) = leg
            && !(1..=6).contains(&l)
        {
            return Err(PyValueError::new_err(format!(
                "leg: expected a hexapod leg number 1–6, got {l}"
            )));
        }
        let model = hexapod_model(&geometry(py, config)?);
        let t = targets.as_array();
        let mut out = Array2::<f64>::zeros((t.nrows(), 3));
        for (r, row) in t.rows().into_iter().enumerate() {
            let p = Vector3::new(row[0], row[1], row[2]);
            let angles = match leg {
                Some(l) => ik::leg_ik_body(&model, l - 1, &p, branch),
                None => ik::leg_ik(model.leg(), &p, branch),
            }
            .map_err(|e| PyValueError::new_err(format!("targets[{r}]: {e}")))?;
            for i in 0..3 {
                out[[r, i]] = angles[i];
            }
        }
        Ok(PyArray2::from_owned_array(py, out))
    })
}

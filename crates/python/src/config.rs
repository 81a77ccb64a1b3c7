//! A configuration from Python: `None` (the built-in default experiment), a
//! path (`str` or `os.PathLike`), a TOML string, or a dict with the keys of
//! the files. Every form goes through [`fbd_scenario::parse_str`]: one
//! validation for the CLI, Rust and Python.

use std::path::PathBuf;

use fbd_scenario::Config;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyBool, PyDict, PyFloat, PyInt, PyString};

/// A loaded configuration and the name errors and files give it.
pub struct Loaded {
    /// The validated configuration.
    pub config: Config,
    /// The file name, `<string>`, `<dict>` or `the built-in default`.
    pub source: String,
    /// `true` when line and column numbers refer to text the user wrote
    /// (not for a dict).
    pub from_text: bool,
}

/// Name of a configuration given as a TOML string.
pub const STRING_SOURCE: &str = "<string>";
/// Name of a configuration given as a dict.
pub const DICT_SOURCE: &str = "<dict>";

/// `true` when a `str` argument is TOML text rather than a path: it has a
/// line break, an `=` or a table header, or is empty (the default).
fn is_toml_text(s: &str) -> bool {
    s.trim().is_empty() || s.contains('\n') || s.contains('=') || s.trim_start().starts_with('[')
}

/// A Python value as a TOML value; `key` names it in errors.
fn to_toml(v: &Bound<'_, PyAny>, key: &str) -> PyResult<toml::Value> {
    if v.is_instance_of::<PyBool>() {
        return Ok(toml::Value::Boolean(v.extract()?));
    }
    if v.is_instance_of::<PyInt>() {
        return Ok(toml::Value::Integer(v.extract()?));
    }
    if v.is_instance_of::<PyFloat>() {
        return Ok(toml::Value::Float(v.extract()?));
    }
    if v.is_instance_of::<PyString>() {
        return Ok(toml::Value::String(v.extract()?));
    }
    if let Ok(d) = v.cast::<PyDict>() {
        return Ok(toml::Value::Table(to_table(d, key)?));
    }
    // NumPy scalars: integers have __index__, floats __float__.
    if v.hasattr("__index__")? && !v.hasattr("__len__")? {
        return Ok(toml::Value::Integer(
            v.call_method0("__index__")?.extract()?,
        ));
    }
    if v.hasattr("__float__")? && !v.hasattr("__len__")? {
        return Ok(toml::Value::Float(v.call_method0("__float__")?.extract()?));
    }
    if let Ok(items) = v.try_iter() {
        let mut out = Vec::new();
        for (i, item) in items.enumerate() {
            out.push(to_toml(&item?, &format!("{key}[{i}]"))?);
        }
        return Ok(toml::Value::Array(out));
    }
    Err(PyTypeError::new_err(format!(
        "{key}: a {} cannot be a configuration value (expected a number, string, bool, list or dict)",
        v.get_type().name()?
    )))
}

fn to_table(d: &Bound<'_, PyDict>, prefix: &str) -> PyResult<toml::Table> {
    let mut t = toml::Table::new();
    for (k, v) in d.iter() {
        let name: String = k.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "{}: configuration keys must be strings",
                if prefix.is_empty() { "<dict>" } else { prefix }
            ))
        })?;
        let key = if prefix.is_empty() {
            name.clone()
        } else {
            format!("{prefix}.{name}")
        };
        if v.is_none() {
            continue;
        }
        t.insert(name, to_toml(&v, &key)?);
    }
    Ok(t)
}

/// A dict configuration as TOML text (its conversion needs the GIL, its
/// parsing not), with whether it is an imported robot's (`model =
/// "robot"`); None when `config` is no dict.
pub fn dict_text(config: Option<&Bound<'_, PyAny>>) -> PyResult<Option<(String, bool)>> {
    let Some(d) = config.and_then(|c| c.cast::<PyDict>().ok()) else {
        return Ok(None);
    };
    let table = to_table(d, "")?;
    let robot = table.get("model").and_then(|m| m.as_str()) == Some(fbd_scenario::robot::MODEL);
    Ok(Some((table_text(&table)?, robot)))
}

/// A dict's table as TOML text.
fn table_text(table: &toml::Table) -> PyResult<String> {
    toml::to_string(table)
        .map_err(|e| PyTypeError::new_err(format!("<dict>: cannot be written as TOML: {e}")))
}

/// Loads `config` (None, path, TOML text or dict) and validates it.
pub fn load(py: Python<'_>, config: Option<&Bound<'_, PyAny>>) -> PyResult<Loaded> {
    let Some(obj) = config.filter(|c| !c.is_none()) else {
        return Ok(Loaded {
            config: Config::default(),
            source: "the built-in default".into(),
            from_text: true,
        });
    };
    let err =
        |e: fbd_scenario::ConfigError, from_text| crate::errors::config_error(py, &e, from_text);
    if let Ok(d) = obj.cast::<PyDict>() {
        let text = table_text(&to_table(d, "")?)?;
        let config = fbd_scenario::parse_str(&text, DICT_SOURCE, &[]).map_err(|e| err(e, false))?;
        return Ok(Loaded {
            config,
            source: DICT_SOURCE.into(),
            from_text: false,
        });
    }
    if let Ok(s) = obj.cast::<PyString>() {
        let s: String = s.extract()?;
        if is_toml_text(&s) {
            let config =
                fbd_scenario::parse_str(&s, STRING_SOURCE, &[]).map_err(|e| err(e, true))?;
            return Ok(Loaded {
                config,
                source: STRING_SOURCE.into(),
                from_text: true,
            });
        }
    }
    let path: PathBuf = obj.extract().map_err(|_| {
        PyTypeError::new_err(format!(
            "config: expected a path, a TOML string or a dict, got a {}",
            obj.get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default()
        ))
    })?;
    let config = fbd_scenario::load(&path).map_err(|e| err(e, true))?;
    Ok(Loaded {
        config,
        source: path.display().to_string(),
        from_text: true,
    })
}

/// The robot of a `model = "robot"` configuration (a path, TOML text or a
/// dict; a description path in text or a dict is relative to the working
/// directory), `None` for the paper's models.
pub fn load_robot(
    py: Python<'_>,
    config: Option<&Bound<'_, PyAny>>,
) -> PyResult<Option<fbd_scenario::robot::LoadedRobot>> {
    use fbd_scenario::robot::{is_robot, load_str};
    let Some(obj) = config.filter(|c| !c.is_none()) else {
        return Ok(None);
    };
    let err =
        |e: fbd_scenario::ConfigError, from_text| crate::errors::config_error(py, &e, from_text);
    if let Ok(d) = obj.cast::<PyDict>() {
        // Only `model` decides (the whole dict is converted once, by
        // whichever loader takes it).
        let model: Option<String> = d.get_item("model")?.and_then(|m| m.extract().ok());
        if model.as_deref() != Some(fbd_scenario::robot::MODEL) {
            return Ok(None);
        }
        let text = table_text(&to_table(d, "")?)?;
        return load_str(&text, std::path::Path::new(DICT_SOURCE))
            .map(Some)
            .map_err(|e| err(e, false));
    }
    if let Ok(s) = obj.cast::<PyString>() {
        let s: String = s.extract()?;
        if is_toml_text(&s) {
            if !is_robot(&s) {
                return Ok(None);
            }
            return load_str(&s, std::path::Path::new(STRING_SOURCE))
                .map(Some)
                .map_err(|e| err(e, true));
        }
    }
    let Ok(path) = obj.extract::<PathBuf>() else {
        return Ok(None); // `load` gives the error
    };
    let Ok(text) = fbd_scenario::read_text(&path) else {
        return Ok(None); // `load` gives the error
    };
    if !is_robot(&text) {
        return Ok(None);
    }
    load_str(&text, &path).map(Some).map_err(|e| err(e, true))
}

/// The name a robot configuration goes by in errors and results (as
/// [`load`] names it: the path, `<string>` or `<dict>`) and whether its
/// errors' lines refer to text the user wrote.
pub fn robot_source(config: Option<&Bound<'_, PyAny>>) -> (String, bool) {
    let Some(obj) = config.filter(|c| !c.is_none()) else {
        return ("the built-in default".into(), true);
    };
    if obj.cast::<PyDict>().is_ok() {
        return (DICT_SOURCE.into(), false);
    }
    if let Ok(s) = obj.extract::<String>()
        && is_toml_text(&s)
    {
        return (STRING_SOURCE.into(), true);
    }
    match obj.extract::<PathBuf>() {
        Ok(p) => (p.display().to_string(), true),
        Err(_) => ("<config>".into(), true),
    }
}

/// `config_toml(config=None) -> str`: the complete configuration with every
/// key, as `fbd run` writes it to `config.toml`.
#[pyfunction]
#[pyo3(signature = (config=None))]
pub fn config_toml(py: Python<'_>, config: Option<&Bound<'_, PyAny>>) -> PyResult<String> {
    crate::errors::guard(|| {
        if let Some(robot) = load_robot(py, config)? {
            return Ok(robot.config.to_toml());
        }
        Ok(load(py, config)?.config.to_toml())
    })
}

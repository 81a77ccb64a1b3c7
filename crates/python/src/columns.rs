//! Every column of `trajectory.csv`, kept in memory: the same names
//! ([`fbd_cli::output::trajectory_columns`]) and the same values, so that a
//! run from Python equals the CLI's file bit for bit (the test suite
//! compares them).

use fbd_cli::steptime::StepTimes;
use fbd_sim::StepRecord;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};

/// The values of one column.
enum Values {
    /// Numbers (m, rad, N, N·m, J, s).
    Float(Vec<f64>),
    /// Contact states `ST1`, `ST2`, `ST3`.
    State(Vec<&'static str>),
    /// Counts.
    Int(Vec<i64>),
}

/// The columns of a run, filled row by row.
pub struct Columns {
    names: Vec<String>,
    values: Vec<Values>,
    times: StepTimes,
    tips: [Option<usize>; 2],
    extras: Vec<usize>,
}

impl Columns {
    /// Empty columns for a model with contact points `contacts` and time
    /// step `dt`, with room for `rows` rows.
    pub fn new(contacts: &[String], dt: f64, rows: usize) -> Self {
        let names = fbd_cli::output::trajectory_columns(contacts);
        let tips = [
            contacts.iter().position(|n| n == "tip3"),
            contacts.iter().position(|n| n == "tip4"),
        ];
        let extras: Vec<usize> = (0..contacts.len())
            .filter(|&i| !tips.contains(&Some(i)))
            .collect();
        let mut c = Self::named(names, dt, rows);
        c.tips = tips;
        c.extras = extras;
        c
    }

    /// Empty columns named `names` (`newton_iterations` holds counts,
    /// `state*` and `*_state` contact states, every other one numbers),
    /// filled through [`Columns::sink`].
    pub fn named(names: Vec<String>, dt: f64, rows: usize) -> Self {
        let values = names
            .iter()
            .map(|n| {
                if n == "newton_iterations" {
                    Values::Int(Vec::with_capacity(rows))
                } else if n.starts_with("state") || n.ends_with("_state") {
                    Values::State(Vec::with_capacity(rows))
                } else {
                    Values::Float(Vec::with_capacity(rows))
                }
            })
            .collect();
        Self {
            names,
            values,
            times: StepTimes::new(dt),
            tips: [None; 2],
            extras: Vec::new(),
        }
    }

    /// The row being written, one value per call in column order (the 3D
    /// run's [`fbd_cli::spatial::csv::row_values`]).
    pub fn sink(&mut self) -> Sink<'_> {
        Sink {
            w: Writer {
                values: &mut self.values,
                i: 0,
            },
            times: &self.times,
        }
    }

    /// Appends the row of `r`, in the order of `trajectory.csv`.
    pub fn push(&mut self, r: &StepRecord) {
        let mut w = Writer {
            values: &mut self.values,
            i: 0,
        };
        w.f(self.times.value(r.step, r.t));
        for &x in &r.q {
            w.f(x);
        }
        for c in self.tips {
            let p = c.map_or([f64::NAN; 2], |c| r.point[c]);
            w.f(p[0]);
            w.f(p[1]);
        }
        for c in self.tips {
            w.s(c.map_or("ST1", |c| r.state[c].as_str()));
        }
        for c in self.tips {
            let (fa, n) = c.map_or((0.0, 0.0), |c| (r.fa[c], r.n[c]));
            w.f(fa);
            w.f(n);
        }
        for j in &r.joint_force {
            w.f(j[0]);
            w.f(j[1]);
        }
        for &c in &self.extras {
            w.s(r.state[c].as_str());
            w.f(r.fa[c]);
            w.f(r.n[c]);
        }
        for &t in &r.torque {
            w.f(t);
        }
        w.f(r.kinetic);
        w.f(r.potential);
        w.f(r.kinetic + r.potential);
        w.i(r.newton_iterations as i64);
        for &m in &r.limit_moment {
            w.f(m);
        }
        debug_assert_eq!(w.i, self.names.len(), "a value for every column");
    }

    /// `(names, {name: numpy array})`; state columns are lists of str (the
    /// Python layer turns them into NumPy string arrays).
    pub fn into_py<'py>(
        self,
        py: Python<'py>,
    ) -> PyResult<(Bound<'py, PyList>, Bound<'py, PyDict>)> {
        let data = PyDict::new(py);
        for (name, v) in self.names.iter().zip(self.values) {
            match v {
                Values::Float(v) => data.set_item(name, PyArray1::from_vec(py, v))?,
                Values::Int(v) => data.set_item(name, PyArray1::from_vec(py, v))?,
                Values::State(v) => data.set_item(name, PyList::new(py, v)?)?,
            }
        }
        Ok((PyList::new(py, &self.names)?, data))
    }
}

/// Writes one row's values column by column.
struct Writer<'a> {
    values: &'a mut [Values],
    i: usize,
}

impl Writer<'_> {
    fn f(&mut self, x: f64) {
        if let Values::Float(v) = &mut self.values[self.i] {
            v.push(x);
        }
        self.i += 1;
    }
    fn s(&mut self, x: &'static str) {
        if let Values::State(v) = &mut self.values[self.i] {
            v.push(x);
        }
        self.i += 1;
    }
    fn i(&mut self, x: i64) {
        if let Values::Int(v) = &mut self.values[self.i] {
            v.push(x);
        }
        self.i += 1;
    }
}

/// One row of [`Columns`] filled by the 3D run's row builder: the same
/// values, in the same order, as its `trajectory.csv`.
pub struct Sink<'a> {
    w: Writer<'a>,
    times: &'a StepTimes,
}

impl fbd_cli::spatial::csv::RowSink for Sink<'_> {
    fn time(&mut self, step: usize, t: f64) {
        self.w.f(self.times.value(step, t));
    }
    fn num(&mut self, x: f64) {
        self.w.f(x);
    }
    fn state(&mut self, s: fbd_contact::StateCode) {
        self.w.s(s.as_str());
    }
    fn count(&mut self, n: usize) {
        self.w.i(n as i64);
    }
}

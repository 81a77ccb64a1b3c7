//! Every column of `trajectory.csv`, kept in memory: the same names
//! ([`fbd_output::output::trajectory_columns`]) and the same values, from the
//! same row builder ([`fbd_output::tree::Plan::row`], the planar model's
//! plan [`ContactSlots::plan`]), so that a run from Python equals the
//! CLI's file bit for bit (the test suite compares them).

use fbd_output::output::{ContactSlots, RowSink};
use fbd_output::steptime::StepTimes;
use fbd_output::tree::Plan;
use fbd_sim::RobotRecord;
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
    /// The planar model's columns and where their values are in its
    /// record (empty for [`Columns::named`]).
    plan: Plan,
}

impl Columns {
    /// Empty columns for a planar model whose contact points go to `slots`
    /// (found by their `{leg, kind}`: [`ContactSlots::of`] the model's
    /// contact points) and time step `dt`, with room for `rows` rows.
    pub fn new(slots: ContactSlots, dt: f64, rows: usize) -> Self {
        let plan = slots.plan();
        let mut c = Self::named(plan.names.clone(), dt, rows);
        c.plan = plan;
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
            plan: Plan::default(),
        }
    }

    /// The row being written, one value per call in column order (the 3D
    /// run's [`fbd_output::tree::Plan::row`]).
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
    pub fn push(&mut self, r: &RobotRecord) {
        let mut sink = Sink {
            w: Writer {
                values: &mut self.values,
                i: 0,
            },
            times: &self.times,
        };
        self.plan.row(r, None, &mut sink);
        debug_assert_eq!(sink.w.i, self.names.len(), "a value for every column");
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

impl RowSink for Sink<'_> {
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

//! `trajectory.parquet` (`[output] format = "parquet"`): the columns of
//! `trajectory.csv` in Apache Parquet, written with the `parquet` crate's
//! column writer.
//!
//! Types follow the values the row builders hand over ([`RowSink`]):
//! numbers and times as `DOUBLE` (float64; a time is the double nearest to
//! the decimal `trajectory.csv` writes, [`StepTimes::value`]), contact
//! states as `BYTE_ARRAY` strings (`ST1`, `ST2`, `ST3`), counts
//! (`newton_iterations`) and the kinematic gait's stance flags (1 / 0) as
//! `INT64`: the types pandas gives the CSV's columns. Every column is required (no nulls); a NaN stays a
//! NaN. The types are learnt from the first row (a run of no row writes
//! every column as `DOUBLE`). Rows are buffered and written as row groups
//! of about [`GROUP_BYTES`]; the file is written to a temporary file and
//! renamed into place when complete, like every other file.

use std::io::{self, BufWriter};
use std::path::{Path, PathBuf};
use std::sync::Arc;

use fbd_contact::StateCode;
use parquet::basic::{Compression, LogicalType, Repetition, Type as Physical};
use parquet::data_type::{ByteArray, ByteArrayType, DoubleType, Int64Type};
use parquet::file::properties::WriterProperties;
use parquet::file::writer::SerializedFileWriter;
use parquet::schema::types::Type;
use tempfile::NamedTempFile;

use crate::OutputError;
use crate::output::{self, RowSink};
use crate::steptime::StepTimes;

/// Bytes of values buffered before a row group is written (16 MiB: 9 000
/// rows of the 3D hexapod's 230 columns, 50 000 of the planar model's 40).
pub const GROUP_BYTES: usize = 16 << 20;

/// A buffered column.
enum Column {
    Num(Vec<f64>),
    Str(Vec<ByteArray>),
    Int(Vec<i64>),
}

impl Column {
    fn clear(&mut self) {
        match self {
            Self::Num(v) => v.clear(),
            Self::Str(v) => v.clear(),
            Self::Int(v) => v.clear(),
        }
    }
}

/// Streams the trajectory into a Parquet file.
pub struct ParquetTable {
    names: Vec<String>,
    columns: Vec<Column>,
    /// The column the next value goes to; the row is being learnt while
    /// `columns` is shorter than `names` (first row).
    next: usize,
    rows_in_group: usize,
    group_rows: usize,
    times: StepTimes,
    states: [ByteArray; 3],
    writer: Option<SerializedFileWriter<BufWriter<NamedTempFile>>>,
    tmp: Option<NamedTempFile>,
    dest: PathBuf,
    error: Option<String>,
    rows: usize,
}

fn err(e: impl std::fmt::Display) -> String {
    e.to_string()
}

impl ParquetTable {
    /// Opens `dir/trajectory.parquet` (as a temporary file) for the columns
    /// `names`; `dt` is the time step of the times.
    pub fn create(dir: &Path, names: Vec<String>, dt: f64) -> Result<Self, OutputError> {
        let tmp = output::temp_in(dir, "trajectory.parquet")?;
        let group_rows = (GROUP_BYTES / (8 * names.len().max(1))).max(256);
        Ok(Self {
            columns: Vec::with_capacity(names.len()),
            names,
            next: 0,
            rows_in_group: 0,
            group_rows,
            times: StepTimes::new(dt),
            states: [StateCode::St1, StateCode::St2, StateCode::St3]
                .map(|s| ByteArray::from(s.as_str())),
            writer: None,
            tmp: Some(tmp),
            dest: dir.join("trajectory.parquet"),
            error: None,
            rows: 0,
        })
    }

    /// Rows written so far.
    pub fn rows(&self) -> usize {
        self.rows
    }

    fn learning(&self) -> bool {
        self.columns.len() < self.names.len()
    }

    fn push(&mut self, v: Value) {
        if self.error.is_some() {
            return;
        }
        if self.learning() && self.next == self.columns.len() {
            self.columns.push(match v {
                Value::Num(_) => Column::Num(Vec::with_capacity(self.group_rows)),
                Value::Str(_) => Column::Str(Vec::with_capacity(self.group_rows)),
                Value::Int(_) => Column::Int(Vec::with_capacity(self.group_rows)),
            });
        }
        let Some(c) = self.columns.get_mut(self.next) else {
            self.error = Some(format!("a row of more than {} values", self.names.len()));
            return;
        };
        match (c, v) {
            (Column::Num(c), Value::Num(x)) => c.push(x),
            (Column::Str(c), Value::Str(s)) => c.push(self.states[s].clone()),
            (Column::Int(c), Value::Int(n)) => c.push(n),
            _ => {
                self.error = Some(format!(
                    "column {}: a value of another type than its first",
                    self.names[self.next]
                ))
            }
        }
        self.next += 1;
    }

    /// Ends a row (after its values went through [`RowSink`]); writes a
    /// row group when the buffer is full.
    pub fn end_row(&mut self) {
        if self.error.is_some() {
            return;
        }
        if self.next != self.names.len() {
            self.error = Some(format!(
                "a row of {} values for {} columns",
                self.next,
                self.names.len()
            ));
            return;
        }
        self.next = 0;
        self.rows += 1;
        self.rows_in_group += 1;
        if self.rows_in_group >= self.group_rows
            && let Err(e) = self.flush_group()
        {
            self.error = Some(e);
        }
    }

    fn schema(&self) -> Result<Arc<Type>, String> {
        let fields = self
            .names
            .iter()
            .enumerate()
            .map(|(i, name)| {
                let b = match self.columns.get(i) {
                    Some(Column::Str(_)) => {
                        Type::primitive_type_builder(name, Physical::BYTE_ARRAY)
                            .with_logical_type(Some(LogicalType::String))
                    }
                    Some(Column::Int(_)) => Type::primitive_type_builder(name, Physical::INT64),
                    Some(Column::Num(_)) | None => {
                        Type::primitive_type_builder(name, Physical::DOUBLE)
                    }
                };
                b.with_repetition(Repetition::REQUIRED)
                    .build()
                    .map(Arc::new)
                    .map_err(err)
            })
            .collect::<Result<Vec<_>, _>>()?;
        Type::group_type_builder("trajectory")
            .with_fields(fields)
            .build()
            .map(Arc::new)
            .map_err(err)
    }

    fn open(&mut self) -> Result<(), String> {
        if self.writer.is_some() {
            return Ok(());
        }
        let schema = self.schema()?;
        let props = WriterProperties::builder()
            .set_compression(Compression::SNAPPY)
            .set_created_by(format!("fbd {}", env!("CARGO_PKG_VERSION")))
            .build();
        let tmp = self.tmp.take().ok_or("the file is closed")?;
        let w = SerializedFileWriter::new(
            BufWriter::with_capacity(1 << 16, tmp),
            schema,
            Arc::new(props),
        )
        .map_err(err)?;
        self.writer = Some(w);
        Ok(())
    }

    fn flush_group(&mut self) -> Result<(), String> {
        self.open()?;
        if self.rows_in_group == 0 {
            return Ok(());
        }
        let w = self.writer.as_mut().ok_or("the file is closed")?;
        let mut g = w.next_row_group().map_err(err)?;
        for c in &self.columns {
            let Some(mut col) = g.next_column().map_err(err)? else {
                return Err("fewer columns in the schema than in the rows".into());
            };
            match c {
                Column::Num(v) => col
                    .typed::<DoubleType>()
                    .write_batch(v, None, None)
                    .map(drop),
                Column::Str(v) => col
                    .typed::<ByteArrayType>()
                    .write_batch(v, None, None)
                    .map(drop),
                Column::Int(v) => col
                    .typed::<Int64Type>()
                    .write_batch(v, None, None)
                    .map(drop),
            }
            .map_err(err)?;
            col.close().map_err(err)?;
        }
        g.close().map_err(err)?;
        for c in &mut self.columns {
            c.clear();
        }
        self.rows_in_group = 0;
        Ok(())
    }

    /// Writes the last row group and the footer and renames the file into
    /// place; the first error of the run, if any, naming the file.
    pub fn finish(mut self) -> Result<PathBuf, OutputError> {
        let fail = |dest: &Path, e: String| OutputError::Io(format!("{}: {e}", dest.display()));
        if let Some(e) = self.error.take() {
            return Err(fail(&self.dest, e));
        }
        self.flush_group().map_err(|e| fail(&self.dest, e))?;
        let w = self
            .writer
            .take()
            .ok_or_else(|| fail(&self.dest, "the file is closed".into()))?;
        let buf = w.into_inner().map_err(|e| fail(&self.dest, err(e)))?;
        let tmp = buf
            .into_inner()
            .map_err(|e| OutputError::io(self.dest.display(), e.error()))?;
        output::persist(tmp, &self.dest)?;
        Ok(self.dest)
    }
}

/// A value handed over by [`RowSink`].
enum Value {
    Num(f64),
    Str(usize),
    Int(i64),
}

impl RowSink for ParquetTable {
    fn time(&mut self, step: usize, t: f64) {
        let v = self.times.value(step, t);
        self.push(Value::Num(v));
    }
    fn num(&mut self, x: f64) {
        self.push(Value::Num(x));
    }
    fn state(&mut self, s: StateCode) {
        let i = match s {
            StateCode::St1 => 0,
            StateCode::St2 => 1,
            StateCode::St3 => 2,
        };
        self.push(Value::Str(i));
    }
    fn count(&mut self, n: usize) {
        self.push(Value::Int(i64::try_from(n).unwrap_or(i64::MAX)));
    }
    fn flag(&mut self, on: bool) {
        self.push(Value::Int(i64::from(on)));
    }
}

/// `io::Error` of a message (for writers that keep an `io::Error`).
pub fn io_error(msg: String) -> io::Error {
    io::Error::other(msg)
}

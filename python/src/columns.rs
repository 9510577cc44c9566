//! Columns across the boundary: a stream is a dict of column name → 1-D
//! float64 numpy array, both ways (no Python object per element).

use numpy::{PyArray1, PyReadonlyArray1};
use pyo3::prelude::*;
use pyo3::types::PyDict;

use crate::DeadreckonError;

/// Named columns read from a dict of numpy arrays, all the same length.
pub struct Columns<'py> {
    stream: &'static str,
    dict: Bound<'py, PyDict>,
    /// Rows.
    pub len: usize,
}

impl<'py> Columns<'py> {
    /// The columns of `stream` (its file name, for messages).
    pub fn new(stream: &'static str, dict: Bound<'py, PyDict>) -> PyResult<Self> {
        let mut len = None;
        for (k, v) in dict.iter() {
            let a: PyReadonlyArray1<'_, f64> = v.extract().map_err(|_| {
                DeadreckonError::new_err(format!(
                    "{stream}: column `{k}` is not a 1-D float64 array"
                ))
            })?;
            let n = a.len()?;
            match len {
                None => len = Some(n),
                Some(m) if m != n => {
                    return Err(DeadreckonError::new_err(format!(
                        "{stream}: column `{k}` has {n} rows, the others {m}"
                    )))
                }
                _ => {}
            }
        }
        Ok(Columns {
            stream,
            dict,
            len: len.unwrap_or(0),
        })
    }

    /// Whether the column exists.
    pub fn has(&self, name: &str) -> bool {
        self.dict.contains(name).unwrap_or(false)
    }

    /// A required column: every value finite.
    pub fn col(&self, name: &str) -> PyResult<Vec<f64>> {
        let v = self.opt_col(name)?.ok_or_else(|| {
            DeadreckonError::new_err(format!("{}: missing column `{name}`", self.stream))
        })?;
        v.into_iter()
            .enumerate()
            .map(|(i, x)| {
                x.ok_or_else(|| {
                    DeadreckonError::new_err(format!(
                        "{}: row {i}: column `{name}` is empty (NaN)",
                        self.stream
                    ))
                })
            })
            .collect()
    }

    /// An optional column: NaN means absent; infinities are refused.
    pub fn opt_col(&self, name: &str) -> PyResult<Option<Vec<Option<f64>>>> {
        let Some(v) = self.dict.get_item(name)? else {
            return Ok(None);
        };
        let a: PyReadonlyArray1<'_, f64> = v.extract()?;
        let a = a.as_array();
        let mut out = Vec::with_capacity(a.len());
        for (i, &x) in a.iter().enumerate() {
            if x.is_infinite() {
                return Err(DeadreckonError::new_err(format!(
                    "{}: row {i}: column `{name}` is infinite",
                    self.stream
                )));
            }
            out.push((!x.is_nan()).then_some(x));
        }
        Ok(Some(out))
    }

    /// A column of integer counts (as float64, each an integer).
    pub fn int_col(&self, name: &str) -> PyResult<Vec<i64>> {
        self.col(name)?
            .into_iter()
            .enumerate()
            .map(|(i, x)| {
                if x.fract() == 0.0 && x.abs() < 9.0e15 {
                    Ok(x as i64)
                } else {
                    Err(DeadreckonError::new_err(format!(
                        "{}: row {i}: column `{name}` is not an integer: {x}",
                        self.stream
                    )))
                }
            })
            .collect()
    }
}

/// Builds a dict of columns: name → numpy array.
pub struct ColumnsOut<'py> {
    py: Python<'py>,
    dict: Bound<'py, PyDict>,
}

impl<'py> ColumnsOut<'py> {
    /// An empty set of columns.
    pub fn new(py: Python<'py>) -> Self {
        ColumnsOut {
            py,
            dict: PyDict::new(py),
        }
    }

    /// Adds a column of `f(row)` over `rows`.
    pub fn add<T>(&mut self, name: &str, rows: &[T], f: impl Fn(&T) -> f64) -> PyResult<&mut Self> {
        let v: Vec<f64> = rows.iter().map(f).collect();
        self.dict.set_item(name, PyArray1::from_vec(self.py, v))?;
        Ok(self)
    }

    /// The dict.
    pub fn finish(self) -> Bound<'py, PyDict> {
        self.dict
    }
}

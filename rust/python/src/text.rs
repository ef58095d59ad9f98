//! The fast path of the text readers (allanite-core `text`).

use crate::allanite_error;
use allanite_core::text;
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;

/// The columns `cols` (sorted) of the data lines of `text[offset:]` as a (rows, len(cols)) array, or
/// None where a line is outside the fast path's grammar (allanite-core `text::parse_decimal_table`:
/// plain decimal numbers, `delimiter` one ASCII character or None for whitespace). The caller then
/// reads the text the slow way, which names the problem.
#[pyfunction]
#[pyo3(signature = (text, offset, delimiter, ncols, cols))]
pub(crate) fn parse_decimal_table<'py>(
    py: Python<'py>,
    text: &[u8],
    offset: usize,
    delimiter: Option<char>,
    ncols: usize,
    cols: Vec<usize>,
) -> PyResult<Option<Bound<'py, PyArray2<f64>>>> {
    let delim = match delimiter {
        None => None,
        Some(c) if c.is_ascii() => Some(c as u8),
        Some(_) => return Ok(None),
    };
    let body = text.get(offset..).unwrap_or(&[]);
    let parsed = py.detach(|| text::parse_decimal_table(body, delim, ncols, &cols));
    let Some((values, rows)) = parsed else {
        return Ok(None);
    };
    let arr = Array2::from_shape_vec((rows, cols.len()), values)
        .map_err(|e| allanite_error(py, format!("parse_decimal_table: {e}")))?;
    Ok(Some(arr.into_pyarray(py)))
}

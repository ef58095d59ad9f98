//! The `allanite._core` extension module: numpy in, numpy out, GIL released around the work.
//! Nothing else lives here — validation with friendly messages happens in Python, the arithmetic in
//! allanite-core, and core errors come back as the matching `allanite.errors` class (`InputError`,
//! `ParameterError`; both ValueErrors).
//!
//! Every long call goes through [`run_interruptible`], so Ctrl-C stops it: a kernel takes a
//! `&Cancel` (see allanite_core::cancel) and the binding calls it as
//! `run_interruptible(py, workers, |cancel| kernel_cancellable(..., cancel))` — or, for a kernel of
//! contiguous axes giving an (axes, len(ms)[, windows]) array, as
//! `per_axis_and_m(py, &columns, ms.len(), workers, |cols, cancel| kernel(cols, ..., cancel))`
//! ([`arrays`]), which checks the axes, runs it so and shapes the result.
//!
//! This file is the module definition alone: one binding module per concern (a new binding goes in a
//! file of its own, registered below), the shared helpers ([`errors`], [`arrays`]) re-exported here so
//! that every binding module takes them as `crate::…`.

mod allan;
mod arrays;
mod deviations;
mod errors;
mod fits;
mod phase_grid;
mod phase_terms;
mod streaming;
mod sums;
mod text;
mod theo;

pub(crate) use arrays::{as_i64, c_slice, contiguous, contiguous_one, to_2d, to_3d};
pub(crate) use arrays::{per_axis_and_m, per_axis_m_and_window};
pub(crate) use errors::{
    allanite_error, core_error, input_error, parameter_error, run_interruptible,
};

use allan::{davar, davar_hann, davar_part, davar_ranged, part_grid};
use deviations::{
    deviation_gaps, deviation_gaps_dynamic, deviation_static, mtie_phase, ohvar_dynamic, tie_gaps,
    tierms_phase, ttotvar_static,
};
use fits::{fit_windows, irls_curves, whittle_noise};
use phase_terms::{allan_covariance_phase, oavar_phase_gaps, pvar_phase};
use pyo3::prelude::*;
use streaming::StreamingVariance;
use sums::{angle_term_sums, block_lag1_sums, compensated_sums};
use text::parse_decimal_table;
use theo::{theo1_dynamic, theo1_static};

#[pymodule]
fn _core(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(davar, m)?)?;
    m.add_function(wrap_pyfunction!(davar_ranged, m)?)?;
    m.add_function(wrap_pyfunction!(davar_hann, m)?)?;
    m.add_function(wrap_pyfunction!(fit_windows, m)?)?;
    m.add_function(wrap_pyfunction!(irls_curves, m)?)?;
    m.add_function(wrap_pyfunction!(whittle_noise, m)?)?;
    m.add_function(wrap_pyfunction!(phase_grid::phase_bins, m)?)?;
    m.add_function(wrap_pyfunction!(phase_grid::add_waveform, m)?)?;
    m.add_function(wrap_pyfunction!(phase_grid::lattice_bins, m)?)?;
    m.add_function(wrap_pyfunction!(phase_grid::add_lattice_waveform, m)?)?;
    m.add_function(wrap_pyfunction!(davar_part, m)?)?;
    m.add_function(wrap_pyfunction!(part_grid, m)?)?;
    m.add_function(wrap_pyfunction!(compensated_sums, m)?)?;
    m.add_function(wrap_pyfunction!(block_lag1_sums, m)?)?;
    m.add_function(wrap_pyfunction!(parse_decimal_table, m)?)?;
    m.add_function(wrap_pyfunction!(angle_term_sums, m)?)?;
    m.add_function(wrap_pyfunction!(theo1_static, m)?)?;
    m.add_function(wrap_pyfunction!(theo1_dynamic, m)?)?;
    m.add_function(wrap_pyfunction!(deviation_static, m)?)?;
    m.add_function(wrap_pyfunction!(ttotvar_static, m)?)?;
    m.add_function(wrap_pyfunction!(deviation_gaps, m)?)?;
    m.add_function(wrap_pyfunction!(ohvar_dynamic, m)?)?;
    m.add_function(wrap_pyfunction!(deviation_gaps_dynamic, m)?)?;
    m.add_function(wrap_pyfunction!(tie_gaps, m)?)?;
    m.add_function(wrap_pyfunction!(mtie_phase, m)?)?;
    m.add_function(wrap_pyfunction!(tierms_phase, m)?)?;
    m.add_function(wrap_pyfunction!(pvar_phase, m)?)?;
    m.add_function(wrap_pyfunction!(allan_covariance_phase, m)?)?;
    m.add_function(wrap_pyfunction!(oavar_phase_gaps, m)?)?;
    m.add_class::<StreamingVariance>()?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}

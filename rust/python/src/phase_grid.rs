//! Bindings of allanite-core's `phase_grid` (the line families' time-domain passes, used by
//! `allanite.model.linefit` where the core has them): numpy in, numpy out, GIL released.

use crate::{c_slice, parameter_error};
use allanite_core::phase_grid;
use numpy::{IntoPyArray, PyArray1, PyReadonlyArray1, PyReadwriteArray1};
use pyo3::prelude::*;

/// `linefit._binned` of each part on `linefit._gridding(u, m_bins, seg)`: the parts (each as long as
/// `u`, the unit phases in [0, 1)) spread onto `n_seg` × `m_bins` bins by linear interpolation; `seg`
/// (int64 per sample, < n_seg) or None for one segment. With `ph` (the phasors, complex as interleaved
/// float64), `parts` is the one series y and the parts are y·Re ph and y·(−Im ph). Returns one float64
/// array per part.
#[pyfunction]
#[pyo3(signature = (parts, u, m_bins, seg, n_seg, ph=None))]
pub(crate) fn phase_bins<'py>(
    py: Python<'py>,
    parts: Vec<PyReadonlyArray1<'py, f64>>,
    u: PyReadonlyArray1<'py, f64>,
    m_bins: usize,
    seg: Option<PyReadonlyArray1<'py, i64>>,
    n_seg: usize,
    ph: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<Vec<Bound<'py, PyArray1<f64>>>> {
    let uv = c_slice(py, &u, "u")?;
    let ps = parts
        .iter()
        .map(|p| c_slice(py, p, "parts"))
        .collect::<PyResult<Vec<_>>>()?;
    let pv = ph.as_ref().map(|p| c_slice(py, p, "ph")).transpose()?;
    let segs = segment_indices(py, seg.as_ref())?;
    let sg = segs.as_deref();
    let out = py
        .detach(|| match (pv, ps.as_slice()) {
            (None, _) => phase_grid::phase_bins(&ps, uv, m_bins, sg, n_seg),
            (Some(p), [y]) => phase_grid::phase_bins_heterodyned(y, p, uv, m_bins, sg, n_seg)
                .map(|b| b.to_vec()),
            (Some(_), _) => None,
        })
        .ok_or_else(|| {
            parameter_error(
                py,
                format!(
                    "phase_bins: every part must be as long as u ({}), u in [0, 1), seg in [0, {n_seg}), m_bins ≥ 1, with ph one part and 2·{} phasor values",
                    uv.len(), uv.len()
                ),
            )
        })?;
    Ok(out.into_iter().map(|v| v.into_pyarray(py)).collect())
}

/// `linefit.evaluate`'s pass: adds to `out` the waveform `wave` (m + 1 complex bins as interleaved
/// float64, the last the first again) interpolated at the unit phases `u`, times the phasors `ph`
/// (interleaved complex per sample) or its real part alone when `ph` is None.
#[pyfunction]
#[pyo3(signature = (out, u, wave, ph))]
pub(crate) fn add_waveform<'py>(
    py: Python<'py>,
    mut out: PyReadwriteArray1<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
    wave: PyReadonlyArray1<'py, f64>,
    ph: Option<PyReadonlyArray1<'py, f64>>,
) -> PyResult<()> {
    let (uv, wv) = (c_slice(py, &u, "u")?, c_slice(py, &wave, "wave")?);
    let pv = ph.as_ref().map(|p| c_slice(py, p, "ph")).transpose()?;
    let ov = out
        .as_slice_mut()
        .map_err(|_| parameter_error(py, "out must be a C-contiguous float64 array".to_string()))?;
    let n = ov.len();
    if !py.detach(|| phase_grid::add_waveform(ov, uv, wv, pv)) {
        return Err(parameter_error(
            py,
            format!(
                "add_waveform: u must be {n} phases in [0, 1), wave 2(m + 1) ≥ 4 values, ph 2·{n} values"
            ),
        ));
    }
    Ok(())
}

/// The lattice of phasors of `linefit._groups` (allanite-core `phase_grid::Lattice`) from its tables.
fn lattice<'a>(
    idx: &'a [i64],
    blocks: &'a [f64],
    offsets: &'a [f64],
    k0: i64,
    power: usize,
    conj: bool,
) -> phase_grid::Lattice<'a> {
    phase_grid::Lattice {
        idx,
        blocks,
        offsets,
        k0,
        power,
        conj,
    }
}

/// [`phase_bins`] of the one series `y` heterodyned by the phasors e^{i2πaνn} at the sample indices
/// `idx` (int64), made sample by sample from two tables instead of read from n complex values: block
/// ⌊n/B⌋'s phasor `blocks[⌊n/B⌋ − k0]` times `offsets[n mod B]` (B = len(offsets); both complex as
/// interleaved float64), raised to `power` ≥ 1 by repeated products, conjugated when `conj` — the
/// numbers of `linefit._phasor` and `linefit._groups` on x86-64 (allanite-core `phase_grid::Lattice`).
/// Returns the bins of y·Re ph and of y·(−Im ph).
#[pyfunction]
#[pyo3(signature = (y, u, m_bins, seg, n_seg, idx, blocks, offsets, k0, power, conj))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn lattice_bins<'py>(
    py: Python<'py>,
    y: PyReadonlyArray1<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
    m_bins: usize,
    seg: Option<PyReadonlyArray1<'py, i64>>,
    n_seg: usize,
    idx: PyReadonlyArray1<'py, i64>,
    blocks: PyReadonlyArray1<'py, f64>,
    offsets: PyReadonlyArray1<'py, f64>,
    k0: i64,
    power: usize,
    conj: bool,
) -> PyResult<Vec<Bound<'py, PyArray1<f64>>>> {
    let (yv, uv) = (c_slice(py, &y, "y")?, c_slice(py, &u, "u")?);
    let (iv, bv, ov) = (
        c_slice(py, &idx, "idx")?,
        c_slice(py, &blocks, "blocks")?,
        c_slice(py, &offsets, "offsets")?,
    );
    let segs = segment_indices(py, seg.as_ref())?;
    let sg = segs.as_deref();
    let ph = lattice(iv, bv, ov, k0, power, conj);
    let out = py
        .detach(|| phase_grid::phase_bins_lattice(yv, &ph, uv, m_bins, sg, n_seg))
        .ok_or_else(|| {
            parameter_error(
                py,
                format!(
                    "lattice_bins: y and idx must be as long as u ({}), u in [0, 1), seg in [0, {n_seg}), m_bins ≥ 1, power ≥ 1, blocks and offsets whole complex numbers with every index's block (its index // len(offsets) − k0) among the blocks",
                    uv.len()
                ),
            )
        })?;
    Ok(out.into_iter().map(|v| v.into_pyarray(py)).collect())
}

/// [`add_waveform`] with the phasors of [`lattice_bins`] (`idx`, `blocks`, `offsets`, `k0`, `power`,
/// `conj`) made sample by sample.
#[pyfunction]
#[pyo3(signature = (out, u, wave, idx, blocks, offsets, k0, power, conj))]
#[allow(clippy::too_many_arguments)]
pub(crate) fn add_lattice_waveform<'py>(
    py: Python<'py>,
    mut out: PyReadwriteArray1<'py, f64>,
    u: PyReadonlyArray1<'py, f64>,
    wave: PyReadonlyArray1<'py, f64>,
    idx: PyReadonlyArray1<'py, i64>,
    blocks: PyReadonlyArray1<'py, f64>,
    offsets: PyReadonlyArray1<'py, f64>,
    k0: i64,
    power: usize,
    conj: bool,
) -> PyResult<()> {
    let (uv, wv) = (c_slice(py, &u, "u")?, c_slice(py, &wave, "wave")?);
    let (iv, bv, ov) = (
        c_slice(py, &idx, "idx")?,
        c_slice(py, &blocks, "blocks")?,
        c_slice(py, &offsets, "offsets")?,
    );
    let outv = out
        .as_slice_mut()
        .map_err(|_| parameter_error(py, "out must be a C-contiguous float64 array".to_string()))?;
    let n = outv.len();
    let ph = lattice(iv, bv, ov, k0, power, conj);
    if !py.detach(|| phase_grid::add_waveform_lattice(outv, uv, wv, &ph)) {
        return Err(parameter_error(
            py,
            format!(
                "add_lattice_waveform: u and idx must be {n} values (u in [0, 1)), wave 2(m + 1) ≥ 4 values, power ≥ 1, every index's block among the blocks"
            ),
        ));
    }
    Ok(())
}

/// The optional per-sample segment numbers as indices (a negative one maps past every segment: the core
/// refuses it as out of range).
fn segment_indices(
    py: Python<'_>,
    seg: Option<&PyReadonlyArray1<'_, i64>>,
) -> PyResult<Option<Vec<usize>>> {
    seg.map(|s| {
        Ok(c_slice(py, s, "seg")?
            .iter()
            .map(|&k| usize::try_from(k).unwrap_or(usize::MAX))
            .collect())
    })
    .transpose()
}

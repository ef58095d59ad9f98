//! Which path the fast estimator takes for a record (the static window's, the double-word phase per
//! segment, chunked phases, streaming block sums), where a record can be cut into parts that give its
//! values bit for bit, and the rows of every (axis, m) of a part along that path.

use super::rows::{classic_row_at, PHASE_M_MAX};
use super::{n_windows, overlapping_row_at, Estimator, Method, Part, Request, RowScratch};
use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
use crate::gather::{classic_window, GATHER_MAX};
use crate::oavar::overlapping_window;
use crate::range::Range;
use rayon::prelude::*;

/// The one window `y[..window]` of a request by the static estimators' paths — every m from one
/// double-word phase (overlapping, `crate::oavar`) or cluster sums gathered from one double-word
/// prefix (classic, `crate::gather`) — centred on each window's mean from the parallel pass that
/// also checks the samples are finite (the samples after the window are checked too). `None` when
/// the window is too long for them (`GATHER_MAX`); the caller then streams.
pub(super) fn static_window(req: &Request, out: &mut [f64], cancel: &Cancel) -> Option<Result<()>> {
    let n_axes = req.columns.len();
    let fits = match req.estimator {
        Estimator::Overlapping => req.window <= GATHER_MAX,
        Estimator::Classic => req.window * n_axes <= GATHER_MAX,
    };
    if !fits {
        return None;
    }
    let mut run = || -> Result<()> {
        for (axis, c) in req.columns.iter().enumerate() {
            if let Some(i) = c[req.window..].iter().position(|v| !v.is_finite()) {
                let index = req.window + i;
                return Err(CoreError::NonFinite {
                    axis,
                    index,
                    value: c[index],
                });
            }
        }
        let mus = req
            .columns
            .iter()
            .enumerate()
            .map(|(a, c)| crate::oavar::centre(&c[..req.window], a))
            .collect::<Result<Vec<f64>>>()?;
        match req.estimator {
            Estimator::Overlapping => {
                overlapping_window(req.columns, &mus, req.ms, req.window, out, cancel)
            }
            Estimator::Classic => {
                classic_window(req.columns, &mus, req.ms, req.window, out, cancel)
            }
        }
        cancel.check()
    };
    Some(run())
}

/// Whether a record whose windows read `n_used` samples × `n_axes` is *long* for the phase path
/// (more than `PHASE_RECORD_MAX`, 2^26): its segments are shorter, and long windows stream.
pub(super) fn long_record(n_used: usize, n_axes: usize) -> bool {
    n_used.saturating_mul(n_axes) > crate::oavar::PHASE_RECORD_MAX
}

/// Whether the fast dynamic estimator of a record of several windows takes the double-word phase
/// path: the overlapping estimator on a short record (≤ 2^26 samples × axes) at any window, on a long
/// one while its segments span at most `PHASE_SPAN_MAX` (2^23) samples — windows up to 2^21. The phase
/// it holds is one segment's either way. Longer windows on long records take chunked phases
/// ([`RowPath::Chunked`]) or stream their sums (hops below 64), see [`dynamic_avar_part_cancellable`].
pub(super) fn takes_phase_path(
    estimator: Estimator,
    n_used: usize,
    n_axes: usize,
    window: usize,
) -> bool {
    let long = long_record(n_used, n_axes);
    estimator == Estimator::Overlapping
        && (!long || crate::oavar::segment_span(window, true) <= crate::oavar::PHASE_SPAN_MAX)
}

/// How the fast path forms a record's rows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum RowPath {
    /// The double-word phase of each segment of whole windows (`takes_phase_path`).
    Phase,
    /// Terms from the phase built chunk by chunk (`crate::chunked`): the overlapping estimator on a
    /// long record with long windows at hops ≥ 64, and its static estimator beyond `GATHER_MAX`.
    Chunked,
    /// Streaming block sums per m (the classic estimator; overlapping hops below 64 on long windows).
    Stream,
}

/// The path of a record of `n_win` windows whose windows read `n_used` samples × `n_axes`.
pub(crate) fn row_path(req: &Request, n_used: usize, n_axes: usize, n_win: usize) -> RowPath {
    if takes_phase_path(req.estimator, n_used, n_axes, req.window) {
        RowPath::Phase
    } else if req.estimator == Estimator::Overlapping
        && (n_win == 1 || req.hop >= crate::oavar::SMALL_HOP)
    {
        RowPath::Chunked
    } else {
        RowPath::Stream
    }
}

/// Samples between the places a record of `n` samples × `n_axes` can be cut into parts whose
/// [`dynamic_avar_part_cancellable`] values are the whole call's bit for bit: parts must start at
/// a multiple of this (the hop where the call streams; a phase segment, `segment_windows` · hop,
/// on the phase path). `None` if the arguments do not describe a valid dynamic call.
pub fn part_grid(
    n: usize,
    n_axes: usize,
    window: usize,
    hop: usize,
    estimator: Estimator,
    method: Method,
) -> Option<usize> {
    if hop == 0 || window < 2 || window > n || n_axes == 0 {
        return None;
    }
    let n_win = n_windows(n, window, hop);
    let n_used = (n_win - 1) * hop + window;
    if method != Method::Fast || n_win < 2 {
        return Some(hop);
    }
    let req = Request {
        columns: &[],
        window,
        hop,
        ms: &[],
        estimator,
        method,
    };
    Some(match row_path(&req, n_used, n_axes, n_win) {
        RowPath::Phase => {
            crate::oavar::segment_windows(window, hop, long_record(n_used, n_axes)) * hop
        }
        RowPath::Chunked => crate::chunked::chunk_len(window, hop),
        RowPath::Stream => hop,
    })
}

/// The fast path of [`dynamic_avar_part_cancellable`] (and of [`dynamic_avar`], as the part that is
/// the whole record) into `out` ([axis][m][window]): the record's phase path when `phase`, its
/// streaming rows otherwise (and for what the phase path streams).
///
/// The phase path runs segment by segment: the record's windows are cut into runs of
/// `segment_windows` (a grid on the record's window index, so a part that starts on it cuts where
/// the record does), and each run's phase is built from its own first sample — memory for one
/// segment's phase, not the record's. Within a segment: every m from the phase, tiled for hops ≥ 64;
/// at shorter hops the rows of m > `PHASE_M_MAX` stream the segment's samples instead.
pub(super) fn part_rows(
    req: &Request,
    mus: &[f64],
    part: Part,
    path: RowPath,
    out: &mut [f64],
    cancel: &Cancel,
) -> Option<Vec<Range>> {
    match path {
        RowPath::Chunked => chunked_rows(req, mus, part, out, cancel),
        RowPath::Phase => phase_rows(req, mus, part, out, cancel),
        RowPath::Stream => Some(stream_rows(req, mus, part, out, cancel)),
    }
}

/// [`part_rows`] on chunked phases (`crate::chunked`), axis by axis.
fn chunked_rows(
    req: &Request,
    mus: &[f64],
    part: Part,
    out: &mut [f64],
    cancel: &Cancel,
) -> Option<Vec<Range>> {
    let n_m = req.ms.len();
    let n_m_win = out.len() / req.columns.len();
    let mut ranges = Vec::with_capacity(req.columns.len() * n_m);
    for (a, y) in req.columns.iter().enumerate() {
        let dst_axis = &mut out[a * n_m_win..(a + 1) * n_m_win];
        let (w, h) = (req.window, req.hop);
        ranges.extend(crate::chunked::overlapping_rows(
            y, part, mus[a], req.ms, w, h, dst_axis, cancel,
        ));
    }
    (ranges.len() == req.columns.len() * n_m).then_some(ranges)
}

/// [`part_rows`] on the double-word phase, segment by segment: a segment's rows tiled for hops ≥ 64,
/// else row by row ([`phase_segment_rows`]). Each row's range is noted right after the row is formed
/// (in cache); the tiled path leaves it open (`None`).
fn phase_rows(
    req: &Request,
    mus: &[f64],
    part: Part,
    out: &mut [f64],
    cancel: &Cancel,
) -> Option<Vec<Range>> {
    let n_m = req.ms.len();
    let n_win = out.len() / (req.columns.len() * n_m);
    let n_m_win = n_m * n_win;
    let mut ranges = vec![Range::default(); req.columns.len() * n_m];
    let mut noted = true;
    let n_used_record = (part.total - 1) * req.hop + req.window;
    let long = long_record(n_used_record, req.columns.len());
    let seg = crate::oavar::segment_windows(req.window, req.hop, long);
    for (a, y) in req.columns.iter().enumerate() {
        let dst_axis = &mut out[a * n_m_win..(a + 1) * n_m_win];
        // the part's windows j0 .. j1 (its own index), cut where the record's segments start
        let mut j0 = 0;
        while j0 < n_win {
            if cancel.is_cancelled() {
                return None;
            }
            let g = part.first + j0; // the record's window index
            let j1 = ((g / seg + 1) * seg - part.first).min(n_win);
            let nw = j1 - j0;
            let s0 = j0 * req.hop;
            let ys = &y[s0..s0 + (nw - 1) * req.hop + req.window];
            let ph = crate::oavar::Phase::new(ys, mus[a]);
            let (hi, lo) = ph.parts();
            if part.total >= 2 && nw >= 2 && req.hop >= crate::oavar::SMALL_HOP {
                noted = false;
                crate::oavar::overlapping_dynamic_tiled(
                    hi,
                    lo,
                    req.ms,
                    req.window,
                    req.hop,
                    dst_axis,
                    (n_win, j0, nw),
                    cancel,
                );
            } else {
                let sub = Part {
                    first: g,
                    total: part.total,
                };
                let seg_part = Segment {
                    hi,
                    lo,
                    y: &y[s0..],
                    mu: mus[a],
                    sub,
                    cols: j0..j1,
                };
                let rows = phase_segment_rows(req, &seg_part, dst_axis, n_win, cancel);
                for (t, r) in rows.into_iter().enumerate() {
                    ranges[a * n_m + t] = ranges[a * n_m + t].merge(r);
                }
            }
            j0 = j1;
        }
    }
    noted.then_some(ranges)
}

/// One phase segment of one axis: its phase (`hi`, `lo`), the axis's samples from its first window on
/// (`y`), the axis mean, the segment as a part of the record, and its windows in the part's rows.
struct Segment<'a> {
    hi: &'a [f64],
    lo: &'a [f64],
    y: &'a [f64],
    mu: f64,
    sub: Part,
    cols: std::ops::Range<usize>,
}

/// The rows of one phase segment (`dst_axis`: one axis's rows of `n_win` windows), m by m in parallel:
/// from the phase for m ≤ `PHASE_M_MAX` (and a one-window record, and hops ≥ 64), else streaming the
/// segment's samples. Each row's range.
fn phase_segment_rows(
    req: &Request,
    sp: &Segment,
    dst_axis: &mut [f64],
    n_win: usize,
    cancel: &Cancel,
) -> Vec<Range> {
    let total = sp.sub.total;
    dst_axis
        .par_chunks_mut(n_win)
        .enumerate()
        .map_init(
            || (crate::oavar::DynScratch::default(), RowScratch::default()),
            |(sc, rs), (t, row)| {
                if cancel.is_cancelled() {
                    return Range::default();
                }
                let dst = &mut row[sp.cols.clone()];
                let m = req.ms[t];
                // (a one-window run at a hop ≥ 64 is the tiled path's blocks)
                if m <= PHASE_M_MAX || total == 1 || req.hop >= crate::oavar::SMALL_HOP {
                    crate::oavar::overlapping_dynamic_row(
                        sp.hi,
                        sp.lo,
                        m,
                        req.window,
                        req.hop,
                        total == 1,
                        dst,
                        sc,
                    )
                } else {
                    overlapping_row_at(
                        sp.y, sp.sub, sp.mu, m, req.window, req.hop, dst, rs, cancel,
                    );
                    Range::of(dst)
                }
            },
        )
        .collect()
}

/// [`part_rows`] streaming every (axis, m) row in parallel.
fn stream_rows(
    req: &Request,
    mus: &[f64],
    part: Part,
    out: &mut [f64],
    cancel: &Cancel,
) -> Vec<Range> {
    let n_m = req.ms.len();
    let n_win = out.len() / (req.columns.len() * n_m);
    out.par_chunks_mut(n_win)
        .enumerate()
        .map_init(RowScratch::default, |sc, (row, dst)| {
            if cancel.is_cancelled() {
                return Range::default();
            }
            let (a, t) = (row / n_m, row % n_m);
            let (y, m) = (req.columns[a], req.ms[t]);
            match req.estimator {
                Estimator::Overlapping => {
                    overlapping_row_at(y, part, mus[a], m, req.window, req.hop, dst, sc, cancel)
                }
                Estimator::Classic => {
                    classic_row_at(y, part, mus[a], m, req.window, req.hop, dst, cancel)
                }
            }
            Range::of(dst)
        })
        .collect()
}

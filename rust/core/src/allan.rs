//! Static and dynamic (sliding-window) Allan variance of rate samples.
//!
//! Conventions (NIST SP 1065, paper 000): `y` holds M rate samples at interval τ0; the angle record has
//! N = M + 1 points; τ = m·τ0. A window of `window` rate samples covers `window + 1` angle points and
//! holds `window + 1 − 2m` overlapping second differences at m. Everything here works in the rate
//! domain, where the second difference of the angle is the difference of two adjacent m-sample block
//! sums: d_m(k) = B(k+m) − B(k), B(k) = Σ_{i=k}^{k+m−1} y_i, so that
//!
//!   σ²(m) = Σ_k d_m(k)² / (2 m² L),   L = number of terms,
//!
//! which equals paper 000's Σ (θ(k+2m) − 2θ(k+m) + θ(k))² / (2 m² τ0² L) with θ = τ0·cumsum(y).
//!
//! # How drift and cancellation are controlled
//! A running sum updated by "add the entering term, subtract the leaving one" (paper 000 eq. 17) and
//! a global prefix sum both carry rounding error proportional to the *largest* values ever summed: a
//! quiet stretch after a loud one (noise level ×10⁻⁶) loses every digit. The fast path here never
//! subtracts a sum that contains samples outside the quantity being computed:
//!
//! 1. Block sums B(k) use the Van Herk / Gil-Werman split: the record is cut into aligned segments of
//!    m samples; B(k) = (suffix sum of k's segment from k) + (prefix sum of the next segment up to
//!    k+m−1). Both partial sums contain only samples of B(k)'s own range, so the error of B(k) is
//!    bounded by m·ε·max|y| over that range — local, with no drift along the record.
//! 2. Window sums of the squared differences a(k) = d_m(k)² ≥ 0 are sums of non-negative numbers,
//!    which have no cancellation: a(k) are accumulated in hop-aligned blocks (in runs of at most
//!    `RUN` terms with four partial accumulators, so the error grows like hop/RUN, not hop), and the
//!    blocks are combined per window by the same Van Herk split over the block array. A window's sum
//!    therefore has relative error ≲ (RUN + window/RUN)·ε, whatever the rest of the record holds.
//!
//! 3. The static classic estimator (one window) gathers its ⌊W/m⌋ cluster sums from one double-word
//!    prefix per axis instead of streaming the record per m (`crate::gather`): O(W/m) per τ, so dense τ
//!    lists cost what their arithmetic costs.
//!
//! Each (axis, m) row is computed by one sequential routine, so results are bit-identical for any
//! number of worker threads.

mod naive;
mod paths;
mod rows;
mod sums;
mod terms;
#[cfg(test)]
mod tests;

pub(crate) use naive::{centred_angle, naive_rows};
pub use paths::part_grid;
pub(crate) use rows::{overlapping_row_at, Part, RowScratch};
pub(crate) use sums::{
    block_window_sums, compensated_means, sliding_sums, sliding_sums_at, sum4, Compensated,
};
pub use sums::{compensated_mean, compensated_sum_from};
pub(crate) use terms::{for_each_term_chunk, for_each_term_chunk_at, TermScratch};

use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
use crate::range::Range;
use naive::naive_window;
use paths::{part_rows, row_path, static_window};
use rayon::prelude::*;

/// Which Allan estimator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Estimator {
    /// Overlapping Allan variance (all start points), SP 1065 eq. 11.
    Overlapping,
    /// Classic, non-overlapping Allan variance (clusters at stride m), SP 1065 eq. 7.
    Classic,
}

/// How the sliding-window estimate is computed.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Method {
    /// Sliding block sums: O(M) per τ for the whole record, independent of window and hop.
    Fast,
    /// Recompute every window from scratch (paper 000's DAVAR): O(window) per τ per window.
    Naive,
}

/// Longest run of terms added into one partial sum before it is folded into its block total.
pub(crate) const RUN: usize = 1024;

/// Averaging factors up to this use direct block sums, in chunks of `DIRECT_CHUNK` terms.
pub(crate) const DIRECT_M: usize = 8;
const DIRECT_CHUNK: usize = 2048;

/// Hops up to this many terms are cut into blocks after the terms are stored.
const SMALL_HOP: usize = 64;

/// Number of windows of `window` samples, starting every `hop` samples, that fit in `n` samples.
pub fn n_windows(n: usize, window: usize, hop: usize) -> usize {
    if window > n || hop == 0 || window == 0 {
        0
    } else {
        (n - window) / hop + 1
    }
}

/// Number of squared differences averaged at factor m in a window of `window` rate samples.
pub fn n_terms(estimator: Estimator, window: usize, m: usize) -> usize {
    match estimator {
        Estimator::Overlapping => (window + 1).saturating_sub(2 * m),
        Estimator::Classic => (window / m.max(1)).saturating_sub(1),
    }
}

/// Largest averaging factor the estimators accept for a window of `window` rate samples.
pub fn max_m(window: usize) -> usize {
    window / 2
}

/// What to compute: the same window, hop and factors for every axis.
#[derive(Clone, Copy, Debug)]
pub struct Request<'a> {
    /// One rate record per axis, all the same length M.
    pub columns: &'a [&'a [f64]],
    /// Window length in rate samples (M for the static estimator).
    pub window: usize,
    /// Window start spacing in samples (≥ 1).
    pub hop: usize,
    /// Averaging factors, each 1 ≤ m ≤ window / 2.
    pub ms: &'a [usize],
    pub estimator: Estimator,
    pub method: Method,
}

impl<'a> Request<'a> {
    /// The usual request: the overlapping estimator by the fast method, with these windows and factors.
    pub fn overlapping(
        columns: &'a [&'a [f64]],
        window: usize,
        hop: usize,
        ms: &'a [usize],
    ) -> Self {
        Request {
            columns,
            window,
            hop,
            ms,
            estimator: Estimator::Overlapping,
            method: Method::Fast,
        }
    }
}

/// At least one axis, all the same length, at least 2 samples: the record length.
pub(crate) fn check_shape(cols: &[&[f64]]) -> Result<usize> {
    if cols.is_empty() {
        return Err(CoreError::InvalidInput(
            "no axes given: at least one record is needed".into(),
        ));
    }
    let n = cols[0].len();
    if let Some((a, c)) = cols.iter().enumerate().find(|(_, c)| c.len() != n) {
        return Err(CoreError::InvalidInput(format!(
            "axis {a} has {} samples but axis 0 has {n}; all axes must have the same length",
            c.len()
        )));
    }
    if n < 2 {
        return Err(CoreError::TooShort {
            what: "record",
            needed: 2,
            got: n,
        });
    }
    Ok(n)
}

/// The first NaN or ±inf of any axis, as an error naming it.
pub(crate) fn check_finite(cols: &[&[f64]]) -> Result<()> {
    for (a, c) in cols.iter().enumerate() {
        if let Some(i) = c.iter().position(|v| !v.is_finite()) {
            return Err(CoreError::NonFinite {
                axis: a,
                index: i,
                value: c[i],
            });
        }
    }
    Ok(())
}

/// A window of `min ..= n` samples (`n`: the record length) and a hop of at least 1 sample, or the
/// error naming the value and what is allowed.
pub(crate) fn check_window_hop(window: usize, hop: usize, n: usize, min: usize) -> Result<()> {
    if window < min || window > n {
        return Err(CoreError::InvalidParameter(format!(
            "window ({window} samples) must be between {min} and the record length ({n} samples)"
        )));
    }
    if hop == 0 {
        return Err(CoreError::InvalidParameter(
            "hop (0) must be at least 1 sample".into(),
        ));
    }
    Ok(())
}

/// Checks a request; the messages name the value and what is allowed.
pub fn validate(req: &Request) -> Result<usize> {
    let n_win = validate_shape(req)?;
    check_finite(req.columns)?;
    Ok(n_win)
}

/// [`validate`] without the finite check (for a path that checks while it reads the samples).
fn validate_shape(req: &Request) -> Result<usize> {
    let n = check_shape(req.columns)?;
    check_window_hop(req.window, req.hop, n, 2)?;
    if req.ms.is_empty() {
        return Err(CoreError::InvalidParameter(
            "no averaging factors given".into(),
        ));
    }
    let mmax = max_m(req.window);
    if let Some(&m) = req.ms.iter().find(|&&m| m == 0 || m > mmax) {
        return Err(CoreError::InvalidParameter(format!(
            "averaging factor m = {m} is outside 1..={mmax} allowed for a window of {} samples",
            req.window
        )));
    }
    Ok(n_windows(n, req.window, req.hop))
}

/// Allan variance of every window at every m, for every axis, in the calling rayon pool.
/// Returns (values laid out as [axis][m][window], number of windows).
pub fn dynamic_avar(req: &Request) -> Result<(Vec<f64>, usize)> {
    dynamic_avar_cancellable(req, &Cancel::new())
}

/// [`dynamic_avar`] that stops within one row chunk (at most a few thousand terms per worker) once
/// `cancel` is set, and then returns [`CoreError::Cancelled`].
pub fn dynamic_avar_cancellable(req: &Request, cancel: &Cancel) -> Result<(Vec<f64>, usize)> {
    dynamic_avar_rows(req, cancel).map(|(out, n_win, _)| (out, n_win))
}

/// [`dynamic_avar_cancellable`] and the [`Range`] of every (axis, m) row of the result, [axis][m]:
/// noted as each row is formed where the path allows it (the hop-1 surfaces, whose second read would
/// cost as much as the call), else from one parallel pass over the rows.
pub fn dynamic_avar_ranged_cancellable(
    req: &Request,
    cancel: &Cancel,
) -> Result<(Vec<f64>, usize, Vec<Range>)> {
    let (out, n_win, ranges) = dynamic_avar_rows(req, cancel)?;
    let ranges = match ranges {
        Some(r) => r,
        None => out.par_chunks(n_win.max(1)).map(Range::of).collect(),
    };
    cancel.check()?;
    Ok((out, n_win, ranges))
}

/// The values, the number of windows, and the rows' ranges when the path noted them.
type Rows = (Vec<f64>, usize, Option<Vec<Range>>);

fn dynamic_avar_rows(req: &Request, cancel: &Cancel) -> Result<Rows> {
    let n_win = validate_shape(req)?;
    let (n_axes, n_m) = (req.columns.len(), req.ms.len());
    let mut out = vec![0.0f64; n_axes * n_m * n_win];
    if (4 << 20..=1 << 30).contains(&(out.len() * 8)) {
        // Measured (hop-1 DAVAR, one worker): 55 MB of output 10 ms faster, 612 MB 0.58 s instead of
        // 0.78 s; but 6 GB 38 s instead of 30 s (the kernel compacting memory for 2 MiB pages), and
        // below a few MB the advice's syscall costs more than it saves.
        crate::oavar::advise_huge_pages(&mut out);
    }
    if req.method == Method::Fast && n_win == 1 {
        if let Some(r) = static_window(req, &mut out, cancel) {
            r?;
            return Ok((out, n_win, None));
        }
    }
    check_finite(req.columns)?;
    let mut ranges = None;
    match req.method {
        Method::Fast => {
            let mus = compensated_means(req.columns);
            // samples any window reads
            let n_used = ((n_win - 1) * req.hop + req.window).min(req.columns[0].len());
            let path = row_path(req, n_used, n_axes, n_win);
            ranges = part_rows(req, &mus, Part::whole(n_win), path, &mut out, cancel);
        }
        Method::Naive => {
            naive_rows(req, n_win, &mut out, cancel, |yw, angle, col| {
                naive_window(yw, req.ms, req.estimator, angle, col)
            })?;
        }
    }
    // A row that stopped early left garbage: never return it.
    cancel.check()?;
    Ok((out, n_win, ranges))
}

/// The windows `first_window ..` of a record of `n_windows_total` windows, from a part of it: what
/// [`dynamic_avar`] of the whole record gives those windows — bit for bit for a part that starts on
/// the record's [`part_grid`], to rounding (a few ε) for one that starts inside a phase segment.
///
/// `req.columns` hold the record's samples from `first_window · hop` on (at least one window's
/// worth; the part's windows are those that fit, up to the record's last); `mus` is the record's
/// centring value per axis, its [`compensated_mean`] (build it part by part with
/// [`compensated_sum_from`]; a record of one window is centred from the window itself, as the
/// whole-record call does, and `mus` is only checked). The path is the record's: [`dynamic_avar`] takes the phase path for the
/// overlapping estimator when the samples its windows read, times the axes, are at most 2^26 or its
/// window is at most 2^21 samples (see `takes_phase_path`); longer windows on a long record take
/// chunked phases at hops ≥ 64 ([`RowPath::Chunked`], `crate::chunked`); the rest streams (the classic
/// estimator, longer windows at hops below 64, rows of m > `PHASE_M_MAX` at hops below 64).
///
/// * Chunked phases: the record's terms in chunks of `crate::chunked::chunk_len` (a multiple of the
///   hop), each chunk's phase from its own first term: a part that starts on that grid has the
///   record's chunks: **bit for bit**; one that starts inside a chunk, to a few ε (as the phase path).
///
/// * Streaming: the part centres on `mus`, cuts the terms and block sums at the record's boundaries
///   (multiples of m, of the hop, of the window sums' segments) and sizes the edge segments as the
///   record does — the same additions in the same order: **bit for bit**.
/// * Phase path: the record's phase is a double-word running sum of y − μ from the first sample of
///   each phase segment (runs of `segment_windows` windows, see [`part_rows`]); the part cuts its
///   windows at the same segment starts, so a part that starts on a segment start has the record's
///   segments, phases and block sums: **bit for bit**. A part that starts inside a segment builds
///   its first segment's phase from its own start, so each term there is the same quantity formed
///   from differently rounded phase values — equal to a few ε of the term's own block sums
///   (measured ≲ 1e-14 relative).
/// * Naive: each window from its own samples anyway: bit for bit.
///
/// Returns ([axis][m][window], windows).
pub fn dynamic_avar_part_cancellable(
    req: &Request,
    mus: &[f64],
    first_window: usize,
    n_windows_total: usize,
    cancel: &Cancel,
) -> Result<(Vec<f64>, usize)> {
    // the finite check: in the static paths' pass, or below (the naive path makes its own)
    let n_part = validate_shape(req)?;
    let n_axes = req.columns.len();
    if mus.len() != n_axes || mus.iter().any(|v| !v.is_finite()) {
        return Err(CoreError::InvalidParameter(format!(
            "the record's means must be {n_axes} finite numbers (one per axis), got {mus:?}"
        )));
    }
    if first_window >= n_windows_total {
        return Err(CoreError::InvalidParameter(format!(
            "first window {first_window} is not a window of a record of {n_windows_total} windows"
        )));
    }
    let n_win = n_part.min(n_windows_total - first_window);
    let part = Part {
        first: first_window,
        total: n_windows_total,
    };
    let mut out = vec![0.0f64; n_axes * req.ms.len() * n_win];
    if req.method == Method::Naive {
        let (all, n) = dynamic_avar_cancellable(req, cancel)?;
        for (row, dst) in out.chunks_mut(n_win).enumerate() {
            dst.copy_from_slice(&all[row * n..row * n + n_win]);
        }
        return Ok((out, n_win));
    }
    if n_windows_total == 1 {
        // The record's one window: the static estimator's paths, centred as the whole-record call
        // centres it (from the window itself; `mus` is not needed).
        if let Some(r) = static_window(req, &mut out, cancel) {
            r?;
            return Ok((out, n_win));
        }
    }
    check_finite(req.columns)?;
    // the samples the record's windows read
    let n_used_record = (n_windows_total - 1) * req.hop + req.window;
    let path = row_path(req, n_used_record, n_axes, n_windows_total);
    part_rows(req, mus, part, path, &mut out, cancel);
    cancel.check()?;
    Ok((out, n_win))
}

/// Static Allan variance of each whole record at every m: [axis][m].
pub fn static_avar(columns: &[&[f64]], ms: &[usize], estimator: Estimator) -> Result<Vec<f64>> {
    let n = columns.first().map_or(0, |c| c.len());
    let req = Request {
        columns,
        window: n,
        hop: 1,
        ms,
        estimator,
        method: Method::Fast,
    };
    Ok(dynamic_avar(&req)?.0)
}

/// Runs `f` in a rayon pool of `workers` threads (0: rayon's default, i.e. RAYON_NUM_THREADS or
/// the number of cores).
pub fn run_in_pool<R: Send>(workers: usize, f: impl FnOnce() -> R + Send) -> Result<R> {
    Ok(build_pool(workers)?.install(f))
}

/// A rayon pool of `workers` threads (0: rayon's default).
pub(crate) fn build_pool(workers: usize) -> Result<rayon::ThreadPool> {
    rayon::ThreadPoolBuilder::new()
        .num_threads(workers)
        .build()
        .map_err(|e| {
            CoreError::InvalidParameter(format!("cannot start {workers} worker threads: {e}"))
        })
}

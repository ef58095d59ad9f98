//! The rest of the deviation family (NIST SP 1065, W. J. Riley, *Handbook of Frequency Stability
//! Analysis*, 2008, §5.2): modified Allan, Hadamard (classic and overlapping), total, modified total,
//! time total and Hadamard total variances; MTIE and TIE rms; gap-aware (NaN-skipping) OAVAR, MVAR
//! and OHVAR; and a dynamic (sliding-window) overlapping Hadamard variance.
//!
//! Conventions (as in `allan.rs`): `y` holds M rate (fractional-frequency) samples at interval τ0;
//! the phase (angle) record has N = M + 1 points x_k = τ0·Σ_{i<k} y_i; τ = m·τ0. Every variance below
//! is returned for τ0 = 1 in the rate's own units (it does not depend on τ0, except TTOTVAR, which
//! takes τ0). Phase differences are written as block sums of the rate, B(k) = Σ_{i=k}^{k+m−1}
//! (y_i − ȳ), so x_{k+m} − x_k = τ0·B(k) with no global phase and no subtraction of running sums:
//!
//!   x_{k+2m} − 2x_{k+m} + x_k            = τ0·(B(k+m) − B(k))                 (second difference)
//!   x_{k+3m} − 3x_{k+2m} + 3x_{k+m} − x_k = τ0·(B(k+2m) − 2B(k+m) + B(k))     (third difference)
//!
//! B is formed by the Van Herk / Gil-Werman split (`allan::sliding_sums`): each B(k) is a sum of the
//! samples of its own range only, so its rounding is local whatever the rest of the record holds.
//! MVAR's inner sum over m second differences is a second sliding m-sum of the same kind — O(M) per τ.
//! Sums of squares (non-negative) are accumulated in short runs with four accumulators and the runs
//! combined by Neumaier's compensated sum.
//!
//! MTOTVAR and HTOTVAR detrend and reflect every 3m-point subsequence separately (SP 1065 §5.2.12,
//! §5.2.14); they cost O(m) per subsequence, O((N − 3m)·m) per τ, like Stable32 and allantools. The
//! subsequences are processed in fixed chunks whose partial sums are combined in order, so the
//! results are bit-identical for any number of worker threads (as everywhere in the core: every
//! (axis, τ) value is one deterministic computation).

mod sliding;
mod tie;
mod total;

pub use sliding::{dynamic_ohvar, gap_dynamic};
pub use tie::{mtie, tie_gaps, tie_rms};
use total::{htotvar_gap, htotvar_value, mtotvar_gap, mtotvar_value, totvar_sum, totvar_value};

use crate::allan::{check_shape, compensated_mean, sliding_sums, sum4, Compensated};
use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
use rayon::prelude::*;

/// Which deviation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// Overlapping Allan variance (only for the gap-aware path; the fast one lives in `allan.rs`).
    Oavar,
    /// Modified Allan variance, SP 1065 eq. (14).
    Mvar,
    /// Classic (non-overlapping) Hadamard variance, SP 1065 eq. (17)/(18).
    Hvar,
    /// Overlapping Hadamard variance, SP 1065 eq. (20).
    Ohvar,
    /// Total variance, SP 1065 eq. (25).
    Totvar,
    /// Modified total variance, SP 1065 eq. (27).
    Mtotvar,
    /// Hadamard total variance, SP 1065 eq. (30); m = 1 gives OHVAR (Riley's rule, as Stable32).
    Htotvar,
}

impl Kind {
    fn name(self) -> &'static str {
        match self {
            Kind::Oavar => "OAVAR",
            Kind::Mvar => "MVAR",
            Kind::Hvar => "HVAR",
            Kind::Ohvar => "OHVAR",
            Kind::Totvar => "TOTVAR",
            Kind::Mtotvar => "MTOTVAR",
            Kind::Htotvar => "HTOTVAR",
        }
    }
}

/// Largest averaging factor `kind` accepts for a record of `n_rate` rate samples (0: none).
///
/// OAVAR: 2m ≤ M; MVAR and MTOTVAR: 3m ≤ N = M + 1; HVAR, OHVAR and HTOTVAR: 3m ≤ M;
/// TOTVAR: m ≤ M = N − 1 (the reflected record of SP 1065 eq. 25 reaches that far; allantools'
/// "all" grid goes there too).
pub fn max_m(kind: Kind, n_rate: usize) -> usize {
    match kind {
        Kind::Oavar => n_rate / 2,
        Kind::Mvar | Kind::Mtotvar => (n_rate + 1) / 3,
        Kind::Hvar | Kind::Ohvar | Kind::Htotvar => n_rate / 3,
        Kind::Totvar => n_rate,
    }
}

/// Number of terms averaged at factor m, for a gap-free record of `n_rate` rate samples (N = M + 1).
///
/// OAVAR N − 2m; MVAR N − 3m + 1; HVAR ⌊M/m⌋ − 2; OHVAR N − 3m; TOTVAR N − 2; MTOTVAR N − 3m + 1
/// (subsequences); HTOTVAR M − 3m + 1 (subsequences; N − 3 at m = 1, where it is OHVAR).
/// These are Stable32's "#" column.
pub fn n_terms(kind: Kind, n_rate: usize, m: usize) -> usize {
    let (nm, n) = (n_rate, n_rate + 1);
    match kind {
        Kind::Oavar => n.saturating_sub(2 * m),
        Kind::Mvar | Kind::Mtotvar => (n + 1).saturating_sub(3 * m),
        Kind::Hvar => (nm / m.max(1)).saturating_sub(2),
        Kind::Ohvar => n.saturating_sub(3 * m),
        Kind::Totvar => n.saturating_sub(2),
        Kind::Htotvar if m == 1 => n.saturating_sub(3),
        Kind::Htotvar => (nm + 1).saturating_sub(3 * m),
    }
}

fn check_ms(kind: Kind, n_rate: usize, ms: &[usize], what: &str) -> Result<()> {
    if ms.is_empty() {
        return Err(CoreError::InvalidParameter(
            "no averaging factors given".into(),
        ));
    }
    let hi = max_m(kind, n_rate);
    if let Some(&m) = ms.iter().find(|&&m| m == 0 || m > hi) {
        return Err(CoreError::InvalidParameter(format!(
            "{} averaging factor m = {m} is outside 1..={hi} allowed for a {what} of {n_rate} \
             rate samples",
            kind.name()
        )));
    }
    Ok(())
}

/// ±inf anywhere, or NaN when `allow_nan` is false, as an error naming it.
fn check_values(cols: &[&[f64]], allow_nan: bool) -> Result<()> {
    for (a, c) in cols.iter().enumerate() {
        if let Some(i) = c
            .iter()
            .position(|v| v.is_infinite() || (!allow_nan && v.is_nan()))
        {
            return Err(CoreError::NonFinite {
                axis: a,
                index: i,
                value: c[i],
            });
        }
    }
    Ok(())
}

const RUN: usize = 512;

/// Σ v² in runs of `RUN` (four accumulators each), runs combined with compensation.
fn sum_sq(v: &[f64]) -> f64 {
    let mut acc = Compensated::default();
    let mut buf = [0.0f64; RUN];
    for chunk in v.chunks(RUN) {
        for (b, x) in buf.iter_mut().zip(chunk) {
            *b = x * x;
        }
        acc.add(sum4(&buf[..chunk.len()]));
    }
    acc.value()
}

/// The rate minus its mean, NaN (gaps) replaced by 0 so that sums over gap-free ranges are exact
/// and sums touching a gap stay finite (those terms are discarded by the caller).
fn centred(y: &[f64]) -> Vec<f64> {
    let finite: Vec<f64> = y.iter().copied().filter(|v| !v.is_nan()).collect();
    let mu = compensated_mean(&finite);
    y.iter()
        .map(|&v| if v.is_nan() { 0.0 } else { v - mu })
        .collect()
}

/// Prefix count of the NaN samples (gaps) of `column`: cnt[0] = 0, cnt[k + 1] = cnt[k] + (y_k is NaN),
/// so a span [a, a + s) holds no gap iff cnt[a + s] == cnt[a]. The count is kept modulo 2³² (4 bytes a
/// sample): a count that wrapped still differs across a span holding a NaN unless that span holds a
/// multiple of 2³² of them, which a span of fewer than 2³² samples cannot — [`check_gap_span`] refuses
/// longer spans, so the test is exact.
fn nan_prefix_counts(column: &[f64]) -> Vec<u32> {
    nan_prefix_counts_from(column, 0)
}

/// [`nan_prefix_counts`] starting at `start` instead of 0 (the tests' way to reach the wrap-around).
fn nan_prefix_counts_from(column: &[f64], start: u32) -> Vec<u32> {
    let mut cnt = Vec::with_capacity(column.len() + 1);
    cnt.push(start);
    let mut k = start;
    for v in column {
        k = k.wrapping_add(v.is_nan() as u32);
        cnt.push(k);
    }
    cnt
}

/// The longest span a gap-aware estimate tests with [`nan_prefix_counts`] (samples of a `what`), as an
/// error when it reaches 2³² samples and the 32-bit count could no longer tell a gap from none.
fn check_gap_span(longest: usize, what: &str) -> Result<()> {
    if longest as u64 > u32::MAX as u64 {
        return Err(CoreError::InvalidInput(format!(
            "gap-aware estimation takes a {what} of at most {} samples (its gap count is 32-bit), \
             got {longest}",
            u32::MAX
        )));
    }
    Ok(())
}

/// Terms per chunk at least; a chunk also spans ≥ 4m terms so the O(m) edge work stays ≤ ¼ of it.
/// Memory per (axis, m) task is O(chunk + m), not O(M): a 10⁸-sample record stays cheap.
const TERM_CHUNK: usize = 1 << 16;

/// Span (rate samples per term) and scale of the overlapping estimators:
///
/// OAVAR  t_k = B(k+m) − B(k),                       span 2m,     scale 1/(2m²)
/// MVAR   t_j = Σ_{i=j}^{j+m−1} (B(i+m) − B(i)),      span 3m − 1, scale 1/(2m⁴)
/// OHVAR  t_k = B(k+2m) − 2B(k+m) + B(k),            span 3m,     scale 1/(6m²)
///
/// Term k uses f[k .. k + span]; the estimate is Σ t_k² · scale / count.
fn span_scale(kind: Kind, m: usize) -> (usize, f64) {
    let mf = m as f64;
    match kind {
        Kind::Oavar => (2 * m, 1.0 / (2.0 * mf * mf)),
        Kind::Mvar => (3 * m - 1, 1.0 / (2.0 * mf * mf * mf * mf)),
        Kind::Ohvar => (3 * m, 1.0 / (6.0 * mf * mf)),
        _ => unreachable!("span_scale called for {kind:?}"),
    }
}

/// Scratch of one (axis, m) task of the overlapping estimators.
#[derive(Default)]
struct TermBuf {
    b: Vec<f64>,
    d: Vec<f64>,
    t: Vec<f64>,
}

/// Calls `g(k0, terms)` for consecutive chunks of the terms t_k, k = 0 … count − 1 (count =
/// f.len() + 1 − span). Each chunk's block sums are formed from f over the chunk's own range only
/// (Van Herk / Gil-Werman via `sliding_sums`), so rounding is local and no sum runs along the record.
fn for_each_term_chunk(
    kind: Kind,
    f: &[f64],
    m: usize,
    buf: &mut TermBuf,
    mut g: impl FnMut(usize, &[f64]),
) {
    let (span, _) = span_scale(kind, m);
    let count = f.len() + 1 - span;
    let chunk = TERM_CHUNK.max(4 * m);
    let mut k0 = 0;
    while k0 < count {
        let c = chunk.min(count - k0);
        let TermBuf { b, d, t } = &mut *buf;
        let nb = c + span - m; // B(k0) … B(k0 + c − 1 + span − m)
        b.clear();
        b.resize(nb, 0.0);
        sliding_sums(&f[k0..k0 + nb + m - 1], m, b);
        t.clear();
        match kind {
            Kind::Oavar => t.extend(b[m..m + c].iter().zip(&b[..c]).map(|(p, q)| p - q)),
            Kind::Ohvar => t.extend((0..c).map(|k| (b[k + 2 * m] - b[k + m]) - (b[k + m] - b[k]))),
            Kind::Mvar => {
                // d(i) = B(i+m) − B(i) for i < c + m − 1, then t_j = Σ_{i=j}^{j+m−1} d(i).
                d.clear();
                d.extend(b[m..].iter().zip(b.iter()).map(|(p, q)| p - q));
                t.resize(c, 0.0);
                sliding_sums(&d[..c + m - 1], m, t);
            }
            _ => unreachable!(),
        }
        g(k0, t);
        k0 += c;
    }
}

/// MVAR (SP 1065 eq. 14):
///   Mod σ²(τ) = 1/(2 m² τ² (N−3m+1)) Σ_{j=1}^{N−3m+1} [ Σ_{i=j}^{j+m−1} (x_{i+2m} − 2x_{i+m} + x_i) ]².
/// OHVAR (SP 1065 eq. 20):
///   Hσ²(τ) = 1/(6 τ² (N−3m)) Σ_{i=1}^{N−3m} (x_{i+3m} − 3x_{i+2m} + 3x_{i+m} − x_i)².
/// OAVAR (SP 1065 eq. 11), for the gap-aware path.
fn overlapping_value(kind: Kind, f: &[f64], m: usize) -> f64 {
    let (span, scale) = span_scale(kind, m);
    let mut acc = Compensated::default();
    for_each_term_chunk(kind, f, m, &mut TermBuf::default(), |_, t| {
        acc.add(sum_sq(t))
    });
    acc.value() * scale / (f.len() + 1 - span) as f64
}

/// HVAR (SP 1065 eq. 17, frequency form): with ȳ_j the non-overlapping m-sample averages, K = ⌊M/m⌋,
///   Hσ²(τ) = 1/(6 (K−2)) Σ_{j=1}^{K−2} (ȳ_{j+2} − 2ȳ_{j+1} + ȳ_j)²,
/// equal to eq. (18) on phase with stride m (the terms of allantools' `hdev` and Stable32's HDEV).
fn hvar_value(f: &[f64], m: usize) -> f64 {
    let k = f.len() / m;
    let c: Vec<f64> = (0..k).map(|j| f[j * m..(j + 1) * m].iter().sum()).collect();
    let h: Vec<f64> = (0..k - 2)
        .map(|j| (c[j + 2] - c[j + 1]) - (c[j + 1] - c[j]))
        .collect();
    let mf = m as f64;
    sum_sq(&h) / (6.0 * mf * mf * h.len() as f64)
}

fn value(kind: Kind, f: &[f64], m: usize, cancel: &Cancel) -> f64 {
    if cancel.is_cancelled() {
        return 0.0;
    }
    match kind {
        Kind::Oavar | Kind::Mvar | Kind::Ohvar => overlapping_value(kind, f, m),
        Kind::Hvar => hvar_value(f, m),
        Kind::Totvar => totvar_value(f, m),
        Kind::Mtotvar => mtotvar_value(f, m, cancel),
        Kind::Htotvar => htotvar_value(f, m, cancel),
    }
}

/// `kind` of each whole rate record at every m, laid out [axis][m], in the calling rayon pool.
/// Rejects NaN/±inf (use [`gap_deviation`] for NaN-marked gaps).
pub fn static_deviation(columns: &[&[f64]], ms: &[usize], kind: Kind) -> Result<Vec<f64>> {
    static_deviation_cancellable(columns, ms, kind, &Cancel::new())
}

/// [`static_deviation`], stopping early (with [`CoreError::Cancelled`]) once `cancel` is set; the
/// flag is looked at per (axis, m) row and per chunk of the total variances' subsequences.
pub fn static_deviation_cancellable(
    columns: &[&[f64]],
    ms: &[usize],
    kind: Kind,
    cancel: &Cancel,
) -> Result<Vec<f64>> {
    let n = check_shape(columns)?;
    check_ms(kind, n, ms, "record")?;
    check_values(columns, false)?;
    let centred: Vec<Vec<f64>> = columns.par_iter().map(|c| centred(c)).collect();
    let n_m = ms.len();
    let out: Vec<f64> = (0..columns.len() * n_m)
        .into_par_iter()
        .map(|row| value(kind, &centred[row / n_m], ms[row % n_m], cancel))
        .collect();
    cancel.check()?;
    Ok(out)
}

/// TTOTVAR (SP 1065 eq. 28, corrected: τ²/3, not τ³): Ttot var(τ) = (τ²/3)·Mod Totvar(τ), τ = m·τ0,
/// in the rate's units × time² (τ0 in the unit of time wanted). [axis][m].
pub fn static_ttotvar(columns: &[&[f64]], ms: &[usize], tau0: f64) -> Result<Vec<f64>> {
    static_ttotvar_cancellable(columns, ms, tau0, &Cancel::new())
}

/// [`static_ttotvar`] with a cancel flag, as [`static_deviation_cancellable`].
pub fn static_ttotvar_cancellable(
    columns: &[&[f64]],
    ms: &[usize],
    tau0: f64,
    cancel: &Cancel,
) -> Result<Vec<f64>> {
    if !(tau0.is_finite() && tau0 > 0.0) {
        return Err(CoreError::InvalidParameter(format!(
            "tau0 ({tau0}) must be a finite positive sampling interval"
        )));
    }
    let v = static_deviation_cancellable(columns, ms, Kind::Mtotvar, cancel)?;
    let n_m = ms.len();
    Ok(v.iter()
        .enumerate()
        .map(|(i, &s)| {
            let tau = ms[i % n_m] as f64 * tau0;
            tau * tau / 3.0 * s
        })
        .collect())
}

/// Gap-aware OAVAR, MVAR, OHVAR, TOTVAR, MTOTVAR and HTOTVAR: NaN samples mark gaps; each estimate
/// averages only the terms whose span holds no NaN (a term of the overlapping estimators: see
/// `span_scale`; of TOTVAR: see `totvar_sum`; of MTOTVAR/HTOTVAR: its 3m-point subsequence). Returns
/// (values [axis][m], term counts [axis][m]); a τ with no complete term gives NaN and count 0.
/// Without NaN it equals the plain estimator. ±inf is still an error.
///
/// `classic`: only the terms that start at a multiple of m — the non-overlapping estimators, classic
/// AVAR from the OAVAR terms and HVAR from the OHVAR terms (cluster k's term starts at sample k·m).
pub fn gap_deviation(
    columns: &[&[f64]],
    ms: &[usize],
    kind: Kind,
    classic: bool,
) -> Result<(Vec<f64>, Vec<u64>)> {
    gap_deviation_cancellable(columns, ms, kind, classic, &Cancel::new())
}

/// [`gap_deviation`] with a cancel flag, as [`static_deviation_cancellable`].
pub fn gap_deviation_cancellable(
    columns: &[&[f64]],
    ms: &[usize],
    kind: Kind,
    classic: bool,
    cancel: &Cancel,
) -> Result<(Vec<f64>, Vec<u64>)> {
    if kind == Kind::Hvar || (classic && !matches!(kind, Kind::Oavar | Kind::Ohvar)) {
        return Err(CoreError::InvalidParameter(format!(
            "gap-aware estimation is available for OAVAR, MVAR, OHVAR, TOTVAR, MTOTVAR and HTOTVAR (and \
             classic AVAR/HVAR), not {}{}",
            if classic { "classic " } else { "" },
            kind.name()
        )));
    }
    let n = check_shape(columns)?;
    check_ms(kind, n, ms, "record")?;
    check_values(columns, true)?;
    check_gap_span(n, "record")?; // a term's span is at most the record
    let prepared: Vec<(Vec<f64>, Vec<u32>)> = columns
        .par_iter()
        .map(|c| (centred(c), nan_prefix_counts(c)))
        .collect();
    let n_m = ms.len();
    let res: Vec<(f64, u64)> = (0..columns.len() * n_m)
        .into_par_iter()
        .map(|row| {
            let (f, cnt) = &prepared[row / n_m];
            let m = ms[row % n_m];
            if cancel.is_cancelled() {
                return (0.0, 0);
            }
            match kind {
                Kind::Totvar => {
                    let (s, kept) = totvar_sum(f, m, Some(cnt));
                    let mf = m as f64;
                    let v = s / (2.0 * mf * mf * kept as f64);
                    (if kept == 0 { f64::NAN } else { v }, kept as u64)
                }
                Kind::Mtotvar => mtotvar_gap(f, m, Some(cnt), cancel),
                Kind::Htotvar if m > 1 => htotvar_gap(f, m, Some(cnt), cancel),
                Kind::Htotvar => overlapping_gap(Kind::Ohvar, f, cnt, m, false),
                _ => overlapping_gap(kind, f, cnt, m, classic),
            }
        })
        .collect();
    cancel.check()?;
    Ok(res.into_iter().unzip())
}

/// One gap-aware overlapping (or, `classic`, non-overlapping) estimate and its count of terms.
fn overlapping_gap(kind: Kind, f: &[f64], cnt: &[u32], m: usize, classic: bool) -> (f64, u64) {
    let (span, scale) = span_scale(kind, m);
    let (mut acc, mut kept) = (Compensated::default(), 0usize);
    let mut keep = Vec::new();
    for_each_term_chunk(kind, f, m, &mut TermBuf::default(), |k0, t| {
        keep.clear();
        keep.extend(
            t.iter()
                .enumerate()
                .filter(|(i, _)| {
                    cnt[k0 + i + span] == cnt[k0 + i] && (!classic || (k0 + i) % m == 0)
                })
                .map(|(_, v)| *v),
        );
        kept += keep.len();
        acc.add(sum_sq(&keep));
    });
    if kept == 0 {
        (f64::NAN, 0)
    } else {
        (acc.value() * scale / kept as f64, kept as u64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The span test stays exact where the 32-bit count wraps around (a record with 2³² NaN before
    /// this stretch would reach it; starting the count just below 2³² reaches it cheaply).
    #[test]
    fn nan_prefix_counts_wrap_around() {
        let y = [1.0, f64::NAN, 2.0, f64::NAN, f64::NAN, 3.0, 4.0];
        let plain = nan_prefix_counts(&y);
        assert_eq!(plain, vec![0, 0, 1, 1, 2, 3, 3, 3]);
        for start in [u32::MAX - 2, u32::MAX - 1, u32::MAX] {
            let cnt = nan_prefix_counts_from(&y, start);
            assert!(cnt.iter().any(|&c| c < start), "the count must wrap");
            for a in 0..=y.len() {
                for b in a..=y.len() {
                    let clean = y[a..b].iter().all(|v| !v.is_nan());
                    assert_eq!(cnt[b] == cnt[a], clean, "span [{a}, {b}) from {start}");
                }
            }
        }
    }

    #[test]
    #[cfg(target_pointer_width = "64")]
    fn gap_span_limit() {
        assert!(check_gap_span(u32::MAX as usize, "record").is_ok());
        let err = check_gap_span(u32::MAX as usize + 1, "window").unwrap_err();
        assert_eq!(
            err.to_string(),
            "gap-aware estimation takes a window of at most 4294967295 samples (its gap count is \
             32-bit), got 4294967296"
        );
    }
}

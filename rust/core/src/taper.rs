//! Hann-weighted overlapping Allan variance of sliding windows (paper 002; docs/FORMULAS.md §10).
//!
//! A window of W rate samples holds M = W − 2m + 1 squared second differences at lag m,
//! a_k = ½(ȳ_{k+m} − ȳ_k)² (ȳ the m-sample block means) — the overlapping Allan variance's terms.
//! The Hann estimate of the window starting at term s weights them by
//!
//!   w_i = ½ − ½·cos(θ(i + 1)) = sin²(θ(i + 1)/2),   θ = 2π/(M + 1),   i = 0 … M − 1,
//!
//!   σ²_H = Σ_i w_i·a_{s+i} / Σw,   Σw = (M + 1)/2.
//!
//! # O(1) per output
//! With k = s + i, cos(θ(i + 1)) = Re(e^{iθ(1−s)}·e^{iθk}), so
//!
//!   Σ_i w_i a_{s+i} = ½·S0(s) − ½·Re(e^{iθ(1−s)}·S1(s)),
//!   S0(s) = Σ_{k=s}^{s+M−1} a_k,   S1(s) = Σ_{k=s}^{s+M−1} e^{iθk}·a_k.
//!
//! The phases e^{iθk} come from a table indexed by k mod (M + 1): no rotation is accumulated.
//!
//! # Drift-free sums
//! S0 and S1 are window sums over aligned blocks of exactly M terms (Van Herk / Gil-Werman, as in
//! allan.rs): a window starting at offset r of block b is the suffix sum of block b from r plus the
//! prefix sum of block b + 1 over its first r terms. Every term of both partial sums lies inside the
//! window, so the rounding error of S0 and |S1| is bounded by ≈ M·u·S0 with S0 the window's own sum
//! — whatever the rest of the record holds (no running difference over the record, no loss at a
//! 10⁶ noise contrast). The remaining cancellation is in ½S0 − ½Re(…): the result R ≥ w_min·S0, so
//! a window whose terms sit at its very edges (R ≪ S0) could lose digits; such a window
//! (R < [`fallback_ratio`]·S0) is recomputed directly, Σ w_i a_i over non-negative products.
//!
//! One window (the static estimator, window = record) and short windows (M ≤ [`DIRECT_TERMS`]) are
//! computed directly. Each (axis, m) row is one sequential routine: results are bit-identical for
//! any number of worker threads.

use crate::allan::{
    centred_angle, compensated_means, for_each_term_chunk, naive_rows, sum4, validate, Estimator,
    Method, Request,
};
use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
use rayon::prelude::*;
use std::f64::consts::PI;

/// Fewest terms per window the Hann weighting accepts (with fewer, the taper is a spike).
pub const MIN_TERMS: usize = 3;

/// Windows of at most this many terms are weighted directly (O(M) per window is cheaper here).
pub const DIRECT_TERMS: usize = 16;

/// Unit roundoff of f64.
const U: f64 = f64::EPSILON / 2.0;

/// Target relative error of a fast-path value before it is recomputed directly.
const TARGET: f64 = 5e-10;

/// Largest fallback ratio: past M ≈ 56 000 the worst-case bound M·u no longer certifies 5e-10 for
/// typical windows (R/S0 ≈ ½); there the statistical error growth (≈ √M·u) is what holds.
const MAX_RATIO: f64 = 0.05;

/// A fast-path value R with R < ratio·S0 is recomputed directly: the worst-case rounding error of
/// ½S0 − ½Re(…) is ≈ 4·M·u·S0, so R ≥ 4·M·u·S0/TARGET keeps the relative error ≤ TARGET.
pub fn fallback_ratio(terms: usize) -> f64 {
    (4.0 * terms as f64 * U / TARGET).min(MAX_RATIO)
}

/// The Hann weights w_i = sin²(π(i + 1)/(M + 1)), i = 0 … M − 1 (the sin² form keeps the small
/// edge weights accurate to a few ulps).
pub fn hann_weights(terms: usize) -> Vec<f64> {
    let phi = PI / (terms + 1) as f64;
    (1..=terms)
        .map(|j| {
            let s = (phi * j as f64).sin();
            s * s
        })
        .collect()
}

/// Σ w_i over a window of M terms, exactly (M + 1)/2.
pub fn weight_sum(terms: usize) -> f64 {
    (terms + 1) as f64 / 2.0
}

/// Terms per window at factor m, the smallest over `ms`, checked against [`MIN_TERMS`].
fn check_terms(window: usize, ms: &[usize]) -> Result<()> {
    if let Some(&m) = ms.iter().find(|&&m| window + 1 < 2 * m + MIN_TERMS) {
        let got = (window + 1).saturating_sub(2 * m);
        let m_max = (window + 1 - MIN_TERMS) / 2;
        return Err(CoreError::InvalidParameter(format!(
            "taper 'hann' needs at least {MIN_TERMS} terms per window, but a window of {window} \
             samples holds M = window + 1 − 2m = {got} at m = {m}: use m ≤ {m_max} or a longer window"
        )));
    }
    Ok(())
}

/// Validates a Hann request (as [`validate`], plus the overlapping estimator and M ≥ 3 at every
/// m); returns the number of windows.
pub fn validate_hann(req: &Request) -> Result<usize> {
    let n_win = validate(req)?;
    if req.estimator != Estimator::Overlapping {
        return Err(CoreError::InvalidParameter(
            "taper 'hann' applies to the overlapping Allan variance only".into(),
        ));
    }
    check_terms(req.window, req.ms)?;
    Ok(n_win)
}

/// Phase table e^{iθj}, j = 0 … M (cos, sin), θ = 2π/(M + 1).
fn phase_table(terms: usize, cos_t: &mut Vec<f64>, sin_t: &mut Vec<f64>) {
    let n = terms + 1;
    let theta = 2.0 * PI / n as f64;
    cos_t.clear();
    sin_t.clear();
    for j in 0..n {
        let (s, c) = (theta * j as f64).sin_cos();
        cos_t.push(c);
        sin_t.push(s);
    }
}

/// Σ w_i a_i for one window by the definition: products of non-negative numbers, no cancellation.
#[inline]
fn weighted_direct(a: &[f64], w: &[f64], prod: &mut Vec<f64>) -> f64 {
    prod.clear();
    prod.extend(a.iter().zip(w).map(|(x, v)| x * v));
    sum4(prod)
}

/// Hops from this up use sums over the stretches between window starts.
const SEGMENT_HOP: usize = 8;

/// (Σ a_i, Σ a_i·cos θk, Σ a_i·sin θk) over a run of terms whose first has index k0 (k = k0 + i),
/// with the phase table split at its wrap so every piece is a plain zip (four accumulators each).
fn dot3(a: &[f64], k0: usize, cos_t: &[f64], sin_t: &[f64]) -> [f64; 3] {
    let period = cos_t.len();
    let p0 = k0 % period;
    let first = a.len().min(period - p0);
    let mut out = [0.0f64; 3];
    for (piece, p) in [(&a[..first], p0), (&a[first..], 0)] {
        if piece.is_empty() {
            continue;
        }
        let (c, s) = (&cos_t[p..p + piece.len()], &sin_t[p..p + piece.len()]);
        let mut acc = [[0.0f64; 4]; 3];
        let (ac, cc, sc) = (piece.chunks_exact(4), c.chunks_exact(4), s.chunks_exact(4));
        let (ra, rc, rs) = (ac.remainder(), cc.remainder(), sc.remainder());
        for ((x, y), z) in ac.zip(cc).zip(sc) {
            for l in 0..4 {
                acc[0][l] += x[l];
                acc[1][l] += x[l] * y[l];
                acc[2][l] += x[l] * z[l];
            }
        }
        for ((x, y), z) in ra.iter().zip(rc).zip(rs) {
            acc[0][0] += x;
            acc[1][0] += x * y;
            acc[2][0] += x * z;
        }
        for (o, v) in out.iter_mut().zip(acc) {
            *o += (v[0] + v[1]) + (v[2] + v[3]);
        }
    }
    out
}

/// Reusable buffers of one worker.
#[derive(Default)]
struct HannScratch {
    terms: Vec<f64>,
    w: Vec<f64>,
    cos_t: Vec<f64>,
    sin_t: Vec<f64>,
    suf: Vec<[f64; 3]>,
    pre: Vec<[f64; 3]>,
    prod: Vec<f64>,
}

/// One window spanning the first `terms` terms: Σ w_i a_i streamed, the weights from a two-level
/// table (sin(φ(qB + r)) by angle addition, B ≈ √(M + 1)), so memory stays O(√M) for any record.
fn one_window(y: &[f64], mu: f64, m: usize, terms: usize, cancel: &Cancel) -> f64 {
    let phi = PI / (terms + 1) as f64;
    let b = ((terms + 1) as f64).sqrt().ceil() as usize;
    let lo: Vec<(f64, f64)> = (0..b).map(|r| (phi * r as f64).sin_cos()).collect();
    let hi: Vec<(f64, f64)> = (0..=terms / b)
        .map(|q| (phi * (q * b) as f64).sin_cos())
        .collect();
    let scale = 1.0 / (2.0 * (m as f64) * (m as f64));
    let (mut total, mut j) = (0.0f64, 1usize); // j = i + 1: the weight index of the next term
    let mut prod = Vec::new();
    for_each_term_chunk(y, mu, m, terms, scale, cancel, |chunk| {
        prod.clear();
        for &a in chunk {
            let (q, r) = (j / b, j % b);
            let (sq, cq) = hi[q];
            let (sr, cr) = lo[r];
            let s = sq * cr + cq * sr;
            prod.push(a * s * s);
            j += 1;
        }
        total += sum4(&prod);
    });
    total / weight_sum(terms)
}

/// Hann-weighted overlapping Allan variance of every window, for one m, written to `out`.
/// Once `cancel` is set, `out` holds garbage (the caller returns `Cancelled` instead).
#[allow(clippy::too_many_arguments)] // the row's geometry (y, mu, m, window, hop) is irreducible
fn hann_row(
    y: &[f64],
    mu: f64,
    m: usize,
    window: usize,
    hop: usize,
    out: &mut [f64],
    sc: &mut HannScratch,
    cancel: &Cancel,
) {
    let n_win = out.len();
    let mt = window + 1 - 2 * m; // M
    if n_win == 1 {
        out[0] = one_window(y, mu, m, mt, cancel);
        return;
    }
    let k_end = (n_win - 1) * hop + mt;
    let scale = 1.0 / (2.0 * (m as f64) * (m as f64));
    let sw = weight_sum(mt);
    let HannScratch {
        terms,
        w,
        cos_t,
        sin_t,
        suf,
        pre,
        prod,
    } = sc;
    // The weights serve only the direct paths (short windows, the rare fallback): made on demand.
    w.clear();
    terms.clear();
    if mt <= DIRECT_TERMS {
        *w = hann_weights(mt);
        for_each_term_chunk(y, mu, m, k_end, scale, cancel, |c| {
            terms.extend_from_slice(c)
        });
        if cancel.is_cancelled() {
            return;
        }
        for (j, o) in out.iter_mut().enumerate() {
            let s = j * hop;
            *o = weighted_direct(&terms[s..s + mt], w, prod) / sw;
        }
        return;
    }
    phase_table(mt, cos_t, sin_t);
    suf.clear();
    suf.resize(mt, [0.0; 3]);
    pre.clear();
    pre.resize(mt + 1, [0.0; 3]);
    let mut em = HannEmitter {
        mt,
        hop,
        ratio: fallback_ratio(mt),
        sw,
        cos_t,
        sin_t,
        suf,
        pre,
        w,
        prod,
        next: 0,
    };
    em.run(terms, (y, mu, m), (k_end, scale), cancel, out);
}

/// The windows of a [`hann_row`] of M = `mt` terms per window, emitted block by block.
struct HannEmitter<'s> {
    mt: usize,
    hop: usize,
    /// Below `ratio` × the window's plain sum, the window is recomputed directly.
    ratio: f64,
    /// The Hann weights' sum.
    sw: f64,
    cos_t: &'s [f64],
    sin_t: &'s [f64],
    suf: &'s mut [[f64; 3]],
    pre: &'s mut [[f64; 3]],
    w: &'s mut Vec<f64>,
    prod: &'s mut Vec<f64>,
    /// The next window to emit.
    next: usize,
}

impl HannEmitter<'_> {
    /// Every window of the row: the record's (y, mu, m) `k_end` terms (times `scale`) streamed through
    /// `terms`, each block's windows emitted once the next block is in.
    fn run(
        &mut self,
        terms: &mut Vec<f64>,
        (y, mu, m): (&[f64], f64, usize),
        (k_end, scale): (usize, f64),
        cancel: &Cancel,
        out: &mut [f64],
    ) {
        let mt = self.mt;
        let mut base = 0usize; // term index of terms[0]: always a multiple of M
        let mut received = 0usize;
        for_each_term_chunk(y, mu, m, k_end, scale, cancel, |chunk| {
            terms.extend_from_slice(chunk);
            received += chunk.len();
            while terms.len() >= 2 * mt {
                self.emit(terms, base, out);
                terms.drain(..mt);
                base += mt;
            }
        });
        if cancel.is_cancelled() {
            return;
        }
        debug_assert_eq!(received, k_end);
        while self.next < out.len() {
            self.emit(terms, base, out);
            let cut = mt.min(terms.len());
            terms.drain(..cut);
            base += mt;
        }
    }

    /// Emits every window that starts in the block [base, base + M) (`terms[0]` is term `base`): needs
    /// terms up to base + 2M − 1 (or the end of the record).
    fn emit(&mut self, terms: &[f64], base: usize, out: &mut [f64]) {
        let (first, hop) = (self.next, self.hop);
        let mut last = first;
        while last < out.len() && last * hop < base + self.mt {
            last += 1;
        }
        if last == first {
            return;
        }
        let r_min = first * hop - base;
        let r_max = (last - 1) * hop - base;
        if hop < SEGMENT_HOP {
            self.dense_sums(terms, base, r_min, r_max);
        } else {
            self.sparse_sums(terms, base, r_min, r_max);
        }
        self.windows(terms, base, first..last, out);
        self.next = last;
    }

    /// Suffix sums of the block from r (terms [base + r, base + M)), r ≥ r_min, and prefix sums of the
    /// next block over its first r terms, r ≤ r_max: every r.
    fn dense_sums(&mut self, terms: &[f64], base: usize, r_min: usize, r_max: usize) {
        let (mt, cos_t, sin_t) = (self.mt, self.cos_t, self.sin_t);
        let period = mt + 1;
        let mut acc = [0.0f64; 3];
        let mut p = (base + mt - 1) % period;
        for r in (r_min..mt).rev() {
            let a = terms[r];
            acc[0] += a;
            acc[1] += a * cos_t[p];
            acc[2] += a * sin_t[p];
            self.suf[r] = acc;
            p = if p == 0 { period - 1 } else { p - 1 };
        }
        let mut acc = [0.0f64; 3];
        let mut p = (base + mt) % period;
        self.pre[0] = acc;
        for r in 0..r_max {
            let a = terms[mt + r];
            acc[0] += a;
            acc[1] += a * cos_t[p];
            acc[2] += a * sin_t[p];
            self.pre[r + 1] = acc;
            p += 1;
            if p == period {
                p = 0;
            }
        }
    }

    /// [`Self::dense_sums`] at the window starts only (sparse starts): sums over the stretches between
    /// consecutive starts (independent accumulators, vectorisable), then cumulated — still only terms
    /// inside each window.
    fn sparse_sums(&mut self, terms: &[f64], base: usize, r_min: usize, r_max: usize) {
        let (mt, hop, cos_t, sin_t) = (self.mt, self.hop, self.cos_t, self.sin_t);
        let seg = |i0: usize, i1: usize| dot3(&terms[i0..i1], base + i0, cos_t, sin_t);
        let mut acc = seg(r_max, mt);
        self.suf[r_max] = acc;
        let mut r = r_max;
        while r > r_min {
            let lo = r - hop;
            let v = seg(lo, r);
            for (x, y) in acc.iter_mut().zip(v) {
                *x += y;
            }
            self.suf[lo] = acc;
            r = lo;
        }
        let mut acc = seg(mt, mt + r_min);
        self.pre[r_min] = acc;
        let mut r = r_min;
        while r < r_max {
            let v = seg(mt + r, mt + r + hop);
            for (x, y) in acc.iter_mut().zip(v) {
                *x += y;
            }
            r += hop;
            self.pre[r] = acc;
        }
    }

    /// The windows `range` from the suffix and prefix sums of their two blocks.
    fn windows(
        &mut self,
        terms: &[f64],
        base: usize,
        range: std::ops::Range<usize>,
        out: &mut [f64],
    ) {
        let (mt, cos_t, sin_t) = (self.mt, self.cos_t, self.sin_t);
        let period = mt + 1;
        for (j, o) in out.iter_mut().enumerate().take(range.end).skip(range.start) {
            let s = j * self.hop;
            let r = s - base;
            let (sf, pr) = (self.suf[r], self.pre[r]);
            let s0 = sf[0] + pr[0];
            let (re, im) = (sf[1] + pr[1], sf[2] + pr[2]);
            // e^{iθ(1 − s)}: index (1 − s) mod (M + 1).
            let q = (period + 1 - s % period) % period;
            let v = 0.5 * s0 - 0.5 * (cos_t[q] * re - sin_t[q] * im);
            let v = if v < self.ratio * s0 {
                // Terms piled up at the window's edges: the difference lost digits; recompute.
                if self.w.is_empty() {
                    *self.w = hann_weights(mt);
                }
                weighted_direct(&terms[r..r + mt], self.w, self.prod)
            } else {
                v
            };
            *o = v / self.sw;
        }
    }
}

/// One window recomputed from scratch, all m: remove the window mean, integrate to angle, weight
/// the squared second differences (the definition; the reference for the fast path).
fn naive_window(yw: &[f64], ms: &[usize], angle: &mut Vec<f64>, out: &mut [f64]) {
    let n = yw.len();
    centred_angle(yw, angle);
    let xs = &angle[..];
    for (o, &m) in out.iter_mut().zip(ms) {
        let mt = n + 1 - 2 * m;
        let w = hann_weights(mt);
        let mut s = 0.0;
        for (k, wk) in w.iter().enumerate() {
            let d = xs[k + 2 * m] - 2.0 * xs[k + m] + xs[k];
            s += wk * d * d;
        }
        *o = s / (2.0 * (m * m) as f64 * weight_sum(mt));
    }
}

/// Hann-weighted overlapping Allan variance of every window at every m, for every axis:
/// (values laid out as [axis][m][window], number of windows).
pub fn dynamic_hann(req: &Request) -> Result<(Vec<f64>, usize)> {
    dynamic_hann_cancellable(req, &Cancel::new())
}

/// [`dynamic_hann`] that stops within one block of terms once `cancel` is set, and then returns
/// [`CoreError::Cancelled`].
pub fn dynamic_hann_cancellable(req: &Request, cancel: &Cancel) -> Result<(Vec<f64>, usize)> {
    let n_win = validate_hann(req)?;
    let (n_axes, n_m) = (req.columns.len(), req.ms.len());
    let mut out = vec![0.0f64; n_axes * n_m * n_win];
    match req.method {
        Method::Fast => {
            let mus = compensated_means(req.columns);
            out.par_chunks_mut(n_win).enumerate().for_each_init(
                HannScratch::default,
                |sc, (row, dst)| {
                    if cancel.is_cancelled() {
                        return;
                    }
                    let (a, t) = (row / n_m, row % n_m);
                    hann_row(
                        req.columns[a],
                        mus[a],
                        req.ms[t],
                        req.window,
                        req.hop,
                        dst,
                        sc,
                        cancel,
                    );
                },
            );
        }
        Method::Naive => {
            naive_rows(req, n_win, &mut out, cancel, |yw, angle, col| {
                naive_window(yw, req.ms, angle, col)
            })?;
        }
    }
    cancel.check()?;
    Ok((out, n_win))
}

/// Hann-weighted static overlapping Allan variance of each whole record at every m: [axis][m].
pub fn static_hann(columns: &[&[f64]], ms: &[usize]) -> Result<Vec<f64>> {
    let n = columns.first().map_or(0, |c| c.len());
    let req = Request {
        columns,
        window: n,
        hop: 1,
        ms,
        estimator: Estimator::Overlapping,
        method: Method::Fast,
    };
    Ok(dynamic_hann(&req)?.0)
}

#[cfg(test)]
mod tests;

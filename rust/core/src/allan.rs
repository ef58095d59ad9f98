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

use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
use crate::gather::{classic_window, GATHER_MAX};
use crate::oavar::overlapping_window;
use crate::range::Range;
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

/// Mean by Neumaier's compensated sum, so that a long record's mean is right to ~ε.
pub fn compensated_mean(y: &[f64]) -> f64 {
    if y.is_empty() {
        return 0.0;
    }
    let (s, c) = compensated_sum_from(y, (0.0, 0.0));
    (s + c) / y.len() as f64
}

/// Neumaier's compensated sum of `y` continued from the state (sum, compensation) = `state`: the
/// loop of [`compensated_mean`], so feeding a record's parts in order, each from the state the
/// previous one left, gives the state of the whole record bit for bit — and
/// `(s + c) / n` its [`compensated_mean`]. This is how a record held in pieces (a Dask array)
/// gets the centring value the whole-record call uses.
pub fn compensated_sum_from(y: &[f64], state: (f64, f64)) -> (f64, f64) {
    let (mut s, mut c) = state;
    for &v in y {
        let t = s + v;
        if s.abs() >= v.abs() {
            c += (s - t) + v;
        } else {
            c += (v - t) + s;
        }
        s = t;
    }
    (s, c)
}

/// Sum with four partial accumulators: shorter dependency chains and ~¼ the rounding growth.
#[inline]
pub(crate) fn sum4(v: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let chunks = v.chunks_exact(4);
    let rest = chunks.remainder();
    for c in chunks {
        acc[0] += c[0];
        acc[1] += c[1];
        acc[2] += c[2];
        acc[3] += c[3];
    }
    let mut tail = 0.0;
    for &x in rest {
        tail += x;
    }
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// Interleaved chains for the running sums below: a running sum is a chain of dependent additions,
/// latency-bound; independent chains over separate parts of the range overlap their latencies.
const CHAINS: usize = 4; // the hot loops below are unrolled for exactly four

/// Scratch and state for the terms of one m, reused across segments.
pub(crate) struct TermScratch {
    suf: Vec<f64>,
    pre: Vec<f64>,
    pub(crate) bprev: Vec<f64>,
}

/// Part boundaries for `CHAINS` chains over `len` items: parts of q items, the last takes the rest.
#[inline]
fn parts(len: usize) -> (usize, [usize; CHAINS + 1]) {
    let q = len / CHAINS;
    let mut b = [0usize; CHAINS + 1];
    for (p, v) in b.iter_mut().enumerate() {
        *v = (p * q).min(len);
    }
    b[CHAINS] = len;
    (q, b)
}

impl TermScratch {
    pub(crate) fn new(m: usize) -> Self {
        TermScratch {
            suf: vec![0.0; m],
            pre: vec![0.0; m],
            bprev: vec![0.0; m],
        }
    }

    /// Block sums B(k) = Σ_{i=k}^{k+m−1} (y_i − μ) for k = start + r, r < len, `start` a multiple of
    /// m (Van Herk / Gil-Werman: suffix sum of the segment [start, start+m) from k, plus prefix sum
    /// of the next segment up to k+m−1). With `terms = Some(scale)`, writes a(k−m) =
    /// scale·(B(k) − B(k−m))² over the suffix sums in `suf[..len]` and keeps B in `bprev`; with
    /// `None`, only fills `bprev`.
    ///
    /// Both running sums are split into `CHAINS` parts whose local sums run interleaved; the parts
    /// are joined in the same pass that forms B, by adding per-part constants (the suffix totals of
    /// the parts above and the prefix totals of the parts below). Every term of every sum lies inside
    /// B(k)'s own range [k, k+m): the rounding error is local, whatever the rest of the record holds.
    /// Requires start + len − 1 + m ≤ y.len().
    pub(crate) fn segment(
        &mut self,
        y: &[f64],
        mu: f64,
        m: usize,
        start: usize,
        len: usize,
        terms: Option<f64>,
    ) {
        debug_assert!(len >= 1 && len <= m && start + len - 1 + m <= y.len());
        let seg = &y[start..start + m];
        let next = &y[start + m..start + m + len - 1];
        let (q, bd) = parts(len);
        let chained = q >= 4;
        let suf = &mut self.suf[..len];
        let pre = &mut self.pre[..len];
        // Tail of the segment beyond len: belongs to every B(k) of this call.
        let mut tail = 0.0;
        for &v in seg[len..].iter().rev() {
            tail += v - mu;
        }
        let mut soff = [0.0f64; CHAINS];
        let mut poff = [0.0f64; CHAINS];
        if chained {
            // Local suffix sums per part, interleaved; the longest (last) part's extra items first.
            let mut s = [0.0f64; CHAINS];
            for i in (CHAINS * q..len).rev() {
                s[CHAINS - 1] += seg[i] - mu;
                suf[i] = s[CHAINS - 1];
            }
            // Hot loop: indices are in range by construction (p·q + i < CHAINS·q ≤ len ≤ m).
            assert!(CHAINS * q <= len && len <= seg.len());
            {
                let (mut s0, mut s1, mut s2, mut s3) = (s[0], s[1], s[2], s[3]);
                for i in (0..q).rev() {
                    // SAFETY: i + 3q < CHAINS·q ≤ len = suf.len() ≤ seg.len() (asserted above).
                    unsafe {
                        s0 += *seg.get_unchecked(i) - mu;
                        s1 += *seg.get_unchecked(i + q) - mu;
                        s2 += *seg.get_unchecked(i + 2 * q) - mu;
                        s3 += *seg.get_unchecked(i + 3 * q) - mu;
                        *suf.get_unchecked_mut(i) = s0;
                        *suf.get_unchecked_mut(i + q) = s1;
                        *suf.get_unchecked_mut(i + 2 * q) = s2;
                        *suf.get_unchecked_mut(i + 3 * q) = s3;
                    }
                }
                s = [s0, s1, s2, s3];
            }
            // Local prefix sums: pre[r] = Σ next[bd[p]..r] for r in part p; the running value after
            // the part's last item is the part's total.
            // next has len − 1 items: every part but the last is full; the last part's final item
            // (index len − 1) has no next sample, which the tail loop below handles.
            let mut t: [f64; CHAINS];
            assert!(CHAINS * q <= len && next.len() + 1 == len && pre.len() == len);
            let full_q = if CHAINS * q == len { q - 1 } else { q };
            {
                let (mut t0, mut t1, mut t2, mut t3) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
                for i in 0..full_q {
                    // SAFETY: i + 3q < CHAINS·q − 1 ≤ len − 1 = next.len() when CHAINS·q == len,
                    // else i + 3q < CHAINS·q ≤ len − 1; pre.len() == len (asserted above).
                    unsafe {
                        *pre.get_unchecked_mut(i) = t0;
                        *pre.get_unchecked_mut(i + q) = t1;
                        *pre.get_unchecked_mut(i + 2 * q) = t2;
                        *pre.get_unchecked_mut(i + 3 * q) = t3;
                        t0 += *next.get_unchecked(i) - mu;
                        t1 += *next.get_unchecked(i + q) - mu;
                        t2 += *next.get_unchecked(i + 2 * q) - mu;
                        t3 += *next.get_unchecked(i + 3 * q) - mu;
                    }
                }
                t = [t0, t1, t2, t3];
            }
            for i in full_q..q {
                for (p, tp) in t.iter_mut().enumerate() {
                    let idx = p * q + i;
                    pre[idx] = *tp;
                    if idx < next.len() {
                        *tp += next[idx] - mu;
                    }
                }
            }
            for idx in CHAINS * q..len {
                pre[idx] = t[CHAINS - 1];
                if idx < next.len() {
                    t[CHAINS - 1] += next[idx] - mu;
                }
            }
            let mut above = tail;
            for p in (0..CHAINS).rev() {
                soff[p] = above;
                above += s[p];
            }
            let mut below = 0.0;
            for p in 0..CHAINS {
                poff[p] = below;
                below += t[p];
            }
        } else {
            let mut sacc = tail;
            for i in (0..len).rev() {
                sacc += seg[i] - mu;
                suf[i] = sacc;
            }
            let mut pacc = 0.0;
            for r in 0..len {
                pre[r] = pacc;
                if r < next.len() {
                    pacc += next[r] - mu;
                }
            }
        }
        let bprev = &mut self.bprev[..len];
        match terms {
            Some(scale) => {
                // a(k) overwrites the suffix sums in place: one buffer less in cache for large m.
                for p in 0..CHAINS {
                    let (lo, hi) = if chained {
                        (bd[p], bd[p + 1])
                    } else if p == 0 {
                        (0, len)
                    } else {
                        break;
                    };
                    let c = soff[p] + poff[p];
                    let it = suf[lo..hi]
                        .iter_mut()
                        .zip(&pre[lo..hi])
                        .zip(bprev[lo..hi].iter_mut());
                    for ((s, pr), bp) in it {
                        let b = (*s + pr) + c;
                        let d = b - *bp;
                        *bp = b;
                        *s = d * d * scale;
                    }
                }
            }
            None => {
                for p in 0..CHAINS {
                    let (lo, hi) = if chained {
                        (bd[p], bd[p + 1])
                    } else if p == 0 {
                        (0, len)
                    } else {
                        break;
                    };
                    let c = soff[p] + poff[p];
                    for ((s, pr), bp) in suf[lo..hi]
                        .iter()
                        .zip(&pre[lo..hi])
                        .zip(bprev[lo..hi].iter_mut())
                    {
                        *bp = (s + pr) + c;
                    }
                }
            }
        }
    }
}

/// Calls `f` with consecutive chunks of a(k) = scale·d_m(k)² for k = 0, 1, …, k_end − 1 (in
/// order); `scale` folds the estimator's normalisation into the pass that forms the terms.
/// Stops early (the chunks seen so far are then incomplete) once `cancel` is set.
/// Requires 1 ≤ k_end ≤ y.len() + 1 − 2m.
pub(crate) fn for_each_term_chunk(
    y: &[f64],
    mu: f64,
    m: usize,
    k_end: usize,
    scale: f64,
    cancel: &Cancel,
    f: impl FnMut(&[f64]),
) {
    debug_assert!(k_end >= 1 && k_end + 2 * m <= y.len() + 1);
    for_each_term_chunk_at(y, 0, mu, m, (0, k_end), k_end, scale, cancel, f)
}

/// [`for_each_term_chunk`] of a whole record of which `y` holds a part: `y[i]` is the record's
/// sample `off + i`, the record's terms run to `k_end` (exclusive), and this call gives the terms
/// `k_lo ≤ k < k_hi` (`range`, in record indices) — the same values, in chunks with the same
/// boundaries (cut at `range`) as the whole-record call gives them.
///
/// The whole-record pass cuts the terms into chunks at multiples of `DIRECT_CHUNK` (m ≤ `DIRECT_M`)
/// or of m, and forms each block sum B(k) from a segment aligned to a multiple of m whose length is
/// set by `k_end`; both only shape the rounding. Here the segments keep the record's alignment and
/// lengths. A segment reaching outside `y` (the first one may start before `off`, the last ones may
/// need up to m samples past `y`) is read from a copy padded with `mu`: B(k) reads only
/// y[k .. k+m) (see [`TermScratch::segment`]), so the padding reaches no term of the range.
/// Requires off ≤ k_lo < k_hi ≤ k_end and k_hi + 2m − 1 ≤ off + y.len().
#[allow(clippy::too_many_arguments)] // the part's place in the record is irreducible
pub(crate) fn for_each_term_chunk_at(
    y: &[f64],
    off: usize,
    mu: f64,
    m: usize,
    range: (usize, usize),
    k_end: usize,
    scale: f64,
    cancel: &Cancel,
    mut f: impl FnMut(&[f64]),
) {
    let (k_lo, k_hi) = range;
    debug_assert!(off <= k_lo && k_lo < k_hi && k_hi <= k_end && k_hi + 2 * m <= off + y.len() + 1);
    if m <= DIRECT_M {
        // Short blocks: sum each B(k) directly over its own m samples (exactly local too), in
        // chunks of k so the per-call bookkeeping of the segment scheme is not paid per sample.
        let mut bbuf = vec![0.0; DIRECT_CHUNK + m];
        let mut a = vec![0.0; DIRECT_CHUNK];
        let mut k0 = k_lo;
        while k0 < k_hi {
            if cancel.is_cancelled() {
                return;
            }
            // chunks end at the record's multiples of DIRECT_CHUNK
            let c = ((k0 / DIRECT_CHUNK + 1) * DIRECT_CHUNK).min(k_hi) - k0;
            let b = &mut bbuf[..c + m];
            b.fill(0.0);
            let i0 = k0 - off;
            for j in 0..m {
                let src = &y[i0 + j..i0 + j + c + m];
                for (bt, v) in b.iter_mut().zip(src) {
                    *bt += v - mu;
                }
            }
            for (t, at) in a[..c].iter_mut().enumerate() {
                let d = b[t + m] - b[t];
                *at = d * d * scale;
            }
            f(&a[..c]);
            k0 += c;
        }
        return;
    }
    // The record's segment at p (a multiple of m) is formed with this many block sums.
    let seg_len = |p: usize| {
        if p == 0 {
            m.min(k_end)
        } else {
            m.min(k_end + m - p)
        }
    };
    let mut sc = TermScratch::new(m);
    let mut pad: Vec<f64> = Vec::new();
    // The segment at record index p with `len` block sums, read from y or from a padded copy.
    let mut segment = |sc: &mut TermScratch, p: usize, len: usize, terms: Option<f64>| {
        let need = m + len - 1; // samples the segment reads: [p, p + need)
        if p >= off && p + need <= off + y.len() {
            sc.segment(y, mu, m, p - off, len, terms);
        } else {
            pad.clear();
            pad.resize(need, mu);
            let (a, b) = (p.max(off), (p + need).min(off + y.len()));
            if a < b {
                pad[a - p..b - p].copy_from_slice(&y[a - off..b - off]);
            }
            sc.segment(&pad, mu, m, 0, len, terms);
        }
    };
    let mut start = k_lo / m * m;
    segment(&mut sc, start, seg_len(start), None);
    while start < k_hi {
        // One load per chunk of m > DIRECT_M terms: negligible next to forming them.
        if cancel.is_cancelled() {
            return;
        }
        let len = seg_len(start + m); // = min(m, k_end − start)
                                      // d_m(k) = B(k + m) − B(k): the next aligned segment against the one kept in bprev.
        segment(&mut sc, start + m, len, Some(scale));
        let (a, b) = (k_lo.max(start) - start, k_hi.min(start + len) - start);
        f(&sc.suf[a..b]);
        start += m;
    }
}

/// out[j] = Σ f[j..j+q] for j < out.len(), non-negative f (Van Herk / Gil-Werman, no subtraction):
/// the suffix sum of j's q-segment from j plus the prefix sum of the next segment up to j+q−1.
/// Written in place, no scratch. Requires f.len() ≥ out.len() + q − 1 and q ≥ 1.
pub(crate) fn sliding_sums(f: &[f64], q: usize, out: &mut [f64]) {
    let n_out = out.len();
    if q == 1 {
        out.copy_from_slice(&f[..n_out]);
        return;
    }
    // Each segment's running sum is a chain of dependent additions (latency-bound); `CHAINS`
    // segments are run interleaved so their latencies overlap. Every chain adds the same values in
    // the same order as one segment at a time: the results are bit-identical either way.
    // Suffix sums within each segment, for the indices that start a window. Full segments (whose
    // windows all start inside the output and read no tail) go CHAINS at a time.
    let full_suffix = if n_out >= q { n_out / q } else { 0 }; // segments [g·q, g·q + q) ⊂ [0, n_out)
    let mut g = 0;
    while g + CHAINS <= full_suffix {
        let b = [g * q, (g + 1) * q, (g + 2) * q, (g + 3) * q];
        let (mut s0, mut s1, mut s2, mut s3) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        assert!(b[3] + q <= n_out && n_out <= f.len());
        for i in (0..q).rev() {
            // SAFETY: b[p] + i < b[3] + q ≤ n_out = out.len() ≤ f.len() (asserted above).
            unsafe {
                s0 += *f.get_unchecked(b[0] + i);
                s1 += *f.get_unchecked(b[1] + i);
                s2 += *f.get_unchecked(b[2] + i);
                s3 += *f.get_unchecked(b[3] + i);
                *out.get_unchecked_mut(b[0] + i) = s0;
                *out.get_unchecked_mut(b[1] + i) = s1;
                *out.get_unchecked_mut(b[2] + i) = s2;
                *out.get_unchecked_mut(b[3] + i) = s3;
            }
        }
        g += CHAINS;
    }
    let mut s0 = g * q;
    while s0 < n_out {
        let end = (s0 + q).min(n_out + q - 1);
        let mut s: f64 = f[n_out.min(end)..end].iter().rev().sum();
        for j in (s0..end.min(n_out)).rev() {
            s += f[j];
            out[j] = s;
        }
        s0 += q;
    }
    // Prefix sums of the following segment complete every window that does not start a segment:
    // window j (j mod q ≠ 0) ends at i = j + q − 1 inside the next segment. Segment g (from g·q)
    // runs over [g·q, g·q + q − 1) when that lies below n_out + q − 1.
    let mut g = 1;
    while (g + CHAINS - 1) * q <= n_out {
        let b = [g * q, (g + 1) * q, (g + 2) * q, (g + 3) * q];
        let (mut p0, mut p1, mut p2, mut p3) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
        assert!(b[3] <= n_out && b[3] + q - 1 <= f.len() && b[0] >= q - 1);
        for i in 0..q - 1 {
            // SAFETY: b[p] + i < b[3] + q − 1 ≤ f.len(), and the output index b[p] + i + 1 − q
            // < b[3] + q − 1 + 1 − q ≤ n_out (asserted above).
            unsafe {
                p0 += *f.get_unchecked(b[0] + i);
                p1 += *f.get_unchecked(b[1] + i);
                p2 += *f.get_unchecked(b[2] + i);
                p3 += *f.get_unchecked(b[3] + i);
                *out.get_unchecked_mut(b[0] + i + 1 - q) += p0;
                *out.get_unchecked_mut(b[1] + i + 1 - q) += p1;
                *out.get_unchecked_mut(b[2] + i + 1 - q) += p2;
                *out.get_unchecked_mut(b[3] + i + 1 - q) += p3;
            }
        }
        g += CHAINS;
    }
    let mut s0 = g * q;
    while s0 < n_out + q - 1 {
        let end = (s0 + q - 1).min(n_out + q - 1); // the segment's last index never ends such a window
        let mut p = 0.0;
        for i in s0..end {
            p += f[i];
            out[i + 1 - q] += p;
        }
        s0 += q;
    }
}

/// Short-hop DAVAR rows take their terms from the double-word phase up to this m; beyond, the three
/// phase streams at k, k + m, k + 2m (48 bytes per term) no longer share cache lines, and the
/// streaming block sums read fewer bytes per term. (Measured at N = 10⁷, window 10⁶, hop 1, 45 τ, one
/// worker: 8.9–17 s against 9.1–12 s for the former all-streaming path — memory-bound either way, the
/// kernel zeroing 3 GB of fresh output pages is the largest single cost.)
const PHASE_M_MAX: usize = 8192;

/// Reusable buffers of one worker, so that rows do not pay fresh allocations (page faults).
#[derive(Default)]
pub(crate) struct RowScratch {
    terms: Vec<f64>,
    full: Vec<f64>,
    part: Vec<f64>,
}

/// The windows of a record that one call computes: windows `first .. first + out.len()` of the
/// record's `total`, from samples that start at the record's sample `first · hop`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Part {
    pub(crate) first: usize,
    pub(crate) total: usize,
}

impl Part {
    /// The whole record: every one of its `n_win` windows.
    fn whole(n_win: usize) -> Self {
        Part {
            first: 0,
            total: n_win,
        }
    }
}

/// `sliding_sums` of a part of the record's block array: `f[i]` is the record's block `g0 + i`,
/// `out[j]` the record's window `g0 + j`, and the record has `n_total` windows. Every value is
/// formed by the same additions in the same order as the whole-record `sliding_sums(f_record, q,
/// out_record)` forms it: the segments stay aligned to the record's multiples of q, the suffix sums
/// run from the record's segment end down, and the last segment is cut where the record's is.
/// Requires f.len() ≥ out.len() + q − 1, q ≥ 1 and g0 + out.len() ≤ n_total.
pub(crate) fn sliding_sums_at(f: &[f64], q: usize, g0: usize, n_total: usize, out: &mut [f64]) {
    let (lo, hi) = (g0, g0 + out.len());
    debug_assert!(q >= 1 && hi <= n_total && f.len() + 1 >= out.len() + q);
    if q == 1 {
        out.copy_from_slice(&f[..out.len()]);
        return;
    }
    // Suffix sums within each of the record's segments, down to the first window of this part.
    let mut s0 = lo / q * q;
    while s0 < hi {
        let end = (s0 + q).min(n_total + q - 1);
        let mut s: f64 = f[n_total.min(end) - g0..end - g0].iter().rev().sum();
        for j in (s0.max(lo)..end.min(n_total)).rev() {
            s += f[j - g0];
            if j < hi {
                out[j - g0] = s;
            }
        }
        s0 += q;
    }
    // Prefix sums of the following segment: window w (w mod q ≠ 0) ends at i = w + q − 1, in the
    // segment from its own segment's end; this part's windows end at i ∈ [lo + q − 1, hi + q − 1).
    let stop = (hi + q - 1).min(n_total + q - 1);
    let mut s0 = (lo.div_ceil(q) * q).max(q); // the segment holding i = lo + q − 1
    while s0 < stop {
        let end = (s0 + q - 1).min(n_total + q - 1);
        let mut p = 0.0;
        for i in s0..end.min(stop) {
            p += f[i - g0];
            let w = i + 1 - q;
            if w >= lo {
                out[w - g0] += p;
            }
        }
        s0 += q;
    }
}

/// Overlapping Allan variance of the windows `part` of a record, for one m, written to `out` (length: the
/// part's windows), from `y` = the record's samples from `part.first · hop` on: the values the
/// whole-record call gives them, bit for bit (the same terms, block sums and window sums, see
/// [`for_each_term_chunk_at`] and [`sliding_sums_at`]). Once `cancel` is set, `out` holds garbage
/// (the caller returns `Cancelled` instead).
#[allow(clippy::too_many_arguments)]
pub(crate) fn overlapping_row_at(
    y: &[f64],
    part: Part,
    mu: f64,
    m: usize,
    window: usize,
    hop: usize,
    out: &mut [f64],
    sc: &mut RowScratch,
    cancel: &Cancel,
) {
    let n_win = out.len();
    let l = window + 1 - 2 * m;
    // With one window any block size works; a whole-window block keeps memory O(1).
    let hop = if part.total == 1 { l } else { hop };
    let (q, r) = (l / hop, l % hop);
    let off = part.first * hop; // the record's index of y[0] and of this part's first term
    let k_end = (part.total - 1) * hop + l; // the record's terms
    let k_hi = off + (n_win - 1) * hop + l; // this part's
    let nblocks = n_win + q;
    let norm = 1.0 / (2.0 * (m as f64) * (m as f64) * l as f64);
    let RowScratch {
        terms,
        full,
        part: head,
    } = sc;
    full.clear();
    full.resize(nblocks, 0.0);
    head.clear();
    head.resize(nblocks, 0.0);
    let range = (off, k_hi);
    if hop <= SMALL_HOP {
        // Short blocks: per-block bookkeeping would cost more than the arithmetic, so keep the
        // terms and cut them afterwards (the output is already ~k_end/hop values per m).
        terms.clear();
        for_each_term_chunk_at(y, off, mu, m, range, k_end, norm, cancel, |chunk| {
            terms.extend_from_slice(chunk)
        });
        if hop == 1 {
            std::mem::swap(terms, full);
        } else {
            for (b, blk) in terms.chunks(hop).enumerate() {
                full[b] = sum4(blk);
                head[b] = sum4(&blk[..r.min(blk.len())]);
            }
        }
    } else {
        let (mut b, mut pos, mut total) = (0usize, 0usize, 0.0f64);
        for_each_term_chunk_at(y, off, mu, m, range, k_end, norm, cancel, |chunk| {
            let mut i = 0;
            while i < chunk.len() {
                let target = if pos < r { r } else { hop };
                let n = (target - pos).min(chunk.len() - i).min(RUN);
                total += sum4(&chunk[i..i + n]);
                pos += n;
                i += n;
                if pos == r {
                    head[b] = total;
                }
                if pos == hop {
                    full[b] = total;
                    b += 1;
                    pos = 0;
                    total = 0.0;
                }
            }
        });
    }
    if cancel.is_cancelled() {
        return;
    }
    // The terms already carry the normalisation, so the window sums are the variances.
    if q == 0 {
        out.copy_from_slice(&head[..n_win]);
    } else {
        if part.first == 0 && n_win == part.total {
            sliding_sums(full, q, out);
        } else {
            sliding_sums_at(full, q, part.first, part.total, out);
        }
        if r != 0 {
            for (o, p) in out.iter_mut().zip(&head[q..]) {
                *o += p;
            }
        }
    }
}

/// Classic (non-overlapping) Allan variance of the windows `part` of a record, for one m: clusters
/// start at the window's first sample, so window j uses the terms a(s + i·m), i = 0 … K−2, s = j·hop;
/// `y` = the record's samples from `part.first · hop` on. Bit for bit the whole-record values (the same
/// terms; each window's sum is formed from its own terms in the same order).
#[allow(clippy::too_many_arguments)]
fn classic_row_at(
    y: &[f64],
    part: Part,
    mu: f64,
    m: usize,
    window: usize,
    hop: usize,
    out: &mut [f64],
    cancel: &Cancel,
) {
    let n_win = out.len();
    let k = window / m;
    let terms = k - 1;
    let k_end = (part.total - 1) * hop + (terms - 1) * m + 1;
    let off = part.first * hop;
    let range = (off, off + (n_win - 1) * hop + (terms - 1) * m + 1);
    let norm = 1.0 / (2.0 * (m as f64) * (m as f64) * terms as f64);
    if part.total == 1 {
        // One window: keep only the strided terms, O(m) memory.
        let mut picked = Vec::with_capacity(terms);
        let mut k0 = 0usize;
        for_each_term_chunk_at(y, off, mu, m, range, k_end, norm, cancel, |chunk| {
            let first = (m - k0 % m) % m;
            picked.extend(chunk.iter().skip(first).step_by(m));
            k0 += chunk.len();
        });
        out[0] = sum4(&picked);
        return;
    }
    let mut a = Vec::with_capacity(range.1 - range.0);
    for_each_term_chunk_at(y, off, mu, m, range, k_end, norm, cancel, |chunk| {
        a.extend_from_slice(chunk)
    });
    if cancel.is_cancelled() {
        return;
    }
    let mut buf = Vec::with_capacity(terms);
    for (j, o) in out.iter_mut().enumerate() {
        // Many long windows add up: look at the flag per window (each is `terms` additions).
        if cancel.is_cancelled() {
            return;
        }
        let s = j * hop;
        buf.clear();
        buf.extend((0..terms).map(|i| a[s + i * m]));
        *o = sum4(&buf);
    }
}

/// One window recomputed from scratch, all m: the plain definition (paper 000's DAVAR step):
/// remove the window mean, integrate to angle, sum squared second differences.
fn naive_window(
    yw: &[f64],
    ms: &[usize],
    estimator: Estimator,
    angle: &mut Vec<f64>,
    out: &mut [f64],
) {
    let w = yw.len();
    let mu = yw.iter().sum::<f64>() / w as f64;
    angle.clear();
    angle.push(0.0);
    let mut x = 0.0;
    for &v in yw {
        x += v - mu;
        angle.push(x);
    }
    let xs = &angle[..];
    for (o, &m) in out.iter_mut().zip(ms) {
        let mm = (m * m) as f64;
        *o = match estimator {
            Estimator::Overlapping => {
                let l = w + 1 - 2 * m;
                let mut s = 0.0;
                for k in 0..l {
                    let d = xs[k + 2 * m] - 2.0 * xs[k + m] + xs[k];
                    s += d * d;
                }
                s / (2.0 * mm * l as f64)
            }
            Estimator::Classic => {
                let k = w / m;
                let mut s = 0.0;
                for i in 0..k - 1 {
                    let d = (xs[(i + 2) * m] - xs[(i + 1) * m]) - (xs[(i + 1) * m] - xs[i * m]);
                    s += d * d;
                }
                s / (2.0 * mm * (k - 1) as f64)
            }
        };
    }
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

/// Checks a request; the messages name the value and what is allowed.
pub fn validate(req: &Request) -> Result<usize> {
    let n_win = validate_shape(req)?;
    check_finite(req.columns)?;
    Ok(n_win)
}

/// [`validate`] without the finite check (for a path that checks while it reads the samples).
fn validate_shape(req: &Request) -> Result<usize> {
    let n = check_shape(req.columns)?;
    if req.window < 2 || req.window > n {
        return Err(CoreError::InvalidParameter(format!(
            "window ({} samples) must be between 2 and the record length ({n} samples)",
            req.window
        )));
    }
    if req.hop == 0 {
        return Err(CoreError::InvalidParameter(
            "hop (0) must be at least 1 sample".into(),
        ));
    }
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
            let mus: Vec<f64> = req
                .columns
                .par_iter()
                .map(|c| compensated_mean(c))
                .collect();
            // samples any window reads
            let n_used = ((n_win - 1) * req.hop + req.window).min(req.columns[0].len());
            let path = row_path(req, n_used, n_axes, n_win);
            ranges = part_rows(req, &mus, Part::whole(n_win), path, &mut out, cancel);
        }
        Method::Naive => {
            for (a, y) in req.columns.iter().enumerate() {
                let cols: Vec<Vec<f64>> = (0..n_win)
                    .into_par_iter()
                    .map_init(Vec::new, |angle, j| {
                        let s = j * req.hop;
                        let mut col = vec![0.0; n_m];
                        if cancel.is_cancelled() {
                            return col;
                        }
                        naive_window(
                            &y[s..s + req.window],
                            req.ms,
                            req.estimator,
                            angle,
                            &mut col,
                        );
                        col
                    })
                    .collect();
                cancel.check()?;
                let block = &mut out[a * n_m * n_win..(a + 1) * n_m * n_win];
                for (j, col) in cols.iter().enumerate() {
                    for (t, v) in col.iter().enumerate() {
                        block[t * n_win + j] = *v;
                    }
                }
            }
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

/// The one window `y[..window]` of a request by the static estimators' paths — every m from one
/// double-word phase (overlapping, `crate::oavar`) or cluster sums gathered from one double-word
/// prefix (classic, `crate::gather`) — centred on each window's mean from the parallel pass that
/// also checks the samples are finite (the samples after the window are checked too). `None` when
/// the window is too long for them (`GATHER_MAX`); the caller then streams.
fn static_window(req: &Request, out: &mut [f64], cancel: &Cancel) -> Option<Result<()>> {
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
fn long_record(n_used: usize, n_axes: usize) -> bool {
    n_used.saturating_mul(n_axes) > crate::oavar::PHASE_RECORD_MAX
}

/// Whether the fast dynamic estimator of a record of several windows takes the double-word phase
/// path: the overlapping estimator on a short record (≤ 2^26 samples × axes) at any window, on a long
/// one while its segments span at most `PHASE_SPAN_MAX` (2^23) samples — windows up to 2^21. The phase
/// it holds is one segment's either way. Longer windows on long records take chunked phases
/// ([`RowPath::Chunked`]) or stream their sums (hops below 64), see [`dynamic_avar_part_cancellable`].
fn takes_phase_path(estimator: Estimator, n_used: usize, n_axes: usize, window: usize) -> bool {
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
fn part_rows(
    req: &Request,
    mus: &[f64],
    part: Part,
    path: RowPath,
    out: &mut [f64],
    cancel: &Cancel,
) -> Option<Vec<Range>> {
    let n_m = req.ms.len();
    let n_win = out.len() / (req.columns.len() * n_m);
    let n_m_win = n_m * n_win;
    if path == RowPath::Chunked {
        let mut ranges = Vec::with_capacity(req.columns.len() * n_m);
        for (a, y) in req.columns.iter().enumerate() {
            let dst_axis = &mut out[a * n_m_win..(a + 1) * n_m_win];
            let (w, h) = (req.window, req.hop);
            ranges.extend(crate::chunked::overlapping_rows(
                y, part, mus[a], req.ms, w, h, dst_axis, cancel,
            ));
        }
        return (ranges.len() == req.columns.len() * n_m).then_some(ranges);
    }
    let phase = path == RowPath::Phase;
    // each row's range, noted right after the row is formed (in cache); the tiled path leaves it open
    let mut ranges = vec![Range::default(); req.columns.len() * n_m];
    let mut noted = true;
    if phase {
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
                    let rows: Vec<Range> = dst_axis
                        .par_chunks_mut(n_win)
                        .enumerate()
                        .map_init(
                            || (crate::oavar::DynScratch::default(), RowScratch::default()),
                            |(sc, rs), (t, row)| {
                                if cancel.is_cancelled() {
                                    return Range::default();
                                }
                                let dst = &mut row[j0..j1];
                                let m = req.ms[t];
                                // (a one-window run at a hop ≥ 64 is the tiled path's blocks)
                                if m <= PHASE_M_MAX
                                    || part.total == 1
                                    || req.hop >= crate::oavar::SMALL_HOP
                                {
                                    crate::oavar::overlapping_dynamic_row(
                                        hi,
                                        lo,
                                        m,
                                        req.window,
                                        req.hop,
                                        part.total == 1,
                                        dst,
                                        sc,
                                    )
                                } else {
                                    overlapping_row_at(
                                        &y[s0..],
                                        sub,
                                        mus[a],
                                        m,
                                        req.window,
                                        req.hop,
                                        dst,
                                        rs,
                                        cancel,
                                    );
                                    Range::of(dst)
                                }
                            },
                        )
                        .collect();
                    for (t, r) in rows.into_iter().enumerate() {
                        ranges[a * n_m + t] = ranges[a * n_m + t].merge(r);
                    }
                }
                j0 = j1;
            }
        }
        return noted.then_some(ranges);
    }
    let rows: Vec<Range> = out
        .par_chunks_mut(n_win)
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
        .collect();
    Some(rows)
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sliding_sums_match_direct() {
        let f: Vec<f64> = (0..37).map(|i| (i * i % 11) as f64).collect();
        for q in 1..10 {
            for n_out in 1..=f.len() - q + 1 {
                let mut s = vec![f64::NAN; n_out];
                sliding_sums(&f, q, &mut s);
                for j in 0..n_out {
                    assert_eq!(s[j], f[j..j + q].iter().sum::<f64>());
                }
            }
        }
    }

    /// The one-segment-at-a-time form `sliding_sums` interleaves: the same additions in the same order.
    fn sliding_sums_serial(f: &[f64], q: usize, out: &mut [f64]) {
        let n_out = out.len();
        let mut s0 = 0;
        while s0 < n_out {
            let end = (s0 + q).min(n_out + q - 1);
            let mut s: f64 = f[n_out.min(end)..end].iter().rev().sum();
            for j in (s0..end.min(n_out)).rev() {
                s += f[j];
                out[j] = s;
            }
            s0 += q;
        }
        let mut s0 = q;
        while s0 < n_out + q - 1 {
            let end = (s0 + q - 1).min(n_out + q - 1);
            let mut p = 0.0;
            for i in s0..end {
                p += f[i];
                out[i + 1 - q] += p;
            }
            s0 += q;
        }
    }

    #[test]
    fn interleaved_sliding_sums_are_bit_identical_to_serial() {
        let f: Vec<f64> = (0..5000u64)
            .map(|i| ((i.wrapping_mul(2654435761) % 1000) as f64 / 7.0).sqrt() * 1e-3)
            .collect();
        for q in [2, 3, 7, 64, 100, 333, 1000, 1249, 1250, 1251, 2500, 4999] {
            for n_out in [
                1,
                2,
                q - 1,
                q,
                q + 1,
                4 * q - 1,
                4 * q,
                4 * q + 1,
                9 * q + 5,
                f.len() + 1 - q,
            ] {
                if n_out == 0 || n_out + q - 1 > f.len() {
                    continue;
                }
                let (mut a, mut b) = (vec![0.0; n_out], vec![0.0; n_out]);
                sliding_sums(&f, q, &mut a);
                sliding_sums_serial(&f, q, &mut b);
                assert!(
                    a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
                    "q {q} n_out {n_out}"
                );
            }
        }
    }

    #[test]
    fn sliding_sums_at_is_the_records_arithmetic() {
        let f: Vec<f64> = (0..300u64)
            .map(|i| ((i.wrapping_mul(2654435761) % 1000) as f64 / 7.0).sqrt() * 1e-3)
            .collect();
        for q in [1, 2, 3, 7, 16, 33, 100] {
            for n_total in [1, 2, q, q + 1, 3 * q + 2, f.len() + 1 - q] {
                if n_total + q - 1 > f.len() {
                    continue;
                }
                let mut whole = vec![f64::NAN; n_total];
                sliding_sums(&f[..n_total + q - 1], q, &mut whole);
                for g0 in 0..n_total {
                    for len in [1, 2, 5, q, q + 3, n_total] {
                        let len = len.min(n_total - g0);
                        let mut part = vec![f64::NAN; len];
                        sliding_sums_at(&f[g0..g0 + len + q - 1], q, g0, n_total, &mut part);
                        for j in 0..len {
                            assert_eq!(
                                part[j].to_bits(),
                                whole[g0 + j].to_bits(),
                                "q {q} n {n_total} g0 {g0} len {len} j {j}"
                            );
                        }
                    }
                }
            }
        }
    }

    /// A record whose mean is far above its noise (7000 σ) and whose noise level changes: centring
    /// and block alignment matter in the last bits.
    fn biased_record(n: usize, seed: u64) -> Vec<f64> {
        let mut x = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (0..n)
            .map(|i| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                let u = (x >> 11) as f64 / (1u64 << 53) as f64 - 0.5;
                7000.0 + u * if i < n / 3 { 3.0 } else { 1.0 }
            })
            .collect()
    }

    /// The streaming path of a part (what the record's call does when it streams).
    fn streamed(req: &Request, mus: &[f64], first: usize, total: usize) -> Vec<f64> {
        let n_win = validate(req).unwrap().min(total - first);
        let mut out = vec![0.0; req.columns.len() * req.ms.len() * n_win];
        let part = Part { first, total };
        part_rows(req, mus, part, RowPath::Stream, &mut out, &Cancel::new());
        out
    }

    #[test]
    fn a_part_of_the_record_gives_the_records_windows() {
        let n = 3001;
        let cols_owned = [biased_record(n, 1), biased_record(n, 2)];
        let cols: Vec<&[f64]> = cols_owned.iter().map(|c| c.as_slice()).collect();
        let mus: Vec<f64> = cols.iter().map(|c| compensated_mean(c)).collect();
        // (window, hop): m ≤ 8 and > 8, hop 1, ≤ 64, > 64, hops longer than some terms (q = 0),
        // a single window.
        let cases = [
            (500, 1),
            (500, 7),
            (401, 64),
            (700, 65),
            (1000, 130),
            (300, 290),
            (2999, 3),
            (n, 1),
            (2500, 600),
        ];
        let (mut differ, mut compared, mut worst) = (0usize, 0usize, 0.0f64);
        for estimator in [Estimator::Overlapping, Estimator::Classic] {
            for (window, hop) in cases {
                let mut ms: Vec<usize> = vec![1, 2, 3, 8, 9, 10, 17, 64, 100, 149, window / 2];
                ms.retain(|&m| m <= window / 2);
                ms.dedup();
                let req = Request {
                    columns: &cols,
                    window,
                    hop,
                    ms: &ms,
                    estimator,
                    method: Method::Fast,
                };
                let (record, n_win) = dynamic_avar(&req).unwrap();
                let whole = streamed(&req, &mus, 0, n_win);
                // this record is small: the record's call streams only the classic estimator
                let phase = estimator == Estimator::Overlapping;
                if !phase && n_win >= 2 {
                    assert!(whole
                        .iter()
                        .zip(&record)
                        .all(|(a, b)| a.to_bits() == b.to_bits()));
                }
                let starts: Vec<usize> = (0..n_win)
                    .step_by(1 + n_win / 7)
                    .chain([n_win - 1])
                    .collect();
                for &first in &starts {
                    for count in [1, 2, 3, n_win] {
                        let count = count.min(n_win - first);
                        let s0 = first * hop;
                        let len = ((count - 1) * hop + window).min(n - s0);
                        let part_cols: Vec<&[f64]> =
                            cols.iter().map(|c| &c[s0..s0 + len]).collect();
                        let preq = Request {
                            columns: &part_cols,
                            ..req
                        };
                        let (got, k) = dynamic_avar_part_cancellable(
                            &preq,
                            &mus,
                            first,
                            n_win,
                            &Cancel::new(),
                        )
                        .unwrap();
                        assert_eq!(k, count);
                        let part = streamed(&preq, &mus, first, n_win);
                        // the part on its own (its own mean and alignment) rounds differently
                        let (alone, _) = dynamic_avar(&preq).unwrap();
                        let per_row = alone.len() / (cols.len() * ms.len());
                        for row in 0..cols.len() * ms.len() {
                            for j in 0..count {
                                let w = whole[row * n_win + first + j];
                                differ += usize::from(alone[row * per_row + j] != w);
                                compared += 1;
                                // streaming: the same additions in the same order
                                assert_eq!(
                                    part[row * count + j].to_bits(),
                                    w.to_bits(),
                                    "{estimator:?} window {window} hop {hop} first {first} \
                                     count {count} row {row} j {j}"
                                );
                                // the part entry against the record's call (its path)
                                let (g, r) =
                                    (got[row * count + j], record[row * n_win + first + j]);
                                // (the phase path: bit for bit from a segment's start)
                                let seg = crate::oavar::segment_windows(window, hop, false);
                                let exact = !phase || first % seg == 0;
                                if exact {
                                    assert_eq!(
                                        g.to_bits(),
                                        r.to_bits(),
                                        "{estimator:?} {window} {hop}"
                                    );
                                } else {
                                    worst = worst.max((g / r - 1.0).abs());
                                }
                            }
                        }
                    }
                }
            }
        }
        // the phase path of a part: the record's terms from differently rounded phase values
        assert!(worst > 0.0 && worst < 1e-13, "worst {worst:e}");
        // the streaming equality is not a property of any part: computed on their own (their own
        // mean, their own alignment) a quarter of these values differ in the last bits
        assert!(differ * 10 > compared, "{differ} of {compared} differ");
    }

    /// The phase path in segments (the unit tests' segments span 2^12 samples): parts that start on
    /// the segment grid are the record's call bit for bit, others to a few ε; every value matches
    /// the plain recomputation of its window.
    #[test]
    fn phase_segments_cut_where_parts_can() {
        // a long record in the unit tests (> 2^14 samples × axes: segments of max(2^12, 4·window)) and
        // a short one (segments of max(2^12, 16·window))
        let long_cases = vec![
            (300, 1),
            (500, 7),
            (256, 64),
            (1000, 100),
            (200, 5000),
            (2500, 100),
        ];
        let short_cases = vec![(200, 1), (250, 3), (200, 64)];
        for (n, n_axes, long, cases) in [
            (20_011, 2, true, long_cases),
            (16_000, 1, false, short_cases),
        ] {
            segments_case(n, n_axes, long, &cases);
        }
    }

    fn segments_case(n: usize, n_axes: usize, long: bool, cases: &[(usize, usize)]) {
        let cols_owned: Vec<Vec<f64>> = (0..n_axes)
            .map(|a| biased_record(n, 7 + a as u64))
            .collect();
        let cols: Vec<&[f64]> = cols_owned.iter().map(|c| c.as_slice()).collect();
        let mus: Vec<f64> = cols.iter().map(|c| compensated_mean(c)).collect();
        // hop 1 (rows), 3 and 7 (rows, blocks), 64 and 100 (tiled), a hop longer than a segment's span
        for &(window, hop) in cases {
            let seg = crate::oavar::segment_windows(window, hop, long);
            let ms: Vec<usize> = [1, 2, 5, 16, 33, window / 2]
                .into_iter()
                .filter(|&m| m <= window / 2)
                .collect();
            let req = Request {
                columns: &cols,
                window,
                hop,
                ms: &ms,
                estimator: Estimator::Overlapping,
                method: Method::Fast,
            };
            let (record, n_win) = dynamic_avar(&req).unwrap();
            // (the unit tests' span limit for a long record is 2^13: window 2500 takes chunked phases
            // (`crate::chunked`), the others keep the phase path; a short record keeps it at any window)
            let phase = !long || window * 4 <= 1 << 13;
            assert!(
                n_win > seg || hop > 4096 || !phase,
                "window {window} hop {hop}: one segment only"
            );
            let grid = if phase {
                seg * hop
            } else {
                crate::chunked::chunk_len(window, hop)
            };
            assert_eq!(
                part_grid(n, n_axes, window, hop, Estimator::Overlapping, Method::Fast),
                Some(grid)
            );
            // the parts' own grid in windows
            let seg = grid / hop;
            // every value against the window's own plain recomputation
            for (a, y) in cols.iter().enumerate() {
                for (t, &m) in ms.iter().enumerate() {
                    for j in (0..n_win).step_by(1 + n_win / 40) {
                        let w = &y[j * hop..j * hop + window];
                        let mut x = vec![0.0f64; window + 1];
                        let mu = compensated_mean(w);
                        for (i, v) in w.iter().enumerate() {
                            x[i + 1] = x[i] + (v - mu);
                        }
                        let l = window + 1 - 2 * m;
                        let s: f64 = (0..l)
                            .map(|k| (x[k + 2 * m] - 2.0 * x[k + m] + x[k]).powi(2))
                            .sum();
                        let plain = s / (2.0 * (m * m) as f64 * l as f64);
                        let got = record[(a * ms.len() + t) * n_win + j];
                        assert!(
                            (got / plain - 1.0).abs() < 1e-9,
                            "{window} {hop} m {m} j {j}: {got} vs {plain}"
                        );
                    }
                }
            }
            let (mut worst, mut off_grid) = (0.0f64, 0usize);
            for first in [0, seg, 2 * seg, seg / 2 + 1, seg + 3] {
                if first >= n_win {
                    continue;
                }
                for count in [1, seg, seg + 1, n_win] {
                    let count = count.min(n_win - first);
                    let s0 = first * hop;
                    let len = ((count - 1) * hop + window).min(n - s0);
                    let part_cols: Vec<&[f64]> = cols.iter().map(|c| &c[s0..s0 + len]).collect();
                    let preq = Request {
                        columns: &part_cols,
                        ..req
                    };
                    let (got, k) =
                        dynamic_avar_part_cancellable(&preq, &mus, first, n_win, &Cancel::new())
                            .unwrap();
                    assert_eq!(k, count);
                    for row in 0..cols.len() * ms.len() {
                        for j in 0..count {
                            let (g, r) = (got[row * count + j], record[row * n_win + first + j]);
                            if first % seg == 0 {
                                assert_eq!(
                                    g.to_bits(),
                                    r.to_bits(),
                                    "{window} {hop} first {first} count {count}"
                                );
                            } else {
                                worst = worst.max((g / r - 1.0).abs());
                                off_grid += 1;
                            }
                        }
                    }
                }
            }
            assert!(off_grid == 0 || worst < 1e-13, "{window} {hop}: {worst:e}");
        }
    }

    #[test]
    fn the_record_mean_from_its_parts_is_bit_identical() {
        let y = biased_record(10_007, 3);
        let mut st = (0.0, 0.0);
        for c in y.chunks(977) {
            st = compensated_sum_from(c, st);
        }
        assert_eq!(
            ((st.0 + st.1) / y.len() as f64).to_bits(),
            compensated_mean(&y).to_bits()
        );
    }

    #[test]
    fn a_part_names_bad_arguments() {
        let y = biased_record(100, 4);
        let cols = [y.as_slice()];
        let req = Request {
            columns: &cols,
            window: 10,
            hop: 5,
            ms: &[1, 2],
            estimator: Estimator::Overlapping,
            method: Method::Fast,
        };
        let c = Cancel::new();
        assert!(dynamic_avar_part_cancellable(&req, &[f64::NAN], 0, 30, &c).is_err());
        assert!(dynamic_avar_part_cancellable(&req, &[1.0, 2.0], 0, 30, &c).is_err());
        assert!(dynamic_avar_part_cancellable(&req, &[1.0], 30, 30, &c).is_err());
        // a part longer than the rest of the record gives the record's windows only
        assert_eq!(
            dynamic_avar_part_cancellable(&req, &[1.0], 25, 28, &c)
                .unwrap()
                .1,
            3
        );
    }

    #[test]
    fn parts_name_a_non_finite_sample() {
        // a part of several windows (checked before its rows) and a record's one window (checked in
        // the static paths' centring pass), a NaN in the window and an inf after it
        let mut y: Vec<f64> = (0..1000).map(|i| ((i * 37) % 11) as f64).collect();
        y[700] = f64::NAN;
        let mut z = y.clone();
        z[700] = 1.0;
        z[900] = f64::INFINITY;
        for (col, index, window, total) in
            [(&y, 700, 500, 6), (&y, 700, 1000, 1), (&z, 900, 800, 1)]
        {
            for estimator in [Estimator::Overlapping, Estimator::Classic] {
                let cols = [&col[..]];
                let req = Request {
                    columns: &cols,
                    window,
                    hop: 100,
                    ms: &[1, 2],
                    estimator,
                    method: Method::Fast,
                };
                let err = dynamic_avar_part_cancellable(&req, &[0.0], 0, total, &Cancel::new())
                    .unwrap_err();
                assert!(
                    matches!(err, CoreError::NonFinite { axis: 0, index: i, .. } if i == index),
                    "{window} {estimator:?}: {err}"
                );
                assert!(err.to_string().contains("only finite numbers are allowed"));
                if total == 1 {
                    // the whole-record call of one window (hop past the record's end): the same
                    let req = Request { hop: 1000, ..req };
                    let err = dynamic_avar(&req).unwrap_err();
                    assert!(
                        matches!(err, CoreError::NonFinite { axis: 0, index: i, .. } if i == index),
                        "whole record {window} {estimator:?}: {err}"
                    );
                }
            }
        }
    }

    #[test]
    fn block_sums_match_direct() {
        // Integer-valued data: every order of summation is exact, so equality is exact.
        let y: Vec<f64> = (0..400).map(|i| ((i * 7919) % 23) as f64 - 11.0).collect();
        for m in [1, 2, 3, 5, 8, 63, 64, 65, 100, 130] {
            let mut start = 0;
            while start + 2 * m <= y.len() {
                for len in [1, 2, m / 2 + 1, m.saturating_sub(1).max(1), m]
                    .into_iter()
                    .filter(|&l| l <= m)
                {
                    let mut sc = TermScratch::new(m);
                    sc.segment(&y, 1.0, m, start, len, None);
                    for r in 0..len {
                        let direct: f64 = y[start + r..start + r + m].iter().map(|v| v - 1.0).sum();
                        assert_eq!(sc.bprev[r], direct, "m {m} start {start} len {len} r {r}");
                    }
                }
                start += m;
            }
        }
    }
}

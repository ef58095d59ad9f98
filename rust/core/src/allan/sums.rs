//! The sums every Allan path is built from: Neumaier's compensated mean (the centring value), four-way
//! sums, and the window sums of non-negative blocks by the Van Herk / Gil-Werman split — for a whole
//! record ([`sliding_sums`]) or a part of one, bit for bit the record's ([`sliding_sums_at`]).

use super::terms::CHAINS;
use rayon::prelude::*;

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
    let mut acc = Compensated::from_state(state);
    for &v in y {
        acc.add(v);
    }
    acc.state()
}

/// The per-column [`compensated_mean`]s, the columns in parallel (each one sequential, so the
/// same bits for any number of threads): every path's centring values.
pub(crate) fn compensated_means(columns: &[&[f64]]) -> Vec<f64> {
    columns.par_iter().map(|c| compensated_mean(c)).collect()
}

/// Neumaier's compensated running sum (sum s, compensation c; the value s + c): the one
/// implementation of the step behind [`compensated_sum_from`] and the kernels that add their
/// terms or blocks of terms one at a time.
#[derive(Default, Clone, Copy, Debug)]
pub(crate) struct Compensated {
    s: f64,
    c: f64,
}

impl Compensated {
    /// The sum continued from the state (s, c).
    pub(crate) fn from_state((s, c): (f64, f64)) -> Self {
        Self { s, c }
    }

    /// Adds `v`; the rounding error of s + v goes to the compensation.
    #[inline]
    pub(crate) fn add(&mut self, v: f64) {
        let t = self.s + v;
        if self.s.abs() >= v.abs() {
            self.c += (self.s - t) + v;
        } else {
            self.c += (v - t) + self.s;
        }
        self.s = t;
    }

    /// The compensated value s + c.
    #[inline]
    pub(crate) fn value(self) -> f64 {
        self.s + self.c
    }

    /// The state (s, c), to continue from.
    pub(crate) fn state(self) -> (f64, f64) {
        (self.s, self.c)
    }
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

/// Window sums from hop-aligned block sums, for windows of q·hop + r terms: window j's sum is the
/// full blocks j .. j + q (the Van Herk sliding sums, [`sliding_sums_at`] for the windows `g0 ..` of a
/// record of `n_total` windows, `place` = (g0, n_total)) plus the first r terms of block j + q
/// (`part`); with q = 0, only those. `full` and `part` hold `out.len() + q` blocks.
pub(crate) fn block_window_sums(
    full: &[f64],
    part: &[f64],
    (q, r): (usize, usize),
    place: (usize, usize),
    out: &mut [f64],
) {
    if q == 0 {
        out.copy_from_slice(&part[..out.len()]);
        return;
    }
    let (g0, n_total) = place;
    if g0 == 0 && out.len() == n_total {
        sliding_sums(full, q, out);
    } else {
        sliding_sums_at(full, q, g0, n_total, out);
    }
    if r != 0 {
        for (o, p) in out.iter_mut().zip(&part[q..]) {
            *o += p;
        }
    }
}

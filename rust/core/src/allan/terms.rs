//! The squared differences a(k) = scale·d_m(k)² of one averaging factor, formed in chunks from block
//! sums that hold only their own samples (direct sums for short blocks, the aligned-segment split for
//! longer ones): for a whole record or a part of one, with the record's chunks and rounding.

use super::{DIRECT_CHUNK, DIRECT_M};
use crate::cancel::Cancel;

/// Interleaved chains for the running sums below: a running sum is a chain of dependent additions,
/// latency-bound; independent chains over separate parts of the range overlap their latencies.
pub(super) const CHAINS: usize = 4; // the hot loops below are unrolled for exactly four

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
        return direct_term_chunks((y, off), mu, m, range, scale, cancel, f);
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

/// [`for_each_term_chunk_at`] for short blocks (m ≤ `DIRECT_M`; `part`: (y, off) as there): each B(k)
/// summed directly over its own m samples (exactly local too), in chunks of k so the per-call
/// bookkeeping of the segment scheme is not paid per sample.
fn direct_term_chunks(
    (y, off): (&[f64], usize),
    mu: f64,
    m: usize,
    (k_lo, k_hi): (usize, usize),
    scale: f64,
    cancel: &Cancel,
    mut f: impl FnMut(&[f64]),
) {
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
}

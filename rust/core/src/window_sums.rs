//! The windows' sums of a dynamic row written in one pass, with the row's range noted on the way.
//!
//! [`crate::allan::sliding_sums`] forms every window sum of q consecutive non-negative blocks by the
//! Van Herk / Gil-Werman split (suffix sum of the window's q-segment from its start, plus prefix sum of
//! the next segment up to its end: no subtraction, so no drift) in two passes over the output: the
//! suffix sums are written, then the prefix sums added. On a hop-1 surface the output is the largest
//! thing the call touches (N = 10⁵, window 10⁴, 76 τ: 55 MB, the row larger than a core's L2), so the
//! second pass and the range check after it read it back from memory.
//!
//! [`sliding_sums_ranged`] keeps the suffix sums of (up to four) segments in a scratch that stays in
//! cache, and writes each output once as suffix + prefix (+ the head blocks), noting the largest and
//! smallest value and whether one is not finite as it goes. Every value is formed by the same IEEE
//! additions in the same order as the two-pass form (floating-point addition is commutative, so
//! s + p is p + s): the results are bit-identical to `sliding_sums` followed by the head's addition.

use crate::range::Range;

/// Segments whose running sums run interleaved (their latencies overlap; the hot loops are unrolled
/// for exactly four).
const CHAINS: usize = 4;

/// The range noted per chain, merged at the end.
#[derive(Clone, Copy)]
struct Acc {
    hi: f64,
    lo: f64,
    bad: f64,
}

impl Acc {
    const NEW: Acc = Acc {
        hi: f64::NEG_INFINITY,
        lo: f64::INFINITY,
        bad: 0.0,
    };

    #[inline(always)]
    fn note(&mut self, v: f64) {
        // plain comparisons; v·0 is 0 for a finite v and NaN otherwise, and a NaN stays in the sum
        self.hi = if v > self.hi { v } else { self.hi };
        self.lo = if v < self.lo { v } else { self.lo };
        self.bad += v * 0.0;
    }

    fn range(self) -> Range {
        Range {
            max: self.hi,
            min: self.lo,
            non_finite: self.bad.is_nan(),
        }
    }
}

/// out[j] = Σ f[j..j+q] (+ head[j] when given) for j < out.len(), f ≥ 0, each value written once;
/// returns the range of `out`. Bit-identical to [`crate::allan::sliding_sums`] followed by
/// `out[j] += head[j]`. `scratch` is resized to at most 4q. Requires f.len() ≥ out.len() + q − 1,
/// q ≥ 1 and head.len() ≥ out.len().
pub(crate) fn sliding_sums_ranged(
    f: &[f64],
    q: usize,
    head: Option<&[f64]>,
    out: &mut [f64],
    scratch: &mut Vec<f64>,
) -> Range {
    let n = out.len();
    assert!(q >= 1 && f.len() + 1 >= n + q && head.is_none_or(|h| h.len() >= n));
    let mut acc = [Acc::NEW; CHAINS];
    if q == 1 {
        for (j, o) in out.iter_mut().enumerate() {
            let v = match head {
                Some(h) => f[j] + h[j],
                None => f[j],
            };
            *o = v;
            acc[j % CHAINS].note(v);
        }
        return merged(acc);
    }
    scratch.clear();
    scratch.resize(CHAINS * q, 0.0);
    let mut h = 0; // first segment not yet written
    while (h + CHAINS) * q <= n {
        four_segments(f, q, h * q, head, out, scratch, &mut acc);
        h += CHAINS;
    }
    while h * q < n {
        one_segment(f, q, h * q, head, out, scratch, &mut acc[0]);
        h += 1;
    }
    merged(acc)
}

fn merged(acc: [Acc; CHAINS]) -> Range {
    acc.iter().fold(Range::default(), |r, a| r.merge(a.range()))
}

/// The windows of the four full segments from `b0` (b0 + 4q ≤ out.len()): suffix sums of each segment
/// into `scratch`, four chains interleaved, then each window as its suffix sum plus the running prefix
/// sum of the next segment.
#[inline(always)]
fn four_segments(
    f: &[f64],
    q: usize,
    b0: usize,
    head: Option<&[f64]>,
    out: &mut [f64],
    scratch: &mut [f64],
    acc: &mut [Acc; CHAINS],
) {
    let b = [b0, b0 + q, b0 + 2 * q, b0 + 3 * q];
    // the prefix pass reads f up to b[3] + 2q − 2 < out.len() + q − 1 ≤ f.len()
    assert!(b[3] + q <= out.len() && b[3] + 2 * q - 1 <= f.len() && scratch.len() >= CHAINS * q);
    let (mut s0, mut s1, mut s2, mut s3) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for i in (0..q).rev() {
        // SAFETY: b[p] + i < b[3] + q ≤ f.len(); p·q + i < 4q ≤ scratch.len() (asserted above).
        unsafe {
            s0 += *f.get_unchecked(b[0] + i);
            s1 += *f.get_unchecked(b[1] + i);
            s2 += *f.get_unchecked(b[2] + i);
            s3 += *f.get_unchecked(b[3] + i);
            *scratch.get_unchecked_mut(i) = s0;
            *scratch.get_unchecked_mut(q + i) = s1;
            *scratch.get_unchecked_mut(2 * q + i) = s2;
            *scratch.get_unchecked_mut(3 * q + i) = s3;
        }
    }
    // a window that starts a segment is its suffix sum alone
    for p in 0..CHAINS {
        let v = match head {
            Some(hd) => scratch[p * q] + hd[b[p]],
            None => scratch[p * q],
        };
        out[b[p]] = v;
        acc[p].note(v);
    }
    let (mut p0, mut p1, mut p2, mut p3) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    let [mut a0, mut a1, mut a2, mut a3] = *acc;
    match head {
        None => {
            for i in 0..q - 1 {
                // SAFETY: f index b[p] + q + i < b[3] + 2q − 1 ≤ f.len(); out index b[p] + i + 1 <
                // b[3] + q ≤ out.len(); scratch index p·q + i + 1 < 4q (asserted above).
                unsafe {
                    p0 += *f.get_unchecked(b[1] + i);
                    p1 += *f.get_unchecked(b[2] + i);
                    p2 += *f.get_unchecked(b[3] + i);
                    p3 += *f.get_unchecked(b[3] + q + i);
                    let v0 = *scratch.get_unchecked(i + 1) + p0;
                    let v1 = *scratch.get_unchecked(q + i + 1) + p1;
                    let v2 = *scratch.get_unchecked(2 * q + i + 1) + p2;
                    let v3 = *scratch.get_unchecked(3 * q + i + 1) + p3;
                    *out.get_unchecked_mut(b[0] + i + 1) = v0;
                    *out.get_unchecked_mut(b[1] + i + 1) = v1;
                    *out.get_unchecked_mut(b[2] + i + 1) = v2;
                    *out.get_unchecked_mut(b[3] + i + 1) = v3;
                    a0.note(v0);
                    a1.note(v1);
                    a2.note(v2);
                    a3.note(v3);
                }
            }
        }
        Some(hd) => {
            assert!(hd.len() >= b[3] + q);
            for i in 0..q - 1 {
                // SAFETY: as above; head index b[p] + i + 1 < b[3] + q ≤ hd.len() (asserted).
                unsafe {
                    p0 += *f.get_unchecked(b[1] + i);
                    p1 += *f.get_unchecked(b[2] + i);
                    p2 += *f.get_unchecked(b[3] + i);
                    p3 += *f.get_unchecked(b[3] + q + i);
                    let v0 = (*scratch.get_unchecked(i + 1) + p0) + *hd.get_unchecked(b[0] + i + 1);
                    let v1 =
                        (*scratch.get_unchecked(q + i + 1) + p1) + *hd.get_unchecked(b[1] + i + 1);
                    let v2 = (*scratch.get_unchecked(2 * q + i + 1) + p2)
                        + *hd.get_unchecked(b[2] + i + 1);
                    let v3 = (*scratch.get_unchecked(3 * q + i + 1) + p3)
                        + *hd.get_unchecked(b[3] + i + 1);
                    *out.get_unchecked_mut(b[0] + i + 1) = v0;
                    *out.get_unchecked_mut(b[1] + i + 1) = v1;
                    *out.get_unchecked_mut(b[2] + i + 1) = v2;
                    *out.get_unchecked_mut(b[3] + i + 1) = v3;
                    a0.note(v0);
                    a1.note(v1);
                    a2.note(v2);
                    a3.note(v3);
                }
            }
        }
    }
    *acc = [a0, a1, a2, a3];
}

/// The windows of the one segment from `s0` (the last ones may run past the output: the suffix sum
/// then starts with the blocks beyond the last window, summed from the segment's end down, as
/// `sliding_sums` does).
#[inline(always)]
fn one_segment(
    f: &[f64],
    q: usize,
    s0: usize,
    head: Option<&[f64]>,
    out: &mut [f64],
    scratch: &mut [f64],
    acc: &mut Acc,
) {
    let n = out.len();
    let end = s0 + q; // ≤ n + q − 1 ≤ f.len() since s0 < n
    let wend = end.min(n);
    let mut s: f64 = f[n.min(end)..end].iter().rev().sum();
    for j in (s0..wend).rev() {
        s += f[j];
        scratch[j - s0] = s;
    }
    let mut p = 0.0;
    for o in 0..wend - s0 {
        if o > 0 {
            p += f[end + o - 1];
        }
        let v = if o > 0 { scratch[o] + p } else { scratch[o] };
        let v = match head {
            Some(hd) => v + hd[s0 + o],
            None => v,
        };
        out[s0 + o] = v;
        acc.note(v);
    }
}

/// What every segment of a hop-1 row shares: the phase, the factor, the segment length q (= L) and
/// the terms' normalisation, the number of windows, and whether AVX2 is there.
struct Row<'p> {
    hi: &'p [f64],
    lo: &'p [f64],
    m: usize,
    q: usize,
    norm: f64,
    avx2: bool,
    n: usize,
}

impl Row<'_> {
    /// The terms a(k0) … a(k0 + t.len() − 1).
    #[inline(always)]
    fn terms(&self, k0: usize, t: &mut [f64]) {
        crate::oavar::terms_dispatch(self.avx2, self.hi, self.lo, self.m, k0, self.norm, t);
    }
}

/// A run of whole segments of a row's windows: `out` holds the windows base … base + out.len(), `h0`
/// is the segment being written, `cur` its suffix sums; `t` takes the next segment's terms and `nxt`
/// their suffix sums.
struct Lane<'a> {
    out: &'a mut [f64],
    base: usize,
    h0: usize,
    t: &'a mut [f64],
    cur: &'a mut [f64],
    nxt: &'a mut [f64],
    range: Range,
}

impl Lane<'_> {
    /// The first segment's terms and their suffix sums (from the segment's end down).
    fn start(&mut self, row: &Row) {
        row.terms(self.h0, self.t);
        let mut s = 0.0f64;
        for (c, v) in self.cur.iter_mut().zip(self.t.iter()).rev() {
            s += v;
            *c = s;
        }
    }

    fn done(&self) -> bool {
        self.h0 >= self.base + self.out.len()
    }

    /// Whether the segment being written is full and the row has windows after it: the step then
    /// needs all q terms of the next segment (≤ n + q − 2 < k_end) and forms their suffix sums too.
    fn full(&self, row: &Row) -> bool {
        !self.done() && self.h0 + row.q < row.n
    }

    /// The segment's windows (its first one written: the suffix sum alone), the next segment's first
    /// `len` terms (formed here), the segment's suffix sums and the buffer for the next one's.
    #[allow(clippy::type_complexity)]
    fn begin(&mut self, row: &Row, len: usize) -> (&mut [f64], &[f64], &[f64], &mut [f64]) {
        let nw = row.q.min(row.n - self.h0);
        let at = self.h0 - self.base;
        let Lane {
            out, t, cur, nxt, ..
        } = self;
        out[at] = cur[0];
        row.terms(self.h0 + row.q, &mut t[..len]);
        (&mut out[at..at + nw], &t[..len], &cur[..], &mut nxt[..])
    }

    /// Notes the written segment's range (in cache) and moves on to the next segment.
    fn end(&mut self, row: &Row, swap: bool) {
        let at = self.h0 - self.base;
        let nw = row.q.min(row.n - self.h0);
        self.range = self.range.merge(Range::of(&self.out[at..at + nw]));
        if swap {
            std::mem::swap(&mut self.cur, &mut self.nxt);
        }
        self.h0 += row.q;
    }

    /// One segment of this lane alone.
    fn step(&mut self, row: &Row) {
        let q = row.q;
        if self.full(row) {
            let (dst, t, cur, nxt) = self.begin(row, q);
            let (mut p, mut s) = (0.0f64, 0.0f64);
            for i in 0..q - 1 {
                p += t[i];
                dst[i + 1] = cur[i + 1] + p;
                s += t[q - 1 - i];
                nxt[q - 1 - i] = s;
            }
            nxt[0] = s + t[0];
            self.end(row, true);
        } else {
            // the row's last segment: the prefix of the next segment's first nw − 1 terms completes it
            let nw = q.min(row.n - self.h0);
            let (dst, t, cur, _) = self.begin(row, nw - 1);
            let mut p = 0.0f64;
            for ((d, c), v) in dst[1..].iter_mut().zip(&cur[1..]).zip(t) {
                p += v;
                *d = c + p;
            }
            self.end(row, false);
        }
    }
}

/// One full segment of each of two lanes, their four running sums (a prefix and a suffix each)
/// interleaved in one loop so that their latencies overlap: the same additions in the same order as
/// two [`Lane::step`] calls.
fn step_pair(a: &mut Lane, b: &mut Lane, row: &Row) {
    let q = row.q;
    let (da, ta, ca, na) = a.begin(row, q);
    let (db, tb, cb, nb) = b.begin(row, q);
    assert!([da.len(), ta.len(), ca.len(), na.len()] == [q; 4]);
    assert!([db.len(), tb.len(), cb.len(), nb.len()] == [q; 4]);
    let (mut pa, mut sa, mut pb, mut sb) = (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for i in 0..q - 1 {
        let r = q - 1 - i;
        // SAFETY: i + 1 < q and r < q, and every slice here has q items (asserted above).
        unsafe {
            pa += *ta.get_unchecked(i);
            pb += *tb.get_unchecked(i);
            sa += *ta.get_unchecked(r);
            sb += *tb.get_unchecked(r);
            *da.get_unchecked_mut(i + 1) = *ca.get_unchecked(i + 1) + pa;
            *db.get_unchecked_mut(i + 1) = *cb.get_unchecked(i + 1) + pb;
            *na.get_unchecked_mut(r) = sa;
            *nb.get_unchecked_mut(r) = sb;
        }
    }
    na[0] = sa + ta[0];
    nb[0] = sb + tb[0];
    a.end(row, true);
    b.end(row, true);
}

/// A hop-1 row of the overlapping estimator at factor m from the phase (hi, lo): window j is the sum of
/// the q = L terms a(j) … a(j + q − 1), a(k) = norm·d_k² (`crate::oavar::terms_dispatch`), for j <
/// out.len(); returns the row's range. The values are [`crate::allan::sliding_sums`] of the row's
/// terms bit for bit, but the terms are formed segment by segment (q at a time) into a cache-sized
/// scratch instead of a row-long buffer, and each window is written once: while segment h's windows
/// are completed by the running prefix sum of segment h + 1's terms, the same loop runs the suffix sum
/// of segment h + 1 from its end down, for the windows of the next step. The row's segments are cut
/// into two lanes (the first and second half) whose steps run interleaved: four independent chains.
/// Needs hi, lo to hold the phase up to k_end + 2m, k_end = out.len() + q − 1.
#[allow(clippy::too_many_arguments)]
pub(crate) fn hop1_row(
    hi: &[f64],
    lo: &[f64],
    m: usize,
    q: usize,
    norm: f64,
    avx2: bool,
    out: &mut [f64],
    scratch: &mut Vec<f64>,
) -> Range {
    let n = out.len();
    assert!(q >= 1 && n >= 1 && hi.len() + 1 >= n + q + 2 * m && lo.len() == hi.len());
    if q == 1 {
        crate::oavar::terms_dispatch(avx2, hi, lo, m, 0, norm, out);
        return Range::of(out);
    }
    let row = Row {
        hi,
        lo,
        m,
        q,
        norm,
        avx2,
        n,
    };
    // every buffer is written before it is read: only sized, never cleared
    if scratch.len() < 6 * q {
        scratch.resize(6 * q, 0.0);
    }
    let mut bufs = scratch[..6 * q].chunks_exact_mut(q);
    // the second lane starts at a segment boundary halfway through the row (none for one segment)
    let split = n.div_ceil(q) / 2 * q;
    let (oa, ob) = out.split_at_mut(split);
    let mut lanes = [(oa, 0), (ob, split)].map(|(out, base)| Lane {
        out,
        base,
        h0: base,
        t: bufs.next().expect("six buffers of q"),
        cur: bufs.next().expect("six buffers of q"),
        nxt: bufs.next().expect("six buffers of q"),
        range: Range::default(),
    });
    let [a, b] = &mut lanes;
    a.start(&row);
    b.start(&row);
    while a.full(&row) && b.full(&row) {
        step_pair(a, b, &row);
    }
    for l in [&mut *a, &mut *b] {
        while !l.done() {
            l.step(&row);
        }
    }
    a.range.merge(b.range)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::sliding_sums;
    use allanite_testutil::Lcg;

    use allanite_testutil::hashed_levels as blocks;

    /// The two-pass form and the head's addition, as the rows formed them before.
    fn two_pass(f: &[f64], q: usize, head: Option<&[f64]>, n: usize) -> Vec<f64> {
        let mut out = vec![f64::NAN; n];
        sliding_sums(f, q, &mut out);
        if let Some(h) = head {
            for (o, p) in out.iter_mut().zip(h) {
                *o += p;
            }
        }
        out
    }

    #[test]
    fn one_pass_sums_are_the_two_pass_sums_bit_for_bit_and_note_the_range() {
        let f = blocks(5000);
        let hd: Vec<f64> = blocks(5000).iter().map(|v| v * 0.37).collect();
        let mut scratch = Vec::new();
        for q in [1, 2, 3, 7, 64, 100, 333, 1000, 1249, 1250, 1251, 2500, 4999] {
            for n in [
                1,
                2,
                q - 1,
                q,
                q + 1,
                4 * q - 1,
                4 * q,
                4 * q + 1,
                8 * q,
                9 * q + 5,
            ] {
                if n == 0 || n + q - 1 > f.len() {
                    continue;
                }
                for head in [None, Some(&hd[..])] {
                    let want = two_pass(&f, q, head, n);
                    let mut got = vec![f64::NAN; n];
                    let r = sliding_sums_ranged(&f, q, head, &mut got, &mut scratch);
                    assert!(
                        got.iter()
                            .zip(&want)
                            .all(|(a, b)| a.to_bits() == b.to_bits()),
                        "q {q} n {n} head {}",
                        head.is_some()
                    );
                    assert_eq!(r, Range::of(&want), "q {q} n {n}");
                }
            }
        }
    }

    #[cfg(target_arch = "x86_64")]
    fn has_avx2() -> bool {
        std::arch::is_x86_feature_detected!("avx2")
    }

    #[cfg(not(target_arch = "x86_64"))]
    fn has_avx2() -> bool {
        false
    }

    /// The record's phase, as the dynamic phase path builds it.
    fn phase(n: usize, seed: u64) -> crate::oavar::Phase {
        let mut g = Lcg::new(seed.wrapping_mul(Lcg::MUL).wrapping_add(1));
        let y: Vec<f64> = (0..n)
            .map(|i| {
                let u = g.next_centered();
                // a loud first half, a quiet second one, on a large offset
                7000.0 + if i < n / 2 { u * 1e3 } else { u * 1e-3 }
            })
            .collect();
        let mu = crate::allan::compensated_mean(&y);
        crate::oavar::Phase::new(&y, mu)
    }

    #[test]
    fn hop1_rows_are_the_row_long_terms_summed_in_two_passes_bit_for_bit() {
        let ph = phase(3000, 7);
        let (hi, lo) = ph.parts();
        let mut scratch = Vec::new();
        // windows of 2 … 1201 samples: 1 to ~1500 segments per row, both lanes of every length
        for window in [2, 3, 9, 40, 101, 400, 1201] {
            for m in [1, 2, window / 3, window / 2]
                .into_iter()
                .filter(|&m| m >= 1 && 2 * m <= window)
            {
                let q = window + 1 - 2 * m;
                for n in [1, 2, q, q + 1, 2 * q, 3 * q - 1, 5 * q + 3, 3001 - window] {
                    if n == 0 || n + q - 1 + 2 * m > hi.len() - 1 || n > 3001 - window {
                        continue;
                    }
                    let norm = 1.0 / (2.0 * (m * m) as f64 * q as f64);
                    let mut terms = vec![0.0; n + q - 1];
                    crate::oavar::terms_dispatch(false, hi, lo, m, 0, norm, &mut terms);
                    let want = two_pass(&terms, q, None, n);
                    for avx2 in [false, has_avx2()] {
                        let mut got = vec![f64::NAN; n];
                        let r = hop1_row(hi, lo, m, q, norm, avx2, &mut got, &mut scratch);
                        assert!(
                            got.iter()
                                .zip(&want)
                                .all(|(a, b)| a.to_bits() == b.to_bits()),
                            "window {window} m {m} n {n} avx2 {avx2}"
                        );
                        assert_eq!(r, Range::of(&want), "window {window} m {m} n {n}");
                    }
                }
            }
        }
    }

    #[test]
    fn a_non_finite_block_is_noted() {
        let mut scratch = Vec::new();
        for bad in [f64::NAN, f64::INFINITY] {
            for at in [0, 17, 130, 299] {
                let mut f = blocks(300);
                f[at] = bad;
                for q in [1, 5, 40] {
                    let mut out = vec![0.0; 300 + 1 - q];
                    let r = sliding_sums_ranged(&f, q, None, &mut out, &mut scratch);
                    assert!(r.non_finite, "{bad} at {at}, q {q}");
                }
            }
        }
    }
}

//! The total variances (SP 1065 §5.2.11–5.2.14): TOTVAR on the evenly reflected rate, and MTOTVAR
//! and HTOTVAR, which detrend and reflect every 3m-point subsequence — in fixed chunks of
//! subsequences whose sums are combined in order (bit-identical for any number of threads); with a
//! gap count, only the complete terms or subsequences.

use super::{overlapping_value, sum_sq, Compensated, Kind, RUN, TERM_CHUNK};
use crate::allan::{sliding_sums, sum4};
use crate::cancel::Cancel;
use rayon::prelude::*;

/// TOTVAR (SP 1065 eq. 25):
///   Tot var(τ) = 1/(2 τ² (N−2)) Σ_{i=2}^{N−1} (x*_{i−m} − 2x*_i + x*_{i+m})²,
/// x* the phase extended by odd reflection about both end points, x*_{1−j} = 2x_1 − x_{1+j},
/// x*_{N+j} = 2x_N − x_{N−j}. On the rate this is the *even* reflection y*_{−1−j} = y_j,
/// y*_{M+j} = y_{M−1−j}, so every term is B*(p) − B*(p−m) over the extended rate, p = 1 … M−1.
pub(super) fn totvar_value(f: &[f64], m: usize) -> f64 {
    let (s, kept) = totvar_sum(f, m, None);
    let mf = m as f64;
    s / (2.0 * mf * mf * kept as f64)
}

/// Σ of the squared TOTVAR terms (block-sum differences, τ0 = 1) and their count. With `cnt` (the
/// prefix count of gaps, `f` holding 0 at a gap) only the complete terms: the term centred at p uses
/// the extended rate over [p − m, p + m), whose reflected parts mirror samples already inside
/// [max(0, p − m), min(M, p + m)) — so it is complete iff that original range holds no gap.
pub(super) fn totvar_sum(f: &[f64], m: usize, cnt: Option<&[u32]>) -> (f64, usize) {
    let mm = f.len();
    // y*_q for q = 1−m … M+m−2 (even reflection of the rate), generated per chunk of centres.
    let ext = |q: isize| -> f64 {
        if q < 0 {
            f[(-q - 1) as usize]
        } else if (q as usize) < mm {
            f[q as usize]
        } else {
            f[2 * mm - 1 - q as usize]
        }
    };
    let chunk = TERM_CHUNK.max(4 * m);
    let (mut z, mut b) = (Vec::new(), Vec::new());
    let mut acc = Compensated::default();
    let mut kept = 0usize;
    let mut p0 = 1;
    while p0 < mm {
        let c = chunk.min(mm - p0);
        // Centres p0 … p0+c−1 need B*(p − m) and B*(p): y* over [p0 − m, p0 + c − 1 + m).
        let lo = p0 as isize - m as isize;
        z.clear();
        z.extend((0..c + 2 * m - 1).map(|i| ext(lo + i as isize)));
        b.clear();
        b.resize(c + m, 0.0); // b[i] = B*(lo + i)
        sliding_sums(&z, m, &mut b);
        let t: Vec<f64> = match cnt {
            None => (0..c).map(|i| b[i + m] - b[i]).collect(),
            Some(cnt) => (0..c)
                .filter(|&i| {
                    let p = p0 + i;
                    cnt[(p + m).min(mm)] == cnt[p.saturating_sub(m)]
                })
                .map(|i| b[i + m] - b[i])
                .collect(),
        };
        kept += t.len();
        acc.add(sum_sq(&t));
        p0 += c;
    }
    (acc.value(), kept)
}

/// Subsequences per parallel chunk in MTOTVAR/HTOTVAR (fixed: results independent of threads).
pub(super) const SUB_CHUNK: usize = 256;

/// Scratch of one subsequence: compensated prefix sums of it and of its 9m-point reflection.
pub(super) struct TotScratch {
    u: Vec<f64>,
    p3h: Vec<f64>,
    p3l: Vec<f64>,
    ph: Vec<f64>,
    pl: Vec<f64>,
}

impl TotScratch {
    fn new(m: usize) -> Self {
        TotScratch {
            u: vec![0.0; 3 * m],
            p3h: vec![0.0; 3 * m + 1],
            p3l: vec![0.0; 3 * m + 1],
            ph: vec![0.0; 9 * m + 1],
            pl: vec![0.0; 9 * m + 1],
        }
    }

    /// Removes the half-average slope from `u` (3m values), reflects it to 9m values and returns
    /// Σ_{j=0}^{6m−1} (s1 − 2s2 + s3)², s1..s3 the consecutive m-sums starting at j.
    ///
    /// Slope (SP 1065 §5.2.12 step 1, as Stable32 and allantools): the means of the first ⌊3m/2⌋ and
    /// the last ⌊3m/2⌋ values, divided by their distance ⌈3m/2⌉.
    fn reflected_square_sum(&mut self, m: usize) -> f64 {
        let n3 = 3 * m;
        let (h1, h2) = (n3 / 2, n3.div_ceil(2));
        let u = &mut self.u;
        let mean1 = sum4(&u[..h1]) / h1 as f64;
        let mean2 = sum4(&u[h2..]) / (n3 - h2) as f64;
        let slope = (mean2 - mean1) / h2 as f64;
        // Centre the ramp on the subsequence so the detrended values stay small.
        let c = (n3 - 1) as f64 / 2.0;
        let centre = sum4(u) / n3 as f64;
        for (k, v) in u.iter_mut().enumerate() {
            *v = (*v - centre) - slope * (k as f64 - c);
        }
        // Prefix sums P(t) = Σ_{s<t} u_s of the detrended subsequence as an unevaluated pair
        // (hi + lo, TwoSum): block sums by differences of nearby prefixes lose nothing to the
        // prefix's magnitude. Only 3m serial steps; the reflected record is never built.
        let (p3h, p3l) = (&mut self.p3h, &mut self.p3l);
        p3h[0] = 0.0;
        p3l[0] = 0.0;
        let (mut s, mut e) = (0.0f64, 0.0f64);
        for (i, &v) in u.iter().enumerate() {
            let t = s + v;
            let bp = t - s;
            e += (s - (t - bp)) + (v - bp);
            s = t;
            p3h[i + 1] = s;
            p3l[i + 1] = e;
        }
        // Prefix sums Q of the uninverted even reflection [rev(u), u, rev(u)] (9m values), from P:
        //   Q(t) = T − P(3m − t) (t ≤ 3m),  T + P(t − 3m) (3m ≤ t ≤ 6m),  3T − P(9m − t) (t ≥ 6m),
        // T = P(3m) ≈ 0 (u is centred and its ramp removed), so no large value enters a difference.
        let (th, tl) = (p3h[n3], p3l[n3]);
        let (ph, pl) = (&mut self.ph, &mut self.pl);
        for t in 0..=n3 {
            ph[t] = th - p3h[n3 - t];
            pl[t] = tl - p3l[n3 - t];
            ph[n3 + t] = th + p3h[t];
            pl[n3 + t] = tl + p3l[t];
            ph[3 * n3 - t] = 3.0 * th - p3h[t];
            pl[3 * n3 - t] = 3.0 * tl - p3l[t];
        }
        // z_j·m = Q(j+3m) − 3Q(j+2m) + 3Q(j+m) − Q(j), j < 6m; squares summed in runs of RUN with
        // four accumulators (independent chains), the runs with compensation.
        let mut acc = Compensated::default();
        let mut buf = [0.0f64; RUN];
        let mut j0 = 0;
        while j0 < 2 * n3 {
            let c = RUN.min(2 * n3 - j0);
            let (a0, a1, a2, a3) = (
                &ph[j0..],
                &ph[j0 + m..],
                &ph[j0 + 2 * m..],
                &ph[j0 + 3 * m..],
            );
            let (b0, b1, b2, b3) = (
                &pl[j0..],
                &pl[j0 + m..],
                &pl[j0 + 2 * m..],
                &pl[j0 + 3 * m..],
            );
            for (i, z2) in buf[..c].iter_mut().enumerate() {
                let hi = (a3[i] - a0[i]) - 3.0 * (a2[i] - a1[i]);
                let lo = (b3[i] - b0[i]) - 3.0 * (b2[i] - b1[i]);
                let z = hi + lo;
                *z2 = z * z;
            }
            acc.add(sum4(&buf[..c]));
            j0 += c;
        }
        acc.value()
    }
}

/// MTOTVAR (SP 1065 eq. 27, Howe & Vernotte):
///   Mod Totvar(τ) = 1/(2 τ² (N−3m+1)) Σ_{n=1}^{N−3m+1} { 1/(6m) Σ_{i=n−3m}^{n+3m−1} [z#_i(m)]² },
///   z#_i(m) = (1/m) Σ_{j=i}^{i+m−1} (x#_{j+2m} − 2x#_{j+m} + x#_j),
/// x# the 3m-point phase subsequence x_n … x_{n+3m−1}, its half-average slope removed, extended to 9m
/// points by uninverted even reflection. No bias correction (Stable32 divides by a noise-dependent
/// factor; see tests/test_deviations_core.py).
pub(super) fn mtotvar_value(f: &[f64], m: usize, cancel: &Cancel) -> f64 {
    mtotvar_gap(f, m, None, cancel).0
}

/// MTOTVAR and its count of subsequences; with `cnt` (prefix count of gaps) only the subsequences
/// whose 3m − 1 rate samples hold no gap (NaN with no complete subsequence).
pub(super) fn mtotvar_gap(f: &[f64], m: usize, cnt: Option<&[u32]>, cancel: &Cancel) -> (f64, u64) {
    let l = f.len() + 2 - 3 * m;
    let n3 = 3 * m;
    let (total, kept) = chunked_sum(l, m, cancel, |sc, n| {
        if let Some(c) = cnt {
            if c[n + n3 - 1] != c[n] {
                return None;
            }
        }
        // Local phase: x_{n+k} − x_n = Σ_{i<k} f_{n+i}, summed from the subsequence's own samples.
        let mut x = 0.0;
        sc.u[0] = 0.0;
        for k in 1..n3 {
            x += f[n + k - 1];
            sc.u[k] = x;
        }
        Some(sc.reflected_square_sum(m))
    });
    let mf = m as f64;
    // Σ (S/m)²/(6m) / (2 m² L): S the block-sum second difference in phase units (τ0 = 1).
    let v = total / (mf * mf) / (6.0 * mf) / (2.0 * mf * mf * kept as f64);
    (if kept == 0 { f64::NAN } else { v }, kept as u64)
}

/// HTOTVAR (SP 1065 eq. 30, Howe et al.):
///   Htotvar(τ) = 1/(6 (M−3m+1)) Σ_{n=1}^{M−3m+1} { 1/(6m) Σ_{i=n−3m}^{n+3m−1} [H_i(m)]² },
///   H_i(m) = ȳ#_{i+2m}(m) − 2ȳ#_{i+m}(m) + ȳ#_i(m)   (m-sample averages),
/// y# the 3m-sample frequency subsequence y_n … y_{n+3m−1}, half-average slope removed, extended to
/// 9m samples by uninverted even reflection. At m = 1 it is OHVAR (Riley: "for best consistency";
/// Stable32 and allantools do the same). No bias correction.
pub(super) fn htotvar_value(f: &[f64], m: usize, cancel: &Cancel) -> f64 {
    if m == 1 {
        return overlapping_value(Kind::Ohvar, f, 1);
    }
    htotvar_gap(f, m, None, cancel).0
}

/// HTOTVAR (m ≥ 2) and its count of subsequences; with `cnt` only those whose 3m rate samples hold no
/// gap.
pub(super) fn htotvar_gap(f: &[f64], m: usize, cnt: Option<&[u32]>, cancel: &Cancel) -> (f64, u64) {
    let l = f.len() + 1 - 3 * m;
    let n3 = 3 * m;
    let (total, kept) = chunked_sum(l, m, cancel, |sc, n| {
        if let Some(c) = cnt {
            if c[n + n3] != c[n] {
                return None;
            }
        }
        sc.u.copy_from_slice(&f[n..n + n3]);
        Some(sc.reflected_square_sum(m))
    });
    let mf = m as f64;
    let v = total / (mf * mf) / (6.0 * mf) / (6.0 * kept as f64);
    (if kept == 0 { f64::NAN } else { v }, kept as u64)
}

/// Σ_{n<l} g(n) over fixed chunks of subsequences, in parallel; chunk totals added in order. A
/// subsequence for which `g` returns None (it touches a gap) is skipped; returns (Σ, count kept).
pub(super) fn chunked_sum(
    l: usize,
    m: usize,
    cancel: &Cancel,
    g: impl Fn(&mut TotScratch, usize) -> Option<f64> + Sync,
) -> (f64, usize) {
    let parts: Vec<(f64, usize)> = (0..l.div_ceil(SUB_CHUNK))
        .into_par_iter()
        .map_init(
            || TotScratch::new(m),
            |sc, c| {
                if cancel.is_cancelled() {
                    return (0.0, 0); // the caller checks the flag and discards the value
                }
                let mut acc = Compensated::default();
                let mut kept = 0;
                for n in c * SUB_CHUNK..((c + 1) * SUB_CHUNK).min(l) {
                    if let Some(v) = g(sc, n) {
                        acc.add(v);
                        kept += 1;
                    }
                }
                (acc.value(), kept)
            },
        )
        .collect();
    let mut acc = Compensated::default();
    let mut kept = 0;
    for (p, k) in parts {
        acc.add(p);
        kept += k;
    }
    (acc.value(), kept)
}

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

use crate::allan::{
    block_window_sums, check_shape, check_window_hop, compensated_mean, sliding_sums, sum4,
};
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

/// Neumaier-compensated accumulator.
#[derive(Default, Clone, Copy, Debug)]
pub(crate) struct Acc {
    s: f64,
    c: f64,
}

impl Acc {
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
    pub(crate) fn get(self) -> f64 {
        self.s + self.c
    }
}

const RUN: usize = 512;

/// Σ v² in runs of `RUN` (four accumulators each), runs combined with compensation.
fn sum_sq(v: &[f64]) -> f64 {
    let mut acc = Acc::default();
    let mut buf = [0.0f64; RUN];
    for chunk in v.chunks(RUN) {
        for (b, x) in buf.iter_mut().zip(chunk) {
            *b = x * x;
        }
        acc.add(sum4(&buf[..chunk.len()]));
    }
    acc.get()
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
    let mut acc = Acc::default();
    for_each_term_chunk(kind, f, m, &mut TermBuf::default(), |_, t| {
        acc.add(sum_sq(t))
    });
    acc.get() * scale / (f.len() + 1 - span) as f64
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

/// TOTVAR (SP 1065 eq. 25):
///   Tot var(τ) = 1/(2 τ² (N−2)) Σ_{i=2}^{N−1} (x*_{i−m} − 2x*_i + x*_{i+m})²,
/// x* the phase extended by odd reflection about both end points, x*_{1−j} = 2x_1 − x_{1+j},
/// x*_{N+j} = 2x_N − x_{N−j}. On the rate this is the *even* reflection y*_{−1−j} = y_j,
/// y*_{M+j} = y_{M−1−j}, so every term is B*(p) − B*(p−m) over the extended rate, p = 1 … M−1.
fn totvar_value(f: &[f64], m: usize) -> f64 {
    let (s, kept) = totvar_sum(f, m, None);
    let mf = m as f64;
    s / (2.0 * mf * mf * kept as f64)
}

/// Σ of the squared TOTVAR terms (block-sum differences, τ0 = 1) and their count. With `cnt` (the
/// prefix count of gaps, `f` holding 0 at a gap) only the complete terms: the term centred at p uses
/// the extended rate over [p − m, p + m), whose reflected parts mirror samples already inside
/// [max(0, p − m), min(M, p + m)) — so it is complete iff that original range holds no gap.
fn totvar_sum(f: &[f64], m: usize, cnt: Option<&[u32]>) -> (f64, usize) {
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
    let mut acc = Acc::default();
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
    (acc.get(), kept)
}

/// Subsequences per parallel chunk in MTOTVAR/HTOTVAR (fixed: results independent of threads).
const SUB_CHUNK: usize = 256;

/// Scratch of one subsequence: compensated prefix sums of it and of its 9m-point reflection.
struct TotScratch {
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
        let mut acc = Acc::default();
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
        acc.get()
    }
}

/// MTOTVAR (SP 1065 eq. 27, Howe & Vernotte):
///   Mod Totvar(τ) = 1/(2 τ² (N−3m+1)) Σ_{n=1}^{N−3m+1} { 1/(6m) Σ_{i=n−3m}^{n+3m−1} [z#_i(m)]² },
///   z#_i(m) = (1/m) Σ_{j=i}^{i+m−1} (x#_{j+2m} − 2x#_{j+m} + x#_j),
/// x# the 3m-point phase subsequence x_n … x_{n+3m−1}, its half-average slope removed, extended to 9m
/// points by uninverted even reflection. No bias correction (Stable32 divides by a noise-dependent
/// factor; see tests/test_deviations_core.py).
fn mtotvar_value(f: &[f64], m: usize, cancel: &Cancel) -> f64 {
    mtotvar_gap(f, m, None, cancel).0
}

/// MTOTVAR and its count of subsequences; with `cnt` (prefix count of gaps) only the subsequences
/// whose 3m − 1 rate samples hold no gap (NaN with no complete subsequence).
fn mtotvar_gap(f: &[f64], m: usize, cnt: Option<&[u32]>, cancel: &Cancel) -> (f64, u64) {
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
fn htotvar_value(f: &[f64], m: usize, cancel: &Cancel) -> f64 {
    if m == 1 {
        return overlapping_value(Kind::Ohvar, f, 1);
    }
    htotvar_gap(f, m, None, cancel).0
}

/// HTOTVAR (m ≥ 2) and its count of subsequences; with `cnt` only those whose 3m rate samples hold no
/// gap.
fn htotvar_gap(f: &[f64], m: usize, cnt: Option<&[u32]>, cancel: &Cancel) -> (f64, u64) {
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
fn chunked_sum(
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
                let mut acc = Acc::default();
                let mut kept = 0;
                for n in c * SUB_CHUNK..((c + 1) * SUB_CHUNK).min(l) {
                    if let Some(v) = g(sc, n) {
                        acc.add(v);
                        kept += 1;
                    }
                }
                (acc.get(), kept)
            },
        )
        .collect();
    let mut acc = Acc::default();
    let mut kept = 0;
    for (p, k) in parts {
        acc.add(p);
        kept += k;
    }
    (acc.get(), kept)
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
    let prepared: Vec<(Vec<f64>, Vec<u32>)> = columns
        .par_iter()
        .map(|c| {
            // Prefix count of gaps: a span [a, a+s) is complete iff cnt[a+s] == cnt[a] (exact).
            let mut cnt = Vec::with_capacity(c.len() + 1);
            cnt.push(0u32);
            let mut k = 0u32;
            for v in c.iter() {
                k += v.is_nan() as u32;
                cnt.push(k);
            }
            (centred(c), cnt)
        })
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
    let (mut acc, mut kept) = (Acc::default(), 0usize);
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
        (acc.get() * scale / kept as f64, kept as u64)
    }
}

/// MTIE (ITU-T G.810 §B.2, SP 1065 §5.2.15) of each *phase* record at window m: the largest
/// peak-to-peak phase excursion over all windows of m + 1 consecutive points,
///   MTIE(m) = max_{k=0}^{N−1−m} ( max_{k≤i≤k+m} x_i − min_{k≤i≤k+m} x_i ),  1 ≤ m ≤ N − 1.
/// Computed by Van Herk / Gil-Werman running max/min (exact: no arithmetic but comparisons).
/// [axis][m]. No mean or drift is removed (TIE includes the frequency offset).
pub fn mtie(phases: &[&[f64]], ms: &[usize]) -> Result<Vec<f64>> {
    let n = check_phase(phases, ms, "MTIE")?;
    let n_m = ms.len();
    Ok((0..phases.len() * n_m)
        .into_par_iter()
        .map(|row| {
            let (x, w) = (phases[row / n_m], ms[row % n_m] + 1);
            let hi = running_extreme(x, w, f64::max);
            let lo = running_extreme(x, w, f64::min);
            debug_assert_eq!(hi.len(), n + 1 - w);
            hi.iter()
                .zip(&lo)
                .map(|(a, b)| a - b)
                .fold(0.0f64, f64::max)
        })
        .collect())
}

/// TIE rms (ITU-T G.810 §B.3; Stable32 TIErms) of each *phase* record:
///   TIErms(m) = sqrt( 1/(N−m) Σ_{i=0}^{N−1−m} (x_{i+m} − x_i)² ),  1 ≤ m ≤ N − 1. [axis][m]
pub fn tie_rms(phases: &[&[f64]], ms: &[usize]) -> Result<Vec<f64>> {
    check_phase(phases, ms, "TIE rms")?;
    let n_m = ms.len();
    Ok((0..phases.len() * n_m)
        .into_par_iter()
        .map(|row| {
            let (x, m) = (phases[row / n_m], ms[row % n_m]);
            let d: Vec<f64> = x[m..].iter().zip(x).map(|(a, b)| a - b).collect();
            (sum_sq(&d) / d.len() as f64).sqrt()
        })
        .collect())
}

/// Gap-aware MTIE (`mtie` true) or TIE rms of phase records built from rate samples with gaps:
/// `gaps[a]` is axis a's prefix count of missing *rate* samples (length N), the phase holding any
/// finite value where its offset is unknown. A window of phase points [k, k + m] (MTIE) or a
/// difference x_{k+m} − x_k (TIE) is kept iff its rate samples [k, k + m) are all present — then its
/// phase differences are exact whatever offset a gap before it left. Returns (values [axis][m], kept
/// windows [axis][m]); NaN and 0 where none is complete.
pub fn tie_gaps(
    phases: &[&[f64]],
    gaps: &[&[u64]],
    ms: &[usize],
    mtie: bool,
) -> Result<(Vec<f64>, Vec<u64>)> {
    let n = check_phase(phases, ms, if mtie { "MTIE" } else { "TIE rms" })?;
    if gaps.len() != phases.len() || gaps.iter().any(|g| g.len() != n) {
        return Err(CoreError::InvalidParameter(format!(
            "gap counts must be one array of {n} values per axis ({} axes)",
            phases.len()
        )));
    }
    let n_m = ms.len();
    let res: Vec<(f64, u64)> = (0..phases.len() * n_m)
        .into_par_iter()
        .map(|row| {
            let (x, g, m) = (phases[row / n_m], gaps[row / n_m], ms[row % n_m]);
            let complete = |k: usize| g[k + m] == g[k];
            let (value, kept) = if mtie {
                let hi = running_extreme(x, m + 1, f64::max);
                let lo = running_extreme(x, m + 1, f64::min);
                let mut best = 0.0f64;
                let mut kept = 0u64;
                for (k, (a, b)) in hi.iter().zip(&lo).enumerate() {
                    if complete(k) {
                        best = best.max(a - b);
                        kept += 1;
                    }
                }
                (best, kept)
            } else {
                let d: Vec<f64> = (0..n - m)
                    .filter(|&k| complete(k))
                    .map(|k| x[k + m] - x[k])
                    .collect();
                let kept = d.len() as u64;
                ((sum_sq(&d) / kept as f64).sqrt(), kept)
            };
            if kept == 0 {
                (f64::NAN, 0)
            } else {
                (value, kept)
            }
        })
        .collect();
    Ok(res.into_iter().unzip())
}

fn check_phase(phases: &[&[f64]], ms: &[usize], what: &str) -> Result<usize> {
    let n = check_shape(phases)?;
    check_values(phases, false)?;
    if ms.is_empty() {
        return Err(CoreError::InvalidParameter(
            "no averaging factors given".into(),
        ));
    }
    if let Some(&m) = ms.iter().find(|&&m| m == 0 || m >= n) {
        return Err(CoreError::InvalidParameter(format!(
            "{what} interval m = {m} is outside 1..={} allowed for a phase record of {n} points",
            n - 1
        )));
    }
    Ok(n)
}

/// op-extreme of every window of w consecutive values (Van Herk / Gil-Werman: 3 comparisons each).
fn running_extreme(x: &[f64], w: usize, op: fn(f64, f64) -> f64) -> Vec<f64> {
    let n = x.len();
    let mut suf = x.to_vec();
    let mut pre = x.to_vec();
    let mut s = 0;
    while s < n {
        let e = (s + w).min(n);
        for i in s + 1..e {
            pre[i] = op(pre[i - 1], x[i]);
        }
        for i in (s..e - 1).rev() {
            suf[i] = op(suf[i + 1], x[i]);
        }
        s += w;
    }
    (0..n + 1 - w)
        .map(|k| {
            if k % w == 0 {
                suf[k]
            } else {
                op(suf[k], pre[k + w - 1])
            }
        })
        .collect()
}

/// Dynamic overlapping Hadamard variance: OHVAR of every window of `window` rate samples starting
/// every `hop` samples, at every m (1 ≤ 3m ≤ window). Returns (values [axis][m][window], windows).
///
/// Design as `allan.rs`'s DAVAR: the terms a(i) = (B(i+2m) − 2B(i+m) + B(i))² / (6m²L) are formed
/// once per m from local block sums, summed in hop-aligned blocks, and every window's sum is made of
/// whole blocks by Van Herk sliding sums over the block array plus one partial block — sums of
/// non-negative numbers only, no running subtraction, so no drift along the record. The Hadamard
/// variance ignores a constant and a linear rate, so one record-wide mean serves every window.
pub fn dynamic_ohvar(
    columns: &[&[f64]],
    window: usize,
    hop: usize,
    ms: &[usize],
) -> Result<(Vec<f64>, usize)> {
    let n = check_shape(columns)?;
    check_window_hop(window, hop, n, 3)?;
    check_ms(Kind::Ohvar, window, ms, "window")?;
    check_values(columns, false)?;
    let n_win = (n - window) / hop + 1;
    let n_m = ms.len();
    let centred: Vec<Vec<f64>> = columns.par_iter().map(|c| centred(c)).collect();
    let mut out = vec![0.0; columns.len() * n_m * n_win];
    out.par_chunks_mut(n_win)
        .enumerate()
        .for_each(|(row, dst)| {
            let (f, m) = (&centred[row / n_m], ms[row % n_m]);
            let l = window + 1 - 3 * m;
            let k_end = (n_win - 1) * hop + l;
            let (_, scale) = span_scale(Kind::Ohvar, m);
            let mut t = Vec::with_capacity(k_end);
            let mut tb = TermBuf::default();
            for_each_term_chunk(Kind::Ohvar, &f[..k_end + 3 * m - 1], m, &mut tb, |_, c| {
                t.extend_from_slice(c)
            });
            let norm = scale / l as f64;
            let hop_b = if n_win == 1 { l } else { hop };
            let (q, r) = (l / hop_b, l % hop_b);
            let nblocks = n_win + q;
            let mut full = vec![0.0; nblocks];
            let mut part = vec![0.0; nblocks];
            let mut buf = Vec::with_capacity(hop_b.min(RUN));
            for (b, blk) in t[..k_end].chunks(hop_b).enumerate() {
                let mut acc = Acc::default();
                let mut pacc = Acc::default();
                for (c, sub) in blk.chunks(RUN).enumerate() {
                    buf.clear();
                    buf.extend(sub.iter().map(|v| v * v * norm));
                    acc.add(sum4(&buf));
                    // The partial block: the first r terms of the block.
                    let lo = c * RUN;
                    if lo < r {
                        pacc.add(sum4(&buf[..(r - lo).min(buf.len())]));
                    }
                }
                full[b] = acc.get();
                part[b] = pacc.get();
            }
            block_window_sums(&full, &part, (q, r), (0, n_win), dst);
        });
    Ok((out, n_win))
}

/// Gap-aware dynamic OAVAR or OHVAR: the estimate of every window of `window` samples, `hop` apart,
/// from the terms inside the window whose span holds no NaN (as [`gap_deviation`] on that window
/// alone). Returns (values [axis][m][window], complete-term counts [axis][m][window], windows); a
/// window with no complete term at some m gives NaN and 0 there.
///
/// The same scheme as [`dynamic_ohvar`]: the record's terms are formed once per (axis, m), their
/// squares (0 for an incomplete term) summed per block of `hop` terms with compensation, each window's
/// sum the Van Herk sliding sum of whole blocks plus the partial block — sums of non-negative values of
/// the window's own terms only, so a level change of 10⁶ elsewhere costs nothing. The counts are exact
/// integer prefix differences. Memory per running (axis, m) task: the record's terms (8 bytes each)
/// and their prefix count (8 bytes each).
pub fn gap_dynamic(
    columns: &[&[f64]],
    window: usize,
    hop: usize,
    ms: &[usize],
    kind: Kind,
    cancel: &Cancel,
) -> Result<(Vec<f64>, Vec<u64>, usize)> {
    if !matches!(kind, Kind::Oavar | Kind::Ohvar) {
        return Err(CoreError::InvalidParameter(format!(
            "gap-aware sliding-window estimation is available for OAVAR and OHVAR, not {}",
            kind.name()
        )));
    }
    let n = check_shape(columns)?;
    check_window_hop(window, hop, n, 2)?;
    check_ms(kind, window, ms, "window")?;
    check_values(columns, true)?;
    let n_win = (n - window) / hop + 1;
    let n_m = ms.len();
    let prepared: Vec<(Vec<f64>, Vec<u32>)> = columns
        .par_iter()
        .map(|c| {
            let mut cnt = Vec::with_capacity(c.len() + 1);
            cnt.push(0u32);
            let mut k = 0u32;
            for v in c.iter() {
                k = k.wrapping_add(v.is_nan() as u32);
                cnt.push(k);
            }
            (centred(c), cnt)
        })
        .collect();
    let mut out = vec![0.0; columns.len() * n_m * n_win];
    let mut counts = vec![0u64; columns.len() * n_m * n_win];
    out.par_chunks_mut(n_win)
        .zip(counts.par_chunks_mut(n_win))
        .enumerate()
        .for_each(|(row, (dst, dcnt))| {
            if cancel.is_cancelled() {
                return;
            }
            let ((f, gap), m) = (&prepared[row / n_m], ms[row % n_m]);
            let (span, scale) = span_scale(kind, m);
            let l = window + 1 - span; // terms per window
            let k_end = (n_win - 1) * hop + l; // terms used by some window
                                               // squares of the complete terms (0 otherwise) and the prefix count of complete terms;
                                               // a gap count that wrapped (≥ 2³² NaN) still differs across a span holding a NaN unless
                                               // the span holds exactly 2³² of them, which a span of < 2³² samples cannot
            let mut t = Vec::with_capacity(k_end);
            let mut done = vec![0u64; k_end + 1];
            let mut tb = TermBuf::default();
            for_each_term_chunk(kind, &f[..k_end + span - 1], m, &mut tb, |k0, c| {
                for (i, v) in c.iter().enumerate() {
                    let k = k0 + i;
                    let ok = gap[k + span] == gap[k];
                    t.push(if ok { v * v } else { 0.0 });
                    done[k + 1] = done[k] + ok as u64;
                }
            });
            for (j, o) in dcnt.iter_mut().enumerate() {
                *o = done[j * hop + l] - done[j * hop];
            }
            let hop_b = if n_win == 1 { l } else { hop };
            let (q, r) = (l / hop_b, l % hop_b);
            let nblocks = n_win + q;
            let mut full = vec![0.0; nblocks];
            let mut part = vec![0.0; nblocks];
            for (b, blk) in t[..k_end].chunks(hop_b).enumerate() {
                let mut acc = Acc::default();
                let mut pacc = Acc::default();
                for (c, sub) in blk.chunks(RUN).enumerate() {
                    acc.add(sum4(sub));
                    let lo = c * RUN;
                    if lo < r {
                        pacc.add(sum4(&sub[..(r - lo).min(sub.len())]));
                    }
                }
                full[b] = acc.get();
                part[b] = pacc.get();
            }
            block_window_sums(&full, &part, (q, r), (0, n_win), dst);
            for (o, &c) in dst.iter_mut().zip(dcnt.iter()) {
                *o = if c == 0 {
                    f64::NAN
                } else {
                    *o * scale / c as f64
                };
            }
        });
    cancel.check()?;
    Ok((out, counts, n_win))
}

//! The static overlapping Allan variance (one window: the whole record) from one double-word phase
//! prefix, every τ in one pass over the record.
//!
//! At factor m the estimator is Σ_k d_k² / (2 m² L), d_k = P_{k+2m} − 2 P_{k+m} + P_k, L = W + 1 − 2m,
//! with P_j = Σ_{i<j} (y_i − μ) the phase. The streaming path ([`crate::allan`]) forms the block sums
//! of every m from the samples, one m at a time: two running-sum passes per m, the record read once
//! per τ. Here the phase is built once per axis and every term of every m is three reads of it.
//!
//! # Why the phase does not drift
//! A plain f64 prefix carries an absolute error ~ε·max|P| into every d: a quiet stretch after a loud
//! one, or small noise on a slow large swing of the rate, loses its digits. P is kept as hi + lo:
//! hi the running f64 sum, lo the running sum of the exact rounding errors of hi (Knuth's TwoSum),
//! built in fixed blocks, each started from its double-word offset (the blocks' totals are summed
//! first, in parallel, and scanned in double words), each pair stored normalised (|lo| ≲ ½ ulp(hi)).
//! Its error is ~ε²·(samples)·max|P|, i.e. ≲ 10⁻²⁵·max|P| for 10⁸ samples. μ is the window's mean
//! from the same blocks' double-word total (that pass is also the finite check).
//!
//! A term is then d = [(hi₂ − hi₁) − (hi₁ − hi₀)] + [(lo₂ − lo₁) − (lo₁ − lo₀)]. The differences of
//! hi are rounded once each: hi₂ − hi₁ is the block sum B_{k+m} (to within the lo parts), so the
//! error of d is ≲ ε·(|B_k| + |B_{k+m}| + |d|) + O(ε²·max|P|) — relative to the term's own block sums,
//! never to the rest of the record. The terms d² ≥ 0 are summed without cancellation.
//!
//! # Single words where they are provably enough
//! Dropping lo halves the reads and the arithmetic, and costs each term at most 4ε·max|hi| + 4·max|lo|
//! over the pairs it reads (+ ε|d|) — small against the terms unless the phase is far larger than
//! they are. Each (chunk, m) partial sum is therefore first formed from hi alone and kept only if a
//! rigorous bound on its difference from the double-word sum, from the chunk's largest |hi| and |lo|
//! (recorded while the phase is built), is within 10⁻¹¹ of it ([`single_word_holds`]); otherwise the
//! chunk is summed in double words. White noise of 10⁷ samples passes everywhere; a quiet stretch
//! after a loud one, a steep ramp of the rate or a random-walk rate fall back where they need to
//! (the unit test `single_word_partials_stand_for_the_double_word_ones` checks every partial of such
//! records against the double-word one).
//!
//! # Speed
//! The record is cut into chunks of `CHUNK` terms; a chunk computes its partial sums for every m,
//! so the phase values at k (and, for short m, at k + m and k + 2m) are read from cache by every τ.
//! The term loop is written over `LANES` independent partial sums in `chunks_exact` so that it
//! compiles to packed vector operations (AVX2 where the CPU has it, chosen at run time; the same
//! IEEE operations in the same order either way, so the bits do not depend on it).
//!
//! # Bit-identical for any thread count
//! Block and chunk boundaries depend on the record length only; each chunk's partial sums are
//! formed by one sequential routine (whose single- or double-word choice depends on the data and
//! that grid only), and the partials are added in chunk order.

use crate::allan::block_window_sums;
use crate::cancel::Cancel;
use crate::gather::two_sum;
use crate::range::Range;
use rayon::prelude::*;

/// Samples per block of the phase build.
const BLOCK: usize = 1 << 16;
/// Terms per chunk of the term pass.
const CHUNK: usize = 1 << 13;
/// Chunks per super-chunk (one rayon task).
const SUPER: usize = 16;
/// Factors up to this run chunk by chunk inside a super-chunk, longer ones factor by factor.
const SHORT_M: usize = CHUNK / 2;
/// Independent partial sums per chunk and m (the vector width the term loop is written for).
const LANES: usize = 8;

/// The double-word total of `src − μ` (each fl(v − μ) as the prefix pass rounds it), in `LANES`
/// independent TwoSum accumulators so that it vectorises; their exact errors are kept and the lanes
/// are joined with TwoSum. Error ≲ ε²·len·Σ|v − μ|.
#[inline(always)]
fn block_total(src: &[f64], mu: f64) -> (f64, f64) {
    let mut s = [0.0f64; LANES];
    let mut c = [0.0f64; LANES];
    let body = src.chunks_exact(LANES);
    let tail = body.remainder();
    for v in body {
        for j in 0..LANES {
            let (t, e) = two_sum(s[j], v[j] - mu);
            s[j] = t;
            c[j] += e;
        }
    }
    for (j, &v) in tail.iter().enumerate() {
        let (t, e) = two_sum(s[j], v - mu);
        s[j] = t;
        c[j] += e;
    }
    let (mut th, mut tl) = (0.0f64, 0.0f64);
    for j in 0..LANES {
        let (t, e) = two_sum(th, s[j]);
        th = t;
        tl += e + c[j];
    }
    (th, tl)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn block_total_avx2(src: &[f64], mu: f64) -> (f64, f64) {
    block_total(src, mu)
}

pub(crate) fn block_total_dispatch(src: &[f64], mu: f64) -> (f64, f64) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has the feature the function is compiled for (checked just above).
        return unsafe { block_total_avx2(src, mu) };
    }
    block_total(src, mu)
}

/// The phase of one block from its double-word offset (oh, ol): running TwoSum of fl(v − μ) from
/// s = oh with the exact errors summed in c (from ol), each (s, c) stored normalised (|l| ≤ ½ ulp(h):
/// hi alone is the phase rounded once). Returns, into `maxima`, the largest |h| and
/// |l| of each run of `CHUNK` pairs (the bounds the single-word term pass checks itself against, see
/// [`single_word_holds`]).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn block_phase(
    src: &[f64],
    mu: f64,
    oh: f64,
    ol: f64,
    h: &mut [f64],
    l: &mut [f64],
    maxima: &mut [(f64, f64)],
) {
    let (mut s, mut c) = (oh, ol);
    for (((hc, lc), yc), mx) in h
        .chunks_mut(CHUNK)
        .zip(l.chunks_mut(CHUNK))
        .zip(src.chunks(CHUNK))
        .zip(maxima.iter_mut())
    {
        let (mut mh, mut ml) = (0.0f64, 0.0f64);
        for ((hv, lv), &v) in hc.iter_mut().zip(lc.iter_mut()).zip(yc) {
            let (t, e) = two_sum(s, v - mu);
            s = t;
            c += e;
            // Fast2Sum (|c| ≪ |s| but where s crosses zero; there the pair is off by ≲ ε·|c|, far
            // below the phase's own error): hi = the phase rounded once
            let p = s + c;
            let q = c - (p - s);
            *hv = p;
            *lv = q;
            // plain compares (maxsd): the samples are finite, so NaN needs no care here
            mh = if p.abs() > mh { p.abs() } else { mh };
            ml = if q.abs() > ml { q.abs() } else { ml };
        }
        *mx = (mh, ml);
    }
}

/// Exclusive scan of blocks' double-word totals in double-word arithmetic (sequential, one step per
/// block): each block's offset, the phase at its first sample.
pub(crate) fn block_offsets(totals: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut offs = Vec::with_capacity(totals.len());
    let (mut oh, mut ol) = (0.0f64, 0.0f64);
    for &(s, c) in totals {
        offs.push((oh, ol));
        let (t, e) = two_sum(oh, s);
        let low = e + (ol + c);
        let h = t + low;
        ol = low - (h - t);
        oh = h;
    }
    offs
}

/// The centring value of one static window and its finite check, in one parallel pass: the mean
/// from the double-word total of fixed blocks (joined in block order, so the same bits for any
/// thread count). A sample that is NaN or ±inf makes the total non-finite and is then located.
pub(crate) fn centre(y: &[f64], axis: usize) -> crate::Result<f64> {
    let totals: Vec<(f64, f64)> = y
        .par_chunks(BLOCK)
        .map(|src| block_total_dispatch(src, 0.0))
        .collect();
    let (mut th, mut tl) = (0.0f64, 0.0f64);
    for &(s, c) in &totals {
        let (t, e) = two_sum(th, s);
        th = t;
        tl += e + c;
    }
    let total = th + tl;
    if !total.is_finite() {
        if let Some(index) = y.iter().position(|v| !v.is_finite()) {
            return Err(crate::CoreError::NonFinite {
                axis,
                index,
                value: y[index],
            });
        }
        // finite samples whose sum overflows: the sequential compensated mean, as elsewhere
        return Ok(crate::allan::compensated_mean(y));
    }
    Ok(total / y.len() as f64)
}

/// The phase of `y − μ` as hi[j] + lo[j], j = 0 … y.len() (hi, lo of length y.len() + 1; P_0 = 0),
/// each pair normalised (|lo| ≤ ½ ulp(hi)). Returns the largest |hi| and |lo| over the pairs
/// 1 + c·CHUNK ..= (c + 1)·CHUNK, c = 0, 1, … (see [`max_slot`]; P_0 = 0 needs none).
pub(crate) fn phase_prefix(y: &[f64], mu: f64, hi: &mut [f64], lo: &mut [f64]) -> Vec<(f64, f64)> {
    debug_assert!(hi.len() == y.len() + 1 && lo.len() == y.len() + 1);
    hi[0] = 0.0;
    lo[0] = 0.0;
    let totals: Vec<(f64, f64)> = y
        .par_chunks(BLOCK)
        .map(|src| block_total_dispatch(src, mu))
        .collect();
    let offs = block_offsets(&totals);
    let mut maxima = vec![(0.0f64, 0.0f64); y.len().div_ceil(CHUNK)];
    hi[1..]
        .par_chunks_mut(BLOCK)
        .zip(lo[1..].par_chunks_mut(BLOCK))
        .zip(y.par_chunks(BLOCK))
        .zip(offs.par_iter())
        .zip(maxima.par_chunks_mut(BLOCK / CHUNK))
        .for_each(|((((h, l), src), &(oh, ol)), mx)| block_phase(src, mu, oh, ol, h, l, mx));
    maxima
}

/// The slot of [`phase_prefix`]'s maxima that covers phase index j.
#[inline(always)]
fn max_slot(j: usize) -> usize {
    j.saturating_sub(1) / CHUNK
}

/// Advises the kernel to back the 2 MiB-aligned interior of `v` with 2 MiB pages (Linux; advice only,
/// an error is ignored). For large fresh zeroed outputs: written once, they cost a page fault per 4 KiB
/// otherwise — a third of a hop-1 DAVAR's time (75 MB of output at N = 10⁵, window 10⁴). Call it before
/// the first write.
pub(crate) fn advise_huge_pages(v: &mut [f64]) {
    #[cfg(target_os = "linux")]
    {
        let addr = v.as_ptr() as usize;
        let start = addr.next_multiple_of(HUGE);
        let end = (addr + std::mem::size_of_val(v)) / HUGE * HUGE;
        if end > start {
            // SAFETY: [start, end) lies inside v's allocation and is 2 MiB aligned; MADV_HUGEPAGE
            // changes no contents.
            unsafe {
                libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = v;
}

/// A zeroed f64 buffer whose pages the kernel may back with 2 MiB pages: the phase of a long record
/// is 16 bytes per sample, and faulting it in 4 KiB pages cost more than building it (~80 ms of
/// ~100 ms at 10⁷ samples). The zeroed allocation is fresh memory (calloc maps it untouched), so the
/// advice lands before the first touch. Also the buffer of the Dask tasks' angles (`angle.rs`).
pub(crate) struct PhaseBuf {
    v: Vec<f64>,
    off: usize,
    len: usize,
}

const HUGE: usize = 2 << 20;

impl PhaseBuf {
    pub(crate) fn new(len: usize) -> Self {
        if len * 8 < HUGE {
            // a small phase: no 2 MiB padding, no advice (their syscalls would cost more than the faults)
            return PhaseBuf {
                v: vec![0.0f64; len],
                off: 0,
                len,
            };
        }
        let v = vec![0.0f64; len + HUGE / 8];
        let addr = v.as_ptr() as usize;
        let off = (addr.next_multiple_of(HUGE) - addr) / 8;
        #[cfg(target_os = "linux")]
        {
            let bytes = (len * 8) / HUGE * HUGE;
            if bytes > 0 {
                // SAFETY: the range [v + off, v + off + bytes) lies inside v's allocation and is
                // 2 MiB aligned; MADV_HUGEPAGE is advice only (an error is ignored: 4 KiB pages).
                unsafe {
                    libc::madvise(
                        v.as_ptr().add(off) as *mut libc::c_void,
                        bytes,
                        libc::MADV_HUGEPAGE,
                    );
                }
            }
        }
        PhaseBuf { v, off, len }
    }

    pub(crate) fn slice(&mut self) -> &mut [f64] {
        &mut self.v[self.off..self.off + self.len]
    }

    pub(crate) fn get(&self) -> &[f64] {
        &self.v[self.off..self.off + self.len]
    }
}

/// Σ d_k² over k = k0 … k0 + len − 1 at factor m, from the phase: with `LO`, the double-word term
/// d = [(hi₂ − hi₁) − (hi₁ − hi₀)] + [(lo₂ − lo₁) − (lo₁ − lo₀)]; without, dₕ = the hi bracket alone —
/// half the reads and arithmetic, used only where [`single_word_holds`] certifies it (`lo` unread).
#[inline(always)]
fn chunk_sum<const LO: bool>(hi: &[f64], lo: &[f64], m: usize, k0: usize, len: usize) -> f64 {
    let h0 = &hi[k0..k0 + len];
    let h1 = &hi[k0 + m..k0 + m + len];
    let h2 = &hi[k0 + 2 * m..k0 + 2 * m + len];
    // without LO the lo "streams" are hi's, never read
    let lo = if LO { lo } else { hi };
    let l0 = &lo[k0..k0 + len];
    let l1 = &lo[k0 + m..k0 + m + len];
    let l2 = &lo[k0 + 2 * m..k0 + 2 * m + len];
    let term = |a0: f64, a1: f64, a2: f64, b0: f64, b1: f64, b2: f64| -> f64 {
        let dh = (a2 - a1) - (a1 - a0);
        if LO {
            dh + ((b2 - b1) - (b1 - b0))
        } else {
            dh
        }
    };
    let mut acc = [0.0f64; LANES];
    let it = h0
        .chunks_exact(LANES)
        .zip(h1.chunks_exact(LANES))
        .zip(h2.chunks_exact(LANES))
        .zip(l0.chunks_exact(LANES))
        .zip(l1.chunks_exact(LANES))
        .zip(l2.chunks_exact(LANES));
    for (((((a0, a1), a2), b0), b1), b2) in it {
        for j in 0..LANES {
            let d = term(a0[j], a1[j], a2[j], b0[j], b1[j], b2[j]);
            acc[j] += d * d;
        }
    }
    let done = len - len % LANES;
    for (j, i) in (done..len).enumerate() {
        let d = term(h0[i], h1[i], h2[i], l0[i], l1[i], l2[i]);
        acc[j] += d * d;
    }
    ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]))
}

/// [`chunk_sum`] in AVX2 intrinsics: the same IEEE operations per lane in the same order (no FMA),
/// so the same bits.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn chunk_sum_avx2<const LO: bool>(
    hi: &[f64],
    lo: &[f64],
    m: usize,
    k0: usize,
    len: usize,
) -> f64 {
    use std::arch::x86_64::*;
    assert!(k0 + 2 * m + len <= hi.len() && (!LO || k0 + 2 * m + len <= lo.len()));
    // SAFETY (every pointer below): offsets k0 + {0, m, 2m} + i with i < len stay within hi and,
    // when LO, lo (asserted above); loads are unaligned.
    let h0 = hi.as_ptr().add(k0);
    let (h1, h2) = (h0.add(m), h0.add(2 * m));
    let l0 = if LO { lo.as_ptr().add(k0) } else { h0 };
    let (l1, l2) = (l0.add(m), l0.add(2 * m));
    // the term of the four lanes from offset i
    let term = |i: usize| -> __m256d {
        let a0 = _mm256_loadu_pd(h0.add(i));
        let a1 = _mm256_loadu_pd(h1.add(i));
        let a2 = _mm256_loadu_pd(h2.add(i));
        let dh = _mm256_sub_pd(_mm256_sub_pd(a2, a1), _mm256_sub_pd(a1, a0));
        if LO {
            let b0 = _mm256_loadu_pd(l0.add(i));
            let b1 = _mm256_loadu_pd(l1.add(i));
            let b2 = _mm256_loadu_pd(l2.add(i));
            let dl = _mm256_sub_pd(_mm256_sub_pd(b2, b1), _mm256_sub_pd(b1, b0));
            _mm256_add_pd(dh, dl)
        } else {
            dh
        }
    };
    let mut acc_a = _mm256_setzero_pd();
    let mut acc_b = _mm256_setzero_pd();
    let done = len - len % LANES;
    let mut i = 0;
    while i < done {
        let d = term(i);
        acc_a = _mm256_add_pd(acc_a, _mm256_mul_pd(d, d));
        let d = term(i + 4);
        acc_b = _mm256_add_pd(acc_b, _mm256_mul_pd(d, d));
        i += LANES;
    }
    let mut acc = [0.0f64; LANES];
    _mm256_storeu_pd(acc.as_mut_ptr(), acc_a);
    _mm256_storeu_pd(acc.as_mut_ptr().add(4), acc_b);
    for (j, i) in (done..len).enumerate() {
        let dh = (*h2.add(i) - *h1.add(i)) - (*h1.add(i) - *h0.add(i));
        let d = if LO {
            dh + ((*l2.add(i) - *l1.add(i)) - (*l1.add(i) - *l0.add(i)))
        } else {
            dh
        };
        acc[j] += d * d;
    }
    ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]))
}

/// Σ d² of one (chunk, m) (double words with `LO`, hi alone without), with the AVX2 term loop where
/// the CPU has it.
#[inline(always)]
pub(crate) fn chunk_sum_dispatch<const LO: bool>(
    avx2: bool,
    hi: &[f64],
    lo: &[f64],
    m: usize,
    k0: usize,
    len: usize,
) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: the caller checked that the CPU has AVX2.
        return unsafe { chunk_sum_avx2::<LO>(hi, lo, m, k0, len) };
    }
    let _ = avx2;
    chunk_sum::<LO>(hi, lo, m, k0, len)
}

/// Relative bound the single-word sum must meet to stand for the double-word one: 10⁻¹¹, a hundredth
/// of the 10⁻⁹ the estimator promises against an extended-precision recomputation.
const SINGLE_WORD_TOL: f64 = 1e-11;

/// The largest |hi| and |lo| over the phase indices k0 + j·m … k0 + j·m + len − 1, j = 0, 1, 2 (the
/// pairs one (chunk, m) reads), from [`phase_prefix`]'s maxima.
#[inline(always)]
fn region_maxima(maxima: &[(f64, f64)], m: usize, k0: usize, len: usize) -> (f64, f64) {
    let (mut mh, mut ml) = (0.0f64, 0.0f64);
    for j in 0..3 {
        let a = k0 + j * m;
        for &(h, l) in &maxima[max_slot(a)..=max_slot(a + len - 1)] {
            mh = mh.max(h);
            ml = ml.max(l);
        }
    }
    (mh, ml)
}

/// Whether Σ dₕ² = `s` over `len` terms is within `SINGLE_WORD_TOL`·s of the sum of the exact
/// squares of the double-word terms d = (H₂+L₂) − 2(H₁+L₁) + (H₀+L₀), given |H| ≤ `mh`, |L| ≤ `ml`
/// over the pairs read. Each term: |dₕ − d| ≤ A + u|dₕ| with A = 4u·mh + 4·ml (u = 2⁻⁵³: the three
/// rounded differences of hi, |hᵢ − hⱼ| ≤ 2·mh; the dropped lo parts, ≤ 4·ml). Summed, with
/// Σ|dₕ| ≤ √(len·s) (Cauchy–Schwarz): |Σd² − s| ≤ 2A(1+u)√(len·s) + (2u+u²)s + len·A². A bound, not
/// an estimate: where it holds the result is the double-word one to 10⁻¹¹; where it does not (a
/// phase far larger than the terms: a quiet stretch after a loud one, a large slow swing of the rate),
/// the chunk is summed in double words.
#[inline(always)]
fn single_word_holds(s: f64, len: usize, mh: f64, ml: f64) -> bool {
    const U: f64 = f64::EPSILON / 2.0;
    let a = 4.0 * U * mh + 4.0 * ml;
    let l = len as f64;
    let bound = 2.0 * a * (1.0 + U) * (l * s).sqrt() + (2.0 * U + U * U) * s + l * a * a;
    bound <= SINGLE_WORD_TOL * s
}

/// The partial sums of the chunks `c0 ..` of one super-chunk, rows of `n_m` in `dst`. Short m run
/// chunk by chunk, every m per chunk (their three reads share the chunk's cache lines); long m run
/// m by m over the super-chunk's chunks, so that only a few streams are in flight at a time.
///
/// Each (chunk, m) is summed from hi alone when [`single_word_holds`] certifies the result, in double
/// words otherwise. Which one is tried first follows the previous chunk of the same m in this
/// super-chunk (the first tries hi; `single_word` false: double words throughout): a record that needs double words pays for one wasted
/// single-word chunk per change, not one per chunk. The choice depends on the data and the fixed
/// chunk grid only, so the bits do not depend on the thread count. Returns how many (chunk, m) were
/// summed in double words.
#[allow(clippy::too_many_arguments)]
fn super_chunk(
    hi: &[f64],
    lo: &[f64],
    maxima: &[(f64, f64)],
    ms: &[usize],
    n: usize,
    c0: usize,
    dst: &mut [f64],
    single_word: bool,
) -> usize {
    #[cfg(target_arch = "x86_64")]
    let avx2 = std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    let avx2 = false;
    let n_m = ms.len();
    let mut doubles = 0usize;
    let mut one = |t: usize, c: usize, try_hi: &mut bool| -> f64 {
        let (m, k0) = (ms[t], c * CHUNK);
        let l = n + 1 - 2 * m;
        if k0 >= l {
            return 0.0;
        }
        let len = CHUNK.min(l - k0);
        let (mh, ml) = region_maxima(maxima, m, k0, len);
        if *try_hi {
            let s = chunk_sum_dispatch::<false>(avx2, hi, lo, m, k0, len);
            if single_word_holds(s, len, mh, ml) {
                return s;
            }
        }
        doubles += 1;
        let s = chunk_sum_dispatch::<true>(avx2, hi, lo, m, k0, len);
        *try_hi = single_word && single_word_holds(s, len, mh, ml);
        s
    };
    let mut try_hi = vec![single_word; n_m];
    for (r, row) in dst.chunks_mut(n_m).enumerate() {
        for (t, o) in row.iter_mut().enumerate() {
            if ms[t] <= SHORT_M {
                *o = one(t, c0 + r, &mut try_hi[t]);
            }
        }
    }
    for t in (0..n_m).filter(|&t| ms[t] > SHORT_M) {
        for (r, row) in dst.chunks_mut(n_m).enumerate() {
            row[t] = one(t, c0 + r, &mut try_hi[t]);
        }
    }
    doubles
}

/// Overlapping Allan variance of the windows `y[..window]` of every axis at every m of `ms` (each
/// 1 ≤ m ≤ window / 2), into `out` laid out [axis][m], in the calling rayon pool. Stops early
/// (leaving `out` partly written) once `cancel` is set; the caller checks the flag.
pub(crate) fn overlapping_window(
    cols: &[&[f64]],
    mus: &[f64],
    ms: &[usize],
    window: usize,
    out: &mut [f64],
    cancel: &Cancel,
) {
    let n = window;
    let n_m = ms.len();
    let m_min = ms.iter().copied().min().unwrap_or(1);
    let n_chunks = (n + 1 - 2 * m_min).div_ceil(CHUNK);
    let mut hi_buf = PhaseBuf::new(n + 1);
    let mut lo_buf = PhaseBuf::new(n + 1);
    let (hi, lo) = (hi_buf.slice(), lo_buf.slice());
    let mut partial = vec![0.0f64; n_chunks * n_m];
    for (a, y) in cols.iter().enumerate() {
        if cancel.is_cancelled() {
            return;
        }
        let maxima = phase_prefix(&y[..n], mus[a], hi, lo);
        let (hi, lo, maxima) = (&*hi, &*lo, &maxima[..]);
        partial
            .par_chunks_mut(SUPER * n_m)
            .enumerate()
            .for_each(|(s, dst)| {
                if !cancel.is_cancelled() {
                    let _ = super_chunk(hi, lo, maxima, ms, n, s * SUPER, dst, true);
                }
            });
        for (t, &m) in ms.iter().enumerate() {
            let s = partial.iter().skip(t).step_by(n_m).fold(0.0, |s, v| s + v);
            let l = (n + 1 - 2 * m) as f64;
            out[a * n_m + t] = s / (2.0 * (m as f64) * (m as f64) * l);
        }
    }
}

/// Writes d_k²·scale for k = k0 … k0 + out.len() − 1 at factor m from the phase (the terms of the
/// short-hop path; d formed with the same operations as in [`chunk_sum`]).
#[inline(always)]
fn terms_into(hi: &[f64], lo: &[f64], m: usize, k0: usize, scale: f64, out: &mut [f64]) {
    let len = out.len();
    let h0 = &hi[k0..k0 + len];
    let h1 = &hi[k0 + m..k0 + m + len];
    let h2 = &hi[k0 + 2 * m..k0 + 2 * m + len];
    let l0 = &lo[k0..k0 + len];
    let l1 = &lo[k0 + m..k0 + m + len];
    let l2 = &lo[k0 + 2 * m..k0 + 2 * m + len];
    for (i, o) in out.iter_mut().enumerate() {
        let dh = (h2[i] - h1[i]) - (h1[i] - h0[i]);
        let dl = (l2[i] - l1[i]) - (l1[i] - l0[i]);
        let d = dh + dl;
        *o = d * d * scale;
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn terms_into_avx2(
    hi: &[f64],
    lo: &[f64],
    m: usize,
    k0: usize,
    scale: f64,
    out: &mut [f64],
) {
    terms_into(hi, lo, m, k0, scale, out)
}

/// [`terms_into`] compiled for AVX2 where the CPU has it (`avx2`: checked by the caller, once per row).
#[inline(always)]
pub(crate) fn terms_dispatch(
    avx2: bool,
    hi: &[f64],
    lo: &[f64],
    m: usize,
    k0: usize,
    scale: f64,
    out: &mut [f64],
) {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: the caller checked that the CPU has AVX2.
        unsafe { terms_into_avx2(hi, lo, m, k0, scale, out) };
        return;
    }
    let _ = avx2;
    terms_into(hi, lo, m, k0, scale, out)
}

/// Scratch of one worker of [`overlapping_dynamic`].
#[derive(Default)]
pub(crate) struct DynScratch {
    terms: Vec<f64>,
    full: Vec<f64>,
    part: Vec<f64>,
    sums: Vec<f64>,
}

/// Hops below this keep every term and cut blocks afterwards; longer hops sum each block directly.
pub(crate) const SMALL_HOP: usize = 64;

/// Overlapping Allan variance of every window `y[j·hop .. j·hop + window)`, j < out.len(), at factor m,
/// from the record's phase (hi, lo): the terms of window j are k = j·hop … j·hop + L − 1, L = window +
/// 1 − 2m. Each block of `hop` terms is summed once (first its r = L mod hop terms, then the rest), and
/// every window is the Van Herk sliding sum of q = ⌊L/hop⌋ whole blocks plus the next block's first r
/// terms — sums of non-negative values over the window's own terms only. Every d_k comes from the
/// phase as in [`overlapping_window`], so its rounding is local to its block sums. `one_window`: the
/// record has one window (its terms are one block); a run of windows of a longer record keeps the
/// record's blocks even when it holds one window, so its values do not depend on where it ends.
#[allow(clippy::too_many_arguments)]
pub(crate) fn overlapping_dynamic_row(
    hi: &[f64],
    lo: &[f64],
    m: usize,
    window: usize,
    hop: usize,
    one_window: bool,
    out: &mut [f64],
    sc: &mut DynScratch,
) -> Range {
    #[cfg(target_arch = "x86_64")]
    let avx2 = std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    let avx2 = false;
    let n_win = out.len();
    let l = window + 1 - 2 * m;
    let hop = if one_window { l } else { hop };
    let (q, r) = (l / hop, l % hop);
    let k_end = (n_win - 1) * hop + l;
    let nblocks = n_win + q;
    let norm = 1.0 / (2.0 * (m as f64) * (m as f64) * l as f64);
    let DynScratch {
        terms,
        full,
        part,
        sums,
    } = sc;
    if hop == 1 {
        // terms formed segment by segment, each window written once (`crate::window_sums`)
        return crate::window_sums::hop1_row(hi, lo, m, q, norm, avx2, out, sums);
    }
    if hop < SMALL_HOP {
        // every term is written below: the buffer is only sized (no fill of what it already holds)
        terms.resize(k_end, 0.0);
        #[cfg(target_arch = "x86_64")]
        if avx2 {
            // SAFETY: the CPU has AVX2 (checked above).
            unsafe { terms_into_avx2(hi, lo, m, 0, norm, terms) };
        } else {
            terms_into(hi, lo, m, 0, norm, terms);
        }
        #[cfg(not(target_arch = "x86_64"))]
        terms_into(hi, lo, m, 0, norm, terms);
        if hop == 1 {
            // the terms are the one-term blocks (k_end = n_win + q − 1 of them: all sliding_sums reads)
            std::mem::swap(terms, full);
        } else {
            full.clear();
            full.resize(nblocks, 0.0);
            part.clear();
            part.resize(nblocks, 0.0);
            for (b, blk) in terms.chunks(hop).enumerate() {
                full[b] = crate::allan::sum4(blk);
                part[b] = crate::allan::sum4(&blk[..r.min(blk.len())]);
            }
        }
    } else {
        full.clear();
        full.resize(nblocks, 0.0);
        part.clear();
        part.resize(nblocks, 0.0);
        for b in 0..nblocks {
            let k0 = b * hop;
            if k0 >= k_end {
                break;
            }
            let len = hop.min(k_end - k0);
            let rr = r.min(len);
            let p = chunk_sum_dispatch::<true>(avx2, hi, lo, m, k0, rr);
            let rest = chunk_sum_dispatch::<true>(avx2, hi, lo, m, k0 + rr, len - rr);
            part[b] = p * norm;
            full[b] = (p + rest) * norm;
        }
    }
    if q == 0 {
        out.copy_from_slice(&part[..n_win]);
        // noted while the row is in cache: the caller's range check then reads nothing again
        Range::of(out)
    } else {
        // each window written once, its range noted as it is written
        let head = (r != 0).then(|| &part[q..]);
        crate::window_sums::sliding_sums_ranged(full, q, head, out, sums)
    }
}

/// [`overlapping_dynamic_row`] for every m of `ms` at once, for hops ≥ `SMALL_HOP`: the block sums
/// (part: a block's first r_m terms, full: all its terms) are formed tile by tile — a tile is a run of
/// whole blocks, ≈ `CHUNK` terms or one block — and within a tile every m with m ≤ `SHORT_M` reads
/// the tile's phase from cache (the three reads at k, k + m, k + 2m land in the same few lines for
/// every such m), as [`super_chunk`] does for the static estimator. Tiles run in parallel; each
/// (m, block) sum is one sequential routine, so the bits do not depend on the thread count. Writes
/// the `n_win` windows into `out` laid out [m][stride], at `first .. first + n_win` of each row.
#[allow(clippy::too_many_arguments)]
pub(crate) fn overlapping_dynamic_tiled(
    hi: &[f64],
    lo: &[f64],
    ms: &[usize],
    window: usize,
    hop: usize,
    out: &mut [f64],
    (stride, first, n_win): (usize, usize, usize),
    cancel: &Cancel,
) {
    #[cfg(target_arch = "x86_64")]
    let avx2 = std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    let avx2 = false;
    let n_m = ms.len();
    debug_assert!(n_win >= 2 && hop >= SMALL_HOP && first + n_win <= stride);
    debug_assert_eq!(out.len(), n_m * stride);
    let geo: Vec<(usize, usize, usize, usize)> = ms
        .iter()
        .map(|&m| {
            let l = window + 1 - 2 * m;
            (l / hop, l % hop, (n_win - 1) * hop + l, m) // (q, r, k_end, m)
        })
        .collect();
    let nblocks = geo.iter().map(|g| n_win + g.0).max().unwrap_or(0);
    let tile_blocks = (CHUNK / hop).max(1);
    let n_tiles = nblocks.div_ceil(tile_blocks);
    // [tile][m][block in tile] → (part, full)
    let mut sums = vec![(0.0f64, 0.0f64); n_tiles * n_m * tile_blocks];
    sums.par_chunks_mut(n_m * tile_blocks)
        .enumerate()
        .for_each(|(tile, dst)| {
            if cancel.is_cancelled() {
                return;
            }
            let one = |t: usize, bi: usize| -> (f64, f64) {
                let (_q, r, k_end, m) = geo[t];
                let k0 = (tile * tile_blocks + bi) * hop;
                if k0 >= k_end {
                    return (0.0, 0.0);
                }
                let len = hop.min(k_end - k0);
                let rr = r.min(len);
                let p = chunk_sum_dispatch::<true>(avx2, hi, lo, m, k0, rr);
                let rest = chunk_sum_dispatch::<true>(avx2, hi, lo, m, k0 + rr, len - rr);
                (p, p + rest)
            };
            // short m block by block (the tile's phase in cache for all of them), long m m by m
            for bi in 0..tile_blocks {
                for t in (0..n_m).filter(|&t| ms[t] <= SHORT_M) {
                    dst[t * tile_blocks + bi] = one(t, bi);
                }
            }
            for t in (0..n_m).filter(|&t| ms[t] > SHORT_M) {
                for bi in 0..tile_blocks {
                    dst[t * tile_blocks + bi] = one(t, bi);
                }
            }
        });
    if cancel.is_cancelled() {
        return;
    }
    out.par_chunks_mut(stride).enumerate().for_each(|(t, row)| {
        let row = &mut row[first..first + n_win];
        let (q, r, _k_end, m) = geo[t];
        let l = window + 1 - 2 * m;
        let norm = 1.0 / (2.0 * (m as f64) * (m as f64) * l as f64);
        let nb = n_win + q;
        let block = |b: usize| sums[((b / tile_blocks) * n_m + t) * tile_blocks + b % tile_blocks];
        let part: Vec<f64> = (0..nb).map(|b| block(b).0 * norm).collect();
        let full: Vec<f64> = (0..nb).map(|b| block(b).1 * norm).collect();
        block_window_sums(&full, &part, (q, r), (0, n_win), row);
    });
}

/// Fewest samples a phase segment spans (see [`segment_windows`]): 2^22, 64 MiB of phase.
#[cfg(not(test))]
const SEGMENT_SPAN: usize = 1 << 22;
/// The unit tests' segments are short, so small records cross several.
#[cfg(test)]
const SEGMENT_SPAN: usize = 1 << 12;

/// Records of at most this many samples × axes (the windows' samples) are *short*: 2^26, 512 MiB of
/// float64. A short record's segments span 16 windows' worth (≤ 1/16 of the work rebuilt where two
/// segments overlap) and it takes the phase path at any window.
#[cfg(not(test))]
pub(crate) const PHASE_RECORD_MAX: usize = 1 << 26;
#[cfg(test)]
pub(crate) const PHASE_RECORD_MAX: usize = 1 << 14;

/// A long record's segments span 4 windows' worth (≤ 1/3 rebuilt), so that a Dask task that holds whole
/// segments stays small, and it takes the phase path while a segment spans at most this many samples:
/// 2^23 (128 MiB of phase; windows up to 2^21 samples). Longer windows build the phase chunk by chunk
/// of their terms (`crate::chunked`, hops ≥ 64) or stream their sums in O(window) per worker.
#[cfg(not(test))]
pub(crate) const PHASE_SPAN_MAX: usize = 1 << 23;
#[cfg(test)]
pub(crate) const PHASE_SPAN_MAX: usize = 1 << 13;

/// Samples a phase segment spans at most: max(2^22, 16 · window) on a short record, max(2^22, 4 · window)
/// on a long one (see [`PHASE_RECORD_MAX`]).
pub(crate) fn segment_span(window: usize, long_record: bool) -> usize {
    SEGMENT_SPAN.max(window.saturating_mul(if long_record { 4 } else { 16 }))
}

/// Windows per phase segment. The dynamic estimator's phase path cuts a record's windows into runs
/// of this many (the record's windows 0 .. K, K .. 2K, …: a grid that depends on the record's length
/// only through whether it is long, and not on the thread count) and builds each run's double-word
/// phase from the run's first sample, so it holds 16 bytes per sample of one segment — at most
/// [`segment_span`] samples — instead of 16 per sample of the record. A part of the record that starts
/// on this grid has its segments' phases bit for bit.
pub fn segment_windows(window: usize, hop: usize, long_record: bool) -> usize {
    (segment_span(window, long_record).saturating_sub(window) / hop.max(1)).saturating_add(1)
}

/// The phase of one axis for [`overlapping_dynamic_row`]: (hi, lo) of its first `n` samples.
pub(crate) struct Phase {
    hi: PhaseBuf,
    lo: PhaseBuf,
}

impl Phase {
    pub(crate) fn new(y: &[f64], mu: f64) -> Self {
        let n = y.len();
        let mut hi = PhaseBuf::new(n + 1);
        let mut lo = PhaseBuf::new(n + 1);
        phase_prefix(y, mu, hi.slice(), lo.slice());
        Phase { hi, lo }
    }

    /// The phase of another `y` in the same buffers where they are long enough (no fresh pages).
    pub(crate) fn refill(&mut self, y: &[f64], mu: f64) {
        let n = y.len();
        let fits = |b: &PhaseBuf| b.off + n < b.v.len();
        if !(fits(&self.hi) && fits(&self.lo)) {
            *self = Phase::new(y, mu);
            return;
        }
        self.hi.len = n + 1;
        self.lo.len = n + 1;
        phase_prefix(y, mu, self.hi.slice(), self.lo.slice());
    }

    pub(crate) fn parts(&self) -> (&[f64], &[f64]) {
        (
            &self.hi.v[self.hi.off..self.hi.off + self.hi.len],
            &self.lo.v[self.lo.off..self.lo.off + self.lo.len],
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
            })
            .collect()
    }

    /// The plain definition on the angle (its own f64 rounding: compare at 1e-10 on tame data).
    fn direct(y: &[f64], m: usize) -> f64 {
        let mut x = vec![0.0f64; y.len() + 1];
        for (i, v) in y.iter().enumerate() {
            x[i + 1] = x[i] + v;
        }
        let l = y.len() + 1 - 2 * m;
        let s: f64 = (0..l)
            .map(|k| (x[k + 2 * m] - 2.0 * x[k + m] + x[k]).powi(2))
            .sum();
        s / (2.0 * (m * m) as f64 * l as f64)
    }

    #[test]
    fn matches_the_definition_across_blocks_and_chunks() {
        let n = 3 * BLOCK + 1234;
        let y = noise(n, 5);
        let ms = [
            1usize,
            2,
            3,
            7,
            8,
            9,
            100,
            4097,
            CHUNK,
            CHUNK + 1,
            n / 3,
            n / 2,
        ];
        let mut out = vec![0.0; ms.len()];
        overlapping_window(&[&y], &[0.0], &ms, n, &mut out, &Cancel::new());
        for (o, &m) in out.iter().zip(&ms) {
            let want = direct(&y, m);
            assert!(((o - want) / want).abs() < 1e-10, "m={m}: {o} vs {want}");
        }
    }

    /// Every (chunk, m) partial sum of a record, with the single-word terms where certified or in
    /// double words throughout.
    fn partials(y: &[f64], ms: &[usize], single_word: bool) -> (Vec<f64>, usize) {
        let n = y.len();
        let mu = crate::oavar::centre(y, 0).unwrap();
        let (mut hi, mut lo) = (vec![0.0; n + 1], vec![0.0; n + 1]);
        let maxima = phase_prefix(y, mu, &mut hi, &mut lo);
        let n_chunks = (n + 1 - 2 * ms.iter().min().unwrap()).div_ceil(CHUNK);
        let mut out = vec![0.0; n_chunks * ms.len()];
        let mut doubles = 0;
        for (s, dst) in out.chunks_mut(SUPER * ms.len()).enumerate() {
            doubles += super_chunk(&hi, &lo, &maxima, ms, n, s * SUPER, dst, single_word);
        }
        (out, doubles)
    }

    #[test]
    fn single_word_partials_stand_for_the_double_word_ones() {
        let n = 3 * BLOCK + 1234;
        let ms = [1usize, 2, 3, 7, 9, 100, 4097, CHUNK + 1, n / 3];
        let white = noise(n, 3);
        let mut loud_quiet = noise(n, 4);
        for v in loud_quiet[..n / 3].iter_mut() {
            *v *= 1e6;
        }
        // a rate ramp of 10⁴ noise levels plus an offset: a phase far larger than the short terms
        let ramp: Vec<f64> = noise(n, 6)
            .iter()
            .enumerate()
            .map(|(i, v)| 300.0 + 1e4 * i as f64 / n as f64 + v)
            .collect();
        let mut walk = noise(n, 8);
        for i in 1..n {
            walk[i] += walk[i - 1];
        }
        for (name, y, hi_share) in [
            ("white", &white, 0.99),
            ("loud then quiet", &loud_quiet, 0.1),
            ("ramp", &ramp, 0.1),
            ("random-walk rate", &walk, 0.1),
        ] {
            let (adaptive, doubles) = partials(y, &ms, true);
            let (double, all) = partials(y, &ms, false);
            for (i, (a, d)) in adaptive.iter().zip(&double).enumerate() {
                assert!(
                    (a - d).abs() <= 2e-11 * d.abs(),
                    "{name}: partial {i} (m = {}): {a} vs {d}",
                    ms[i % ms.len()]
                );
            }
            // `all`: the (chunk, m) that have terms; each tried in single words is counted once
            let share = 1.0 - doubles as f64 / all as f64;
            assert!(
                share >= hi_share,
                "{name}: single words in {share:.3} of the partials"
            );
            if name != "white" {
                assert!(doubles > 0, "{name}: no partial needed double words");
            }
        }
    }

    #[test]
    fn the_phase_keeps_its_digits_after_a_loud_stretch() {
        // level ×10⁻⁶ after the first block and a half: the phase's block sums there stay exact
        let n = 3 * BLOCK;
        let mut y = noise(n, 9);
        for v in y[..n / 2].iter_mut() {
            *v *= 1e6;
        }
        let mut hi = vec![0.0; n + 1];
        let mut lo = vec![0.0; n + 1];
        phase_prefix(&y, 0.0, &mut hi, &mut lo);
        for (a, b) in [
            (n / 2 + 10, n / 2 + 11),
            (n - 100, n - 1),
            (2 * BLOCK - 3, 2 * BLOCK + 5),
        ] {
            let got = (hi[b] - hi[a]) + (lo[b] - lo[a]);
            let want: f64 = y[a..b].iter().sum();
            let scale: f64 = y[a..b].iter().map(|v| v.abs()).sum();
            assert!(
                (got - want).abs() <= 1e-14 * scale,
                "[{a}, {b}): {got} vs {want}"
            );
        }
    }
}

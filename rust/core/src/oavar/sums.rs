//! The static estimator's term pass: per (chunk, m) partial sums of d², in single words where a bound
//! certifies them and in double words otherwise, summed in chunk order.

use super::phase::{max_slot, phase_prefix, PhaseBuf};
use super::{CHUNK, LANES, SHORT_M, SUPER};
use crate::cancel::Cancel;
use rayon::prelude::*;

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
///
/// [`phase_prefix`]: super::phase::phase_prefix
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

#[cfg(test)]
mod tests {
    use super::super::{noise, BLOCK};
    use super::*;

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
}

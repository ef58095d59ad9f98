//! The classic (non-overlapping) Allan variance of one window by gathering cluster sums from one
//! double-word prefix sum, shared by every averaging factor m.
//!
//! The classic estimator at m needs only the ⌊W/m⌋ cluster sums B_k = Σ_{i=km}^{(k+1)m−1} (y_i − μ).
//! Streaming all W samples per m (what the sliding-sum path does) costs O(W) per τ; a dense τ list
//! (every 0.1 s to 1000 s: ~10⁴ values of m) then costs 10⁴ passes over the record. Here one prefix
//! P_j = Σ_{i<j} (y_i − μ) is built once per axis and each m reads only its W/m + 1 prefix values, so the
//! whole list costs Σ_m W/m ≈ W·ln(m_max) reads.
//!
//! # Why the prefix does not drift
//! A plain f64 prefix carries an absolute error of ~ε·max|P| into every later difference: a quiet
//! stretch after a loud one (noise level ×10⁻⁶) would lose its digits. The prefix is kept as an
//! unevaluated double-word sum hi + lo (Knuth's TwoSum, renormalised after every sample), whose
//! error is ~ε²·|P| (Dekker/Knuth; Muller et al., Handbook of Floating-Point Arithmetic, §14). A
//! cluster sum B = (hi₂ − hi₁) + (lo₂ − lo₁) is formed with TwoSum on the high parts, so its error
//! is ≲ ε·|B| + 4ε²·max|P|: with |P| ≤ 10¹⁰σ (10⁸ samples, level ×10⁶) the second term is ~10⁻²² σ,
//! far below any cluster sum's own size. The squared differences d² ≥ 0 are then summed without
//! cancellation, as in [`crate::allan`].
//!
//! The prefix costs 16 bytes per sample and axis and is built in parallel over fixed blocks (each from
//! its double-word offset); the m run in parallel, each one sequential routine, so results are
//! bit-identical for any number of worker threads.

use crate::cancel::Cancel;
use rayon::prelude::*;

/// Largest window × axes (samples) handled by the gather: its prefix holds 16 bytes per sample and axis
/// (1 GiB here);
/// longer windows use the streaming path, whose memory does not grow with the record.
pub(crate) const GATHER_MAX: usize = 1 << 26;

/// Error-free sum: a + b = s + e exactly (Knuth).
#[inline(always)]
fn two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    let bb = s - a;
    let e = (a - (s - bb)) + (b - bb);
    (s, e)
}

/// Renormalise hi + lo when |hi| ≥ |lo| (Dekker's fast TwoSum).
#[inline(always)]
fn quick_two_sum(a: f64, b: f64) -> (f64, f64) {
    let s = a + b;
    (s, b - (s - a))
}

/// Samples per block of the parallel prefix build.
const PBLOCK: usize = 1 << 16;

/// Double-word prefix sums of every axis, interleaved: `p[j·A + a] = (hi, lo)` holds P_j of axis a,
/// P_0 = 0, so that one gather at sample j reads the prefixes of all A axes from adjacent memory (at
/// long strides every read is a cache miss; one miss then serves every axis).
///
/// Built in parallel over fixed blocks of `PBLOCK` samples: each block's double-word total first
/// (vectorised TwoSum lanes), the totals scanned in double words, then each block's prefixes from its
/// offset — the same blocks for any thread count, so the same bits.
pub(crate) fn prefix(cols: &[&[f64]], mus: &[f64], len: usize) -> Vec<[f64; 2]> {
    let n_axes = cols.len();
    let mut p = vec![[0.0f64; 2]; (len + 1) * n_axes];
    // offsets[b·A + a]: P of axis a at the start of block b
    let n_blocks = len.div_ceil(PBLOCK);
    let mut offsets = vec![[0.0f64; 2]; n_blocks * n_axes];
    for (a, (c, &mu)) in cols.iter().zip(mus).enumerate() {
        let totals: Vec<(f64, f64)> = c[..len]
            .par_chunks(PBLOCK)
            .map(|src| crate::oavar::block_total_dispatch(src, mu))
            .collect();
        let (mut oh, mut ol) = (0.0f64, 0.0f64);
        for (b, &(s, c)) in totals.iter().enumerate() {
            offsets[b * n_axes + a] = [oh, ol];
            let (t, e) = two_sum(oh, s);
            let (h, l) = quick_two_sum(t, e + (ol + c));
            oh = h;
            ol = l;
        }
    }
    p[n_axes..]
        .par_chunks_mut(PBLOCK * n_axes)
        .zip(offsets.par_chunks(n_axes))
        .enumerate()
        .for_each(|(b, (rows, off))| {
            // the axes advance together: their TwoSum chains are independent, so their latencies overlap
            let mut state = off.to_vec();
            for (jj, row) in rows.chunks_exact_mut(n_axes).enumerate() {
                let j = b * PBLOCK + jj;
                for (a, (dst, st)) in row.iter_mut().zip(state.iter_mut()).enumerate() {
                    let (s, e) = two_sum(st[0], cols[a][j] - mus[a]);
                    let (h, l) = quick_two_sum(s, st[1] + e);
                    *st = [h, l];
                    *dst = [h, l];
                }
            }
        });
    p
}

/// P_b − P_a from the double-word prefix, rounded once.
#[inline(always)]
fn diff(pa: [f64; 2], pb: [f64; 2]) -> f64 {
    let (s, e) = two_sum(pb[0], -pa[0]);
    s + (e + (pb[1] - pa[1]))
}

/// Classic Allan variance at one m of the windows `y[..window]` of every axis, from their interleaved
/// prefix `p`, into `out` (one value per axis).
pub(crate) fn classic_from_prefix(
    p: &[[f64; 2]],
    n_axes: usize,
    m: usize,
    window: usize,
    out: &mut [f64],
) {
    let k = window / m;
    let norm = 1.0 / (2.0 * (m as f64) * (m as f64) * (k - 1) as f64);
    // four partial sums per axis (term i into sum i mod 4): shorter dependency chains, ~¼ the rounding
    // growth, and no buffer of terms (allocating one per m cost more than the arithmetic)
    let mut acc = vec![[0.0f64; 4]; n_axes];
    let mut prev: Vec<f64> = (0..n_axes).map(|a| diff(p[a], p[m * n_axes + a])).collect();
    for c in 1..k {
        let (r0, r1) = (c * m * n_axes, (c + 1) * m * n_axes);
        for a in 0..n_axes {
            let b = diff(p[r0 + a], p[r1 + a]);
            let d = b - prev[a];
            acc[a][(c - 1) & 3] += d * d;
            prev[a] = b;
        }
    }
    for (o, s) in out.iter_mut().zip(&acc) {
        *o = ((s[0] + s[1]) + (s[2] + s[3])) * norm;
    }
}

/// Classic Allan variance of the windows `y[..window]` of every axis at every m of `ms`, into `out`
/// laid out [axis][m], in the calling rayon pool (parallel over m). Stops early (leaving `out` partly
/// written) once `cancel` is set; the caller checks the flag.
pub(crate) fn classic_window(
    cols: &[&[f64]],
    mus: &[f64],
    ms: &[usize],
    window: usize,
    out: &mut [f64],
    cancel: &Cancel,
) {
    let n_axes = cols.len();
    let p = prefix(cols, mus, window);
    if cancel.is_cancelled() {
        return;
    }
    let per_m: Vec<Vec<f64>> = ms
        .par_iter()
        .map(|&m| {
            let mut v = vec![0.0; n_axes];
            if !cancel.is_cancelled() {
                classic_from_prefix(&p, n_axes, m, window, &mut v);
            }
            v
        })
        .collect();
    for (t, v) in per_m.iter().enumerate() {
        for (a, x) in v.iter().enumerate() {
            out[a * ms.len() + t] = *x;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The plain definition: cluster means by direct summation, in the same layout.
    fn direct(y: &[f64], m: usize) -> f64 {
        let k = y.len() / m;
        let means: Vec<f64> = (0..k)
            .map(|c| y[c * m..(c + 1) * m].iter().sum::<f64>() / m as f64)
            .collect();
        let s: f64 = means.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum();
        s / (2.0 * (k - 1) as f64)
    }

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

    #[test]
    fn matches_the_definition() {
        let y: Vec<f64> = noise(10_007, 3).iter().map(|v| v + 3.0).collect();
        let z: Vec<f64> = noise(10_007, 4);
        let p = prefix(&[&y, &z], &[3.0, 0.0], y.len());
        for m in [1, 2, 3, 7, 100, 1000, 5003] {
            let mut got2 = [0.0; 2];
            classic_from_prefix(&p, 2, m, y.len(), &mut got2);
            let got = got2[0];
            let want_z = direct(&z, m);
            assert!(((got2[1] - want_z) / want_z).abs() < 1e-12, "axis 1, m={m}");
            // the reference sums y − 3 (exact by Sterbenz: y ∈ [2.5, 3.5]) so that it is the accurate side
            let centred: Vec<f64> = y.iter().map(|v| v - 3.0).collect();
            let want = direct(&centred, m);
            assert!(
                ((got - want) / want).abs() < 1e-12,
                "m={m}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn quiet_stretch_after_a_loud_one_keeps_its_digits() {
        // level ×10⁻⁶ after the first half: each quiet cluster's sum must not inherit the loud half's error
        let n = 200_000;
        let mut y = noise(n, 9);
        for v in y[..n / 2].iter_mut() {
            *v *= 1e6;
        }
        let p = prefix(&[&y], &[0.0], n);
        for m in [1, 10, 1000] {
            for c in [n / (2 * m), n / m - 1] {
                let got = diff(p[c * m], p[(c + 1) * m]);
                let want: f64 = y[c * m..(c + 1) * m].iter().sum();
                let scale: f64 = y[c * m..(c + 1) * m].iter().map(|v| v.abs()).sum();
                assert!(
                    (got - want).abs() <= 1e-14 * scale,
                    "m={m} c={c}: {got} vs {want}"
                );
            }
        }
    }
}

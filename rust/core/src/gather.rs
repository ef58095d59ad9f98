//! The classic (non-overlapping) Allan variance of one window by gathering cluster sums from one
//! double-word prefix sum, shared by every averaging factor m.
//!
//! The classic estimator at m needs only the ⌊W/m⌋ cluster sums B_k = Σ_{i=km}^{(k+1)m−1} (y_i − μ).
//! Streaming all W samples per m (what the sliding-sum path does) costs O(W) per τ; a dense τ list
//! (every 0.1 s to 1000 s: ~10⁴ values of m) then costs 10⁴ passes over the record. Here one prefix
//! P_j = Σ_{i<j} (y_i − μ) is built once per axis and each m reads only its W/m + 1 prefix values, so the
//! whole list costs Σ_m W/m ≈ W·ln(m_max) reads. At long strides each of those reads is a cache miss,
//! so a dense list's long m instead share sweeps over the prefix in order ([`classic_sweep`]: the same
//! cluster sums, the same bits), each m taking its rows from the cached stretch the sweep is on.
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
pub(crate) fn two_sum(a: f64, b: f64) -> (f64, f64) {
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
        for (b, (oh, ol)) in crate::oavar::block_offsets(&totals).into_iter().enumerate() {
            offsets[b * n_axes + a] = [oh, ol];
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

/// Rows of the prefix one step of [`classic_sweep`] holds in cache.
const SWEEP_ROWS: usize = 2048;

/// Factors whose rows lie at least this many bytes apart are gathered by [`classic_sweep`].
const SWEEP_STRIDE_BYTES: usize = 4096;

/// [`classic_from_prefix`] for many long m at once, by one sweep over the prefix instead of one
/// strided walk per m. At long strides every row a walk reads is a cache miss (the prefix is 16 bytes
/// per sample and axis, far larger than the caches, and each m reads it at its own stride); here the
/// prefix is read once, in order, `SWEEP_ROWS` rows at a time, and every m whose next multiple falls in
/// those rows takes its cluster sum from cache, keeping its previous prefix row and cluster sum in its
/// own small state. Each m still forms the same cluster sums and squared differences in the same
/// order with the same operations as [`classic_from_prefix`]: the same bits. `out` is [m][axis]
/// (left partly written once `cancel` is set).
pub(crate) fn classic_sweep(
    p: &[[f64; 2]],
    n_axes: usize,
    ms: &[usize],
    window: usize,
    out: &mut [f64],
    cancel: &Cancel,
) {
    let n_m = ms.len();
    // per m: position of its next multiple, clusters done, and per axis P at the last multiple, the
    // last cluster sum and the four partial sums
    let mut next: Vec<usize> = ms.to_vec();
    let last: Vec<usize> = ms.iter().map(|&m| (window / m) * m).collect();
    let mut done = vec![0usize; n_m];
    let mut prev_p: Vec<[f64; 2]> = (0..n_m).flat_map(|_| p[..n_axes].iter().copied()).collect();
    let mut prev_b = vec![0.0f64; n_m * n_axes];
    let mut acc = vec![[0.0f64; 4]; n_m * n_axes];
    let mut row_start = 0;
    while row_start <= window {
        if cancel.is_cancelled() {
            return;
        }
        let row_end = (row_start + SWEEP_ROWS).min(window + 1);
        for t in 0..n_m {
            let m = ms[t];
            while next[t] < row_end && next[t] <= last[t] {
                let j = next[t] * n_axes;
                let c = done[t];
                for a in 0..n_axes {
                    let i = t * n_axes + a;
                    let b = diff(prev_p[i], p[j + a]);
                    if c >= 1 {
                        let d = b - prev_b[i];
                        acc[i][(c - 1) & 3] += d * d;
                    }
                    prev_b[i] = b;
                    prev_p[i] = p[j + a];
                }
                done[t] = c + 1;
                next[t] += m;
            }
        }
        row_start = row_end;
    }
    for (t, &m) in ms.iter().enumerate() {
        let k = window / m;
        let norm = 1.0 / (2.0 * (m as f64) * (m as f64) * (k - 1) as f64);
        for a in 0..n_axes {
            let s = acc[t * n_axes + a];
            out[t * n_axes + a] = ((s[0] + s[1]) + (s[2] + s[3])) * norm;
        }
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
    // Short strides walk the prefix per m (their rows share cache lines); long ones share sweeps —
    // when they are many: a sweep reads every row once, in order (~10× cheaper per row than a
    // walk's cache miss), so a few long m (an octave grid) walk their window/m rows instead.
    let n_groups = rayon::current_num_threads().max(1);
    let far = |m: usize| m * n_axes * 16 >= SWEEP_STRIDE_BYTES;
    let walked_rows: usize = ms.iter().filter(|&&m| far(m)).map(|&m| window / m).sum();
    let sweep = walked_rows.saturating_mul(10) >= window.saturating_mul(n_groups);
    let long = |m: usize| sweep && far(m);
    let short: Vec<usize> = (0..ms.len()).filter(|&t| !long(ms[t])).collect();
    let swept: Vec<usize> = (0..ms.len()).filter(|&t| long(ms[t])).collect();
    let per_m: Vec<Vec<f64>> = short
        .par_iter()
        .map(|&t| {
            let mut v = vec![0.0; n_axes];
            if !cancel.is_cancelled() {
                classic_from_prefix(&p, n_axes, ms[t], window, &mut v);
            }
            v
        })
        .collect();
    for (&t, v) in short.iter().zip(&per_m) {
        for (a, x) in v.iter().enumerate() {
            out[a * ms.len() + t] = *x;
        }
    }
    if swept.is_empty() || cancel.is_cancelled() {
        return;
    }
    // one sweep per worker, over every n_groups-th long m (each m's bits do not depend on its group)
    let n_groups = n_groups.min(swept.len());
    let groups: Vec<(Vec<usize>, Vec<f64>)> = (0..n_groups)
        .into_par_iter()
        .map(|g| {
            let ts: Vec<usize> = swept.iter().copied().skip(g).step_by(n_groups).collect();
            let gms: Vec<usize> = ts.iter().map(|&t| ms[t]).collect();
            let mut v = vec![0.0; gms.len() * n_axes];
            if !cancel.is_cancelled() {
                classic_sweep(&p, n_axes, &gms, window, &mut v, cancel);
            }
            (ts, v)
        })
        .collect();
    for (ts, v) in &groups {
        for (i, &t) in ts.iter().enumerate() {
            for a in 0..n_axes {
                out[a * ms.len() + t] = v[i * n_axes + a];
            }
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

    use allanite_testutil::lcg_uniform as noise;

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
    fn the_sweep_gives_every_m_the_walks_bits() {
        let n = 3 * SWEEP_ROWS + 17;
        let cols: Vec<Vec<f64>> = (0..3).map(|a| noise(n, 20 + a)).collect();
        let refs: Vec<&[f64]> = cols.iter().map(|c| &c[..]).collect();
        let p = prefix(&refs, &[0.1, 0.0, -0.2], n);
        // multiples inside one block, across blocks, ending on the last row, and k = 2
        let ms = [1usize, 5, 300, SWEEP_ROWS - 1, SWEEP_ROWS + 3, n / 3, n / 2];
        let mut swept = vec![0.0; ms.len() * 3];
        classic_sweep(&p, 3, &ms, n, &mut swept, &Cancel::new());
        for (t, &m) in ms.iter().enumerate() {
            let mut walked = [0.0; 3];
            classic_from_prefix(&p, 3, m, n, &mut walked);
            for a in 0..3 {
                assert_eq!(
                    swept[t * 3 + a].to_bits(),
                    walked[a].to_bits(),
                    "m={m} axis {a}"
                );
            }
        }
        // and a dense list through the window, which splits it between walks and sweeps (any thread
        // count: the same bits)
        let ms: Vec<usize> = (1..=n / 2).step_by(5).collect();
        let mut out = vec![0.0; 3 * ms.len()];
        classic_window(&refs, &[0.1, 0.0, -0.2], &ms, n, &mut out, &Cancel::new());
        for (t, &m) in ms.iter().enumerate() {
            let mut walked = [0.0; 3];
            classic_from_prefix(&p, 3, m, n, &mut walked);
            for a in 0..3 {
                assert_eq!(
                    out[a * ms.len() + t].to_bits(),
                    walked[a].to_bits(),
                    "m={m} axis {a}"
                );
            }
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

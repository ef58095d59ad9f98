//! Time-interval error of phase records: MTIE by running max/min (exact), TIE rms, and their
//! gap-aware forms.

use super::{check_values, sum_sq};
use crate::allan::check_shape;
use crate::error::{CoreError, Result};
use rayon::prelude::*;

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

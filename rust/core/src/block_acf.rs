//! The sums behind the lag-1 autocorrelation of block averages and their differences, in one pass
//! over a long rate record (the noise identification of `allanite.estimators._long_id`).
//!
//! At an averaging factor m the block averages are z_j = (Σ_{i<m} (x[jm + i] − μ)) / m for
//! j = 0 … ⌊n/m⌋ − 1 (for m = 1 the sample less μ itself), w⁰ = z and w^d the d-th difference
//! (w^d_j = w^{d−1}_{j+1} − w^{d−1}_j, NumPy's `diff`). For each d ≤ dmax the pass gives Σw, Σw²,
//! Σ w_j w_{j+1} and the first and last element of w^d — from which the caller forms Stable32's lag-1
//! autocorrelation without holding z (which is as long as the record at m = 1).
//!
//! The sums are added in runs of [`RUN`] values each summed on its own (a pairwise-like split of the
//! rounding); they differ from NumPy's pairwise sums over the same values by rounding only.

use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
use rayon::prelude::*;

/// Values of each sum added on their own before joining the running total.
const RUN: usize = 4096;

/// Values per level (d) in the output: Σw, Σw², Σ w_j w_{j+1}, first w, last w (NaN where w^d is empty).
pub const STATS: usize = 5;

/// The running sums of one difference level: Σw, Σw², Σ w_j w_(j+1), and its first and last value.
#[derive(Clone, Copy)]
struct Level {
    total: [f64; 3],
    first: f64,
    last: f64,
    count: usize,
}

impl Level {
    const fn new() -> Self {
        Level {
            total: [0.0; 3],
            first: f64::NAN,
            last: f64::NAN,
            count: 0,
        }
    }

    /// Adds the run `v` (the level's next values, in order): its sums on their own (four lanes, so
    /// that they vectorise), then joined to the totals; the product across the run's start too.
    fn add_run(&mut self, v: &[f64]) {
        let Some((&v0, &vl)) = v.first().zip(v.last()) else {
            return;
        };
        let (mut s1, mut s2, mut c) = ([0.0f64; 4], [0.0f64; 4], [0.0f64; 4]);
        let body = v.len() - 1; // products v[i]·v[i + 1] for i < body
        for (w, nx) in v[..body].chunks_exact(4).zip(v[1..].chunks_exact(4)) {
            for l in 0..4 {
                s1[l] += w[l];
                s2[l] += w[l] * w[l];
                c[l] += w[l] * nx[l];
            }
        }
        let done = body - body % 4;
        let (mut t1, mut t2, mut tc) = (
            (s1[0] + s1[1]) + (s1[2] + s1[3]),
            (s2[0] + s2[1]) + (s2[2] + s2[3]),
            (c[0] + c[1]) + (c[2] + c[3]),
        );
        for i in done..v.len() {
            t1 += v[i];
            t2 += v[i] * v[i];
            if i + 1 < v.len() {
                tc += v[i] * v[i + 1];
            }
        }
        if self.count == 0 {
            self.first = v0;
        } else {
            tc += self.last * v0;
        }
        self.total[0] += t1;
        self.total[1] += t2;
        self.total[2] += tc;
        self.last = vl;
        self.count += v.len();
    }
}

/// Block averages of `x` less `mu` at `m` from block `j0` on, into `out` (as many as it holds).
fn block_means(x: &[f64], mu: f64, m: usize, j0: usize, out: &mut [f64]) {
    if m == 1 {
        for (o, &s) in out.iter_mut().zip(&x[j0..]) {
            *o = s - mu;
        }
        return;
    }
    for (o, block) in out.iter_mut().zip(x[j0 * m..].chunks_exact(m)) {
        // the NumPy mean of the block: its sum divided by m
        *o = block.iter().map(|&s| s - mu).sum::<f64>() / m as f64;
    }
}

/// The [`STATS`] values of each level d = 0 … dmax (row-major, (dmax + 1) × STATS) of the block
/// averages of `x` less `mu` at `m`, [`RUN`] averages at a time. Stops early, with meaningless sums,
/// once `cancel` is set.
fn one_factor(x: &[f64], mu: f64, m: usize, dmax: usize, cancel: &Cancel) -> Vec<f64> {
    let mut levels = vec![Level::new(); dmax + 1];
    let k = x.len() / m;
    let mut buf = vec![0.0f64; RUN];
    let mut j = 0;
    while j < k && !cancel.is_cancelled() {
        let len = RUN.min(k - j);
        block_means(x, mu, m, j, &mut buf[..len]);
        let mut lo = 0; // the run of level d is buf[lo..len]
        for lv in levels.iter_mut() {
            if lo >= len {
                break;
            }
            let (prev, had) = (lv.last, lv.count > 0);
            lv.add_run(&buf[lo..len]);
            // the next level's run, in place (from the end): differences within this run, and across
            // its start where this level had a value before it
            for i in (lo + 1..len).rev() {
                buf[i] -= buf[i - 1];
            }
            if had {
                buf[lo] -= prev;
            } else {
                lo += 1;
            }
        }
        j += len;
    }
    let mut out = Vec::with_capacity((dmax + 1) * STATS);
    for lv in &levels {
        out.extend_from_slice(&[lv.total[0], lv.total[1], lv.total[2], lv.first, lv.last]);
    }
    out
}

/// [`STATS`] sums of the lag-1 autocorrelation of the block averages of `x` less `mu` and of their
/// differences up to `dmax`, at each averaging factor of `ms` (factors in parallel on the current
/// rayon pool): shape (len(ms), dmax + 1, STATS), row-major. Returns `Cancelled` once `cancel` is set.
pub fn block_lag1_sums(
    x: &[f64],
    mu: f64,
    ms: &[usize],
    dmax: usize,
    cancel: &Cancel,
) -> Result<Vec<f64>> {
    if let Some(&m) = ms.iter().find(|&&m| m == 0 || m > x.len()) {
        return Err(CoreError::InvalidParameter(format!(
            "averaging factor {m} for {} samples: 1 ≤ m ≤ samples is needed",
            x.len()
        )));
    }
    let rows: Vec<Vec<f64>> = ms
        .par_iter()
        .map(|&m| one_factor(x, mu, m, dmax, cancel))
        .collect();
    cancel.check()?;
    Ok(rows.concat())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The sums the slow way: every block average and difference held.
    fn direct(x: &[f64], mu: f64, m: usize, dmax: usize) -> Vec<f64> {
        let k = x.len() / m;
        let mut w: Vec<f64> = (0..k)
            .map(|j| x[j * m..(j + 1) * m].iter().map(|&s| s - mu).sum::<f64>() / m as f64)
            .collect();
        let mut out = Vec::new();
        for d in 0..=dmax {
            if d > 0 {
                w = w.windows(2).map(|p| p[1] - p[0]).collect();
            }
            let s1: f64 = w.iter().sum();
            let s2: f64 = w.iter().map(|v| v * v).sum();
            let c: f64 = w.windows(2).map(|p| p[0] * p[1]).sum();
            let (f, l) = match (w.first(), w.last()) {
                (Some(&f), Some(&l)) => (f, l),
                _ => (f64::NAN, f64::NAN),
            };
            out.extend_from_slice(&[s1, s2, c, f, l]);
        }
        out
    }

    fn close(a: f64, b: f64) -> bool {
        (a.is_nan() && b.is_nan()) || (a - b).abs() <= 1e-12 * (1.0 + a.abs().max(b.abs()))
    }

    #[test]
    fn sums_match_the_held_averages() {
        let x: Vec<f64> = (0..10_007)
            .map(|i| ((i * 7919 % 1013) as f64).sin() + 1e-3 * i as f64)
            .collect();
        let ms = [1, 2, 3, 7, 64, 3000, 5003, 10_007];
        let got = block_lag1_sums(&x, 0.4, &ms, 2, &Cancel::new()).unwrap();
        for (r, &m) in ms.iter().enumerate() {
            let want = direct(&x, 0.4, m, 2);
            let row = &got[r * 3 * STATS..(r + 1) * 3 * STATS];
            for (g, w) in row.iter().zip(&want) {
                assert!(close(*g, *w), "m = {m}: {g} vs {w}");
            }
        }
    }

    #[test]
    fn bad_factor_and_cancel_are_errors() {
        let x = [1.0, 2.0, 3.0];
        let e = block_lag1_sums(&x, 0.0, &[4], 2, &Cancel::new()).unwrap_err();
        assert!(format!("{e}").contains("averaging factor 4 for 3 samples"));
        let c = Cancel::new();
        c.cancel();
        assert!(matches!(
            block_lag1_sums(&x, 0.0, &[1], 2, &c),
            Err(CoreError::Cancelled)
        ));
    }
}

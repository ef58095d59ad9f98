//! Theo1 (Howe & Peppler 2003) of whole records and of sliding windows.
//!
//! Conventions: `y` holds M rate samples; the phase (angle) record has N = M + 1 points
//! x_0 = 0, x_k = Σ_{i<k} (y_i − ȳ) (in rate·τ0 units, so the results below need no τ0 factor).
//! For even m, 2 ≤ m ≤ N − 1, h = m/2, L = N − m:
//!
//!   Theo1(m) = T(m) / (0.75 · L · m²),   T(m) = Σ_{d=1}^{h} (1/d) Σ_{i=0}^{L−1} e_{d,m−d}(i)²,
//!   e_{d,s}(i) = x_i − x_{i+d} − x_{i+s} + x_{i+d+s},                          τ = 0.75 · m · τ0,
//!
//! which is SP 1065's double sum with d = m/2 − δ. (e is the difference of two d-sample block sums
//! of the rate, s samples apart: e_{d,s}(i) = B_d(i+s) − B_d(i).)
//!
//! # Whole record: O(N²) for all m at once
//! A squared combination with zero-sum coefficients is a combination of squared differences:
//! (Σ c_k x_k)² = −Σ_{k<l} c_k c_l (x_k − x_l)². With F_ℓ = Σ_{k=0}^{N−1−ℓ} (x_{k+ℓ} − x_k)² (all
//! pairs at lag ℓ) and W_n(ℓ) = the same sum over the pairs inside the first n points plus over the
//! pairs inside the last n points, the range corrections of the six pairs of e collapse to
//!
//!   Σ_i e_{d,m−d}(i)² = 2F_d + 2F_{m−d} − F_m − F_{m−2d} − W_m(d) − W_m(m−d) + W_{m−d}(m−2d).
//!
//! W_n is built point by point (adding point n adds the n pairs that end on it, one vectorised pass)
//! and read at the stages where the m's need it; the head and tail halves run on the record and on
//! its reverse, in parallel. Every F and W is a sum of non-negative squares of differences — no
//! products x_k·x_l of large phase values as in the textbook expansion — and the phase is detrended
//! first (Theo1 ignores a linear phase), so the cancellation in the combination stays small.
//!
//! # Sliding windows: per (d, m) term sequences
//! For windows the same pairs are summed with the DAVAR machinery: for each m and d ≤ m/2 the terms
//! e_{d,m−d}(i)² are formed from Van Herk / Gil-Werman block sums of the rate (local rounding, no
//! drift) and summed per window in hop-aligned blocks — O(M) per (d, m), independent of window and
//! hop, and exactly the per-window double sum up to rounding. Theo1 is invariant to the window's own
//! mean and slope, so one record-wide mean serves every window.
//!
//! The module's parts: `whole` (whole records: the head passes and their vectorised kernels) and
//! `sliding` (sliding windows).

mod sliding;
mod whole;

pub use sliding::{dynamic_theo1, dynamic_theo1_cancellable};
pub use whole::{static_theo1, static_theo1_cancellable};

use crate::allan::{check_finite, check_shape, compensated_mean, Compensated};
use crate::error::{CoreError, Result};

/// Checks Theo1 averaging factors for a record (or window) of `n_rate` rate samples.
fn check_ms(n_rate: usize, ms: &[usize], what: &str) -> Result<()> {
    if ms.is_empty() {
        return Err(CoreError::InvalidParameter(
            "no averaging factors given".into(),
        ));
    }
    if let Some(&m) = ms.iter().find(|&&m| m < 2 || m % 2 != 0 || m > n_rate) {
        return Err(CoreError::InvalidParameter(format!(
            "Theo1 averaging factor m = {m} is not allowed for a {what} of {n_rate} samples: \
             m must be even and 2 ≤ m ≤ {n_rate} (the number of phase points − 1)"
        )));
    }
    Ok(())
}

fn check_columns(columns: &[&[f64]]) -> Result<usize> {
    let n = check_shape(columns)?;
    check_finite(columns)?;
    Ok(n)
}

/// Phase of the mean-removed rate (compensated cumulative sum), with its least-squares line removed.
pub fn detrended_phase(y: &[f64]) -> Vec<f64> {
    let mu = compensated_mean(y);
    let n = y.len() + 1;
    let mut x = Vec::with_capacity(n);
    x.push(0.0);
    let mut acc = Compensated::default();
    for &v in y {
        acc.add(v - mu);
        x.push(acc.value());
    }
    let mid = (n - 1) as f64 / 2.0;
    let a = compensated_mean(&x);
    let mut sxy = Compensated::default();
    for (i, &v) in x.iter().enumerate() {
        sxy.add((v - a) * (i as f64 - mid));
    }
    let nf = n as f64;
    let b = sxy.value() / (nf * (nf * nf - 1.0) / 12.0);
    for (i, v) in x.iter_mut().enumerate() {
        *v -= a + b * (i as f64 - mid);
    }
    x
}

/// Theo1 numerator T(m) by the definition (O(L·m)); the reference the fast paths are tested against.
pub fn theo1_direct(x: &[f64], m: usize) -> f64 {
    let n = x.len();
    let h = m / 2;
    let l = n - m;
    let mut t = 0.0;
    for d in 1..=h {
        let mut s = 0.0;
        for i in 0..l {
            let e = x[i] - x[i + d] - x[i + m - d] + x[i + m];
            s += e * e;
        }
        t += s / d as f64;
    }
    t / (0.75 * l as f64 * (m * m) as f64)
}

/// Sorted distinct copy of `ms` and, for each original position, its index in the copy.
fn sorted_unique(ms: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let mut u = ms.to_vec();
    u.sort_unstable();
    u.dedup();
    let pos = ms.iter().map(|m| u.binary_search(m).unwrap()).collect();
    (u, pos)
}

#[cfg(test)]
mod tests {
    use super::*;

    pub(super) use allanite_testutil::lcg_uniform as lcg;

    pub(super) fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

    #[test]
    fn bad_m_is_an_error() {
        let y = lcg(50, 1);
        assert!(static_theo1(&[&y], &[3]).is_err());
        assert!(static_theo1(&[&y], &[52]).is_err());
        assert!(dynamic_theo1(&[&y], 20, 1, &[22]).is_err());
    }
}

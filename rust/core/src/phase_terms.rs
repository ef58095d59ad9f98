//! Phase-domain estimators of the allantools-compatible front door (`allanite.compat`) that the
//! rate-domain kernels do not cover. Each works on a *phase* record x_0 … x_{N−1} (allantools' and
//! SigmaTheta's input) and returns, per averaging factor m, the sum of its terms and their number;
//! the caller scales (τ0 enters only there).
//!
//! * **Parabolic variance** (PVAR; F. Vernotte, M. Lenczner, P.-Y. Bourgeois, E. Rubiola, *The
//!   parabolic variance (PVAR): a wavelet variance based on the least-square fit*, IEEE TUFFC 63(4),
//!   2016, eq. 13): σ²_P(τ) = 72 / (M m⁴ τ²) · Σ_{i<M} u_i²,
//!   u_i = Σ_{k=0}^{m−1} ((m − 1)/2 − k)(x_{i+k} − x_{i+k+m}), over the M = N − 2m terms
//!   i = 0 … N − 2m − 1 that SigmaTheta (and allantools) average. m ≥ 2; at m = 1 PVAR is AVAR.
//! * **Allan covariance** of two synchronous phase records (the Groslambert codeviation, F. Vernotte
//!   et al., *Three-cornered hat and Groslambert covariance*, 2016; Lantz et al. 2019): the sum of
//!   products of their overlapping second differences Δ²x = x_{i+2m} − 2x_{i+m} + x_i, i < N − 2m.
//! * **Gap-skipping overlapping Allan variance** of a phase record with missing points (NaN): the
//!   overlapping second differences whose three points are all present, as allantools' `gradev`
//!   (Sesia, Cantoni, Cernigliaro, Signorile, Fantino, Tavella, *An efficient and
//!   configurable preprocessing algorithm to improve stability analysis*, IEEE TUFFC 63(4), 2016).
//!
//! u_i is a weighted m-sum, formed in O(1) per term by the recurrences
//!   w_{i+1} = w_i − d_i + d_{i+m},  u_{i+1} = u_i − c_0 d_i + (c_0 − m) d_{i+m} + w_{i+1}
//! (d_j = x_j − x_{j+m}, w_i = Σ_{k<m} d_{i+k}, c_0 = (m − 1)/2), restarted from its definition every
//! m terms so that rounding cannot build up along the record: O(N) per τ. The weights sum to zero, so
//! d is centred on its mean first (u is unchanged) and a frequency offset costs no digits.

use crate::allan::compensated_mean;
use crate::allan::Compensated;
use crate::error::{CoreError, Result};
use rayon::prelude::*;

/// Σ of one estimator's terms at one averaging factor, and their number.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TermSum {
    pub sum: f64,
    pub count: usize,
}

fn check_ms(n: usize, ms: &[usize], span: usize, what: &str) -> Result<()> {
    if ms.is_empty() {
        return Err(CoreError::InvalidParameter(
            "no averaging factors given".into(),
        ));
    }
    if let Some(&m) = ms.iter().find(|&&m| m == 0 || span * m >= n) {
        return Err(CoreError::InvalidParameter(format!(
            "{what} averaging factor m = {m} needs 1 ≤ m and {span}·m < N = {n} phase points"
        )));
    }
    Ok(())
}

fn check_finite(x: &[f64], axis: usize, allow_nan: bool) -> Result<()> {
    match x
        .iter()
        .position(|v| v.is_infinite() || (!allow_nan && v.is_nan()))
    {
        Some(index) => Err(CoreError::NonFinite {
            axis,
            index,
            value: x[index],
        }),
        None => Ok(()),
    }
}

/// PVAR term sums Σ u_i² (M = N − 2m terms) of a phase record at every m ≥ 2.
pub fn pvar_sums(x: &[f64], ms: &[usize]) -> Result<Vec<TermSum>> {
    check_ms(x.len(), ms, 2, "PVAR")?;
    if let Some(&m) = ms.iter().find(|&&m| m < 2) {
        return Err(CoreError::InvalidParameter(format!(
            "PVAR averaging factor m = {m}: the parabolic weights need m ≥ 2 (at m = 1 PVAR is AVAR)"
        )));
    }
    check_finite(x, 0, false)?;
    Ok(ms.par_iter().map(|&m| pvar_one(x, m)).collect())
}

fn pvar_one(x: &[f64], m: usize) -> TermSum {
    let n = x.len();
    let count = n - 2 * m;
    let mut d: Vec<f64> = (0..n - m).map(|j| x[j] - x[j + m]).collect();
    let mu = compensated_mean(&d);
    d.iter_mut().for_each(|v| *v -= mu);
    let c0 = (m as f64 - 1.0) / 2.0;
    let cm = c0 - m as f64;
    let (mut u, mut w) = (0.0f64, 0.0f64);
    let mut acc = Compensated::default();
    for i in 0..count {
        if i % m == 0 {
            let win = &d[i..i + m];
            w = win.iter().sum();
            u = win
                .iter()
                .enumerate()
                .map(|(k, v)| (c0 - k as f64) * v)
                .sum();
        } else {
            let (old, new) = (d[i - 1], d[i - 1 + m]);
            w += new - old;
            u += cm * new - c0 * old + w;
        }
        acc.add(u * u);
    }
    TermSum {
        sum: acc.value(),
        count,
    }
}

/// Σ Δ²x1·Δ²x2 over the N − 2m overlapping second differences of two phase records of equal length.
pub fn allan_covariance_sums(x1: &[f64], x2: &[f64], ms: &[usize]) -> Result<Vec<TermSum>> {
    if x1.len() != x2.len() {
        return Err(CoreError::InvalidInput(format!(
            "the two phase records must have the same length, got {} and {} points",
            x1.len(),
            x2.len()
        )));
    }
    check_ms(x1.len(), ms, 2, "Allan covariance")?;
    check_finite(x1, 0, false)?;
    check_finite(x2, 1, false)?;
    Ok(ms
        .par_iter()
        .map(|&m| {
            let count = x1.len() - 2 * m;
            let mut acc = Compensated::default();
            for i in 0..count {
                let a = x1[i + 2 * m] - 2.0 * x1[i + m] + x1[i];
                let b = x2[i + 2 * m] - 2.0 * x2[i + m] + x2[i];
                acc.add(a * b);
            }
            TermSum {
                sum: acc.value(),
                count,
            }
        })
        .collect())
}

/// Σ (Δ²x)² over the overlapping second differences whose three phase points are all present
/// (not NaN), and how many there are. ±inf is refused.
pub fn oavar_phase_gap_sums(x: &[f64], ms: &[usize]) -> Result<Vec<TermSum>> {
    check_ms(x.len(), ms, 2, "OAVAR")?;
    check_finite(x, 0, true)?;
    Ok(ms
        .par_iter()
        .map(|&m| {
            let mut acc = Compensated::default();
            let mut count = 0;
            for i in 0..x.len() - 2 * m {
                let v = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
                if !v.is_nan() {
                    acc.add(v * v);
                    count += 1;
                }
            }
            TermSum {
                sum: acc.value(),
                count,
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    use allanite_testutil::lcg_uniform as lcg;

    /// PVAR's sum straight from its definition (O(N·m)).
    fn pvar_direct(x: &[f64], m: usize) -> f64 {
        let c0 = (m as f64 - 1.0) / 2.0;
        (0..x.len() - 2 * m)
            .map(|i| {
                let u: f64 = (0..m)
                    .map(|k| (c0 - k as f64) * (x[i + k] - x[i + k + m]))
                    .sum();
                u * u
            })
            .sum()
    }

    #[test]
    fn pvar_recurrence_equals_the_definition() {
        // phase with a large frequency offset, which the weights (summing to 0) cancel exactly: the
        // centring keeps the digits the definition on the offset-free record has
        let v = lcg(3001, 7);
        let x: Vec<f64> = v
            .iter()
            .enumerate()
            .map(|(i, v)| 1e3 * i as f64 + v)
            .collect();
        let ms = [2, 3, 7, 64, 500, 1000];
        let got = pvar_sums(&x, &ms).unwrap();
        for (g, &m) in got.iter().zip(&ms) {
            assert_eq!(g.count, x.len() - 2 * m);
            let want = pvar_direct(&v, m);
            assert!(
                ((g.sum - want) / want).abs() < 1e-9,
                "m={m}: {} vs {want}",
                g.sum
            );
        }
    }

    #[test]
    fn pvar_of_a_line_is_zero_and_bad_m_is_named() {
        let x: Vec<f64> = (0..100).map(|i| 3.0 + 0.5 * i as f64).collect();
        assert!(pvar_sums(&x, &[2, 10, 49])
            .unwrap()
            .iter()
            .all(|t| t.sum.abs() < 1e-18));
        let e = pvar_sums(&x, &[1]).unwrap_err().to_string();
        assert!(e.contains("m = 1") && e.contains("m ≥ 2"), "{e}");
        let e = pvar_sums(&x, &[50]).unwrap_err().to_string();
        assert!(e.contains("m = 50") && e.contains("N = 100"), "{e}");
    }

    #[test]
    fn covariance_of_a_record_with_itself_is_its_allan_sum() {
        let x = lcg(500, 3);
        let cov = allan_covariance_sums(&x, &x, &[1, 5, 100]).unwrap();
        let var = oavar_phase_gap_sums(&x, &[1, 5, 100]).unwrap();
        for (c, v) in cov.iter().zip(&var) {
            assert_eq!(c.count, v.count);
            assert!(((c.sum - v.sum) / v.sum).abs() < 1e-14);
        }
        let e = allan_covariance_sums(&x, &x[1..], &[1])
            .unwrap_err()
            .to_string();
        assert!(e.contains("500 and 499"), "{e}");
    }

    #[test]
    fn gap_sums_skip_terms_touching_a_missing_point() {
        let mut x = lcg(50, 11);
        x[20] = f64::NAN;
        let got = oavar_phase_gap_sums(&x, &[1, 4]).unwrap();
        for (g, m) in got.iter().zip([1usize, 4]) {
            let kept: Vec<f64> = (0..50 - 2 * m)
                .filter(|&i| ![i, i + m, i + 2 * m].contains(&20))
                .map(|i| (x[i + 2 * m] - 2.0 * x[i + m] + x[i]).powi(2))
                .collect();
            assert_eq!(g.count, kept.len());
            assert_eq!(g.count, 50 - 2 * m - 3);
            assert!((g.sum - kept.iter().sum::<f64>()).abs() < 1e-12);
        }
        x[3] = f64::INFINITY;
        let e = oavar_phase_gap_sums(&x, &[1]).unwrap_err().to_string();
        assert!(e.contains("sample 3"), "{e}");
    }
}

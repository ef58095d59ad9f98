//! The Whittle noise fit's reweighted NNLS (Python `allanite.model._whittle._fit_noise`): non-negative
//! amounts of a few spectral shapes fitted to band-mean powers, the weights √m/S of the Whittle
//! likelihood's score equations recomputed from the last pass's S, until S moves by less than `rtol`
//! (relative) in every band. The shapes are taken as given (scaled by their maxima in Python) and
//! the weighted columns are not rescaled, as SciPy's `nnls` gets them there; the NNLS is Lawson–
//! Hanson's of the per-window fits (started from the previous pass's positive set when that is
//! feasible), so the numbers agree with the Python loop to rounding, not bit for bit.

use super::curves::CurveFitError;
use super::dense::{nnls, NnlsWork};

/// One noise fit: `shapes` (bands × k, row-major), `power` and `root_m` (√ of each band's bins) and
/// the first pass's noise level `s_start` per band. Returns the amounts (k) and the fitted level per
/// band (the last pass's, floored at 1e-12 of its largest band).
pub fn whittle_noise(
    shapes: &[f64],
    k: usize,
    power: &[f64],
    root_m: &[f64],
    s_start: &[f64],
    max_iter: usize,
    rtol: f64,
) -> Result<(Vec<f64>, Vec<f64>), CurveFitError> {
    let nb = power.len();
    assert!(shapes.len() == nb * k && root_m.len() == nb && s_start.len() == nb);
    let mut s_cur = s_start.to_vec();
    let mut s_new = vec![0.0; nb];
    let mut coef = vec![0.0; k];
    let mut x = vec![0.0; k];
    let mut aw = vec![0.0; nb * k]; // column-major, as the NNLS takes it
    let mut bw = vec![0.0; nb];
    let mut ws = NnlsWork::new(nb, k);
    for _ in 0..max_iter {
        for i in 0..nb {
            let sw = root_m[i] / s_cur[i];
            for c in 0..k {
                aw[c * nb + i] = shapes[i * k + c] * sw;
            }
            bw[i] = power[i] * sw;
        }
        if !(aw.iter().all(|v| v.is_finite()) && bw.iter().all(|v| v.is_finite())) {
            return Err(CurveFitError::NonFinite);
        }
        if !nnls(&aw, nb, k, &bw, &mut x, 50 * k, &mut ws) {
            return Err(CurveFitError::MaxIter);
        }
        let mut top = f64::NEG_INFINITY;
        for (i, s) in s_new.iter_mut().enumerate() {
            *s = shapes[i * k..(i + 1) * k]
                .iter()
                .zip(&x)
                .map(|(a, c)| a * c)
                .sum();
            top = top.max(*s);
        }
        let floor = 1e-12 * top.max(1e-300);
        let mut change: f64 = 0.0;
        for (s, &old) in s_new.iter_mut().zip(&s_cur) {
            *s = s.max(floor);
            change = change.max((*s / old - 1.0).abs());
        }
        coef.copy_from_slice(&x);
        std::mem::swap(&mut s_cur, &mut s_new);
        if change < rtol {
            break;
        }
    }
    Ok((coef, s_cur))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Band powers exactly a·shape₀ + b·shape₁ (no noise): the fit returns the amounts and the level.
    #[test]
    fn exact_powers_give_their_amounts() {
        let nb = 40;
        let f: Vec<f64> = (1..=nb).map(|i| i as f64 / nb as f64).collect();
        let shapes: Vec<f64> = f.iter().flat_map(|&v| [v * v, 1.0, v]).collect();
        let power: Vec<f64> = f.iter().map(|&v| 3.0 * v * v + 0.5).collect();
        let root_m: Vec<f64> = (0..nb).map(|i| ((1 + i % 4) as f64).sqrt()).collect();
        let (coef, s) = whittle_noise(&shapes, 3, &power, &root_m, &power, 60, 1e-6).unwrap();
        assert!((coef[0] - 3.0).abs() < 1e-9 && (coef[1] - 0.5).abs() < 1e-9);
        assert!(coef[2].abs() < 1e-9);
        for (a, b) in s.iter().zip(&power) {
            assert!((a / b - 1.0).abs() < 1e-9);
        }
    }

    /// A power that no non-negative amounts reach below (a negative slope on increasing shapes):
    /// the amounts stay ≥ 0, and a non-finite power is refused as SciPy refuses it.
    #[test]
    fn amounts_stay_non_negative_and_nan_is_refused() {
        let nb = 30;
        let shapes: Vec<f64> = (0..nb)
            .flat_map(|i| [1.0, (i + 1) as f64 / nb as f64])
            .collect();
        let power: Vec<f64> = (0..nb).map(|i| 2.0 - (i as f64) / nb as f64).collect();
        let root_m = vec![1.0; nb];
        let (coef, _) = whittle_noise(&shapes, 2, &power, &root_m, &power, 60, 1e-6).unwrap();
        assert!(coef[0] > 0.0 && coef[1] == 0.0);
        let mut bad = power.clone();
        bad[3] = f64::NAN;
        let err = whittle_noise(&shapes, 2, &bad, &root_m, &power, 60, 1e-6);
        assert_eq!(err, Err(CurveFitError::NonFinite));
    }
}

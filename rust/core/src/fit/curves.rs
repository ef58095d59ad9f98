//! `refine`'s reweighted NNLS of one Allan curve on many designs at once (Python
//! `allanite.model.refinement._irls.irls`), the designs on rayon's threads.
//!
//! Each design (n τ × k columns) is fitted alone, as the Python loop fits it: weights ν/(2·model²),
//! the columns scaled to unit norm, Lawson–Hanson's NNLS (the one of the per-window fits, started
//! from the previous pass's set of positive coefficients when that is feasible), the model damped geometrically between passes, ν per τ the Satterthwaite combination
//! of the columns' EDF by their shares of the model; a design stops once no coefficient moved by more
//! than `rtol` (relative). Held columns stay at their coefficient and the others are fitted to the
//! curve less the held part. The NNLS is not SciPy's routine, so the numbers agree with the Python
//! loop to rounding, not bit for bit.

use super::dense::{nnls, NnlsWork};
use rayon::prelude::*;

/// The designs of one curve to fit.
#[derive(Debug, Clone, Copy)]
pub struct CurveDesigns<'a> {
    /// Designs.
    pub n_designs: usize,
    /// τ of the curve.
    pub n_tau: usize,
    /// Columns per design.
    pub n_cols: usize,
    /// Allan variance per unit coefficient, (designs, n_tau, n_cols) row-major.
    pub design: &'a [f64],
    /// EDF of each column's estimate per τ, shaped as `design`.
    pub nu_cols: &'a [f64],
    /// The curve, n_tau.
    pub y: &'a [f64],
    /// EDF per τ the first pass weights with, n_tau.
    pub nu0: &'a [f64],
    /// Per column: the coefficient a held column stays at, NaN for a fitted one.
    pub fixed: &'a [f64],
    /// Passes at most.
    pub max_iter: usize,
    /// Floor of the model (the weights' denominator and the damped model).
    pub floor: f64,
    /// Relative change of every coefficient below which a design stops.
    pub rtol: f64,
}

/// Why a design's fit could not be made.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum CurveFitError {
    /// A weighted design or curve was not finite (SciPy's "array must not contain infs or NaNs").
    NonFinite,
    /// The NNLS did not settle in 50 × (fitted columns) steps (SciPy's "Maximum number of iterations").
    MaxIter,
}

/// One design's (design, EDF columns) and where its (coefficients, EDF per τ) go.
type Job<'x> = ((&'x [f64], &'x [f64]), (&'x mut [f64], &'x mut [f64]));

/// Coefficients (designs × n_cols) and EDF per τ (designs × n_tau) each design stopped at.
pub fn irls_curves(p: &CurveDesigns) -> Result<(Vec<f64>, Vec<f64>), CurveFitError> {
    let (g_n, n, k) = (p.n_designs, p.n_tau, p.n_cols);
    assert_eq!(p.design.len(), g_n * n * k);
    assert_eq!(p.nu_cols.len(), g_n * n * k);
    assert!(p.y.len() == n && p.nu0.len() == n && p.fixed.len() == k);
    let mut theta = vec![0.0; g_n * k];
    let mut nu = vec![0.0; g_n * n];
    let one = |((a, nc), (th, nu)): Job| Fit::new(p, a, nc).run(p, th, nu);
    // a design is some hundred microseconds' work: threads only where there are several
    if g_n >= 4 {
        p.design
            .par_chunks_exact(n * k)
            .zip(p.nu_cols.par_chunks_exact(n * k))
            .zip(
                theta
                    .par_chunks_exact_mut(k)
                    .zip(nu.par_chunks_exact_mut(n)),
            )
            .try_for_each(one)?;
    } else {
        p.design
            .chunks_exact(n * k)
            .zip(p.nu_cols.chunks_exact(n * k))
            .zip(theta.chunks_exact_mut(k).zip(nu.chunks_exact_mut(n)))
            .try_for_each(one)?;
    }
    Ok((theta, nu))
}

/// One design's fit and its workspace.
struct Fit<'a> {
    a: &'a [f64],
    nu_cols: &'a [f64],
    /// Fitted columns' indices.
    free: Vec<usize>,
    /// The curve less the held columns' part.
    y_free: Vec<f64>,
    aw: Vec<f64>,
    bw: Vec<f64>,
    scale: Vec<f64>,
    x: Vec<f64>,
    new: Vec<f64>,
    model: Vec<f64>,
    tot: Vec<f64>,
    ws: NnlsWork,
}

impl<'a> Fit<'a> {
    fn new(p: &CurveDesigns, a: &'a [f64], nu_cols: &'a [f64]) -> Self {
        let (n, k) = (p.n_tau, p.n_cols);
        let free: Vec<usize> = (0..k).filter(|&c| p.fixed[c].is_nan()).collect();
        let y_free = (0..n)
            .map(|i| {
                let row = &a[i * k..(i + 1) * k];
                let held: f64 = (0..k)
                    .filter(|&c| !p.fixed[c].is_nan())
                    .map(|c| row[c] * p.fixed[c])
                    .sum();
                p.y[i] - held
            })
            .collect();
        let f = free.len();
        Fit {
            a,
            nu_cols,
            y_free,
            aw: vec![0.0; n * f],
            bw: vec![0.0; n],
            scale: vec![0.0; f],
            x: vec![0.0; f],
            new: vec![0.0; k],
            model: p.y.to_vec(),
            tot: vec![0.0; n],
            ws: NnlsWork::new(n, f),
            free,
        }
    }

    fn run(
        mut self,
        p: &CurveDesigns,
        theta: &mut [f64],
        nu: &mut [f64],
    ) -> Result<(), CurveFitError> {
        let (n, k) = (p.n_tau, p.n_cols);
        if !(self.a.iter().all(|v| v.is_finite()) && p.y.iter().all(|v| v.is_finite())) {
            return Err(CurveFitError::NonFinite);
        }
        for (t, &f) in theta.iter_mut().zip(p.fixed) {
            *t = if f.is_nan() { 0.0 } else { f };
        }
        nu.copy_from_slice(p.nu0);
        for pass in 0..p.max_iter {
            self.solve(p, nu)?;
            // the model: its parts' sum, damped geometrically after the first pass
            for i in 0..n {
                let row = &self.a[i * k..(i + 1) * k];
                self.tot[i] = sum_products(row, &self.new);
                let new_model = self.tot[i].max(p.floor);
                self.model[i] = if pass == 0 {
                    new_model
                } else {
                    (self.model[i] * new_model).sqrt()
                };
            }
            let done = (0..k).all(|c| (self.new[c] - theta[c]).abs() <= p.rtol * theta[c].abs());
            theta.copy_from_slice(&self.new);
            if self.new.iter().any(|&v| v != 0.0) {
                self.combined_edf(k, nu);
            }
            if done {
                break;
            }
        }
        Ok(())
    }

    /// The weighted NNLS of the fitted columns into `self.new` (held columns at their coefficients).
    fn solve(&mut self, p: &CurveDesigns, nu: &[f64]) -> Result<(), CurveFitError> {
        let (n, k, f) = (p.n_tau, p.n_cols, self.free.len());
        for (c, &fx) in self.new.iter_mut().zip(p.fixed) {
            *c = if fx.is_nan() { 0.0 } else { fx };
        }
        if f == 0 {
            return Ok(());
        }
        for (i, &nu_i) in nu.iter().enumerate() {
            let m = self.model[i].max(p.floor);
            let sw = (nu_i / (2.0 * (m * m))).sqrt();
            self.bw[i] = self.y_free[i] * sw;
            for (j, &c) in self.free.iter().enumerate() {
                self.aw[j * n + i] = self.a[i * k + c] * sw;
            }
        }
        if !(self.aw.iter().all(|v| v.is_finite()) && self.bw.iter().all(|v| v.is_finite())) {
            return Err(CurveFitError::NonFinite);
        }
        for (j, col) in self.aw.chunks_exact_mut(n).enumerate() {
            let norm = col.iter().map(|v| v * v).sum::<f64>().sqrt();
            let s = if norm == 0.0 { 1.0 } else { norm };
            self.scale[j] = s;
            for v in col.iter_mut() {
                *v /= s;
            }
        }
        if !nnls(&self.aw, n, f, &self.bw, &mut self.x, 50 * f, &mut self.ws) {
            return Err(CurveFitError::MaxIter);
        }
        for (j, &c) in self.free.iter().enumerate() {
            self.new[c] = self.x[j] / self.scale[j];
        }
        Ok(())
    }

    /// ν per τ: tot² / Σ_c part_c²/ν_c (Satterthwaite), kept where no column contributes.
    fn combined_edf(&self, k: usize, nu: &mut [f64]) {
        for (i, nu_i) in nu.iter_mut().enumerate() {
            let row = &self.a[i * k..(i + 1) * k];
            let nc = &self.nu_cols[i * k..(i + 1) * k];
            let mut den = 0.0;
            for c in 0..k {
                let part = row[c] * self.new[c];
                den += part * part / nc[c];
            }
            if den > 0.0 {
                *nu_i = self.tot[i] * self.tot[i] / den.max(1e-300);
            }
        }
    }
}

fn sum_products(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// y = 2·col0 + 3·col1 exactly: the fit returns the coefficients whatever the weights.
    #[test]
    fn an_exact_curve_is_fitted_exactly() {
        let n = 12;
        let tau: Vec<f64> = (0..n).map(|i| 2f64.powi(i as i32)).collect();
        let mut a = vec![0.0; n * 2];
        for i in 0..n {
            a[i * 2] = 1.0 / tau[i];
            a[i * 2 + 1] = tau[i];
        }
        let y: Vec<f64> = (0..n)
            .map(|i| 2.0 * a[i * 2] + 3.0 * a[i * 2 + 1])
            .collect();
        let nu_cols = vec![10.0; n * 2];
        let nu0 = vec![10.0; n];
        let fixed = [f64::NAN, f64::NAN];
        let p = CurveDesigns {
            n_designs: 1,
            n_tau: n,
            n_cols: 2,
            design: &a,
            nu_cols: &nu_cols,
            y: &y,
            nu0: &nu0,
            fixed: &fixed,
            max_iter: 40,
            floor: 1e-12,
            rtol: 1e-6,
        };
        let (theta, nu) = irls_curves(&p).unwrap();
        assert!((theta[0] - 2.0).abs() < 1e-9 && (theta[1] - 3.0).abs() < 1e-9);
        assert!(nu
            .iter()
            .all(|&v| (v - 10.0).abs() < 1e-9 * 10.0 || v > 10.0));
        // held at 3, the other column still fitted to 2
        let fixed = [f64::NAN, 3.0];
        let (theta, _) = irls_curves(&CurveDesigns { fixed: &fixed, ..p }).unwrap();
        assert_eq!(theta[1], 3.0);
        assert!((theta[0] - 2.0).abs() < 1e-9);
    }

    #[test]
    fn a_non_finite_design_is_an_error() {
        let a = [1.0, f64::NAN];
        let p = CurveDesigns {
            n_designs: 1,
            n_tau: 2,
            n_cols: 1,
            design: &a,
            nu_cols: &[1.0, 1.0],
            y: &[1.0, 1.0],
            nu0: &[1.0, 1.0],
            fixed: &[f64::NAN],
            max_iter: 5,
            floor: 1e-12,
            rtol: 1e-6,
        };
        assert_eq!(irls_curves(&p), Err(CurveFitError::NonFinite));
    }
}

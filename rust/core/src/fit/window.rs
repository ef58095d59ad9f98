//! One window's noise-model fit: the iteration of `allanite.model.fitting` (`_fit_core`, `_fit_irls`,
//! `_fit_gls`) step for step, in buffers reused from window to window. The Python functions are the
//! reference; each step here names the one it mirrors, and `tests/test_batched_fit.py` checks the two
//! agree on measured and simulated windows.

use super::dense::{cholesky, forward_solve, nnls, NnlsWork};
use super::shared::{tri_len, tri_row, Shared};

mod covariance;
use super::{Gls, Problem};
use std::cmp::Ordering;

/// A model this far below the estimates' peak is floored (fitting's `1e-12 * np.max(avar)`).
const MODEL_FLOOR: f64 = 1e-12;
/// A model variance below this share of the independent one is replaced by it (a bare ramp).
const BARE_SHARE: f64 = 1e-6;
/// Ridges tried on the correlation matrix when rounding made it indefinite (`_chol`).
const RIDGES: [f64; 6] = [0.0, 1e-12, 1e-10, 1e-8, 1e-6, 1e-4];

/// Why a window is handed back to the reference path (each is what the Python fit does differently:
/// an eigen-decomposition, the independent-weights result, an error).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Handback {
    /// Every ridge of the Cholesky factor failed (Python then uses `eigh`).
    Indefinite,
    /// The GLS started or ended at θ = 0 (Python then returns the IRLS fit as it is).
    ZeroFit,
    /// NNLS did not settle, or a number was not finite.
    Numerical,
}

/// Buffers for one thread's windows.
pub(crate) struct Window {
    nt: usize,
    k: usize,
    sh: Shared,
    y: Vec<f64>,
    model: Vec<f64>,
    nu: Vec<f64>,
    nu0: Vec<f64>,
    theta: Vec<f64>,
    new: Vec<f64>,
    t1: Vec<f64>,
    t2: Vec<f64>,
    jump: Vec<f64>,
    tmp: Vec<f64>,
    scale: Vec<f64>,
    colw: Vec<f64>,
    aw: Vec<f64>,
    bw: Vec<f64>,
    cov: Vec<f64>,
    corr: Vec<f64>,
    l: Vec<f64>,
    th_s: Vec<f64>,
    gram: Vec<f64>,
    gv: Vec<f64>,
    ginv: Vec<f64>,
    bread: Vec<f64>,
    meat: Vec<f64>,
    idx: Vec<usize>,
    nn: NnlsWork,
}

/// The fit of one window: θ (squared coefficients), their covariance (k×k, NaN where the reference
/// leaves it so), χ² and the GLS iterations.
pub(crate) struct Out<'o> {
    pub theta: &'o mut [f64],
    pub cov: &'o mut [f64],
    pub chi2: f64,
    pub iterations: usize,
}

impl Window {
    pub(crate) fn new(p: &Problem) -> Self {
        let (nt, k) = (p.n_tau, p.n_terms);
        let z = |n: usize| vec![0.0; n];
        Window {
            nt,
            k,
            sh: Shared::new(p),
            y: z(nt),
            model: z(nt),
            nu: z(nt),
            nu0: z(nt),
            theta: z(k),
            new: z(k),
            t1: z(k),
            t2: z(k),
            jump: z(k),
            tmp: z(nt.max(k)),
            scale: z(k),
            colw: z(k),
            aw: z(nt * k),
            bw: z(nt),
            cov: z(nt * nt),
            corr: z(nt * nt),
            l: z(nt * nt),
            th_s: z(k),
            gram: z(k * k),
            gv: z(k * k),
            ginv: z(k * k),
            bread: z(k * k),
            meat: z(k * k),
            idx: Vec::with_capacity(k),
            nn: NnlsWork::new(nt, k),
        }
    }

    /// `_fit_core` on one window's estimates `avar` (already floored at 1e-300 and finite).
    pub(crate) fn fit(&mut self, p: &Problem, avar: &[f64], out: &mut Out) -> Result<(), Handback> {
        let peak = avar.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        // the power of two at the peak (math.frexp's exponent): exact scaling, no under- or overflow
        let scale = if peak > 0.0 && peak.is_finite() {
            2f64.powi(frexp_exp(peak))
        } else {
            1.0
        };
        if !scale.is_finite() {
            return Err(Handback::Numerical);
        }
        for (yi, &v) in self.y.iter_mut().zip(avar) {
            *yi = v / scale;
        }
        let iterations = if let Some(g) = &p.gls {
            self.irls(p, p.irls_iter.min(p.max_iter))?;
            if !self.theta.iter().any(|&v| v != 0.0) {
                return Err(Handback::ZeroFit);
            }
            let it = self.gls(p, g)?;
            out.chi2 = self.gls_covariance(p, g, out.cov)?;
            it
        } else {
            let it = self.irls(p, p.max_iter)?;
            out.chi2 = self.irls_covariance(p, out.cov);
            it
        };
        for (o, &t) in out.theta.iter_mut().zip(&self.theta) {
            *o = t * scale;
        }
        for c in out.cov.iter_mut() {
            *c *= scale * scale;
        }
        out.iterations = iterations;
        if out
            .theta
            .iter()
            .chain(std::iter::once(&out.chi2))
            .all(|v| v.is_finite())
        {
            Ok(())
        } else {
            Err(Handback::Numerical)
        }
    }

    fn floor(&self) -> f64 {
        MODEL_FLOOR * self.y.iter().copied().fold(f64::NEG_INFINITY, f64::max)
    }

    /// `nnls(a * sw[:, None], b * sw)` of `fitting`: columns scaled to unit norm, solved, scaled back.
    /// `self.aw` holds the (column-major) matrix, `self.bw` the right side; the result goes to `self.new`.
    fn scaled_nnls(&mut self) -> Result<(), Handback> {
        let (nt, k) = (self.nt, self.k);
        for c in 0..k {
            let col = &mut self.aw[c * nt..(c + 1) * nt];
            let norm = col.iter().map(|v| v * v).sum::<f64>().sqrt();
            let s = if norm == 0.0 { 1.0 } else { norm };
            self.colw[c] = s;
            for v in col.iter_mut() {
                *v /= s;
            }
        }
        if !nnls(
            &self.aw,
            nt,
            k,
            &self.bw,
            &mut self.new,
            50 * k,
            &mut self.nn,
        ) {
            return Err(Handback::Numerical);
        }
        for c in 0..k {
            self.new[c] /= self.colw[c];
        }
        Ok(())
    }

    /// `_fit_irls`'s iteration (independent weights ν/(2σ⁴), damped): leaves θ in `self.theta`, the
    /// model in `self.model`, ν in `self.nu`; returns the passes made.
    fn irls(&mut self, p: &Problem, max_iter: usize) -> Result<usize, Handback> {
        let (nt, k) = (self.nt, self.k);
        let a = p.design;
        self.model.copy_from_slice(&self.y);
        for i in 0..nt {
            self.nu[i] = p.nu_terms[i * k + p.start_col];
        }
        self.theta.fill(0.0);
        let floor = self.floor();
        let mut it = 0;
        for pass in 1..=max_iter {
            it = pass;
            for i in 0..nt {
                let m = self.model[i].max(1e-300);
                self.tmp[i] = (self.nu[i] / (2.0 * m * m)).sqrt();
                self.bw[i] = self.y[i] * self.tmp[i];
            }
            for (aw, col) in self
                .aw
                .chunks_exact_mut(nt)
                .zip(self.sh.design_cm.chunks_exact(nt))
            {
                for ((v, &d), &sw) in aw.iter_mut().zip(col).zip(&self.tmp[..nt]) {
                    *v = d * sw;
                }
            }
            self.scaled_nnls()?;
            let done = (0..k)
                .all(|c| (self.new[c] - self.theta[c]).abs() <= p.irls_rtol * self.theta[c].abs());
            for (i, row) in a.chunks_exact(k).enumerate() {
                let new_model = row_dot(row, &self.new).max(floor);
                self.model[i] = if pass == 1 {
                    new_model
                } else {
                    (self.model[i] * new_model).sqrt()
                };
            }
            self.theta.copy_from_slice(&self.new);
            if self.theta.iter().any(|&v| v != 0.0) {
                self.mixture_edf(p);
            }
            if done {
                break;
            }
        }
        Ok(it)
    }

    /// Σ(θ) into `self.cov` (`_covariance.assemble`), the model into `self.model`, a bare ramp's
    /// diagonal replaced by the independent variance, and Σ's Cholesky factor into `self.l`
    /// (`_fit_gls.factor` and `_chol`: the correlation matrix, with a growing ridge when rounding made
    /// it indefinite, scaled back).
    fn factor(&mut self, p: &Problem, g: &Gls, theta: &[f64]) -> Result<(), Handback> {
        let (nt, k) = (self.nt, self.k);
        let floor = self.floor();
        for (m, row) in self.model.iter_mut().zip(p.design.chunks_exact(k)) {
            *m = row_dot(row, theta).max(floor);
        }
        let ns = g.stoch.len();
        for (q, &c) in g.stoch.iter().enumerate() {
            self.th_s[q] = theta[c];
        }
        // Σ is symmetric and only its lower triangle is read below (Cholesky): only that is formed,
        // packed, from the blocks' packed lower triangles in `sh.blocks` (their order: S[a, b], T[a])
        let ntri = tri_len(nt);
        let tri = &mut self.cov[..ntri];
        tri.fill(0.0);
        let mut blocks = self.sh.blocks.chunks_exact(ntri);
        let mut add = |w: f64| {
            let blk = blocks.next().expect("one packed block per weight");
            if w != 0.0 {
                tri.iter_mut().zip(blk).for_each(|(c, s)| *c += w * s);
            }
        };
        for a in 0..ns {
            for b in 0..ns {
                add(self.th_s[a] * self.th_s[b]);
            }
        }
        if let Some(r) = g.ramp {
            for a in 0..ns {
                add(theta[r] * self.th_s[a]);
            }
        }
        for i in 0..nt {
            let d = tri_row(i) + i;
            let indep = 2.0 * self.model[i] * self.model[i] / self.nu0[i];
            // NumPy's `~(diag > 1e-6 · indep)`: a NaN diagonal counts as too small too
            let big = self.cov[d].partial_cmp(&(BARE_SHARE * indep)) == Some(Ordering::Greater);
            if !big {
                self.cov[d] += indep;
            }
        }
        for i in 0..nt {
            let c = self.cov[tri_row(i) + i];
            if !c.is_finite() {
                return Err(Handback::Numerical);
            }
            self.tmp[i] = c.max(1e-300).sqrt();
        }
        for i in 0..nt {
            let row = &self.cov[tri_row(i)..tri_row(i) + i + 1];
            for (j, &c) in row.iter().enumerate() {
                self.corr[i * nt + j] = c / (self.tmp[i] * self.tmp[j]);
            }
        }
        for ridge in RIDGES {
            if cholesky(&self.corr, nt, ridge, &mut self.l) {
                for i in 0..nt {
                    for v in &mut self.l[i * nt..i * nt + i + 1] {
                        *v *= self.tmp[i];
                    }
                }
                return Ok(());
            }
        }
        Err(Handback::Indefinite)
    }

    /// L⁻¹·A into `self.aw` (column-major) and L⁻¹·`rhs` into `self.bw`, L = `self.l`.
    fn whiten(&mut self, p: &Problem, rhs_is_residual: bool) {
        let (nt, k) = (self.nt, self.k);
        self.aw[..nt * k].copy_from_slice(&self.sh.design_cm);
        for col in self.aw[..nt * k].chunks_exact_mut(nt) {
            forward_solve(&self.l, nt, col);
        }
        for ((b, &y), row) in self
            .bw
            .iter_mut()
            .zip(&self.y)
            .zip(p.design.chunks_exact(k))
        {
            *b = if rhs_is_residual {
                y - row_dot(row, &self.theta)
            } else {
                y
            };
        }
        forward_solve(&self.l, nt, &mut self.bw);
    }

    /// One GLS pass from `theta` (`_fit_gls.step`): the whitened NNLS; the result in `self.new`.
    fn step(&mut self, p: &Problem, g: &Gls, theta: &[f64]) -> Result<(), Handback> {
        self.factor(p, g, theta)?;
        self.whiten(p, false);
        self.scaled_nnls()
    }

    /// The largest move of the model between `old` and `new`, relative to the new model (`_fit_gls.change`).
    fn change(&self, p: &Problem, new: &[f64], old: &[f64], floor: f64) -> f64 {
        let k = self.k;
        let (new, old) = (&new[..k], &old[..k]);
        p.design
            .chunks_exact(k)
            .map(|row| {
                let d: f64 = row
                    .iter()
                    .zip(new)
                    .zip(old)
                    .map(|((r, n), o)| r * (n - o))
                    .sum();
                let m = row_dot(row, new);
                d.abs() / m.max(floor)
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// `_fit_gls`'s fixed-point iteration with SQUAREM steps, from the IRLS θ in `self.theta`; returns
    /// the passes made.
    fn gls(&mut self, p: &Problem, g: &Gls) -> Result<usize, Handback> {
        let (nt, k) = (self.nt, self.k);
        self.nu0.copy_from_slice(&self.nu);
        let floor = self.floor();
        for c in 0..k {
            self.scale[c] = (0..nt)
                .map(|i| p.design[i * k + c] / self.y[i].max(floor))
                .fold(f64::NEG_INFINITY, f64::max);
        }
        let any = |v: &[f64]| v.iter().any(|&x| x != 0.0);
        let mut theta = std::mem::take(&mut self.theta);
        let (mut t1, mut t2, mut jump) = (
            std::mem::take(&mut self.t1),
            std::mem::take(&mut self.t2),
            std::mem::take(&mut self.jump),
        );
        let mut it = 0;
        let result = (|| {
            while it < p.max_iter {
                self.step(p, g, &theta)?;
                t1.copy_from_slice(&self.new);
                it += 1;
                if !any(&t1) || self.change(p, &t1, &theta, floor) < p.gls_tol {
                    theta.copy_from_slice(&t1);
                    break;
                }
                self.step(p, g, &t1)?;
                t2.copy_from_slice(&self.new);
                it += 1;
                let (mut nr, mut nv) = (0.0, 0.0);
                for c in 0..k {
                    let r = (t1[c] - theta[c]) * self.scale[c];
                    let v = (t2[c] - t1[c]) * self.scale[c] - r;
                    nr += r * r;
                    nv += v * v;
                }
                let (nr, nv) = (nr.sqrt(), nv.sqrt());
                let alpha = if nv == 0.0 {
                    -1.0
                } else {
                    (-nr / nv).min(-1.0)
                };
                for c in 0..k {
                    let j = theta[c] - 2.0 * alpha * (t1[c] - theta[c])
                        + alpha * alpha * (t2[c] - 2.0 * t1[c] + theta[c]);
                    jump[c] = j.max(0.0);
                }
                if jump.iter().all(|v| v.is_finite()) && any(&jump) {
                    self.step(p, g, &jump)?;
                } else {
                    self.new.copy_from_slice(&t2);
                }
                it += 1;
                let done = self.change(p, &self.new, &t2, floor) < p.gls_tol
                    && self.change(p, &t2, &t1, floor) < p.gls_tol;
                theta.copy_from_slice(&self.new);
                if done || !any(&theta) {
                    break;
                }
            }
            Ok(())
        })();
        self.theta = theta;
        (self.t1, self.t2, self.jump) = (t1, t2, jump);
        result?;
        if !any(&self.theta) {
            return Err(Handback::ZeroFit);
        }
        Ok(it)
    }

    /// ν of the model mixture at every τ: (Σ s_k)² / Σ s_k²/ν_k (`_fit_irls.edf_of`).
    fn mixture_edf(&mut self, p: &Problem) {
        let k = self.k;
        let rows = p.design.chunks_exact(k).zip(p.nu_terms.chunks_exact(k));
        for (nu, (row, nu_row)) in self.nu.iter_mut().zip(rows) {
            let (mut tot, mut den) = (0.0, 0.0);
            for ((&a, &t), &n) in row.iter().zip(&self.theta[..k]).zip(nu_row) {
                let s = a * t;
                tot += s;
                den += s * s / n;
            }
            *nu = if den > 0.0 {
                tot * tot / den
            } else {
                nu_row[0]
            };
        }
    }
}

/// Σ row[c]·v[c] in order (one row of the design matrix times a coefficient vector).
#[inline]
fn row_dot(row: &[f64], v: &[f64]) -> f64 {
    row.iter().zip(v).map(|(a, b)| a * b).sum()
}

/// The exponent e of `math.frexp(x)` (x = f·2^e, 0.5 ≤ f < 1) for a positive finite x.
fn frexp_exp(x: f64) -> i32 {
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i32;
    if e == 0 {
        // subnormal: normalise first
        return frexp_exp(x * 2f64.powi(64)) - 64;
    }
    e - 1022
}

#[cfg(test)]
mod tests {
    use super::frexp_exp;

    #[test]
    fn frexp_exponent_matches_python() {
        // math.frexp(1.0) = (0.5, 1); frexp(0.75) = (0.75, 0); frexp(1e-300) = (…, -996)
        assert_eq!(frexp_exp(1.0), 1);
        assert_eq!(frexp_exp(0.75), 0);
        assert_eq!(frexp_exp(1e-300), -996);
        assert_eq!(frexp_exp(5e-324), -1073);
    }
}

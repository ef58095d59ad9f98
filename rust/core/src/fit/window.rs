//! One window's noise-model fit: the iteration of `allanite.model.fitting` (`_fit_core`, `_fit_irls`,
//! `_fit_gls`) step for step, in buffers reused from window to window. The Python functions are the
//! reference; each step here names the one it mirrors, and `tests/test_batched_fit.py` checks the two
//! agree on measured and simulated windows.

use super::dense::{cholesky, forward_solve, nnls, pinv_sym, NnlsWork};
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
    pub(crate) fn new(nt: usize, k: usize) -> Self {
        let z = |n: usize| vec![0.0; n];
        Window {
            nt,
            k,
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
                let sw = (self.nu[i] / (2.0 * m * m)).sqrt();
                for c in 0..k {
                    self.aw[c * nt + i] = a[i * k + c] * sw;
                }
                self.bw[i] = self.y[i] * sw;
            }
            self.scaled_nnls()?;
            let done = (0..k)
                .all(|c| (self.new[c] - self.theta[c]).abs() <= p.irls_rtol * self.theta[c].abs());
            for i in 0..nt {
                let s: f64 = (0..k).map(|c| a[i * k + c] * self.new[c]).sum();
                let new_model = s.max(floor);
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
        let (nt, k, nn) = (self.nt, self.k, self.nt * self.nt);
        let floor = self.floor();
        for i in 0..nt {
            let s: f64 = (0..k).map(|c| p.design[i * k + c] * theta[c]).sum();
            self.model[i] = s.max(floor);
        }
        let ns = g.stoch.len();
        for (q, &c) in g.stoch.iter().enumerate() {
            self.th_s[q] = theta[c];
        }
        // Σ is symmetric and only its lower triangle is read below (Cholesky): only that is formed
        self.cov.fill(0.0);
        let mut add = |w: f64, blk: &[f64]| {
            if w != 0.0 {
                for i in 0..nt {
                    let (c, b) = (
                        &mut self.cov[i * nt..i * nt + i + 1],
                        &blk[i * nt..i * nt + i + 1],
                    );
                    c.iter_mut().zip(b).for_each(|(c, s)| *c += w * s);
                }
            }
        };
        for a in 0..ns {
            for b in 0..ns {
                add(
                    self.th_s[a] * self.th_s[b],
                    &g.s_blk[(a * ns + b) * nn..(a * ns + b + 1) * nn],
                );
            }
        }
        if let Some(r) = g.ramp {
            for a in 0..ns {
                add(theta[r] * self.th_s[a], &g.t_blk[a * nn..(a + 1) * nn]);
            }
        }
        for i in 0..nt {
            let indep = 2.0 * self.model[i] * self.model[i] / self.nu0[i];
            // NumPy's `~(diag > 1e-6 · indep)`: a NaN diagonal counts as too small too
            let big =
                self.cov[i * nt + i].partial_cmp(&(BARE_SHARE * indep)) == Some(Ordering::Greater);
            if !big {
                self.cov[i * nt + i] += indep;
            }
        }
        for i in 0..nt {
            let c = self.cov[i * nt + i];
            if !c.is_finite() {
                return Err(Handback::Numerical);
            }
            self.tmp[i] = c.max(1e-300).sqrt();
        }
        for i in 0..nt {
            for j in 0..=i {
                self.corr[i * nt + j] = self.cov[i * nt + j] / (self.tmp[i] * self.tmp[j]);
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
        for c in 0..k {
            let col = &mut self.aw[c * nt..(c + 1) * nt];
            for (i, v) in col.iter_mut().enumerate() {
                *v = p.design[i * k + c];
            }
            forward_solve(&self.l, nt, col);
        }
        for i in 0..nt {
            self.bw[i] = if rhs_is_residual {
                let s: f64 = (0..k).map(|c| p.design[i * k + c] * self.theta[c]).sum();
                self.y[i] - s
            } else {
                self.y[i]
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
        (0..self.nt)
            .map(|i| {
                let row = &p.design[i * k..(i + 1) * k];
                let d: f64 = (0..k).map(|c| row[c] * (new[c] - old[c])).sum();
                let m: f64 = (0..k).map(|c| row[c] * new[c]).sum();
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

    /// χ² of the whitened residuals and the coefficient covariance (AᵀΣ⁻¹A)⁻¹ over the active terms;
    /// each inactive term's variance as if freed alone (the end of `_fit_gls`).
    fn gls_covariance(&mut self, p: &Problem, g: &Gls, cov: &mut [f64]) -> Result<f64, Handback> {
        let theta = std::mem::take(&mut self.theta);
        let factored = self.factor(p, g, &theta);
        self.theta = theta;
        factored?;
        self.whiten(p, true);
        let chi2 = self.bw.iter().map(|v| v * v).sum();
        self.covariance_over_active(cov, |w| {
            let (nt, q) = (w.nt, w.idx.len());
            for a in 0..q {
                for b in 0..q {
                    let (ca, cb) = (w.idx[a] * nt, w.idx[b] * nt);
                    w.gram[a * q + b] = (0..nt).map(|i| w.aw[ca + i] * w.aw[cb + i]).sum();
                }
            }
            pinv_sym(&mut w.gram, q, &mut w.gv, &mut w.ginv);
        });
        Ok(chi2)
    }

    /// `cov[idx, idx] = B(idx)` for the active terms idx, and for each inactive k `cov[k, k] =
    /// B(idx ∪ k)[k, k]` — B the block `block` leaves in `self.ginv` for the terms in `self.idx`;
    /// NaN elsewhere (the reference's layout).
    fn covariance_over_active(&mut self, cov: &mut [f64], block: impl Fn(&mut Self)) {
        let k = self.k;
        cov.fill(f64::NAN);
        self.idx.clear();
        self.idx.extend((0..k).filter(|&c| self.theta[c] > 0.0));
        let n_active = self.idx.len();
        for e in 0..=k {
            // e = 0: the active block; e = c + 1: inactive term c freed alone
            let extra = match e.checked_sub(1) {
                None => None,
                Some(c) if self.theta[c] > 0.0 => continue,
                Some(c) => Some(c),
            };
            self.idx.truncate(n_active);
            if let Some(c) = extra {
                self.idx.push(c);
            }
            let q = self.idx.len();
            if q == 0 {
                continue;
            }
            block(self);
            match extra {
                None => {
                    for a in 0..q {
                        for b in 0..q {
                            cov[self.idx[a] * k + self.idx[b]] = self.ginv[a * q + b];
                        }
                    }
                }
                Some(c) => cov[c * k + c] = self.ginv[q * q - 1],
            }
        }
    }

    /// The end of `_fit_irls`: z and χ² under independent weights, and the sandwich covariance
    /// (AᵀWA)⁻¹ AᵀWΣWA (AᵀWA)⁻¹ with Σ from the octave-correlation model (`_estimate_correlation`).
    fn irls_covariance(&mut self, p: &Problem, cov: &mut [f64]) -> f64 {
        let (nt, k) = (self.nt, self.k);
        let floor = self.floor();
        let any = self.theta.iter().any(|&v| v != 0.0);
        let mut chi2 = 0.0;
        for i in 0..nt {
            let row = &p.design[i * k..(i + 1) * k];
            let m = (0..k)
                .map(|c| row[c] * self.theta[c])
                .sum::<f64>()
                .max(floor);
            self.model[i] = m;
            let w = self.nu[i] / (2.0 * m * m);
            self.bw[i] = w; // the weights, kept for the sandwich
            let z = (self.y[i] - m) * w.sqrt();
            chi2 += z * z;
            // the mixture's octave correlation at this τ: the terms' shares of the model (of A when θ = 0)
            let part = |c: usize| if any { row[c] * self.theta[c] } else { row[c] };
            let total = (0..k).map(part).sum::<f64>().max(1e-300);
            let rho = (0..k).map(|c| part(c) / total * p.rho[c]).sum::<f64>();
            self.tmp[i] = rho.clamp(0.0, 0.99);
        }
        for i in 0..nt {
            let sd_i = (2.0 / self.nu[i]).sqrt() * self.model[i];
            for j in 0..nt {
                let dist = (p.log2_tau[i] - p.log2_tau[j]).abs();
                let corr = if dist == 0.0 {
                    1.0
                } else {
                    (self.tmp[i] * self.tmp[j]).sqrt().powf(dist)
                };
                let sd_j = (2.0 / self.nu[j]).sqrt() * self.model[j];
                self.corr[i * nt + j] = corr * (sd_i * sd_j);
            }
        }
        self.covariance_over_active(cov, |w| w.sandwich(p));
        chi2
    }

    /// The sandwich for the terms in `self.idx` into `self.ginv` (weights in `self.bw`, Σ in `self.corr`).
    fn sandwich(&mut self, p: &Problem) {
        let (nt, k, q) = (self.nt, self.k, self.idx.len());
        for (b, &c) in self.idx.iter().enumerate() {
            for i in 0..nt {
                self.aw[b * nt + i] = p.design[i * k + c] * self.bw[i];
            }
        }
        for a in 0..q {
            for b in 0..q {
                let cb = self.idx[b];
                self.gram[a * q + b] = (0..nt)
                    .map(|i| self.aw[a * nt + i] * p.design[i * k + cb])
                    .sum();
            }
        }
        pinv_sym(&mut self.gram, q, &mut self.gv, &mut self.bread);
        // meat = awᵀ Σ aw
        for b in 0..q {
            for i in 0..nt {
                self.l[b * nt + i] = (0..nt)
                    .map(|j| self.corr[i * nt + j] * self.aw[b * nt + j])
                    .sum();
            }
        }
        for a in 0..q {
            for b in 0..q {
                self.meat[a * q + b] = (0..nt)
                    .map(|i| self.aw[a * nt + i] * self.l[b * nt + i])
                    .sum();
            }
        }
        for a in 0..q {
            for b in 0..q {
                self.gram[a * q + b] = (0..q)
                    .map(|c| self.bread[a * q + c] * self.meat[c * q + b])
                    .sum();
            }
        }
        for a in 0..q {
            for b in 0..q {
                self.ginv[a * q + b] = (0..q)
                    .map(|c| self.gram[a * q + c] * self.bread[c * q + b])
                    .sum();
            }
        }
    }

    /// ν of the model mixture at every τ: (Σ s_k)² / Σ s_k²/ν_k (`_fit_irls.edf_of`).
    fn mixture_edf(&mut self, p: &Problem) {
        let k = self.k;
        for i in 0..self.nt {
            let (mut tot, mut den) = (0.0, 0.0);
            for c in 0..k {
                let s = p.design[i * k + c] * self.theta[c];
                tot += s;
                den += s * s / p.nu_terms[i * k + c];
            }
            self.nu[i] = if den > 0.0 {
                tot * tot / den
            } else {
                p.nu_terms[i * k]
            };
        }
    }
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

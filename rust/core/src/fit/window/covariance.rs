//! The end of a window's fit: χ² and the coefficient covariance — (AᵀΣ⁻¹A)⁻¹ over the active terms after
//! the GLS (`_fit_gls`), the sandwich under independent weights after the IRLS (`_fit_irls`) — each inactive
//! term's variance as if freed alone, NaN elsewhere (the reference's layout).

use super::super::dense::pinv_sym;
use super::super::{Gls, Problem};
use super::{Handback, Window};

impl Window {
    /// χ² of the whitened residuals and the coefficient covariance (AᵀΣ⁻¹A)⁻¹ over the active terms;
    /// each inactive term's variance as if freed alone (the end of `_fit_gls`).
    pub(super) fn gls_covariance(
        &mut self,
        p: &Problem,
        g: &Gls,
        cov: &mut [f64],
    ) -> Result<f64, Handback> {
        let theta = std::mem::take(&mut self.theta);
        let factored = self.factor(p, g, &theta);
        self.theta = theta;
        factored?;
        self.whiten(p, true);
        let chi2 = self.bw.iter().map(|v| v * v).sum();
        self.covariance_over_active(cov, |w| {
            let (nt, q) = (w.nt, w.idx.len());
            // symmetric: each product sum once (x·y = y·x exactly, so the mirror is the same number)
            for a in 0..q {
                let col_a = &w.aw[w.idx[a] * nt..(w.idx[a] + 1) * nt];
                for b in 0..=a {
                    let col_b = &w.aw[w.idx[b] * nt..(w.idx[b] + 1) * nt];
                    let s: f64 = col_a.iter().zip(col_b).map(|(x, y)| x * y).sum();
                    w.gram[a * q + b] = s;
                    w.gram[b * q + a] = s;
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
    pub(super) fn irls_covariance(&mut self, p: &Problem, cov: &mut [f64]) -> f64 {
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
}

//! The noise-model fit of every window of a dynamic Allan variance, in parallel.
//!
//! `allanite.fit(dynamic_result)` fits the IEEE-952 terms to each window's Allan variance: the same τ,
//! design matrix, EDF and covariance blocks in every window, only the estimates differ. Python prepares
//! what the windows share ([`Problem`]); this module runs `allanite.model.fitting._fit_core` on each
//! window — the same iteration, step for step ([`window`]) — on rayon's threads. A window whose fit
//! takes a branch kept in Python only (an indefinite covariance, a fit at θ = 0, a failed NNLS) is
//! flagged and refitted there, so every window gets the reference's answer.

pub mod curves;
mod dense;
mod shared;
pub mod whittle;
mod window;

use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
use rayon::prelude::*;

pub use window::Handback;

/// The generalized-least-squares part of a problem: the covariance blocks of overlapping estimates
/// (`allanite.model._covariance._blocks`).
#[derive(Debug, Clone, Copy)]
pub struct Gls<'a> {
    /// S, shape (ns, ns, n_tau, n_tau) C-order, ns = `stoch.len()`.
    pub s_blk: &'a [f64],
    /// T, shape (ns, n_tau, n_tau) (used when `ramp` is set).
    pub t_blk: &'a [f64],
    /// Column of each stochastic term (the blocks' order).
    pub stoch: &'a [usize],
    /// Column of the rate ramp R, if fitted.
    pub ramp: Option<usize>,
}

/// What every window of a dynamic fit shares.
#[derive(Debug, Clone, Copy)]
pub struct Problem<'a> {
    /// Fitted τ per window.
    pub n_tau: usize,
    /// Terms fitted.
    pub n_terms: usize,
    /// Allan variance per unit squared coefficient, (n_tau, n_terms) row-major.
    pub design: &'a [f64],
    /// EDF of each term's noise type at each τ, (n_tau, n_terms) row-major.
    pub nu_terms: &'a [f64],
    /// Column of `nu_terms` the IRLS starts from (white rate's when fitted, else the first).
    pub start_col: usize,
    /// IRLS passes before the GLS (the fit's `min(max_iter, 8)`), or of the IRLS fit itself.
    pub irls_iter: usize,
    /// Passes at most (the fit's `max_iter`).
    pub max_iter: usize,
    /// GLS stopping tolerance (`fitting.GLS_TOL`).
    pub gls_tol: f64,
    /// IRLS stopping tolerance (`fitting.IRLS_RTOL`).
    pub irls_rtol: f64,
    /// Octave correlation of each term (`fitting.OCTAVE_CORRELATION`), for the IRLS sandwich.
    pub rho: &'a [f64],
    /// log2 τ of the fitted τ, for the IRLS sandwich.
    pub log2_tau: &'a [f64],
    /// Present for overlapping estimates: the GLS fit; absent: the IRLS fit.
    pub gls: Option<Gls<'a>>,
}

/// Values per window in the output of [`fit_windows`]: θ (n_terms), covariance (n_terms²), χ²,
/// iterations, status (0 fitted, else 1 + the [`Handback`] discriminant).
pub fn record_width(n_terms: usize) -> usize {
    n_terms + n_terms * n_terms + 3
}

/// Windows per unit of parallel work: a few hundred microseconds each.
const CHUNK: usize = 64;

impl Problem<'_> {
    fn check(&self) -> Result<()> {
        let (nt, k) = (self.n_tau, self.n_terms);
        let bad = |what: &str| Err(CoreError::InvalidParameter(format!("fit_windows: {what}")));
        if k == 0 || nt <= k {
            return bad(&format!(
                "{nt} τ for {k} terms; more τ than terms are needed"
            ));
        }
        if self.design.len() != nt * k || self.nu_terms.len() != nt * k {
            return bad("design and nu_terms must be (n_tau, n_terms)");
        }
        if self.rho.len() != k || self.log2_tau.len() != nt || self.start_col >= k {
            return bad("rho must have one value per term, log2_tau one per τ");
        }
        if let Some(g) = &self.gls {
            let ns = g.stoch.len();
            if g.s_blk.len() != ns * ns * nt * nt || g.t_blk.len() != ns * nt * nt {
                return bad("covariance blocks of the wrong shape");
            }
            if g.stoch.iter().chain(g.ramp.iter()).any(|&c| c >= k) {
                return bad("a term column out of range");
            }
        }
        Ok(())
    }
}

/// Fits every window: `avar` holds the windows' estimates at the fitted τ, (windows, n_tau) row-major,
/// finite and floored at 1e-300 by the caller. Returns (windows, [`record_width`]) row-major.
pub fn fit_windows(problem: &Problem, avar: &[f64], cancel: &Cancel) -> Result<Vec<f64>> {
    problem.check()?;
    let (nt, k) = (problem.n_tau, problem.n_terms);
    if !avar.len().is_multiple_of(nt) {
        return Err(CoreError::InvalidParameter(format!(
            "fit_windows: {} estimates are not a whole number of windows of {nt} τ",
            avar.len()
        )));
    }
    let width = record_width(k);
    let n_windows = avar.len() / nt;
    let mut out = vec![0.0; n_windows * width];
    out.par_chunks_mut(CHUNK * width)
        .zip(avar.par_chunks(CHUNK * nt))
        .for_each_init(
            || window::Window::new(problem),
            |w, (rec, ys)| {
                if cancel.is_cancelled() {
                    return;
                }
                for (r, y) in rec.chunks_mut(width).zip(ys.chunks(nt)) {
                    let (theta, rest) = r.split_at_mut(k);
                    let (cov, tail) = rest.split_at_mut(k * k);
                    let mut o = window::Out {
                        theta,
                        cov,
                        chi2: f64::NAN,
                        iterations: 0,
                    };
                    let status = match w.fit(problem, y, &mut o) {
                        Ok(()) => 0.0,
                        Err(h) => 1.0 + h as u8 as f64,
                    };
                    tail[0] = o.chi2;
                    tail[1] = o.iterations as f64;
                    tail[2] = status;
                }
            },
        );
    cancel.check()?;
    Ok(out)
}

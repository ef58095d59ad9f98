//! The naive method (paper 000's DAVAR): every window recomputed from scratch from its own angle —
//! the definition, and the reference the fast paths are checked against. Shared by the rectangular
//! estimators here and the Hann-weighted ones (`crate::taper`).

use super::{Estimator, Request};
use crate::cancel::Cancel;
use crate::error::Result;
use rayon::prelude::*;

/// The angle of a window centred on its own mean: `angle[0] = 0`, `angle[i + 1] = Σ_{j ≤ i} (y_j − ȳ)`.
pub(crate) fn centred_angle(yw: &[f64], angle: &mut Vec<f64>) {
    let mu = yw.iter().sum::<f64>() / yw.len() as f64;
    angle.clear();
    angle.push(0.0);
    let mut x = 0.0;
    for &v in yw {
        x += v - mu;
        angle.push(x);
    }
}

/// Every window of every axis of `req` by `window_fn(window's samples, angle scratch, one value per m)`,
/// in parallel over the windows, written to `out` as [axis][m][window] (`n_win` windows). A window
/// started after `cancel` is set is left at 0; the caller checks `cancel` before using `out`.
pub(crate) fn naive_rows(
    req: &Request,
    n_win: usize,
    out: &mut [f64],
    cancel: &Cancel,
    window_fn: impl Fn(&[f64], &mut Vec<f64>, &mut [f64]) + Sync,
) -> Result<()> {
    let n_m = req.ms.len();
    for (a, y) in req.columns.iter().enumerate() {
        let cols: Vec<Vec<f64>> = (0..n_win)
            .into_par_iter()
            .map_init(Vec::new, |angle, j| {
                let s = j * req.hop;
                let mut col = vec![0.0; n_m];
                if cancel.is_cancelled() {
                    return col;
                }
                window_fn(&y[s..s + req.window], angle, &mut col);
                col
            })
            .collect();
        cancel.check()?;
        let block = &mut out[a * n_m * n_win..(a + 1) * n_m * n_win];
        for (j, col) in cols.iter().enumerate() {
            for (t, v) in col.iter().enumerate() {
                block[t * n_win + j] = *v;
            }
        }
    }
    Ok(())
}

/// One window recomputed from scratch, all m: the plain definition (paper 000's DAVAR step):
/// remove the window mean, integrate to angle, sum squared second differences.
pub(super) fn naive_window(
    yw: &[f64],
    ms: &[usize],
    estimator: Estimator,
    angle: &mut Vec<f64>,
    out: &mut [f64],
) {
    let w = yw.len();
    centred_angle(yw, angle);
    let xs = &angle[..];
    for (o, &m) in out.iter_mut().zip(ms) {
        let mm = (m * m) as f64;
        *o = match estimator {
            Estimator::Overlapping => {
                let l = w + 1 - 2 * m;
                let mut s = 0.0;
                for k in 0..l {
                    let d = xs[k + 2 * m] - 2.0 * xs[k + m] + xs[k];
                    s += d * d;
                }
                s / (2.0 * mm * l as f64)
            }
            Estimator::Classic => {
                let k = w / m;
                let mut s = 0.0;
                for i in 0..k - 1 {
                    let d = (xs[(i + 2) * m] - xs[(i + 1) * m]) - (xs[(i + 1) * m] - xs[i * m]);
                    s += d * d;
                }
                s / (2.0 * mm * (k - 1) as f64)
            }
        };
    }
}

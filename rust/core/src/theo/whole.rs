//! Theo1 of whole records: O(N²) for every m at once from the head and tail passes (see the parent
//! module), with their vectorised kernels.

use super::{check_columns, check_ms, detrended_phase, sorted_unique};
use crate::cancel::Cancel;
use crate::error::Result;
use rayon::prelude::*;

#[inline(always)]
fn add_pairs_body(h: &mut [f64], zp: f64, r: &[f64]) {
    for (hv, &rv) in h.iter_mut().zip(r) {
        let d = zp - rv;
        *hv += d * d;
    }
}

#[inline(always)]
fn add_pairs2_body(h: &mut [f64], za: f64, ra: &[f64], zb: f64, rb: &[f64]) {
    for ((hv, &u), &v) in h.iter_mut().zip(ra).zip(rb) {
        let d = za - u;
        let e = zb - v;
        *hv += d * d + e * e;
    }
}

#[inline(always)]
fn sq_diff_sum_body(a: &[f64], b: &[f64]) -> f64 {
    let mut acc = [0.0f64; 8];
    let ca = a.chunks_exact(8);
    let cb = b.chunks_exact(8);
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (u, v) in ca.zip(cb) {
        for k in 0..8 {
            let d = u[k] - v[k];
            acc[k] += d * d;
        }
    }
    let mut tail = 0.0;
    for (u, v) in ra.iter().zip(rb) {
        let d = u - v;
        tail += d * d;
    }
    ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7])) + tail
}

/// The same arithmetic compiled for AVX2 where the CPU has it (no FMA: identical rounding).
#[derive(Clone, Copy)]
struct Kernels {
    add_pairs: fn(&mut [f64], f64, &[f64]),
    add_pairs2: fn(&mut [f64], f64, &[f64], f64, &[f64]),
    sq_diff_sum: fn(&[f64], &[f64]) -> f64,
}

#[cfg(target_arch = "x86_64")]
mod avx2 {
    #[target_feature(enable = "avx2")]
    unsafe fn add_pairs_impl(h: &mut [f64], zp: f64, r: &[f64]) {
        super::add_pairs_body(h, zp, r)
    }
    #[target_feature(enable = "avx2")]
    unsafe fn add_pairs2_impl(h: &mut [f64], za: f64, ra: &[f64], zb: f64, rb: &[f64]) {
        super::add_pairs2_body(h, za, ra, zb, rb)
    }
    #[target_feature(enable = "avx2")]
    unsafe fn sq_diff_sum_impl(a: &[f64], b: &[f64]) -> f64 {
        super::sq_diff_sum_body(a, b)
    }
    pub fn add_pairs(h: &mut [f64], zp: f64, r: &[f64]) {
        // SAFETY: only reachable through `kernels()` after AVX2 was detected.
        unsafe { add_pairs_impl(h, zp, r) }
    }
    pub fn add_pairs2(h: &mut [f64], za: f64, ra: &[f64], zb: f64, rb: &[f64]) {
        // SAFETY: as above.
        unsafe { add_pairs2_impl(h, za, ra, zb, rb) }
    }
    pub fn sq_diff_sum(a: &[f64], b: &[f64]) -> f64 {
        // SAFETY: as above.
        unsafe { sq_diff_sum_impl(a, b) }
    }
}

fn kernels() -> Kernels {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("avx2") {
            return Kernels {
                add_pairs: avx2::add_pairs,
                add_pairs2: avx2::add_pairs2,
                sq_diff_sum: avx2::sq_diff_sum,
            };
        }
    }
    Kernels {
        add_pairs: add_pairs_body,
        add_pairs2: add_pairs2_body,
        sq_diff_sum: sq_diff_sum_body,
    }
}

/// The W-part of T(m) from the pairs inside the first points of `z`, for each m of `ms` (sorted,
/// distinct, even). With `want_f` the pass continues to all points and also returns F_ℓ (ℓ < N).
/// Stops early, with meaningless sums, once `cancel` is set.
fn head_pass(
    z: &[f64],
    ms: &[usize],
    want_f: bool,
    k: Kernels,
    cancel: &Cancel,
) -> (Vec<f64>, Option<Vec<f64>>) {
    let n = z.len();
    let mmax = *ms.last().expect("ms checked non-empty");
    let last = if want_f { n - 1 } else { mmax - 1 };
    let zr: Vec<f64> = z.iter().rev().copied().collect();
    // h[ℓ] = Σ over the pairs (k, k+ℓ) inside the points added so far.
    let mut h = vec![0.0f64; last + 1];
    let mut part = vec![0.0f64; ms.len()];
    let inv: Vec<f64> = (0..=mmax)
        .map(|d| if d == 0 { 0.0 } else { 1.0 / d as f64 })
        .collect();
    let deposits = Deposits { ms, inv: &inv };
    let mut p = 1;
    while p <= last {
        // Each step adds p pairs: one load of the flag per step is lost in that work.
        if cancel.is_cancelled() {
            break;
        }
        let s = p + 1; // stage reached after point p: the pairs inside [0, s)
                       // Two points per pass over h (half the memory traffic) unless stage s needs all of h.
        let fuse = p < last && (s > mmax || ms.binary_search(&s).is_err());
        if fuse {
            // Points p and p + 1; z_{p−ℓ} = zr[n−1−p+ℓ], z_{p+1−ℓ} = zr[n−2−p+ℓ].
            (k.add_pairs2)(
                &mut h[1..=p],
                z[p],
                &zr[n - p..n],
                z[p + 1],
                &zr[n - p - 1..n - 1],
            );
            let d0 = z[p + 1] - z[0];
            h[p + 1] += d0 * d0;
        } else {
            (k.add_pairs)(&mut h[1..=p], z[p], &zr[n - p..n]);
        }
        if s <= mmax {
            // fused, h already holds point p + 1's pairs: they are taken back out
            deposits.stage(&h, s, &mut part, !fuse, fuse.then_some((z, p + 1)));
        }
        if fuse {
            let s2 = p + 2;
            if s2 <= mmax {
                deposits.stage(&h, s2, &mut part, true, None);
            }
            p += 2;
        } else {
            p += 1;
        }
    }
    (part, if want_f { Some(h) } else { None })
}

/// The W-part's deposits of [`head_pass`] on the factors `ms`; `inv[d]` = 1/d.
struct Deposits<'a> {
    ms: &'a [usize],
    inv: &'a [f64],
}

impl Deposits<'_> {
    /// −W_m(d) − W_m(m−d), d = 1..=m/2, once the pairs inside [0, m) are in h.
    fn full(&self, h: &[f64], m: usize) -> f64 {
        let mut acc = 0.0;
        for d in 1..=m / 2 {
            acc += self.inv[d] * (h[d] + h[m - d]);
        }
        acc
    }

    /// The deposits of stage s (the pairs inside [0, s) in h) into `part`: with `full`, the full
    /// deposit of m = s; +W_{m−d}(m−2d) at stage s = m − d, for every m with s < m < 2s (d = m − s ≤
    /// m/2). `ahead`: (z, q) when h also holds point q's pairs, each taken back out at its lag.
    fn stage(
        &self,
        h: &[f64],
        s: usize,
        part: &mut [f64],
        full: bool,
        ahead: Option<(&[f64], usize)>,
    ) {
        let (ms, inv) = (self.ms, self.inv);
        if full {
            if let Ok(idx) = ms.binary_search(&s) {
                part[idx] -= self.full(h, s);
            }
        }
        let lo = ms.partition_point(|&m| m <= s);
        for (idx, &m) in ms.iter().enumerate().skip(lo) {
            if m >= 2 * s {
                break;
            }
            let l = 2 * s - m;
            let mut v = h[l];
            if let Some((z, q)) = ahead {
                if l >= 1 {
                    let e = z[q] - z[q - l];
                    v -= e * e;
                }
            }
            part[idx] += inv[m - s] * v;
        }
    }
}

/// Theo1 of one whole record of phase points `x` (detrended) at each m of `ms` (sorted, distinct).
/// Returns `Cancelled` once `cancel` is set.
fn static_theo1_phase(x: &[f64], ms: &[usize], cancel: &Cancel) -> Result<Vec<f64>> {
    let n = x.len();
    let k = kernels();
    let mmax = *ms.last().expect("ms checked non-empty");
    // Running the head pass to the end yields F for free; worth it when m reaches past N/2.
    let want_f = 2 * mmax > n;
    let xr: Vec<f64> = x.iter().rev().copied().collect();
    let ((head, f_head), (tail, _)) = rayon::join(
        || head_pass(x, ms, want_f, k, cancel),
        || head_pass(&xr, ms, false, k, cancel),
    );
    cancel.check()?;
    let f: Vec<f64> = match f_head {
        Some(f) => f,
        None => (0..mmax + 1)
            .into_par_iter()
            .with_min_len(16)
            .map(|l| {
                if l == 0 || cancel.is_cancelled() {
                    0.0
                } else {
                    (k.sq_diff_sum)(&x[l..], &x[..n - l])
                }
            })
            .collect(),
    };
    cancel.check()?;
    Ok(ms
        .iter()
        .enumerate()
        .map(|(idx, &m)| {
            let h = m / 2;
            let (mut acc, mut harmonic) = (0.0, 0.0);
            for d in 1..=h {
                let w = 1.0 / d as f64;
                acc += w * (2.0 * f[d] + 2.0 * f[m - d] - f[m - 2 * d]);
                harmonic += w;
            }
            let t = acc - harmonic * f[m] + head[idx] + tail[idx];
            t / (0.75 * (n - m) as f64 * (m * m) as f64)
        })
        .collect())
}

/// Theo1 of each whole rate record at every m: values laid out as [axis][m]. Phase per record:
/// N = M + 1 points; m even, 2 ≤ m ≤ M. Axes run one after another, each on the calling pool.
pub fn static_theo1(columns: &[&[f64]], ms: &[usize]) -> Result<Vec<f64>> {
    static_theo1_cancellable(columns, ms, &Cancel::new())
}

/// [`static_theo1`] that stops within one pass step (O(N) work) once `cancel` is set, and then
/// returns [`CoreError::Cancelled`](crate::CoreError::Cancelled).
pub fn static_theo1_cancellable(
    columns: &[&[f64]],
    ms: &[usize],
    cancel: &Cancel,
) -> Result<Vec<f64>> {
    let n = check_columns(columns)?;
    check_ms(n, ms, "record")?;
    let (u, pos) = sorted_unique(ms);
    let mut out = Vec::with_capacity(columns.len() * ms.len());
    for y in columns {
        let x = detrended_phase(y);
        let vals = static_theo1_phase(&x, &u, cancel)?;
        out.extend(pos.iter().map(|&p| vals[p]));
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::super::tests::{lcg, rel};
    use super::super::theo1_direct;
    use super::*;

    #[test]
    fn static_matches_direct_sum() {
        for &n in &[13usize, 64, 301] {
            let y = lcg(n, 7 + n as u64);
            let x = detrended_phase(&y);
            let ms: Vec<usize> = (2..=n).step_by(2).collect();
            let fast = static_theo1(&[&y], &ms).unwrap();
            for (v, &m) in fast.iter().zip(&ms) {
                let direct = theo1_direct(&x, m);
                assert!(rel(*v, direct) < 1e-11, "n {n} m {m}: {v} vs {direct}");
            }
        }
    }

    #[test]
    fn static_uses_f_shortcut_consistently() {
        // A grid ending below N/2 computes F directly; one ending above takes it from the head pass.
        let y = lcg(500, 3);
        let low = static_theo1(&[&y], &[10, 40, 200]).unwrap();
        let high = static_theo1(&[&y], &[10, 40, 200, 480]).unwrap();
        for i in 0..3 {
            assert!(rel(low[i], high[i]) < 1e-12);
        }
    }

    #[test]
    fn static_keeps_precision_on_random_walk_rate() {
        // Rate that is itself a random walk, on a large offset: the phase
        // grows like n^1.5; the squared-difference form must still match the direct sum.
        let n = 3000;
        let w = lcg(n, 9);
        let mut y = vec![0.0; n];
        let mut acc = 0.0;
        for (i, v) in w.iter().enumerate() {
            acc += v;
            y[i] = acc + 1e6;
        }
        let x = detrended_phase(&y);
        let ms: Vec<usize> = vec![2, 10, 12, 100, 1000, 2000, 2998, 3000];
        let fast = static_theo1(&[&y], &ms).unwrap();
        for (v, &m) in fast.iter().zip(&ms) {
            let direct = theo1_direct(&x, m);
            assert!(rel(*v, direct) < 1e-9, "m {m}: {v} vs {direct}");
        }
    }
}

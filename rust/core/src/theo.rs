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

use crate::allan::{
    check_finite, check_shape, check_window_hop, compensated_mean, sliding_sums, sum4, TermScratch,
    DIRECT_M,
};
use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
use rayon::prelude::*;

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

/// Neumaier-compensated running sum.
#[derive(Default, Clone, Copy)]
struct Compensated {
    s: f64,
    c: f64,
}

impl Compensated {
    #[inline]
    fn add(&mut self, v: f64) {
        let t = self.s + v;
        if self.s.abs() >= v.abs() {
            self.c += (self.s - t) + v;
        } else {
            self.c += (v - t) + self.s;
        }
        self.s = t;
    }
    #[inline]
    fn value(&self) -> f64 {
        self.s + self.c
    }
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
    // −W_m(d) − W_m(m−d), d = 1..=m/2, once the pairs inside [0, m) are in h.
    let full_deposit = |h: &[f64], m: usize| -> f64 {
        let mut acc = 0.0;
        for d in 1..=m / 2 {
            acc += inv[d] * (h[d] + h[m - d]);
        }
        acc
    };
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
            if !fuse {
                if let Ok(idx) = ms.binary_search(&s) {
                    part[idx] -= full_deposit(&h, s);
                }
            }
            // +W_{m−d}(m−2d) at stage s = m − d, for every m with s < m < 2s (d = m − s ≤ m/2).
            let lo = ms.partition_point(|&m| m <= s);
            for (idx, &m) in ms.iter().enumerate().skip(lo) {
                if m >= 2 * s {
                    break;
                }
                let l = 2 * s - m;
                let mut v = h[l];
                if fuse && l >= 1 {
                    // h already holds point p + 1's pairs: take its pair at lag l back out.
                    let e = z[p + 1] - z[p + 1 - l];
                    v -= e * e;
                }
                part[idx] += inv[m - s] * v;
            }
        }
        if fuse {
            let s2 = p + 2;
            if s2 <= mmax {
                if let Ok(idx) = ms.binary_search(&s2) {
                    part[idx] -= full_deposit(&h, s2);
                }
                let lo = ms.partition_point(|&m| m <= s2);
                for (idx, &m) in ms.iter().enumerate().skip(lo) {
                    if m >= 2 * s2 {
                        break;
                    }
                    part[idx] += inv[m - s2] * h[2 * s2 - m];
                }
            }
            p += 2;
        } else {
            p += 1;
        }
    }
    (part, if want_f { Some(h) } else { None })
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

/// Sorted distinct copy of `ms` and, for each original position, its index in the copy.
fn sorted_unique(ms: &[usize]) -> (Vec<usize>, Vec<usize>) {
    let mut u = ms.to_vec();
    u.sort_unstable();
    u.dedup();
    let pos = ms.iter().map(|m| u.binary_search(m).unwrap()).collect();
    (u, pos)
}

/// Theo1 of each whole rate record at every m: values laid out as [axis][m]. Phase per record:
/// N = M + 1 points; m even, 2 ≤ m ≤ M. Axes run one after another, each on the calling pool.
pub fn static_theo1(columns: &[&[f64]], ms: &[usize]) -> Result<Vec<f64>> {
    static_theo1_cancellable(columns, ms, &Cancel::new())
}

/// [`static_theo1`] that stops within one pass step (O(N) work) once `cancel` is set, and then
/// returns [`CoreError::Cancelled`].
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

/// Block sums B_d(i) = Σ_{k=i}^{i+d−1} (y_k − μ), i < count, each summed over its own samples only.
fn block_sums(y: &[f64], mu: f64, d: usize, count: usize, out: &mut Vec<f64>) {
    debug_assert!(count + d - 1 <= y.len());
    out.clear();
    if d <= DIRECT_M {
        out.resize(count, 0.0);
        for j in 0..d {
            for (o, v) in out.iter_mut().zip(&y[j..j + count]) {
                *o += v - mu;
            }
        }
        return;
    }
    let mut sc = TermScratch::new(d);
    let mut start = 0;
    while start < count {
        let len = d.min(count - start);
        sc.segment(y, mu, d, start, len, None);
        out.extend_from_slice(&sc.bprev[..len]);
        start += d;
    }
}

#[derive(Default)]
struct TheoScratch {
    b: Vec<f64>,
    t: Vec<f64>,
    full: Vec<f64>,
    part: Vec<f64>,
    win: Vec<f64>,
}

/// Adds the window sums of `t` (window j = t[j·hop .. j·hop + l]) to `out`, via hop-aligned blocks.
fn add_window_sums(
    t: &[f64],
    l: usize,
    hop: usize,
    out: &mut [f64],
    sc_full: &mut Vec<f64>,
    sc_part: &mut Vec<f64>,
    win: &mut Vec<f64>,
) {
    let n_win = out.len();
    let (q, r) = (l / hop, l % hop);
    if hop == 1 {
        win.clear();
        win.resize(n_win, 0.0);
        sliding_sums(t, l, win);
    } else {
        sc_full.clear();
        sc_part.clear();
        for blk in t.chunks(hop) {
            sc_full.push(sum4(blk));
            sc_part.push(sum4(&blk[..r.min(blk.len())]));
        }
        sc_full.resize(n_win + q, 0.0);
        sc_part.resize(n_win + q, 0.0);
        win.clear();
        win.resize(n_win, 0.0);
        if q == 0 {
            win.copy_from_slice(&sc_part[..n_win]);
        } else {
            sliding_sums(sc_full, q, win);
            if r != 0 {
                for (o, p) in win.iter_mut().zip(&sc_part[q..]) {
                    *o += p;
                }
            }
        }
    }
    for (o, w) in out.iter_mut().zip(win.iter()) {
        *o += w;
    }
}

/// Theo1 of every window for a group of m's (rows of `out`, n_windows each). The d-loop is outermost
/// so that each block-sum sequence B_d is formed once for the whole group; every row still receives
/// its d-contributions in increasing d, so the numbers do not depend on how m's are grouped.
/// Stops early, leaving `out` meaningless, once `cancel` is set.
#[allow(clippy::too_many_arguments)] // the group's geometry (y, mu, ms, window, hop) is irreducible
fn theo1_group(
    y: &[f64],
    mu: f64,
    ms: &[usize],
    window: usize,
    hop: usize,
    out: &mut [f64],
    sc: &mut TheoScratch,
    cancel: &Cancel,
) {
    let n_win = out.len() / ms.len();
    out.fill(0.0);
    let TheoScratch {
        b,
        t,
        full,
        part,
        win,
    } = sc;
    let h_max = ms.iter().map(|m| m / 2).max().unwrap_or(0);
    for d in 1..=h_max {
        if cancel.is_cancelled() {
            return;
        }
        // B_d(i) is needed for i < k_end + (m − d) = (n_win − 1)·hop + window + 1 − d, the same for
        // every m (with one window, "hop" is the window's term count and the product vanishes).
        let count = (n_win - 1) * hop + window + 1 - d;
        block_sums(y, mu, d, count, b);
        for (&m, row) in ms.iter().zip(out.chunks_mut(n_win)) {
            // A (d, m) pass is O(record): look at the flag before each one.
            if m / 2 < d || cancel.is_cancelled() {
                continue;
            }
            let l = window + 1 - m; // terms per window (window + 1 phase points)
            let hop_m = if n_win == 1 { l } else { hop };
            let k_end = (n_win - 1) * hop_m + l;
            let s = m - d;
            let w = 1.0 / (0.75 * l as f64 * (m * m) as f64) / d as f64;
            t.clear();
            t.extend(b[s..s + k_end].iter().zip(&b[..k_end]).map(|(u, v)| {
                let e = u - v;
                e * e * w
            }));
            add_window_sums(t, l, hop_m, row, full, part, win);
        }
    }
}

/// Splits the (sorted) factors into contiguous groups of roughly equal work (Σ m/2 terms each).
fn work_groups(ms: &[usize], groups: usize) -> Vec<std::ops::Range<usize>> {
    let total: usize = ms.iter().map(|m| m / 2).sum();
    let target = total.div_ceil(groups.max(1)).max(1);
    let mut out = Vec::new();
    let (mut start, mut acc) = (0, 0);
    for (i, m) in ms.iter().enumerate() {
        acc += m / 2;
        if acc >= target {
            out.push(start..i + 1);
            start = i + 1;
            acc = 0;
        }
    }
    if start < ms.len() {
        out.push(start..ms.len());
    }
    out
}

/// Theo1 of every window of `window` rate samples (window + 1 phase points), starting every `hop`
/// samples, at every m, for every axis: values laid out as [axis][m][window] and the window count.
/// m even, 2 ≤ m ≤ window. Groups of m's (per axis) run in parallel; each value is computed by one
/// sequential routine in a fixed order (bit-identical for any number of threads).
pub fn dynamic_theo1(
    columns: &[&[f64]],
    window: usize,
    hop: usize,
    ms: &[usize],
) -> Result<(Vec<f64>, usize)> {
    dynamic_theo1_cancellable(columns, window, hop, ms, &Cancel::new())
}

/// [`dynamic_theo1`] that stops within one (d, m) pass (O(M) work per worker) once `cancel` is set,
/// and then returns [`CoreError::Cancelled`].
pub fn dynamic_theo1_cancellable(
    columns: &[&[f64]],
    window: usize,
    hop: usize,
    ms: &[usize],
    cancel: &Cancel,
) -> Result<(Vec<f64>, usize)> {
    let n = check_columns(columns)?;
    check_window_hop(window, hop, n, 2)?;
    check_ms(window, ms, "window")?;
    let n_win = crate::allan::n_windows(n, window, hop);
    let (u, pos) = sorted_unique(ms);
    let mus: Vec<f64> = columns.par_iter().map(|c| compensated_mean(c)).collect();
    // A fixed number of groups (not the thread count), so grouping never depends on the machine.
    let groups = work_groups(&u, 8);
    let mut sorted = vec![0.0f64; columns.len() * u.len() * n_win];
    let mut tasks: Vec<(usize, std::ops::Range<usize>, &mut [f64])> = Vec::new();
    for (a, axis_out) in sorted.chunks_mut(u.len() * n_win).enumerate() {
        let mut rest = axis_out;
        for g in &groups {
            let (head, tail) = rest.split_at_mut(g.len() * n_win);
            tasks.push((a, g.clone(), head));
            rest = tail;
        }
    }
    tasks
        .into_par_iter()
        .for_each_init(TheoScratch::default, |sc, (a, g, dst)| {
            theo1_group(columns[a], mus[a], &u[g], window, hop, dst, sc, cancel);
        });
    // A group that stopped early left garbage: never return it.
    cancel.check()?;
    let mut out = Vec::with_capacity(columns.len() * ms.len() * n_win);
    for a in 0..columns.len() {
        let base = a * u.len() * n_win;
        for &p in &pos {
            out.extend_from_slice(&sorted[base + p * n_win..base + (p + 1) * n_win]);
        }
    }
    Ok((out, n_win))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lcg(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
            })
            .collect()
    }

    fn rel(a: f64, b: f64) -> f64 {
        (a - b).abs() / b.abs()
    }

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
    fn dynamic_matches_direct_per_window() {
        let y = lcg(700, 11);
        let (window, hop) = (97, 5);
        let ms = [2usize, 4, 10, 12, 30, 96];
        let (vals, n_win) = dynamic_theo1(&[&y], window, hop, &ms).unwrap();
        for j in [0, 1, n_win / 2, n_win - 1] {
            let x = detrended_phase(&y[j * hop..j * hop + window]);
            for (i, &m) in ms.iter().enumerate() {
                let direct = theo1_direct(&x, m);
                let v = vals[i * n_win + j];
                assert!(rel(v, direct) < 1e-11, "window {j} m {m}: {v} vs {direct}");
            }
        }
    }

    #[test]
    fn whole_record_window_equals_static() {
        let y = lcg(400, 5);
        let ms = [10usize, 50, 200, 398];
        let st = static_theo1(&[&y], &ms).unwrap();
        let (dy, n_win) = dynamic_theo1(&[&y], 400, 1, &ms).unwrap();
        assert_eq!(n_win, 1);
        for i in 0..ms.len() {
            assert!(rel(st[i], dy[i]) < 1e-11);
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

    #[test]
    fn bad_m_is_an_error() {
        let y = lcg(50, 1);
        assert!(static_theo1(&[&y], &[3]).is_err());
        assert!(static_theo1(&[&y], &[52]).is_err());
        assert!(dynamic_theo1(&[&y], 20, 1, &[22]).is_err());
    }
}

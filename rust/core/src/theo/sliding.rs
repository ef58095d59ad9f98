//! Theo1 of sliding windows: per (d, m) term sequences from block sums, summed per window in
//! hop-aligned blocks (see the parent module).

use super::{check_columns, check_ms, sorted_unique};
use crate::allan::{
    check_window_hop, compensated_means, sliding_sums, sum4, TermScratch, DIRECT_M,
};
use crate::cancel::Cancel;
use crate::error::Result;
use rayon::prelude::*;

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
/// and then returns [`CoreError::Cancelled`](crate::CoreError::Cancelled).
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
    let mus = compensated_means(columns);
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
    use super::super::tests::{lcg, rel};
    use super::super::{detrended_phase, static_theo1, theo1_direct};
    use super::*;

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
}

//! Partial sums of squared second differences of an exactly quantised angle — the per-task kernel of
//! the static Allan variance on Dask (`allanite.dask.avar`), where no task holds the whole record.
//!
//! Every rate sample y is split exactly into whole quanta and a remainder: u = y / q with q = 2^e a
//! power of two (so u is exact), w = round-half-even(u) (an integer, |u| ≤ 2^26 by the caller's choice
//! of q) and r = u − w (exact, |r| ≤ ½). The angle in quanta is X = X_w + X_r: X_w the exact running
//! sum of the whole quanta — kept per run of consecutive chunks as base + hi, base the exact int64
//! offset of the run's first chunk and hi the f64 sum since the run's start (an integer below 2^52,
//! so every partial sum is exact) — and X_r the f64 running sum of the remainders from 0 plus the
//! run's remainder offset. A term at factor m is
//!
//!   d_i = ([(hi_c − hi_b) − (hi_b − hi_a)] + k)  +  [(lo_c − lo_b) − (lo_b − lo_a)],
//!
//! k = base_c − 2·base_b + base_a formed in int64 (0 when the three slices share a run): the first
//! part is the exact integer second difference of X_w (exactly a float64 while below 2^53, rounded
//! once beyond), the second is small (the remainders never exceed half a quantum each). These are the
//! values the NumPy code it replaces formed (`allanite._reference.angle_term_sums`: an int64 cumulative
//! sum and the same remainder sums), in one vectorised pass per factor instead of ~10 NumPy passes.
//!
//! Sums: d² ≥ 0, summed in runs of at most `RUN` terms over `LANES` independent partial sums, runs
//! added by Neumaier's compensated sum — relative error ≲ (RUN/LANES + 2)·ε, independent of the task's
//! length. Each plan item is summed by one sequential routine, so the bits do not depend on the number
//! of threads.

use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
use crate::oavar::PhaseBuf;
use rayon::prelude::*;

/// Longest run of terms summed into the lane accumulators before it is folded into the total.
const RUN: usize = 2048;
/// Independent partial sums per run.
const LANES: usize = 8;

/// One chunk of the record as a task sees it.
#[derive(Clone, Copy, Debug)]
pub struct AngleChunk<'a> {
    /// The record's index of the chunk's first sample.
    pub start: usize,
    /// Rate samples, (samples × axes) row-major.
    pub y: &'a [f64],
    /// Exact angle at `start` per axis: whole quanta.
    pub off_w: &'a [i64],
    /// … and the remainder (in quanta).
    pub off_r: &'a [f64],
}

/// A term range of the plan: factor m, terms i0 ≤ i < i1 (the record's indices; classic: only the
/// multiples of m among them).
pub type PlanItem = (usize, usize, usize);

/// y · 2^k, exact whenever the result is a normal number (two steps when 2^k itself is not one).
#[inline(always)]
fn scale(y: f64, k: i32) -> f64 {
    let pow = |k: i32| f64::from_bits(((1023 + k) as u64) << 52);
    if (-1022..=1023).contains(&k) {
        y * pow(k)
    } else {
        let h = k / 2;
        y * pow(h) * pow(k - h)
    }
}

/// The angle of one run of consecutive chunks, one axis: X_w = base + hi exactly (hi the whole quanta
/// since the run's start, an integer below 2^52 in magnitude, so exact in f64), X_r = lo.
struct Run {
    start: usize,
    base: i64,
    hi: PhaseBuf,
    lo: PhaseBuf,
}

/// Whole quanta per sample beyond this mean the quantum was chosen too small for the samples.
const MAX_WHOLE: f64 = (1u64 << 40) as f64;

/// Local whole-quanta angles up to this magnitude are exact in f64 with room for one difference.
const MAX_LOCAL: f64 = (1u64 << 52) as f64;

/// Round half to even for |u| < 2^51 (the default rounding of the addition does it; no libm call on
/// CPUs without SSE4.1). Larger |u| give a value of about the same size, which the caller refuses.
#[inline(always)]
fn rint(u: f64) -> f64 {
    const MAGIC: f64 = 6755399441055744.0; // 1.5 · 2^52
    if u >= 0.0 {
        (u + MAGIC) - MAGIC
    } else {
        (u - MAGIC) + MAGIC
    }
}

/// The angle of the run's first `len` samples (points 0 … len).
fn build_run(
    chunks: &[AngleChunk],
    axis: usize,
    n_axes: usize,
    q_exp: i32,
    len: usize,
) -> Result<Run> {
    let mut hi_buf = PhaseBuf::new(len + 1);
    let mut lo_buf = PhaseBuf::new(len + 1);
    let (hi, lo) = (hi_buf.slice(), lo_buf.slice());
    let (base, or) = (chunks[0].off_w[axis], chunks[0].off_r[axis]);
    lo[0] = or;
    let (mut w_acc, mut r_acc) = (0.0f64, 0.0f64);
    let mut peak_u = 0.0f64;
    let mut t = 0;
    for c in chunks {
        if t >= len {
            break;
        }
        let rows = (c.y.len() / n_axes).min(len - t);
        let (h, l) = (&mut hi[t + 1..t + 1 + rows], &mut lo[t + 1..t + 1 + rows]);
        for ((hv, lv), row) in h.iter_mut().zip(l.iter_mut()).zip(c.y.chunks_exact(n_axes)) {
            let u = scale(row[axis], -q_exp);
            let w = rint(u);
            peak_u = peak_u.max(w.abs());
            // whole quanta sum exactly in f64 while the run stays below 2^52 (checked below)
            w_acc += w;
            r_acc += u - w;
            *hv = w_acc;
            *lv = r_acc + or;
        }
        t += rows;
    }
    let bound = peak_u * len as f64;
    if !(peak_u <= MAX_WHOLE && bound <= MAX_LOCAL) {
        return Err(CoreError::InvalidParameter(format!(
            "{len} samples of up to {peak_u} quanta of 2^{q_exp} may sum beyond 2^52: use shorter chunks"
        )));
    }
    Ok(Run {
        start: chunks[0].start,
        base,
        hi: hi_buf,
        lo: lo_buf,
    })
}

/// The run holding angle points [lo, hi), and the offset of `lo` in it.
fn find(runs: &[Run], lo: usize, hi: usize) -> Option<(&Run, usize)> {
    runs.iter()
        .find(|r| r.start <= lo && hi - r.start <= r.hi.get().len())
        .map(|r| (r, lo - r.start))
}

/// Σ d² over contiguous terms: d = ([(hc − hb) − (hb − ha)] + k) + [(lc − lb) − (lb − la)], in
/// `LANES` partial sums (packed vector operations; the same IEEE operations whatever the width).
#[inline(always)]
fn run_sum(h: [&[f64]; 3], l: [&[f64]; 3], k: f64) -> f64 {
    let mut acc = [0.0f64; LANES];
    let n = h[0].len();
    let full = n / LANES * LANES;
    let it = h[0][..full]
        .chunks_exact(LANES)
        .zip(h[1][..full].chunks_exact(LANES))
        .zip(h[2][..full].chunks_exact(LANES))
        .zip(l[0][..full].chunks_exact(LANES))
        .zip(l[1][..full].chunks_exact(LANES))
        .zip(l[2][..full].chunks_exact(LANES));
    for (((((ha, hb), hc), la), lb), lc) in it {
        for t in 0..LANES {
            let dh = (hc[t] - hb[t]) - (hb[t] - ha[t]);
            let dl = (lc[t] - lb[t]) - (lb[t] - la[t]);
            let d = (dh + k) + dl;
            acc[t] += d * d;
        }
    }
    for t in full..n {
        let dh = (h[2][t] - h[1][t]) - (h[1][t] - h[0][t]);
        let dl = (l[2][t] - l[1][t]) - (l[1][t] - l[0][t]);
        let d = (dh + k) + dl;
        acc[t - full] += d * d;
    }
    ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]))
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn run_sum_avx2(h: [&[f64]; 3], l: [&[f64]; 3], k: f64) -> f64 {
    run_sum(h, l, k)
}

fn run_sum_dispatch(avx2: bool, h: [&[f64]; 3], l: [&[f64]; 3], k: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: the caller checked that the CPU has AVX2.
        return unsafe { run_sum_avx2(h, l, k) };
    }
    let _ = avx2;
    run_sum(h, l, k)
}

/// Σ d_i² over `count` terms whose three points start at offsets a, b, c of their runs, `step` apart.
/// The whole-quanta part of d is [(hc − hb) − (hb − ha)] + k, k = base_c − 2·base_b + base_a formed
/// exactly in int64: the integer second difference, exact while below 2^53 (rounded once beyond).
fn term_sum(
    avx2: bool,
    (ra, a): (&Run, usize),
    (rb, b): (&Run, usize),
    (rc, c): (&Run, usize),
    count: usize,
    step: usize,
) -> f64 {
    let k = rc
        .base
        .wrapping_sub(rb.base.wrapping_mul(2))
        .wrapping_add(ra.base) as f64;
    let (ha, hb, hc) = (ra.hi.get(), rb.hi.get(), rc.hi.get());
    let (la, lb, lc) = (ra.lo.get(), rb.lo.get(), rc.lo.get());
    let (mut s, mut comp) = (0.0f64, 0.0f64);
    let mut done = 0;
    while done < count {
        let n = RUN.min(count - done);
        let run = if step == 1 {
            let (a0, b0, c0) = (a + done, b + done, c + done);
            run_sum_dispatch(
                avx2,
                [&ha[a0..a0 + n], &hb[b0..b0 + n], &hc[c0..c0 + n]],
                [&la[a0..a0 + n], &lb[b0..b0 + n], &lc[c0..c0 + n]],
                k,
            )
        } else {
            let mut acc = [0.0f64; LANES];
            for t in 0..n {
                let (i, j, l) = (
                    a + (done + t) * step,
                    b + (done + t) * step,
                    c + (done + t) * step,
                );
                let dh = (hc[l] - hb[j]) - (hb[j] - ha[i]);
                let dl = (lc[l] - lb[j]) - (lb[j] - la[i]);
                let d = (dh + k) + dl;
                acc[t % LANES] += d * d;
            }
            ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]))
        };
        // Neumaier
        let t = s + run;
        if s.abs() >= run.abs() {
            comp += (s - t) + run;
        } else {
            comp += (run - t) + s;
        }
        s = t;
        done += n;
    }
    s + comp
}

/// The angle of one axis of a run of consecutive chunks, produced point by point without storing it:
/// the same running sums as [`build_run`] (so the same values), for a plan item that reads the run
/// only once (one factor per task: a few slices far apart, where building the whole run would cost
/// more than the terms).
struct Cursor<'a> {
    chunks: &'a [AngleChunk<'a>],
    axis: usize,
    n_axes: usize,
    q_exp: i32,
    /// chunk and row of the next sample
    ci: usize,
    row: usize,
    w_acc: f64,
    r_acc: f64,
    or: f64,
    base: i64,
    peak: f64,
    consumed: usize,
}

impl<'a> Cursor<'a> {
    fn new(chunks: &'a [AngleChunk<'a>], axis: usize, n_axes: usize, q_exp: i32) -> Self {
        Cursor {
            chunks,
            axis,
            n_axes,
            q_exp,
            ci: 0,
            row: 0,
            w_acc: 0.0,
            r_acc: 0.0,
            or: chunks[0].off_r[axis],
            base: chunks[0].off_w[axis],
            peak: 0.0,
            consumed: 0,
        }
    }

    /// Adds the next `k` samples (the angle moves k points on); stops at the end of the run.
    #[inline(always)]
    fn advance(&mut self, mut k: usize) {
        while k > 0 && self.ci < self.chunks.len() {
            let c = &self.chunks[self.ci];
            let rows = c.y.len() / self.n_axes;
            let take = k.min(rows - self.row);
            for r in self.row..self.row + take {
                let u = scale(c.y[r * self.n_axes + self.axis], -self.q_exp);
                let w = rint(u);
                self.peak = self.peak.max(w.abs());
                self.w_acc += w;
                self.r_acc += u - w;
            }
            self.row += take;
            self.consumed += take;
            k -= take;
            if self.row == rows {
                self.ci += 1;
                self.row = 0;
            }
        }
    }

    /// Writes the next h.len() points (hi, lo), one sample apart, and moves past them: the points of
    /// [`build_run`], for one block of terms at a time (cache-resident).
    #[inline(always)]
    fn fill(&mut self, h: &mut [f64], l: &mut [f64]) {
        let n = h.len();
        let mut t = 0;
        while t < n {
            if self.ci >= self.chunks.len() {
                // past the run's last sample: only the point at its end remains
                let (hv, lv) = self.point();
                h[t..].fill(hv);
                l[t..].fill(lv);
                return;
            }
            let c = &self.chunks[self.ci];
            let rows = c.y.len() / self.n_axes;
            let take = (n - t).min(rows - self.row);
            let (hs, ls) = (&mut h[t..t + take], &mut l[t..t + take]);
            let ys = &c.y[self.row * self.n_axes..(self.row + take) * self.n_axes];
            let (mut w_acc, mut r_acc, mut peak) = (self.w_acc, self.r_acc, self.peak);
            for ((hv, lv), row) in hs
                .iter_mut()
                .zip(ls.iter_mut())
                .zip(ys.chunks_exact(self.n_axes))
            {
                *hv = w_acc;
                *lv = r_acc + self.or;
                let u = scale(row[self.axis], -self.q_exp);
                let w = rint(u);
                peak = peak.max(w.abs());
                w_acc += w;
                r_acc += u - w;
            }
            (self.w_acc, self.r_acc, self.peak) = (w_acc, r_acc, peak);
            self.row += take;
            self.consumed += take;
            t += take;
            if self.row == rows {
                self.ci += 1;
                self.row = 0;
            }
        }
    }

    /// (hi, lo) of the current point, as [`build_run`] stores them.
    #[inline(always)]
    fn point(&self) -> (f64, f64) {
        (self.w_acc, self.r_acc + self.or)
    }

    fn check(&self) -> Result<()> {
        if self.peak <= MAX_WHOLE && self.peak * self.consumed as f64 <= MAX_LOCAL {
            Ok(())
        } else {
            Err(CoreError::InvalidParameter(format!(
                "{} samples of up to {} quanta of 2^{} may sum beyond 2^52: use shorter chunks",
                self.consumed, self.peak, self.q_exp
            )))
        }
    }
}

/// [`term_sum`] of one plan item read through three cursors: the same terms and the same partial sums
/// (LANES lanes in runs of RUN terms, runs added by Neumaier), so the same bits.
fn stream_sum(
    avx2: bool,
    cur: &mut [Cursor; 3],
    starts: [usize; 3],
    count: usize,
    step: usize,
) -> Result<f64> {
    for (c, &s) in cur.iter_mut().zip(&starts) {
        c.advance(s);
    }
    let k = cur[2]
        .base
        .wrapping_sub(cur[1].base.wrapping_mul(2))
        .wrapping_add(cur[0].base) as f64;
    let (mut s, mut comp) = (0.0f64, 0.0f64);
    let mut done = 0;
    let mut buf = vec![0.0f64; 6 * RUN];
    while done < count {
        let n = RUN.min(count - done);
        let run = if step == 1 {
            // the block's points of the three slices, then the vectorised sum of the stored path
            let (h, l) = buf.split_at_mut(3 * RUN);
            let (h0, h12) = h.split_at_mut(RUN);
            let (h1, h2) = h12.split_at_mut(RUN);
            let (l0, l12) = l.split_at_mut(RUN);
            let (l1, l2) = l12.split_at_mut(RUN);
            cur[0].fill(&mut h0[..n], &mut l0[..n]);
            cur[1].fill(&mut h1[..n], &mut l1[..n]);
            cur[2].fill(&mut h2[..n], &mut l2[..n]);
            run_sum_dispatch(
                avx2,
                [&h0[..n], &h1[..n], &h2[..n]],
                [&l0[..n], &l1[..n], &l2[..n]],
                k,
            )
        } else {
            let mut acc = [0.0f64; LANES];
            for (t, a) in (0..n).zip((0..LANES).cycle()) {
                if t > 0 || done > 0 {
                    for c in cur.iter_mut() {
                        c.advance(step);
                    }
                }
                let ((ha, la), (hb, lb), (hc, lc)) =
                    (cur[0].point(), cur[1].point(), cur[2].point());
                let dh = (hc - hb) - (hb - ha);
                let dl = (lc - lb) - (lb - la);
                let d = (dh + k) + dl;
                acc[a] += d * d;
            }
            ((acc[0] + acc[1]) + (acc[2] + acc[3])) + ((acc[4] + acc[5]) + (acc[6] + acc[7]))
        };
        let t = s + run;
        if s.abs() >= run.abs() {
            comp += (s - t) + run;
        } else {
            comp += (run - t) + s;
        }
        s = t;
        done += n;
    }
    for c in cur.iter() {
        c.check()?;
    }
    Ok(s + comp)
}

/// For every plan item and axis, Σ (X[i+2m] − 2X[i+m] + X[i])² in quanta² over the item's terms, X the
/// exact angle of the chunks (see the module notes): [item][axis]. `chunks` in record order; those that
/// follow each other form runs, and each of a term range's three slices must lie in one run.
pub fn angle_term_sums_cancellable(
    chunks: &[AngleChunk],
    n_axes: usize,
    q_exp: i32,
    plan: &[PlanItem],
    classic: bool,
    cancel: &Cancel,
) -> Result<Vec<f64>> {
    if n_axes == 0 || chunks.is_empty() {
        return Err(CoreError::InvalidParameter(
            "no chunks or no axes given".into(),
        ));
    }
    if !(-1100..=1100).contains(&q_exp) {
        return Err(CoreError::InvalidParameter(format!(
            "quantum exponent {q_exp} is outside −1100 … 1100"
        )));
    }
    for (j, c) in chunks.iter().enumerate() {
        if c.y.len() % n_axes != 0 || c.off_w.len() != n_axes || c.off_r.len() != n_axes {
            return Err(CoreError::InvalidParameter(format!(
                "chunk {j}: {} values, {} and {} offsets do not fit {n_axes} axes",
                c.y.len(),
                c.off_w.len(),
                c.off_r.len()
            )));
        }
        if let Some(i) = c.y.iter().position(|v| !v.is_finite()) {
            return Err(CoreError::NonFinite {
                axis: i % n_axes,
                index: c.start + i / n_axes,
                value: c.y[i],
            });
        }
        if j > 0 && c.start < chunks[j - 1].start + chunks[j - 1].y.len() / n_axes {
            return Err(CoreError::InvalidParameter(format!(
                "chunk {j} starts at {} inside the chunk before it: chunks must be in record order",
                c.start
            )));
        }
    }
    // runs of consecutive chunks
    let mut groups: Vec<&[AngleChunk]> = Vec::new();
    let mut g0 = 0;
    for j in 1..=chunks.len() {
        let prev = &chunks[j - 1];
        if j == chunks.len() || chunks[j].start != prev.start + prev.y.len() / n_axes {
            groups.push(&chunks[g0..j]);
            g0 = j;
        }
    }
    // every item's terms and slices, checked before any work
    let mut items = Vec::with_capacity(plan.len());
    for &(m, i0, i1) in plan {
        if m == 0 {
            return Err(CoreError::InvalidParameter(
                "averaging factor m = 0 in the plan".into(),
            ));
        }
        let i0 = if classic { i0.div_ceil(m) * m } else { i0 };
        let step = if classic { m } else { 1 };
        let count = if i1 > i0 { (i1 - i0).div_ceil(step) } else { 0 };
        let last = i0 + count.saturating_sub(1) * step + 1; // one past the item's last term
        items.push((m, i0, last, step, count));
    }
    // samples of each run that some slice reaches (its angle points up to that one)
    let mut needed = vec![0usize; groups.len()];
    for &(m, i0, last, _step, count) in &items {
        if count == 0 {
            continue;
        }
        for s in [0, m, 2 * m] {
            let (lo, hi) = (i0 + s, last + s);
            if let Some(g) = groups.iter().position(|g| {
                let start = g[0].start;
                let len: usize = g.iter().map(|c| c.y.len() / n_axes).sum();
                start <= lo && hi - start <= len + 1
            }) {
                needed[g] = needed[g].max(hi - 1 - groups[g][0].start);
            }
        }
    }
    #[cfg(target_arch = "x86_64")]
    let avx2 = std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    let avx2 = false;
    let mut out = vec![0.0f64; plan.len() * n_axes];
    let busy: Vec<usize> = (0..items.len()).filter(|&p| items[p].4 > 0).collect();
    if busy.len() == 1 {
        // One factor (a long one: its slices lie far apart): stream the three slices, store nothing.
        let (m, i0, last, step, count) = items[busy[0]];
        let mut at = [(0usize, 0usize); 3]; // (group, first point's offset in it)
        for (j, s) in [0, m, 2 * m].into_iter().enumerate() {
            let (lo, hi) = (i0 + s, last + s);
            at[j] = groups
                .iter()
                .enumerate()
                .find_map(|(g, grp)| {
                    let len: usize = grp.iter().map(|c| c.y.len() / n_axes).sum();
                    (grp[0].start <= lo && hi - grp[0].start <= len + 1)
                        .then(|| (g, lo - grp[0].start))
                })
                .ok_or_else(|| {
                    CoreError::InvalidParameter(format!(
                        "angle points {lo}..{hi} (m = {m}) are not in the chunks given"
                    ))
                })?;
        }
        let sums: Vec<Result<f64>> = (0..n_axes)
            .into_par_iter()
            .map(|axis| {
                if cancel.is_cancelled() {
                    return Ok(0.0);
                }
                let mut cur = at.map(|(g, _)| Cursor::new(groups[g], axis, n_axes, q_exp));
                stream_sum(avx2, &mut cur, at.map(|(_, o)| o), count, step)
            })
            .collect();
        for (axis, s) in sums.into_iter().enumerate() {
            out[busy[0] * n_axes + axis] = s?;
        }
        cancel.check()?;
        return Ok(out);
    }
    for axis in 0..n_axes {
        cancel.check()?;
        let runs: Vec<Run> = groups
            .par_iter()
            .zip(&needed)
            .map(|(g, &len)| build_run(g, axis, n_axes, q_exp, len))
            .collect::<Result<_>>()?;
        let sums: Vec<Result<f64>> = items
            .par_iter()
            .map(|&(m, i0, last, step, count)| {
                if count == 0 || cancel.is_cancelled() {
                    return Ok(0.0);
                }
                let slice = |s: usize| {
                    find(&runs, i0 + s, last + s).ok_or_else(|| {
                        CoreError::InvalidParameter(format!(
                            "angle points {}..{} (m = {m}) are not in the chunks given",
                            i0 + s,
                            last + s
                        ))
                    })
                };
                Ok(term_sum(
                    avx2,
                    slice(0)?,
                    slice(m)?,
                    slice(2 * m)?,
                    count,
                    step,
                ))
            })
            .collect();
        for (p, s) in sums.into_iter().enumerate() {
            out[p * n_axes + axis] = s?;
        }
    }
    cancel.check()?;
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Integer-valued samples on a quantum of 1: every sum is exact, so the kernel must match the
    /// plain definition exactly.
    #[test]
    fn matches_the_plain_definition_on_exact_data() {
        let n = 997;
        let y: Vec<f64> = (0..2 * n)
            .map(|i| ((i * 7919) % 201) as f64 - 100.0)
            .collect(); // 2 axes, row-major
        let angle = |a: usize| {
            let mut x = vec![0.0f64];
            for i in 0..n {
                x.push(x[i] + y[2 * i + a]);
            }
            x
        };
        let xs = [angle(0), angle(1)];
        // three chunks, the middle one left out of the second task to make two runs
        let cut = [0, 300, 640, n];
        let offs: Vec<[i64; 2]> = cut[..3]
            .iter()
            .map(|&s| [xs[0][s] as i64, xs[1][s] as i64])
            .collect();
        let zeros = [0.0, 0.0];
        let chunk = |j: usize| AngleChunk {
            start: cut[j],
            y: &y[2 * cut[j]..2 * cut[j + 1]],
            off_w: &offs[j],
            off_r: &zeros,
        };
        let all = [chunk(0), chunk(1), chunk(2)];
        for classic in [false, true] {
            let plan = [
                (1, 0, 996),
                (7, 3, 600),
                (100, 0, 400),
                (300, 0, 398),
                (5, 0, 290),
            ];
            let got =
                angle_term_sums_cancellable(&all, 2, 0, &plan, classic, &Cancel::new()).unwrap();
            for (p, &(m, i0, i1)) in plan.iter().enumerate() {
                for a in 0..2 {
                    let x = &xs[a];
                    let want: f64 = (i0..i1)
                        .filter(|i| !classic || i % m == 0)
                        .map(|i| {
                            let d = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
                            d * d
                        })
                        .sum();
                    assert_eq!(got[p * 2 + a], want, "classic {classic} m {m} axis {a}");
                }
            }
        }
        // two runs: chunks 0 and 2 only; a term range whose slices lie in them works, one that needs
        // chunk 1 is refused
        let two = [chunk(0), chunk(2)];
        let ok = angle_term_sums_cancellable(&two, 2, 0, &[(349, 291, 293)], false, &Cancel::new());
        let x = &xs[1];
        let want: f64 = (291..293)
            .map(|i| (x[i + 698] - 2.0 * x[i + 349] + x[i]).powi(2))
            .sum();
        assert_eq!(ok.unwrap()[1], want);
        let bad = angle_term_sums_cancellable(&two, 2, 0, &[(320, 0, 10)], false, &Cancel::new());
        assert!(matches!(bad, Err(CoreError::InvalidParameter(_))));
    }

    #[test]
    fn streaming_one_factor_gives_the_stored_paths_bits() {
        // noisy, biased, three axes; chunks of uneven length in two runs
        let n = 5000;
        let na = 3;
        let mut x = 0x9E3779B97F4A7C15u64;
        let y: Vec<f64> = (0..n * na)
            .map(|i| {
                x = x
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((x >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * [1.0, 3e-3, 40.0][i % na]
                    + [0.0, 7.0, -900.0][i % na]
            })
            .collect();
        let q_exp = -16; // |y/q| ≤ 2^26
        let cut = [0, 700, 1900, 2600, 5000];
        let offs_w: Vec<Vec<i64>> = cut[..4].iter().map(|&c| vec![c as i64 * 3; na]).collect();
        let offs_r: Vec<Vec<f64>> = cut[..4]
            .iter()
            .map(|&c| vec![c as f64 * 1e-3; na])
            .collect();
        let chunk = |j: usize| AngleChunk {
            start: cut[j],
            y: &y[na * cut[j]..na * cut[j + 1]],
            off_w: &offs_w[j],
            off_r: &offs_r[j],
        };
        let all = [chunk(0), chunk(1), chunk(2), chunk(3)];
        let two = [chunk(0), chunk(2), chunk(3)];
        let c = Cancel::new();
        for classic in [false, true] {
            for (chunks, item) in [
                (&all[..], (1usize, 0usize, 4998usize)),
                (&all[..], (37, 650, 2700)),
                (&all[..], (1200, 100, 2500)),
                (&two[..], (1300, 600, 650)), // slices in two runs: [600,650) and [1900,1950), [3200,3250)
            ] {
                let one =
                    angle_term_sums_cancellable(chunks, na, q_exp, &[item], classic, &c).unwrap();
                // a second (empty-free) item makes the call build and store the runs
                let stored = angle_term_sums_cancellable(
                    chunks,
                    na,
                    q_exp,
                    &[item, (1, 0, 10)],
                    classic,
                    &c,
                )
                .unwrap();
                for a in 0..na {
                    assert_eq!(
                        one[a].to_bits(),
                        stored[a].to_bits(),
                        "{item:?} {classic} {a}"
                    );
                    let terms = (item.1..item.2).any(|i| !classic || i % item.0 == 0);
                    assert_eq!(one[a] > 0.0, terms);
                }
            }
        }
    }

    #[test]
    fn bad_input_is_named() {
        let y = [1.0, f64::NAN, 3.0];
        let c = [AngleChunk {
            start: 10,
            y: &y,
            off_w: &[0],
            off_r: &[0.0],
        }];
        let e = angle_term_sums_cancellable(&c, 1, 0, &[(1, 10, 11)], false, &Cancel::new());
        assert!(matches!(e, Err(CoreError::NonFinite { index: 11, .. })));
        let e = angle_term_sums_cancellable(&c, 1, 2000, &[(1, 10, 11)], false, &Cancel::new());
        assert!(matches!(e, Err(CoreError::InvalidParameter(_))));
    }

    #[test]
    fn scale_is_exact_across_the_range() {
        assert_eq!(scale(3.0, -1), 1.5);
        assert_eq!(scale(1.0, -1074), f64::from_bits(1));
        assert_eq!(scale(f64::from_bits(1), 1074), 1.0);
        assert_eq!(scale(1.5, 1023), 1.5 * 2f64.powi(1023));
    }
}

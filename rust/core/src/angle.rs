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
//!
//! The module's parts: `runs` (the stored runs and the vectorised term sums over them) and `stream`
//! (a run's angle produced point by point, for items that read it once).

mod runs;
mod stream;
#[cfg(test)]
mod tests;

use runs::{build_run, find, term_sum, Run};
use stream::{stream_sum, Cursor};

use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
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

/// A plan item as the sums read it: (m, first term, one past the last term, step, terms).
type Item = (usize, usize, usize, usize, usize);

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
    check_chunks(chunks, n_axes, q_exp)?;
    let groups = runs_of(chunks, n_axes);
    let items = plan_items(plan, classic)?;
    let needed = needed_lengths(&groups, &items, n_axes);
    #[cfg(target_arch = "x86_64")]
    let avx2 = std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    let avx2 = false;
    let angle = Angle {
        groups: &groups,
        n_axes,
        q_exp,
        avx2,
    };
    let mut out = vec![0.0f64; plan.len() * n_axes];
    let busy: Vec<usize> = (0..items.len()).filter(|&p| items[p].4 > 0).collect();
    if busy.len() == 1 {
        // One factor (a long one: its slices lie far apart): stream the three slices, store nothing.
        let sums = angle.streamed(items[busy[0]], cancel)?;
        for (axis, s) in sums.into_iter().enumerate() {
            out[busy[0] * n_axes + axis] = s?;
        }
        cancel.check()?;
        return Ok(out);
    }
    for axis in 0..n_axes {
        cancel.check()?;
        let sums = angle.stored(axis, &needed, &items, cancel)?;
        for (p, s) in sums.into_iter().enumerate() {
            out[p * n_axes + axis] = s?;
        }
    }
    cancel.check()?;
    Ok(out)
}

/// The chunks' shapes, values and order and the quantum's exponent, checked before any work.
fn check_chunks(chunks: &[AngleChunk], n_axes: usize, q_exp: i32) -> Result<()> {
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
    Ok(())
}

/// The runs of consecutive chunks.
fn runs_of<'c, 'a>(chunks: &'c [AngleChunk<'a>], n_axes: usize) -> Vec<&'c [AngleChunk<'a>]> {
    let mut groups: Vec<&[AngleChunk]> = Vec::new();
    let mut g0 = 0;
    for j in 1..=chunks.len() {
        let prev = &chunks[j - 1];
        if j == chunks.len() || chunks[j].start != prev.start + prev.y.len() / n_axes {
            groups.push(&chunks[g0..j]);
            g0 = j;
        }
    }
    groups
}

/// Every item's terms and slices, checked before any work.
fn plan_items(plan: &[PlanItem], classic: bool) -> Result<Vec<Item>> {
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
    Ok(items)
}

/// Samples of each run that some slice reaches (its angle points up to that one).
fn needed_lengths(groups: &[&[AngleChunk]], items: &[Item], n_axes: usize) -> Vec<usize> {
    let mut needed = vec![0usize; groups.len()];
    for &(m, i0, last, _step, count) in items {
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
    needed
}

/// The runs of chunks and how their angle is read.
struct Angle<'g, 'c, 'a> {
    groups: &'g [&'c [AngleChunk<'a>]],
    n_axes: usize,
    q_exp: i32,
    avx2: bool,
}

impl Angle<'_, '_, '_> {
    /// The sums of one item, the three slices streamed from the chunks and nothing stored: one per axis.
    fn streamed(&self, item: Item, cancel: &Cancel) -> Result<Vec<Result<f64>>> {
        let (m, i0, last, step, count) = item;
        let (groups, n_axes, q_exp, avx2) = (self.groups, self.n_axes, self.q_exp, self.avx2);
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
        Ok((0..n_axes)
            .into_par_iter()
            .map(|axis| {
                if cancel.is_cancelled() {
                    return Ok(0.0);
                }
                let mut cur = at.map(|(g, _)| Cursor::new(groups[g], axis, n_axes, q_exp));
                stream_sum(avx2, &mut cur, at.map(|(_, o)| o), count, step)
            })
            .collect())
    }

    /// Every item's sum on one axis from the runs' angles, stored as far as some slice reaches
    /// (`needed`).
    fn stored(
        &self,
        axis: usize,
        needed: &[usize],
        items: &[Item],
        cancel: &Cancel,
    ) -> Result<Vec<Result<f64>>> {
        let (n_axes, q_exp, avx2) = (self.n_axes, self.q_exp, self.avx2);
        let runs: Vec<Run> = self
            .groups
            .par_iter()
            .zip(needed)
            .map(|(g, &len)| build_run(g, axis, n_axes, q_exp, len))
            .collect::<Result<_>>()?;
        Ok(items
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
            .collect())
    }
}

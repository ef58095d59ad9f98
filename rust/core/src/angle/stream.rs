//! The angle of a run produced point by point (no stored run), for plan items that read a run once.

use super::runs::{rint, run_sum_dispatch, scale, MAX_LOCAL, MAX_WHOLE};
use super::{AngleChunk, LANES, RUN};
use crate::allan::Compensated;
use crate::error::{CoreError, Result};

/// The angle of one axis of a run of consecutive chunks, produced point by point without storing it:
/// the same running sums as [`build_run`] (so the same values), for a plan item that reads the run
/// only once (one factor per task: a few slices far apart, where building the whole run would cost
/// more than the terms).
///
/// [`build_run`]: super::runs::build_run
pub(super) struct Cursor<'a> {
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
    pub(super) fn new(
        chunks: &'a [AngleChunk<'a>],
        axis: usize,
        n_axes: usize,
        q_exp: i32,
    ) -> Self {
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
    ///
    /// [`build_run`]: super::runs::build_run
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
    ///
    /// [`build_run`]: super::runs::build_run
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
///
/// [`term_sum`]: super::runs::term_sum
pub(super) fn stream_sum(
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
    let mut sum = Compensated::default();
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
        sum.add(run);
        done += n;
    }
    for c in cur.iter() {
        c.check()?;
    }
    Ok(sum.value())
}

//! The runs of consecutive chunks, built whole (the exact whole-quanta and remainder angles of one
//! axis), and the vectorised sum of a plan item's squared second differences over them.

use super::{AngleChunk, LANES, RUN};
use crate::allan::Compensated;
use crate::error::{CoreError, Result};
use crate::oavar::PhaseBuf;

/// y · 2^k, exact whenever the result is a normal number (two steps when 2^k itself is not one).
#[inline(always)]
pub(super) fn scale(y: f64, k: i32) -> f64 {
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
pub(super) struct Run {
    start: usize,
    base: i64,
    hi: PhaseBuf,
    lo: PhaseBuf,
}

/// Whole quanta per sample beyond this mean the quantum was chosen too small for the samples.
pub(super) const MAX_WHOLE: f64 = (1u64 << 40) as f64;

/// Local whole-quanta angles up to this magnitude are exact in f64 with room for one difference.
pub(super) const MAX_LOCAL: f64 = (1u64 << 52) as f64;

/// Round half to even for |u| < 2^51 (the default rounding of the addition does it; no libm call on
/// CPUs without SSE4.1). Larger |u| give a value of about the same size, which the caller refuses.
#[inline(always)]
pub(super) fn rint(u: f64) -> f64 {
    const MAGIC: f64 = 6755399441055744.0; // 1.5 · 2^52
    if u >= 0.0 {
        (u + MAGIC) - MAGIC
    } else {
        (u - MAGIC) + MAGIC
    }
}

/// The angle of the run's first `len` samples (points 0 … len).
pub(super) fn build_run(
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
pub(super) fn find(runs: &[Run], lo: usize, hi: usize) -> Option<(&Run, usize)> {
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

pub(super) fn run_sum_dispatch(avx2: bool, h: [&[f64]; 3], l: [&[f64]; 3], k: f64) -> f64 {
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
pub(super) fn term_sum(
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
    let mut sum = Compensated::default();
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
        sum.add(run);
        done += n;
    }
    sum.value()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scale_is_exact_across_the_range() {
        assert_eq!(scale(3.0, -1), 1.5);
        assert_eq!(scale(1.0, -1074), f64::from_bits(1));
        assert_eq!(scale(f64::from_bits(1), 1074), 1.0);
        assert_eq!(scale(1.5, 1023), 1.5 * 2f64.powi(1023));
    }
}

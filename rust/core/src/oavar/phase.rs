//! The double-word phase P = hi + lo of a centred record, built block by block in parallel, and the
//! buffers that hold it (see the parent module on why it does not drift).

use super::{BLOCK, CHUNK, LANES};
use crate::gather::two_sum;
use rayon::prelude::*;

/// The double-word total of `src − μ` (each fl(v − μ) as the prefix pass rounds it), in `LANES`
/// independent TwoSum accumulators so that it vectorises; their exact errors are kept and the lanes
/// are joined with TwoSum. Error ≲ ε²·len·Σ|v − μ|.
#[inline(always)]
fn block_total(src: &[f64], mu: f64) -> (f64, f64) {
    let mut s = [0.0f64; LANES];
    let mut c = [0.0f64; LANES];
    let body = src.chunks_exact(LANES);
    let tail = body.remainder();
    for v in body {
        for j in 0..LANES {
            let (t, e) = two_sum(s[j], v[j] - mu);
            s[j] = t;
            c[j] += e;
        }
    }
    for (j, &v) in tail.iter().enumerate() {
        let (t, e) = two_sum(s[j], v - mu);
        s[j] = t;
        c[j] += e;
    }
    let (mut th, mut tl) = (0.0f64, 0.0f64);
    for j in 0..LANES {
        let (t, e) = two_sum(th, s[j]);
        th = t;
        tl += e + c[j];
    }
    (th, tl)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn block_total_avx2(src: &[f64], mu: f64) -> (f64, f64) {
    block_total(src, mu)
}

pub(crate) fn block_total_dispatch(src: &[f64], mu: f64) -> (f64, f64) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the CPU has the feature the function is compiled for (checked just above).
        return unsafe { block_total_avx2(src, mu) };
    }
    block_total(src, mu)
}

/// The phase of one block from its double-word offset (oh, ol): running TwoSum of fl(v − μ) from
/// s = oh with the exact errors summed in c (from ol), each (s, c) stored normalised (|l| ≤ ½ ulp(h):
/// hi alone is the phase rounded once). Returns, into `maxima`, the largest |h| and
/// |l| of each run of `CHUNK` pairs (the bounds the single-word term pass checks itself against, see
/// `sums::single_word_holds`).
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn block_phase(
    src: &[f64],
    mu: f64,
    oh: f64,
    ol: f64,
    h: &mut [f64],
    l: &mut [f64],
    maxima: &mut [(f64, f64)],
) {
    let (mut s, mut c) = (oh, ol);
    for (((hc, lc), yc), mx) in h
        .chunks_mut(CHUNK)
        .zip(l.chunks_mut(CHUNK))
        .zip(src.chunks(CHUNK))
        .zip(maxima.iter_mut())
    {
        let (mut mh, mut ml) = (0.0f64, 0.0f64);
        for ((hv, lv), &v) in hc.iter_mut().zip(lc.iter_mut()).zip(yc) {
            let (t, e) = two_sum(s, v - mu);
            s = t;
            c += e;
            // Fast2Sum (|c| ≪ |s| but where s crosses zero; there the pair is off by ≲ ε·|c|, far
            // below the phase's own error): hi = the phase rounded once
            let p = s + c;
            let q = c - (p - s);
            *hv = p;
            *lv = q;
            // plain compares (maxsd): the samples are finite, so NaN needs no care here
            mh = if p.abs() > mh { p.abs() } else { mh };
            ml = if q.abs() > ml { q.abs() } else { ml };
        }
        *mx = (mh, ml);
    }
}

/// Exclusive scan of blocks' double-word totals in double-word arithmetic (sequential, one step per
/// block): each block's offset, the phase at its first sample.
pub(crate) fn block_offsets(totals: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let mut offs = Vec::with_capacity(totals.len());
    let (mut oh, mut ol) = (0.0f64, 0.0f64);
    for &(s, c) in totals {
        offs.push((oh, ol));
        let (t, e) = two_sum(oh, s);
        let low = e + (ol + c);
        let h = t + low;
        ol = low - (h - t);
        oh = h;
    }
    offs
}

/// The centring value of one static window and its finite check, in one parallel pass: the mean
/// from the double-word total of fixed blocks (joined in block order, so the same bits for any
/// thread count). A sample that is NaN or ±inf makes the total non-finite and is then located.
pub(crate) fn centre(y: &[f64], axis: usize) -> crate::Result<f64> {
    let totals: Vec<(f64, f64)> = y
        .par_chunks(BLOCK)
        .map(|src| block_total_dispatch(src, 0.0))
        .collect();
    let (mut th, mut tl) = (0.0f64, 0.0f64);
    for &(s, c) in &totals {
        let (t, e) = two_sum(th, s);
        th = t;
        tl += e + c;
    }
    let total = th + tl;
    if !total.is_finite() {
        if let Some(index) = y.iter().position(|v| !v.is_finite()) {
            return Err(crate::CoreError::NonFinite {
                axis,
                index,
                value: y[index],
            });
        }
        // finite samples whose sum overflows: the sequential compensated mean, as elsewhere
        return Ok(crate::allan::compensated_mean(y));
    }
    Ok(total / y.len() as f64)
}

/// The phase of `y − μ` as hi[j] + lo[j], j = 0 … y.len() (hi, lo of length y.len() + 1; P_0 = 0),
/// each pair normalised (|lo| ≤ ½ ulp(hi)). Returns the largest |hi| and |lo| over the pairs
/// 1 + c·CHUNK ..= (c + 1)·CHUNK, c = 0, 1, … (see [`max_slot`]; P_0 = 0 needs none).
pub(crate) fn phase_prefix(y: &[f64], mu: f64, hi: &mut [f64], lo: &mut [f64]) -> Vec<(f64, f64)> {
    debug_assert!(hi.len() == y.len() + 1 && lo.len() == y.len() + 1);
    hi[0] = 0.0;
    lo[0] = 0.0;
    let totals: Vec<(f64, f64)> = y
        .par_chunks(BLOCK)
        .map(|src| block_total_dispatch(src, mu))
        .collect();
    let offs = block_offsets(&totals);
    let mut maxima = vec![(0.0f64, 0.0f64); y.len().div_ceil(CHUNK)];
    hi[1..]
        .par_chunks_mut(BLOCK)
        .zip(lo[1..].par_chunks_mut(BLOCK))
        .zip(y.par_chunks(BLOCK))
        .zip(offs.par_iter())
        .zip(maxima.par_chunks_mut(BLOCK / CHUNK))
        .for_each(|((((h, l), src), &(oh, ol)), mx)| block_phase(src, mu, oh, ol, h, l, mx));
    maxima
}

/// The slot of [`phase_prefix`]'s maxima that covers phase index j.
#[inline(always)]
pub(super) fn max_slot(j: usize) -> usize {
    j.saturating_sub(1) / CHUNK
}

/// Advises the kernel to back the 2 MiB-aligned interior of `v` with 2 MiB pages (Linux; advice only,
/// an error is ignored). For large fresh zeroed outputs: written once, they cost a page fault per 4 KiB
/// otherwise — a third of a hop-1 DAVAR's time (75 MB of output at N = 10⁵, window 10⁴). Call it before
/// the first write.
pub(crate) fn advise_huge_pages(v: &mut [f64]) {
    #[cfg(target_os = "linux")]
    {
        let addr = v.as_ptr() as usize;
        let start = addr.next_multiple_of(HUGE);
        let end = (addr + std::mem::size_of_val(v)) / HUGE * HUGE;
        if end > start {
            // SAFETY: [start, end) lies inside v's allocation and is 2 MiB aligned; MADV_HUGEPAGE
            // changes no contents.
            unsafe {
                libc::madvise(start as *mut libc::c_void, end - start, libc::MADV_HUGEPAGE);
            }
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = v;
}

/// A zeroed f64 buffer whose pages the kernel may back with 2 MiB pages: the phase of a long record
/// is 16 bytes per sample, and faulting it in 4 KiB pages cost more than building it (~80 ms of
/// ~100 ms at 10⁷ samples). The zeroed allocation is fresh memory (calloc maps it untouched), so the
/// advice lands before the first touch. Also the buffer of the Dask tasks' angles (`angle.rs`).
pub(crate) struct PhaseBuf {
    v: Vec<f64>,
    off: usize,
    len: usize,
}

const HUGE: usize = 2 << 20;

impl PhaseBuf {
    pub(crate) fn new(len: usize) -> Self {
        if len * 8 < HUGE {
            // a small phase: no 2 MiB padding, no advice (their syscalls would cost more than the faults)
            return PhaseBuf {
                v: vec![0.0f64; len],
                off: 0,
                len,
            };
        }
        let v = vec![0.0f64; len + HUGE / 8];
        let addr = v.as_ptr() as usize;
        let off = (addr.next_multiple_of(HUGE) - addr) / 8;
        #[cfg(target_os = "linux")]
        {
            let bytes = (len * 8) / HUGE * HUGE;
            if bytes > 0 {
                // SAFETY: the range [v + off, v + off + bytes) lies inside v's allocation and is
                // 2 MiB aligned; MADV_HUGEPAGE is advice only (an error is ignored: 4 KiB pages).
                unsafe {
                    libc::madvise(
                        v.as_ptr().add(off) as *mut libc::c_void,
                        bytes,
                        libc::MADV_HUGEPAGE,
                    );
                }
            }
        }
        PhaseBuf { v, off, len }
    }

    pub(crate) fn slice(&mut self) -> &mut [f64] {
        &mut self.v[self.off..self.off + self.len]
    }

    pub(crate) fn get(&self) -> &[f64] {
        &self.v[self.off..self.off + self.len]
    }
}

/// The phase of one axis for [`overlapping_dynamic_row`]: (hi, lo) of its first `n` samples.
///
/// [`overlapping_dynamic_row`]: super::dynamic::overlapping_dynamic_row
pub(crate) struct Phase {
    hi: PhaseBuf,
    lo: PhaseBuf,
}

impl Phase {
    pub(crate) fn new(y: &[f64], mu: f64) -> Self {
        let n = y.len();
        let mut hi = PhaseBuf::new(n + 1);
        let mut lo = PhaseBuf::new(n + 1);
        phase_prefix(y, mu, hi.slice(), lo.slice());
        Phase { hi, lo }
    }

    /// The phase of another `y` in the same buffers where they are long enough (no fresh pages).
    pub(crate) fn refill(&mut self, y: &[f64], mu: f64) {
        let n = y.len();
        let fits = |b: &PhaseBuf| b.off + n < b.v.len();
        if !(fits(&self.hi) && fits(&self.lo)) {
            *self = Phase::new(y, mu);
            return;
        }
        self.hi.len = n + 1;
        self.lo.len = n + 1;
        phase_prefix(y, mu, self.hi.slice(), self.lo.slice());
    }

    pub(crate) fn parts(&self) -> (&[f64], &[f64]) {
        (
            &self.hi.v[self.hi.off..self.hi.off + self.hi.len],
            &self.lo.v[self.lo.off..self.lo.off + self.lo.len],
        )
    }
}

#[cfg(test)]
mod tests {
    use super::super::noise;
    use super::*;

    #[test]
    fn the_phase_keeps_its_digits_after_a_loud_stretch() {
        // level ×10⁻⁶ after the first block and a half: the phase's block sums there stay exact
        let n = 3 * BLOCK;
        let mut y = noise(n, 9);
        for v in y[..n / 2].iter_mut() {
            *v *= 1e6;
        }
        let mut hi = vec![0.0; n + 1];
        let mut lo = vec![0.0; n + 1];
        phase_prefix(&y, 0.0, &mut hi, &mut lo);
        for (a, b) in [
            (n / 2 + 10, n / 2 + 11),
            (n - 100, n - 1),
            (2 * BLOCK - 3, 2 * BLOCK + 5),
        ] {
            let got = (hi[b] - hi[a]) + (lo[b] - lo[a]);
            let want: f64 = y[a..b].iter().sum();
            let scale: f64 = y[a..b].iter().map(|v| v.abs()).sum();
            assert!(
                (got - want).abs() <= 1e-14 * scale,
                "[{a}, {b}): {got} vs {want}"
            );
        }
    }
}

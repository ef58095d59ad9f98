//! The dynamic (sliding-window) overlapping Allan variance from the phase: the short-hop rows, the
//! tiled rows of hops ≥ `SMALL_HOP`, and the grid of phase segments.

use super::sums::chunk_sum_dispatch;
use super::{CHUNK, SHORT_M};
use crate::allan::block_window_sums;
use crate::cancel::Cancel;
use crate::range::Range;
use rayon::prelude::*;

/// Writes d_k²·scale for k = k0 … k0 + out.len() − 1 at factor m from the phase (the terms of the
/// short-hop path; d formed with the same operations as in `sums::chunk_sum`).
#[inline(always)]
fn terms_into(hi: &[f64], lo: &[f64], m: usize, k0: usize, scale: f64, out: &mut [f64]) {
    let len = out.len();
    let h0 = &hi[k0..k0 + len];
    let h1 = &hi[k0 + m..k0 + m + len];
    let h2 = &hi[k0 + 2 * m..k0 + 2 * m + len];
    let l0 = &lo[k0..k0 + len];
    let l1 = &lo[k0 + m..k0 + m + len];
    let l2 = &lo[k0 + 2 * m..k0 + 2 * m + len];
    for (i, o) in out.iter_mut().enumerate() {
        let dh = (h2[i] - h1[i]) - (h1[i] - h0[i]);
        let dl = (l2[i] - l1[i]) - (l1[i] - l0[i]);
        let d = dh + dl;
        *o = d * d * scale;
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn terms_into_avx2(
    hi: &[f64],
    lo: &[f64],
    m: usize,
    k0: usize,
    scale: f64,
    out: &mut [f64],
) {
    terms_into(hi, lo, m, k0, scale, out)
}

/// [`terms_into`] compiled for AVX2 where the CPU has it (`avx2`: checked by the caller, once per row).
#[inline(always)]
pub(crate) fn terms_dispatch(
    avx2: bool,
    hi: &[f64],
    lo: &[f64],
    m: usize,
    k0: usize,
    scale: f64,
    out: &mut [f64],
) {
    #[cfg(target_arch = "x86_64")]
    if avx2 {
        // SAFETY: the caller checked that the CPU has AVX2.
        unsafe { terms_into_avx2(hi, lo, m, k0, scale, out) };
        return;
    }
    let _ = avx2;
    terms_into(hi, lo, m, k0, scale, out)
}

/// Scratch of one worker of [`overlapping_dynamic_row`].
#[derive(Default)]
pub(crate) struct DynScratch {
    terms: Vec<f64>,
    full: Vec<f64>,
    part: Vec<f64>,
    sums: Vec<f64>,
}

/// Hops below this keep every term and cut blocks afterwards; longer hops sum each block directly.
pub(crate) const SMALL_HOP: usize = 64;

/// Overlapping Allan variance of every window `y[j·hop .. j·hop + window)`, j < out.len(), at factor m,
/// from the record's phase (hi, lo): the terms of window j are k = j·hop … j·hop + L − 1, L = window +
/// 1 − 2m. Each block of `hop` terms is summed once (first its r = L mod hop terms, then the rest), and
/// every window is the Van Herk sliding sum of q = ⌊L/hop⌋ whole blocks plus the next block's first r
/// terms — sums of non-negative values over the window's own terms only. Every d_k comes from the
/// phase as in [`overlapping_window`], so its rounding is local to its block sums. `one_window`: the
/// record has one window (its terms are one block); a run of windows of a longer record keeps the
/// record's blocks even when it holds one window, so its values do not depend on where it ends.
///
/// [`overlapping_window`]: super::sums::overlapping_window
#[allow(clippy::too_many_arguments)]
pub(crate) fn overlapping_dynamic_row(
    hi: &[f64],
    lo: &[f64],
    m: usize,
    window: usize,
    hop: usize,
    one_window: bool,
    out: &mut [f64],
    sc: &mut DynScratch,
) -> Range {
    #[cfg(target_arch = "x86_64")]
    let avx2 = std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    let avx2 = false;
    let n_win = out.len();
    let l = window + 1 - 2 * m;
    let hop = if one_window { l } else { hop };
    let (q, r) = (l / hop, l % hop);
    let k_end = (n_win - 1) * hop + l;
    let nblocks = n_win + q;
    let norm = 1.0 / (2.0 * (m as f64) * (m as f64) * l as f64);
    if hop == 1 {
        // terms formed segment by segment, each window written once (`crate::window_sums`)
        return crate::window_sums::hop1_row(hi, lo, m, q, norm, avx2, out, &mut sc.sums);
    }
    let blocks = RowBlocks {
        hop,
        r,
        k_end,
        nblocks,
        norm,
    };
    blocks.form(hi, lo, m, avx2, sc);
    let DynScratch {
        full, part, sums, ..
    } = sc;
    if q == 0 {
        out.copy_from_slice(&part[..n_win]);
        // noted while the row is in cache: the caller's range check then reads nothing again
        Range::of(out)
    } else {
        // each window written once, its range noted as it is written
        let head = (r != 0).then(|| &part[q..]);
        crate::window_sums::sliding_sums_ranged(full, q, head, out, sums)
    }
}

/// How the terms of an [`overlapping_dynamic_row`] fall into blocks: `hop` (≥ 2) terms per block,
/// `k_end` terms in all, `nblocks` blocks, each window's terms L = q·hop + r, each term scaled by `norm`.
struct RowBlocks {
    hop: usize,
    r: usize,
    k_end: usize,
    nblocks: usize,
    norm: f64,
}

impl RowBlocks {
    /// The block sums into `sc.full` (a block's terms) and `sc.part` (its first r terms): below
    /// `SMALL_HOP` from every term formed first, else each block summed directly from the phase.
    fn form(&self, hi: &[f64], lo: &[f64], m: usize, avx2: bool, sc: &mut DynScratch) {
        let RowBlocks {
            hop,
            r,
            k_end,
            nblocks,
            norm,
        } = *self;
        let DynScratch {
            terms, full, part, ..
        } = sc;
        full.clear();
        full.resize(nblocks, 0.0);
        part.clear();
        part.resize(nblocks, 0.0);
        if hop < SMALL_HOP {
            // every term is written below: the buffer is only sized (no fill of what it already holds)
            terms.resize(k_end, 0.0);
            #[cfg(target_arch = "x86_64")]
            if avx2 {
                // SAFETY: the CPU has AVX2 (checked by the caller).
                unsafe { terms_into_avx2(hi, lo, m, 0, norm, terms) };
            } else {
                terms_into(hi, lo, m, 0, norm, terms);
            }
            #[cfg(not(target_arch = "x86_64"))]
            terms_into(hi, lo, m, 0, norm, terms);
            for (b, blk) in terms.chunks(hop).enumerate() {
                full[b] = crate::allan::sum4(blk);
                part[b] = crate::allan::sum4(&blk[..r.min(blk.len())]);
            }
        } else {
            for b in 0..nblocks {
                let k0 = b * hop;
                if k0 >= k_end {
                    break;
                }
                let len = hop.min(k_end - k0);
                let rr = r.min(len);
                let p = chunk_sum_dispatch::<true>(avx2, hi, lo, m, k0, rr);
                let rest = chunk_sum_dispatch::<true>(avx2, hi, lo, m, k0 + rr, len - rr);
                part[b] = p * norm;
                full[b] = (p + rest) * norm;
            }
        }
    }
}

/// [`overlapping_dynamic_row`] for every m of `ms` at once, for hops ≥ `SMALL_HOP`: the block sums
/// (part: a block's first r_m terms, full: all its terms) are formed tile by tile — a tile is a run of
/// whole blocks, ≈ `CHUNK` terms or one block — and within a tile every m with m ≤ `SHORT_M` reads
/// the tile's phase from cache (the three reads at k, k + m, k + 2m land in the same few lines for
/// every such m), as `sums::super_chunk` does for the static estimator. Tiles run in parallel; each
/// (m, block) sum is one sequential routine, so the bits do not depend on the thread count. Writes
/// the `n_win` windows into `out` laid out [m][stride], at `first .. first + n_win` of each row.
#[allow(clippy::too_many_arguments)]
pub(crate) fn overlapping_dynamic_tiled(
    hi: &[f64],
    lo: &[f64],
    ms: &[usize],
    window: usize,
    hop: usize,
    out: &mut [f64],
    (stride, first, n_win): (usize, usize, usize),
    cancel: &Cancel,
) {
    #[cfg(target_arch = "x86_64")]
    let avx2 = std::arch::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    let avx2 = false;
    let n_m = ms.len();
    debug_assert!(n_win >= 2 && hop >= SMALL_HOP && first + n_win <= stride);
    debug_assert_eq!(out.len(), n_m * stride);
    let geo: Vec<(usize, usize, usize, usize)> = ms
        .iter()
        .map(|&m| {
            let l = window + 1 - 2 * m;
            (l / hop, l % hop, (n_win - 1) * hop + l, m) // (q, r, k_end, m)
        })
        .collect();
    let nblocks = geo.iter().map(|g| n_win + g.0).max().unwrap_or(0);
    let tile_blocks = (CHUNK / hop).max(1);
    let n_tiles = nblocks.div_ceil(tile_blocks);
    // [tile][m][block in tile] → (part, full)
    let mut sums = vec![(0.0f64, 0.0f64); n_tiles * n_m * tile_blocks];
    sums.par_chunks_mut(n_m * tile_blocks)
        .enumerate()
        .for_each(|(tile, dst)| {
            if cancel.is_cancelled() {
                return;
            }
            let one = |t: usize, bi: usize| -> (f64, f64) {
                let (_q, r, k_end, m) = geo[t];
                let k0 = (tile * tile_blocks + bi) * hop;
                if k0 >= k_end {
                    return (0.0, 0.0);
                }
                let len = hop.min(k_end - k0);
                let rr = r.min(len);
                let p = chunk_sum_dispatch::<true>(avx2, hi, lo, m, k0, rr);
                let rest = chunk_sum_dispatch::<true>(avx2, hi, lo, m, k0 + rr, len - rr);
                (p, p + rest)
            };
            // short m block by block (the tile's phase in cache for all of them), long m m by m
            for bi in 0..tile_blocks {
                for t in (0..n_m).filter(|&t| ms[t] <= SHORT_M) {
                    dst[t * tile_blocks + bi] = one(t, bi);
                }
            }
            for t in (0..n_m).filter(|&t| ms[t] > SHORT_M) {
                for bi in 0..tile_blocks {
                    dst[t * tile_blocks + bi] = one(t, bi);
                }
            }
        });
    if cancel.is_cancelled() {
        return;
    }
    out.par_chunks_mut(stride).enumerate().for_each(|(t, row)| {
        let row = &mut row[first..first + n_win];
        let (q, r, _k_end, m) = geo[t];
        let l = window + 1 - 2 * m;
        let norm = 1.0 / (2.0 * (m as f64) * (m as f64) * l as f64);
        let nb = n_win + q;
        let block = |b: usize| sums[((b / tile_blocks) * n_m + t) * tile_blocks + b % tile_blocks];
        let part: Vec<f64> = (0..nb).map(|b| block(b).0 * norm).collect();
        let full: Vec<f64> = (0..nb).map(|b| block(b).1 * norm).collect();
        block_window_sums(&full, &part, (q, r), (0, n_win), row);
    });
}

/// Fewest samples a phase segment spans (see [`segment_windows`]): 2^22, 64 MiB of phase.
#[cfg(not(test))]
const SEGMENT_SPAN: usize = 1 << 22;
/// The unit tests' segments are short, so small records cross several.
#[cfg(test)]
const SEGMENT_SPAN: usize = 1 << 12;

/// Records of at most this many samples × axes (the windows' samples) are *short*: 2^26, 512 MiB of
/// float64. A short record's segments span 16 windows' worth (≤ 1/16 of the work rebuilt where two
/// segments overlap) and it takes the phase path at any window.
#[cfg(not(test))]
pub(crate) const PHASE_RECORD_MAX: usize = 1 << 26;
#[cfg(test)]
pub(crate) const PHASE_RECORD_MAX: usize = 1 << 14;

/// A long record's segments span 4 windows' worth (≤ 1/3 rebuilt), so that a Dask task that holds whole
/// segments stays small, and it takes the phase path while a segment spans at most this many samples:
/// 2^23 (128 MiB of phase; windows up to 2^21 samples). Longer windows build the phase chunk by chunk
/// of their terms (`crate::chunked`, hops ≥ 64) or stream their sums in O(window) per worker.
#[cfg(not(test))]
pub(crate) const PHASE_SPAN_MAX: usize = 1 << 23;
#[cfg(test)]
pub(crate) const PHASE_SPAN_MAX: usize = 1 << 13;

/// Samples a phase segment spans at most: max(2^22, 16 · window) on a short record, max(2^22, 4 · window)
/// on a long one (see [`PHASE_RECORD_MAX`]).
pub(crate) fn segment_span(window: usize, long_record: bool) -> usize {
    SEGMENT_SPAN.max(window.saturating_mul(if long_record { 4 } else { 16 }))
}

/// Windows per phase segment. The dynamic estimator's phase path cuts a record's windows into runs
/// of this many (the record's windows 0 .. K, K .. 2K, …: a grid that depends on the record's length
/// only through whether it is long, and not on the thread count) and builds each run's double-word
/// phase from the run's first sample, so it holds 16 bytes per sample of one segment — at most
/// [`segment_span`] samples — instead of 16 per sample of the record. A part of the record that starts
/// on this grid has its segments' phases bit for bit.
pub fn segment_windows(window: usize, hop: usize, long_record: bool) -> usize {
    (segment_span(window, long_record).saturating_sub(window) / hop.max(1)).saturating_add(1)
}

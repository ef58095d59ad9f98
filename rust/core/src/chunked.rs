//! The overlapping Allan variance of a long record from its phase, one chunk of terms at a time.
//!
//! A record over 2^26 samples × axes cannot hold its double-word phase (16 bytes a sample) whole, and
//! the phase path's segments (`crate::oavar::segment_windows`) must each hold whole windows: with
//! windows over 2^21 samples they would grow past 2^23 samples. Such records used to stream their block
//! sums instead (Van Herk per m, [`crate::allan::for_each_term_chunk_at`]): five passes over m-sized
//! scratch per m, about 2.7 ns per term against the phase path's 1.0 at 10⁸ samples.
//!
//! Here the terms d_m(k) = X(k+2m) − 2X(k+m) + X(k) come from the phase as on the phase path, but the
//! phase is built chunk by chunk: the terms k of chunk c (record indices c·C … (c+1)·C − 1) read the
//! double-word phase of y − μ from the chunk's first sample to its last term's k + 2m. Only the phase is
//! rebuilt where chunks overlap (2·m_max samples, one cheap pass shared by every m); every term is formed
//! once. The chunk length C is a multiple of the hop, so the hop blocks of the sliding sums never
//! straddle two chunks: each block's sums (its first r terms, all its terms) are formed as on the phase
//! path ([`crate::oavar::chunk_sum_dispatch`], double words), and every window is the Van Herk sum of its
//! blocks as on the streaming path ([`crate::allan::sliding_sums_at`]) — sums of non-negative values.
//!
//! Memory: one chunk's phase, 16 bytes × (C + 2·m_max) ≤ 16 × (2·max(2^22, window) + hop), and per m
//! the block sums of the part's windows (two values a window, as the phase path's tiles).
//!
//! A part of the record that starts on the chunk grid (`part_grid`: C) has the record's chunks, phases
//! and block sums: bit for bit; one that starts inside a chunk builds its first phase from its own
//! start: the same terms from differently rounded phase values (a few ε).
//!
//! The static estimator (one window, the whole record) takes the same chunks of `CHUNK_TERMS` terms for
//! m ≤ `CHUNK_TERMS`/2, each chunk's Σ d² summed in runs of `RUN_TERMS`; longer m stream as before.

use crate::allan::{overlapping_row_at, sliding_sums, sliding_sums_at, Part, RowScratch};
use crate::cancel::Cancel;
use crate::oavar::{chunk_sum_dispatch, Phase};
use crate::range::Range;
use rayon::prelude::*;

/// Terms per chunk at least: 2^22 (64 MiB of phase, the phase path's shortest segment).
#[cfg(not(test))]
pub(crate) const CHUNK_TERMS: usize = 1 << 22;
/// The unit tests' chunks are short, so small records cross several.
#[cfg(test)]
pub(crate) const CHUNK_TERMS: usize = 1 << 9;

/// Terms summed by one double-word [`chunk_sum_dispatch`] call (the runs then added in order): the
/// rounding of a block's sum grows with this, not with the block. Within a run every m ≤ `SHORT_M`
/// reads the run's phase from cache (their reads at k, k + m, k + 2m share its lines); longer m go
/// m by m, so that only a few streams are in flight at a time.
#[cfg(not(test))]
const RUN_TERMS: usize = 1 << 13;
/// The unit tests' runs are short, so their m cross from short to long.
#[cfg(test)]
const RUN_TERMS: usize = 1 << 6;
const SHORT_M: usize = RUN_TERMS / 2;

/// Σ d² over the terms `k0 .. k1` (phase indices) at m, in runs of `RUN_TERMS` from `k0`, added in
/// order.
#[inline]
fn run_sums(avx2: bool, hi: &[f64], lo: &[f64], m: usize, k0: usize, k1: usize) -> f64 {
    let mut s = 0.0;
    let mut k = k0;
    while k < k1 {
        let len = RUN_TERMS.min(k1 - k);
        s += chunk_sum_dispatch::<true>(avx2, hi, lo, m, k, len);
        k += len;
    }
    s
}

/// The (head, full) sums of hop block `k0 ..` (record indices) at every m of `geo`, into `dst`
/// ([m]), from the phase (hi, lo) whose index 0 is the record's `p0`: short m run by run (see
/// `RUN_TERMS`), long m one after another; the same runs either way.
fn block_sums(
    avx2: bool,
    (hi, lo, p0): (&[f64], &[f64], usize),
    geo: &[Geo],
    k0: usize,
    hop: usize,
    dst: &mut [(f64, f64)],
) {
    // per m: the block's head terms k0 .. k0 + rr and its rest .. k0 + len (empty past the part's terms)
    let span = |g: &Geo| {
        let len = hop.min(g.k_lim.saturating_sub(k0));
        (g.r.min(len), len)
    };
    for (g, d) in geo.iter().zip(dst.iter_mut()) {
        *d = (0.0, 0.0);
        if g.m > SHORT_M {
            let (rr, len) = span(g);
            let i0 = k0 - p0;
            let head = run_sums(avx2, hi, lo, g.m, i0, i0 + rr);
            *d = (head, run_sums(avx2, hi, lo, g.m, i0 + rr, i0 + len));
        }
    }
    // short m: every such m's runs that start in [pos, pos + RUN_TERMS), in each m's order
    let longest = geo
        .iter()
        .filter(|g| g.m <= SHORT_M)
        .map(|g| span(g).1)
        .max();
    let i0 = k0 - p0;
    let mut pos = 0;
    while pos < longest.unwrap_or(0) {
        for (g, d) in geo
            .iter()
            .zip(dst.iter_mut())
            .filter(|(g, _)| g.m <= SHORT_M)
        {
            let (rr, len) = span(g);
            if pos < rr {
                let e = (pos + RUN_TERMS).min(rr);
                d.0 += chunk_sum_dispatch::<true>(avx2, hi, lo, g.m, i0 + pos, e - pos);
            }
            // the rest's runs start at rr + j·RUN_TERMS: the one in [pos, pos + RUN_TERMS), if any
            let st = if pos > rr {
                rr + (pos - rr).div_ceil(RUN_TERMS) * RUN_TERMS
            } else {
                rr
            };
            if st < len && st < pos + RUN_TERMS {
                let e = (st + RUN_TERMS).min(len);
                d.1 += chunk_sum_dispatch::<true>(avx2, hi, lo, g.m, i0 + st, e - st);
            }
        }
        pos += RUN_TERMS;
    }
}

/// Terms per parallel block of the static estimator's chunks (a divisor of `CHUNK_TERMS`).
const STATIC_BLOCK: usize = if CHUNK_TERMS > 1 << 16 {
    1 << 16
} else {
    CHUNK_TERMS / 4
};

/// The chunk length of a dynamic call with several windows: max(`CHUNK_TERMS`, window) rounded up to a
/// multiple of the hop (a chunk holds whole hop blocks, and its phase spans at most two windows' worth
/// more than its terms).
pub fn chunk_len(window: usize, hop: usize) -> usize {
    let hop = hop.max(1);
    CHUNK_TERMS.max(window).div_ceil(hop) * hop
}

#[cfg(target_arch = "x86_64")]
fn has_avx2() -> bool {
    std::arch::is_x86_feature_detected!("avx2")
}
#[cfg(not(target_arch = "x86_64"))]
fn has_avx2() -> bool {
    false
}

/// The phase of the record's samples `p0 .. p1` (record indices; `y[i]` is the record's sample
/// `off + i`), centred on `mu`, in `ph`'s buffers where they are long enough.
fn phase_of(ph: &mut Option<Phase>, y: &[f64], off: usize, p0: usize, p1: usize, mu: f64) {
    let ys = &y[p0 - off..p1 - off];
    match ph {
        Some(p) => p.refill(ys, mu),
        None => *ph = Some(Phase::new(ys, mu)),
    }
}

/// Geometry of one m's row: (m, q, r, the part's term limit, normalisation).
struct Geo {
    m: usize,
    q: usize,
    r: usize,
    k_lim: usize,
    norm: f64,
}

/// Overlapping Allan variance of the windows `part` of a record at every m of `ms`, into `out` laid out
/// [m][window] (this axis): the record's samples from `part.first · hop` are `y`, its centring value
/// `mu`. Several windows need `hop ≥ 1` whole blocks per chunk (any hop works; the caller sends hops ≥
/// 64, where blocks are summed directly); one window (`part.total == 1`) is the static estimator. Once
/// `cancel` is set `out` holds garbage (the caller returns `Cancelled`). Returns each row's range.
#[allow(clippy::too_many_arguments)]
pub(crate) fn overlapping_rows(
    y: &[f64],
    part: Part,
    mu: f64,
    ms: &[usize],
    window: usize,
    hop: usize,
    out: &mut [f64],
    cancel: &Cancel,
) -> Vec<Range> {
    if part.total == 1 {
        return static_rows(y, mu, ms, window, out, cancel);
    }
    let n_win = out.len() / ms.len();
    let off = part.first * hop;
    let geo: Vec<Geo> = ms
        .iter()
        .map(|&m| {
            let l = window + 1 - 2 * m;
            let k_end = (part.total - 1) * hop + l; // the record's terms
            Geo {
                m,
                q: l / hop,
                r: l % hop,
                k_lim: k_end.min(off + (n_win - 1) * hop + l), // this part's
                norm: 1.0 / (2.0 * (m as f64) * (m as f64) * l as f64),
            }
        })
        .collect();
    // per m: (full, head) sums of the part's blocks part.first + b, b < n_win + q
    let mut blocks: Vec<(Vec<f64>, Vec<f64>)> = geo
        .iter()
        .map(|g| (vec![0.0; n_win + g.q], vec![0.0; n_win + g.q]))
        .collect();
    let k_hi = geo.iter().map(|g| g.k_lim).max().unwrap_or(off);
    let n_blocks = blocks.iter().map(|b| b.0.len()).max().unwrap_or(0);
    let n_m = ms.len();
    let m_max = ms.iter().copied().max().unwrap_or(1);
    let c_len = chunk_len(window, hop);
    let avx2 = has_avx2();
    let mut cs = off / c_len * c_len;
    let mut ph = None;
    while cs < k_hi {
        if cancel.is_cancelled() {
            return Vec::new();
        }
        let ce = cs + c_len;
        // the phase from the chunk's first term (the part's first on a chunk it starts inside) to the
        // samples its last term reads
        let p0 = cs.max(off);
        let p1 = (ce.min(k_hi) + 2 * m_max - 1).min(off + y.len());
        phase_of(&mut ph, y, off, p0, p1, mu);
        let (hi, lo) = ph.as_ref().map_or((&[][..], &[][..]), Phase::parts);
        // blocks whose terms start in [p0, ce): p0 and ce are multiples of the hop
        let b_lo = p0 / hop - part.first;
        let b_hi = (ce / hop - part.first).min(n_blocks);
        let mut tmp = vec![(0.0f64, 0.0f64); (b_hi - b_lo) * n_m];
        tmp.par_chunks_mut(n_m).enumerate().for_each(|(i, dst)| {
            let k0 = (part.first + b_lo + i) * hop;
            block_sums(avx2, (hi, lo, p0), &geo, k0, hop, dst);
        });
        for (t, ((full, head), g)) in blocks.iter_mut().zip(&geo).enumerate() {
            for b in b_lo..b_hi.min(full.len()) {
                let (p, rest) = tmp[(b - b_lo) * n_m + t];
                head[b] = p * g.norm;
                full[b] = (p + rest) * g.norm;
            }
        }
        cs = ce;
    }
    if cancel.is_cancelled() {
        return Vec::new();
    }
    window_sums(&blocks, &geo, part, out)
}

/// Every window of the part from its rows' block sums (`blocks`: (full, head) per m): the Van Herk sum
/// of its q whole blocks plus the next block's head, as the streaming rows form it; each row's range.
fn window_sums(
    blocks: &[(Vec<f64>, Vec<f64>)],
    geo: &[Geo],
    part: Part,
    out: &mut [f64],
) -> Vec<Range> {
    let n_win = out.len() / geo.len();
    out.par_chunks_mut(n_win)
        .zip(blocks.par_iter())
        .zip(geo.par_iter())
        .map(|((dst, (full, head)), g)| {
            if g.q == 0 {
                dst.copy_from_slice(&head[..n_win]);
            } else {
                if part.first == 0 && n_win == part.total {
                    sliding_sums(full, g.q, dst);
                } else {
                    sliding_sums_at(full, g.q, part.first, part.total, dst);
                }
                if g.r != 0 {
                    for (o, p) in dst.iter_mut().zip(&head[g.q..]) {
                        *o += p;
                    }
                }
            }
            Range::of(dst)
        })
        .collect()
}

/// The static estimator of the record `y[..window]` at every m: m ≤ `CHUNK_TERMS`/2 from chunked
/// phases (each chunk's Σ d² in runs of `RUN_TERMS`, the chunks' sums added in order), longer m by the
/// streaming rows. `out`: one value per m.
fn static_rows(
    y: &[f64],
    mu: f64,
    ms: &[usize],
    window: usize,
    out: &mut [f64],
    cancel: &Cancel,
) -> Vec<Range> {
    let short = |m: usize| 2 * m <= CHUNK_TERMS;
    let m_max = ms.iter().copied().filter(|&m| short(m)).max();
    // the chunked m (no head: r = 0) and their sums
    let geo: Vec<Geo> = ms
        .iter()
        .filter(|&&m| short(m))
        .map(|&m| Geo {
            m,
            q: 0,
            r: 0,
            k_lim: window + 1 - 2 * m,
            norm: 1.0,
        })
        .collect();
    let mut sums = vec![0.0f64; geo.len()];
    if let Some(m_max) = m_max {
        let k_hi = window + 1 - 2 * ms.iter().copied().filter(|&m| short(m)).min().unwrap_or(1);
        let avx2 = has_avx2();
        let mut cs = 0;
        let mut ph = None;
        while cs < k_hi {
            if cancel.is_cancelled() {
                return Vec::new();
            }
            let ce = cs + CHUNK_TERMS;
            let p1 = (ce.min(k_hi) + 2 * m_max - 1).min(window);
            phase_of(&mut ph, y, 0, cs, p1, mu);
            let (hi, lo) = ph.as_ref().map_or((&[][..], &[][..]), Phase::parts);
            // the chunk's terms in blocks of STATIC_BLOCK, in parallel; each m's block sums added in order
            let nb = (ce.min(k_hi) - cs).div_ceil(STATIC_BLOCK);
            let mut tmp = vec![(0.0f64, 0.0f64); nb * geo.len()];
            tmp.par_chunks_mut(geo.len())
                .enumerate()
                .for_each(|(i, dst)| {
                    let k0 = cs + i * STATIC_BLOCK;
                    block_sums(avx2, (hi, lo, cs), &geo, k0, STATIC_BLOCK, dst);
                });
            for (t, s) in sums.iter_mut().enumerate() {
                for i in 0..nb {
                    *s += tmp[i * geo.len() + t].1;
                }
            }
            cs = ce;
        }
    }
    finish_static(y, mu, ms, window, &sums, out, cancel)
}

/// The static values from the chunked m's sums (`sums`, in the order of the chunked m of `ms`), the
/// other m streamed; each value's range.
fn finish_static(
    y: &[f64],
    mu: f64,
    ms: &[usize],
    window: usize,
    sums: &[f64],
    out: &mut [f64],
    cancel: &Cancel,
) -> Vec<Range> {
    let short = |m: usize| 2 * m <= CHUNK_TERMS;
    let mut chunked = sums.iter();
    let sums: Vec<f64> = ms
        .iter()
        .map(|&m| {
            if short(m) {
                *chunked.next().unwrap_or(&0.0)
            } else {
                0.0
            }
        })
        .collect();
    out.par_iter_mut()
        .zip(ms)
        .zip(&sums)
        .map_init(RowScratch::default, |sc, ((o, &m), &s)| {
            if cancel.is_cancelled() {
                return Range::default();
            }
            if short(m) {
                let l = window + 1 - 2 * m;
                *o = s / (2.0 * (m as f64) * (m as f64) * l as f64);
            } else {
                let part = Part { first: 0, total: 1 };
                overlapping_row_at(
                    y,
                    part,
                    mu,
                    m,
                    window,
                    window,
                    std::slice::from_mut(o),
                    sc,
                    cancel,
                );
            }
            Range::of(std::slice::from_ref(o))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::allan::{compensated_mean, dynamic_avar, Estimator, Method, Request};
    use allanite_testutil::Lcg;

    /// White noise on a large offset whose level drops ×10⁴ after the first third (a loud stretch
    /// then a quiet one: what a global running sum would lose), and a slow random walk.
    fn record(n: usize, seed: u64) -> Vec<f64> {
        let mut g = Lcg::new(seed.wrapping_mul(Lcg::MUL).wrapping_add(7));
        let mut walk = 0.0;
        (0..n)
            .map(|i| {
                let u = g.next_centered();
                walk += 1e-6 * u;
                7000.0 + walk + u * if i < n / 3 { 1.0 } else { 1e-4 }
            })
            .collect()
    }

    /// The streaming rows of the same request (the path long windows took before).
    fn streamed(
        y: &[f64],
        part: Part,
        mu: f64,
        ms: &[usize],
        window: usize,
        hop: usize,
    ) -> Vec<f64> {
        let n_win = if part.total == 1 {
            1
        } else {
            ((y.len() - window) / hop + 1).min(part.total - part.first)
        };
        let mut out = vec![0.0; ms.len() * n_win];
        let mut sc = RowScratch::default();
        for (row, &m) in out.chunks_mut(n_win).zip(ms) {
            overlapping_row_at(y, part, mu, m, window, hop, row, &mut sc, &Cancel::new());
        }
        out
    }

    fn worst(a: &[f64], b: &[f64]) -> f64 {
        assert_eq!(a.len(), b.len());
        a.iter()
            .zip(b)
            .map(|(x, y)| (x / y - 1.0).abs())
            .fold(0.0, f64::max)
    }

    #[test]
    fn chunked_rows_match_the_streaming_rows() {
        // chunks of max(2^9, window) terms rounded to the hop: hops that divide it and not, a hop
        // longer than the window's terms (q = 0), one longer than a chunk
        let n = 9001;
        let y = record(n, 3);
        let mu = compensated_mean(&y);
        for (window, hop) in [(300, 64), (1000, 65), (700, 100), (2000, 333), (400, 900)] {
            let ms: Vec<usize> = [1, 2, 7, 9, 64, 150, window / 2]
                .into_iter()
                .filter(|&m| m <= window / 2)
                .collect();
            let total = (n - window) / hop + 1;
            let part = Part { first: 0, total };
            let mut got = vec![0.0; ms.len() * total];
            let ranges = overlapping_rows(&y, part, mu, &ms, window, hop, &mut got, &Cancel::new());
            assert_eq!(ranges.len(), ms.len());
            let want = streamed(&y, part, mu, &ms, window, hop);
            let w = worst(&got, &want);
            assert!(w < 1e-12, "window {window} hop {hop}: {w:e}");
            for (r, row) in ranges.iter().zip(got.chunks(total)) {
                assert_eq!(*r, Range::of(row));
            }
        }
    }

    #[test]
    fn the_static_estimator_from_chunks_matches_the_phase_path() {
        // m ≤ 2^8 from chunks of 2^9 terms, longer m streamed; the whole record's own phase as reference
        let n = 5000;
        let y = record(n, 11);
        let mu = compensated_mean(&y);
        let ms = [1, 3, 8, 9, 100, 256, 257, 1000, 2500];
        let part = Part { first: 0, total: 1 };
        let mut got = vec![0.0; ms.len()];
        overlapping_rows(&y, part, mu, &ms, n, n, &mut got, &Cancel::new());
        let mut want = vec![0.0; ms.len()];
        crate::oavar::overlapping_window(&[&y], &[mu], &ms, n, &mut want, &Cancel::new());
        let w = worst(&got, &want);
        assert!(w < 1e-12, "{w:e}");
        // and the streaming rows give the same to rounding
        let s = streamed(&y, part, mu, &ms, n, n);
        assert!(worst(&got, &s) < 1e-12);
    }

    #[test]
    fn a_long_record_with_long_windows_takes_chunks_and_matches_a_short_ones_phase_path() {
        // the unit tests' long record: over 2^14 samples × axes; windows over 2^11 leave the phase path
        let n = 20_000;
        let y = record(n, 5);
        let (window, hop) = (2600, 130);
        let ms = [1, 4, 33, 500, 1300];
        let cols = [y.as_slice()];
        let req = Request::overlapping(&cols, window, hop, &ms);
        let (got, n_win) = dynamic_avar(&req).unwrap();
        assert_eq!(
            crate::allan::part_grid(n, 1, window, hop, Estimator::Overlapping, Method::Fast),
            Some(chunk_len(window, hop))
        );
        // each window on its own is a short record: the phase path of one window
        for j in (0..n_win).step_by(7) {
            let w = &y[j * hop..j * hop + window];
            let one = [w];
            let short = Request {
                columns: &one,
                window,
                hop: 1,
                ..req
            };
            let (want, _) = dynamic_avar(&short).unwrap();
            for (t, v) in want.iter().enumerate() {
                let g = got[t * n_win + j];
                // the window's own mean against the record's: a few ε of the terms
                assert!((g / v - 1.0).abs() < 1e-12, "j {j} m {}: {g} vs {v}", ms[t]);
            }
        }
    }
}

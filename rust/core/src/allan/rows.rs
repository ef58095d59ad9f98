//! One (axis, m) row of the dynamic estimators: the overlapping and the classic Allan variance of the
//! windows of a part of a record (the record's values, bit for bit), and one window recomputed from
//! scratch (the naive method, paper 000's DAVAR step).

use super::{block_window_sums, for_each_term_chunk_at, sum4, RUN, SMALL_HOP};
use crate::cancel::Cancel;

/// Short-hop DAVAR rows take their terms from the double-word phase up to this m; beyond, the three
/// phase streams at k, k + m, k + 2m (48 bytes per term) no longer share cache lines, and the
/// streaming block sums read fewer bytes per term. (Measured at N = 10⁷, window 10⁶, hop 1, 45 τ, one
/// worker: 8.9–17 s against 9.1–12 s for the former all-streaming path — memory-bound either way, the
/// kernel zeroing 3 GB of fresh output pages is the largest single cost.)
pub(super) const PHASE_M_MAX: usize = 8192;

/// Reusable buffers of one worker, so that rows do not pay fresh allocations (page faults).
#[derive(Default)]
pub(crate) struct RowScratch {
    terms: Vec<f64>,
    full: Vec<f64>,
    part: Vec<f64>,
}

/// The windows of a record that one call computes: windows `first .. first + out.len()` of the
/// record's `total`, from samples that start at the record's sample `first · hop`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Part {
    pub(crate) first: usize,
    pub(crate) total: usize,
}

impl Part {
    /// The whole record: every one of its `n_win` windows.
    pub(super) fn whole(n_win: usize) -> Self {
        Part {
            first: 0,
            total: n_win,
        }
    }
}

/// Overlapping Allan variance of the windows `part` of a record, for one m, written to `out` (length: the
/// part's windows), from `y` = the record's samples from `part.first · hop` on: the values the
/// whole-record call gives them, bit for bit (the same terms, block sums and window sums, see
/// [`for_each_term_chunk_at`] and [`sliding_sums_at`]). Once `cancel` is set, `out` holds garbage
/// (the caller returns `Cancelled` instead).
#[allow(clippy::too_many_arguments)]
pub(crate) fn overlapping_row_at(
    y: &[f64],
    part: Part,
    mu: f64,
    m: usize,
    window: usize,
    hop: usize,
    out: &mut [f64],
    sc: &mut RowScratch,
    cancel: &Cancel,
) {
    let n_win = out.len();
    let l = window + 1 - 2 * m;
    // With one window any block size works; a whole-window block keeps memory O(1).
    let hop = if part.total == 1 { l } else { hop };
    let (q, r) = (l / hop, l % hop);
    let off = part.first * hop; // the record's index of y[0] and of this part's first term
    let k_end = (part.total - 1) * hop + l; // the record's terms
    let k_hi = off + (n_win - 1) * hop + l; // this part's
    let nblocks = n_win + q;
    let norm = 1.0 / (2.0 * (m as f64) * (m as f64) * l as f64);
    let RowScratch {
        terms,
        full,
        part: head,
    } = sc;
    full.clear();
    full.resize(nblocks, 0.0);
    head.clear();
    head.resize(nblocks, 0.0);
    let range = (off, k_hi);
    if hop <= SMALL_HOP {
        // Short blocks: per-block bookkeeping would cost more than the arithmetic, so keep the
        // terms and cut them afterwards (the output is already ~k_end/hop values per m).
        terms.clear();
        for_each_term_chunk_at(y, off, mu, m, range, k_end, norm, cancel, |chunk| {
            terms.extend_from_slice(chunk)
        });
        if hop == 1 {
            std::mem::swap(terms, full);
        } else {
            for (b, blk) in terms.chunks(hop).enumerate() {
                full[b] = sum4(blk);
                head[b] = sum4(&blk[..r.min(blk.len())]);
            }
        }
    } else {
        let (mut b, mut pos, mut total) = (0usize, 0usize, 0.0f64);
        for_each_term_chunk_at(y, off, mu, m, range, k_end, norm, cancel, |chunk| {
            let mut i = 0;
            while i < chunk.len() {
                let target = if pos < r { r } else { hop };
                let n = (target - pos).min(chunk.len() - i).min(RUN);
                total += sum4(&chunk[i..i + n]);
                pos += n;
                i += n;
                if pos == r {
                    head[b] = total;
                }
                if pos == hop {
                    full[b] = total;
                    b += 1;
                    pos = 0;
                    total = 0.0;
                }
            }
        });
    }
    if cancel.is_cancelled() {
        return;
    }
    // The terms already carry the normalisation, so the window sums are the variances.
    block_window_sums(full, head, (q, r), (part.first, part.total), out);
}

/// Classic (non-overlapping) Allan variance of the windows `part` of a record, for one m: clusters
/// start at the window's first sample, so window j uses the terms a(s + i·m), i = 0 … K−2, s = j·hop;
/// `y` = the record's samples from `part.first · hop` on. Bit for bit the whole-record values (the same
/// terms; each window's sum is formed from its own terms in the same order).
#[allow(clippy::too_many_arguments)]
pub(super) fn classic_row_at(
    y: &[f64],
    part: Part,
    mu: f64,
    m: usize,
    window: usize,
    hop: usize,
    out: &mut [f64],
    cancel: &Cancel,
) {
    let n_win = out.len();
    let k = window / m;
    let terms = k - 1;
    let k_end = (part.total - 1) * hop + (terms - 1) * m + 1;
    let off = part.first * hop;
    let range = (off, off + (n_win - 1) * hop + (terms - 1) * m + 1);
    let norm = 1.0 / (2.0 * (m as f64) * (m as f64) * terms as f64);
    if part.total == 1 {
        // One window: keep only the strided terms, O(m) memory.
        let mut picked = Vec::with_capacity(terms);
        let mut k0 = 0usize;
        for_each_term_chunk_at(y, off, mu, m, range, k_end, norm, cancel, |chunk| {
            let first = (m - k0 % m) % m;
            picked.extend(chunk.iter().skip(first).step_by(m));
            k0 += chunk.len();
        });
        out[0] = sum4(&picked);
        return;
    }
    let mut a = Vec::with_capacity(range.1 - range.0);
    for_each_term_chunk_at(y, off, mu, m, range, k_end, norm, cancel, |chunk| {
        a.extend_from_slice(chunk)
    });
    if cancel.is_cancelled() {
        return;
    }
    let mut buf = Vec::with_capacity(terms);
    for (j, o) in out.iter_mut().enumerate() {
        // Many long windows add up: look at the flag per window (each is `terms` additions).
        if cancel.is_cancelled() {
            return;
        }
        let s = j * hop;
        buf.clear();
        buf.extend((0..terms).map(|i| a[s + i * m]));
        *o = sum4(&buf);
    }
}

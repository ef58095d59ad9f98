//! The static overlapping Allan variance (one window: the whole record) from one double-word phase
//! prefix, every τ in one pass over the record.
//!
//! At factor m the estimator is Σ_k d_k² / (2 m² L), d_k = P_{k+2m} − 2 P_{k+m} + P_k, L = W + 1 − 2m,
//! with P_j = Σ_{i<j} (y_i − μ) the phase. The streaming path ([`crate::allan`]) forms the block sums
//! of every m from the samples, one m at a time: two running-sum passes per m, the record read once
//! per τ. Here the phase is built once per axis and every term of every m is three reads of it.
//!
//! # Why the phase does not drift
//! A plain f64 prefix carries an absolute error ~ε·max|P| into every d: a quiet stretch after a loud
//! one, or small noise on a slow large swing of the rate, loses its digits. P is kept as hi + lo:
//! hi the running f64 sum, lo the running sum of the exact rounding errors of hi (Knuth's TwoSum),
//! built in fixed blocks, each started from its double-word offset (the blocks' totals are summed
//! first, in parallel, and scanned in double words), each pair stored normalised (|lo| ≲ ½ ulp(hi)).
//! Its error is ~ε²·(samples)·max|P|, i.e. ≲ 10⁻²⁵·max|P| for 10⁸ samples. μ is the window's mean
//! from the same blocks' double-word total (that pass is also the finite check).
//!
//! A term is then d = [(hi₂ − hi₁) − (hi₁ − hi₀)] + [(lo₂ − lo₁) − (lo₁ − lo₀)]. The differences of
//! hi are rounded once each: hi₂ − hi₁ is the block sum B_{k+m} (to within the lo parts), so the
//! error of d is ≲ ε·(|B_k| + |B_{k+m}| + |d|) + O(ε²·max|P|) — relative to the term's own block sums,
//! never to the rest of the record. The terms d² ≥ 0 are summed without cancellation.
//!
//! # Single words where they are provably enough
//! Dropping lo halves the reads and the arithmetic, and costs each term at most 4ε·max|hi| + 4·max|lo|
//! over the pairs it reads (+ ε|d|) — small against the terms unless the phase is far larger than
//! they are. Each (chunk, m) partial sum is therefore first formed from hi alone and kept only if a
//! rigorous bound on its difference from the double-word sum, from the chunk's largest |hi| and |lo|
//! (recorded while the phase is built), is within 10⁻¹¹ of it (`sums::single_word_holds`); otherwise the
//! chunk is summed in double words. White noise of 10⁷ samples passes everywhere; a quiet stretch
//! after a loud one, a steep ramp of the rate or a random-walk rate fall back where they need to
//! (the unit test `single_word_partials_stand_for_the_double_word_ones` checks every partial of such
//! records against the double-word one).
//!
//! # Speed
//! The record is cut into chunks of `CHUNK` terms; a chunk computes its partial sums for every m,
//! so the phase values at k (and, for short m, at k + m and k + 2m) are read from cache by every τ.
//! The term loop is written over `LANES` independent partial sums in `chunks_exact` so that it
//! compiles to packed vector operations (AVX2 where the CPU has it, chosen at run time; the same
//! IEEE operations in the same order either way, so the bits do not depend on it).
//!
//! # Bit-identical for any thread count
//! Block and chunk boundaries depend on the record length only; each chunk's partial sums are
//! formed by one sequential routine (whose single- or double-word choice depends on the data and
//! that grid only), and the partials are added in chunk order.
//!
//! The module's parts: `phase` (the double-word phase and its buffers), `sums` (the static estimator's
//! term pass) and `dynamic` (the sliding-window rows and the phase segments).

mod dynamic;
mod phase;
mod sums;

pub use dynamic::segment_windows;
pub(crate) use dynamic::{
    overlapping_dynamic_row, overlapping_dynamic_tiled, segment_span, terms_dispatch, DynScratch,
    PHASE_RECORD_MAX, PHASE_SPAN_MAX, SMALL_HOP,
};
pub(crate) use phase::{
    advise_huge_pages, block_offsets, block_total_dispatch, centre, Phase, PhaseBuf,
};
pub(crate) use sums::{chunk_sum_dispatch, overlapping_window};

/// Samples per block of the phase build.
const BLOCK: usize = 1 << 16;
/// Terms per chunk of the term pass.
const CHUNK: usize = 1 << 13;
/// Chunks per super-chunk (one rayon task).
const SUPER: usize = 16;
/// Factors up to this run chunk by chunk inside a super-chunk, longer ones factor by factor.
const SHORT_M: usize = CHUNK / 2;
/// Independent partial sums per chunk and m (the vector width the term loop is written for).
const LANES: usize = 8;

#[cfg(test)]
use allanite_testutil::lcg_uniform as noise;

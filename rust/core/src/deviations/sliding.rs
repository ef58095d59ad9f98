//! Sliding-window deviations: the dynamic overlapping Hadamard variance, and gap-aware dynamic OAVAR,
//! MVAR and OHVAR — terms formed once per m, summed in hop-aligned blocks, each window's sum of whole
//! blocks and one partial block (as `allan`'s DAVAR).

use super::{
    centred, check_gap_span, check_ms, check_values, for_each_term_chunk, nan_prefix_counts,
    span_scale, Compensated, Kind, TermBuf, RUN,
};
use crate::allan::{block_window_sums, check_shape, check_window_hop, sum4};
use crate::cancel::Cancel;
use crate::error::{CoreError, Result};
use rayon::prelude::*;

/// Dynamic overlapping Hadamard variance: OHVAR of every window of `window` rate samples starting
/// every `hop` samples, at every m (1 ≤ 3m ≤ window). Returns (values [axis][m][window], windows).
///
/// Design as `allan.rs`'s DAVAR: the terms a(i) = (B(i+2m) − 2B(i+m) + B(i))² / (6m²L) are formed
/// once per m from local block sums, summed in hop-aligned blocks, and every window's sum is made of
/// whole blocks by Van Herk sliding sums over the block array plus one partial block — sums of
/// non-negative numbers only, no running subtraction, so no drift along the record. The Hadamard
/// variance ignores a constant and a linear rate, so one record-wide mean serves every window.
pub fn dynamic_ohvar(
    columns: &[&[f64]],
    window: usize,
    hop: usize,
    ms: &[usize],
) -> Result<(Vec<f64>, usize)> {
    let n = check_shape(columns)?;
    check_window_hop(window, hop, n, 3)?;
    check_ms(Kind::Ohvar, window, ms, "window")?;
    check_values(columns, false)?;
    let n_win = (n - window) / hop + 1;
    let n_m = ms.len();
    let centred: Vec<Vec<f64>> = columns.par_iter().map(|c| centred(c)).collect();
    let mut out = vec![0.0; columns.len() * n_m * n_win];
    out.par_chunks_mut(n_win)
        .enumerate()
        .for_each(|(row, dst)| {
            let (f, m) = (&centred[row / n_m], ms[row % n_m]);
            let l = window + 1 - 3 * m;
            let k_end = (n_win - 1) * hop + l;
            let (_, scale) = span_scale(Kind::Ohvar, m);
            let mut t = Vec::with_capacity(k_end);
            let mut tb = TermBuf::default();
            for_each_term_chunk(Kind::Ohvar, &f[..k_end + 3 * m - 1], m, &mut tb, |_, c| {
                t.extend_from_slice(c)
            });
            let norm = scale / l as f64;
            let hop_b = if n_win == 1 { l } else { hop };
            let (q, r) = (l / hop_b, l % hop_b);
            let nblocks = n_win + q;
            let mut full = vec![0.0; nblocks];
            let mut part = vec![0.0; nblocks];
            let mut buf = Vec::with_capacity(hop_b.min(RUN));
            for (b, blk) in t[..k_end].chunks(hop_b).enumerate() {
                let mut acc = Compensated::default();
                let mut pacc = Compensated::default();
                for (c, sub) in blk.chunks(RUN).enumerate() {
                    buf.clear();
                    buf.extend(sub.iter().map(|v| v * v * norm));
                    acc.add(sum4(&buf));
                    // The partial block: the first r terms of the block.
                    let lo = c * RUN;
                    if lo < r {
                        pacc.add(sum4(&buf[..(r - lo).min(buf.len())]));
                    }
                }
                full[b] = acc.value();
                part[b] = pacc.value();
            }
            block_window_sums(&full, &part, (q, r), (0, n_win), dst);
        });
    Ok((out, n_win))
}

/// Gap-aware dynamic OAVAR or OHVAR: the estimate of every window of `window` samples, `hop` apart,
/// from the terms inside the window whose span holds no NaN (as [`gap_deviation`] on that window
/// alone). Returns (values [axis][m][window], complete-term counts [axis][m][window], windows); a
/// window with no complete term at some m gives NaN and 0 there.
///
/// The same scheme as [`dynamic_ohvar`]: the record's terms are formed once per (axis, m), their
/// squares (0 for an incomplete term) summed per block of `hop` terms with compensation, each window's
/// sum the Van Herk sliding sum of whole blocks plus the partial block — sums of non-negative values of
/// the window's own terms only, so a level change of 10⁶ elsewhere costs nothing. The counts are exact
/// integer prefix differences. Memory per running (axis, m) task: the record's terms (8 bytes each)
/// and their prefix count (8 bytes each).
pub fn gap_dynamic(
    columns: &[&[f64]],
    window: usize,
    hop: usize,
    ms: &[usize],
    kind: Kind,
    cancel: &Cancel,
) -> Result<(Vec<f64>, Vec<u64>, usize)> {
    if !matches!(kind, Kind::Oavar | Kind::Ohvar) {
        return Err(CoreError::InvalidParameter(format!(
            "gap-aware sliding-window estimation is available for OAVAR and OHVAR, not {}",
            kind.name()
        )));
    }
    let n = check_shape(columns)?;
    check_window_hop(window, hop, n, 2)?;
    check_ms(kind, window, ms, "window")?;
    check_values(columns, true)?;
    check_gap_span(window, "window")?; // a term's span is at most the window
    let n_win = (n - window) / hop + 1;
    let n_m = ms.len();
    let prepared: Vec<(Vec<f64>, Vec<u32>)> = columns
        .par_iter()
        .map(|c| (centred(c), nan_prefix_counts(c)))
        .collect();
    let mut out = vec![0.0; columns.len() * n_m * n_win];
    let mut counts = vec![0u64; columns.len() * n_m * n_win];
    out.par_chunks_mut(n_win)
        .zip(counts.par_chunks_mut(n_win))
        .enumerate()
        .for_each(|(row, (dst, dcnt))| {
            if cancel.is_cancelled() {
                return;
            }
            let ((f, gap), m) = (&prepared[row / n_m], ms[row % n_m]);
            gap_dynamic_row(kind, (f, gap), m, (window, hop, n_win), dst, dcnt);
        });
    cancel.check()?;
    Ok((out, counts, n_win))
}

/// One (axis, m) row of [`gap_dynamic`] on the centred record `f` and its NaN prefix counts `gap`: every
/// window's value into `dst`, its complete terms into `dcnt`.
fn gap_dynamic_row(
    kind: Kind,
    (f, gap): (&[f64], &[u32]),
    m: usize,
    (window, hop, n_win): (usize, usize, usize),
    dst: &mut [f64],
    dcnt: &mut [u64],
) {
    let (span, scale) = span_scale(kind, m);
    let l = window + 1 - span; // terms per window
    let k_end = (n_win - 1) * hop + l; // terms used by some window
                                       // squares of the complete terms (0 otherwise) and the prefix count of complete terms
                                       // (the gap count's wrap-around: see `nan_prefix_counts`)
    let mut t = Vec::with_capacity(k_end);
    let mut done = vec![0u64; k_end + 1];
    let mut tb = TermBuf::default();
    for_each_term_chunk(kind, &f[..k_end + span - 1], m, &mut tb, |k0, c| {
        for (i, v) in c.iter().enumerate() {
            let k = k0 + i;
            let ok = gap[k + span] == gap[k];
            t.push(if ok { v * v } else { 0.0 });
            done[k + 1] = done[k] + ok as u64;
        }
    });
    for (j, o) in dcnt.iter_mut().enumerate() {
        *o = done[j * hop + l] - done[j * hop];
    }
    let hop_b = if n_win == 1 { l } else { hop };
    let (q, r) = (l / hop_b, l % hop_b);
    let (full, part) = block_sums(&t[..k_end], hop_b, r, n_win + q);
    block_window_sums(&full, &part, (q, r), (0, n_win), dst);
    for (o, &c) in dst.iter_mut().zip(dcnt.iter()) {
        *o = if c == 0 {
            f64::NAN
        } else {
            *o * scale / c as f64
        };
    }
}

/// The compensated sums of `t` per block of `hop_b` terms (`nblocks` of them), and of each block's
/// first `r` terms: (full, part).
fn block_sums(t: &[f64], hop_b: usize, r: usize, nblocks: usize) -> (Vec<f64>, Vec<f64>) {
    let mut full = vec![0.0; nblocks];
    let mut part = vec![0.0; nblocks];
    for (b, blk) in t.chunks(hop_b).enumerate() {
        let mut acc = Compensated::default();
        let mut pacc = Compensated::default();
        for (c, sub) in blk.chunks(RUN).enumerate() {
            acc.add(sum4(sub));
            let lo = c * RUN;
            if lo < r {
                pacc.add(sum4(&sub[..(r - lo).min(sub.len())]));
            }
        }
        full[b] = acc.value();
        part[b] = pacc.value();
    }
    (full, part)
}

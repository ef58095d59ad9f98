use super::paths::RowPath;
use super::*;
use allanite_testutil::{hashed_levels, Lcg};

#[test]
fn sliding_sums_match_direct() {
    let f: Vec<f64> = (0..37).map(|i| (i * i % 11) as f64).collect();
    for q in 1..10 {
        for n_out in 1..=f.len() - q + 1 {
            let mut s = vec![f64::NAN; n_out];
            sliding_sums(&f, q, &mut s);
            for j in 0..n_out {
                assert_eq!(s[j], f[j..j + q].iter().sum::<f64>());
            }
        }
    }
}

/// The one-segment-at-a-time form `sliding_sums` interleaves: the same additions in the same order.
fn sliding_sums_serial(f: &[f64], q: usize, out: &mut [f64]) {
    let n_out = out.len();
    let mut s0 = 0;
    while s0 < n_out {
        let end = (s0 + q).min(n_out + q - 1);
        let mut s: f64 = f[n_out.min(end)..end].iter().rev().sum();
        for j in (s0..end.min(n_out)).rev() {
            s += f[j];
            out[j] = s;
        }
        s0 += q;
    }
    let mut s0 = q;
    while s0 < n_out + q - 1 {
        let end = (s0 + q - 1).min(n_out + q - 1);
        let mut p = 0.0;
        for i in s0..end {
            p += f[i];
            out[i + 1 - q] += p;
        }
        s0 += q;
    }
}

#[test]
fn interleaved_sliding_sums_are_bit_identical_to_serial() {
    let f = hashed_levels(5000);
    for q in [2, 3, 7, 64, 100, 333, 1000, 1249, 1250, 1251, 2500, 4999] {
        for n_out in [
            1,
            2,
            q - 1,
            q,
            q + 1,
            4 * q - 1,
            4 * q,
            4 * q + 1,
            9 * q + 5,
            f.len() + 1 - q,
        ] {
            if n_out == 0 || n_out + q - 1 > f.len() {
                continue;
            }
            let (mut a, mut b) = (vec![0.0; n_out], vec![0.0; n_out]);
            sliding_sums(&f, q, &mut a);
            sliding_sums_serial(&f, q, &mut b);
            assert!(
                a.iter().zip(&b).all(|(x, y)| x.to_bits() == y.to_bits()),
                "q {q} n_out {n_out}"
            );
        }
    }
}

#[test]
fn sliding_sums_at_is_the_records_arithmetic() {
    let f = hashed_levels(300);
    for q in [1, 2, 3, 7, 16, 33, 100] {
        for n_total in [1, 2, q, q + 1, 3 * q + 2, f.len() + 1 - q] {
            if n_total + q - 1 > f.len() {
                continue;
            }
            let mut whole = vec![f64::NAN; n_total];
            sliding_sums(&f[..n_total + q - 1], q, &mut whole);
            for g0 in 0..n_total {
                for len in [1, 2, 5, q, q + 3, n_total] {
                    let len = len.min(n_total - g0);
                    let mut part = vec![f64::NAN; len];
                    sliding_sums_at(&f[g0..g0 + len + q - 1], q, g0, n_total, &mut part);
                    for j in 0..len {
                        assert_eq!(
                            part[j].to_bits(),
                            whole[g0 + j].to_bits(),
                            "q {q} n {n_total} g0 {g0} len {len} j {j}"
                        );
                    }
                }
            }
        }
    }
}

/// A record whose mean is far above its noise (7000 σ) and whose noise level changes: centring
/// and block alignment matter in the last bits.
fn biased_record(n: usize, seed: u64) -> Vec<f64> {
    let mut g = Lcg::new(seed.wrapping_mul(Lcg::MUL).wrapping_add(Lcg::INC));
    (0..n)
        .map(|i| {
            let u = g.next_centered();
            7000.0 + u * if i < n / 3 { 3.0 } else { 1.0 }
        })
        .collect()
}

/// The streaming path of a part (what the record's call does when it streams).
fn streamed(req: &Request, mus: &[f64], first: usize, total: usize) -> Vec<f64> {
    let n_win = validate(req).unwrap().min(total - first);
    let mut out = vec![0.0; req.columns.len() * req.ms.len() * n_win];
    let part = Part { first, total };
    part_rows(req, mus, part, RowPath::Stream, &mut out, &Cancel::new());
    out
}

/// The columns of windows `first .. first + count` (the samples they span, the record's end at most).
fn part_columns<'a>(
    cols: &[&'a [f64]],
    first: usize,
    count: usize,
    window: usize,
    hop: usize,
) -> Vec<&'a [f64]> {
    let s0 = first * hop;
    let len = ((count - 1) * hop + window).min(cols[0].len() - s0);
    cols.iter().map(|c| &c[s0..s0 + len]).collect()
}

/// The part call's values for `preq` (windows `first ..` of `n_win`), checked to hold `count` windows.
fn part_values(preq: &Request, mus: &[f64], first: usize, n_win: usize, count: usize) -> Vec<f64> {
    let (got, k) = dynamic_avar_part_cancellable(preq, mus, first, n_win, &Cancel::new()).unwrap();
    assert_eq!(k, count);
    got
}

#[test]
fn a_part_of_the_record_gives_the_records_windows() {
    let n = 3001;
    let cols_owned = [biased_record(n, 1), biased_record(n, 2)];
    let cols: Vec<&[f64]> = cols_owned.iter().map(|c| c.as_slice()).collect();
    let mus: Vec<f64> = cols.iter().map(|c| compensated_mean(c)).collect();
    // (window, hop): m ≤ 8 and > 8, hop 1, ≤ 64, > 64, hops longer than some terms (q = 0),
    // a single window.
    let cases = [
        (500, 1),
        (500, 7),
        (401, 64),
        (700, 65),
        (1000, 130),
        (300, 290),
        (2999, 3),
        (n, 1),
        (2500, 600),
    ];
    let (mut differ, mut compared, mut worst) = (0usize, 0usize, 0.0f64);
    for estimator in [Estimator::Overlapping, Estimator::Classic] {
        for (window, hop) in cases {
            let (d, c, w) = part_case(&cols, &mus, estimator, window, hop);
            (differ, compared, worst) = (differ + d, compared + c, worst.max(w));
        }
    }
    // the phase path of a part: the record's terms from differently rounded phase values
    assert!(worst > 0.0 && worst < 1e-13, "worst {worst:e}");
    // the streaming equality is not a property of any part: computed on their own (their own
    // mean, their own alignment) a quarter of these values differ in the last bits
    assert!(differ * 10 > compared, "{differ} of {compared} differ");
}

/// One (estimator, window, hop) of [`a_part_of_the_record_gives_the_records_windows`]: every part
/// checked against the record's call and its streaming path; (parts' values computed on their own
/// that differ from the record's, values compared, the phase path's worst relative difference).
fn part_case(
    cols: &[&[f64]],
    mus: &[f64],
    estimator: Estimator,
    window: usize,
    hop: usize,
) -> (usize, usize, f64) {
    let (mut differ, mut compared, mut worst) = (0usize, 0usize, 0.0f64);
    let mut ms: Vec<usize> = vec![1, 2, 3, 8, 9, 10, 17, 64, 100, 149, window / 2];
    ms.retain(|&m| m <= window / 2);
    ms.dedup();
    let req = Request {
        columns: cols,
        window,
        hop,
        ms: &ms,
        estimator,
        method: Method::Fast,
    };
    let (record, n_win) = dynamic_avar(&req).unwrap();
    let whole = streamed(&req, mus, 0, n_win);
    // this record is small: the record's call streams only the classic estimator
    let phase = estimator == Estimator::Overlapping;
    if !phase && n_win >= 2 {
        assert!(whole
            .iter()
            .zip(&record)
            .all(|(a, b)| a.to_bits() == b.to_bits()));
    }
    let starts: Vec<usize> = (0..n_win)
        .step_by(1 + n_win / 7)
        .chain([n_win - 1])
        .collect();
    for &first in &starts {
        for count in [1, 2, 3, n_win] {
            let count = count.min(n_win - first);
            let part_cols = part_columns(cols, first, count, window, hop);
            let preq = Request {
                columns: &part_cols,
                ..req
            };
            let got = part_values(&preq, mus, first, n_win, count);
            let part = streamed(&preq, mus, first, n_win);
            // the part on its own (its own mean and alignment) rounds differently
            let (alone, _) = dynamic_avar(&preq).unwrap();
            let per_row = alone.len() / (cols.len() * ms.len());
            for row in 0..cols.len() * ms.len() {
                for j in 0..count {
                    let w = whole[row * n_win + first + j];
                    differ += usize::from(alone[row * per_row + j] != w);
                    compared += 1;
                    // streaming: the same additions in the same order
                    assert_eq!(
                        part[row * count + j].to_bits(),
                        w.to_bits(),
                        "{estimator:?} window {window} hop {hop} first {first} \
                         count {count} row {row} j {j}"
                    );
                    // the part entry against the record's call (its path)
                    let (g, r) = (got[row * count + j], record[row * n_win + first + j]);
                    // (the phase path: bit for bit from a segment's start)
                    let seg = crate::oavar::segment_windows(window, hop, false);
                    let exact = !phase || first % seg == 0;
                    if exact {
                        assert_eq!(g.to_bits(), r.to_bits(), "{estimator:?} {window} {hop}");
                    } else {
                        worst = worst.max((g / r - 1.0).abs());
                    }
                }
            }
        }
    }
    (differ, compared, worst)
}

/// The phase path in segments (the unit tests' segments span 2^12 samples): parts that start on
/// the segment grid are the record's call bit for bit, others to a few ε; every value matches
/// the plain recomputation of its window.
#[test]
fn phase_segments_cut_where_parts_can() {
    // a long record in the unit tests (> 2^14 samples × axes: segments of max(2^12, 4·window)) and
    // a short one (segments of max(2^12, 16·window))
    let long_cases = vec![
        (300, 1),
        (500, 7),
        (256, 64),
        (1000, 100),
        (200, 5000),
        (2500, 100),
    ];
    let short_cases = vec![(200, 1), (250, 3), (200, 64)];
    for (n, n_axes, long, cases) in [
        (20_011, 2, true, long_cases),
        (16_000, 1, false, short_cases),
    ] {
        segments_case(n, n_axes, long, &cases);
    }
}

/// The overlapping Allan variance of one window at factor `m`, the plain way (phase by a running sum).
fn plain_overlapping(w: &[f64], m: usize) -> f64 {
    let mut x = vec![0.0f64; w.len() + 1];
    let mu = compensated_mean(w);
    for (i, v) in w.iter().enumerate() {
        x[i + 1] = x[i] + (v - mu);
    }
    let l = w.len() + 1 - 2 * m;
    let s: f64 = (0..l)
        .map(|k| (x[k + 2 * m] - 2.0 * x[k + m] + x[k]).powi(2))
        .sum();
    s / (2.0 * (m * m) as f64 * l as f64)
}

fn segments_case(n: usize, n_axes: usize, long: bool, cases: &[(usize, usize)]) {
    let cols_owned: Vec<Vec<f64>> = (0..n_axes)
        .map(|a| biased_record(n, 7 + a as u64))
        .collect();
    let cols: Vec<&[f64]> = cols_owned.iter().map(|c| c.as_slice()).collect();
    let mus: Vec<f64> = cols.iter().map(|c| compensated_mean(c)).collect();
    // hop 1 (rows), 3 and 7 (rows, blocks), 64 and 100 (tiled), a hop longer than a segment's span
    for &(window, hop) in cases {
        let seg = crate::oavar::segment_windows(window, hop, long);
        let ms: Vec<usize> = [1, 2, 5, 16, 33, window / 2]
            .into_iter()
            .filter(|&m| m <= window / 2)
            .collect();
        let req = Request::overlapping(&cols, window, hop, &ms);
        let (record, n_win) = dynamic_avar(&req).unwrap();
        // (the unit tests' span limit for a long record is 2^13: window 2500 takes chunked phases
        // (`crate::chunked`), the others keep the phase path; a short record keeps it at any window)
        let phase = !long || window * 4 <= 1 << 13;
        assert!(
            n_win > seg || hop > 4096 || !phase,
            "window {window} hop {hop}: one segment only"
        );
        let grid = if phase {
            seg * hop
        } else {
            crate::chunked::chunk_len(window, hop)
        };
        assert_eq!(
            part_grid(n, n_axes, window, hop, Estimator::Overlapping, Method::Fast),
            Some(grid)
        );
        // the parts' own grid in windows
        let seg = grid / hop;
        // every value against the window's own plain recomputation
        for (a, y) in cols.iter().enumerate() {
            for (t, &m) in ms.iter().enumerate() {
                for j in (0..n_win).step_by(1 + n_win / 40) {
                    let plain = plain_overlapping(&y[j * hop..j * hop + window], m);
                    let got = record[(a * ms.len() + t) * n_win + j];
                    assert!(
                        (got / plain - 1.0).abs() < 1e-9,
                        "{window} {hop} m {m} j {j}: {got} vs {plain}"
                    );
                }
            }
        }
        let (mut worst, mut off_grid) = (0.0f64, 0usize);
        for first in [0, seg, 2 * seg, seg / 2 + 1, seg + 3] {
            if first >= n_win {
                continue;
            }
            for count in [1, seg, seg + 1, n_win] {
                let count = count.min(n_win - first);
                let part_cols = part_columns(&cols, first, count, window, hop);
                let preq = Request {
                    columns: &part_cols,
                    ..req
                };
                let got = part_values(&preq, &mus, first, n_win, count);
                for row in 0..cols.len() * ms.len() {
                    for j in 0..count {
                        let (g, r) = (got[row * count + j], record[row * n_win + first + j]);
                        if first % seg == 0 {
                            assert_eq!(
                                g.to_bits(),
                                r.to_bits(),
                                "{window} {hop} first {first} count {count}"
                            );
                        } else {
                            worst = worst.max((g / r - 1.0).abs());
                            off_grid += 1;
                        }
                    }
                }
            }
        }
        assert!(off_grid == 0 || worst < 1e-13, "{window} {hop}: {worst:e}");
    }
}

#[test]
fn the_record_mean_from_its_parts_is_bit_identical() {
    let y = biased_record(10_007, 3);
    let mut st = (0.0, 0.0);
    for c in y.chunks(977) {
        st = compensated_sum_from(c, st);
    }
    assert_eq!(
        ((st.0 + st.1) / y.len() as f64).to_bits(),
        compensated_mean(&y).to_bits()
    );
}

#[test]
fn a_part_names_bad_arguments() {
    let y = biased_record(100, 4);
    let cols = [y.as_slice()];
    let req = Request {
        columns: &cols,
        window: 10,
        hop: 5,
        ms: &[1, 2],
        estimator: Estimator::Overlapping,
        method: Method::Fast,
    };
    let c = Cancel::new();
    assert!(dynamic_avar_part_cancellable(&req, &[f64::NAN], 0, 30, &c).is_err());
    assert!(dynamic_avar_part_cancellable(&req, &[1.0, 2.0], 0, 30, &c).is_err());
    assert!(dynamic_avar_part_cancellable(&req, &[1.0], 30, 30, &c).is_err());
    // a part longer than the rest of the record gives the record's windows only
    assert_eq!(
        dynamic_avar_part_cancellable(&req, &[1.0], 25, 28, &c)
            .unwrap()
            .1,
        3
    );
}

#[test]
fn parts_name_a_non_finite_sample() {
    // a part of several windows (checked before its rows) and a record's one window (checked in
    // the static paths' centring pass), a NaN in the window and an inf after it
    let mut y: Vec<f64> = (0..1000).map(|i| ((i * 37) % 11) as f64).collect();
    y[700] = f64::NAN;
    let mut z = y.clone();
    z[700] = 1.0;
    z[900] = f64::INFINITY;
    for (col, index, window, total) in [(&y, 700, 500, 6), (&y, 700, 1000, 1), (&z, 900, 800, 1)] {
        for estimator in [Estimator::Overlapping, Estimator::Classic] {
            let cols = [&col[..]];
            let req = Request {
                columns: &cols,
                window,
                hop: 100,
                ms: &[1, 2],
                estimator,
                method: Method::Fast,
            };
            let err =
                dynamic_avar_part_cancellable(&req, &[0.0], 0, total, &Cancel::new()).unwrap_err();
            assert!(
                matches!(err, CoreError::NonFinite { axis: 0, index: i, .. } if i == index),
                "{window} {estimator:?}: {err}"
            );
            assert!(err.to_string().contains("only finite numbers are allowed"));
            if total == 1 {
                // the whole-record call of one window (hop past the record's end): the same
                let req = Request { hop: 1000, ..req };
                let err = dynamic_avar(&req).unwrap_err();
                assert!(
                    matches!(err, CoreError::NonFinite { axis: 0, index: i, .. } if i == index),
                    "whole record {window} {estimator:?}: {err}"
                );
            }
        }
    }
}

#[test]
fn block_sums_match_direct() {
    // Integer-valued data: every order of summation is exact, so equality is exact.
    let y: Vec<f64> = (0..400).map(|i| ((i * 7919) % 23) as f64 - 11.0).collect();
    for m in [1, 2, 3, 5, 8, 63, 64, 65, 100, 130] {
        let mut start = 0;
        while start + 2 * m <= y.len() {
            for len in [1, 2, m / 2 + 1, m.saturating_sub(1).max(1), m]
                .into_iter()
                .filter(|&l| l <= m)
            {
                let mut sc = TermScratch::new(m);
                sc.segment(&y, 1.0, m, start, len, None);
                for r in 0..len {
                    let direct: f64 = y[start + r..start + r + m].iter().map(|v| v - 1.0).sum();
                    assert_eq!(sc.bprev[r], direct, "m {m} start {start} len {len} r {r}");
                }
            }
            start += m;
        }
    }
}

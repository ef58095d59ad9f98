use super::*;
use allanite_testutil::Lcg;

/// Integer-valued samples on a quantum of 1: every sum is exact, so the kernel must match the
/// plain definition exactly.
#[test]
fn matches_the_plain_definition_on_exact_data() {
    let n = 997;
    let y: Vec<f64> = (0..2 * n)
        .map(|i| ((i * 7919) % 201) as f64 - 100.0)
        .collect(); // 2 axes, row-major
    let angle = |a: usize| {
        let mut x = vec![0.0f64];
        for i in 0..n {
            x.push(x[i] + y[2 * i + a]);
        }
        x
    };
    let xs = [angle(0), angle(1)];
    // three chunks, the middle one left out of the second task to make two runs
    let cut = [0, 300, 640, n];
    let offs: Vec<[i64; 2]> = cut[..3]
        .iter()
        .map(|&s| [xs[0][s] as i64, xs[1][s] as i64])
        .collect();
    let zeros = [0.0, 0.0];
    let chunk = |j: usize| AngleChunk {
        start: cut[j],
        y: &y[2 * cut[j]..2 * cut[j + 1]],
        off_w: &offs[j],
        off_r: &zeros,
    };
    let all = [chunk(0), chunk(1), chunk(2)];
    for classic in [false, true] {
        let plan = [
            (1, 0, 996),
            (7, 3, 600),
            (100, 0, 400),
            (300, 0, 398),
            (5, 0, 290),
        ];
        let got = angle_term_sums_cancellable(&all, 2, 0, &plan, classic, &Cancel::new()).unwrap();
        for (p, &(m, i0, i1)) in plan.iter().enumerate() {
            for a in 0..2 {
                let x = &xs[a];
                let want: f64 = (i0..i1)
                    .filter(|i| !classic || i % m == 0)
                    .map(|i| {
                        let d = x[i + 2 * m] - 2.0 * x[i + m] + x[i];
                        d * d
                    })
                    .sum();
                assert_eq!(got[p * 2 + a], want, "classic {classic} m {m} axis {a}");
            }
        }
    }
    // two runs: chunks 0 and 2 only; a term range whose slices lie in them works, one that needs
    // chunk 1 is refused
    let two = [chunk(0), chunk(2)];
    let ok = angle_term_sums_cancellable(&two, 2, 0, &[(349, 291, 293)], false, &Cancel::new());
    let x = &xs[1];
    let want: f64 = (291..293)
        .map(|i| (x[i + 698] - 2.0 * x[i + 349] + x[i]).powi(2))
        .sum();
    assert_eq!(ok.unwrap()[1], want);
    let bad = angle_term_sums_cancellable(&two, 2, 0, &[(320, 0, 10)], false, &Cancel::new());
    assert!(matches!(bad, Err(CoreError::InvalidParameter(_))));
}

#[test]
fn streaming_one_factor_gives_the_stored_paths_bits() {
    // noisy, biased, three axes; chunks of uneven length in two runs
    let n = 5000;
    let na = 3;
    let mut g = Lcg::new(0x9E3779B97F4A7C15);
    let y: Vec<f64> = (0..n * na)
        .map(|i| g.next_centered() * [1.0, 3e-3, 40.0][i % na] + [0.0, 7.0, -900.0][i % na])
        .collect();
    let q_exp = -16; // |y/q| ≤ 2^26
    let cut = [0, 700, 1900, 2600, 5000];
    let offs_w: Vec<Vec<i64>> = cut[..4].iter().map(|&c| vec![c as i64 * 3; na]).collect();
    let offs_r: Vec<Vec<f64>> = cut[..4]
        .iter()
        .map(|&c| vec![c as f64 * 1e-3; na])
        .collect();
    let chunk = |j: usize| AngleChunk {
        start: cut[j],
        y: &y[na * cut[j]..na * cut[j + 1]],
        off_w: &offs_w[j],
        off_r: &offs_r[j],
    };
    let all = [chunk(0), chunk(1), chunk(2), chunk(3)];
    let two = [chunk(0), chunk(2), chunk(3)];
    let c = Cancel::new();
    for classic in [false, true] {
        for (chunks, item) in [
            (&all[..], (1usize, 0usize, 4998usize)),
            (&all[..], (37, 650, 2700)),
            (&all[..], (1200, 100, 2500)),
            (&two[..], (1300, 600, 650)), // slices in two runs: [600,650) and [1900,1950), [3200,3250)
        ] {
            let one = angle_term_sums_cancellable(chunks, na, q_exp, &[item], classic, &c).unwrap();
            // a second (empty-free) item makes the call build and store the runs
            let stored =
                angle_term_sums_cancellable(chunks, na, q_exp, &[item, (1, 0, 10)], classic, &c)
                    .unwrap();
            for a in 0..na {
                assert_eq!(
                    one[a].to_bits(),
                    stored[a].to_bits(),
                    "{item:?} {classic} {a}"
                );
                let terms = (item.1..item.2).any(|i| !classic || i % item.0 == 0);
                assert_eq!(one[a] > 0.0, terms);
            }
        }
    }
}

#[test]
fn bad_input_is_named() {
    let y = [1.0, f64::NAN, 3.0];
    let c = [AngleChunk {
        start: 10,
        y: &y,
        off_w: &[0],
        off_r: &[0.0],
    }];
    let e = angle_term_sums_cancellable(&c, 1, 0, &[(1, 10, 11)], false, &Cancel::new());
    assert!(matches!(e, Err(CoreError::NonFinite { index: 11, .. })));
    let e = angle_term_sums_cancellable(&c, 1, 2000, &[(1, 10, 11)], false, &Cancel::new());
    assert!(matches!(e, Err(CoreError::InvalidParameter(_))));
}

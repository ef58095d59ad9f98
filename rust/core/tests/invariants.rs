//! Property tests of the estimators' invariants, against a plain per-window recomputation.

use allanite_core::{dynamic_avar, run_in_pool, static_avar, Estimator, Method, Request};
use proptest::prelude::*;

use allanite_testutil::proptest_config;

/// Plain definition: remove the mean, integrate, sum squared second differences.
fn reference(y: &[f64], m: usize, estimator: Estimator) -> f64 {
    let mu = y.iter().sum::<f64>() / y.len() as f64;
    let mut x = vec![0.0];
    for v in y {
        let last = *x.last().unwrap();
        x.push(last + (v - mu));
    }
    let mm = (m * m) as f64;
    match estimator {
        Estimator::Overlapping => {
            let l = x.len() - 2 * m;
            (0..l)
                .map(|k| (x[k + 2 * m] - 2.0 * x[k + m] + x[k]).powi(2))
                .sum::<f64>()
                / (2.0 * mm * l as f64)
        }
        Estimator::Classic => {
            let k = y.len() / m;
            (0..k - 1)
                .map(|i| (x[(i + 2) * m] - 2.0 * x[(i + 1) * m] + x[i * m]).powi(2))
                .sum::<f64>()
                / (2.0 * mm * (k - 1) as f64)
        }
    }
}

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + 1e-300
}

fn record() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-1e3f64..1e3, 4..400)
}

fn estimator() -> impl Strategy<Value = Estimator> {
    prop_oneof![Just(Estimator::Overlapping), Just(Estimator::Classic)]
}

proptest! {
    #![proptest_config(proptest_config::config(200))]

    #[test]
    fn every_window_equals_the_plain_recomputation(
        y in record(), wfrac in 0.05f64..1.0, hop in 1usize..50, est in estimator(),
        method in prop_oneof![Just(Method::Fast), Just(Method::Naive)],
    ) {
        let window = ((y.len() as f64 * wfrac) as usize).clamp(2, y.len());
        let mut ms: Vec<usize> = vec![1, 2, 3, 5, 8, 9, 13, 40, 64, 65, 100, 150];
        ms.retain(|&m| m <= window / 2);
        let cols = [&y[..]];
        let req = Request { columns: &cols, window, hop, ms: &ms, estimator: est, method };
        let (out, n_win) = dynamic_avar(&req).unwrap();
        prop_assert_eq!(n_win, (y.len() - window) / hop + 1);
        for (t, &m) in ms.iter().enumerate() {
            for j in 0..n_win {
                let s = j * hop;
                let want = reference(&y[s..s + window], m, est);
                prop_assert!(close(out[t * n_win + j], want, 1e-9), "m {} j {}: {} vs {}", m, j, out[t * n_win + j], want);
            }
        }
    }

    #[test]
    fn scaling_by_c_scales_avar_by_c_squared(y in record(), c in 1e-3f64..1e3, est in estimator()) {
        // m ≤ n/9 (≥ 9 clusters): with one or two terms a single second difference can be a
        // cancellation of nearly equal block sums, whose last digits differ between y and c·y.
        let ms: Vec<usize> = (1..=(y.len() / 9).max(1)).step_by(3).collect();
        let scaled: Vec<f64> = y.iter().map(|v| v * c).collect();
        let a = static_avar(&[&y[..]], &ms, est).unwrap();
        let b = static_avar(&[&scaled[..]], &ms, est).unwrap();
        for (x, z) in a.iter().zip(&b) {
            prop_assert!(close(x * c * c, *z, 1e-12));
        }
    }

    #[test]
    fn constant_rate_gives_zero(c in -1e6f64..1e6, n in 4usize..300, est in estimator()) {
        // Constant rate = linear angle: every second difference vanishes.
        let y = vec![c; n];
        let ms: Vec<usize> = (1..=n / 2).collect();
        for v in static_avar(&[&y[..]], &ms, est).unwrap() {
            prop_assert_eq!(v, 0.0);
        }
    }

    #[test]
    fn window_as_long_as_the_record_is_the_static_estimator(y in record(), est in estimator()) {
        let ms: Vec<usize> = (1..=y.len() / 2).collect();
        let cols = [&y[..]];
        let req = Request { columns: &cols, window: y.len(), hop: 1, ms: &ms, estimator: est, method: Method::Fast };
        let (dynamic, n_win) = dynamic_avar(&req).unwrap();
        prop_assert_eq!(n_win, 1);
        prop_assert_eq!(dynamic, static_avar(&cols, &ms, est).unwrap());
    }

    #[test]
    fn serial_equals_parallel_bit_for_bit(y in record(), hop in 1usize..20) {
        let window = (y.len() / 2).max(2);
        let ms: Vec<usize> = (1..=window / 2).collect();
        let z: Vec<f64> = y.iter().rev().copied().collect();
        let cols = [&y[..], &z[..]];
        let req = Request { columns: &cols, window, hop, ms: &ms, estimator: Estimator::Overlapping, method: Method::Fast };
        let one = run_in_pool(1, || dynamic_avar(&req)).unwrap().unwrap();
        let two = run_in_pool(2, || dynamic_avar(&req)).unwrap().unwrap();
        let four = run_in_pool(4, || dynamic_avar(&req)).unwrap().unwrap();
        prop_assert_eq!(&one, &two);
        prop_assert_eq!(&one, &four);
    }
}

#[test]
fn nist_sp1065_suite() {
    // NBS14 1000-point data, docs/FORMULAS.md §2.4.
    let mut n: u64 = 1234567890;
    let y: Vec<f64> = (0..1000)
        .map(|_| {
            let v = n as f64 / 2147483647.0;
            n = (16807 * n) % 2147483647;
            v
        })
        .collect();
    let o = static_avar(&[&y[..]], &[1, 10, 100], Estimator::Overlapping).unwrap();
    let a = static_avar(&[&y[..]], &[1, 10, 100], Estimator::Classic).unwrap();
    for (got, want) in o.iter().zip([0.2922319, 0.09159953, 0.03241343]) {
        assert!(close(got.sqrt(), want, 5e-7), "OADEV {got} vs {want}");
    }
    for (got, want) in a.iter().zip([0.2922319, 0.09965736, 0.03897804]) {
        assert!(close(got.sqrt(), want, 5e-7), "ADEV {got} vs {want}");
    }
}

#[test]
fn errors_name_the_value() {
    let y = [0.0, 1.0, f64::NAN, 2.0];
    let cols = [&y[..]];
    let err = static_avar(&cols, &[1], Estimator::Overlapping)
        .unwrap_err()
        .to_string();
    assert!(err.contains("sample 2") && err.contains("NaN"), "{err}");
    let y = [0.0; 10];
    let cols = [&y[..]];
    let bad = |window, hop, ms: &[usize]| {
        let req = Request::overlapping(&cols, window, hop, ms);
        dynamic_avar(&req).unwrap_err().to_string()
    };
    assert!(bad(11, 1, &[1]).contains("window (11 samples)"));
    assert!(bad(4, 0, &[1]).contains("hop (0)"));
    assert!(bad(4, 1, &[3]).contains("m = 3"));
    assert!(bad(4, 1, &[]).contains("no averaging factors"));
}

use super::*;
use allanite_testutil::Xorshift;

/// Xorshift noise uniform in [−1, 1) (twice the [−½, ½) values: exact, multiples of 2⁻⁵²).
fn noise(n: usize, seed: u64) -> Vec<f64> {
    let mut g = Xorshift::new(seed.max(1));
    (0..n).map(|_| 2.0 * g.next_centered()).collect()
}

fn run(y: &[f64], window: usize, hop: usize, ms: &[usize], method: Method) -> Vec<f64> {
    let cols = [y];
    let req = Request {
        columns: &cols,
        window,
        hop,
        ms,
        estimator: Estimator::Overlapping,
        method,
    };
    dynamic_hann(&req).unwrap().0
}

#[test]
fn weights_sum_as_stated() {
    for mt in [3, 4, 17, 400, 1001] {
        let w = hann_weights(mt);
        let s: f64 = w.iter().sum();
        let s2: f64 = w.iter().map(|v| v * v).sum();
        assert!((s - weight_sum(mt)).abs() < 1e-12 * s);
        assert!((s2 - 3.0 * (mt + 1) as f64 / 8.0).abs() < 1e-12 * s2);
    }
}

#[test]
fn fast_matches_naive() {
    let mut y = noise(3000, 7);
    for v in y[1500..].iter_mut() {
        *v *= 1e3;
    }
    for (window, hop) in [
        (40, 1),
        (41, 3),
        (401, 1),
        (401, 7),
        (401, 8),
        (401, 33),
        (401, 450),
        (1000, 999),
    ] {
        let ms: Vec<usize> = [1, 2, 5, 9, 20, 100, 190]
            .into_iter()
            .filter(|&m| window + 1 >= 2 * m + MIN_TERMS)
            .collect();
        let f = run(&y, window, hop, &ms, Method::Fast);
        let n = run(&y, window, hop, &ms, Method::Naive);
        for (a, b) in f.iter().zip(&n) {
            assert!(
                (a - b).abs() <= 1e-10 * b.abs(),
                "{window} {hop}: {a} vs {b}"
            );
        }
    }
}

#[test]
fn one_window_matches_sliding() {
    let y = noise(2001, 3);
    let ms = [1, 3, 50, 700];
    let one = run(&y, 2001, 1, &ms, Method::Fast);
    let two = run(&y[..2001], 2000, 1, &ms, Method::Fast);
    let naive = run(&y, 2001, 1, &ms, Method::Naive);
    for (a, b) in one.iter().zip(&naive) {
        assert!((a - b).abs() <= 1e-12 * b, "{a} vs {b}");
    }
    assert_eq!(two.len(), 2 * ms.len());
}

#[test]
fn too_few_terms_is_an_error() {
    let y = noise(100, 1);
    let cols = [&y[..]];
    let req = Request::overlapping(&cols, 10, 1, &[4]);
    assert!(dynamic_hann(&req).is_ok()); // M = 3: the fewest allowed
    let req = Request { ms: &[5], ..req };
    let e = dynamic_hann(&req).unwrap_err().to_string();
    assert!(
        e.contains("M = window + 1 − 2m = 1 at m = 5") && e.contains("m ≤ 4"),
        "{e}"
    );
    let req = Request {
        ms: &[2],
        estimator: Estimator::Classic,
        ..req
    };
    assert!(dynamic_hann(&req).is_err());
}

#[test]
fn thread_count_does_not_change_bits() {
    let y = noise(5000, 11);
    let cols = [&y[..]];
    let req = Request {
        columns: &cols,
        window: 777,
        hop: 5,
        ms: &[1, 4, 33, 200],
        estimator: Estimator::Overlapping,
        method: Method::Fast,
    };
    let one = crate::run_in_pool(1, || dynamic_hann(&req))
        .unwrap()
        .unwrap();
    let two = crate::run_in_pool(2, || dynamic_hann(&req))
        .unwrap()
        .unwrap();
    assert_eq!(one, two);
}

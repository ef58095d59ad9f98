//! Property tests of the Theo1 paths against the direct double sum, and their invariants.

use allanite_core::{detrended_phase, dynamic_theo1, run_in_pool, static_theo1, theo1_direct};
use proptest::prelude::*;

use allanite_testutil::proptest_config;

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * a.abs().max(b.abs()) + 1e-300
}

fn record() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(-1e3f64..1e3, 12..260)
}

proptest! {
    #![proptest_config(proptest_config::config(120))]

    #[test]
    fn every_window_equals_the_direct_double_sum(y in record(), wfrac in 0.1f64..1.0, hop in 1usize..40) {
        let window = ((y.len() as f64 * wfrac) as usize).clamp(10, y.len());
        let ms: Vec<usize> = [2usize, 4, 10, 12, 14, 30, 64, 100, 200, 258]
            .into_iter().filter(|&m| m <= window).collect();
        prop_assume!(!ms.is_empty());
        let (out, n_win) = dynamic_theo1(&[&y], window, hop, &ms).unwrap();
        prop_assert_eq!(n_win, (y.len() - window) / hop + 1);
        for j in [0, n_win / 2, n_win - 1] {
            let x = detrended_phase(&y[j * hop..j * hop + window]);
            for (i, &m) in ms.iter().enumerate() {
                let want = theo1_direct(&x, m);
                prop_assert!(close(out[i * n_win + j], want, 1e-10), "window {} m {}: {} vs {}", j, m, out[i * n_win + j], want);
            }
        }
    }

    #[test]
    fn static_equals_direct_and_scales_by_c_squared(y in record(), c in 1e-3f64..1e3) {
        let n = y.len();
        let ms: Vec<usize> = (2..=n).step_by(2).collect();
        let a = static_theo1(&[&y], &ms).unwrap();
        let x = detrended_phase(&y);
        let yc: Vec<f64> = y.iter().map(|v| c * v).collect();
        let b = static_theo1(&[&yc], &ms).unwrap();
        for (i, &m) in ms.iter().enumerate() {
            prop_assert!(close(a[i], theo1_direct(&x, m), 1e-10));
            prop_assert!(close(b[i], c * c * a[i], 1e-10));
        }
    }

    #[test]
    fn constant_or_linear_rate_phase_gives_zero(c in -1e6f64..1e6, n in 12usize..200) {
        // A constant rate is a linear phase: Theo1 ignores it exactly.
        let y = vec![c; n];
        let ms: Vec<usize> = (2..=n).step_by(2).collect();
        for v in static_theo1(&[&y], &ms).unwrap() {
            prop_assert!(v.abs() <= 1e-20 * c * c + 1e-300);
        }
    }

    #[test]
    fn serial_equals_parallel_bit_for_bit(y in record(), hop in 1usize..20) {
        let window = y.len().min(120);
        let ms: Vec<usize> = [2usize, 10, 12, 40, 100, 120].into_iter().filter(|&m| m <= window).collect();
        let one = run_in_pool(1, || dynamic_theo1(&[&y], window, hop, &ms)).unwrap().unwrap();
        let two = run_in_pool(2, || dynamic_theo1(&[&y], window, hop, &ms)).unwrap().unwrap();
        prop_assert_eq!(one, two);
        let all: Vec<usize> = (2..=y.len()).step_by(2).collect();
        let s1 = run_in_pool(1, || static_theo1(&[&y], &all)).unwrap().unwrap();
        let s2 = run_in_pool(2, || static_theo1(&[&y], &all)).unwrap().unwrap();
        prop_assert_eq!(s1, s2);
    }
}

#[test]
fn errors_name_the_value() {
    let y = vec![0.5; 40];
    let e = static_theo1(&[&y], &[7]).unwrap_err().to_string();
    assert!(e.contains("m = 7") && e.contains("even"), "{e}");
    let e = dynamic_theo1(&[&y], 50, 1, &[10]).unwrap_err().to_string();
    assert!(e.contains("window (50 samples)"), "{e}");
    let e = dynamic_theo1(&[&y], 20, 0, &[10]).unwrap_err().to_string();
    assert!(e.contains("hop (0)"), "{e}");
    let bad = [0.0, f64::NAN, 1.0];
    let e = static_theo1(&[&bad], &[2]).unwrap_err().to_string();
    assert!(e.contains("non-finite") && e.contains("sample 1"), "{e}");
}

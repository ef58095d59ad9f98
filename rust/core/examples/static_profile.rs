//! Times the static overlapping Allan variance without Python, with a STREAM-like roofline measured
//! in the same run: `cargo run --release --example static_profile -- [N] [workers]`.
use allanite_core::{run_in_pool, static_avar, Estimator};
use allanite_testutil::xorshift_uniform;
use std::time::Instant;

fn best<R>(reps: usize, mut f: impl FnMut() -> R) -> (f64, R) {
    let mut b = f64::INFINITY;
    let mut last = None;
    for _ in 0..reps {
        let t = Instant::now();
        let r = f();
        b = b.min(t.elapsed().as_secs_f64());
        last = Some(r);
    }
    (b, last.unwrap())
}

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(10_000_000, |s| s.parse().unwrap());
    let workers: usize = std::env::args().nth(2).map_or(1, |s| s.parse().unwrap());
    let y = xorshift_uniform(n, 0x9E3779B97F4A7C15);
    let mut ms: Vec<usize> = (0..200)
        .map(|k| 1.2f64.powi(k).round() as usize)
        .filter(|&m| m <= n / 10)
        .collect();
    ms.dedup();
    // roofline: a copy of the record (bandwidth) and one pass of Σ (y[k+2] − 2y[k+1] + y[k])² (arithmetic)
    let mut dst = vec![0.0f64; n];
    let (tc, _) = best(5, || {
        dst.copy_from_slice(&y);
        dst[n / 2]
    });
    let (ts, _) = best(5, || {
        let mut acc = [0.0f64; 8];
        for (i, w) in y.windows(3).enumerate() {
            let d = w[2] - 2.0 * w[1] + w[0];
            acc[i & 7] += d * d;
        }
        acc.iter().sum::<f64>()
    });
    println!(
        "copy: {:.2} GB/s ({:.3} ns/sample); second-difference Σd²: {:.3} ns/sample",
        16.0 * n as f64 / tc / 1e9,
        tc / n as f64 * 1e9,
        ts / n as f64 * 1e9
    );
    let (tm, mu) = best(3, || allanite_core::compensated_mean(&y));
    println!("compensated mean: {:.4} s ({mu:.3e})", tm);
    let cols = [&y[..]];
    let groups: Vec<(&str, Vec<usize>)> = vec![
        ("all", ms.clone()),
        ("m=1", vec![1]),
        (
            "m<=1000",
            ms.iter().copied().filter(|&m| m <= 1000).collect(),
        ),
        (
            "1000<m<=16384",
            ms.iter()
                .copied()
                .filter(|&m| m > 1000 && m <= 16384)
                .collect(),
        ),
        (
            "m>16384",
            ms.iter().copied().filter(|&m| m > 16384).collect(),
        ),
    ];
    for (name, g) in groups {
        let (t, out) = best(3, || {
            run_in_pool(workers, || static_avar(&cols, &g, Estimator::Overlapping))
                .unwrap()
                .unwrap()
        });
        println!(
            "{name:>14}: {:>3} τ, workers {workers}: {:.4} s, {:.3} ns/sample/τ (check {:.6e})",
            g.len(),
            t,
            t / (n * g.len()) as f64 * 1e9,
            out[0]
        );
    }
}

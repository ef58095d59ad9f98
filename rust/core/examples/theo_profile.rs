//! Timing of the Theo1 paths without Python: `cargo run --release --example theo_profile -p allanite-core`.
use allanite_core::{dynamic_theo1, static_theo1};
use allanite_testutil::lcg_uniform as lcg;
use std::time::Instant;

/// TheoH's Theo1 factors: the bias-ratio set 12 + 4i and a log grid beyond 10 % of the span.
fn theoh_ms(n_rate: usize) -> Vec<usize> {
    let np = n_rate + 1;
    let nk = ((0.1 * np as f64) / 3.0 - 3.0).floor() as usize;
    let mut ms: Vec<usize> = (0..=nk).map(|i| 12 + 4 * i).collect();
    let lo = (0.1 * n_rate as f64 / 0.75) as usize;
    let mut m = lo as f64;
    while (m as usize) <= n_rate {
        ms.push((m as usize) & !1);
        m *= 1.25;
    }
    ms.push(n_rate & !1);
    ms.sort();
    ms.dedup();
    ms
}

fn main() {
    for &n in &[10_000usize, 100_000] {
        let y = lcg(n, 1);
        let ms = theoh_ms(n);
        let t = Instant::now();
        let v = static_theo1(&[&y], &ms).unwrap();
        println!(
            "static N={n}: {} m's, {:.3} s (first {:.4e})",
            ms.len(),
            t.elapsed().as_secs_f64(),
            v[0]
        );
    }
    let y = lcg(40_000, 2);
    let ms: Vec<usize> = theoh_ms(401).into_iter().filter(|&m| m <= 401).collect();
    let t = Instant::now();
    let (_, nw) = dynamic_theo1(&[&y], 401, 1, &ms).unwrap();
    println!(
        "dynamic N=4e4 W=401 hop 1: {} m's, {nw} windows, {:.3} s",
        ms.len(),
        t.elapsed().as_secs_f64()
    );
}

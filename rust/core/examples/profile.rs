//! Times the core on the large case without Python: `cargo run --release --example profile`.
use allanite_core::{dynamic_avar, run_in_pool, Request};
use allanite_testutil::xorshift_uniform;
use std::time::Instant;

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map_or(10_000_000, |s| s.parse().unwrap());
    let window = std::env::args()
        .nth(2)
        .map_or(n / 10, |s| s.parse().unwrap());
    let hop = std::env::args()
        .nth(3)
        .map_or((n / 1000).max(1), |s| s.parse().unwrap());
    let y = xorshift_uniform(n, 0x9E3779B97F4A7C15);
    let top = window / 9;
    let g = (top as f64).powf(1.0 / 149.0);
    let mut ms: Vec<usize> = (0..150)
        .map(|i| (g.powi(i)).round() as usize)
        .filter(|&m| m <= top)
        .collect();
    ms.dedup();
    if std::env::var("PER_M").is_ok() {
        per_m(&y, window, hop);
        return;
    }
    let cols = [&y[..]];
    for workers in [1, 2] {
        let req = Request::overlapping(&cols, window, hop, &ms);
        let t = Instant::now();
        let (out, nw) = run_in_pool(workers, || dynamic_avar(&req))
            .unwrap()
            .unwrap();
        println!("n {n} window {window} hop {hop} taus {} windows {nw} workers {workers}: {:.3} s (check {:.6})", ms.len(), t.elapsed().as_secs_f64(), out[0]);
    }
}

#[allow(dead_code)]
pub fn per_m(y: &[f64], window: usize, hop: usize) {
    let cols = [y];
    for m in [1usize, 4, 8, 9, 16, 32, 64, 100, 1000, 10000, 100000] {
        let ms = [m; 8];
        let req = Request::overlapping(&cols, window, hop, &ms);
        let t = Instant::now();
        run_in_pool(1, || dynamic_avar(&req)).unwrap().unwrap();
        println!(
            "m {m}: {:.2} ns/sample",
            t.elapsed().as_secs_f64() * 1e9 / (8 * y.len()) as f64
        );
    }
}

//! Criterion benches of the core loops, so a regression shows without Python:
//! `cargo bench -p allanite-core`. Sizes are small enough to run in a minute or two.

use allanite_core::{dynamic_avar, run_in_pool, Estimator, Method, Request};
use allanite_testutil::xorshift_uniform;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};

fn noise(n: usize) -> Vec<f64> {
    xorshift_uniform(n, 0x2545F4914F6CDD1D)
}

/// Paper 000 §4.2 grid: m = round(g^i), duplicates removed, up to window/9.
fn exp_grid(window: usize, points: usize) -> Vec<usize> {
    let top = (window / 9).max(1);
    let g = (top as f64).powf(1.0 / (points as f64 - 1.0));
    let mut ms: Vec<usize> = (0..points)
        .map(|i| g.powi(i as i32).round() as usize)
        .filter(|&m| m <= top)
        .collect();
    ms.dedup();
    ms
}

fn run(
    y: &[f64],
    window: usize,
    hop: usize,
    ms: &[usize],
    estimator: Estimator,
    method: Method,
) -> f64 {
    let cols = [y];
    let req = Request {
        columns: &cols,
        window,
        hop,
        ms,
        estimator,
        method,
    };
    let (out, _) = run_in_pool(1, || dynamic_avar(&req)).unwrap().unwrap();
    out[0]
}

fn single_m(c: &mut Criterion) {
    // Cost per sample of one averaging factor on one thread: the inner loops (direct sums for
    // small m, the segmented block sums for larger m, the window accumulation).
    let n = 200_000;
    let y = noise(n);
    let mut g = c.benchmark_group("fast_one_m");
    g.throughput(Throughput::Elements(n as u64));
    for m in [1usize, 8, 9, 64, 1000, 10_000] {
        g.bench_with_input(BenchmarkId::from_parameter(m), &m, |b, &m| {
            b.iter(|| run(&y, n / 5, 100, &[m], Estimator::Overlapping, Method::Fast))
        });
    }
    g.finish();
}

fn dynamic(c: &mut Criterion) {
    let n = 100_000;
    let y = noise(n);
    let window = 10_000;
    let ms = exp_grid(window, 100);
    let mut g = c.benchmark_group("davar_n1e5_w1e4");
    g.sample_size(10);
    g.bench_function("fast_exp_hop1", |b| {
        b.iter(|| run(&y, window, 1, &ms, Estimator::Overlapping, Method::Fast))
    });
    g.bench_function("fast_exp_hop100", |b| {
        b.iter(|| run(&y, window, 100, &ms, Estimator::Overlapping, Method::Fast))
    });
    g.bench_function("classic_exp_hop100", |b| {
        b.iter(|| run(&y, window, 100, &ms, Estimator::Classic, Method::Fast))
    });
    g.bench_function("naive_exp_hop1000", |b| {
        b.iter(|| run(&y, window, 1000, &ms, Estimator::Overlapping, Method::Naive))
    });
    g.finish();
}

criterion_group!(benches, single_m, dynamic);
criterion_main!(benches);

//! The range of a result: its largest and smallest value, and whether any is not finite.
//!
//! `allanite.davar` checks its result before scaling it back (a value past float64's range is an
//! error naming the samples' scale). A hop-1 surface is tens of megabytes: two NumPy passes over it
//! (max, min) cost almost as much as writing it. The core notes each row's range right after forming
//! it, while the row is still in cache, and hands the ranges over with the values.

/// Largest and smallest value of some outputs, and whether one of them was NaN or ±∞.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Range {
    pub max: f64,
    pub min: f64,
    pub non_finite: bool,
}

impl Default for Range {
    fn default() -> Self {
        Range {
            max: f64::NEG_INFINITY,
            min: f64::INFINITY,
            non_finite: false,
        }
    }
}

/// Accumulators per pass: enough independent lanes for the comparisons to pipeline and vectorise.
const LANES: usize = 8;

impl Range {
    /// The range of `values` (compiled for AVX2 where the CPU has it: the same comparisons, so the same
    /// result).
    pub fn of(values: &[f64]) -> Self {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx2") {
            // SAFETY: the CPU has the feature the function is compiled for (checked just above).
            return unsafe { Self::of_avx2(values) };
        }
        Self::of_any(values)
    }

    /// [`Range::of`] in AVX2 intrinsics: maxpd(v, hi) is `if v > hi { v } else { hi }` and minpd likewise,
    /// so a NaN never enters the extremes and the flag is the NaN-ness of Σ v·0, as in the plain loop.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    unsafe fn of_avx2(values: &[f64]) -> Self {
        use std::arch::x86_64::*;
        let mut hi = [_mm256_set1_pd(f64::NEG_INFINITY); 2];
        let mut lo = [_mm256_set1_pd(f64::INFINITY); 2];
        let mut bad = [_mm256_setzero_pd(); 2];
        let zero = _mm256_setzero_pd();
        let mut chunks = values.chunks_exact(LANES);
        for c in &mut chunks {
            for (h, k) in [0usize, 4].into_iter().enumerate() {
                // SAFETY: c has LANES = 8 items, so c[k .. k + 4] is in range (k ≤ 4).
                let v = _mm256_loadu_pd(c.as_ptr().add(k));
                hi[h] = _mm256_max_pd(v, hi[h]);
                lo[h] = _mm256_min_pd(v, lo[h]);
                bad[h] = _mm256_add_pd(bad[h], _mm256_mul_pd(v, zero));
            }
        }
        let mut r = Self::of_any(chunks.remainder());
        let (mut h, mut l, mut b) = ([0.0f64; 4], [0.0f64; 4], [0.0f64; 4]);
        for k in 0..2 {
            _mm256_storeu_pd(h.as_mut_ptr(), hi[k]);
            _mm256_storeu_pd(l.as_mut_ptr(), lo[k]);
            _mm256_storeu_pd(b.as_mut_ptr(), bad[k]);
            for j in 0..4 {
                r = r.merge(Range {
                    max: h[j],
                    min: l[j],
                    non_finite: b[j].is_nan(),
                });
            }
        }
        r
    }

    #[inline(always)]
    fn of_any(values: &[f64]) -> Self {
        let (mut hi, mut lo, mut bad) = (
            [f64::NEG_INFINITY; LANES],
            [f64::INFINITY; LANES],
            [0.0f64; LANES],
        );
        let mut chunks = values.chunks_exact(LANES);
        for c in &mut chunks {
            for k in 0..LANES {
                let v = c[k];
                // plain comparisons (maxpd/minpd); v·0 is 0 for a finite v and NaN otherwise, and a
                // NaN stays in the sum
                hi[k] = if v > hi[k] { v } else { hi[k] };
                lo[k] = if v < lo[k] { v } else { lo[k] };
                bad[k] += v * 0.0;
            }
        }
        let mut r = Range::default();
        for &v in chunks.remainder() {
            r.max = if v > r.max { v } else { r.max };
            r.min = if v < r.min { v } else { r.min };
            r.non_finite |= !v.is_finite();
        }
        for k in 0..LANES {
            r = r.merge(Range {
                max: hi[k],
                min: lo[k],
                non_finite: bad[k].is_nan(),
            });
        }
        r
    }

    /// The range of both.
    pub fn merge(self, o: Range) -> Range {
        Range {
            max: if o.max > self.max { o.max } else { self.max },
            min: if o.min < self.min { o.min } else { self.min },
            non_finite: self.non_finite || o.non_finite,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Range;

    #[test]
    fn the_range_of_values_zeros_and_non_finite_ones() {
        let v: Vec<f64> = (0..37).map(|i| ((i * 7) % 11) as f64 + 0.5).collect();
        let r = Range::of(&v);
        assert_eq!((r.max, r.min, r.non_finite), (10.5, 0.5, false));
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
            for at in [0, 20, 36] {
                let mut w = v.clone();
                w[at] = bad;
                assert!(Range::of(&w).non_finite, "{bad} at {at}");
            }
        }
        let r = Range::of(&[0.0, 2.0]).merge(Range::of(&[]));
        assert_eq!((r.max, r.min, r.non_finite), (2.0, 0.0, false));
    }
}

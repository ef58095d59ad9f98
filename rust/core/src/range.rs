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
    /// The range of `values`.
    pub fn of(values: &[f64]) -> Self {
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

//! Streaming (real-time) overlapping Allan, overlapping Hadamard and time variances of a phase
//! record that grows one point at a time: add a point, read the current values. After N points each
//! value equals the batch estimator on those N points (the same terms; sums of squares compensated).
//!
//! The recursions are those of A. Dobrogowski and M. Kasznia, *Real-time assessment of Allan
//! deviation and time deviation*, Proc. EFTF/IFCS 2007: a new point x_p closes one new term per
//! averaging factor m,
//!
//!   OAVAR  t = x_p − 2x_{p−m} + x_{p−2m}                         (p ≥ 2m)
//!   OHVAR  t = x_p − 3x_{p−m} + 3x_{p−2m} − x_{p−3m}              (p ≥ 3m)
//!   TVAR   W_j = Σ_{k=j}^{j+m−1} (x_{k+2m} − 2x_{k+m} + x_k),  j = p − 3m + 1   (p ≥ 3m − 1)
//!
//! and the value is Σ t² / (2m²·n), Σ t² / (6m²·n), Σ W² / (6m²·n) for n terms (τ0 = 1; TVAR, the
//! square of TDEV, is in phase units whatever τ0). W_j follows from W_{j−1} by one third difference
//! (eq. 12 of the paper) and is recomputed from its definition every m terms, so rounding cannot
//! build up along a long stream: O(1) amortised per point and averaging factor. The phase history is
//! kept (a new averaging factor needs it, and reaches back 3m points).
//!
//! An averaging factor added to a stream that already holds points starts with every term those
//! points close (O(points) once), so its values are exact from the start. With an automatic
//! schedule (`pending`), the next factor m is added as soon as the stream holds 2m + 1 points.

use crate::allan::Compensated;
use crate::error::{CoreError, Result};

/// Which streaming variance.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StreamKind {
    /// Overlapping Allan variance.
    Oavar,
    /// Overlapping Hadamard variance.
    Ohvar,
    /// Time variance (TDEV²), τ²/3 · MVAR.
    Tvar,
}

#[derive(Clone, Debug)]
struct Lane {
    m: usize,
    sq: Compensated,
    n: u64,
    /// TVAR: the latest inner sum W_j
    w: f64,
}

/// A growing phase record and the terms it has closed at each averaging factor.
#[derive(Clone, Debug)]
pub struct Stream {
    kind: StreamKind,
    x: Vec<f64>,
    lanes: Vec<Lane>,
    /// averaging factors still to come, in order, each added at 2m + 1 points
    pending: Vec<usize>,
}

impl Stream {
    /// A stream at the averaging factors `ms` (kept in the order given; repeats allowed), with the
    /// automatic schedule `pending` (increasing) appended as the record grows.
    pub fn new(kind: StreamKind, ms: &[usize], pending: &[usize]) -> Result<Self> {
        if let Some(&m) = ms.iter().chain(pending).find(|&&m| m == 0) {
            return Err(CoreError::InvalidParameter(format!(
                "averaging factors must be ≥ 1, got {m}"
            )));
        }
        if pending.windows(2).any(|w| w[1] < w[0]) {
            return Err(CoreError::InvalidParameter(
                "the automatic averaging factors must be given in increasing order".into(),
            ));
        }
        let mut s = Stream {
            kind,
            x: Vec::new(),
            lanes: Vec::new(),
            pending: pending.iter().rev().copied().collect(),
        };
        for &m in ms {
            s.add_factor(m)?;
        }
        Ok(s)
    }

    /// Adds an averaging factor; its terms over the points already held are taken at once.
    pub fn add_factor(&mut self, m: usize) -> Result<()> {
        if m == 0 {
            return Err(CoreError::InvalidParameter(
                "averaging factors must be ≥ 1, got 0".into(),
            ));
        }
        let mut lane = Lane {
            m,
            sq: Compensated::default(),
            n: 0,
            w: 0.0,
        };
        for p in 0..self.x.len() {
            close_term(self.kind, &self.x[..=p], &mut lane);
        }
        self.lanes.push(lane);
        Ok(())
    }

    /// Appends one phase point (finite), closing one term per averaging factor that reaches it.
    pub fn push(&mut self, v: f64) -> Result<()> {
        if !v.is_finite() {
            return Err(CoreError::NonFinite {
                axis: 0,
                index: self.x.len(),
                value: v,
            });
        }
        self.x.push(v);
        for lane in &mut self.lanes {
            close_term(self.kind, &self.x, lane);
        }
        while let Some(&m) = self.pending.last() {
            if self.x.len() < 2 * m + 1 {
                break;
            }
            self.pending.pop();
            self.add_factor(m)?;
        }
        Ok(())
    }

    /// Appends points in order; on a non-finite one, the points before it are kept and its index in
    /// the whole stream is reported.
    pub fn extend(&mut self, xs: &[f64]) -> Result<()> {
        xs.iter().try_for_each(|&v| self.push(v))
    }

    /// The averaging factors, in the order they were added.
    pub fn factors(&self) -> Vec<usize> {
        self.lanes.iter().map(|l| l.m).collect()
    }

    /// Number of terms closed at each averaging factor.
    pub fn counts(&self) -> Vec<u64> {
        self.lanes.iter().map(|l| l.n).collect()
    }

    /// The variance (τ0 = 1) at each averaging factor; NaN where no term is closed yet.
    pub fn values(&self) -> Vec<f64> {
        let k = match self.kind {
            StreamKind::Oavar => 2.0,
            StreamKind::Ohvar | StreamKind::Tvar => 6.0,
        };
        self.lanes
            .iter()
            .map(|l| {
                let m = l.m as f64;
                if l.n == 0 {
                    f64::NAN
                } else {
                    l.sq.value() / (k * m * m * l.n as f64)
                }
            })
            .collect()
    }

    /// The phase points held.
    pub fn phase(&self) -> &[f64] {
        &self.x
    }
}

/// The term the newest point of `x` closes at `lane.m`, if any, added to the lane.
fn close_term(kind: StreamKind, x: &[f64], lane: &mut Lane) {
    let (p, m) = (x.len() - 1, lane.m);
    let t = match kind {
        StreamKind::Oavar if p >= 2 * m => x[p] - 2.0 * x[p - m] + x[p - 2 * m],
        StreamKind::Ohvar if p >= 3 * m => {
            x[p] - 3.0 * x[p - m] + 3.0 * x[p - 2 * m] - x[p - 3 * m]
        }
        StreamKind::Tvar if p + 1 >= 3 * m => {
            let j = p + 1 - 3 * m;
            lane.w = if j % m == 0 {
                (j..j + m)
                    .map(|k| x[k + 2 * m] - 2.0 * x[k + m] + x[k])
                    .sum()
            } else {
                // W_j − W_{j−1} = s_{j+m−1} − s_{j−1}: a third difference of x
                lane.w + (x[p] - 3.0 * x[p - m] + 3.0 * x[p - 2 * m] - x[p - 3 * m])
            };
            lane.w
        }
        _ => return,
    };
    lane.sq.add(t * t);
    lane.n += 1;
}

#[cfg(test)]
mod tests {
    use super::*;

    use allanite_testutil::lcg_uniform as lcg;

    /// The batch value from the definitions, for comparison.
    fn batch(kind: StreamKind, x: &[f64], m: usize) -> f64 {
        let n = x.len();
        let (terms, k): (Vec<f64>, f64) = match kind {
            StreamKind::Oavar => (
                (0..n - 2 * m)
                    .map(|i| x[i + 2 * m] - 2.0 * x[i + m] + x[i])
                    .collect(),
                2.0,
            ),
            StreamKind::Ohvar => (
                (0..n - 3 * m)
                    .map(|i| x[i + 3 * m] - 3.0 * x[i + 2 * m] + 3.0 * x[i + m] - x[i])
                    .collect(),
                6.0,
            ),
            StreamKind::Tvar => (
                (0..n + 1 - 3 * m)
                    .map(|j| {
                        (j..j + m)
                            .map(|i| x[i + 2 * m] - 2.0 * x[i + m] + x[i])
                            .sum()
                    })
                    .collect(),
                6.0,
            ),
        };
        let mf = m as f64;
        terms.iter().map(|t| t * t).sum::<f64>() / (k * mf * mf * terms.len() as f64)
    }

    #[test]
    fn every_prefix_equals_the_batch_estimator() {
        // a random walk on a large offset, as a clock's phase
        let mut acc = 1e4;
        let x: Vec<f64> = lcg(700, 5)
            .iter()
            .map(|v| {
                acc += v;
                acc
            })
            .collect();
        for kind in [StreamKind::Oavar, StreamKind::Ohvar, StreamKind::Tvar] {
            let ms = [1, 2, 7, 33];
            let mut s = Stream::new(kind, &ms, &[]).unwrap();
            for (p, &v) in x.iter().enumerate() {
                s.push(v).unwrap();
                if p % 97 != 3 {
                    continue;
                }
                for (got, &m) in s.values().iter().zip(&ms) {
                    let span = if kind == StreamKind::Oavar {
                        2 * m
                    } else {
                        3 * m
                    };
                    if p < span - usize::from(kind == StreamKind::Tvar) {
                        assert!(got.is_nan());
                        continue;
                    }
                    let want = batch(kind, &x[..=p], m);
                    assert!(
                        ((got - want) / want).abs() < 1e-11,
                        "{kind:?} m={m} p={p}: {got} vs {want}"
                    );
                }
            }
        }
    }

    #[test]
    fn a_factor_added_late_or_by_schedule_is_exact_from_the_start() {
        let x = lcg(300, 9);
        let mut s = Stream::new(StreamKind::Tvar, &[1], &[2, 3, 6, 10]).unwrap();
        s.extend(&x[..40]).unwrap();
        assert_eq!(s.factors(), vec![1, 2, 3, 6, 10]);
        s.extend(&x[40..]).unwrap();
        s.add_factor(50).unwrap();
        for (got, m) in s.values().iter().zip(s.factors()) {
            let want = batch(StreamKind::Tvar, &x, m);
            assert!(((got - want) / want).abs() < 1e-12, "m={m}");
        }
        assert_eq!(s.counts()[5], 300 + 1 - 150);
    }

    #[test]
    fn bad_input_is_named() {
        assert!(Stream::new(StreamKind::Oavar, &[0], &[])
            .unwrap_err()
            .to_string()
            .contains("≥ 1, got 0"));
        assert!(Stream::new(StreamKind::Oavar, &[1], &[4, 2])
            .unwrap_err()
            .to_string()
            .contains("increasing"));
        let mut s = Stream::new(StreamKind::Oavar, &[1], &[]).unwrap();
        let e = s.extend(&[1.0, 2.0, f64::NAN]).unwrap_err().to_string();
        assert!(e.contains("sample 2"), "{e}");
        assert_eq!(s.phase(), &[1.0, 2.0]);
    }
}

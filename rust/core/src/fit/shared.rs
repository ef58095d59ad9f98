//! What every window of a fit shares, laid out once for the per-window loops: the design matrix by
//! columns, and the covariance blocks as packed lower triangles in the order Σ(θ) sums them.

use super::Problem;

/// The per-problem tables [`super::window::Window`] reads in every pass.
pub(crate) struct Shared {
    /// The design matrix column by column: column c is `design_cm[c * n_tau..(c + 1) * n_tau]`.
    pub(crate) design_cm: Vec<f64>,
    /// Lower triangles (row i: entries 0..=i, rows one after another) of S[a, b] for a, b over the
    /// stochastic terms, a-major, then of T[a] when the ramp is fitted: Σ(θ) is their sum weighted by
    /// θ_a·θ_b, then θ_R·θ_a, in this order (`_covariance.assemble`).
    pub(crate) blocks: Vec<f64>,
}

/// Entries of the packed lower triangle of an n×n matrix.
pub(crate) fn tri_len(n: usize) -> usize {
    n * (n + 1) / 2
}

/// Offset of row i in a packed lower triangle.
#[inline]
pub(crate) fn tri_row(i: usize) -> usize {
    i * (i + 1) / 2
}

impl Shared {
    pub(crate) fn new(p: &Problem) -> Self {
        let (nt, k) = (p.n_tau, p.n_terms);
        let mut design_cm = vec![0.0; nt * k];
        for c in 0..k {
            for i in 0..nt {
                design_cm[c * nt + i] = p.design[i * k + c];
            }
        }
        let mut blocks = Vec::new();
        if let Some(g) = &p.gls {
            let nn = nt * nt;
            let ns = g.stoch.len();
            let mut pack = |blk: &[f64]| {
                for i in 0..nt {
                    blocks.extend_from_slice(&blk[i * nt..i * nt + i + 1]);
                }
            };
            for ab in 0..ns * ns {
                pack(&g.s_blk[ab * nn..(ab + 1) * nn]);
            }
            if g.ramp.is_some() {
                for a in 0..ns {
                    pack(&g.t_blk[a * nn..(a + 1) * nn]);
                }
            }
        }
        Shared { design_cm, blocks }
    }
}

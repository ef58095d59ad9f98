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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fit::Gls;

    #[test]
    fn blocks_are_packed_lower_triangles_in_assembly_order() {
        // 2 τ, 3 terms (two stochastic, the ramp last): S[a, b] entry (i, j) = 1000a + 100b + 10i + j,
        // T[a] entry (i, j) = 5000 + 1000a + 10i + j; the upper triangle must be left out
        let (nt, ns) = (2, 2);
        let mut s = vec![0.0; ns * ns * nt * nt];
        for (n, v) in s.iter_mut().enumerate() {
            let (ab, ij) = (n / (nt * nt), n % (nt * nt));
            *v = (1000 * (ab / ns) + 100 * (ab % ns) + 10 * (ij / nt) + ij % nt) as f64;
        }
        let t: Vec<f64> = (0..ns * nt * nt)
            .map(|n| (5000 + 1000 * (n / 4) + 10 * (n % 4 / 2) + n % 2) as f64)
            .collect();
        let design = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let (nu, rho, l2) = ([1.0; 6], [0.0; 3], [0.0, 1.0]);
        let p = Problem {
            n_tau: nt,
            n_terms: 3,
            design: &design,
            nu_terms: &nu,
            start_col: 0,
            irls_iter: 1,
            max_iter: 1,
            gls_tol: 1e-7,
            irls_rtol: 1e-7,
            rho: &rho,
            log2_tau: &l2,
            gls: Some(Gls {
                s_blk: &s,
                t_blk: &t,
                stoch: &[0, 1],
                ramp: Some(2),
            }),
        };
        let sh = Shared::new(&p);
        assert_eq!(sh.design_cm, [1.0, 4.0, 2.0, 5.0, 3.0, 6.0]);
        let want = [
            0.0, 10.0, 11.0, 100.0, 110.0, 111.0, 1000.0, 1010.0, 1011.0, 1100.0, 1110.0, 1111.0,
            5000.0, 5010.0, 5011.0, 6000.0, 6010.0, 6011.0,
        ];
        assert_eq!(sh.blocks, want);
        assert_eq!((tri_len(nt), tri_row(1)), (3, 1));
    }
}

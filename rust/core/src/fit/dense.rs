//! Small dense linear algebra for the per-window noise fits: Cholesky, triangular solves, Householder
//! least squares, Lawson–Hanson non-negative least squares and the pseudo-inverse of a small symmetric
//! matrix. Sizes are a few τ by at most five terms, so plain loops over row-major slices beat any
//! blocked library call; every routine works in caller-owned buffers (no allocation per window).

/// Lower Cholesky factor of the n×n symmetric matrix `a` + `ridge`·I (row-major, lower triangle read)
/// into `l` (upper triangle zeroed). False when a pivot is not positive or not a number — LAPACK
/// `dpotrf`'s test, so a matrix NumPy refuses is refused here too.
pub(crate) fn cholesky(a: &[f64], n: usize, ridge: f64, l: &mut [f64]) -> bool {
    for j in 0..n {
        let lj = j * n;
        let row_j = &l[lj..lj + j];
        let s = a[lj + j] + ridge - dot(row_j, row_j);
        if s.is_nan() || s <= 0.0 {
            return false;
        }
        let d = s.sqrt();
        l[lj + j] = d;
        for i in j + 1..n {
            let li = i * n;
            let t = a[li + j] - dot(&l[li..li + j], &l[lj..lj + j]);
            l[li + j] = t / d;
        }
        for v in &mut l[lj + j + 1..lj + n] {
            *v = 0.0;
        }
    }
    true
}

/// Σ aᵢbᵢ over the shorter of the two, in four interleaved partial sums (the products pipeline instead of
/// waiting on one running sum).
#[inline]
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let (a, b) = (&a[..n], &b[..n]);
    let mut acc = [0.0f64; 4];
    let (ca, cb) = (a.chunks_exact(4), b.chunks_exact(4));
    let (ra, rb) = (ca.remainder(), cb.remainder());
    for (x, y) in ca.zip(cb) {
        for k in 0..4 {
            acc[k] += x[k] * y[k];
        }
    }
    let tail: f64 = ra.iter().zip(rb).map(|(x, y)| x * y).sum();
    (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
}

/// Solves L·z = b in place (L lower triangular n×n, row-major).
pub(crate) fn forward_solve(l: &[f64], n: usize, b: &mut [f64]) {
    for i in 0..n {
        let li = i * n;
        let s = b[i] - dot(&l[li..li + i], &b[..i]);
        b[i] = s / l[li + i];
    }
}

/// Buffers of [`nnls`] for problems of up to `m` rows and `n` columns.
pub(crate) struct NnlsWork {
    q: Vec<f64>,
    r: Vec<f64>,
    z: Vec<f64>,
    w: Vec<f64>,
    resid: Vec<f64>,
    passive: Vec<bool>,
    skip: Vec<bool>,
    cols: Vec<usize>,
    /// The passive set of the last solution: the next call starts from it (see [`nnls`]).
    last: Vec<bool>,
}

impl NnlsWork {
    pub(crate) fn new(m: usize, n: usize) -> Self {
        NnlsWork {
            q: vec![0.0; m * n],
            r: vec![0.0; m],
            z: vec![0.0; n],
            w: vec![0.0; n],
            resid: vec![0.0; m],
            passive: vec![false; n],
            skip: vec![false; n],
            cols: Vec::with_capacity(n),
            last: vec![false; n],
        }
    }
}

/// Least squares of the columns `cols` of `a` (column-major, m rows) against `b` by Householder QR;
/// the solution goes to `z[cols[k]]`. False when a column is (numerically) dependent on the others.
fn lstsq_cols(
    a: &[f64],
    m: usize,
    cols: &[usize],
    b: &[f64],
    z: &mut [f64],
    q: &mut [f64],
    r: &mut [f64],
) -> bool {
    let p = cols.len();
    let q = &mut q[..p * m];
    for (k, &c) in cols.iter().enumerate() {
        q[k * m..(k + 1) * m].copy_from_slice(&a[c * m..(c + 1) * m]);
    }
    let r = &mut r[..m];
    r.copy_from_slice(&b[..m]);
    for k in 0..p {
        // column k from row k on (the reflector), and the columns after it
        let (head, tail) = q.split_at_mut((k + 1) * m);
        let v = &mut head[k * m + k..];
        let norm = v.iter().map(|v| v * v).sum::<f64>().sqrt();
        if norm == 0.0 || !norm.is_finite() {
            return false;
        }
        // reflect column k onto ∓norm·e_k (sign chosen against cancellation)
        let alpha = if v[0] > 0.0 { -norm } else { norm };
        let v0 = v[0] - alpha;
        v[0] = v0;
        let vnorm2 = v0 * v0 + v[1..].iter().map(|v| v * v).sum::<f64>();
        if vnorm2 > 0.0 {
            let reflect = |x: &mut [f64]| {
                let mut s = 0.0;
                for (vi, xi) in v.iter().zip(x.iter()) {
                    s += vi * xi;
                }
                let f = 2.0 * s / vnorm2;
                for (xi, vi) in x.iter_mut().zip(v.iter()) {
                    *xi -= f * vi;
                }
            };
            for col in tail.chunks_exact_mut(m) {
                reflect(&mut col[k..]);
            }
            reflect(&mut r[k..]);
        }
        v[0] = alpha; // R's diagonal; the reflector below it is no longer needed
    }
    for k in (0..p).rev() {
        let mut s = r[k];
        for j in k + 1..p {
            s -= q[j * m + k] * z[cols[j]];
        }
        let d = q[k * m + k];
        z[cols[k]] = s / d;
    }
    true
}

/// Non-negative least squares of `a·x ≈ b` (a column-major, m×n), Lawson & Hanson's active-set
/// algorithm (Solving Least Squares Problems, 1974, ch. 23), into `x`. The solution of a full-rank
/// problem is unique, so this agrees with SciPy's `nnls` (the same algorithm from x = 0) to rounding.
/// It starts from the last call's passive set when the least squares on it is feasible (all
/// coefficients positive) — in an iterated fit the set rarely changes, and one solve then checks
/// it — else from x = 0. False when `max_iter` inner steps do not settle it (SciPy raises there).
pub(crate) fn nnls(
    a: &[f64],
    m: usize,
    n: usize,
    b: &[f64],
    x: &mut [f64],
    max_iter: usize,
    ws: &mut NnlsWork,
) -> bool {
    x[..n].fill(0.0);
    ws.skip[..n].fill(false);
    ws.cols.clear();
    ws.cols.extend((0..n).filter(|&c| ws.last[c]));
    let warm = !ws.cols.is_empty()
        && lstsq_cols(a, m, &ws.cols, b, &mut ws.z, &mut ws.q, &mut ws.r)
        && ws.cols.iter().all(|&c| ws.z[c] > 0.0);
    for (c, xc) in x[..n].iter_mut().enumerate() {
        ws.passive[c] = warm && ws.last[c];
        if ws.passive[c] {
            *xc = ws.z[c];
        }
    }
    let done = nnls_from(a, m, n, b, x, max_iter, ws);
    for (last, xc) in ws.last[..n].iter_mut().zip(&x[..n]) {
        *last = *xc > 0.0;
    }
    done
}

/// Lawson–Hanson's loop from a feasible x whose positive entries are `ws.passive`.
fn nnls_from(
    a: &[f64],
    m: usize,
    n: usize,
    b: &[f64],
    x: &mut [f64],
    max_iter: usize,
    ws: &mut NnlsWork,
) -> bool {
    let mut iterations = 0;
    loop {
        let Some(t) = most_useful_column(a, m, n, b, x, ws) else {
            return true;
        };
        ws.passive[t] = true;
        let mut first = true;
        loop {
            iterations += 1;
            if iterations > max_iter {
                return false;
            }
            ws.cols.clear();
            ws.cols.extend((0..n).filter(|&c| ws.passive[c]));
            let solved = lstsq_cols(a, m, &ws.cols, b, &mut ws.z, &mut ws.q, &mut ws.r);
            if first && (!solved || ws.z[t].is_nan() || ws.z[t] <= 0.0) {
                // rounding made a column with a positive dual look useless: leave it out this round
                ws.passive[t] = false;
                ws.skip[t] = true;
                break;
            }
            if !solved {
                return false;
            }
            first = false;
            ws.skip[..n].fill(false);
            if ws.cols.iter().all(|&c| ws.z[c] > 0.0) {
                for (c, xc) in x[..n].iter_mut().enumerate() {
                    *xc = if ws.passive[c] { ws.z[c] } else { 0.0 };
                }
                break;
            }
            step_towards_z(x, n, ws);
        }
    }
}

/// The dual w = aᵀ(b − a·x) into `ws.w`, and the active column (neither passive nor skipped) of the
/// largest positive w, if any.
fn most_useful_column(
    a: &[f64],
    m: usize,
    n: usize,
    b: &[f64],
    x: &[f64],
    ws: &mut NnlsWork,
) -> Option<usize> {
    let resid = &mut ws.resid[..m];
    resid.copy_from_slice(&b[..m]);
    for (col, &xc) in a.chunks_exact(m).zip(&x[..n]) {
        if xc != 0.0 {
            for (ri, &ai) in resid.iter_mut().zip(col) {
                *ri -= ai * xc;
            }
        }
    }
    let mut best = None;
    let mut wmax = 0.0;
    for (c, col) in a.chunks_exact(m).take(n).enumerate() {
        ws.w[c] = col.iter().zip(resid.iter()).map(|(ai, ri)| ai * ri).sum();
        if !ws.passive[c] && !ws.skip[c] && ws.w[c] > wmax {
            wmax = ws.w[c];
            best = Some(c);
        }
    }
    best
}

/// Steps x from itself towards the passive solution `ws.z` until the first passive coefficient reaches
/// zero; the coefficients at zero leave the passive set.
fn step_towards_z(x: &mut [f64], n: usize, ws: &mut NnlsWork) {
    let mut alpha = f64::INFINITY;
    let mut hit = usize::MAX;
    for &c in &ws.cols {
        if ws.z[c] <= 0.0 {
            let s = x[c] / (x[c] - ws.z[c]);
            if s < alpha {
                alpha = s;
                hit = c;
            }
        }
    }
    for &c in &ws.cols {
        x[c] += alpha * (ws.z[c] - x[c]);
    }
    x[hit] = 0.0;
    for (c, xc) in x[..n].iter_mut().enumerate() {
        if ws.passive[c] && *xc <= 0.0 {
            *xc = 0.0;
            ws.passive[c] = false;
        }
    }
}

/// Pseudo-inverse of the symmetric p×p matrix `a` (row-major; overwritten) into `out`, as NumPy's
/// `pinv` (rcond 1e-15: eigenvalues of magnitude ≤ 1e-15 × the largest are dropped), by cyclic
/// Jacobi rotations — accurate for the few-term normal matrices of a fit. `v` is p×p workspace.
pub(crate) fn pinv_sym(a: &mut [f64], p: usize, v: &mut [f64], out: &mut [f64]) {
    v[..p * p].fill(0.0);
    for i in 0..p {
        v[i * p + i] = 1.0;
    }
    for _sweep in 0..60 {
        let mut off = 0.0;
        let mut diag = 0.0;
        for i in 0..p {
            diag += a[i * p + i] * a[i * p + i];
            for j in i + 1..p {
                off += a[i * p + j] * a[i * p + j];
            }
        }
        if off <= 1e-34 * diag || off == 0.0 {
            break;
        }
        for i in 0..p {
            for j in i + 1..p {
                let aij = a[i * p + j];
                if aij == 0.0 {
                    continue;
                }
                let (aii, ajj) = (a[i * p + i], a[j * p + j]);
                let theta = (ajj - aii) / (2.0 * aij);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                let rotate_cols = |m: &mut [f64]| {
                    for row in m[..p * p].chunks_exact_mut(p) {
                        let (ri, rj) = (row[i], row[j]);
                        row[i] = c * ri - s * rj;
                        row[j] = s * ri + c * rj;
                    }
                };
                rotate_cols(a);
                let (upper, lower) = a[..p * p].split_at_mut(j * p);
                let row_i = &mut upper[i * p..(i + 1) * p];
                for (aik, ajk) in row_i.iter_mut().zip(&mut lower[..p]) {
                    let (x, y) = (*aik, *ajk);
                    *aik = c * x - s * y;
                    *ajk = s * x + c * y;
                }
                rotate_cols(v);
            }
        }
    }
    let largest = (0..p).map(|i| a[i * p + i].abs()).fold(0.0, f64::max);
    let cutoff = 1e-15 * largest;
    out[..p * p].fill(0.0);
    for e in 0..p {
        let lam = a[e * p + e];
        if lam.is_nan() || lam.abs() <= cutoff {
            continue;
        }
        for i in 0..p {
            let vi = v[i * p + e] / lam;
            for j in 0..p {
                out[i * p + j] += vi * v[j * p + e];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn nnls_matches_hand_solutions() {
        // scipy's documented examples: columns (1,1,0), (0,0,1)
        let a = [1.0, 1.0, 0.0, 0.0, 0.0, 1.0];
        let mut ws = NnlsWork::new(3, 2);
        let mut x = [0.0; 2];
        assert!(nnls(&a, 3, 2, &[2.0, 1.0, 1.0], &mut x, 100, &mut ws));
        assert!((x[0] - 1.5).abs() < 1e-15 && (x[1] - 1.0).abs() < 1e-15);
        assert!(nnls(&a, 3, 2, &[-1.0, -1.0, -1.0], &mut x, 100, &mut ws));
        assert_eq!(x, [0.0, 0.0]);
    }

    #[test]
    fn nnls_clips_a_negative_unconstrained_coefficient() {
        // unconstrained: b = 2·c0 − 1·c1 exactly; constrained the second is 0 and the first the projection
        let a = [1.0, 0.0, 1.0, 1.0, 1.0, 0.0];
        let b = [1.0, -1.0, 2.0];
        let mut ws = NnlsWork::new(3, 2);
        let mut x = [0.0; 2];
        assert!(nnls(&a, 3, 2, &b, &mut x, 100, &mut ws));
        assert_eq!(x[1], 0.0);
        assert!((x[0] - 1.5).abs() < 1e-14, "{x:?}");
    }

    #[test]
    fn a_warm_start_gives_the_cold_answer() {
        // columns (1,0,1) and (1,1,0): b1 needs both, b2 only the first (the second clips to 0)
        let a = [1.0, 0.0, 1.0, 1.0, 1.0, 0.0];
        let (b1, b2) = ([2.0, 1.0, 1.0], [1.0, -1.0, 2.0]);
        let mut warm = NnlsWork::new(3, 2);
        let (mut x, mut cold_x) = ([0.0; 2], [0.0; 2]);
        for b in [b1, b2, b1, b2] {
            assert!(nnls(&a, 3, 2, &b, &mut x, 100, &mut warm));
            assert!(nnls(
                &a,
                3,
                2,
                &b,
                &mut cold_x,
                100,
                &mut NnlsWork::new(3, 2)
            ));
            assert_eq!(x[1] == 0.0, cold_x[1] == 0.0);
            for c in 0..2 {
                assert!(
                    (x[c] - cold_x[c]).abs() <= 1e-15 * cold_x[c].abs().max(1.0),
                    "{x:?} {cold_x:?}"
                );
            }
        }
    }

    #[test]
    fn cholesky_and_solve_reproduce_the_system() {
        let a = [4.0, 2.0, 0.6, 2.0, 5.0, 1.0, 0.6, 1.0, 3.0];
        let mut l = [0.0; 9];
        assert!(cholesky(&a, 3, 0.0, &mut l));
        let mut b = [1.0, 2.0, 3.0];
        forward_solve(&l, 3, &mut b);
        // L z = (1, 2, 3) checked by multiplying back
        for i in 0..3 {
            let s: f64 = (0..3).map(|p| l[i * 3 + p] * b[p]).sum();
            assert!((s - [1.0, 2.0, 3.0][i]).abs() < 1e-14);
        }
        assert!(!cholesky(&[1.0, 2.0, 2.0, 1.0], 2, 0.0, &mut l));
        assert!(cholesky(&[1.0, 2.0, 2.0, 1.0], 2, 2.0, &mut l));
    }

    #[test]
    fn pinv_inverts_a_regular_matrix_and_drops_a_null_direction() {
        let mut a = [4.0, 1.0, 0.5, 1.0, 3.0, 0.2, 0.5, 0.2, 2.0];
        let orig = a;
        let (mut v, mut inv) = ([0.0; 9], [0.0; 9]);
        pinv_sym(&mut a, 3, &mut v, &mut inv);
        for i in 0..3 {
            for j in 0..3 {
                let s: f64 = (0..3).map(|k| orig[i * 3 + k] * inv[k * 3 + j]).sum();
                assert!((s - if i == j { 1.0 } else { 0.0 }).abs() < 1e-14);
            }
        }
        let mut s = [1.0, 1.0, 1.0, 1.0]; // rank 1: pinv = s / 4
        let (mut v2, mut inv2) = ([0.0; 4], [0.0; 4]);
        pinv_sym(&mut s, 2, &mut v2, &mut inv2);
        for e in inv2 {
            assert!((e - 0.25).abs() < 1e-15, "{inv2:?}");
        }
    }
}

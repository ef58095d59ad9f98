"""Covariance of overlapping Allan variance estimates across τ, from the noise model.

The overlapping estimate at averaging factor m is σ̂²(m) = (1/2M) Σ_k u_k², M = n + 1 − 2m, with
u_k = (x_{k+2m} − 2x_{k+m} + x_k)/(mτ0) the second difference of the phase (angle) x. For a Gaussian
process, Cov(u_k², v_l²) = 2 E[u_k v_l]², and with a deterministic ramp u_k = Rτ + s_k the cross
term adds 4 R²τ_iτ_j E[s_k s_l]. Every term of the IEEE-952 model has a *generalized covariance*
G(h) of the phase (Matheron's intrinsic random functions of order 1): for weights that annihilate
straight lines — as the second difference does — E[(Σλ_p x_p)(Σμ_q x_q)] = Σ λ_p μ_q G(q − p). Per
unit squared coefficient, with h in samples:

=====  ==============================  =========================================================
term   G(h)                             check: Allan variance from the 3 × 3 sum at lags 0, m, 2m
=====  ==============================  =========================================================
Q      δ_h                              3Q²/τ²             (white angle, variance Q²)
N      −τ0·|h|/2                        N²/τ               (white rate, variance N²/τ0)
B      τ0²·h²·ln|h| / (2π)              (2 ln2/π)·B²       (flicker rate, continuous-time form)
K      τ0³·(|h|³ − |h|)/12              K²τ0(2m² + 1)/(6m) (sampled random walk of rate: exact)
=====  ==============================  =========================================================

So Cov(σ̂²_i, σ̂²_j) = (1/M_iM_j) Σ_d c_ij(d)·[r_ij(d)²/2 + R²τ_iτ_j·r_ij(d)], r_ij(d) = E[u^i_k u^j_{k+d}]
(linear in the squared coefficients), c_ij(d) the number of index pairs (k, k + d). The lag sum is
exact on short stretches and on the breakpoints, and a Gauss–Legendre integral of the smooth pieces
in between (Euler–Maclaurin error < 1e-3 relative); for flicker, whose correlation has a long tail,
the tail is integrated on octave-growing pieces out to the record length.

Only the overlapping estimator is covered (the classic estimator and Theo keep the octave-correlation
model of :func:`allanite.fit`).
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ._recent import Suffixes

#: Stochastic terms with a kernel, in the order of the returned blocks.
KERNEL_TERMS = ("Q", "N", "B", "K")
_GL_X, _GL_W = np.polynomial.legendre.leggauss(8)
_EXACT_RUN = 48  # interior stretches up to this many integers are summed exactly


def _kernels(h: np.ndarray, tau0: float) -> np.ndarray:
    """G(h) for Q, N, B, K at real lags h (samples); shape (4, h.size)."""
    a = np.abs(h)
    out = np.empty((4,) + h.shape)
    out[0] = (a == 0).astype(np.float64)
    out[1] = -0.5 * tau0 * a
    with np.errstate(divide="ignore", invalid="ignore"):
        out[2] = np.where(a > 0, a * a * np.log(np.where(a > 0, a, 1.0)), 0.0) * (tau0 * tau0 / (2.0 * math.pi))
    out[3] = (a * a * a - a) * (tau0**3 / 12.0)  # products, not a**3: numpy's pow is ~10× a multiplication
    return out


def _cross(d: np.ndarray, mi, mj, tau0: float) -> np.ndarray:
    """r_ij(d) per unit squared coefficient of each kernel term: shape (4, d.size); ``mi``, ``mj`` the pair's
    averaging factors, integers or integer arrays like ``d`` (many pairs' lags at once, each with its own).

    Outside [−2m_j, 2m_i] the two second differences share no sample: the Q, N and K kernels (δ, |h|,
    |h|³) give exactly zero there — set so, rather than computed as a difference of huge numbers. The
    flicker kernel has a tail; far out (|d| ≥ 4 × the offsets' span) it is summed as its Taylor series
    Σ_k G⁽ᵏ⁾(d)·S_k/k! with S_k = Σλ_aλ_b·o_ab^k (S_k = 0 for k < 4), which keeps full precision where
    the nine-term sum of h²·ln|h| would cancel catastrophically (10⁸-sample records)."""
    mi = np.broadcast_to(np.asarray(mi, dtype=np.int64), d.shape)
    mj = np.broadcast_to(np.asarray(mj, dtype=np.int64), d.shape)
    lam = (1.0, -2.0, 1.0)
    weights = [lam[a] * lam[b] for a in range(3) for b in range(3)]
    acc = np.zeros((4, d.size))
    far = np.abs(d) >= 4.0 * (2 * mi + 2 * mj)
    near = ~far
    dn, mi_n, mj_n = d[near], mi[near], mj[near]  # the offsets on the near lags alone (the same integers)
    acc_near = np.zeros((4, dn.size))
    for w, (a, b) in zip(weights, [(a, b) for a in range(3) for b in range(3)]):
        acc_near += w * _kernels(dn + (b * mj_n - a * mi_n).astype(np.float64), tau0)
    acc[:, near] = acc_near
    outside = (d > 2 * mi) | (d < -2 * mj)
    acc[0, outside] = acc[1, outside] = acc[3, outside] = 0.0
    if far.any():
        # G(h) = h²ln|h| (times τ0²/2π): G⁽ᵏ⁾(h) = 2(−1)^(k−1)(k−3)!/h^(k−2) for h > 0, k ≥ 3; G is even.
        df = d[far]
        ad = np.abs(df)
        sgn = np.sign(df)
        # S_k per pair of averaging factors, then per lag
        mi_f, mj_f = mi[far], mj[far]
        span = int(mj_f.max()) + 1
        if (int(mi_f.max()) + 1) * span < 2**62:  # one integer per pair of averaging factors
            _u, first, back = np.unique(mi_f * span + mj_f, return_index=True, return_inverse=True)
        else:
            _u, first, back = np.unique(np.stack([mi_f, mj_f]), axis=1, return_index=True, return_inverse=True)
            back = back.ravel()
        of = [(b * mj_f[first] - a * mi_f[first]).astype(np.float64) for a in range(3) for b in range(3)]
        total = np.zeros(df.size)
        # 1/|d|^(k−2) and sgn^k by products from one k to the next (pow over every lag, twice per k, was most of
        # this loop's time); a term whose S_k is 0 adds 0, as 1/|d| is finite here (|d| ≥ 4·(2m_i + 2m_j) > 0).
        # In place, into two buffers: c_k·sgn·|d|^−(k−2) is c_k·(sgn·|d|^−(k−2)) to the bit (sgn is ±1)
        inv = 1.0 / ad
        inv_pow = inv * inv
        term = np.empty(df.size)
        for k in range(4, 17):
            s_k = weights[0] * of[0] ** k
            for w, o in zip(weights[1:], of[1:]):
                s_k = s_k + w * o**k
            c_k = s_k * (2.0 * (-1.0) ** (k - 1) * math.factorial(k - 3) / math.factorial(k))
            np.take(c_k, back, out=term)
            if k % 2:
                term *= sgn
            term *= inv_pow
            total += term
            inv_pow *= inv
        acc[2, far] = total * (tau0 * tau0 / (2.0 * math.pi))
    return acc / ((mi * mj) * tau0 * tau0)


def _nodes(mi, mj, big_m_i, big_m_j, long_tail: bool):
    """Quadrature nodes and weights for Σ_d c(d)·f(d) over d ∈ [−(M_i − 1), M_j − 1] of each pair of averaging
    factors (integer arrays ``mi``, ``mj``, ``big_m_i``, ``big_m_j``; f smooth between breakpoints; zero outside
    (−2m_j, 2m_i) unless ``long_tail``), all pairs at once. Returns (d, weight·c(d), nodes per pair): each pair's
    breakpoints in increasing order, then the nodes between them (every integer of a short stretch,
    Gauss–Legendre nodes on a long one), the pairs one after another."""
    mi, mj, big_m_i, big_m_j = (np.asarray(v, dtype=np.int64) for v in (mi, mj, big_m_i, big_m_j))
    pts, pair = _breakpoints(mi, mj, big_m_i, big_m_j, long_tail)
    # between consecutive breakpoints of a pair
    same = pair[1:] == pair[:-1]
    a, b, p_of = pts[:-1][same], pts[1:][same], pair[:-1][same]
    n_in = (b - a).astype(np.int64) - 1
    exact = (n_in > 0) & (n_in <= _EXACT_RUN)
    counts = np.where(exact, n_in, np.where(n_in > _EXACT_RUN, _GL_X.size, 0))
    piece = np.repeat(np.arange(a.size), counts)
    at = np.arange(piece.size) - np.repeat(np.cumsum(counts) - counts, counts)
    gl_at = np.minimum(at, _GL_X.size - 1)
    lo_x, hi_x = a + 0.5, b - 0.5
    half = 0.5 * (hi_x - lo_x)
    mid = 0.5 * (hi_x + lo_x)
    on_int = exact[piece]
    x = np.where(on_int, a[piece] + 1 + at, mid[piece] + half[piece] * _GL_X[gl_at])
    wx = np.where(on_int, 1.0, half[piece] * _GL_W[gl_at])
    # each pair's breakpoints, then its nodes
    n_p = mi.size
    n_pts = np.bincount(pair, minlength=n_p)
    n_x = np.bincount(p_of, weights=counts, minlength=n_p).astype(np.int64)
    sizes = n_pts + n_x
    start = np.cumsum(sizes) - sizes
    order = np.empty(pts.size + x.size, dtype=np.int64)
    order[: pts.size] = start[pair] + np.arange(pts.size) - np.repeat(np.cumsum(n_pts) - n_pts, n_pts)
    x_pair = p_of[piece]
    order[pts.size :] = start[x_pair] + n_pts[x_pair] + np.arange(x.size) - np.repeat(np.cumsum(n_x) - n_x, n_x)
    d, w = np.empty(order.size), np.empty(order.size)
    d[order] = np.concatenate([pts, x])
    w[order] = np.concatenate([np.ones(pts.size), wx])
    who = np.repeat(np.arange(n_p), sizes)
    count = np.minimum(big_m_i[who], big_m_j[who] - d) - np.maximum(0.0, -d)
    return d, w * np.clip(count, 0.0, None), sizes


def _breakpoints(mi, mj, big_m_i, big_m_j, long_tail: bool):
    """Each pair's breakpoints of the lag sum (sorted, each once; as float) and the pair each belongs to."""
    lo, hi = -(big_m_i - 1), big_m_j - 1
    s_lo, s_hi = np.maximum(lo, -2 * mj), np.minimum(hi, 2 * mi)
    cands = [s_lo, s_hi, np.zeros_like(mi), big_m_j - big_m_i] + [a * mi - b * mj for a in range(3) for b in range(3)]
    a_lo, a_hi = s_lo, s_hi
    if long_tail:
        cands += [lo, hi]
        top = int(np.max(np.maximum(hi, -lo))) + 1
        up, down = np.minimum(2 * mi, top), np.minimum(2 * mj, top)
        for _k in range(top.bit_length() + 1):  # 2m·2^k below the far end, on either side (saturating at top)
            cands += [np.where(up < hi, up, lo - 1), np.where(down < -lo, -down, lo - 1)]
            up, down = np.minimum(2 * up, top), np.minimum(2 * down, top)
        a_lo, a_hi = lo, hi
    c = np.sort(np.stack(cands, axis=1), axis=1)
    keep = (c >= a_lo[:, None]) & (c <= a_hi[:, None])
    keep[:, 1:] &= c[:, 1:] != c[:, :-1]
    pair = np.broadcast_to(np.arange(mi.size)[:, None], c.shape)[keep]
    return c[keep].astype(np.float64), pair


def covariance_blocks(m, n_samples: int, fs: float, terms) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_blocks`, remembered for the last few (m, n, fs, terms) — a dynamic fit asks for the same
    blocks in every window, and repeated fits of same-length records share them. A request whose ``m`` ends a
    remembered one (``tau_range="auto"`` cuts the shortest τ one at a time) is its trailing sub-blocks, bit for
    bit: each block entry depends on its own pair of τ only. Read-only arrays."""
    key = tuple(int(v) for v in np.asarray(m).ravel())
    rest = (int(n_samples), float(fs), tuple(terms))
    hit = _RECENT.find(key, rest, strict=True)
    if hit is not None:
        (s_blk, t_blk), k = hit
        return _read_only(s_blk[:, :, k:, k:]), _read_only(t_blk[:, k:, k:])
    return _RECENT.put(key, rest, _blocks_cached(key, *rest))


#: The blocks last computed, by (m, n, fs, terms): where a request's m is a suffix of one, it is sliced from it.
_RECENT = Suffixes(8)


def _read_only(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.flags.writeable = False
    return a


@functools.lru_cache(maxsize=32)
def _blocks_cached(m: tuple, n_samples: int, fs: float, terms: tuple):
    s_blk, t_blk = _blocks(np.asarray(m, dtype=np.int64), n_samples, fs, terms)
    s_blk.flags.writeable = False
    t_blk.flags.writeable = False
    return s_blk, t_blk


def _blocks(m: np.ndarray, n_samples: int, fs: float, terms) -> tuple[np.ndarray, np.ndarray]:
    """Blocks from which the covariance of overlapping AVAR estimates at ``m`` is assembled.

    Returns ``(S, T)``: S[p, q] (n_τ × n_τ) multiplies θ_p·θ_q, T[p] multiplies θ_R·θ_p (only when
    "R" is in ``terms``), p, q over the stochastic terms of ``terms`` (θ = squared coefficients):
    Cov = Σ_pq θ_pθ_q S[p, q] + θ_R Σ_p θ_p T[p]. ``n_samples`` = rate samples (phase points − 1).
    """
    tau0 = 1.0 / float(fs)
    m = np.asarray(m, dtype=np.int64)
    stoch = [t for t in terms if t in KERNEL_TERMS]
    sel = [KERNEL_TERMS.index(t) for t in stoch]
    has_b = "B" in stoch
    n_tau, n_s = m.size, len(stoch)
    big_m = n_samples + 1 - 2 * m
    if np.any(big_m < 1):
        raise ValueError("every m must leave at least one overlapping difference (m ≤ n/2)")
    tau = m * tau0
    s_blk = np.zeros((n_s, n_s, n_tau, n_tau))
    t_blk = np.zeros((n_s, n_tau, n_tau))
    for chunk in _pair_chunks(n_tau):
        ci, cj = np.array(chunk, dtype=np.int64).T
        d_all, wc_all, sizes = _nodes(m[ci], m[cj], big_m[ci], big_m[cj], has_b)
        r_all = _cross(d_all, m[np.repeat(ci, sizes)], m[np.repeat(cj, sizes)], tau0)[sel]
        ends = np.cumsum(sizes)
        for (i, j), hi, size in zip(chunk, ends, sizes):
            r = np.ascontiguousarray(r_all[:, hi - size : hi])
            wc = wc_all[hi - size : hi]
            norm = 1.0 / (float(big_m[i]) * float(big_m[j]))
            rw = r * wc
            s = 0.5 * norm * (rw @ r.T)
            t = norm * tau[i] * tau[j] * rw.sum(axis=1)
            s_blk[:, :, i, j] = s_blk[:, :, j, i] = s
            t_blk[:, i, j] = t_blk[:, j, i] = t
    return s_blk, t_blk


def _pair_chunks(n_tau: int, size: int = 256):
    """The pairs (i ≤ j) of ``n_tau`` estimates, ``size`` at a time (their lags' kernels evaluated together)."""
    pairs = [(i, j) for i in range(n_tau) for j in range(i, n_tau)]
    for a in range(0, len(pairs), size):
        yield pairs[a : a + size]


def assemble(s_blk: np.ndarray, t_blk: np.ndarray, theta: np.ndarray, terms) -> np.ndarray:
    """Covariance matrix of the estimates for squared coefficients ``theta`` (ordered as ``terms``)."""
    stoch = [k for k, t in enumerate(terms) if t in KERNEL_TERMS]
    th = np.asarray(theta, dtype=np.float64)[stoch]
    cov = np.einsum("p,q,pqij->ij", th, th, s_blk)
    if "R" in terms:
        cov = cov + float(theta[list(terms).index("R")]) * np.einsum("p,pij->ij", th, t_blk)
    return cov

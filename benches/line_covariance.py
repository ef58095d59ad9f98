#!/usr/bin/env python3
"""The covariance of Allan estimates when a fixed spectral line is on the curve: simulated against the model.

A record y = l + w (l a fixed sinusoid or two, w Gaussian noise of the five terms) has overlapping Allan
estimates σ̂²_m = L_m + C_m + W_m: the line's own Allan variance (fixed), the noise's (exact covariance,
:func:`allanite.model.tracing.exact_covariance`) and the cross term C_m = (1/K)·Σ_k Δ_m l_k·Δ_m w_k = u_mᵀw,
linear in w, so Cov(C_i, C_j) = u_iᵀΣ_w u_j exactly and C has no covariance with W (third moments of Gaussian
noise vanish). The refine tests' covariance (:func:`allanite.model.refinement.calibrated.curve_test`) takes
for it one rank-one term per line, v·vᵀ with v = L_m·√(8P(f₀)/(A²N)) (P the noise's PSD per sample at f₀).

Over ``--draws`` seeded records per case this prints, for each covariance, the whitened residual's mean χ²/n
(1 when the covariance is right) against the estimates' true mean L_m + the noise's Allan variance:
'scaled' (the five terms' covariance scaled by model/terms — what the tests took before), 'noise + cross'
(the rank-one form), 'noise + exact cross' (u_iᵀΣ_w u_j summed over the samples, white and rate-random-walk
noise), and 'noise only'. Nothing here is tuned; no timing.

Usage::

    python benches/line_covariance.py                 # -> benches/results/line_covariance.md
    python benches/line_covariance.py --draws 100 --out /tmp/lc.md
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path

import numpy as np

import allanite
from allanite.model import tracing
from allanite.model.refinement.calibrated import noise_psd
from allanite.model.terms import design_matrix

HERE = Path(__file__).resolve().parent

#: name: (samples, fs, noise terms, their coefficients², lines as (amplitude, f0, phase))
CASES = {
    "white + line 2.9 Hz at 7.3 Hz (3.9σ)": (8192, 7.3, ("N",), (4e-3**2,), ((0.042, 2.9, 2.2),)),
    "white + line 1.0 Hz at 7.3 Hz (3.9σ)": (8192, 7.3, ("N",), (4e-3**2,), ((0.042, 1.0, 2.2),)),
    "white + lines 3.3, 11.7 Hz at 100 Hz": (8192, 100.0, ("N",), (2e-3**2,), ((0.02, 3.3, 0.1), (0.015, 11.7, 1.0))),
    "white + RRW + line 0.3 Hz at 100 Hz": (8192, 100.0, ("N", "K"), (2e-3**2, 2e-3**2), ((0.01, 0.3, 0.4),)),
    "the same, 65 536 samples": (65536, 100.0, ("N", "K"), (2e-3**2, 2e-3**2), ((0.01, 0.3, 0.4),)),
}


def oavar(y: np.ndarray, ms: np.ndarray) -> np.ndarray:
    """Overlapping Allan variance of rate samples ``y`` at averaging factors ``ms``."""
    x = np.concatenate([[0.0], np.cumsum(y)])
    return np.array([0.5 * np.mean(((x[2 * m :] - 2 * x[m:-m] + x[: -2 * m]) / m) ** 2) for m in ms])


def exact_cross(line: np.ndarray, ms: np.ndarray, fs: float, coef: dict) -> np.ndarray:
    """u_iᵀΣ_w u_j for white (N) and rate-random-walk (K) noise, summed over the samples."""
    n = line.size
    x = np.concatenate([[0.0], np.cumsum(line)])
    u = np.empty((ms.size, n))
    for i, m in enumerate(ms):
        d = (x[2 * m :] - 2 * x[m:-m] + x[: -2 * m]) / m
        k = d.size
        g = np.zeros(n + 1)  # C = (1/K)·Σ_p g_p·X_p with X the noise's cumulative sum
        g[2 * m : 2 * m + k] += d / m
        g[m : m + k] -= 2 * d / m
        g[:k] += d / m
        u[i] = np.cumsum(g[::-1])[::-1][1:] / k
    out = coef.get("N", 0.0) * fs * (u @ u.T)
    if coef.get("K", 0.0):
        tail = np.cumsum(u[:, ::-1], axis=1)[:, ::-1]  # a random walk's increments: Σ_w = var_e·min(i, j)
        out += coef["K"] / fs * (tail @ tail.T)
    return out


def run_case(name: str, draws: int, seed: int) -> list[tuple[str, float]]:
    n, fs, terms, theta, lines = CASES[name]
    coef = dict(zip(terms, theta))
    ms = np.unique(np.round(2 ** np.arange(0, math.log2(n / 4), 0.25)).astype(np.int64))
    t = np.arange(n) / fs
    parts = [a * np.sin(2 * np.pi * f * t + ph) for a, f, ph in lines]
    line = np.sum(parts, axis=0)
    noise_mean = design_matrix(ms / fs, ms, fs, terms) @ np.asarray(theta)
    mu = noise_mean + oavar(line, ms)
    rng = np.random.default_rng(seed)
    kw = {k: math.sqrt(v) for k, v in coef.items()}
    est = np.array(
        [oavar(allanite.simulate(n, fs, seed=int(rng.integers(2**31)), **kw) + line, ms) for _ in range(draws)]
    )
    cov_n = tracing.exact_covariance(ms, n, fs, list(terms), np.asarray(theta))
    s = mu / noise_mean
    rank_one = cov_n.copy()
    for (a, f, _ph), part in zip(lines, parts):
        v = oavar(part, ms) * math.sqrt(8.0 * noise_psd(terms, theta, f, fs) / (a * a * n))
        rank_one += np.outer(v, v)
    covs = {
        "scaled": cov_n * np.outer(s, s),
        "noise + cross": rank_one,
        "noise + exact cross": cov_n + exact_cross(line, ms, fs, coef),
        "noise only": cov_n,
    }
    r = (est - mu).T
    out = []
    for label, c in covs.items():
        z = np.linalg.solve(np.linalg.cholesky(c), r)
        out.append((label, float(np.mean(np.sum(z * z, axis=0)) / ms.size)))
    return out


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--draws", type=int, default=400)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", type=Path, default=HERE / "results" / "line_covariance.md")
    args = ap.parse_args()
    rows = []
    for name in CASES:
        got = run_case(name, args.draws, args.seed)
        rows.append(f"| {name} | " + " | ".join(f"{q:.2f}" for _label, q in got) + " |")
        print(rows[-1], flush=True)
    head = [
        "# Allan estimates' covariance with a fixed spectral line on the curve",
        "",
        f"`python benches/line_covariance.py --draws {args.draws} --seed {args.seed}` — whitened residual's mean "
        "χ²/n over the draws, per covariance (1 when it is right); τ at 4 per octave, m = 1 … N/4.",
        "",
        "| case | scaled (before) | noise + cross (rank one per line, the tests' now) | noise + exact cross | noise only |",
        "|---|---|---|---|---|",
    ]
    args.out.write_text("\n".join(head + rows) + "\n")
    print("wrote", args.out)


if __name__ == "__main__":
    main()

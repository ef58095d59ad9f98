"""Paper 002 rebuilt with known truth: does the Hann window or the window-function combination help?

A fibre-optic gyro on a rate table swinging 5° at 0.5 Hz. The dynamic error (output − table rate)
holds a periodic trend (scale-factor error 2000 ppm and an asymmetric scale factor ∝ ω|ω|)
and noise: angle random walk modulated by the motion (N·(1 + 0.5·|ω|/ω_max)), bias instability and
rate random walk that step ×3 and ×4 halfway. Each method's coefficient series (window 401, hop 100)
is compared with the truth of every window:

  (a) one rectangular window on the raw dynamic error,
  (b) one Hann window on the raw dynamic error,
  (c) the combination (db5, 5 levels: trend A5 dropped, D5…D3 rect, D2…D1 Hann),
  (d) the combination with a fitted periodic trend instead of A5.

Then the six real ADIS16405 static runs: the scatter of the coefficient series with rect vs Hann.

Run: ``ALLANITE_SHARED_DATA=/work/shared/data python benches/paper002.py`` (≈ 2–4 min on 2 cores);
writes benches/results/paper002.md and the figures beside it.
"""

from __future__ import annotations

import gzip
import time
from pathlib import Path

import numpy as np

import _common
import allanite

OUT = _common.HERE / "results"
FS = 100.0
N_SAMPLES = 120_000
WINDOW, HOP = 401, 100
STEP_T = 600.0
N0, B0, K0 = 0.005, 0.01, 0.01
B1, K1 = 3 * B0, 4 * K0
TERMS = ("Q", "N", "B", "K")
SHOWN = ("N", "B", "K")
TAUS = np.unique(np.round(np.geomspace(1, 133, 16))) / FS


def table_rate(t):
    return 5.0 * np.pi * np.cos(np.pi * t)  # θ = 5°·sin(2π·0.5·t) → ω = 5π·cos(πt) °/s


def simulate(seed: int, with_trend: bool = True):
    t = np.arange(N_SAMPLES) / FS
    w = table_rate(t)
    wmax = 5.0 * np.pi
    mod = 1.0 + 0.5 * np.abs(w) / wmax
    rng = np.random.default_rng(seed)
    white = rng.normal(size=N_SAMPLES) * N0 * np.sqrt(FS) * mod
    slow = allanite.simulate(N_SAMPLES, FS, B=[(0.0, B0), (STEP_T, B1)], K=[(0.0, K0), (STEP_T, K1)], seed=seed + 1)
    trend = 2e-3 * w + 1e-4 * w * np.abs(w) if with_trend else 0.0
    return white + slow + trend, mod


def truth(mod):
    """The coefficients of every window: N from the window's mean-square modulation, B and K at its centre."""
    n_win = (N_SAMPLES - WINDOW) // HOP + 1
    c2 = np.concatenate([[0.0], np.cumsum(mod**2)])
    starts = np.arange(n_win) * HOP
    n_eff = N0 * np.sqrt((c2[starts + WINDOW] - c2[starts]) / WINDOW)
    centre = (starts + WINDOW / 2) / FS
    after = centre >= STEP_T
    return centre, {"N": n_eff, "B": np.where(after, B1, B0), "K": np.where(after, K1, K0)}


def series(method: str, y):
    kw = dict(window=WINDOW, hop=HOP, taus=TAUS)
    if method == "rect":
        return allanite.fit(allanite.davar(y, FS, **kw), terms=TERMS).values
    if method == "hann":
        return allanite.fit(allanite.davar(y, FS, taper="hann", **kw), terms=TERMS).values
    split = {"trend": "periodic"} if method == "combination, periodic trend" else None
    c = allanite.combine(y, FS, split=split, terms=TERMS, **kw)
    series.last = c  # type: ignore[attr-defined]
    return c.coefficients.values


def running_median(v, k=9):
    pad = np.pad(v, k // 2, mode="edge")
    return np.median(np.lib.stride_tricks.sliding_window_view(pad, k), axis=1)


def windows_to_90(t, v, term):
    """Windows after the first window that contains the step until the running median of the
    series first reaches 90 % of the step (from the before level to the after level)."""
    lo, hi = (B0, B1) if term == "B" else (K0, K1)
    sm = running_median(v)
    first = int(np.argmax(t + WINDOW / 2 / FS > STEP_T))
    hit = np.flatnonzero(sm[first:] >= lo + 0.9 * (hi - lo))
    return int(hit[0]) if hit.size else -1


METHODS = ("rect", "hann", "combination", "combination, periodic trend")


def experiment(seeds=(1, 2)):
    rows = {m: {k: [] for k in ("rms", "bias", "t90", "leak", "rms0", "bias0")} for m in METHODS}
    keep = {}
    for seed in seeds:
        y, mod = simulate(seed)
        y0, _ = simulate(seed, with_trend=False)
        t, tr = truth(mod)
        steady = np.abs(t - STEP_T) > WINDOW / FS  # windows that do not straddle the step
        for m in METHODS:
            v = series(m, y)
            v0 = series(m, y0)
            if seed == seeds[0]:
                keep[m] = (t, v)
                if m == "combination":
                    keep["combination object"] = series.last  # type: ignore[attr-defined]
            rel = {k: (v[k] - tr[k]) / tr[k] for k in SHOWN}
            rows[m]["rms"].append({k: float(np.sqrt(np.mean(rel[k][steady] ** 2))) for k in SHOWN})
            rows[m]["bias"].append({k: float(np.median(rel[k][steady])) for k in SHOWN})
            rows[m]["t90"].append({k: windows_to_90(t, v[k], k) for k in ("B", "K")})
            rel0 = {k: (v0[k] - tr[k]) / tr[k] for k in SHOWN}
            rows[m]["rms0"].append({k: float(np.sqrt(np.mean(rel0[k][steady] ** 2))) for k in SHOWN})
            rows[m]["bias0"].append({k: float(np.median(rel0[k][steady])) for k in SHOWN})
            rows[m]["leak"].append(
                {k: float(np.median(v[k][steady] - v0[k][steady]) / np.median(tr[k][steady])) for k in SHOWN}
            )
    return rows, keep, tr


def adis(runs_dir: Path):
    out = []
    for path in sorted(runs_dir.glob("adis16405_run*_100Hz.csv.gz")):
        with gzip.open(path, "rt") as fh:
            data = np.loadtxt((ln for ln in fh if not ln.startswith("#")), delimiter=",", skiprows=1, usecols=(0,))
        row = {"run": path.name.split("_")[1]}
        for taper in ("rect", "hann"):
            d = allanite.davar(
                data,
                100.0,
                window=6001,
                hop=5000,
                taus=np.unique(np.round(np.geomspace(1, 2000, 14))) / 100,
                taper=taper,
            )
            v = allanite.fit(d, terms=("Q", "N", "B", "K")).values
            for k in ("N", "B", "K"):
                med = np.median(v[k])
                row[f"{taper} {k}"] = (
                    float(med),
                    float(np.subtract(*np.percentile(v[k], [75, 25])) / med) if med > 0 else float("nan"),
                )
        out.append(row)
    return out


def plot(keep, tr):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(3, 1, figsize=(11, 9), sharex=True)
    for ax, k in zip(axes, SHOWN):
        for m in METHODS:
            t, v = keep[m]
            ax.plot(t, running_median(v[k]), lw=0.9, label=m)
        ax.plot(t, tr[k], "k--", lw=1.2, label="truth")
        ax.set_ylabel(f"{k} (running median of 9)")
        ax.set_yscale("log")
    axes[0].legend(fontsize=8, ncol=3)
    axes[-1].set_xlabel("window centre (s)")
    fig.tight_layout()
    fig.savefig(OUT / "paper002_series.png", dpi=80)
    fig = keep["combination object"].plot()
    fig.savefig(OUT / "paper002_combination.png", dpi=60)


def fmt_table(rows, key, terms, pct=True):
    head = "| method | " + " | ".join(terms) + " |\n|---|" + "---|" * len(terms) + "\n"
    body = ""
    for m in METHODS:
        vals = []
        for k in terms:
            xs = [r[k] for r in rows[m][key]]
            vals.append(" / ".join(f"{x:+.0%}" if pct else f"{x}" for x in xs))
        body += f"| {m} | " + " | ".join(vals) + " |\n"
    return head + body


def main():
    t0 = time.perf_counter()
    rows, keep, tr = experiment()
    cross = keep["combination object"].cross
    plot(keep, tr)
    data_dir = _common.shared_data_dir() / "adis16405"
    real = adis(data_dir) if data_dir.exists() else []
    elapsed = time.perf_counter() - t0
    md = [
        "# Paper 002 rebuilt: Hann window and window-function combination vs truth",
        "",
        f"Rerun: `ALLANITE_SHARED_DATA=/work/shared/data python benches/paper002.py` ({elapsed:.0f} s here).",
        "",
        f"Setting: fs = {FS:g} Hz, {N_SAMPLES} samples, window {WINDOW}, hop {HOP}, τ = 1…133 samples (16 τ); "
        f"FOG on a table swinging 5° at 0.5 Hz; trend 2000 ppm scale factor + 1e-4·ω|ω| (°/s); "
        f"N = {N0} °/√s × (1 + 0.5|ω|/ω_max); B {B0} → {B1} °/s and K {K0} → {K1} °/s/√s at t = {STEP_T:g} s. "
        "Fitted terms Q, N, B, K per window (`allanite.fit`, GLS). Two seeds, shown as seed 1 / seed 2. "
        "Relative errors over the windows that do not straddle the step.",
        "",
    ]
    md += READING + _tables(rows, cross) + _adis_table(real)
    (OUT / "paper002.md").write_text("\n".join(md) + "\n")
    print("\n".join(md))


#: the reading of the recorded run (seeds 1 and 2): fixed text, revised by hand when a rerun moves its numbers
READING = [
    "## Reading (of the recorded run, seeds 1 and 2)",
    "",
    "- **The Hann window does not help here.** On the same data its coefficient series are no closer to "
    "the truth than the rectangular window's (RMS error N 13–14 % vs 11 %, B 80 % vs 75 %), with or without "
    "the periodic trend; it keeps the same leakage of the table motion into K (+570 %), and its time "
    "resolution is the same within the noise. On the static ADIS16405 runs it gives the same medians and a "
    "wider scatter (IQR/median of B 0.30–0.49 vs 0.26–0.39): fewer effective degrees of freedom per "
    "window (≈ 2/3), as its EDF says. Leakage in the sense of paper 002 — power of the periodic trend "
    "entering the noise terms — is not a window-shape effect of the *squared differences*: the "
    "sinusoid's Allan variance is in every term, whatever their weights.",
    "- **Dropping A5 (the paper's split) removes the trend's leakage completely (0 %) — and the slow noise "
    "with it**: bias instability and rate random walk come out at −100 % (zero) in nearly every window, "
    "and the step in B and K is never seen. The high-pass near fs/64 = 1.6 Hz removes exactly the band "
    "where they live in a 4 s window.",
    "- **A fitted periodic trend at the table frequency is what helps**: leakage 0 %, B unbiased "
    "(−3 %), RMS error of B 59 % (vs 75 % rect on the raw error), and the step in B is seen within 4 "
    "windows. K stays poorly determined in 401-sample windows by every method (it needs τ ≫ the window).",
    "- The time-resolution entries of 0 windows for K with rect and Hann are an artefact: the trend's "
    "leakage already holds K above the post-step level before the step.",
    "- The band cross term of the db5 split is small (≤ 0.7 % of the total at every τ): summing the band "
    "DAVARs is a fair stand-in for the DAVAR of the summed bands.",
    "",
]


def _tables(rows, cross) -> list[str]:
    """The simulated experiment's tables (error, bias, time resolution, leakage, without the trend), the band
    cross terms and the figures."""
    return [
        "## RMS relative error of each coefficient series",
        "",
        fmt_table(rows, "rms", SHOWN),
        "## Bias (median relative error)",
        "",
        fmt_table(rows, "bias", SHOWN),
        "## Time resolution: windows (hop 100 = 1 s) from the first window holding the step to 90 % of the step",
        "",
        "(running median of 9 windows; −1: never reached)",
        "",
        fmt_table(rows, "t90", ("B", "K"), pct=False),
        "## Periodic-trend leakage: median(with trend − without trend) / truth, same noise",
        "",
        fmt_table(rows, "leak", SHOWN),
        "## Without the periodic trend (same noise): RMS relative error",
        "",
        fmt_table(rows, "rms0", SHOWN),
        "## Without the periodic trend: bias",
        "",
        fmt_table(rows, "bias0", SHOWN),
        "## Band cross terms of the combination",
        "",
        "2·C(low, high)/AVAR(low + high), median over windows, per τ (db5 split, rect windows): "
        f"max |·| = {np.max(np.abs(cross)):.3f}, values {', '.join(f'{v:+.3f}' for v in cross)}.",
        "",
        "![coefficient series](paper002_series.png)",
        "",
        "![combination, paper 002 Fig. 4–5 style](paper002_combination.png)",
        "",
    ]


def _adis_table(real) -> list[str]:
    """The six static ADIS16405 runs: median and relative IQR of the rect and Hann coefficient series."""
    md = [
        "## ADIS16405, six static runs (gyro x): median and relative IQR of the coefficient series",
        "",
        "window 6001 (60 s), hop 5000, τ = 0.01…20 s; entries `median (IQR/median)` in base form (N °/√s, "
        "B °/s, K °/s/√s); K is fitted as zero in every window of every run (60 s windows hold no random walk "
        "this sensor resolves).",
        "",
        "| run | rect N | hann N | rect B | hann B | rect K | hann K |",
        "|---|---|---|---|---|---|---|",
    ]
    for r in real:
        cells = [
            f"{r[f'{tp} {k}'][0]:.3g} ({r[f'{tp} {k}'][1]:.2f})" for k in ("N", "B", "K") for tp in ("rect", "hann")
        ]
        md.append(f"| {r['run']} | " + " | ".join(cells) + " |")
    return md


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""TheoH / DHVAR benchmark and paper 001 reproduction.

Part 1 — timings (the issue's targets), each against a baseline in the same run:

1. TheoH of N = 1e5 white-rate samples on the exponential τ grid: ``allanite.avar(estimator="theoh")``
   (target ≤ 2 s); the overlapping Allan variance of the same record on the same grid is timed for scale.
2. Theo1 of N = 1e4 on an octave grid of even m: allanite vs ``allantools.theo1`` (one run; target
   ≥ 1000×). Values are compared at allantools' own m, i.e. with its τ = m·τ0 label corrected to
   0.75·m·τ0.
3. DHVAR on N = 4e4, window 401, hop 1 (paper 001's measured-gyro case): ``allanite.davar(estimator=
   "theoh")`` (target ≤ 0.5 s), with DAVAR on the same windows for scale.

Part 2 — paper 001's simulation rebuilt: 1200 s at 25 Hz (40 ms sampling as the paper's gyro), a
first-order Gauss–Markov bias with variance 0.001 (°/s)² outside 400–800 s and 0.01 inside
(T_c = 2.5 s, so its Allan bump sits at τ ≈ 4.7 s, in the paper's "3–6 s"), plus white rate noise
(0.01 °/√s) and a little quantization; window 401 samples, hop 25 (1 s). The paper gives neither
the sampling rate, nor T_c, nor the white level: those are our choices, stated here.
DAVAR, DHVAR-A and DHVAR are computed, the five terms are fitted in every window, and:
- a table like the paper's Table 1: mean of each coefficient over the windows vs the whole-record
  Allan fit ("expected");
- the scatter of the estimates across the windows inside the stationary stretch 0–400 s at matched
  τ (relative spread, and RMS error against the closed-form Allan variance of the simulated process);
- figure: the three surfaces side by side.

Usage::

    python benches/theo.py                    # full run -> benches/results/theo.{json,md,png}
    python benches/theo.py --quick --out DIR  # smoke run (seconds), not a timing check

Needs allantools for part 1.2 (``pip install -e '.[bench]'``); skipped with a note when absent.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
from pathlib import Path

import numpy as np

import _common

HERE = Path(__file__).resolve().parent

SEED = 20261122

CONFIGS = {
    "full": {
        "theoh_n": 100_000,
        "theo1_n": 10_000,
        "dhvar_n": 40_000,
        "dhvar_window": 401,
        "repeats": 3,
        "paper_seconds": 1200.0,
        "paper_hop": 25,
    },
    "quick": {
        "theoh_n": 5_000,
        "theo1_n": 600,
        "dhvar_n": 4_000,
        "dhvar_window": 401,
        "repeats": 1,
        "paper_seconds": 240.0,
        "paper_hop": 100,
    },
}
TARGETS = {"theoh_seconds": 2.0, "theo1_speedup_vs_allantools": 1000.0, "dhvar_seconds": 0.5}

FS = 25.0
GM_TC = 2.5
GM_VAR_QUIET, GM_VAR_LOUD = 0.001, 0.01
WHITE_N = 0.01  # °/√s
QUANT = 1e-4  # °


def part_timings(cfg: dict) -> dict:
    rng = np.random.default_rng(SEED)
    reps = cfg["repeats"]
    # one generator, drawn in this order: TheoH's record, then Theo1's, then DHVAR's
    return {
        "theoh": _time_theoh(rng.normal(size=cfg["theoh_n"]), reps),
        "theo1": _time_theo1(rng.normal(size=cfg["theo1_n"]), reps),
        "dhvar": _time_dhvar(rng.normal(size=cfg["dhvar_n"]), cfg["dhvar_window"], reps),
    }


def _time_theoh(y, reps) -> dict:
    """1. TheoH, N = 1e5, exp grid, against OAVAR on the same grid."""
    import allanite

    with _common.OtherLoad() as load:
        best, times, r = _common.timed(lambda: allanite.avar(y, 1.0, estimator="theoh", taus="exp"), reps, warmup=True)
        a_best, a_times, _ = _common.timed(lambda: allanite.avar(y, 1.0, taus="exp"), reps, warmup=True)
    _common.log(f"TheoH N={y.size}: {best:.3f} s ({r.tau.size} τ; OAVAR same grid {a_best:.3f} s)")
    return {
        "n": y.size,
        "grid": "exp",
        "tau_points": int(r.tau.size),
        "seconds": best,
        "repeats": times,
        "oavar_seconds": a_best,
        "oavar_repeats": a_times,
        "kf": r.kf,
        "theobr_points": int(np.sum(r.source == "theobr")),
        "other_processes_cpu_fraction": load.fraction,
    }


def _time_theo1(y, reps) -> dict:
    """2. Theo1 vs allantools, N = 1e4, octave grid of even m."""
    import allanite

    ms = [m for m in (10, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 8192) if m <= y.size]
    with _common.OtherLoad() as load:
        best, times, r = _common.timed(
            lambda: allanite.avar(y, 1.0, estimator="theo1", taus=0.75 * np.array(ms)), reps, warmup=True
        )
    entry = {"n": y.size, "m": ms, "seconds": best, "repeats": times, "other_processes_cpu_fraction": load.fraction}
    try:
        import allantools
    except ImportError:
        entry["allantools"] = "not installed"
        return entry
    with _common.OtherLoad() as load:
        t_at, _, res = _common.timed(
            lambda: allantools.theo1(y, rate=1.0, data_type="freq", taus=np.array(ms, dtype=float)), 1
        )
    taus_at, dev_at = np.asarray(res[0]), np.asarray(res[1])
    m_at = np.round(taus_at).astype(int)
    ours = {int(m): v for m, v in zip(r.m, r.avar)}
    common = [i for i, m in enumerate(m_at) if m in ours]
    diff = max(abs(dev_at[i] ** 2 / ours[m_at[i]] - 1) for i in common) if common else None
    entry.update(
        {
            "allantools_seconds": t_at,
            "speedup": t_at / best,
            "allantools_version": allantools.__version__,
            "allantools_m": m_at.tolist(),
            "allantools_tau_label": taus_at.tolist(),
            "compared_points": len(common),
            "max_rel_diff_variance": diff,
            "allantools_other_processes_cpu_fraction": load.fraction,
        }
    )
    _common.log(
        f"Theo1 N={y.size}: allanite {best * 1e3:.2f} ms, allantools {t_at:.1f} s → {t_at / best:.0f}×, "
        f"max rel diff {diff:.2e} at corrected τ"
    )
    return entry


def _time_dhvar(y, w, reps) -> dict:
    """3. DHVAR, N = 4e4, window 401, hop 1, against DAVAR on the same windows."""
    import allanite

    with _common.OtherLoad() as load:
        best, times, d = _common.timed(
            lambda: allanite.davar(y, 25.0, window=w, hop=1, estimator="theoh", taus="exp"), reps, warmup=True
        )
        a_best, a_times, da = _common.timed(
            lambda: allanite.davar(y, 25.0, window=w, hop=1, taus="exp"), reps, warmup=True
        )
    _common.log(f"DHVAR N={y.size} W={w}: {best:.3f} s ({d.tau.size} τ × {d.t.size} windows); DAVAR {a_best:.3f} s")
    return {
        "n": y.size,
        "window": w,
        "hop": 1,
        "windows": int(d.t.size),
        "tau_points": int(d.tau.size),
        "seconds": best,
        "repeats": times,
        "davar_seconds": a_best,
        "davar_repeats": a_times,
        "davar_tau_points": int(da.tau.size),
        "other_processes_cpu_fraction": load.fraction,
    }


def simulate_paper001(seconds: float, seed: int = SEED):
    import allanite

    n = int(round(seconds * FS))
    third = seconds / 3.0
    sig = [(0.0, math.sqrt(GM_VAR_QUIET)), (third, math.sqrt(GM_VAR_LOUD)), (2 * third, math.sqrt(GM_VAR_QUIET))]
    return allanite.simulate(n, FS, Q=QUANT, N=WHITE_N, gauss_markov=[(sig, GM_TC)], seed=seed), (third, 2 * third)


def gm_avar(tau, var, tc):
    """Allan variance of a first-order Gauss–Markov rate of variance ``var`` and correlation time ``tc``."""
    x = tau / tc
    return var * tc**2 / tau**2 * (2 * x - 3 + 4 * np.exp(-x) - np.exp(-2 * x))


def true_avar(tau):
    """Closed form of the stationary (quiet) process: quantization + white rate + GM."""
    return 3 * QUANT**2 / tau**2 + WHITE_N**2 / tau + gm_avar(tau, GM_VAR_QUIET, GM_TC)


def part_paper001(cfg: dict, out_dir: Path) -> dict:
    import allanite
    import allanite.model.fitting as fit_mod

    y, (t1, t2) = simulate_paper001(cfg["paper_seconds"])
    window, hop = 401, cfg["paper_hop"]
    res = {
        "DAVAR": allanite.davar(y, FS, window=window, hop=hop, taus="all"),
        "DHVAR-A": allanite.davar(y, FS, window=window, hop=hop, taus="all", estimator="theoh_a"),
        "DHVAR": allanite.davar(y, FS, window=window, hop=hop, taus="all", estimator="theoh"),
    }
    unit = "deg/s"
    whole = allanite.avar(y, FS, taus="all")
    expected = fit_mod.fit(whole, unit=unit)
    table = {"expected": {k: c.ieee for k, c in expected.coefficients.items()}}
    series = {}
    for name, d in res.items():
        s = fit_mod.fit(d, unit=unit)
        series[name] = s
        table[name] = {k: float(np.mean(s.ieee[k])) for k in s.terms}
    ieee_units = (
        {k: c.ieee_unit for k, c in expected.coefficients.items()}
        if hasattr(next(iter(expected.coefficients.values())), "ieee_unit")
        else {}
    )
    quiet, scatter = _quiet_scatter(res, window, t1)
    narrowing = []
    for row in scatter:
        if "DAVAR" in row and "DHVAR" in row:
            narrowing.append(1 - row["DHVAR"]["rms_rel_error"] / row["DAVAR"]["rms_rel_error"])
    _paper001_figures(res, series, table, scatter, window, (t1, t2), out_dir)
    return {
        "seconds": cfg["paper_seconds"],
        "fs": FS,
        "window": window,
        "hop": hop,
        "gm_tc": GM_TC,
        "gm_var": [GM_VAR_QUIET, GM_VAR_LOUD],
        "white_N": WHITE_N,
        "quantization": QUANT,
        "loud_interval_s": [t1, t2],
        "quiet_windows": int(quiet.sum()),
        "table": table,
        "ieee_units": ieee_units,
        "scatter": scatter,
        "median_rms_error_reduction_dhvar_vs_davar": float(np.median(narrowing)) if narrowing else None,
        "kf_median": {n: float(np.median(d.kf)) for n, d in res.items() if d.kf is not None},
    }


def _quiet_scatter(res, window, t1):
    """(the quiet windows' mask, per picked τ each surface's scatter there against the closed form)."""
    # Scatter inside the stationary stretch (windows entirely before the loud part), at matched τ:
    # Theo τ = 0.75·m/fs; DAVAR evaluated at the same τ where it exists (m ≤ window/2).
    d0 = res["DAVAR"]
    quiet = (d0.t + window / 2 / FS) <= t1
    scatter = []
    theo_tau = res["DHVAR"].tau[res["DHVAR"].source == "theobr"]
    picks = [tau for tau in theo_tau if abs(round(tau * FS) - tau * FS) < 1e-9]
    picks = [p for p in picks if p >= 2.0][:: max(1, len(picks) // 8)]
    for tau in picks:
        row = {"tau": float(tau), "true_avar": float(true_avar(tau))}
        for name, d in res.items():
            i = np.flatnonzero(np.isclose(d.tau, tau))
            if i.size == 0:
                continue
            v = d.avar[i[0], quiet]
            row[name] = {
                "rel_spread": float(np.std(v) / np.mean(v)),
                "rms_rel_error": float(np.sqrt(np.mean((v / row["true_avar"] - 1) ** 2))),
                "mean_rel_bias": float(np.mean(v) / row["true_avar"] - 1),
            }
        scatter.append(row)
    return quiet, scatter


def _paper001_figures(res, series, table, scatter, window, loud, out_dir: Path) -> None:
    """theo_paper001_surfaces.png (the three surfaces) and theo_paper001_series.png (B per window, scatter)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    # Figure: the three surfaces side by side (log10 ADEV over t × τ).
    fig = plt.figure(figsize=(15, 4.6))
    for k, (name, d) in enumerate(res.items()):
        ax = fig.add_subplot(1, 3, k + 1, projection="3d")
        tt, ll = np.meshgrid(d.t, np.log10(d.tau))
        ax.plot_surface(tt, ll, np.log10(np.sqrt(d.avar)), cmap="viridis", linewidth=0, antialiased=False)
        ax.set_title(f"{name} (window {window})")
        ax.set_xlabel("t (s)")
        ax.set_ylabel("log10 τ (s)")
        ax.set_zlabel("log10 σ (°/s)")
        ax.set_zlim(-3.5, -0.5)
    fig.tight_layout()
    fig.savefig(out_dir / "theo_paper001_surfaces.png", dpi=90)
    plt.close(fig)

    fig, ax = plt.subplots(1, 2, figsize=(12, 4))
    for name, s in series.items():
        ax[0].plot(s.t, s.ieee["B"], label=name, lw=1)
    ax[0].axhline(table["expected"]["B"], color="k", ls="--", label="whole record")
    ax[0].axvspan(*loud, color="0.9")
    ax[0].set_xlabel("t (s)")
    ax[0].set_ylabel("B (°/h)")
    ax[0].legend()
    ax[0].set_title("bias instability per window (paper 001 Fig. 7)")
    for name in res:
        ax[1].plot(
            [r["tau"] for r in scatter if name in r],
            [r[name]["rms_rel_error"] for r in scatter if name in r],
            "o-",
            label=name,
        )
    ax[1].set_xscale("log")
    ax[1].set_xlabel("τ (s)")
    ax[1].set_ylabel("RMS relative error of σ² across quiet windows")
    ax[1].legend()
    fig.tight_layout()
    fig.savefig(out_dir / "theo_paper001_series.png", dpi=90)
    plt.close(fig)


def _fmt(v, digits=4):
    return "—" if v is None else f"{v:.{digits}g}"


def write_markdown(report: dict, path: Path) -> None:
    lines = _md_timings(report) + _md_paper001(report["paper001"])
    path.write_text("\n".join(lines))


def _md_timings(report: dict) -> list[str]:
    """The page's head and the timing table (TheoH, Theo1 against allantools, DHVAR) with its notes."""
    t = report["timings"]
    lines = [
        "# TheoH / DHVAR benchmark",
        "",
        f"Recorded by `benches/theo.py` on {report['machine'].get('date_utc')}; "
        f"{report['machine'].get('cpu_count')} CPUs. Times are best of {report['config']['repeats']} after a "
        "warm-up; every repeat is in theo.json.",
        "",
        "| case | allanite | baseline (same run) | ratio | target | met |",
        "|---|---|---|---|---|---|",
    ]
    th = t["theoh"]
    lines.append(
        f"| TheoH, N = {th['n']:,}, exp grid ({th['tau_points']} τ, {th['theobr_points']} TheoBR) | "
        f"{th['seconds']:.3f} s | OAVAR same grid {th['oavar_seconds']:.3f} s | "
        f"{th['seconds'] / th['oavar_seconds']:.0f}× OAVAR's time | ≤ 2 s | "
        f"{'yes' if th['seconds'] <= TARGETS['theoh_seconds'] else 'NO'} |"
    )
    t1 = t["theo1"]
    if "speedup" in t1:
        lines.append(
            f"| Theo1, N = {t1['n']:,}, m = {t1['m'][0]}…{t1['m'][-1]} (octave) | {t1['seconds'] * 1e3:.2f} ms | "
            f"allantools.theo1 {t1['allantools_seconds']:.1f} s | {t1['speedup']:,.0f}× | ≥ 1000× | "
            f"{'yes' if t1['speedup'] >= TARGETS['theo1_speedup_vs_allantools'] else 'NO'} |"
        )
    dh = t["dhvar"]
    lines.append(
        f"| DHVAR, N = {dh['n']:,}, window {dh['window']}, hop 1 ({dh['tau_points']} τ × {dh['windows']:,} "
        f"windows) | {dh['seconds']:.3f} s | DAVAR same windows {dh['davar_seconds']:.3f} s | — | ≤ 0.5 s | "
        f"{'yes' if dh['seconds'] <= TARGETS['dhvar_seconds'] else 'NO'} |"
    )
    if "max_rel_diff_variance" in t1:
        lines += [
            "",
            f"allantools.theo1 labels its values τ = m·τ0; at m (τ = 0.75·m·τ0) they equal allanite's Theo1 "
            f"to {_fmt(t1['max_rel_diff_variance'], 2)} relative ({t1['compared_points']} points).",
        ]
    loads = {k: v.get("other_processes_cpu_fraction") for k, v in t.items()}
    lines += [
        "",
        "Other processes' CPU share during each case: "
        + ", ".join(f"{k} {_fmt(100 * v, 2) if v is not None else '?'} %" for k, v in loads.items()),
        "",
    ]
    return lines


def _md_paper001(p: dict) -> list[str]:
    """Paper 001 rebuilt: the mean coefficients per surface, the quiet windows' scatter, the figures."""
    lines = [
        "## Paper 001 rebuilt: DAVAR vs DHVAR-A vs DHVAR",
        "",
        f"{p['seconds']:.0f} s at {p['fs']:g} Hz; Gauss–Markov bias (T_c = {p['gm_tc']} s) of variance "
        f"{p['gm_var'][0]} (°/s)² outside {p['loud_interval_s'][0]:.0f}–{p['loud_interval_s'][1]:.0f} s and "
        f"{p['gm_var'][1]} inside; white rate {p['white_N']} °/√s; quantization {p['quantization']} °. "
        f"Window {p['window']}, hop {p['hop']}. Mean of each fitted coefficient over all windows, vs the "
        'whole-record Allan fit (the paper\'s "expected"):',
        "",
        "| term | expected | DAVAR | DHVAR-A | DHVAR |",
        "|---|---|---|---|---|",
    ]
    units = {"Q": "°", "N": "°/√h", "B": "°/h", "K": "°/h^1.5", "R": "°/h²"}
    for k in ("Q", "N", "B", "K", "R"):
        row = [p["table"][c].get(k) for c in ("expected", "DAVAR", "DHVAR-A", "DHVAR")]
        lines.append(f"| {k} ({units[k]}) | " + " | ".join(_fmt(v) for v in row) + " |")
    lines += [
        "",
        f"Scatter across the {p['quiet_windows']} windows inside the stationary stretch (before "
        f"{p['loud_interval_s'][0]:.0f} s), at matched τ: RMS relative error of σ² against the closed form "
        "(relative spread std/mean in brackets). DAVAR stops at τ = window/2.",
        "",
        "| τ (s) | DAVAR | DHVAR-A | DHVAR |",
        "|---|---|---|---|",
    ]
    for row in p["scatter"]:
        cells = []
        for name in ("DAVAR", "DHVAR-A", "DHVAR"):
            c = row.get(name)
            cells.append("—" if c is None else f"{c['rms_rel_error']:.3f} ({c['rel_spread']:.3f})")
        lines.append(f"| {row['tau']:.2f} | " + " | ".join(cells) + " |")
    red = p["median_rms_error_reduction_dhvar_vs_davar"]
    lines += [
        "",
        f"Median reduction of the RMS error, DHVAR vs DAVAR, where both exist: {_fmt(100 * red, 3) if red is not None else '—'} % "
        "(paper 001 claims ≥ 30 % at medium/long τ).",
        "",
        "![surfaces](theo_paper001_surfaces.png)",
        "",
        "![series](theo_paper001_series.png)",
        "",
    ]
    return lines


def run(quick: bool = False, out: Path | None = None, wait: float = 0.0) -> dict:
    cfg = CONFIGS["quick" if quick else "full"]
    out = Path(out) if out is not None else (Path(tempfile.mkdtemp()) if quick else HERE / "results")
    out.mkdir(parents=True, exist_ok=True)
    idle = _common.wait_idle(wait) if wait > 0 else None
    report = {"config": cfg, "machine": _common.machine_info(), "idle_wait": idle}
    report["timings"] = part_timings(cfg)
    report["paper001"] = part_paper001(cfg, out)
    (out / "theo.json").write_text(json.dumps(report, indent=1, default=float))
    write_markdown(report, out / "theo.md")
    _common.log(f"wrote {out / 'theo.md'}")
    return report


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="small sizes, temporary output folder (smoke test)")
    ap.add_argument("--out", type=Path, help="output folder (default benches/results; temp with --quick)")
    ap.add_argument("--wait-idle", type=float, default=0.0, metavar="S", help="first wait ≤ S s for idle CPUs")
    args = ap.parse_args(argv)
    run(quick=args.quick, out=args.out, wait=args.wait_idle)
    return 0


if __name__ == "__main__":
    sys.exit(main())

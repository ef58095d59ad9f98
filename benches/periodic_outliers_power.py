#!/usr/bin/env python3
"""Power and accuracy of the line-family search (``"periodic"``) and the outlier test on records that carry them.

Each record is a null record of ``periodic_outliers_null.py`` (fs 1 Hz – 2 kHz, 10⁵–10⁶ samples, Q/N/B/K/R
mixtures, low-passes, quantisers) plus one effect, at the line search's α = 1 % and the outlier test's
α = 0.25 % (their proposed shares of refine's level 0.05), default arguments:

- ``square`` / ``sawtooth`` — a square or sawtooth wave of f0 (harmonics k·f0; aliases of a sampled
  waveform beyond f_s/2 too); truth [f0];
- ``am`` — a carrier fc amplitude-modulated (depth ½) at fm: lines fc, fc ± fm; truth [fc, fm];
- ``beat drop`` / ``beat repeat`` — a tone at f1 read by a sensor whose output drops (repeats) a sample every
  1/f2 s: the tone appears at f1·(1 ± f2/f_s) with sidebands every f2; truth [f1·(1 ± f2/f_s), f2];
- ``isolated`` — one sinusoid: it must stay a ``"sinusoid"`` (no family);
- ``imu`` — the consumer IMU of issue 29 (100 Hz, 10⁶ samples): f2 ≈ 0.19 Hz with two harmonics and
  sidebands ±f2 around every multiple of f1 = 1.37 Hz, each 12–90× the local median of the PSD;
- ``spikes`` — sparse spikes (share 10⁻⁵ … 10⁻³ of the samples, 6–20 white-noise σ); truth: the share;
- ``heavy`` — heavy-tailed white noise: a contaminated normal (≈ 30 % of samples with 4.5× the spread: ≈ 14 %
  beyond 4 robust σ, std ≈ 2.8× the robust σ — issue 29's gyro) or Student t with 3 degrees of freedom.

Sizes: the effect scaled so that its Allan deviation is ``size`` × the noise's at the τ (octaves) where the
ratio is largest — 3 is the issue's "detectable size"; smaller sizes give the power curve. Frequencies: f0,
fc, f1 log-uniform with every named line inside 20/T … 0.4·f_s (T the record). Reported per kind and size:
the share named right (a family for the periodic kinds, one sinusoid for ``isolated``; outliers accepted),
frequencies within 1 % (each true fundamental; a carrier modulo the found spacing), RMS within 20 %, χ²/dof of
the five-term fit before and after removing what was found (median; and after over the noise alone's — a
low-pass or a quantiser makes the noise itself misfit the five terms), and for outliers the flagged share
against the truth and N before/after against the true N.

Usage::

    python benches/periodic_outliers_power.py            # -> benches/results/periodic_outliers_power.{json,md}
    python benches/periodic_outliers_power.py --quick    # 2 records per kind, to a temporary folder
"""

from __future__ import annotations

import argparse
import json
import math
import os
import tempfile
import time
from pathlib import Path

import numpy as np

import _common
import allanite
from allanite.model import outliers, periodic
from periodic_outliers_null import LEVEL, LINE_SHARE, OUTLIER_SHARE
from periodic_outliers_null import record as null_record

HERE = Path(__file__).resolve().parent
PERIODIC = ("square", "sawtooth", "am", "beat drop", "beat repeat", "isolated")
IMPULSIVE = ("spikes", "heavy")


def _octave_adev(y, fs):
    m = 2 ** np.arange(0, int(math.log2(y.size // 9)) + 1)
    return allanite.avar(y, fs, taus=m / fs).adev


def _loguniform(rng, lo, hi):
    return float(10 ** rng.uniform(math.log10(lo), math.log10(hi)))


def periodic_effect(kind, rng, n, fs):
    """Unit-scale component and the truth: (component, fundamentals, rms per unit)."""
    t = np.arange(n) / fs
    length = n / fs
    lo, hi = 20.0 / length, 0.4 * fs
    if kind in ("square", "sawtooth"):
        f0 = _loguniform(rng, lo, hi / 3.0)  # at least the third harmonic inside the band
        ph = rng.uniform(0, 1)
        if kind == "square":
            return np.sign(np.sin(2 * np.pi * (f0 * t + ph))), [f0]
        return 2.0 * np.mod(f0 * t + ph, 1.0) - 1.0, [f0]
    if kind == "am":
        fm = _loguniform(rng, lo, hi / 8.0)
        fc = _loguniform(rng, 2.0 * fm + lo, hi - fm)
        return (1 + 0.5 * np.cos(2 * np.pi * fm * t)) * np.cos(2 * np.pi * fc * t + rng.uniform(0, 6)), [fc, fm]
    if kind.startswith("beat"):
        f2 = _loguniform(rng, lo, hi / 8.0)
        f1 = _loguniform(rng, 4.0 * f2 + lo, hi - 4 * f2)
        per = fs / f2
        k = np.arange(n)
        sign = 1.0 if kind == "beat drop" else -1.0
        src = k + sign * np.floor(k / per)
        return np.sin(2 * np.pi * f1 * src / fs + rng.uniform(0, 6)), [f1 * (1 + sign * f2 / fs), f2]
    f0 = _loguniform(rng, lo, hi)
    return np.sin(2 * np.pi * f0 * t + rng.uniform(0, 6)), [f0]


def _scale(noise, comp, fs, size):
    ratio = _octave_adev(comp, fs) / _octave_adev(noise, fs)
    return size / float(np.nanmax(ratio))


def _freq_ok(found, truth) -> bool:
    """Every true fundamental within 1 % of a found one; a two-generator truth's first (a carrier) modulo the
    found spacing (a lattice may name a sideband as its carrier)."""
    found = list(found)
    if len(truth) == 1:
        return any(abs(f / truth[0] - 1) < 0.01 for f in found)
    if len(found) != 2:
        return False
    g1, g2 = sorted(found, reverse=True)
    carrier, spacing = truth
    if abs(g2 / spacing - 1) >= 0.01:
        return False
    return min(abs(g1 + s * g2 - carrier) for s in range(-16, 17)) / carrier < 0.01


def _chi2(y, fs):
    return float(allanite.fit(allanite.avar(y, fs)).chi2_dof)


def run_periodic(kind, size, seed):
    y0, fs, feats = null_record(50_000 + seed)
    rng = np.random.default_rng(70_000 + seed)
    comp, truth = periodic_effect(kind, rng, y0.size, fs)
    comp = comp * _scale(y0, comp, fs, size)
    y = y0 + comp
    t0 = time.process_time()
    r = periodic.periodic_search(y, fs, LEVEL * LINE_SHARE)
    cpu = time.process_time() - t0
    want_family = kind != "isolated"
    got = r["families"] if want_family else r["sinusoids"]
    named = bool(got) and (len(r["families"]) == 0 if not want_family else True)
    out = {
        "kind": kind,
        "size": size,
        "seed": seed,
        "fs": fs,
        "n": int(y.size),
        "features": feats,
        "truth": truth,
        "true_rms": float(np.std(comp)),
        "named": named,
        "families": [[float(g) for g in f.gens] for f in r["families"]],
        "sinusoids": [float(s.gens[0]) for s in r["sinusoids"]],
        "cpu_s": cpu,
    }
    if got:
        best = got[0]
        found = [float(g) for g in best.gens]
        out.update(
            found=found,
            lines=int(best.coefs.shape[0]),
            rms=best.rms,
            freq_ok=_freq_ok(found, truth),
            rms_ok=abs(best.rms / out["true_rms"] - 1) < 0.2,
        )
        removed = sum(f.component() for f in r["families"] + r["sinusoids"])
        out["chi2_before"], out["chi2_after"] = _chi2(y, fs), _chi2(y - removed, fs)
        out["chi2_noise_only"] = _chi2(y0, fs)
        out["chi2_ratio"] = out["chi2_after"] / out["chi2_noise_only"]
    return out


def run_imu(seed):
    fs, n = 100.0, 1_000_000
    rng = np.random.default_rng(90_000 + seed)
    t = np.arange(n) / fs
    level = 0.02
    y = allanite.simulate(n, fs, N=level, B=1e-3, K=1e-5, seed=rng)
    y = np.round(y / 0.005) * 0.005
    s1, df = 2 * level**2, fs / 2**15
    f1, f2 = 1.37 * (1 + 0.02 * rng.normal()), 0.19 * (1 + 0.02 * rng.normal())
    comp = np.zeros(n)
    for h in (1, 2, 3):
        comp += math.sqrt(4 * (90 / h) * s1 * df) * np.cos(2 * np.pi * h * f2 * t + rng.uniform(0, 6))
    for k in range(1, int(0.45 * fs / f1)):
        a = math.sqrt(4 * (12 + 78 * math.exp(-k / 8)) * s1 * df)
        for sgn in (1, -1):
            comp += a * np.cos(2 * np.pi * (k * f1 + sgn * f2) * t + rng.uniform(0, 6))
    y = y + comp
    t0 = time.process_time()
    r = periodic.periodic_search(y, fs, LEVEL * LINE_SHARE)
    cpu = time.process_time() - t0
    removed = sum(f.component() for f in r["families"] + r["sinusoids"])
    fam = r["families"][0] if r["families"] else None
    return {
        "kind": "imu",
        "seed": seed,
        "truth": [f1, f2],
        "true_lines": 3 + 2 * (int(0.45 * fs / f1) - 1),
        "named": fam is not None and len(r["families"]) == 1,
        "found": [float(g) for g in fam.gens] if fam else None,
        "lines": int(fam.coefs.shape[0]) if fam else 0,
        "sinusoids": len(r["sinusoids"]),
        "freq_ok": bool(fam is not None and _freq_ok(fam.gens, [f1, f2])),
        "rms": fam.rms if fam else None,
        "true_rms": float(np.std(comp)),
        "rms_ok": bool(fam is not None and abs(fam.rms / np.std(comp) - 1) < 0.2),
        "chi2_before": _chi2(y, fs),
        "chi2_after": _chi2(y - removed, fs),
        "cpu_s": cpu,
    }


def run_impulsive(kind, seed):
    y0, fs, feats = null_record(60_000 + seed)
    rng = np.random.default_rng(80_000 + seed)
    n = y0.size
    sigma = 1.0 * math.sqrt(fs)  # the null records' white noise: N = 1 → σ = N·√f_s
    truth: dict = {}
    if kind == "spikes":
        share = _loguniform(rng, 1e-5, 1e-3)
        k = max(3, int(round(share * n)))
        at = rng.choice(np.arange(2, n - 2), k, replace=False)
        hit = np.zeros(n)
        hit[at] = rng.choice([-1.0, 1.0], k) * rng.uniform(6, 20, k) * sigma
        y = y0 + hit
        truth = {"rate": k / n}
    elif seed % 2 == 0:
        wild = (rng.random(n) < 0.3) * rng.normal(size=n) * 4.5 * sigma
        y = y0 + wild
        truth = {"model": "contaminated normal, 30 % × 4.5"}
    else:
        y = y0 + rng.standard_t(3, size=n) * sigma
        truth = {"model": "Student t, 3 dof"}
    d = y - np.median(y)
    rob = 1.4826 * np.median(np.abs(np.diff(y))) / math.sqrt(2)
    truth["beyond_4_robust_sigma"] = float(np.mean(np.abs(np.diff(y)) / math.sqrt(2) > 4 * rob))
    truth["std_over_robust"] = float(np.std(np.diff(y)) / math.sqrt(2) / rob)
    del d
    t0 = time.process_time()
    r = outliers.outlier_test(y, fs, LEVEL * OUTLIER_SHARE)
    cpu = time.process_time() - t0
    out = {
        "kind": kind,
        "seed": seed,
        "fs": fs,
        "n": n,
        "features": feats,
        "truth": truth,
        "named": bool(r["accepted"]),
        "note": r.get("note"),
        "cpu_s": cpu,
    }
    fit0 = allanite.fit(allanite.avar(y0, fs))
    fit_raw = allanite.fit(allanite.avar(y, fs))
    out["N_true"] = 1.0
    out["N_noise_only"] = float(fit0.coefficients["N"].value)
    out["N_before"] = float(fit_raw.coefficients["N"].value)
    out["chi2_before"] = float(fit_raw.chi2_dof)
    out["chi2_noise_only"] = float(fit0.chi2_dof)
    if r["accepted"]:
        clean = outliers.replace_outliers(y, r["flags"])
        fit_clean = allanite.fit(allanite.avar(clean, fs))
        out.update(
            rate=r["rate"],
            threshold=r["threshold"],
            cut=r["cut"],
            N_after=float(fit_clean.coefficients["N"].value),
            chi2_after=float(fit_clean.chi2_dof),
        )
        if kind == "spikes":
            out["rate_ok"] = abs(r["rate"] / truth["rate"] - 1) < 0.2
    return out


def run(per_kind: int, sizes, out: Path) -> dict:
    rows = []
    t_all = time.perf_counter()
    seed = 0
    for kind in PERIODIC:
        for size in sizes:
            for _ in range(per_kind):
                rows.append(run_periodic(kind, size, seed))
                seed += 1
            _common.log(f"{kind} size {size}: {time.perf_counter() - t_all:.0f} s")
    for s in range(max(1, per_kind // 3)):
        rows.append(run_imu(s))
    _common.log(f"imu: {time.perf_counter() - t_all:.0f} s")
    for kind in IMPULSIVE:
        for s in range(per_kind):
            rows.append(run_impulsive(kind, seed))
            seed += 1
        _common.log(f"{kind}: {time.perf_counter() - t_all:.0f} s")
    report = {
        "rows": rows,
        "seconds": time.perf_counter() - t_all,
        "machine": _common.machine_info(),
        "loadavg_end": list(os.getloadavg()),
    }
    out.mkdir(parents=True, exist_ok=True)
    (out / "periodic_outliers_power.json").write_text(json.dumps(report, indent=1, default=float))
    (out / "periodic_outliers_power.md").write_text(markdown(report, sizes))
    return report


def _share(rows, key):
    vals = [bool(r.get(key)) for r in rows]
    return f"{sum(vals)}/{len(vals)}"


def _med(rows, key):
    vals = [r[key] for r in rows if r.get(key) is not None]
    return f"{np.median(vals):.3g}" if vals else "—"


def markdown(rep, sizes) -> str:
    rows = rep["rows"]
    m = rep["machine"]
    lines = [
        "# Line families and outliers: power and accuracy",
        "",
        "Written by `benches/periodic_outliers_power.py` (cases in its docstring). Noise: the null records of "
        "`periodic_outliers_null.py` (fs 1 Hz – 2 kHz, 10⁵–10⁶ samples, Q/N/B/K/R, low-passes, quantisers). "
        f"{m.get('cpu_model')}, {m.get('git_commit')}, load average {m.get('loadavg_start')} → "
        f"{rep['loadavg_end']}; {rep['seconds']:.0f} s in all.",
        "",
        "## Line families (α = 1 %)",
        "",
        "| kind | size (ADEV ratio) | named right | frequencies within 1 % | RMS within 20 % | lines (median) "
        "| χ²/dof before → after (median) | after / noise alone (median) | CPU s (median) |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for kind in PERIODIC:
        for size in sizes:
            sub = [r for r in rows if r["kind"] == kind and r.get("size") == size]
            if not sub:
                continue
            lines.append(
                f"| {kind} | {size:g} | {_share(sub, 'named')} | {_share(sub, 'freq_ok')} | {_share(sub, 'rms_ok')} "
                f"| {_med(sub, 'lines')} | {_med(sub, 'chi2_before')} → {_med(sub, 'chi2_after')} "
                f"| {_med(sub, 'chi2_ratio')} | {_med(sub, 'cpu_s')} |"
            )
    imu = [r for r in rows if r["kind"] == "imu"]
    if imu:
        lines += [
            "",
            "## The consumer IMU of issue 29 (100 Hz, 10⁶ samples, quantised)",
            "",
            "| seed | one family | fundamentals found (truth) | lines (truth) | RMS (truth) | χ²/dof before → after "
            "| CPU s |",
            "|---|---|---|---|---|---|---|",
        ]
        for r in imu:
            found = ", ".join(f"{g:.5g}" for g in r["found"]) if r["found"] else "—"
            truth = ", ".join(f"{g:.5g}" for g in r["truth"])
            rms = f"{r['rms']:.3g}" if r["rms"] is not None else "—"
            lines.append(
                f"| {r['seed']} | {r['named']} | {found} ({truth}) | {r['lines']} ({r['true_lines']}) "
                f"| {rms} ({r['true_rms']:.3g}) | {r['chi2_before']:.3g} → {r['chi2_after']:.3g} | {r['cpu_s']:.1f} |"
            )
    lines += [
        "",
        "## Outliers (α = 0.25 %)",
        "",
        "| kind | accepted | flagged share vs truth (spikes: within 20 %) | N before → after (true 1; noise alone) "
        "| χ²/dof before → after (noise alone) | CPU s |",
        "|---|---|---|---|---|---|",
    ]
    for r in [r for r in rows if r["kind"] in IMPULSIVE]:
        t = r["truth"]
        truth = (
            f"{t['rate']:.3g}"
            if "rate" in t
            else f"{t['model']}; {100 * t['beyond_4_robust_sigma']:.1f} % beyond 4 σ_r"
        )
        got = f"{r['rate']:.3g}" if r.get("rate") is not None else "—"
        ok = f" ({'ok' if r.get('rate_ok') else 'off'})" if "rate_ok" in r else ""
        after = f"{r['N_after']:.3g}" if r.get("N_after") is not None else "—"
        chi_after = f"{r['chi2_after']:.3g}" if r.get("chi2_after") is not None else "—"
        lines.append(
            f"| {r['kind']} (fs {r['fs']:.3g}, n {r['n']}) | {r['named']} | {got} vs {truth}{ok} "
            f"| {r['N_before']:.3g} → {after} ({r['N_noise_only']:.3g}) | {r['chi2_before']:.3g} → {chi_after} "
            f"({r['chi2_noise_only']:.3g}) | {r['cpu_s']:.2f} |"
        )
    return "\n".join(lines) + "\n"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--per-kind", type=int, default=12)
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args(argv)
    out = a.out or (Path(tempfile.mkdtemp()) if a.quick else HERE / "results")
    sizes = (3.0,) if a.quick else (3.0, 1.0, 0.5)
    rep = run(2 if a.quick else a.per_kind, sizes, out)
    print(markdown(rep, sizes))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

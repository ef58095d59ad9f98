#!/usr/bin/env python3
"""``allanite.refine`` with default arguments on the Allan curves of five real IMUs (curves only, no samples).

``../shared/data/avar-curves`` holds the maximal-overlap Allan variance, one τ per octave, of every gyro and
accelerometer channel of five IMUs (computed by the R package ``avar`` on real static records): KVH 1750 (FOG,
1 kHz, 10⁶ samples), IMAR (FOG, 400 Hz, 4 h), LN200 (FOG, 400 Hz, 6 h), NavChip (MEMS, 250 Hz, 3.45 h) and
ADIS16405 (MEMS, 100 Hz, 10⁶). Per channel: the plain ``allanite.fit(curve)`` and ``allanite.refine(curve)``
beside it — χ²/dof of the start and of the final model, the steps, what is still unexplained
(``Refinement.unexplained`` in the report's words), the CPU time — and a sanity check of the white noise and
the bias instability against what is known of the sensor: the ``avar`` vignette's NavChip values and, for the
gyros, the plausible range of the sensor's class. The curves' units are not stated: the gyros are read as
rad/s (°/s for the ADIS16405, whose raw logs are in °/s and whose curve these are), which puts the IMAR at
the 0.1 °/√h an iMAR FSAS is specified at.

Usage::

    python benches/refine_curves.py            # -> benches/results/refine_curves.{json,md}
    python benches/refine_curves.py --sensor navchip --out /tmp/x
"""

from __future__ import annotations

import argparse
import math
import time
import warnings
from pathlib import Path

import _common
import allanite
from _common import load_avar_curve
from allanite.model.refinement.words import describe_region

HERE = Path(__file__).resolve().parent

#: Each sensor's class, the gyros' unit as read here, and the plausible range of its gyros' white noise N
#: (°/√h) and bias instability B (°/h): tactical/navigation fibre-optic gyros N 0.003–0.3, B 0.005–3;
#: MEMS gyros N 0.1–5, B 1–100.
SENSORS = {
    "kvh1750": ("FOG", "rad/s", (0.003, 0.3), (0.005, 3.0)),
    "imar": ("FOG", "rad/s", (0.003, 0.3), (0.005, 3.0)),
    "ln200": ("FOG", "rad/s", (0.003, 0.3), (0.005, 3.0)),
    "navchip": ("MEMS", "rad/s", (0.1, 5.0), (1.0, 100.0)),
    "adis": ("MEMS", "deg/s", (0.1, 5.0), (1.0, 100.0)),
}

#: The avar vignette's NavChip fit (SOURCE.txt): avlr slope read-offs pooled over the three axes, raw units.
NAVCHIP_VIGNETTE = {"gyro": {"N": 5.945877e-05, "K": 3.062325e-05}, "acc": {"N": 5.233402e-04, "K": 6.422082e-05}}


def _ieee(term: str, value: float, unit: str) -> float:
    """A gyro term in IEEE-952 units (N °/√h, B °/h) from the rate unit ``unit``."""
    deg = value * (180.0 / math.pi if unit == "rad/s" else 1.0)
    return deg * 60.0 if term == "N" else deg * 3600.0


def _sanity(sensor: str, channel: str, fit) -> dict:
    """N and B of ``fit`` against the class range (gyros) or the vignette (NavChip)."""
    cls, unit, n_rng, b_rng = SENSORS[sensor]
    c = fit.coefficients
    out: dict = {"class": cls}
    if channel.startswith("Gyro"):
        n, b = _ieee("N", c["N"].value, unit), _ieee("B", c["B"].value, unit)
        out |= {"N_ieee": n, "B_ieee": b, "N_ok": n_rng[0] <= n <= n_rng[1]}
        out["B_ok"] = b_rng[0] <= b <= b_rng[1] if b > 0 else None  # B = 0: no flicker floor resolved
    if sensor == "navchip":
        ref = NAVCHIP_VIGNETTE["gyro" if channel.startswith("Gyro") else "acc"]
        out["N_over_vignette"] = c["N"].value / ref["N"]
    return out


def run_channel(sensor: str, channel: str, res) -> dict:
    row: dict = {"sensor": sensor, "channel": channel, "fs": res.fs, "n": res.n_samples, "tau_points": res.tau.size}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        t0 = time.process_time()
        try:
            r = allanite.refine(res, progress=False)
        except Exception as exc:  # a crash is a result here
            row["error"] = f"{type(exc).__name__}: {exc}"
            return row
        row["cpu_seconds"] = time.process_time() - t0
        plain = allanite.fit(res)
    row["warnings"] = sorted({str(w.message) for w in caught})
    row["plain_chi2_dof"] = plain.chi2_dof
    row["start_chi2_dof"] = r.start.chi2_dof
    row["final_chi2_dof"] = r.fit.chi2_dof
    row["steps"] = [{"effect": s.effect, "params": s.params, "intervals": s.intervals} for s in r.steps]
    row["unexplained"] = [describe_region(u) for u in r.unexplained]
    row["sanity_plain"] = _sanity(sensor, channel, plain)
    row["sanity_refined"] = _sanity(sensor, channel, r.fit)
    row["silent_misfit"] = bool(r.fit.chi2_dof > 3.0 and not r.unexplained)
    return row


def _sane(s: dict) -> str:
    if "N_ieee" not in s:
        return f"N/vignette {s['N_over_vignette']:.2f}" if "N_over_vignette" in s else "—"
    mark = {True: "", False: " ✗", None: ""}
    text = f"N {s['N_ieee']:.3g}{mark[s['N_ok']]}, B {s['B_ieee']:.3g}{mark[s['B_ok']]}"
    if "N_over_vignette" in s:
        text += f" (N/vignette {s['N_over_vignette']:.2f})"
    return text


def _row(row) -> str:
    name = f"{row['sensor']} {row['channel']}"
    if "error" in row:
        return f"| {name} | — | — | **crash**: {row['error']} | | | | |"
    left = "; ".join(row["unexplained"]) or "none"
    if row["silent_misfit"]:
        left += " (**χ²/dof > 3 left silent**)"
    warn = f" ⚠ {len(row['warnings'])} warning(s)" if row["warnings"] else ""
    return (
        f"| {name} | {row['plain_chi2_dof']:.3g} | {row['start_chi2_dof']:.3g} → {row['final_chi2_dof']:.3g} | "
        f"{_common.steps_cell(row['steps'], 3)}{warn} | {left} | {_sane(row['sanity_plain'])} | {_sane(row['sanity_refined'])} | "
        f"{row['cpu_seconds']:.1f} |"
    )


def write(rows, out: Path, load: float, notes: list) -> None:
    crashes = sum("error" in r for r in rows)
    silent = sum(r.get("silent_misfit", False) for r in rows)
    warned = sum(bool(r.get("warnings")) for r in rows)
    lines = [
        "# refine on the Allan curves of five real IMUs (curves only)",
        "",
        f"`python benches/refine_curves.py`, {_common.machine_line()}; other processes used {load:.0%} of the CPUs "
        "during the run. "
        "Default calls `allanite.fit(curve)` and `allanite.refine(curve)` on every channel of "
        "`../shared/data/avar-curves` (one τ per octave, from m = 2; raw units). χ²/dof: the plain fit's, then "
        "refine's start → final model. Found: the steps at acceptance (raw units; f0, cutoff in Hz, T_c in s). "
        "Sanity: gyros' N (°/√h) and B (°/h) read as rad/s (ADIS16405: °/s), ✗ where outside the class range "
        "(FOG: N 0.003–0.3, B 0.005–3; MEMS: N 0.1–5, B 1–100; B = 0: no flicker floor resolved); NavChip: N over "
        "the `avar` vignette's white-noise read-off. CPU s: the refine call.",
        "",
        f"**{len(rows)} channels: {crashes} crash(es), {warned} with warnings, {silent} with final χ²/dof > 3 and "
        "nothing said unexplained.**",
        "",
        "| channel | plain fit χ²/dof | refine χ²/dof start → final | found | still unexplained | sanity, plain fit "
        "| sanity, refined | CPU s |",
        "|---|---|---|---|---|---|---|---|",
        *(_row(r) for r in rows),
        "",
        *notes,
    ]
    _common.write_results(out, "refine_curves", lines, rows)


#: What the run showed and what was changed because of it (kept true to the recorded run).
NOTES: list = [
    "What the first run (at 313a76b, before the changes of this bench's commit series) showed, and what was done:",
    "",
    "- **One misfit reported as two overlapping regions**: IMAR gyro y said τ 0.005–0.080 s *and* 0.005–0.64 s, "
    "LN200 accelerometer y τ 655–2621 s twice, LN200 accelerometer x τ 1.3–20 s and 2.6–1311 s (the ADIS16405 "
    "run 2 gyro z record, with samples, also τ 0.09–1.83 s twice). A column that finds a region already reported "
    "now widens it (`_curve_checks._merged`): one region per misfit.",
    "- **The largest misfit unnamed**: LN200 accelerometer y ends at χ²/dof 1785 with the model 2–5× *above* the "
    "curve over τ 1.3–655 s (z −68 … −4), yet the only region said was τ 655–2621 s (χ²/dof 7.9): the score test "
    "adds non-negative columns and cannot see a model held above the curve. Once the test has fired, the runs of "
    '|z| > 2 that no region covers are named too ("the model lies above the Allan curve", τ 1.3–655 s here); '
    "no share of `level` is spent (nothing is said unless the calibrated test already fired).",
    "- **Nothing added at χ²/dof 1.8·10⁵, and no reason given**: LN200 accelerometer z. Its curve falls 4.4× "
    "from m = 2 to m = 4 — a line near f_s/4 = 100 Hz; the curve-only sinusoid (statistic 1.8·10⁶ against 13.5) "
    "and the resonance (8.2·10³) had their best parameter at the top of their ranges (0.5/τ_min and 0.49/τ_min: "
    "f_s/4 on a curve from m = 2), so neither was identified — and `considered` did not say so. Every proposal "
    "whose test passed but that was not taken now says why (`considered[...]['rejected']`: parameter at the edge, "
    "χ²/dof not falling, amplitude 0, held-out error, another candidate taken). Tried and *not* kept: searching "
    "lines and resonances up to f_s/2 on such curves (with the exact sampled-line form below) took LN200 "
    "accelerometer z to χ²/dof 1.1·10³ but changed the greedy path elsewhere (IMAR gyro x final 1.12 → 2.4, "
    "ADIS accelerometer z 2.64 → 3.17, KVH gyro y's line read at 342 Hz instead of 157 Hz) — and on a curve of "
    "even m only a line at f and one at f_s/2 − f differ by their amplitude alone (sin⁴(πνm) is the same), so "
    "above f_s/4 the frequency is not identified anyway (docs/refinement.md, limits).",
    "- **A sampled line's Allan variance**: the continuous form sin⁴(πf0τ)/(πf0τ)² is off by (πν/sin πν)² for "
    "samples (1.23× at f_s/4); `sinusoid_avar(tau, f0, fs)` is now exact in discrete time and the effect's "
    "signature uses it. The steps and χ²/dof of every row stayed the same; the amplitudes of lines found at "
    "f0 ≳ f_s/10 moved by the exact factor (ADIS gyro z's 20.4 Hz line 0.390 → 0.364, NavChip accelerometer y's "
    "41.5 Hz line 0.00823 → 0.00786); in the blind suite (with samples) the 10 Hz logger's 1.7 Hz line's "
    "amplitude error went +3.8 % → −1.0 %.",
    "- **Overflow in the curve test** (seen while trying the wider search above: EDF ~1e298, NumPy overflow "
    "warnings): where the fitted five terms carry nothing the exact five-term covariance was scaled to the whole "
    "model by model/terms = ∞; the octave-correlation model with each estimate's EDF is used there "
    "(`calibrated.TERMS_FLOOR`).",
    '- **A two-sided check of the whole curve** (`"fit"`, curve-only input; i29say): the one-sided score test '
    "cannot see a model held *above* the curve (LN200 gyro x: z ≈ −5 over τ 0.32–5.1 s, final χ²/dof 7.5, nothing "
    "said). The GLS χ² of the whole curve, the model's fitted directions refitted, against the same bootstrap, at "
    "the shares of the checks that need samples (α 0.375 %; 2 of 640 clean octave curves at it, "
    "benches/results/refine_unexplained_null.md): LN200 gyro x now says both regions, KVH 1750 accelerometer y a "
    "misfit spread over the whole curve (GLS χ² 42 on 13 dof, threshold 30; its EDF χ²/dof reads 0.80), LN200 "
    "accelerometer z one more region (τ 10 s).",
    "",
    "Left, and why:",
    "",
    "- 4 channels end above χ²/dof 3 with nothing said, and that is the tests' answer, not a gap: the χ²/dof here "
    "is the final fit's on EDF variances (the diagonal, no cross terms between noise types, the weighted fit's "
    "coefficients). Under the tests' exact covariance, with the same terms refitted there, the misfit is within "
    "the scatter at the check's α: p = 0.14 (ADIS accelerometer y), 0.19 (ADIS accelerometer z), 0.04 (NavChip "
    "accelerometer y), 0.01 (LN200 gyro z) (the fit check's statistic, 2000 draws) — the part a GLS refit of the "
    "same terms absorbs is not something the model misses.",
    "- LN200 accelerometers (χ²/dof 10⁴–10⁵ at the start): a steep 1/τ fall over three decades of τ (lines above "
    "f_s/4 and vibration) that five terms plus a few effects do not describe; the regions say so.",
    "- Units are not stated in the curves' source: read as rad/s, the KVH 1750's N (0.18 °/√h) is at the top of "
    "the FOG range, the IMAR's (0.086–0.11 °/√h) at the 0.1 °/√h an iMAR FSAS is specified at, the LN200's "
    "0.036–0.042 °/√h; NavChip gyros' N is 0.60–0.86 of the vignette's white-noise read-off (that read-off, "
    "at τ 0.26–1 s, holds bias instability too: tests/test_fit_real.py). B = 0 on several FOG channels: the "
    "flicker floor is not resolved on these records (rate random walk or ramp takes the long τ).",
]


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--sensor", default=None, help="only this sensor (file stem before _av)")
    ap.add_argument("--out", default=None, help="results folder (default benches/results)")
    args = ap.parse_args(argv)
    out = Path(args.out) if args.out else HERE / "results"
    out.mkdir(parents=True, exist_ok=True)
    files = sorted((_common.shared_data_dir() / "avar-curves").glob("*_av.csv"))
    rows = []
    with _common.OtherLoad() as load:
        for f in files:
            sensor = f.stem.removesuffix("_av")
            if args.sensor and sensor != args.sensor:
                continue
            for ch, res in load_avar_curve(f)["channels"].items():
                row = run_channel(sensor, ch, res)
                print(_row(row), flush=True)
                rows.append(row)
    write(rows, out, load.fraction or 0.0, NOTES)
    print(f"wrote {out / 'refine_curves.md'}")


if __name__ == "__main__":
    main()

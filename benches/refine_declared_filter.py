#!/usr/bin/env python3
"""Refine with the sensor's own filter declared (``refine(..., filter=...)``) against the default call (r17taps).

Each case is refined twice on the same record (its seed, noise and judge: ``refine_blind9.run_case`` through
``refine_blind.refined``, the blind suites' judge — named, parameters within 20 %, the chain's errors falling,
held out, nothing unexplained — and the call without the effect's candidate): once with the default call (the
bandwidth's kinds searched), once with the filter the sensor runs declared (its taps or (b, a), its rate and
decimation). Cases:

- blind11's row "MEMS decimated 8 kHz → 1 kHz by a 95-tap equiripple FIR (1.3 dB passband ripple ...)", its
  truth the row's own (the FIR's |H| < 1/√2 frequency past the passband);
- an elliptic IIR (4th order, 0.5 dB passband ripple, 50 dB stop band, −3 dB near 150 Hz) running at 2 kHz,
  decimated by 5 to 400 Hz × 10⁶, white, flicker and rate random walk; its truth the declared filter's −3 dB
  frequency (where |H|² falls to half its DC value: the declared kind's own definition);
- a Chebyshev type I IIR (3rd order, 1 dB ripple, edge 20 Hz) at the output rate, 100 Hz × 5·10⁵, quantised at the
  output (a step of 0.3 of the per-sample σ): the floor after the filter.

The ADIS16405 logs: their data README (../shared/data/adis16405/SOURCE.txt) does not state the part's
SMPL_PRD/SENS_AVG setting (its Bartlett window), so no declared-filter run of them is made here.

Usage::

    python benches/refine_declared_filter.py            # -> benches/results/refine_declared_filter.md/.json
    python benches/refine_declared_filter.py --case FIR # a subset, to a temporary folder
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from scipy import signal

sys.path.insert(0, str(Path(__file__).resolve().parent))

import _common  # noqa: E402
import refine_blind as rb  # noqa: E402
import refine_blind9 as rb9  # noqa: E402
import refine_blind11 as rb11  # noqa: E402
from allanite.model._declared import declared_filter  # noqa: E402

OUT = Path(__file__).resolve().parent / "results"
Injected = rb11.Injected

# the elliptic IIR decimator: input rate, decimation, order, ripple dB, stop-band dB, edge Hz
ELL_FS_IN, ELL_DEC, ELL_ORDER, ELL_RP, ELL_RS, ELL_EDGE = 2000.0, 5, 4, 0.5, 50.0, 150.0
# the Chebyshev I at the output rate: rate Hz, order, ripple dB, edge Hz; output quantum over the per-sample σ
CH_FS, CH_ORDER, CH_RP, CH_EDGE, CH_STEP = 100.0, 3, 1.0, 20.0, 0.3


def _ellip():
    return signal.ellip(ELL_ORDER, ELL_RP, ELL_RS, ELL_EDGE, fs=ELL_FS_IN)


def _cheby():
    return signal.cheby1(CH_ORDER, CH_RP, CH_EDGE, fs=CH_FS)


def _ellip_mems(rng):
    n = 1_000_000
    x = rb.noise(n * ELL_DEC, ELL_FS_IN, rng, N=3e-3, B=4e-4, K=1e-5)
    b, a = _ellip()
    return signal.lfilter(b, a, x)[::ELL_DEC], ELL_FS_IN / ELL_DEC, {}, {}, {"without": x[::ELL_DEC]}


def _cheby_quantised(rng):
    n = 500_000
    x = rb.noise(n, CH_FS, rng, N=2e-3, B=3e-4, K=5e-6)
    b, a = _cheby()
    y = signal.lfilter(b, a, x)
    step = CH_STEP * 2e-3 * math.sqrt(CH_FS)
    return np.round(y / step) * step, CH_FS, {}, {}, {"without": x}


def _cases() -> list:
    """(case, declared filter spec) per row: blind11's FIR row as the suite has it, then the two IIRs."""
    fir = next(c for c in rb11.CASES if "equiripple" in c.name)
    b_e, a_e = _ellip()
    b_c, a_c = _cheby()
    ell_cut = declared_filter({"b": b_e, "a": a_e, "rate": ELL_FS_IN}, ELL_FS_IN / ELL_DEC).cutoff
    ch_cut = declared_filter((b_c, a_c), CH_FS).cutoff
    return [
        (fir, {"taps": rb11._fir_taps(), "rate": rb11.FIR_FS_IN}),
        (
            rb11.Blind11(
                f"elliptic IIR (order {ELL_ORDER}, {ELL_RP} dB ripple, {ELL_RS:.0f} dB stop, −3 dB at {ell_cut:.0f} Hz) "
                f"at 2 kHz decimated by {ELL_DEC} to 400 Hz × 10⁶",
                _ellip_mems,
                [Injected("bandwidth", {"cutoff": ell_cut})],
                seed=1701,
            ),
            {"b": b_e, "a": a_e, "rate": ELL_FS_IN},
        ),
        (
            rb11.Blind11(
                f"Chebyshev I IIR (order {CH_ORDER}, {CH_RP} dB ripple, −3 dB at {ch_cut:.1f} Hz) at 100 Hz × 5·10⁵, "
                f"output quantised ({CH_STEP} of the per-sample σ)",
                _cheby_quantised,
                [Injected("bandwidth", {"cutoff": ch_cut})],
                seed=1702,
            ),
            (b_c, a_c),
        ),
    ]


def _declared(case, spec):
    """The case with ``filter=spec`` added to its call."""

    def build(rng, _b=case.build):
        y, fs, channels, kw, comp = _b(rng)
        return y, fs, channels, kw | {"filter": spec}, comp

    return dataclasses.replace(case, build=build)


def _brief(v: dict) -> dict:
    keep = ("passed", "param_errors", "chi2_dof", "rms_adev_pct", "heldout_rms_adev_pct", "unexplained", "steps")
    out = {k: v.get(k) for k in keep}
    out["without_candidate_flags"] = v.get("without_candidate_flags")
    out["cpu_seconds"] = v.get("cpu_seconds")
    return json.loads(json.dumps(out, default=float))


def main(argv=None) -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--case", default=None, help="only cases whose name contains this text")
    args = ap.parse_args(argv)
    out_dir = Path(tempfile.mkdtemp()) if args.case else OUT
    rows = []
    t0 = time.time()
    with _common.OtherLoad() as load:
        for case, spec in _cases():
            if args.case and args.case not in case.name:
                continue
            row = {"name": case.name}
            for label, c in (("default", case), ("declared", _declared(case, spec))):
                row[label] = _brief(rb9.run_case(c))
                print(case.name[:60], label, row[label]["passed"], row[label]["steps"], flush=True)
            rows.append(row)
    res = {"rows": rows, "load_fraction": load.fraction or 0.0, "seconds": time.time() - t0}
    (out_dir / "refine_declared_filter.json").write_text(json.dumps(res, indent=1, default=str))
    write_md(res, out_dir)
    print(f"wrote {out_dir / 'refine_declared_filter.md'}")


def _steps(v: dict) -> str:
    return (
        "; ".join(f"{s['effect']} ({', '.join(f'{k} {_num(x)}' for k, x in s['params'].items())})" for s in v["steps"])
        or "nothing"
    )


def _num(x) -> str:
    return f"{x:.4g}" if isinstance(x, float) else str(x)


def write_md(res: dict, out_dir: Path) -> None:
    md = [
        "# Refine with the sensor's filter declared (`refine(..., filter=...)`) against the default call",
        "",
        f"`python benches/refine_declared_filter.py` (other processes {100 * res['load_fraction']:.0f} % of the CPUs; "
        f"{res['seconds']:.0f} s). Judge: the blind suites' (named, parameters within 20 %, the chain's errors "
        'falling, held out, nothing unexplained); "without": `unexplained` non-empty when the bandwidth candidate is '
        "left out.",
        "",
        "| case | call | steps | errors | χ²/dof | RMS ADEV % | held out % | unexplained | without flags | passed |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in res["rows"]:
        for label in ("default", "declared"):
            v = row[label]
            left = "none" if not v["unexplained"] else "; ".join(rb.describe_region(u) for u in v["unexplained"][:2])
            errs = _common.param_errors_cell(v["param_errors"]) or "—"
            md.append(
                f"| {row['name']} | {label} | {_steps(v)} | {errs} | {_common.arrow_cell(v['chi2_dof'])} | "
                f"{_common.arrow_cell(v['rms_adev_pct'])} | {_common.arrow_cell(v['heldout_rms_adev_pct'])} | {left} | "
                f"{v['without_candidate_flags']} | {'✓' if v['passed'] else '✗'} |"
            )
    md += ["", *NOTES]
    (out_dir / "refine_declared_filter.md").write_text("\n".join(md) + "\n")


#: What the recorded run shows (kept true to benches/results/refine_declared_filter.json).
NOTES: list = [
    "Reading (the recorded run, at 78fec30's library — refine's behaviour unchanged since (later commits moved a check into a helper, docs); other processes used ~90 % of the CPUs, so its CPU seconds in the JSON are a ratio within the run only):",
    "",
    "- *blind11's FIR row passes with its taps declared.* Default: butterworth3 at 309 Hz (−5.6 %), χ²/dof 2576 → 129, held out 11.5 → 4.91 %, the curve departing at τ 1–130 ms — as the suite records it (the same fields). Declared (`{'taps': …, 'rate': 8000.0}`): the bandwidth alone, cutoff 321.6 Hz (−1.8 % against the row's truth 327 Hz, which is |H| < 1/√2 absolute; the declared kind's −3 dB is relative to its DC gain, 1.07), floor 0, χ²/dof 2576 → 1.20, RMS ADEV 11.3 → 2.44 %, held out 11.5 → 3.86 %, nothing unexplained; without the bandwidth candidate `unexplained` is non-empty. CPU 1.96 s against the default call's 3.67 s in this run (0.53×: no kinds searched).",
    "- *An elliptic IIR decimator (2 kHz → 400 Hz, 0.5 dB ripple) and a Chebyshev I at the output rate (1 dB ripple, quantised output) fail by default and pass declared.* Default: a boxcar of 1.13 samples and a spurious 66 Hz resonance, χ²/dof 1167 → 584, the curve departing at τ 5–230 ms and the model above it at 2.5 ms; a butterworth2 at 20.5 Hz, χ²/dof 2341 → 85.6, departing at τ 10 ms–1.3 s. Declared: the bandwidth alone, cutoff exact by construction (+0.0 %), χ²/dof → 1.17 and → 1.33, held out 3.72 → 2.55 % and 24.1 → 2.54 %, nothing unexplained; the Chebyshev's quantised output read as the floor after it (1.68·10⁻⁴ against Δ·√(τ0/12) = 1.73·10⁻⁴).",
    "- *Other seeds* (declared call only, each row's seed +100 and +200; a diagnostic, not in the JSON): 6 of 6 pass — the FIR χ²/dof → 1.22 and 0.84, held out → 2.53 and 1.89 %; the elliptic → 1.04 and 0.87; the Chebyshev → 0.80 and 1.14; nothing unexplained on any, and without the bandwidth candidate each flagged.",
    "- False alarms with a declared filter: `benches/results/refine_declared_null.md` (0 of 40 clean records, CP 0–8.8 %; the default call 28 of 40 on the same records, its kinds lacking the filters' ripple).",
]


if __name__ == "__main__":
    main()

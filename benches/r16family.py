#!/usr/bin/env python3
"""Which of the pulse-counted RLG's lines a family removed in time can hold (r16family) — measured before changing
the grouping for it.

``benches/refine_blind11.py``'s row "navigation-grade RLG ... pulse counts ... 427 Hz dither residue ... fold to a
27 Hz family" leaves line clusters at i·27 + 48.67 Hz (mod 400) unexplained; its notes read them as the counter's
deterministic quantiser error. For each line (the row's own record, seed and generator, ``refine_blind11._rlg``)
this measures its amplitude three ways: the least-squares sinusoid at its exact frequency over the whole record
(what a family removed in time takes), the same fitted on each 50 s block (mean over the blocks: a line coherent
over 50 s but not over the record), and the line search's (``allanite.model.lines.find_lines``: √(2·power) over
the line's Welch width — all its power). A coherent line reads the same three times; a line whose phase diffuses
reads far less in the least squares than in the spectrum.

The count rate's phase is the angle over the pulse weight, θ/Q: its random walk from the white rate noise
(N = 3·10⁻⁷ rad/√s at 400 Hz: 1.5·10⁻⁸ rad = 0.01 pulse a sample) diffuses the phase of every quantiser line of
order j in the count rate by (2π·0.01·j)² rad² a sample — a Lorentzian of FWHM ≈ j²·(2π·0.01)²·400/(2π) ≈ 0.25·j² Hz.
The dither residue's own lines (27 and 54 Hz, j = 0) carry no such phase.

Usage::

    python benches/r16family.py            # -> benches/results/r16family.md/.json
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import _common
import refine_blind11 as rb11
from allanite.model import linefit, lines

HERE = Path(__file__).resolve().parent

BLOCK_S = 50.0


def _amplitudes(y: np.ndarray, fs: float, f: float) -> tuple[float, float]:
    """The least-squares amplitude at ``f`` Hz over the whole record and the mean of it over 50 s blocks."""
    one = np.array([[1]])
    nu = np.array([f / fs])
    a, b = linefit.solve(y, np.arange(y.size), nu, one)
    n = int(BLOCK_S * fs)
    blocks = []
    for j in range(0, y.size - n + 1, n):
        part = y[j : j + n] - y[j : j + n].mean()
        aa, bb = linefit.solve(part, np.arange(j, j + n), nu, one)
        blocks.append(float(np.hypot(aa, bb)[0]))
    return float(np.hypot(a, b)[0]), float(np.mean(blocks))


def main() -> None:
    case = next(c for c in rb11.CASES if "pulse counts" in c.name)
    y, fs, _ch, _kw, _comp = case.build(np.random.default_rng(case.seed))
    y = np.asarray(y, dtype=np.float64)
    rate = 7.3e-5 / rb11.RLG_Q  # the bias's count rate, pulses per second (48.67)
    found = lines.find_lines(y, fs, 0.01)["lines"]
    rows = []
    for name, (i, j) in {
        "27": (1, 0),
        "54": (2, 0),
        "48.67": (0, 1),
        "27 + 48.67": (1, 1),
        "2·27 + 48.67": (2, 1),
        "5·27 + 48.67": (5, 1),
        "400 − (6·27 + 48.67)": (6, 1),
    }.items():
        f_raw = i * (rb11.RLG_FD - rb11.RLG_FS) + j * rate
        f = float(lines.fold_frequency(np.array([f_raw / fs]))[0] * fs)
        whole, block = _amplitudes(y, fs, f)
        near = min(found, key=lambda d: abs(d["f"] - f))
        spectral = float(near["amplitude"]) if abs(near["f"] - f) < 0.2 else math.nan
        rows.append({"line": name, "order_j": j, "f_hz": f, "ls_whole": whole, "ls_50s": block, "spectral": spectral})
    out = [
        "# r16family: which of the pulse-counted RLG's lines a family removed in time can hold",
        "",
        f"`python benches/r16family.py`, {_common.machine_line()}. The record of `benches/refine_blind11.py`'s RLG row "
        f"(its seed {case.seed}); amplitudes in rad/s.",
        "",
        "| line | j | f (Hz) | least squares, whole record | least squares, mean of 50 s blocks | line search (all its power) |",
        "|---|---|---|---|---|---|",
    ]
    for r in rows:
        out.append(
            f"| {r['line']} | {r['order_j']} | {r['f_hz']:.4f} | {r['ls_whole']:.3g} | {r['ls_50s']:.3g} | "
            f"{r['spectral']:.3g} |"
        )
    out += [
        "",
        "The dither residue's lines (j = 0) read the same whole, per block and in the spectrum: coherent, a family "
        "removed in time holds them. Every quantiser line (j = 1) reads a few per cent of its spectral amplitude over "
        "the whole record and about a fifth over 50 s: its phase diffuses with the angle noise (FWHM ≈ 0.25 Hz, the "
        "module docstring), so no lattice of fixed frequencies — one generator or two — removes it, and the row's "
        "`unexplained` naming those clusters is what refine should say. (27 = 81/3 and 48.67 = 146/3 Hz: at 400 Hz "
        "every such line lies on the 1/3 Hz lattice, so a two-generator basis for them is not unique either.)",
    ]
    _common.write_results(HERE / "results", "r16family", out, rows)
    print("\n".join(out))


if __name__ == "__main__":
    main()

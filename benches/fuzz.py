"""The fuzz suite at scale: every property of ``tests/test_fuzz.py`` with many random inputs.

CI runs the same properties with a fixed, small set of inputs; this script runs them with fresh random
inputs (``--examples`` per property, default 15 000: > 10⁵ inputs in all) and records the count, the time
and what failed in ``benches/results/fuzz.md``. A failure is a finding: an exception other than an
AllaniteError, a non-finite or wrong number, a deadline overrun (a hang) or an allocation beyond the
budget; hypothesis prints the smallest failing input, which goes into the record.

    python benches/fuzz.py                      # ~4 min on 2 cores
    python benches/fuzz.py --examples 2000      # a quick look
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import _common

ROOT = Path(__file__).resolve().parents[1]


def run(examples: int) -> tuple[int, str, float]:
    env = dict(os.environ, ALLANITE_FUZZ_EXAMPLES=str(examples), ALLANITE_FUZZ_RANDOM="1")
    t0 = time.perf_counter()
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "pytest",
            "-q",
            "-p",
            "no:cacheprovider",
            str(ROOT / "tests" / "test_fuzz.py"),
            "--hypothesis-show-statistics",
        ],
        env=env,
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    return proc.returncode, proc.stdout + proc.stderr, time.perf_counter() - t0


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--examples", type=int, default=15_000, help="inputs per property (default 15000)")
    p.add_argument("--out", type=Path, default=ROOT / "benches" / "results" / "fuzz.md")
    args = p.parse_args()
    info = _common.machine_info()
    rc, text, seconds = run(args.examples)
    props = re.findall(
        r"tests/test_fuzz\.py::(\w+):\n\n\s+- during generate phase \(([\d.]+) seconds\):\n"
        r"\s+- Typical runtimes: .*\n\s+- (\d+) passing, (\d+) failing, and (\d+) invalid",
        text,
    )
    total = sum(int(n) + int(f) for _, _, n, f, _ in props)
    summary = re.findall(r"^(\d+ (?:passed|failed).*)$", text, flags=re.M)
    lines = [
        "# Fuzz suite at scale (`python benches/fuzz.py`)",
        "",
        "Machine: {cpu_model}, {cpu_count} cores, Python {py}, numpy {np_}, {date}.".format(
            cpu_model=info["cpu_model"],
            cpu_count=info["cpu_count"],
            py=info["versions"]["python"],
            np_=info["versions"]["numpy"],
            date=info["date_utc"],
        ),
        f"Random inputs (not CI's fixed ones), {args.examples} per property; {total} inputs in {seconds:.0f} s; "
        f"pytest: {summary[-1] if summary else 'no summary'}.",
        "",
        "| property | inputs | failing |",
        "|---|---|---|",
    ]
    lines += [f"| `{name}` | {int(n) + int(f)} | {f} |" for name, _, n, f, _ in props]
    lines += ["", "Findings (failing inputs as hypothesis shrank them):", ""]
    failures = []
    for block in re.findall(r"^E\s+(\w+Error: .*?)\n((?:E .*\n)+?)E\s+\)\n", text, flags=re.M):
        error, body = block
        case = "\n".join(line[1:].rstrip() for line in body.splitlines() if "Failing test case" in line or "=" in line)
        failures.append(f"{error}\n{case}")
    lines += [f"```\n{f.strip()}\n```" for f in failures] or ["none"]
    args.out.write_text("\n".join(line for line in lines if line is not None) + "\n", encoding="utf-8")
    print("\n".join(lines))
    return rc


if __name__ == "__main__":
    raise SystemExit(main())

"""Helpers shared by the bench scripts: where the shared data live, timing, machine facts, the
load of other processes, the cells and files of the refine benches' results pages, and the reader of the
``avar`` package's Allan curves.

The scripts in this folder are run as ``python benches/<script>.py``; Python puts the script's own folder
first on ``sys.path``, so they take these helpers with a plain ``import _common`` (no path editing, and
``benches/`` stays a folder of scripts, not a package). Nothing here asserts anything about speed.
"""

from __future__ import annotations

import datetime as _dt
import json
import os
import platform
import re
import subprocess
import time
from pathlib import Path

import numpy as np

from allanite.results import AllanResult

HERE = Path(__file__).resolve().parent
REPO = HERE.parent

#: Where the shared reference data are looked for when ``ALLANITE_SHARED_DATA`` is not set (the
#: same default as ``tests/conftest.py``): the folder ``shared/data`` beside the repository.
DEFAULT_SHARED_DATA = REPO.parent / "shared" / "data"


def shared_data_dir() -> Path:
    """The shared data folder: ``ALLANITE_SHARED_DATA`` if set (and not blank), else the default.

    It may not exist; callers check and skip what needs it."""
    env = os.environ.get("ALLANITE_SHARED_DATA", "").strip()
    return Path(env) if env else DEFAULT_SHARED_DATA


# ----------------------------------------------------------------------------------------------
# timing, comparison, machine and load


def timed(fn, repeats: int, warmup: bool = False):
    """Run ``fn`` (optionally once untimed first), then ``repeats`` timed runs.

    Returns (best seconds, list of every repeat's seconds, the last result)."""
    if warmup:
        fn()
    times = []
    out = None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), times, out


def max_rel_diff(a, b) -> float:
    """max |a − b| / |b| over all entries (0 where both are 0; inf where only b is 0)."""
    a = np.asarray(a, dtype=np.float64)
    b = np.asarray(b, dtype=np.float64)
    if a.shape != b.shape:
        raise ValueError(f"shape mismatch {a.shape} vs {b.shape}")
    if a.size == 0:
        return float("nan")
    diff = np.abs(a - b)
    den = np.abs(b)
    with np.errstate(divide="ignore", invalid="ignore"):
        rel = np.where(diff == 0, 0.0, diff / den)
    return float(np.max(rel))


def clopper_pearson(k: int, n: int, level: float = 0.95) -> tuple[float, float]:
    """Exact (Clopper–Pearson) interval of a binomial rate k/n at ``level``: the benches' false-alarm and
    coverage rates."""
    from scipy.stats import beta

    a = (1 - level) / 2
    lo = float(beta.ppf(a, k, n - k + 1)) if k > 0 else 0.0
    hi = float(beta.isf(a, k + 1, n - k)) if k < n else 1.0
    return lo, hi


def bit_identical(a, b) -> bool:
    a = np.ascontiguousarray(a, dtype=np.float64)
    b = np.ascontiguousarray(b, dtype=np.float64)
    return a.shape == b.shape and bool(np.array_equal(a.view(np.uint64), b.view(np.uint64)))


def sample_starts(n_win: int, count: int) -> np.ndarray:
    """``count`` window indices spread evenly over the record, first and last included."""
    count = max(1, min(count, n_win))
    return np.unique(np.round(np.linspace(0, n_win - 1, count)).astype(np.int64))


def _cmd_output(cmd) -> str | None:
    try:
        return subprocess.run(cmd, capture_output=True, text=True, timeout=30, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None


def machine_info() -> dict:
    cpu_model = None
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.lower().startswith("model name"):
                cpu_model = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    if cpu_model is None:
        cpu_model = platform.processor() or platform.machine()
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:
        usable = os.cpu_count()
    versions = {"python": platform.python_version(), "numpy": np.__version__}
    try:
        import allanite

        versions["allanite"] = allanite.__version__
    except Exception:  # pragma: no cover - reported, not fatal
        versions["allanite"] = None
    try:
        import allantools

        versions["allantools"] = getattr(allantools, "__version__", None)
    except ImportError:
        versions["allantools"] = None
    if versions.get("allantools") is None:
        try:
            from importlib.metadata import version

            versions["allantools"] = version("allantools")
        except Exception:
            pass
    git = _cmd_output(["git", "-C", str(REPO), "rev-parse", "--short", "HEAD"])
    dirty = _cmd_output(["git", "-C", str(REPO), "status", "--porcelain", "--untracked-files=no"])
    return {
        "cpu_model": cpu_model,
        "cpu_count": os.cpu_count(),
        "cpus_usable": usable,
        "platform": platform.platform(),
        "versions": versions,
        "rustc": _cmd_output(["rustc", "--version"]),
        "git_commit": None if git is None else git + ("+dirty" if dirty else ""),
        "env": {
            k: os.environ.get(k)
            for k in ("OPENBLAS_CORETYPE", "ALLANITE_NUM_THREADS", "RAYON_NUM_THREADS", "OMP_NUM_THREADS")
        },
        "date_utc": _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds"),
        "loadavg_start": list(os.getloadavg()) if hasattr(os, "getloadavg") else None,
    }


def cpu_busy_fraction(interval: float = 1.0) -> float | None:
    """Fraction of all CPUs busy over ``interval`` seconds (from /proc/stat), None if unknown."""

    def snap():
        f = Path("/proc/stat").read_text().splitlines()[0].split()[1:]
        v = [int(x) for x in f]
        idle = v[3] + (v[4] if len(v) > 4 else 0)
        return sum(v[:8]), idle

    try:
        t0, i0 = snap()
        time.sleep(interval)
        t1, i1 = snap()
    except (OSError, ValueError, IndexError):
        return None
    return 1.0 - (i1 - i0) / max(1, t1 - t0)


class OtherLoad:
    """CPU time used by *other* processes while a block runs, as a fraction of all CPUs' time
    (total busy time from /proc/stat minus this process's own user+system time)."""

    def __enter__(self):
        self.t0 = time.perf_counter()
        self.busy0 = self._busy()
        self.self0 = self._self()
        return self

    def __exit__(self, *exc):
        wall = time.perf_counter() - self.t0
        busy = self._busy()
        if busy is None or self.busy0 is None or wall <= 0:
            self.fraction = None
        else:
            others = (busy - self.busy0) - (self._self() - self.self0)
            self.fraction = max(0.0, others / (wall * (os.cpu_count() or 1)))
        return False

    @staticmethod
    def _busy():
        try:
            v = [int(x) for x in Path("/proc/stat").read_text().splitlines()[0].split()[1:9]]
        except (OSError, ValueError):
            return None
        return (sum(v) - v[3] - v[4]) / os.sysconf("SC_CLK_TCK")

    @staticmethod
    def _self():
        t = os.times()
        return t.user + t.system


def wait_idle(max_wait: float, threshold: float = 0.10) -> dict:
    """Wait (up to ``max_wait`` s) until the CPUs are < ``threshold`` busy for 3 s running."""
    t0 = time.perf_counter()
    calm = 0
    busy = cpu_busy_fraction()
    while busy is not None and time.perf_counter() - t0 < max_wait:
        calm = calm + 1 if busy < threshold else 0
        if calm >= 3:
            break
        if calm == 0:
            log(f"waiting for an idle machine: CPUs {busy:.0%} busy")
        busy = cpu_busy_fraction()
    return {
        "waited_seconds": round(time.perf_counter() - t0, 1),
        "busy_fraction_before_start": busy,
        "idle": None if busy is None else busy < threshold,
    }


def log(msg: str) -> None:
    print(msg, flush=True)


# ----------------------------------------------------------------------------------------------
# results pages: the cells and the files the refine benches' tables share


def machine_line(m: dict | None = None) -> str:
    """Where a results page was written: ``cpu, N CPUs, allanite at <commit>, <date>`` (``m``: a
    :func:`machine_info`, this machine's by default)."""
    m = machine_info() if m is None else m
    return f"{m['cpu_model']}, {m['cpus_usable']} CPUs, allanite at {m['git_commit']}, {m['date_utc'][:10]}"


def rejection_rates(p, levels) -> dict:
    """For each level (keyed ``f"{level:g}"``): how many of the p-values ``p`` are ≤ it, their share, and
    the share's 95 % Clopper–Pearson interval — a calibration table's row."""
    p = np.asarray(p)
    rates = {}
    for lv in levels:
        k = int(np.sum(p <= lv))
        rates[f"{lv:g}"] = {
            "rejections": k,
            "rate": float(np.mean(p <= lv)),
            "interval_95": clopper_pearson(k, int(p.size)),
        }
    return rates


def rate_cell(r: dict, count: bool = False) -> str:
    """One of :func:`rejection_rates`' entries as ``1.25 % (0.40–2.90)`` (rate and interval in percent);
    with ``count``, the rejections first: ``3 = 1.25 % (0.40–2.90)``."""
    lo, hi = r["interval_95"]
    text = f"{100 * r['rate']:.2f} % ({100 * lo:.2f}–{100 * hi:.2f})"
    return f"{r['rejections']} = {text}" if count else text


def arrow_cell(p) -> str:
    """A (before, after) pair as ``a → b`` to 3 digits; ``—`` without a before, ``a → —`` without an after."""
    if not p or p[0] is None:
        return "—"
    return f"{p[0]:.3g} → {p[1]:.3g}" if p[1] is not None else f"{p[0]:.3g} → —"


def param_errors_cell(errors: dict) -> str:
    """A verdict's parameter errors as ``name +1.2%`` (a float: relative error) or ``name text``, the
    parameters without one left out ("" when none has one)."""
    return ", ".join(
        f"{k} {e:+.1%}" if isinstance(e, float) else f"{k} {e}" for k, e in errors.items() if e is not None
    )


def steps_cell(steps: list, digits: int) -> str:
    """refine's steps as ``effect (parameter value, …)`` joined by ``; `` (floats to ``digits`` significant
    digits), or ``nothing``."""
    out = []
    for s in steps:
        ps = ", ".join(f"{k} {x:.{digits}g}" if isinstance(x, float) else f"{k} {x}" for k, x in s["params"].items())
        out.append(f"{s['effect']} ({ps})")
    return "; ".join(out) or "nothing"


def without_candidate_cell(left) -> str:
    """What ``unexplained`` said when the effect's candidate was left out: ``—`` (not run), ``**none**``
    or how many regions."""
    return "—" if left is None else ("**none**" if not left else f"{len(left)} region(s)")


def write_results(out: Path, stem: str, lines: list, results, end: str = "\n") -> None:
    """A bench's page ``<stem>.md`` (``lines`` joined by newlines, then ``end``) and its ``<stem>.json``
    (``results``; NumPy scalars as floats), in ``out`` (made if missing)."""
    out.mkdir(parents=True, exist_ok=True)
    (out / f"{stem}.md").write_text("\n".join(lines) + end)
    (out / f"{stem}.json").write_text(json.dumps(results, indent=1, default=float))


# ----------------------------------------------------------------------------------------------
# data


def load_avar_curve(path: Path) -> dict:
    """The avar package's curve CSV → {channel: AllanResult}. Meta from the first comment line."""
    lines = path.read_text().splitlines()
    meta = dict(re.findall(r"(\w+)=([^;]+)", lines[0]))
    fs = float(meta["freq_Hz"])
    n = int(float(meta["n"]))
    rows = [ln.split(",") for ln in lines if ln and not ln.startswith("#")][1:]
    chans: dict = {}
    for r in rows:
        chans.setdefault(r[0], []).append((float(r[1]), float(r[2])))
    out = {}
    for ch, v in chans.items():
        a = np.array(v)
        m = np.round(a[:, 0] * fs).astype(np.int64)
        # the avar package's estimator sums T − 2m terms and divides by T − 2m + 1 (one term fewer
        # than the textbook overlapping AVAR, ≤ 6e-6 relative on these curves): kept as is; the
        # EDF only needs the record length and m.
        out[ch] = AllanResult(
            tau=m / fs, avar=a[:, 1], n=(n + 1 - 2 * m).astype(np.int64), m=m, estimator="oavar", fs=fs, n_samples=n
        )
    return {"sensor": meta.get("sensor", path.stem).strip(), "fs": fs, "n": n, "channels": out}

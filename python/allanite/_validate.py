"""Every shared check of user input, with the public error messages in one place.

Turning what users pass into what the core needs (contiguous float64 rate columns) and checking
scalar options (sampling rate, counts, probabilities, choices). Kept apart from the estimators so
that readers, the CLI, the model and every estimator share one set of checks and one set of
messages. Public to the package (no leading underscores), private to users.
"""

from __future__ import annotations

import math
import numbers
import os
from collections.abc import Iterable

import numpy as np

from .errors import InputError, ParameterError

INPUTS = ("rate", "increment", "angle")
DEFAULT_MAX_MEMORY = 2 * 1024**3
MAX_WORKERS = 4096


def check_choice(value: object, name: str, allowed: Iterable[str]) -> str:
    """``value`` if it is one of the strings ``allowed``, else a ParameterError listing them."""
    allowed = tuple(allowed)
    if not isinstance(value, str) or value not in allowed:
        raise ParameterError(f"unknown {name} {value!r}; allowed: {', '.join(map(repr, allowed))}")
    return value


#: the other tools' words for an ``input`` (allantools' ``data_type``, Stable32's data) and allanite's for each
INPUT_WORDS = {"phase": "angle", "freq": "rate", "frequency": "rate"}


def input_word(value: str) -> str:
    """allanite's word for another tool's ``input`` word, any other string as it is (a command line's ``type``:
    its ``choices`` then judge it)."""
    return INPUT_WORDS.get(value, value)


def check_input(value: object) -> str:
    """allanite's word for the kind of samples ``value`` names: one of :data:`INPUTS`, or another tool's word for
    one of them (:data:`INPUT_WORDS`: allantools' and Stable32's ``"phase"`` is ``"angle"`` — a clock's phase or
    time error is the integral of its fractional frequency, M + 1 points — and ``"freq"``/``"frequency"`` is
    ``"rate"``); else a ParameterError listing both. Every public call that takes ``input`` keeps the returned word,
    so its result says ``input="angle"`` where ``"phase"`` was given."""
    if isinstance(value, str) and value in INPUT_WORDS:
        return INPUT_WORDS[value]
    if isinstance(value, str) and value in INPUTS:
        return value
    aliases = ", ".join(f"{k!r} (= {v!r})" for k, v in INPUT_WORDS.items())
    raise ParameterError(f"unknown input {value!r}; allowed: {', '.join(map(repr, INPUTS))}, or {aliases}")


def check_fs(fs: object) -> float:
    """A sampling rate: a positive finite number whose inverse is finite."""
    if isinstance(fs, bool) or not isinstance(fs, (numbers.Real, np.floating, np.integer)):
        raise ParameterError(f"fs must be a positive finite number of samples per second, got {fs!r}")
    fs = float(fs)
    if not math.isfinite(fs) or fs <= 0:
        raise ParameterError(f"fs must be a positive finite number of samples per second, got {fs!r}")
    if not math.isfinite(1.0 / fs) or fs < 1e-200:
        raise ParameterError(f"fs = {fs!r} Hz is too small: the sampling interval 1/fs is not a finite number")
    return fs


def check_real(value: object, name: str, allowed: str) -> float:
    """A finite real scalar (not bool, not str), or a ParameterError naming it and ``allowed``."""
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, np.floating, np.integer)):
        raise ParameterError(f"{name} must be {allowed}, got {value!r}")
    out = float(value)
    if not math.isfinite(out):
        raise ParameterError(f"{name} must be {allowed}, got {value!r}")
    return out


def check_count(value: object, name: str, minimum: int, maximum: int | None = None) -> int:
    """An integer (or an integral float) in [minimum, maximum]."""
    if isinstance(value, bool) or not isinstance(value, (numbers.Integral, np.integer)):
        if isinstance(value, (float, np.floating)) and math.isfinite(value) and float(value).is_integer():
            value = int(value)
        else:
            raise ParameterError(f"{name} must be an integer ≥ {minimum}, got {value!r}")
    out = int(value)
    if out < minimum:
        raise ParameterError(f"{name} must be an integer ≥ {minimum}, got {out}")
    if maximum is not None and out > maximum:
        raise ParameterError(f"{name} must be an integer ≤ {maximum}, got {out}")
    return out


def check_positive(value: object, name: str) -> float:
    """A positive finite number."""
    v = check_real(value, name, "a positive finite number")
    if v <= 0:
        raise ParameterError(f"{name} must be a positive finite number, got {value!r}")
    return v


def check_nonnegative(value: object, name: str) -> float:
    """A finite number ≥ 0."""
    v = check_real(value, name, "a finite number ≥ 0")
    if v < 0:
        raise ParameterError(f"{name} must be a finite number ≥ 0, got {value!r}")
    return v


def check_probability(value: object, name: str = "confidence") -> float:
    """A probability strictly between 0 and 1 (a confidence level)."""
    if isinstance(value, bool) or not isinstance(value, (numbers.Real, np.floating, np.integer)):
        raise ParameterError(f"{name} must be a probability strictly between 0 and 1, got {value!r}")
    c = float(value)
    if not (0.0 < c < 1.0):
        raise ParameterError(
            f"{name} must be a probability strictly between 0 and 1 (e.g. 0.683 or 0.95), got {value!r}"
        )
    return c


def as_rate_columns(
    x: object, fs: object, input: str, *, peaks: list[float] | None = None
) -> tuple[list[np.ndarray], float, bool]:
    """Validate samples and convert them to rate columns.

    Returns ``(columns, fs, is_multi)``: a list of C-contiguous float64 arrays (one per axis) of rate
    samples, the sampling rate, and whether the input had an axes dimension. ``input="increment"``
    (angle per sample) is divided by τ0; ``input="angle"`` (cumulative angle, M + 1 points) is
    differenced first. All three describe the same record and give the same Allan variance.

    ``peaks``: a list that receives each column's largest magnitude (the finite check's min and max
    give it for rate input, so a caller that scales the columns need not read the record again).
    """
    fs = check_fs(fs)
    input = check_input(input)
    try:
        arr = np.asarray(x)
    except Exception as exc:  # ragged lists and the like
        raise InputError(f"samples could not be read as a numeric array: {exc}") from None
    if arr.dtype.kind not in "iuf":
        raise InputError(
            f"samples must be real numbers (integer or float dtype), got dtype {arr.dtype} "
            f"({'bool' if arr.dtype.kind == 'b' else arr.dtype.kind!r} kind)"
        )
    if arr.ndim not in (1, 2):
        raise InputError(
            f"samples must be 1-D (samples,) or 2-D (samples, axes), got {arr.ndim}-D with shape {arr.shape}"
        )
    is_multi = arr.ndim == 2
    cols = [arr] if not is_multi else [arr[:, a] for a in range(arr.shape[1])]
    if is_multi and arr.shape[1] == 0:
        raise InputError(f"samples have shape {arr.shape}: at least one axis is needed")
    n_points = arr.shape[0]
    need = 3 if input == "angle" else 2
    if n_points < need:
        what = "angle points" if input == "angle" else "samples"
        raise InputError(f"record has {n_points} {what}; at least {need} are needed for any Allan variance")
    out = []
    for a, c in enumerate(cols):
        c = np.asarray(c, dtype=np.float64)
        # min and max are NaN if any sample is, ±inf if any is: no per-sample temporary unless one is bad
        c_min, c_max = c.min(), c.max()
        if not (np.isfinite(c_min) and np.isfinite(c_max)):
            i = int(np.argmin(np.isfinite(c)))
            where = f"sample {i}" + (f" of axis {a}" if is_multi else "")
            raise InputError(f"samples contain a non-finite value ({c[i]}) at {where}; only finite numbers are allowed")
        if input == "rate":
            # aligned too: arrays read from a network buffer (e.g. a Dask task's input) may not be
            y = np.require(c, requirements=("C_CONTIGUOUS", "ALIGNED"))
        elif input == "increment":
            y = c * fs
        else:
            y = np.diff(c) * fs
        if peaks is not None:
            if y is c:
                peaks.append(max(float(c_max), -float(c_min)))
            else:
                peaks.append(max(float(y.max()), -float(y.min())) if y.size else 0.0)
        out.append(y)
    return out, fs, is_multi


def resolve_workers(workers: object) -> int:
    """Threads for the core: ``workers`` if given, else ``ALLANITE_NUM_THREADS``, else 0 (rayon's
    default: ``RAYON_NUM_THREADS`` or the number of cores)."""
    if workers is None:
        env = os.environ.get("ALLANITE_NUM_THREADS", "").strip()
        if not env:
            return 0
        try:
            workers = int(env)
        except ValueError:
            raise ParameterError(f"ALLANITE_NUM_THREADS={env!r} must be a positive integer") from None
        if not 1 <= workers <= MAX_WORKERS:
            raise ParameterError(f"ALLANITE_NUM_THREADS={env!r} must be an integer from 1 to {MAX_WORKERS}")
        return workers
    return check_count(workers, "workers", 1, MAX_WORKERS)


def resolve_max_memory(max_memory: object) -> int:
    """Byte budget for a result: ``max_memory`` if given, else ``ALLANITE_MAX_MEMORY``, else 2 GiB."""
    name = "max_memory"
    if max_memory is None:
        env = os.environ.get("ALLANITE_MAX_MEMORY", "").strip()
        if not env:
            return DEFAULT_MAX_MEMORY
        name = f"ALLANITE_MAX_MEMORY={env!r}"
        try:
            max_memory = float(env)
        except ValueError:
            raise ParameterError(f"{name} must be a positive number of bytes") from None
    if isinstance(max_memory, bool) or not isinstance(max_memory, (numbers.Real, np.integer, np.floating)):
        raise ParameterError(f"{name} must be a positive number of bytes, got {max_memory!r}")
    value = float(max_memory)
    if not np.isfinite(value) or value <= 0:
        raise ParameterError(f"{name} must be a positive number of bytes, got {max_memory!r}")
    return int(min(value, 2.0**62))

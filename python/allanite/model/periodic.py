"""Periodic components of a record: every significant line, grouped into families, fitted in the time domain.

:func:`periodic_search` runs the pipeline behind the ``"periodic"`` and ``"sinusoid"`` effects of
:func:`allanite.refine`:

1. :func:`allanite.model.lines.find_lines` — every line of the Welch PSD beyond its neighbours' median,
   at a false-alarm probability ``alpha`` for the whole record (Bonferroni over the bins searched);
2. :func:`allanite.model.lines.group_lines` — the lines into families on a lattice (harmonics k·f0,
   sidebands k·f1 + s·f2); a line no family takes is a sinusoid of its own;
3. per family, the generators refined on the samples (Gauss–Newton on the lines' frequency offsets,
   :func:`allanite.model.linefit.refine_generators`; a line whose Welch width takes in another of the family's
   lines weighted by its least-squares amplitude at the lattice: :func:`_weight_amplitudes`; a harmonic family's
   orders that fold within a bin of each other told apart: :func:`_unaliased`), then the lattice points the
   family predicts but the search did not flag are tested one by one (the F test of the PSD ratio at the point's
   bin, Bonferroni over the points tried, at the same ``alpha``: a family's weak harmonics and sidebands, known in
   advance, need far less than a line found anywhere among all bins); under the null nothing reaches this stage, so
   it adds nothing to the record's false-alarm probability;
4. amplitudes and phases by least squares at the lattice frequencies (:func:`allanite.model.linefit.solve`)
   — on the whole record, or, for a held-out test, on the held-in samples with the frequencies fixed
   (:meth:`LineFamily.refit`).

:func:`hunting_family` gathers, for the removal, the lines of a family whose fundamental hunts (an engine's, a pump's
idle speed): each harmonic smeared over k·Δf and found as several peaks, which step 2 splits among lattices of close
"fundamentals"; the tracker (:mod:`allanite.model.wander`) then follows its phase.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy.stats import f as f_dist

from . import linefit, lines, slowline
from ._recent import Recent

__all__ = ["LineFamily", "hunting_family", "periodic_search", "sinusoid_lines"]


@dataclass
class LineFamily:
    """A family of lines on a lattice ν_i = coefs_i · gens (one generator: harmonics; two: sidebands).

    Attributes
    ----------
    fs : float
        Sampling rate, Hz.
    gens : ndarray
        Generators (fundamentals), Hz.
    gens_cov : ndarray
        Their covariance, Hz² (Cramér–Rao of the lines combined; NaN if not determined).
    coefs : ndarray of int, shape (lines, generators)
        Each line's integer coefficients.
    a, b : ndarray
        Least-squares amplitudes of a cos ω n + b sin ω n (rate unit).
    noise : ndarray
        One-sided noise PSD under each line (rate unit²/Hz), for the amplitudes' errors.
    found : ndarray of bool
        True for lines the search flagged among all bins, False for lattice points added by the targeted test.
    n : int
        Samples the amplitudes were fitted on.
    """

    fs: float
    gens: np.ndarray
    gens_cov: np.ndarray
    coefs: np.ndarray
    a: np.ndarray
    b: np.ndarray
    noise: np.ndarray
    found: np.ndarray
    n: int
    evidence: dict = field(default_factory=dict)

    @property
    def frequencies(self) -> np.ndarray:
        """Each line's frequency as sampled (folded into [0, f_s/2]), Hz."""
        return lines.fold_frequency(self.coefs @ (self.gens / self.fs)) * self.fs

    @property
    def amplitudes(self) -> np.ndarray:
        """Each line's amplitude, √(a² + b²) of its sine and cosine coefficients (rate unit)."""
        return np.hypot(self.a, self.b)

    @property
    def amplitude_sd(self) -> np.ndarray:
        """SD of each amplitude: √(S₁/T) (least squares in locally white noise, T = n/f_s)."""
        return np.sqrt(self.noise * self.fs / self.n)

    @property
    def rms(self) -> float:
        """RMS of the family's component, √(Σ A_i²/2) (rate unit)."""
        return float(math.sqrt(np.sum(self.amplitudes**2) / 2.0))

    @property
    def rms_sd(self) -> float:
        """SD of :attr:`rms` (delta method: var(rms²) = Σ A_i²·var A_i)."""
        r = self.rms
        if r <= 0:
            return float("nan")
        return float(math.sqrt(np.sum(self.amplitudes**2 * self.amplitude_sd**2)) / (2.0 * r))

    @property
    def gens_sd(self) -> np.ndarray:
        """SD of each generator (Hz), from the diagonal of :attr:`gens_cov`."""
        return np.sqrt(np.maximum(np.diag(self.gens_cov), 0.0))

    def component(self, idx: np.ndarray | None = None) -> np.ndarray:
        """The fitted lines at sample indices ``idx`` (all n samples by default)."""
        idx = np.arange(self.n) if idx is None else np.asarray(idx, dtype=np.int64)
        return linefit.evaluate(idx, self.gens / self.fs, self.coefs, self.a, self.b)

    def refit(self, samples: np.ndarray, idx: np.ndarray):
        """Amplitudes and phases refitted on ``samples`` taken at indices ``idx`` (the held-in blocks), the
        frequencies fixed; returns the component as a function of sample indices."""
        idx = np.asarray(idx, dtype=np.int64)
        g = self.gens / self.fs
        a, b = _refitted(np.asarray(samples, dtype=np.float64), idx, g, self.coefs)
        return lambda i: _evaluated(np.asarray(i, dtype=np.int64), g, self.coefs, a, b)


#: Most orders of a hunting family's lattice (:func:`hunting_family`), as :data:`allanite.model.wander.MAX_ORDERS`.
HUNT_ORDERS = 16


def _clusters(found_lines: list[dict]) -> list[dict]:
    """The search's lines grouped where their widths overlap (a line whose frequency wanders is found as several
    peaks across its smear): each cluster's power-weighted centre, half span (its union of widths), power and count."""
    order = sorted(range(len(found_lines)), key=lambda i: found_lines[i]["f"])
    out: list[dict] = []
    for i in order:
        d = found_lines[i]
        lo, hi = d["width_hz"]
        if out and lo <= out[-1]["hi"]:
            c = out[-1]
            c["hi"], c["members"] = max(c["hi"], hi), c["members"] + [i]
        else:
            out.append({"lo": lo, "hi": hi, "members": [i]})
    for c in out:
        amp = np.array([found_lines[i]["amplitude"] for i in c["members"]])
        f = np.array([found_lines[i]["f"] for i in c["members"]])
        c["power"] = float(np.max(amp) ** 2)  # the peaks of one smeared line read its power each: not summed
        c["centre"] = float(np.mean(f)) if f.size > 1 else float(f[0])
        c["half"] = 0.5 * (c["hi"] - c["lo"])
    return out


def hunting_family(y: np.ndarray, fs: float, search: dict) -> tuple[LineFamily, list] | None:
    """A harmonic family whose fundamental hunts, as the search left it split: the search's lines clustered where
    their widths overlap (:func:`_clusters`), a fundamental f0 = centre/k (k ≤ 4) of one cluster taking the most
    clusters at orders m·f0 within each cluster's half span (the largest f0 among equals: no subharmonic), refined by
    least squares on the clusters' centres. Offered where it takes two or more clusters and one of them is smeared
    (two or more peaks): a steady family's lines are single peaks, grouped on their lattice as found. Returns the
    family (its orders fitted by least squares at fixed frequencies, for the tracker to start from) and the search's
    families and sinusoids (:class:`LineFamily`) all of whose lines its clusters hold; None otherwise."""
    found_lines = search["lines"]
    cl = _clusters(found_lines)
    if len(cl) < 2 or not any(len(c["members"]) > 1 for c in cl):
        return None
    centre = np.array([c["centre"] for c in cl])
    half = np.array([max(c["half"], 2.0 * fs / y.size) for c in cl])
    best: tuple | None = None
    for c in cl:
        for k in range(1, 5):
            f0 = c["centre"] / k
            m = np.round(centre / f0)
            hit = (m >= 1) & (m <= HUNT_ORDERS) & (np.abs(centre - m * f0) <= half)
            key = (int(hit.sum()), f0)
            if best is None or key > best[0]:
                best = (key, hit, m)
    assert best is not None
    (count, f0), hit, m = best
    if count < 2 or not any(len(cl[i]["members"]) > 1 for i in np.flatnonzero(hit)) or m[hit].max() * f0 >= fs / 2:
        return None
    w = np.array([c["power"] for c in cl])[hit]
    f0 = float(np.sum(w * m[hit] * centre[hit]) / np.sum(w * m[hit] ** 2))
    orders = m[hit].astype(np.int64)
    inside = [i for j in np.flatnonzero(hit) for i in cl[j]["members"]]
    held = set(inside)
    covered = [u for u in search["families"] + search["sinusoids"] if _held_by(u, found_lines, held)]
    if len(covered) == 1 and covered[0].gens.size == 1 and covered[0].coefs.shape[0] > 1:
        return None  # the search's own harmonic family: tracked as found where it wanders
    coefs = orders[:, None]
    noise = np.array([min(found_lines[i]["noise"] for i in cl[j]["members"]) for j in np.flatnonzero(hit)])
    amp = np.array([math.sqrt(cl[j]["power"]) for j in np.flatnonzero(hit)])
    g, _cov = linefit.refine_generators(y, np.array([f0 / fs]), coefs, _line_var(amp, noise, fs, y.size))
    # the steady lattice the tracked form must beat at its best fundamental (a crude one leaves an excess that reads
    # as wander); the cluster centres' where the refinement leaves the smear
    if not (np.all(np.isfinite(g)) and abs(g[0] * fs - f0) <= float(np.min(half[hit] / m[hit]))):
        g = np.array([f0 / fs])
    f0 = float(g[0] * fs)
    a, b = linefit.solve(y, np.arange(y.size), g, coefs)
    fam = LineFamily(
        fs, np.array([f0]), np.full((1, 1), np.nan), coefs, a, b, noise, np.ones(orders.size, dtype=bool), y.size,
        {
            "psd_ratio": [float(found_lines[i]["psd_ratio"]) for i in inside],
            "threshold": float(min(found_lines[i]["threshold"] for i in inside)),
            "targeted": {"tried": 0, "added": 0},
            "hunting": [[float(found_lines[i]["f"]) for i in cl[j]["members"]] for j in np.flatnonzero(hit)],
        },
    )  # fmt: skip
    return fam, covered


def _held_by(unit: LineFamily, found_lines: list[dict], held: set) -> bool:
    """Whether every line of ``unit`` that the search flagged is one of the search's lines in ``held``."""
    found = np.array([d["f"] for d in found_lines])
    for f, flagged in zip(unit.frequencies, unit.found):
        if not flagged:
            continue
        j = int(np.argmin(np.abs(found - f)))
        if abs(found[j] - f) > 2 * found_lines[j]["bin_hz"] or j not in held:
            return False
    return True


#: Amplitudes refitted by :meth:`LineFamily.refit`, by the held-in samples' content, the lattice and the indices
#: (records up to 4·10⁶ samples): the removal's held-out test in time and its held-out Allan-curve errors refit the
#: same family on the same alternate blocks.
_REFITS = Recent(4, 4_000_000)


#: Refitted components evaluated (:func:`_evaluated`), by the indices' content and the lines (records up to 4·10⁶
#: samples): the removal's held-out test in time and its held-out Allan-curve error evaluate the same refit at the same
#: held-out indices.
_EVALUATED = Recent(2, 4_000_000)


def _evaluated(idx: np.ndarray, g: np.ndarray, coefs: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """``linefit.evaluate(idx, g, coefs, a, b)``, found again for equal indices and lines (a fresh array each time)."""
    key = (g.tobytes(), np.shape(coefs), np.asarray(coefs, dtype=np.int64).tobytes(), a.tobytes(), b.tobytes())
    got = _EVALUATED.get(idx, key)
    if got is None:
        got = _EVALUATED.put(idx, key, linefit.evaluate(idx, g, coefs, a, b))
    return got.copy()


def _refitted(samples: np.ndarray, idx: np.ndarray, g: np.ndarray, coefs: np.ndarray) -> tuple:
    """``linefit.solve(samples, idx, g, coefs)``, found again for equal samples, lattice and indices (read-only)."""
    key = (g.tobytes(), coefs.shape, np.asarray(coefs, dtype=np.int64).tobytes())
    fits = _REFITS.get(samples, key)
    for idx0, a, b in fits or ():
        if idx0.shape == idx.shape and np.array_equal(idx0, idx):
            return a, b
    a, b = linefit.solve(samples, idx, g, coefs)
    a.flags.writeable = b.flags.writeable = False
    if fits is None:
        fits = _REFITS.put(samples, key, [])
    fits.append((idx.copy(), a, b))
    return a, b


def _noise_at(passes: list[dict], f: np.ndarray) -> np.ndarray:
    """The noise level (one-sided PSD) under frequencies ``f``: the finest pass that searched there, else the
    nearest searched bin of the band-wide pass."""
    out = np.full(f.size, np.nan)
    for ps in reversed(passes):  # the band-wide pass last in the list: finest first is the low pass
        k = np.clip(np.round(f / ps["df"]).astype(np.int64), 0, ps["noise"].size - 1)
        val = ps["noise"][k]
        out = np.where(np.isnan(out) & np.isfinite(val), val, out)
    if np.any(np.isnan(out)) and passes:
        ps = passes[-1]
        ok = np.flatnonzero(np.isfinite(ps["noise"]))
        if ok.size:
            k = np.clip(np.round(f / ps["df"]).astype(np.int64), 0, ps["noise"].size - 1)
            near = ok[np.clip(np.searchsorted(ok, k), 0, ok.size - 1)]
            out = np.where(np.isnan(out), ps["noise"][near], out)
    return out


def _targets(fam: dict, gens_nu: np.ndarray, passes: list[dict], taken_f: np.ndarray, fs: float):
    """Lattice rows the family predicts inside the searched band that no detected line occupies."""
    coefs = fam["coefs"]
    k_top = int(np.max(np.abs(coefs[:, 0])))
    if gens_nu.size == 1:
        k_end = max(k_top, int(math.floor(0.5 / gens_nu[0])))
        rows = np.arange(1, k_end + 1)[:, None]
    else:
        s_top = int(np.max(np.abs(coefs[:, 1]))) + 1
        k_end = max(k_top, int(math.floor(0.5 / max(gens_nu[0], 1e-12))))
        k_end = min(k_end, k_top + 1) if k_top < 64 else k_end
        k, s = np.meshgrid(np.arange(0, k_end + 1), np.arange(-s_top, s_top + 1), indexing="ij")
        rows = np.column_stack([k.ravel(), s.ravel()])
        rows = rows[(rows[:, 0] > 0) | (rows[:, 1] > 0)]
    raw = rows @ gens_nu
    if gens_nu.size == 1:
        keep = raw < 0.5
    else:
        keep = (np.abs(raw) < 0.5) & (np.abs(raw) > 0)
    rows, f = rows[keep], np.abs(raw[keep]) * fs
    lo = min(ps["f"][np.flatnonzero(np.isfinite(ps["noise"]))[0]] for ps in passes if np.isfinite(ps["noise"]).any())
    near = np.zeros(f.size, dtype=bool)
    if taken_f.size:
        df = passes[-1]["df"]
        d = np.abs(f[:, None] - taken_f[None, :])
        near = np.any(d <= (lines.LOBE + 1) * df, axis=1)
    ok = (f >= lo) & ~near
    return rows[ok], f[ok]


def _ratio_at(passes: list[dict], f: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Per frequency: the larger PSD ratio of the two bins around it (in the pass that searched there), and
    the F law's degrees of freedom of that bin."""
    ratio = np.full(f.size, -np.inf)
    dof = np.ones(f.size)
    dof_med = np.ones(f.size)
    for ps in passes:
        k0 = np.floor(f / ps["df"]).astype(np.int64)
        for k in (k0, k0 + 1):
            kk = np.clip(k, 0, ps["p"].size - 1)
            nz = ps["noise"][kk]
            ok = np.isfinite(nz)
            r = np.where(ok, ps["p"][kk] / np.where(ok, nz, 1.0), -np.inf)
            better = r > ratio
            ratio = np.where(better, r, ratio)
            dof = np.where(better, ps["dof_bin"][kk], dof)
            dof_med = np.where(better, ps["dof_med"][kk], dof_med)
    return ratio, dof, dof_med


def _line_var(amp: np.ndarray, noise: np.ndarray, fs: float, n: int) -> np.ndarray:
    """Frequency variance of each line in (cycles/sample)² (Cramér–Rao)."""
    return (linefit.frequency_sd(amp, noise, fs, n) / fs) ** 2


def _orient(gens: np.ndarray, coefs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Rows made k ≥ 0 (and s > 0 when k = 0): a row and its negative are the same real line."""
    if gens.size == 2:
        flip = (coefs[:, 0] < 0) | ((coefs[:, 0] == 0) & (coefs[:, 1] < 0))
        coefs = np.where(flip[:, None], -coefs, coefs)
    return gens, coefs


def _weight_amplitudes(y, gens, coefs, found_lines, everywhere=False) -> tuple[np.ndarray, bool]:
    """Each line's amplitude for the generators' weights, and whether any was replaced: the search's own (√(2·power)
    in the line's width of the Welch PSD), or, where that width holds another of the family's lines, the lattice's
    joint least-squares amplitude (:func:`allanite.model.linefit.solve`, which separates neighbouring lines exactly).

    A weak line whose width takes in a strong one reads the strong one's power. A square wave near f_s/60 puts its
    aliased 59th and 61st harmonics 0.06 Hz either side of its fundamental, inside their 0.13–0.2 Hz widths: they
    read the fundamental's amplitude (59× their own), took 59²·3500× their weight in the generator's least squares,
    and their offsets moved the fundamental by 8000 of its standard errors (``benches/results/line_constancy_null.md``).
    With ``everywhere``, every line's (a line given a wrong order reads none). Otherwise only those lines: a line that
    wanders (a site's sway) reads less coherent amplitude than power, and its PSD weight
    is the one the family's removal has been tuned with."""
    amp = np.array([d["amplitude"] for d in found_lines])
    f = np.array([d["f"] for d in found_lines])
    lo = np.array([d["width_hz"][0] for d in found_lines])
    hi = np.array([d["width_hz"][1] for d in found_lines])
    inside = (f[None, :] >= lo[:, None]) & (f[None, :] <= hi[:, None])
    np.fill_diagonal(inside, False)
    shared = inside.any(axis=1) | everywhere
    if not shared.any():
        return amp, False
    a, b = linefit.solve(y, np.arange(y.size), gens, coefs)
    return np.where(shared, np.hypot(a, b), amp), True


def _refined(y, fs, gens, coefs, found_lines, noise, everywhere=False, again=True) -> tuple[np.ndarray, np.ndarray]:
    """The generators refined (:func:`allanite.model.linefit.refine_generators`) with the lines' weights of
    :func:`_weight_amplitudes`; where some line's weight came from the least squares (and ``again``), refined again
    with the weights at the refined generators (at the search's, a high harmonic's phase may turn along the record
    and its least-squares amplitude read low)."""
    amp, leaked = _weight_amplitudes(y, gens, coefs, found_lines, everywhere)
    gens, cov = linefit.refine_generators(y, gens, coefs, _line_var(amp, noise, fs, y.size))
    if not (leaked and again):
        return gens, cov
    amp, _ = _weight_amplitudes(y, gens, coefs, found_lines, everywhere)
    return linefit.refine_generators(y, gens, coefs, _line_var(amp, noise, fs, y.size))


def _unaliased(y, fs, gens, coefs, found_lines, noise) -> tuple[np.ndarray, np.ndarray]:
    """A harmonic family's orders and its fundamental to start from: each line's order, among the orders folding
    within a search bin of it, the one of most power at the record's full resolution.

    Where P·f0 nears a multiple of f_s, orders k and mP ± k fold within a Welch bin of each other: the search's
    lattice cannot tell them apart and may give a line the far order (a square wave at 2.04106 Hz, 100 Hz: its
    9th–27th harmonics taken as the 40th–22nd, the fundamental refined 1400 of its standard errors off). At the
    record's resolution the candidates stand ≈ 10 bins apart: the orders are decided by increasing lowest candidate
    (up to 4, 16, 64, …), each at the fundamental refined on the lines decided before (:func:`_refined`), the
    candidate whose DTFT holds the most power; the fundamental the last refined (one refit per stage, and none for
    a stage with no ambiguous line: a refit at every stage, weights taken twice, made refine 5× slower on a 325-line
    sawtooth). Unchanged where no line is ambiguous."""
    if gens.size != 1 or coefs.shape[0] < 2:
        return coefs, gens
    k = coefs[:, 0]
    orders = np.arange(1, int(np.max(k)) + 1)
    pos = np.abs(lines.fold_frequency(orders * gens[0]))
    tol = min(d["bin_hz"] for d in found_lines) / fs
    near = np.abs(pos[k - 1][:, None] - pos[None, :]) < tol  # (lines, orders): the orders each line could be
    if not np.any(near.sum(axis=1) > 1):
        return coefs, gens
    lowest = np.array([orders[row][0] for row in near])
    ambiguous = near.sum(axis=1) > 1
    out, g, limit = k.copy(), gens, 4
    yd, idx = y - y.mean(), np.arange(y.size)
    while True:
        now = np.flatnonzero(lowest <= limit)
        stage = (
            np.flatnonzero((lowest > limit) & (lowest <= 4 * limit)) if now.size else np.flatnonzero(lowest <= limit)
        )
        stage = stage[ambiguous[stage]]  # a stage with no ambiguous line decides nothing: no refit for it
        if stage.size and now.size >= 2:
            g, _ = _refined(y, fs, g, out[now][:, None], [found_lines[i] for i in now], noise[now], True, False)
        if stage.size:
            power = np.abs(linefit.dtft(yd, idx, g, orders[:, None]))
        for i in stage:
            cand = orders[near[i]]
            best = int(cand[np.argmax(power[cand - 1])])
            if best != out[i] and best not in out:
                out[i] = best
        if limit >= orders.size:
            return out[:, None], g
        limit *= 4


def _fit_family(y, fs, fam, found_lines, passes, alpha, taken_f) -> LineFamily:
    """Refine the generators, add the lattice points the targeted test accepts, fit amplitudes."""
    n = y.size
    gens, coefs = _orient(np.asarray(fam["gens"], dtype=np.float64), np.asarray(fam["coefs"], dtype=np.int64))
    noise = np.array([d["noise"] for d in found_lines])
    coefs, gens = _unaliased(y, fs, gens, coefs, found_lines, noise)
    gens, cov = _refined(y, fs, gens, coefs, found_lines, noise)
    found = np.ones(coefs.shape[0], dtype=bool)
    rows, f_t = _targets({"coefs": coefs}, gens, passes, taken_f, fs)
    added = 0
    if rows.size:
        ratio, dof, dof_med = _ratio_at(passes, f_t)
        thr = f_dist.isf(alpha / (2.0 * rows.shape[0]), dof, dof_med)
        hit = ratio > thr
        if hit.any():
            coefs = np.vstack([coefs, rows[hit]])
            noise = np.concatenate([noise, _noise_at(passes, f_t[hit])])
            found = np.concatenate([found, np.zeros(int(hit.sum()), dtype=bool)])
            added = int(hit.sum())
    a, b = linefit.solve(y, np.arange(n), gens, coefs)
    if not np.all(np.isfinite(cov)):
        cov = np.diag(np.full(gens.size, np.nan))
    return LineFamily(
        fs=fs,
        gens=gens * fs,
        gens_cov=cov * fs * fs,
        coefs=coefs,
        a=a,
        b=b,
        noise=noise,
        found=found,
        n=n,
        evidence={
            "psd_ratio": [float(d["psd_ratio"]) for d in found_lines],
            "threshold": float(min(d["threshold"] for d in found_lines)),
            "targeted": {"tried": int(rows.shape[0]), "added": added},
        },
    )


def periodic_search(y: np.ndarray, fs: float, alpha: float, slow_alpha: float | None = None) -> dict:
    """Lines of ``y`` at false-alarm probability ``alpha`` per record, as families and isolated sinusoids; with
    ``slow_alpha``, a line of few cycles below the search's lowest bin too, tested in time at that false-alarm
    probability (:func:`allanite.model.slowline.slow_line_test`).

    Returns ``families`` (:class:`LineFamily`, two or more lines each, strongest (RMS) first), ``sinusoids`` (one-line
    :class:`LineFamily` each, strongest first), ``lines``, ``bins`` and ``p_value`` of the search
    (:func:`allanite.model.lines.find_lines`), ``slow`` (the line of few cycles found, as :func:`sinusoid_lines`
    gives a line, or none) and ``slow_test`` (that test's result; None where it did not run)."""
    y = np.asarray(y, dtype=np.float64)
    found = lines.find_lines(y, fs, alpha)
    found_lines, passes = found["lines"], found["passes"]
    groups = lines.group_lines(found_lines, fs)
    members = {i for g in groups for i in g["members"]}
    taken_f = np.array([d["f"] for d in found_lines])
    fams = [_fit_family(y, fs, g, [found_lines[i] for i in g["members"]], passes, alpha, taken_f) for g in groups]
    sins: list[LineFamily] = []
    for i, d in enumerate(found_lines):
        if i in members:
            continue
        # a lone line's harmonics, tested where they must be: found, the line is a family of its own
        one = {"gens": np.array([d["f"] / fs]), "coefs": np.array([[1]])}
        fit = _fit_family(y, fs, one, [d], passes, alpha, taken_f)
        (fams if fit.coefs.shape[0] > 1 else sins).append(fit)
    fams.sort(key=lambda fm: -fm.rms)
    slow_test = _slow_search(y, fs, slow_alpha, passes, taken_f) if slow_alpha is not None else None
    return {
        "families": fams,
        "sinusoids": sins,
        "lines": found_lines,
        "bins": found["bins"],
        "p_value": found["p_value"],
        "slow": [_slow_line(slow_test, y.size / fs)] if slow_test is not None and slow_test["accepted"] else [],
        "slow_test": slow_test,
    }


def _slow_search(y: np.ndarray, fs: float, alpha: float, passes: list[dict], taken_f: np.ndarray) -> dict | None:
    """The line of few cycles below the line search's lowest searched bin (:func:`allanite.model.slowline.
    slow_line_test`); not accepted where a line the search found lies within two cycles of it (the same line)."""
    searched = [ps["f"][np.flatnonzero(np.isfinite(ps["noise"]))[0]] for ps in passes if np.isfinite(ps["noise"]).any()]
    f_max = float(min(searched)) if searched else None
    test = slowline.slow_line_test(y, fs, alpha, f_max=f_max)
    if test is not None and test["accepted"] and taken_f.size:
        if np.min(np.abs(taken_f - test["f0"])) <= 2.0 * fs / y.size:
            test["accepted"] = False
            test["rejected"] = "a line the spectrum's search found"
    return test


def _slow_line(test: dict, length: float) -> dict:
    """A line of few cycles as :func:`sinusoid_lines` gives a line: its amplitude (least squares in time, all
    its power: a line of few cycles has no width to wander in) with ±1σ intervals, its test's statistic and
    threshold in place of the spectrum's ratio, and the test itself (``slow``)."""
    amp, sd, f0, f_sd = test["amplitude"], test["amplitude_sd"], test["f0"], test["f0_sd"]
    interval = (max(0.0, amp - sd), amp + sd)
    return {
        "f0": f0,
        "amplitude": amp,
        "phase": test["phase"],
        "f0_interval": (f0 - f_sd, f0 + f_sd),
        "amplitude_interval": interval,
        "power_amplitude": amp,
        "width_hz": (max(0.0, f0 - 1.0 / length), f0 + 1.0 / length),
        "power_amplitude_interval": interval,
        "psd_ratio": test["statistic"],
        "threshold": test["threshold"],
        "bin_hz": 1.0 / length,
        "slow": {k: test[k] for k in ("statistic", "threshold", "alpha", "p_value", "cycles", "separable", "band_hz")},
    }


def sinusoid_lines(search: dict, families=False) -> list[dict]:
    """The lines of a :func:`periodic_search` as the ``"sinusoid"`` candidate takes them, strongest first: each ``f0``
    (Hz, refined), ``amplitude`` and ``phase`` (least squares: the part whose phase carries across the record),
    ``f0_interval`` and ``amplitude_interval`` (±1σ), ``power_amplitude`` and its ``power_amplitude_interval``
    (√(2·power) of the line in the search's spectrum over its ``width_hz``: all its power, a wandering phase too —
    what the Allan curve sees), ``psd_ratio``, ``threshold`` and ``bin_hz`` of the search. The lone lines; with
    ``families`` True, every family's lines too (when families are not removed as a whole); given a list of the
    search's families, those families' lines (the ones a removal in time turned down: a line whose phase does not
    carry from one part of the record to the other — a site's sway, narrowband rather than coherent — is still power
    at its frequency, which the curve's sinusoid term describes)."""
    out: list[dict] = []
    found = np.array([d["f"] for d in search["lines"]])
    chosen = list(search["families"]) if families is True else list(families or [])
    sources = list(search["sinusoids"]) + chosen
    for fam in sources:
        freqs, amps, amp_sd = fam.frequencies, fam.amplitudes, fam.amplitude_sd
        lone = freqs.size == 1 and np.all(np.isfinite(fam.gens_sd))
        f_sd = fam.gens_sd if lone else linefit.frequency_sd(amps, fam.noise, fam.fs, fam.n)
        for i in range(freqs.size):
            if found.size == 0:
                break
            near = search["lines"][int(np.argmin(np.abs(found - freqs[i])))]
            if abs(near["f"] - freqs[i]) > 2 * near["bin_hz"]:
                continue  # a lattice point the targeted test added: not a line of the search itself
            out.append(
                {
                    "f0": float(freqs[i]),
                    "amplitude": float(amps[i]),
                    "phase": float(math.atan2(fam.a[i], fam.b[i])),
                    "f0_interval": (float(freqs[i] - f_sd[i]), float(freqs[i] + f_sd[i])),
                    "amplitude_interval": (max(0.0, float(amps[i] - amp_sd[i])), float(amps[i] + amp_sd[i])),
                    "power_amplitude": float(near["amplitude"]),
                    "width_hz": near["width_hz"],
                    "power_amplitude_interval": (
                        max(0.0, float(near["amplitude"] - near["amplitude_sd"])),
                        float(near["amplitude"] + near["amplitude_sd"]),
                    ),
                    "psd_ratio": float(near["psd_ratio"]),
                    "threshold": float(near["threshold"]),
                    "bin_hz": float(near["bin_hz"]),
                }
            )
    out += [dict(d) for d in search.get("slow", ())]  # a line of few cycles, tested in time (:func:`_slow_search`)
    out.sort(key=lambda d: -d["psd_ratio"])
    return out

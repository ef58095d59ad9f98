"""The window-function combination and the 2-D representation (paper 002).

:func:`combine`: the record is split by a wavelet (:func:`allanite.wavelet_split`), the trend is dropped,
the low band's DAVAR is taken with a rectangular window and the high band's with a Hann window, and
their sum is the combined surface. The noise coefficients are then fitted in every window
(:func:`allanite.fit`), optionally with a first-order Gauss–Markov term (paper 002's "exponentially
correlated noise"), giving each coefficient as a curve over time (paper 002 Fig. 5).

The sum of two band DAVARs is the DAVAR of the sum only if the bands are uncorrelated: AVAR(l + h) =
AVAR(l) + AVAR(h) + 2·C(l, h). The wavelet bands overlap in frequency (the db5 filters are not ideal),
so C ≠ 0; :attr:`Combination.cross` measures it on the record itself (both bands with rectangular
windows) — it is stated with every result, not assumed away.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ._progress import StepBar
from .analysis import davar
from .errors import ParameterError
from .estimators import get_taper
from .model import CoefficientSeries, fit
from .model.effects import gm_avar
from .model.fitting import nnls
from .model.terms import TERMS, check_terms, design_matrix
from .results import DynamicAllanResult
from .wavelet import Split, wavelet_split

__all__ = ["Combination", "combine"]

#: Correlation times searched for the Gauss–Markov term, as fractions of the longest τ.
_GM_GRID = np.geomspace(0.02, 0.25, 24)


@dataclass(frozen=True, repr=False, eq=False)
class Combination:
    """The combined DAVAR surface of a split record and its coefficients per window.

    Attributes
    ----------
    split : Split
        The wavelet split (its ``trend`` is not analysed).
    low, high : DynamicAllanResult
        DAVAR of the low band (``low_taper``) and of the high band (``high_taper``).
    combined : DynamicAllanResult
        ``low.avar + high.avar`` at the same τ and windows (``taper`` names the pair).
    cross : ndarray, (T,)
        Median over windows of the band cross term 2·C(l, h) relative to AVAR(l + h), both bands with
        rectangular windows: how far "the sum of the band DAVARs" is from the DAVAR of the summed bands.
    coefficients : CoefficientSeries
        The noise terms fitted in every window of ``combined`` (after the Gauss–Markov part, if any).
    gauss_markov : dict or None
        ``{"tc": T_c (s), "sigma": array over windows}`` when fitted.
    """

    split: Split
    low: DynamicAllanResult
    high: DynamicAllanResult
    combined: DynamicAllanResult
    cross: np.ndarray
    coefficients: CoefficientSeries
    gauss_markov: dict | None = None

    def __repr__(self) -> str:
        return (
            f"Combination({self.low.taper} on {'+'.join(self.split.bands['low']['levels'])}, "
            f"{self.high.taper} on {'+'.join(self.split.bands['high']['levels'])}, {self.combined.t.size} windows, "
            f"max |cross term| {np.max(np.abs(self.cross)):.2g} of the total)"
        )

    def plot(self, fig=None):
        """Paper 002 Fig. 4 and 5 in one figure: the low- and high-band DAVAR surfaces (3-D) and each
        coefficient against time."""
        import matplotlib.pyplot as plt

        terms = list(self.coefficients.terms) + (["GM"] if self.gauss_markov else [])
        fig = fig or plt.figure(figsize=(12, 4 + 2.0 * len(terms)))
        grid = fig.add_gridspec(2 + len(terms), 2, height_ratios=[3, 0.2] + [1] * len(terms))
        for col, (res, title) in enumerate(((self.low, "low band"), (self.high, "high band"))):
            ax = fig.add_subplot(grid[0, col], projection="3d")
            tt, lt = np.meshgrid(res.t, np.log10(res.tau))
            ax.plot_surface(tt, lt, np.log10(np.sqrt(res.avar)), cmap="viridis", linewidth=0)
            ax.set(xlabel="t (s)", ylabel="log10 τ (s)", zlabel="log10 ADEV", title=f"{title}, {res.taper} window")
        for k, term in enumerate(terms):
            ax = fig.add_subplot(grid[2 + k, :])
            if term == "GM":
                assert self.gauss_markov is not None
                ax.plot(self.combined.t, self.gauss_markov["sigma"], lw=0.8)
                ax.set_ylabel(f"GM σ (T_c = {self.gauss_markov['tc']:.3g} s)")
            else:
                c = self.coefficients
                ax.fill_between(c.t, c.ci_low[term], c.ci_high[term], alpha=0.25, lw=0)
                ax.plot(c.t, c.values[term], lw=0.8)
                ax.set_ylabel(term)
            ax.set_xlabel("t (s)")
        fig.tight_layout()
        return fig


def _cross_term(split: Split, fs, window, hop, taus, workers, done) -> np.ndarray:
    """``done``: band → its rectangular DAVAR when already computed (the band's taper is "rect")."""
    kw = dict(window=window, hop=hop, taus=taus, workers=workers)
    both = davar(split.low + split.high, fs, **kw).avar
    low = done["low"].avar if "low" in done else davar(split.low, fs, **kw).avar
    high = done["high"].avar if "high" in done else davar(split.high, fs, **kw).avar
    rel = (both - (low + high)) / np.where(both > 0, both, 1.0)
    return np.median(rel, axis=-1)


def _gauss_markov(res: DynamicAllanResult, terms) -> tuple[float, np.ndarray, np.ndarray]:
    """T_c from the windows' median curve (grid search, relative least squares), then σ per window by
    non-negative least squares with the other terms; returns (T_c, σ per window, its Allan variance
    (T, J))."""
    tau, m = res.tau, res.m.astype(np.float64)
    a0 = design_matrix(tau, m, res.fs, terms)
    med = np.median(res.avar, axis=1)
    best = (np.inf, 0.0)
    for tc in _GM_GRID * tau[-1]:
        a = np.column_stack([a0, gm_avar(tau, tc)]) / med[:, None]
        theta = nnls(a, np.ones_like(med))
        r = float(np.sum((a @ theta - 1.0) ** 2))
        if r < best[0]:
            best = (r, float(tc))
    tc = best[1]
    col = gm_avar(tau, tc)
    a = np.column_stack([a0, col])
    sig2 = np.empty(res.avar.shape[1])
    for j in range(res.avar.shape[1]):
        y = res.avar[:, j]
        w = 1.0 / np.maximum(y, 1e-300)
        sig2[j] = nnls(a * w[:, None], y * w)[-1]
    return tc, np.sqrt(sig2), col[:, None] * sig2[None, :]


def combine(
    x,
    fs,
    *,
    window,
    hop=1,
    taus="exp",
    split=None,
    low_taper: str = "rect",
    high_taper: str = "hann",
    terms=TERMS,
    gauss_markov: bool = False,
    unit=None,
    workers=None,
    progress=None,
) -> Combination:
    """Paper 002's window-function combination: split, DAVAR per band with its own taper, the summed
    surface, and every noise coefficient per window.

    Parameters
    ----------
    x : array_like, shape (samples,)
        Rate samples (paper 002: the dynamic error, gyro output − table rate).
    fs : float
        Sampling rate, Hz.
    window, hop : int
        DAVAR window and spacing, samples (paper 002: window 401).
    taus : str or array_like
        τ grid for the window, as for :func:`allanite.davar` (a named grid keeps the τ that leave ≥ 3
        terms for the Hann band).
    split : Split or dict, optional
        A :class:`~allanite.Split` of ``x``, or keyword arguments for :func:`allanite.wavelet_split`
        (default: db5, 5 levels, trend = A5, low = D5…D3, high = D2…D1). Removing A5 high-passes the
        record near fs/64: the low band's bias instability and random walk shrink by construction —
        ``split={"trend": "periodic"}`` removes a fitted periodic trend instead.
    low_taper, high_taper : str
        Tapers of the two bands (default rectangular and Hann).
    terms : sequence of {"Q", "N", "B", "K", "R"}
        Terms fitted in every window.
    gauss_markov : bool
        Also fit a first-order Gauss–Markov term: T_c from the windows' median curve, σ per window;
        its part is removed before the other terms are fitted.
    unit : str, optional
        Rate unit of the samples (IEEE-952 values in the coefficient series).
    workers : int, optional
    progress : bool, optional
        A ``tqdm.auto`` bar over the steps (split, DAVARs, cross term, fits per window): None (default)
        in a notebook or a terminal, True always, False never; it appears after a second.

    Returns
    -------
    Combination
    """
    terms = check_terms(terms)
    for taper in (low_taper, high_taper):
        get_taper(taper, "oavar")  # before any work: unknown names fail at once
    if not isinstance(split, (Split, dict)) and split is not None:
        raise ParameterError(f"split must be a Split, a dict of wavelet_split options or None, got {split!r}")
    with StepBar(progress, 5 + bool(gauss_markov), "combine") as bar:
        bar.step("wavelet split")
        parts = split if isinstance(split, Split) else wavelet_split(x, fs, **(split or {}))
        if parts.low.ndim != 1:
            raise ParameterError("combine takes one axis at a time: pass x of shape (samples,)")
        kw = dict(window=window, hop=hop, workers=workers)
        bar.step(f"DAVAR, high band ({high_taper})")
        high = davar(parts.high, fs, taus=taus, taper=high_taper, **kw)
        bar.step(f"DAVAR, low band ({low_taper})")
        low = davar(parts.low, fs, taus=high.tau, taper=low_taper, **kw)
        combined = dataclasses.replace(low, avar=low.avar + high.avar, taper=low_taper)
        bar.step("band cross term")
        rect = {band: res for band, res in (("low", low), ("high", high)) if res.taper == "rect"}
        cross = _cross_term(parts, fs, window, hop, high.tau, workers, rect)
        gm = None
        to_fit = combined
        if gauss_markov:
            bar.step("Gauss–Markov term")
            tc, sigma, part = _gauss_markov(combined, terms)
            gm = {"tc": tc, "sigma": sigma}
            to_fit = dataclasses.replace(combined, avar=np.maximum(combined.avar - part, 1e-30 * combined.avar))
        bar.step("noise fit per window")
        coefficients = fit(to_fit, terms=terms, unit=unit, progress=False)
    assert isinstance(coefficients, CoefficientSeries)
    return Combination(
        split=parts, low=low, high=high, combined=combined, cross=cross, coefficients=coefficients, gauss_markov=gm
    )

"""Brent's bounded minimisation of one variable as a coroutine, so that many searches can run in lockstep.

The candidates of a refinement step each refine their best grid value by a bounded search (Brent's method:
golden sections and parabolic steps, Forsythe, Malcolm & Moler's FMIN, the algorithm of
``scipy.optimize.minimize_scalar(method="bounded")``). Each evaluation is one reweighted fit of an Allan
curve; one at a time, a step fits some eighty of them one after another. As a generator that yields the point
it wants evaluated and receives the value, every search of a step can advance together and its fits run as one
batch (:func:`allanite.model.refinement.curvefit.searches`). The arithmetic is scipy's, operation for
operation, so the points visited and the minimiser are the same numbers bit for bit
(``tests/test_refine_cost.py`` checks it against scipy).
"""

from __future__ import annotations

import math
from collections.abc import Generator

import numpy as np

__all__ = ["bounded", "minimize"]

_SQRT_EPS = math.sqrt(2.2e-16)
_GOLDEN = 0.5 * (3.0 - math.sqrt(5.0))


def bounded(lo: float, hi: float, xatol: float = 1e-5, maxfun: int = 500) -> Generator[float, float, float]:
    """Minimise a function on [``lo``, ``hi``]: yields each point to evaluate, is sent its value; returns the
    minimiser (``StopIteration.value``). ``xatol``: absolute tolerance in x; ``maxfun``: evaluations at most."""
    a, b = lo, hi
    fulc = a + _GOLDEN * (b - a)
    nfc, xf = fulc, fulc
    rat = e = 0.0
    fx = yield xf
    num = 1
    ffulc = fnfc = fx
    xm = 0.5 * (a + b)
    tol1 = _SQRT_EPS * np.abs(xf) + xatol / 3.0
    tol2 = 2.0 * tol1
    while np.abs(xf - xm) > (tol2 - 0.5 * (b - a)):
        rat, e = _next_step(a, b, xf, xm, nfc, fulc, fx, fnfc, ffulc, rat, e, tol1, tol2)
        si = np.sign(rat) + (rat == 0)
        x = xf + si * np.maximum(np.abs(rat), tol1)
        fu = yield x
        num += 1
        if fu <= fx:
            if x >= xf:
                a = xf
            else:
                b = xf
            fulc, ffulc = nfc, fnfc
            nfc, fnfc = xf, fx
            xf, fx = x, fu
        else:
            if x < xf:
                a = x
            else:
                b = x
            if (fu <= fnfc) or (nfc == xf):
                fulc, ffulc = nfc, fnfc
                nfc, fnfc = x, fu
            elif (fu <= ffulc) or (fulc == xf) or (fulc == nfc):
                fulc, ffulc = x, fu
        xm = 0.5 * (a + b)
        tol1 = _SQRT_EPS * np.abs(xf) + xatol / 3.0
        tol2 = 2.0 * tol1
        if num >= maxfun:
            break
    return xf


def _next_step(a, b, xf, xm, nfc, fulc, fx, fnfc, ffulc, rat, e, tol1, tol2) -> tuple:
    """(step, previous step) of one iteration: the parabola through the three best points where it is
    acceptable (inside the bracket, less than half the step before last), else a golden section."""
    if np.abs(e) > tol1:
        r = (xf - nfc) * (fx - ffulc)
        q = (xf - fulc) * (fx - fnfc)
        p = (xf - fulc) * q - (xf - nfc) * r
        q = 2.0 * (q - r)
        if q > 0.0:
            p = -p
        q = np.abs(q)
        r = e
        e = rat
        if (np.abs(p) < np.abs(0.5 * q * r)) and (p > q * (a - xf)) and (p < q * (b - xf)):
            rat = (p + 0.0) / q
            x = xf + rat
            if ((x - a) < tol2) or ((b - x) < tol2):
                si = np.sign(xm - xf) + ((xm - xf) == 0)
                rat = tol1 * si
            return rat, e
    e = a - xf if xf >= xm else b - xf
    return _GOLDEN * e, e


def minimize(func, lo: float, hi: float, xatol: float = 1e-5) -> float:
    """The minimiser of ``func`` on [``lo``, ``hi``] by :func:`bounded`, one evaluation at a time."""
    gen = bounded(lo, hi, xatol)
    x = next(gen)
    try:
        while True:
            x = gen.send(func(x))
    except StopIteration as stop:
        return stop.value

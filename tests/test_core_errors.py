"""Each core error arrives as its `allanite.errors` class, with the core's message.

These call `allanite._core` directly, past the Python-side validation, so that the binding's mapping
itself is what is tested: InputError for unusable samples (too short, NaN/inf, axes that do not
match, non-contiguous memory), ParameterError for options outside their range.
"""

from __future__ import annotations

import numpy as np
import pytest

from allanite import _core
from allanite.errors import AllaniteError, InputError, ParameterError

Y = np.random.default_rng(0).normal(size=100)


def davar(columns, window=100, hop=1, ms=(1,), estimator="oavar", method="fast"):
    return _core.davar(columns, window, hop, list(ms), estimator, method, 1)


# --- InputError -----------------------------------------------------------------------------------


@pytest.mark.parametrize("bad", [np.nan, np.inf, -np.inf])
def test_non_finite_is_an_input_error(bad):
    y = Y.copy()
    y[37] = bad
    with pytest.raises(InputError, match=r"non-finite value \((NaN|inf|-inf)\) at sample 37 of axis 1"):
        davar([Y, y])
    with pytest.raises(InputError, match=r"at sample 37 of axis 0; only finite numbers are allowed"):
        _core.theo1_static([y], [2], 1)
    with pytest.raises(InputError, match=r"at sample 37 of axis 0"):
        _core.theo1_dynamic([y], 50, 1, [2], 1)


def test_too_short_is_an_input_error():
    one = np.array([1.0])
    with pytest.raises(InputError, match=r"^record is too short: 1 samples, at least 2 needed$"):
        davar([one], window=1)
    with pytest.raises(InputError, match=r"^record is too short: 1 samples, at least 2 needed$"):
        _core.theo1_static([one], [2], 1)
    with pytest.raises(InputError, match=r"^record is too short: 0 samples"):
        _core.theo1_dynamic([np.array([])], 2, 1, [2], 1)


def test_axes_that_do_not_match_are_an_input_error():
    with pytest.raises(
        InputError, match=r"^axis 1 has 60 samples but axis 0 has 100; all axes must have the same length$"
    ):
        davar([Y, Y[:60].copy()])
    with pytest.raises(InputError, match=r"^axis 1 has 60 samples but axis 0 has 100"):
        _core.theo1_static([Y, Y[:60].copy()], [2], 1)
    with pytest.raises(InputError, match=r"^no axes given: at least one record is needed$"):
        davar([])
    with pytest.raises(InputError, match=r"^no axes given"):
        _core.theo1_dynamic([], 10, 1, [2], 1)


def test_non_contiguous_memory_is_an_input_error():
    with pytest.raises(InputError, match=r"^axis 1 is not a contiguous float64 array$"):
        davar([Y[:50].copy(), Y[::2]], window=50)


# --- ParameterError -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"window": 101}, r"^window \(101 samples\) must be between 2 and the record length \(100 samples\)$"),
        ({"window": 1}, r"^window \(1 samples\) must be between 2"),
        ({"hop": 0}, r"^hop \(0\) must be at least 1 sample$"),
        ({"ms": ()}, r"^no averaging factors given$"),
        ({"ms": (0,)}, r"^averaging factor m = 0 is outside 1..=50 allowed for a window of 100 samples$"),
        ({"ms": (1, 51)}, r"^averaging factor m = 51 is outside 1..=50"),
        ({"estimator": "mdev"}, r"^unknown estimator \"mdev\"; allowed: 'oavar', 'avar'$"),
        ({"method": "slow"}, r"^unknown method \"slow\"; allowed: 'fast', 'naive'$"),
    ],
)
def test_davar_parameters(kwargs, message):
    with pytest.raises(ParameterError, match=message):
        davar([Y], **kwargs)


def test_theo1_parameters():
    with pytest.raises(
        ParameterError,
        match=r"^Theo1 averaging factor m = 3 is not allowed for a record of 100 samples: m must be even",
    ):
        _core.theo1_static([Y], [2, 3], 1)
    with pytest.raises(ParameterError, match=r"^Theo1 averaging factor m = 102 is not allowed for a record"):
        _core.theo1_static([Y], [102], 1)
    with pytest.raises(ParameterError, match=r"^no averaging factors given$"):
        _core.theo1_static([Y], [], 1)
    with pytest.raises(
        ParameterError, match=r"^Theo1 averaging factor m = 52 is not allowed for a window of 50 samples"
    ):
        _core.theo1_dynamic([Y], 50, 1, [52], 1)
    with pytest.raises(ParameterError, match=r"^window \(101 samples\) must be between 2"):
        _core.theo1_dynamic([Y], 101, 1, [2], 1)
    with pytest.raises(ParameterError, match=r"^hop \(0\) must be at least 1 sample$"):
        _core.theo1_dynamic([Y], 50, 0, [2], 1)


def test_the_classes_are_still_value_errors():
    # Callers that catch ValueError or AllaniteError keep working.
    with pytest.raises(ValueError):
        davar([Y], hop=0)
    with pytest.raises(AllaniteError):
        davar([Y[:1].copy()], window=1)
    try:
        davar([Y], hop=0)
    except AllaniteError as exc:
        assert type(exc) is ParameterError

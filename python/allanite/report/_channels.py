"""The report's ``channels=``: other channels of the record (a temperature, a supply voltage, an accelerometer)
for the model refinement's regression, checked before any heavy work."""

from __future__ import annotations

from collections.abc import Mapping

from ..errors import ParameterError


def check_channels(channels, candidates, n: int) -> dict | None:
    """``channels=`` checked: None or empty → None; else name → float64 samples (n of them, finite, not
    constant), refused without a refinement that tries the regression on them."""
    if channels is None or (isinstance(channels, Mapping) and not channels):
        return None
    if not isinstance(channels, Mapping):
        raise ParameterError(
            f"channels must be a dict of name → samples (e.g. {{'temp': T}}), got {type(channels).__name__}"
        )
    names = ", ".join(map(repr, map(str, channels)))
    if candidates is None:
        raise ParameterError(
            f"channels={{{names}}} are only used by the model refinement's regression: give refine=True "
            "(or refine= a list of effects with 'regression'), or drop channels="
        )
    if "regression" not in candidates:
        raise ParameterError(
            f"channels={{{names}}} are only used by the 'regression' effect, which refine={list(candidates)!r} "
            "leaves out: add 'regression' to the effects, or drop channels="
        )
    from ..model.channels import check_channel  # scipy.stats: only when channels are given

    checked: dict = {}
    for name, c in channels.items():
        if str(name) in checked:  # 1 and "1": one would replace the other silently
            raise ParameterError(f"two channels are named {str(name)!r}; each channel needs its own name")
        checked[str(name)] = check_channel(str(name), c, n)
    return checked

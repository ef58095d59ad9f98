"""The report's ``channels=``: other channels of the record (a temperature, a supply voltage, an accelerometer)
for the model refinement's regression, checked before any heavy work."""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

from ..errors import ParameterError


def check_channels(channels, candidates, n: int) -> dict | None:
    """``channels=`` checked: None or empty → None; else name → float64 samples (n of them, finite, not
    constant), refused when ``refine=`` names effects without the regression on them. ``candidates`` None (no
    refinement asked for) is checked by the caller, which then refines with every effect."""
    if channels is None or (isinstance(channels, Mapping) and not channels):
        return None
    if not isinstance(channels, Mapping):
        raise ParameterError(
            f"channels must be a dict of name → samples (e.g. {{'temp': T}}), got {type(channels).__name__}"
        )
    names = ", ".join(map(repr, map(str, channels)))
    if candidates is not None and "regression" not in candidates:
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


def rate_aligned(channels: dict | None, input: str) -> dict | None:
    """The channels one per rate sample: a cumulative angle's n samples give n − 1 rates (θ[i+1] − θ[i])·fs, each
    between two samples, so each channel is averaged over the same two samples; rates and increments as they are."""
    if not channels or input != "angle":
        return channels
    return {name: 0.5 * (c[:-1] + c[1:]) for name, c in channels.items()}


def log_channels(log, refine, notes: list) -> dict | None:
    """The channels :func:`~allanite.report.from_log` hands on from ``log.channels``: named ones (read_log's
    ``channels=[…]``) as they are — they imply the refinement, as ``channels=`` does; recognised ones (temperature
    names) only when the refinement asked for tries the regression, and then not a constant one. ``notes`` gains
    a line on each recognised channel: that it is not an axis, whether it was used, and how to choose otherwise."""
    if not log.channels:
        return None
    if not log.channels_recognised:
        return dict(log.channels)
    names = ", ".join(map(repr, log.channels))
    one = len(log.channels) == 1
    bag = log.format in ("ros1", "ros2")  # a bag's sensor_msgs/Temperature topics, at the Imu messages' times
    kind = "Topic" if bag else "Column"
    what = kind if one else f"{kind}s"
    how_found = "its type (sensor_msgs/Temperature)" if bag else "its name" if one else "their names"
    found = (
        f"{what} {names} {'was' if one else 'were'} recognised as a temperature by {how_found}: not analysed as "
        f"{'an axis' if one else 'axes'}"
    )
    how = "--channels none (read_log(channels=None)) leaves it out, --channels C1,… chooses the channels."
    tried = () if refine is None or refine is False else ("regression",) if refine is True else refine
    if "regression" not in ((tried,) if isinstance(tried, str) else tuple(tried)):
        asked = refine is not None and refine is not False
        why = "the refinement's effects leave out the regression" if asked else "no refinement was asked for (--refine)"
        notes.append(f"{found}, and not used: {why}, and a channel's only use is its regression. {how}")
        return None
    used = {k: c for k, c in log.channels.items() if np.ptp(c) > 0}
    for k in log.channels:
        if k not in used:
            notes.append(f"{kind} {k!r} (recognised as a temperature) is constant: not used as a channel.")
    if used:
        notes.append(
            f"{found}; every axis's model refinement tries a regression on {'it' if one else 'them'} (kept where its "
            f"test and the held-out error ask for it). {how}"
        )
    return used or None

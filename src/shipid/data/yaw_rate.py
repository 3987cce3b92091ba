"""The yaw rate against the heading: a gyro's offset, how far it moves the heading, and its
correction.

A rate gyro's constant offset b makes r exceed the heading's rate, so ψ − ∫r dt drifts at −b.
A model fitted to that r learns the offset as a yaw moment, and its heading (∫r of its own r)
drifts from the ship's: heading-based indices (zig-zag overshoots, the advance of a turn) move
with it, in replays and closed loop alike. On MARIN's KVLCC2 zig-zags the offset is 0.035–0.039
°/s at model scale, under 2 % of the rms r, yet over the 90 s of a run it puts the heading 3.5°
off. Subtracting it moves the held-out logs' closed-loop overshoots from 0.09° closer to 0.03°
further on average; replayed on its own training log, a model's second overshoot comes 2.7°
high with r as measured and 0.65° less the offset (``benchmarks/study_gyro_offset.py``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pandas as pd

from shipid.data.log import column_values
from shipid.data.preprocess import cumulative_integral, time_gaps, white_noise_variance
from shipid.errors import ShipidError


def yaw_rate_offset(t: np.ndarray, psi: np.ndarray, r: np.ndarray) -> float | None:
    """The constant b [rad/s] by which r exceeds the heading's rate (a gyro's offset): minus the
    least-squares slope of ψ − ∫r dt over the log (ψ unwrapped; ``heading_drift``). None for
    logs too short."""
    drift = heading_drift(t, psi, r)
    return None if drift is None else drift.offset


@dataclass(frozen=True)
class HeadingDrift:
    """How ψ − ∫r dt drifts over a log.

    Attributes
    ----------
    offset : b [rad/s], the constant by which r exceeds the heading's rate.
    drift : |b| times the log's duration [rad]: how far an integrated r ends from the heading.
    scatter : std of ψ − ∫r dt about its straight line [rad] (noise, gain errors, unsteady bias).
    duration : the log's duration [s].
    noise_drift : the std of the drift [rad] that white noise on r and ψ alone would give (its
        level read off their second differences): ∫ of white noise σ_r at step Δt is a random
        walk, whose least-squares slope over a duration T puts a drift of variance
        1.2 σ_r² Δt T (6D/5T for a Brownian motion of diffusion D = σ_r² Δt), and the heading's
        own noise σ_ψ adds 12 σ_ψ² / N.
    """

    offset: float
    drift: float
    scatter: float
    duration: float
    noise_drift: float

    @property
    def linear(self) -> float:
        """The drift over its scatter: large for a steady offset, a few for noise."""
        return self.drift / self.scatter if self.scatter > 0 else math.inf

    @property
    def beyond_noise(self) -> float:
        """The drift over the std of the drift the sensors' white noise alone would give."""
        return self.drift / self.noise_drift if self.noise_drift > 0 else math.inf


def heading_drift(t: np.ndarray, psi: np.ndarray, r: np.ndarray) -> HeadingDrift | None:
    """The straight line through ψ − ∫r dt (``HeadingDrift``); None for logs too short.

    Fitted beside a term in r: a heading sampled a time τ later or earlier than the rate (or
    integrated by Euler steps, a simulator's half step) puts −τ r into ψ − ∫r dt, which would
    otherwise count as scatter (a degree on the paper ship's zig-zag at Δk 0.2 s).
    Across a gap in time (``time_gaps``) neither ψ nor r says how the heading turned: the log
    is read as its pieces joined, the gap closed to one sampling interval."""
    t = np.asarray(t, dtype=float)
    if len(t) < 10 or not t[-1] > t[0]:
        return None
    r = np.asarray(r, dtype=float)
    gaps = time_gaps(t)
    if gaps:
        dts = np.diff(t)
        dts[gaps] = float(np.median(dts))
        t = t[0] + np.concatenate([[0.0], np.cumsum(dts)])
    drift = np.unwrap(np.asarray(psi, dtype=float)) - cumulative_integral(r, t)
    for k in gaps:
        drift[k + 1:] -= drift[k + 1] - drift[k]
    design = np.column_stack([np.ones_like(t), t - t.mean(), r])
    coef, *_ = np.linalg.lstsq(design, drift, rcond=None)
    slope = float(coef[1])
    scatter = float(np.std(drift - design @ coef))
    duration = float(t[-1] - t[0])
    step = float(np.median(np.diff(t)))
    noise_drift = math.sqrt(1.2 * white_noise_variance(r) * step * duration
                            + 12.0 * white_noise_variance(np.unwrap(psi)) / len(t))  # fmt: skip
    return HeadingDrift(-slope, abs(slope) * duration, scatter, duration, noise_drift)


def correct_yaw_rate(log: pd.DataFrame, offset: float | str, name: str) -> pd.DataFrame:
    """``log`` with r less a gyro's offset: ``offset`` in rad/s, or 'auto' for the log's own
    (``yaw_rate_offset``, which needs the heading psi). The offset subtracted is kept in
    ``attrs['yaw_rate_offset']`` [rad/s], added to one an earlier correction subtracted."""
    if offset == "auto":
        if "psi" not in log.columns:
            raise ShipidError(f"{name}: --yaw-rate-offset auto reads the offset off the heading, "
                              "and the log has no 'psi' column; give the offset in °/s")
        value = yaw_rate_offset(*(column_values(log, c, float) for c in ("t", "psi", "r")))
        if value is None:
            raise ShipidError(f"{name}: too short to read the yaw rate's offset off the heading "
                              "(--yaw-rate-offset auto needs at least 10 samples)")
    elif isinstance(offset, int | float) and math.isfinite(offset):
        value = float(offset)
    else:
        raise ShipidError(f"the yaw rate's offset must be 'auto' or a finite number [rad/s], "
                          f"got {offset!r}")
    out = log.assign(r=column_values(log, "r", float) - value)
    # The file keeps the whole offset taken off its r; this reading's share is said apart.
    out.attrs = {**log.attrs,
                 "yaw_rate_offset": float(log.attrs.get("yaw_rate_offset", 0.0)) + value,
                 "yaw_rate_offset_read": value}
    return out

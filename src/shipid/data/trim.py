"""Trimming a log to its manoeuvre: the rudder execute, the end of the manoeuvre, and gaps."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.ndimage import maximum_filter1d, minimum_filter1d

from shipid.errors import ShipidError

EXECUTE_FRACTION = 0.5  # a swing reaching this fraction of the largest one is a manoeuvre
EXECUTE_HOLD_S = 5.0  # ... and staying there this long (helm corrections do not)


def true_runs(mask: np.ndarray) -> list[tuple[int, int]]:
    """(first, last) indices of the runs of True in a boolean array."""
    edges = np.diff(np.concatenate([[0], np.asarray(mask, dtype=np.int8), [0]]))
    return list(zip(np.flatnonzero(edges == 1), np.flatnonzero(edges == -1) - 1, strict=True))


def rudder_execute_time(log: pd.DataFrame, name: str = "log") -> float:
    """Time of the rudder execute: the start of the swing to the first rudder plateau (constant
    within ±0.5° for 5 s) at least half the largest rudder angle. Helm corrections while the ship
    gathers speed are smaller or never steady."""
    t = log["t"].to_numpy()
    delta = log["delta"].to_numpy()
    dt = float(np.median(np.diff(t)))
    dev = np.abs(delta)
    peak = float(dev.max())
    window = max(int(round(EXECUTE_HOLD_S / dt)), 1) + 1
    # Spread of the rudder over the window starting at each sample.
    hi = maximum_filter1d(delta, window, origin=-(window // 2), mode="nearest")
    lo = minimum_filter1d(delta, window, origin=-(window // 2), mode="nearest")
    fits = np.arange(delta.size) + window <= delta.size
    plateau = (dev >= EXECUTE_FRACTION * peak) & (hi - lo <= np.radians(1.0)) & fits
    if peak < np.radians(1.0) or not plateau.any():
        raise ShipidError(f"{name}: no rudder execute found (no rudder deflection held for "
                          f"{EXECUTE_HOLD_S:g} s); give --start in seconds")  # fmt: skip
    k = int(np.argmax(plateau))
    return float(t[swing_start(delta, k, np.sign(delta[k]))])


def swing_start(delta: np.ndarray, k: int, side: float) -> int:
    """Back from sample k along the rudder swing towards ``side`` (±1), to where it started."""
    while k > 0 and side * (delta[k] - delta[k - 1]) > 0:
        k -= 1
    return k


def first_swing_index(delta: np.ndarray) -> int:
    """Start of the first swing that takes the rudder at least halfway from its initial angle to
    its largest deflection from it (0 if the rudder never moves)."""
    dev = np.abs(delta - delta[0])
    if dev.max() <= 0:
        return 0
    k = int(np.argmax(dev >= EXECUTE_FRACTION * dev.max()))
    return swing_start(delta, k, np.sign(delta[k] - delta[0]))


def manoeuvre_end_time(log: pd.DataFrame, name: str = "log") -> float:
    """End of the manoeuvre: the last sample with the rudder at least half its largest angle, or
    earlier, the last sample before the propeller speed (column n) falls below 80 % of its median
    during the manoeuvre (the run is being stopped)."""
    t = log["t"].to_numpy()
    delta = log["delta"].to_numpy()
    start = int(np.searchsorted(t, rudder_execute_time(log, name)))
    big = np.flatnonzero(np.abs(delta) >= EXECUTE_FRACTION * np.abs(delta).max())
    k = int(big[-1])
    if "n" in log.columns:
        n = np.abs(log["n"].to_numpy())
        typical = float(np.median(n[start : k + 1]))
        low = np.flatnonzero(n[start : k + 1] < 0.8 * typical)
        if typical > 0 and low.size:
            k = start + int(low[0]) - 1
    return float(t[max(k, start)])


def _auto_time(value, option: str) -> bool:
    if isinstance(value, str):
        if value != "auto":
            raise ShipidError(f"{option} must be a time in seconds or 'auto', got {value!r}")
        return True
    return False


def trim(log: pd.DataFrame, start: float | str | None = None, end: float | str | None = None,
         name: str = "log", lead: float = 5.0) -> pd.DataFrame:  # fmt: skip
    """Rows with start ≤ t ≤ end, time kept as is. ``start="auto"`` starts ``lead`` seconds
    before the detected rudder execute (``rudder_execute_time``); ``end="auto"`` ends with the
    manoeuvre (``manoeuvre_end_time``)."""
    t = log["t"]
    if _auto_time(start, "--start"):
        if not lead >= 0:
            raise ShipidError(f"--lead must be ≥ 0 s, got {lead!r}")
        start = max(rudder_execute_time(log, name) - lead, float(t.iloc[0]))
    if _auto_time(end, "--end"):
        end = manoeuvre_end_time(log, name)
    keep = np.ones(len(log), dtype=bool)
    if start is not None:
        keep &= t >= start
    if end is not None:
        keep &= t <= end
    if start is not None and end is not None and end <= start:
        raise ShipidError(f"--end ({end}) must be after --start ({start})")
    out = log.loc[keep].reset_index(drop=True)
    out.attrs = dict(log.attrs)
    if len(out) < 3:
        raise ShipidError(f"{name}: only {len(out)} samples between --start and --end "
                          f"(the log spans {t.iloc[0]:g}–{t.iloc[-1]:g} s)")  # fmt: skip
    return out

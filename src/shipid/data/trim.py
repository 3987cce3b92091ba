"""Trimming a log to its manoeuvre: the rudder execute and the end of the manoeuvre."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd

from shipid.data.log import column_values, require_columns
from shipid.errors import ShipidError, ShipidWarning

EXECUTE_FRACTION = 0.5  # a swing reaching this fraction of the largest one is a manoeuvre
EXECUTE_HOLD_S = 5.0  # ... and staying there this long (helm corrections do not)
PLATEAU_SPREAD = math.radians(1.0)  # ... within this spread
# Orders held are read against the largest angle held where it is this share of the largest
# deflection or more (helm corrections up to 2.5 times the orders): ``held_peak``.
HELD_PEAK_SHARE = 0.4
# A step of the rudder smaller than this fraction of the swing's steepest step is not part of the
# swing: a resampled rudder creeps by 1e-4° per sample before the order, a real swing moves degrees.
SWING_STEP_FRACTION = 0.05
# An automatic trim that keeps less than this fraction of the log is reported.
TRIM_KEEP_WARN = 0.25
DEFAULT_LEAD_S = 5.0  # --start auto: seconds kept before the execute


def forward_extremes(x: np.ndarray, window: int) -> tuple[np.ndarray, np.ndarray]:
    """The largest and the smallest of ``x`` over the ``window`` samples from each sample on
    (the last sample repeated past the end), in O(n) whatever the window: blocks of ``window``
    samples, the running extremes from each block's start and from its end, two of which
    cover any window (van Herk 1992; Gil and Werman 1993). SciPy's ``maximum_filter1d`` does the
    same, but importing ``scipy.ndimage`` cost every command that trims a log 0.1–0.3 s."""
    n = x.size
    blocks = -(-(n + window - 1) // window)
    padded = np.full(blocks * window, x[-1], dtype=float)
    padded[:n] = x
    starts = np.arange(n)
    out = []
    for extreme in (np.maximum, np.minimum):
        rows = padded.reshape(blocks, window)
        from_start = extreme.accumulate(rows, axis=1).ravel()
        to_end = extreme.accumulate(rows[:, ::-1], axis=1)[:, ::-1].ravel()
        out.append(extreme(to_end[starts], from_start[starts + window - 1]))
    return out[0], out[1]


def held_plateaus(t: np.ndarray, delta: np.ndarray, hold_s: float = EXECUTE_HOLD_S
                  ) -> np.ndarray:  # fmt: skip
    """Where the rudder ``delta`` (sampled at ``t``) stays within ``PLATEAU_SPREAD`` for
    ``hold_s`` from each sample on: a held order, which a helm correction is not."""
    dt = float(np.median(np.diff(t)))
    window = max(int(round(hold_s / dt)), 1) + 1
    hi, lo = forward_extremes(delta, window)
    fits = np.arange(delta.size) + window <= delta.size
    return (hi - lo <= PLATEAU_SPREAD) & fits


def held_peak(t: np.ndarray, dev: np.ndarray, hold_s: float = EXECUTE_HOLD_S,
              flat: np.ndarray | None = None) -> float:
    """The largest deflection ``dev`` the rudder holds for ``hold_s`` (``held_plateaus``) where
    it is at least ``HELD_PEAK_SHARE`` of the largest, else the largest: the trial's orders, not
    a larger helm correction made briefly before them. A log that starts at rest carries such
    corrections (the Esso Osaka's, 13–22° for one or two seconds); against the largest
    deflection, orders under half of it (a 10° zig-zag after a 22° correction) were never found,
    and the log read as no manoeuvre. The share keeps a small angle held long, where the orders
    are held shorter than ``hold_s`` (a ship's rest angle on its approach, −6° before a quick
    zig-zag's 20°), from being taken for them. ``flat``: ``held_plateaus(t, dev, hold_s)``,
    where the caller has it."""
    largest = float(np.max(np.abs(dev)))
    flat = held_plateaus(t, dev, hold_s) if flat is None else flat
    held = float(np.max(np.abs(dev[flat]))) if flat.any() else largest
    return held if held >= HELD_PEAK_SHARE * largest else largest


def rudder_execute_time(log: pd.DataFrame, name: str = "log") -> float:
    """Time of the rudder execute: the start of the swing to the first rudder plateau (constant
    within ±0.5° for 5 s) at least half the largest plateau's angle (``held_peak``). Helm
    corrections while the ship gathers speed are smaller or never steady."""
    from shipid.data.rudder_signal import rudder_for_events, stand_samples

    t = column_values(log, "t")
    delta, noise = rudder_for_events(t, column_values(log, "delta"))
    dev = np.abs(delta)
    flat = held_plateaus(t, delta)
    plateau = (dev >= EXECUTE_FRACTION * held_peak(t, delta, flat=flat)) & flat
    if dev.max() < np.radians(1.0) or not plateau.any():
        raise ShipidError(f"{name}: no rudder execute found (no rudder deflection held for "
                          f"{EXECUTE_HOLD_S:g} s); give --start in seconds")  # fmt: skip
    k = int(np.argmax(plateau))
    return float(t[swing_start(delta, k, np.sign(delta[k]), stand_samples(t) if noise else 0)])


def swing_start(delta: np.ndarray, k: int, side: float, max_stand: int = 0) -> int:
    """Back from sample k along the rudder swing towards ``side`` (±1), to where it started: the
    last sample before the rudder moved by more than ``SWING_STEP_FRACTION`` of the swing's
    steepest step (the order), so that a slow creep before the order does not count. With
    ``max_stand`` > 0 (a denoised rudder, ``shipid.data.rudder_signal``: no creep, uneven steps
    as its dead band releases) a stand of fewer samples inside the swing is crossed instead, and
    the swing starts where the rudder stood longer or moved the other way."""
    steepest = 0.0
    while k > 0:
        step = side * (delta[k] - delta[k - 1])
        if step == 0 and max_stand:
            j = k - 1
            while j > 0 and delta[j - 1] == delta[k] and k - j < max_stand:
                j -= 1
            if j > 0 and k - j < max_stand and side * (delta[j] - delta[j - 1]) > 0:
                k = j
                continue
        # A denoised rudder does not creep, and its steps are uneven (the dead band releases).
        if step <= 0 or (not max_stand and step < SWING_STEP_FRACTION * steepest):
            break
        steepest = max(steepest, step)
        k -= 1
    return k


def first_swing_index(delta: np.ndarray, max_stand: int = 0) -> int:
    """Start of the first swing that takes the rudder at least halfway from its initial angle to
    its largest deflection from it (0 if the rudder never moves); ``max_stand`` as
    ``swing_start``'s."""
    dev = np.abs(delta - delta[0])
    if dev.max() <= 0:
        return 0
    k = int(np.argmax(dev >= EXECUTE_FRACTION * dev.max()))
    return swing_start(delta, k, np.sign(delta[k] - delta[0]), max_stand)


def manoeuvre_end_time(log: pd.DataFrame, name: str = "log", execute: float | None = None) -> float:
    """End of the manoeuvre: the last sample with the rudder at least half its largest angle
    from the execute on, or earlier, the last sample before the propeller speed (column n) falls
    below 80 % of its median during the manoeuvre (the run is being stopped). From the execute
    on: a helm correction before it larger than the orders (``held_peak``) ended a 10° zig-zag
    at its own execute."""
    t = column_values(log, "t")
    delta = column_values(log, "delta")
    if execute is None:
        execute = rudder_execute_time(log, name)
    start = min(int(np.searchsorted(t, execute)), len(t) - 1)
    after = np.abs(delta[start:])
    k = start + int(np.flatnonzero(after >= EXECUTE_FRACTION * after.max())[-1])
    if "n" in log.columns:
        n = np.abs(column_values(log, "n"))
        typical = float(np.median(n[start : k + 1]))
        low = np.flatnonzero(n[start : k + 1] < 0.8 * typical)
        if typical > 0 and low.size:
            k = start + int(low[0]) - 1
    return float(t[max(k, start)])


def _auto_time(value, option: str) -> bool:
    if isinstance(value, str):
        allowed = ("auto", "dropout") if option == "--end" else ("auto",)
        if value not in allowed:
            raise ShipidError(f"{option} must be a time in seconds or "
                              f"{' or '.join(repr(a) for a in allowed)}, got {value!r}")
        return value == "auto"
    return False


def dropout_end(log: pd.DataFrame, name: str = "log") -> float | None:
    """The last sample before the first propulsion dropout
    (``shipid.data.checks.propulsion_dropouts``), or None when there is none."""
    from shipid.data.checks import propulsion_dropouts

    found = propulsion_dropouts(log)
    if not found:
        return None
    if found[0].before is None:
        raise ShipidError(f"{name}: --end dropout: the log starts in a propulsion dropout "
                          f"(t = {found[0].start:g}–{found[0].end:g} s); give --start")  # fmt: skip
    return found[0].before


def trim(log: pd.DataFrame, start: float | str | None = None, end: float | str | None = None,
         name: str = "log", lead: float = DEFAULT_LEAD_S) -> pd.DataFrame:  # fmt: skip
    """Rows with start ≤ t ≤ end, time kept as is. ``start="auto"`` starts ``lead`` seconds
    before the detected rudder execute (``rudder_execute_time``); ``end="auto"`` ends with the
    manoeuvre (``manoeuvre_end_time``); ``end="dropout"`` before the first span whose logged
    propeller speed cannot have driven the ship (``dropout_end``; the whole log if none)."""
    auto = "auto" in (start, end)
    require_columns(log, ("t", "delta") if auto else ("t",), name,
                    "'auto' finds the manoeuvre by its rudder" if auto else "")  # fmt: skip
    t = log["t"]
    if isinstance(end, str) and end == "dropout":
        end = dropout_end(log, name)
    for option, value in (("--start", start), ("--end", end)):
        if isinstance(value, int | float) and not math.isfinite(value):
            raise ShipidError(f"{option} must be a finite time in seconds or 'auto', got {value!r}")
    auto_start, auto_end = _auto_time(start, "--start"), _auto_time(end, "--end")
    execute = rudder_execute_time(log, name) if auto_start or auto_end else None
    if auto_start:
        if not (isinstance(lead, int | float) and math.isfinite(lead) and lead >= 0):
            raise ShipidError(f"--lead must be a finite number of seconds ≥ 0, got {lead!r}")
        start = max(execute - lead, float(t.iloc[0]))
    if auto_end:
        end = manoeuvre_end_time(log, name, execute)
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
    if execute is not None:
        _check_auto_span(out, log, name, execute)
    return out


def _check_auto_span(out: pd.DataFrame, log: pd.DataFrame, name: str, execute: float) -> None:
    """An automatic trim must keep at least the rudder plateau that defined the execute; keeping
    little of a long log says the log is not one zig-zag or turning circle (e.g. random rudder)."""
    kept = float(out["t"].iloc[-1] - out["t"].iloc[0])
    after = float(out["t"].iloc[-1]) - execute
    total = float(log["t"].iloc[-1] - log["t"].iloc[0])
    span = f"t = {out['t'].iloc[0]:g}–{out['t'].iloc[-1]:g} s"
    if after < EXECUTE_HOLD_S:
        raise ShipidError(f"{name}: --start/--end auto kept {kept:.3g} s ({span}) of a "
                          f"{total:.4g} s log, only {max(after, 0):.3g} s after the rudder execute "
                          f"at t = {execute:g} s: no single zig-zag or turning circle found "
                          "(random rudder?); give --start and --end in seconds")  # fmt: skip
    if kept < TRIM_KEEP_WARN * total:
        warnings.warn(f"{name}: --start/--end auto kept {kept:.4g} s ({span}) of a {total:.4g} s "
                      "log; check that this is the manoeuvre", ShipidWarning, stacklevel=3)

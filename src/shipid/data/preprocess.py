"""Preprocessing of canonical logs: resampling to a uniform Δk, zero-phase low-pass."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pandas as pd

from shipid.errors import ShipidError, ShipidWarning
from shipid.limits import check_samples

SIGNALS = ("u", "v", "r")
MAX_UPSAMPLING = 100.0
# A --dt below this share of the log's own sampling interpolates samples between the measured ones.
UPSAMPLED = 0.99
# An interval longer than this many of the log's median sampling intervals is a gap: samples
# missing, not a sampling that varies. Resampling would draw straight lines across it, and a
# free run would take one step across it with the rudder unknown (a 20/20 zig-zag with 30 s
# missing: the replay diverged, the fit came from 150 invented samples).
GAP_INTERVALS = 10.0


def time_gaps(t: np.ndarray) -> list[int]:
    """Indices k where t[k + 1] − t[k] exceeds ``GAP_INTERVALS`` median intervals."""
    dts = np.diff(np.asarray(t, dtype=float))
    if dts.size == 0:
        return []
    return [int(k) for k in np.flatnonzero(dts > GAP_INTERVALS * float(np.median(dts)))]


def gap_text(t: np.ndarray, gaps: list[int]) -> str:
    """'no samples for 30.2 s (t = 50–80.2, after data row 251)' and how many more."""
    k = gaps[0]
    more = f" and {len(gaps) - 1} more gap(s)" if len(gaps) > 1 else ""
    return (f"no samples for {t[k + 1] - t[k]:.3g} s (t = {t[k]:.6g}–{t[k + 1]:.6g}, after data "
            f"row {k + 1}){more}")



def cumulative_integral(y: np.ndarray, t: np.ndarray, initial: float = 0.0) -> np.ndarray:
    """∫ y dt from t[0] by the trapezoidal rule, sample by sample."""
    out = np.empty(len(y))
    out[0] = initial
    np.cumsum(0.5 * (y[1:] + y[:-1]) * np.diff(t), out=out[1:])
    out[1:] += initial
    return out


def white_noise_variance(x: np.ndarray) -> float:
    """Variance of the white noise on a smooth signal, from its second differences
    (Var Δ²e = 6σ²), robustly (1.4826·MAD). The signal's own second differences, small at a
    sampling that resolves it, add to it."""
    d2 = np.diff(np.asarray(x, dtype=float), 2)
    if d2.size < 3:
        return 0.0
    mad = float(np.median(np.abs(d2 - np.median(d2))))
    return (1.4826 * mad) ** 2 / 6.0


def resample(log: pd.DataFrame, dt: float, name: str = "log", fill_gaps: bool = False
             ) -> pd.DataFrame:  # fmt: skip
    """Linear interpolation of every column onto t0, t0 + dt, ... (heading unwrapped first).

    A ``dt`` finer than the log's own sampling keeps that sampling in ``attrs["measured_dt"]``.
    A gap in time (``time_gaps``) is refused, or with ``fill_gaps`` interpolated with a warning.
    """
    if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
        raise ShipidError(f"--dt must be a finite number > 0, got {dt!r}")
    from shipid.data.log import column_values, require_columns

    require_columns(log, ("t",), name, "a log to resample has its time")
    t = column_values(log, "t")
    gaps = time_gaps(t)
    if gaps and not fill_gaps:
        raise ShipidError(f"{name}: {gap_text(t, gaps)}: resampling would draw straight lines "
                          "across it; cut the log there (--start/--end) or split it into two "
                          "logs (--fill-gaps interpolates it anyway)")  # fmt: skip
    if gaps:
        warnings.warn(f"{name}: {gap_text(t, gaps)}, interpolated in straight lines "
                      "(--fill-gaps)", ShipidWarning, stacklevel=2)  # fmt: skip
    own = float(np.median(np.diff(t)))
    if dt < own / MAX_UPSAMPLING:
        raise ShipidError(f"{name}: --dt {dt:g} s is {own / dt:.3g} times finer than the log's "
                          f"own sampling ({own:g} s): resampling would invent data; use at most "
                          f"{MAX_UPSAMPLING:g} times finer")  # fmt: skip
    n = check_samples(math.floor((t[-1] - t[0]) / dt + 1e-9) + 1, 8 * (len(log.columns) + 1),
                      f"{name}: resampling {t[-1] - t[0]:g} s at --dt {dt:g}")
    grid = t[0] + dt * np.arange(n)
    if len(grid) < 3:
        raise ShipidError(f"{name}: resampling at --dt {dt} leaves {len(grid)} samples")
    cols = {"t": grid}
    for c in log.columns:
        if c == "t":
            continue
        values = column_values(log, c)
        if c in ("psi", "wind_angle"):
            values = np.unwrap(values)
        cols[c] = np.interp(grid, t, values)
        if c == "wind_angle":
            cols[c] = np.angle(np.exp(1j * cols[c]))
    out = pd.DataFrame(cols)
    out.attrs = dict(log.attrs)
    if dt < UPSAMPLED * own:
        # In memory only (not file metadata): a fit told that its samples between are lines.
        out.attrs["measured_dt"] = own
    return out


def lowpass(log: pd.DataFrame, cutoff_hz: float, columns=SIGNALS, order: int = 2) -> pd.DataFrame:
    """Zero-phase Butterworth low-pass of the motion signals (not the rudder, which is commanded).

    Filtering the regressors removes most of the errors-in-variables bias of the one-step
    regression (noise on ξ(k) sits both in the regressors and in the difference ξ(k+1) − ξ(k)).
    """
    from shipid.data.butterworth import butter_lowpass_sos, sosfiltfilt
    from shipid.data.log import column_values, require_columns

    require_columns(log, ("t",), why="a log to filter has its time")
    t = column_values(log, "t")
    fs = 1.0 / float(np.median(np.diff(t)))
    if not 0 < cutoff_hz < fs / 2:
        raise ShipidError(f"--filter cut-off must be between 0 and the Nyquist frequency "
                          f"{fs / 2:g} Hz, got {cutoff_hz!r}")  # fmt: skip
    sos = butter_lowpass_sos(order, cutoff_hz, fs)
    out = log.copy()
    out.attrs = dict(log.attrs)
    for c in columns:
        if c in out.columns and len(out) > 3 * (2 * order + 1):
            out[c] = sosfiltfilt(sos, column_values(out, c))
    out.attrs["lowpass_hz"] = cutoff_hz
    return out

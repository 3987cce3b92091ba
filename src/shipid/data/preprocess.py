"""Preprocessing of canonical logs: resampling to a uniform Δk, zero-phase low-pass."""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.signal import butter, sosfiltfilt

from shipid.errors import ShipidError

SIGNALS = ("u", "v", "r")


def resample(log: pd.DataFrame, dt: float, name: str = "log") -> pd.DataFrame:
    """Linear interpolation of every column onto t0, t0 + dt, ... (heading unwrapped first)."""
    if not dt > 0:
        raise ShipidError(f"--dt must be > 0, got {dt!r}")
    t = log["t"].to_numpy()
    grid = np.arange(t[0], t[-1] + 1e-9 * dt, dt)
    if len(grid) < 3:
        raise ShipidError(f"{name}: resampling at --dt {dt} leaves {len(grid)} samples")
    cols = {"t": grid}
    for c in log.columns:
        if c == "t":
            continue
        values = log[c].to_numpy()
        if c == "psi":
            values = np.unwrap(values)
        cols[c] = np.interp(grid, t, values)
    out = pd.DataFrame(cols)
    out.attrs = dict(log.attrs)
    return out


def lowpass(log: pd.DataFrame, cutoff_hz: float, columns=SIGNALS, order: int = 2) -> pd.DataFrame:
    """Zero-phase Butterworth low-pass of the motion signals (not the rudder, which is commanded).

    Filtering the regressors removes most of the errors-in-variables bias of the one-step
    regression (noise on ξ(k) sits both in the regressors and in the difference ξ(k+1) − ξ(k)).
    """
    t = log["t"].to_numpy()
    fs = 1.0 / float(np.median(np.diff(t)))
    if not 0 < cutoff_hz < fs / 2:
        raise ShipidError(f"--filter cut-off must be between 0 and the Nyquist frequency "
                          f"{fs / 2:g} Hz, got {cutoff_hz!r}")  # fmt: skip
    sos = butter(order, cutoff_hz, fs=fs, output="sos")
    out = log.copy()
    out.attrs = dict(log.attrs)
    for c in columns:
        if c in out.columns and len(out) > 3 * (2 * order + 1):
            out[c] = sosfiltfilt(sos, out[c].to_numpy())
    out.attrs["lowpass_hz"] = cutoff_hz
    return out

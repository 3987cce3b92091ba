"""Preprocessing of canonical logs: resampling to a uniform Δk, zero-phase low-pass."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd

from shipid.errors import ShipidError
from shipid.limits import check_samples

SIGNALS = ("u", "v", "r")
MAX_UPSAMPLING = 100.0
# A --dt below this share of the log's own sampling interpolates samples between the measured ones.
UPSAMPLED = 0.99



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


def resample(log: pd.DataFrame, dt: float, name: str = "log") -> pd.DataFrame:
    """Linear interpolation of every column onto t0, t0 + dt, ... (heading unwrapped first).

    A ``dt`` finer than the log's own sampling keeps that sampling in ``attrs["measured_dt"]``.
    """
    if not (isinstance(dt, int | float) and math.isfinite(dt) and dt > 0):
        raise ShipidError(f"--dt must be a finite number > 0, got {dt!r}")
    t = log["t"].to_numpy()
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
        values = log[c].to_numpy()
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

    t = log["t"].to_numpy()
    fs = 1.0 / float(np.median(np.diff(t)))
    if not 0 < cutoff_hz < fs / 2:
        raise ShipidError(f"--filter cut-off must be between 0 and the Nyquist frequency "
                          f"{fs / 2:g} Hz, got {cutoff_hz!r}")  # fmt: skip
    sos = butter_lowpass_sos(order, cutoff_hz, fs)
    out = log.copy()
    out.attrs = dict(log.attrs)
    for c in columns:
        if c in out.columns and len(out) > 3 * (2 * order + 1):
            out[c] = sosfiltfilt(sos, out[c].to_numpy())
    out.attrs["lowpass_hz"] = cutoff_hz
    return out

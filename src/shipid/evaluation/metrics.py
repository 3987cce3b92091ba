"""Error metrics between measured and simulated signals, and residual analysis.

The paper's table uses the std of the error, which hides a bias; every metric is reported:
rmse, the NRMSE fit in percent as MATLAB's ``compare`` (100·(1 − ‖y − ŷ‖/‖y − ȳ‖): 100 % is a
perfect prediction, 0 % no better than the mean, negative worse), the mean (bias), std, max |error|
and the rmse over the measured range.

Residual analysis (``residual_correlations``): a model that explains the data leaves an error
that is white and uncorrelated with the input. The autocorrelation of the error and its
cross-correlation with the rudder, at lags 0…``max_lag``, with the 95 % band ±1.96/√N of white
noise.
"""

from __future__ import annotations

import numpy as np


def fit_percent(measured: np.ndarray, simulated: np.ndarray) -> float:
    """NRMSE fit [%] of MATLAB's ``compare``: 100·(1 − ‖y − ŷ‖ / ‖y − mean(y)‖)."""
    y = np.asarray(measured, float)
    e = y - np.asarray(simulated, float)
    spread = float(np.linalg.norm(y - y.mean()))
    return 100.0 * (1.0 - float(np.linalg.norm(e)) / spread) if spread > 0 else float("nan")


def error_metrics(measured: np.ndarray, simulated: np.ndarray) -> dict[str, float]:
    """rmse, fit % (see ``fit_percent``), mean (bias), std (the paper's metric), max |error| and
    nrmse (rmse / measured range)."""
    y = np.asarray(measured, float)
    e = y - np.asarray(simulated, float)
    rmse = float(np.sqrt(np.mean(e**2)))
    span = float(np.ptp(y))
    return {"rmse": rmse, "fit_percent": fit_percent(y, y - e), "mean": float(np.mean(e)),
            "std": float(np.std(e)), "max_abs": float(np.max(np.abs(e))),
            "nrmse": rmse / span if span > 0 else float("nan")}  # fmt: skip


def _correlation(a: np.ndarray, b: np.ndarray, max_lag: int) -> np.ndarray:
    """Normalised cross-correlation Σ a(k) b(k − τ) / (N σa σb), τ = 0…max_lag (FFT, O(N log N))."""
    a = a - a.mean()
    b = b - b.mean()
    n = len(a)
    size = 1 << int(np.ceil(np.log2(2 * n)))
    full = np.fft.irfft(np.fft.rfft(a, size) * np.conj(np.fft.rfft(b, size)), size)
    denom = n * a.std() * b.std()
    return full[: max_lag + 1] / denom if denom > 0 else np.full(max_lag + 1, np.nan)


def residual_correlations(measured: np.ndarray, simulated: np.ndarray, rudder: np.ndarray,
                          max_lag: int = 50) -> dict:  # fmt: skip
    """Autocorrelation of the error and its cross-correlation with the rudder at lags 0…max_lag,
    the white-noise band, and the share of lags ≥ 1 outside it (≈ 5 % for a white residual)."""
    e = np.asarray(measured, float) - np.asarray(simulated, float)
    n = len(e)
    max_lag = int(min(max_lag, n - 1))
    band = 1.96 / np.sqrt(n)
    auto = _correlation(e, e, max_lag)
    cross = _correlation(e, np.asarray(rudder, float)[:n], max_lag)
    return {"lags": list(range(max_lag + 1)), "autocorrelation": auto.tolist(),
            "cross_correlation_rudder": cross.tolist(), "band": float(band),
            "auto_outside": float(np.mean(np.abs(auto[1:]) > band)) if max_lag else float("nan"),
            "cross_outside": float(np.mean(np.abs(cross) > band))}  # fmt: skip

"""Error metrics between measured and simulated signals (the paper's table uses the std)."""

from __future__ import annotations

import numpy as np


def error_metrics(measured: np.ndarray, simulated: np.ndarray) -> dict[str, float]:
    """mean, std (the paper's metric), rmse, max |error| and nrmse (rmse / measured range)."""
    e = np.asarray(measured, float) - np.asarray(simulated, float)
    rmse = float(np.sqrt(np.mean(e**2)))
    span = float(np.ptp(measured))
    return {"mean": float(np.mean(e)), "std": float(np.std(e)), "rmse": rmse,
            "max_abs": float(np.max(np.abs(e))),
            "nrmse": rmse / span if span > 0 else float("nan")}

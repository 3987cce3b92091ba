"""Weights of the robust (iteratively reweighted) LS-SVM, Suykens et al. (2002), Neurocomputing 48.

Residuals eᵢ are standardised by the robust scale ŝ = 1.483·MAD(e); each weighting function maps the
standardised residual to a weight vᵢ that multiplies γ for sample i in the next refit.
"""

from __future__ import annotations

import numpy as np

WEIGHTINGS = ("huber", "hampel")

HUBER_C = 1.345
HAMPEL_C1, HAMPEL_C2 = 2.5, 3.0
# Suykens' floor: a gross outlier keeps a tiny weight so the system stays well posed.
HAMPEL_FLOOR = 1e-4


def robust_scale(residuals: np.ndarray) -> float:
    """1.483·MAD, a consistent estimate of σ for Gaussian residuals."""
    med = np.median(residuals)
    return float(1.483 * np.median(np.abs(residuals - med)))


def huber_weights(z: np.ndarray) -> np.ndarray:
    """Huber weights of standardised residuals z: 1 inside ±1.345, 1.345/|z| outside."""
    a = np.abs(z)
    return np.where(a <= HUBER_C, 1.0, HUBER_C / np.maximum(a, HUBER_C))


def hampel_weights(z: np.ndarray) -> np.ndarray:
    """Hampel weights of standardised residuals z (Suykens et al. 2002): 1, linear, floor."""
    a = np.abs(z)
    w = np.where(a <= HAMPEL_C1, 1.0, (HAMPEL_C2 - a) / (HAMPEL_C2 - HAMPEL_C1))
    return np.where(a > HAMPEL_C2, HAMPEL_FLOOR, w)


def robust_weights(residuals: np.ndarray, weighting: str) -> np.ndarray | None:
    """Weights for the next refit, or None when the residuals are all equal (nothing to weigh)."""
    scale = robust_scale(residuals)
    if scale <= 0.0:
        return None
    z = residuals / scale
    if weighting == "huber":
        return huber_weights(z)
    if weighting == "hampel":
        return hampel_weights(z)
    raise ValueError(f"weighting must be one of {WEIGHTINGS} or None, got {weighting!r}")

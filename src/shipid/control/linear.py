"""Linearisation of a model about straight running, and its Nomoto parameters.

About (u0, v = 0, r = 0, δ = 0) at the propeller speed n (models with n terms) and in still air
(wind models: the apparent wind of the ship's own motion), by central differences of the model's
accelerations: the surge–sway–yaw state matrix A (3 × 3, states u, v, r), the rudder column B,
and from the sway–yaw block the transfer function r/δ = K (1 + T3 s) / ((1 + T1 s)(1 + T2 s))
(Nomoto's second-order model) with its first-order approximation T = T1 + T2 − T3, K.
"""

from __future__ import annotations

import math

import numpy as np

from shipid.errors import ShipidError

STATES = ("u", "v", "r")


def _acc(dyn, u, v, r, delta, rps):
    u = np.atleast_1d(np.asarray(u, float))
    v = np.broadcast_to(np.asarray(v, float), u.shape)
    r = np.broadcast_to(np.asarray(r, float), u.shape)
    delta = np.broadcast_to(np.asarray(delta, float), u.shape)
    n = None if rps is None else np.full(u.shape, float(rps))
    extra = {}
    if getattr(dyn, "uses_wind", False):
        extra = {"wind_speed": np.hypot(u, v), "wind_angle": np.arctan2(v, u)}
    if hasattr(dyn, "accelerations"):
        return dyn.accelerations(u, v, r, delta, None, n, **extra)
    nu = np.column_stack([u, v, r])
    return dyn.derivatives(nu, delta) if n is None else dyn.derivatives(nu, delta, None, n)


def linearise(dynamics, speed: float, rps: float | None = None) -> dict:
    """A (3 × 3), B (3,) about straight running at ``speed``: ν̇ ≈ A (ν − ν0) + B δ, and the
    residual acceleration at the point (≈ 0 for a trimmed ship)."""
    dyn = getattr(dynamics, "dynamics", dynamics)
    if not (isinstance(speed, int | float) and math.isfinite(speed) and speed > 0):
        raise ShipidError(f"linearisation needs a speed > 0 m/s, got {speed!r}")
    if getattr(dyn, "uses_rps", False) and rps is None:
        raise ShipidError("the model has propeller-speed terms: give the propeller speed (rps)")
    x0 = np.array([speed, 0.0, 0.0])
    A = np.zeros((3, 3))
    for j in range(3):
        # Small: the modulus terms (|v|v, |v|r) have a kink at 0 that a step h biases by h·coef.
        h = 1e-7 * max(abs(x0[j]), 1.0)
        plus, minus = x0.copy(), x0.copy()
        plus[j] += h
        minus[j] -= h
        A[:, j] = (_acc(dyn, *plus, 0.0, rps)[0] - _acc(dyn, *minus, 0.0, rps)[0]) / (2 * h)
    hd = 1e-6
    B = (_acc(dyn, *x0, hd, rps)[0] - _acc(dyn, *x0, -hd, rps)[0]) / (2 * hd)
    return {"A": A, "B": B, "states": STATES, "speed": float(speed), "rps": rps,
            "residual": _acc(dyn, *x0, 0.0, rps)[0]}  # fmt: skip


def nomoto(dynamics, speed: float, rps: float | None = None) -> dict:
    """Nomoto's K, T1, T2, T3 of the sway–yaw block, and the first-order T = T1 + T2 − T3.

    r/δ = (b2 s + a21 b1 − a11 b2) / (s² − tr s + det) for [v̇, ṙ] = [[a11, a12], [a21, a22]]
    [v, r] + [b1, b2] δ. Complex time constants (an oscillatory sway–yaw pair) are refused."""
    lin = linearise(dynamics, speed, rps)
    A2, b = lin["A"][1:, 1:], lin["B"][1:]
    det, tr = float(np.linalg.det(A2)), float(np.trace(A2))
    if det == 0:
        raise ShipidError("the sway–yaw dynamics are singular at this speed: no Nomoto model")
    roots = np.roots([1.0, -tr, det])
    if np.any(np.abs(roots.imag) > 1e-12):
        raise ShipidError("the sway–yaw poles are complex: Nomoto's real time constants do not "
                          "apply")  # fmt: skip
    T1, T2 = sorted((-1.0 / roots.real).tolist(), reverse=True)
    num0 = A2[1, 0] * b[0] - A2[0, 0] * b[1]
    K = num0 / det
    T3 = b[1] / num0 if num0 != 0 else math.nan
    return {"K": float(K), "T1": float(T1), "T2": float(T2), "T3": float(T3),
            "T": float(T1 + T2 - T3), "stable": bool(np.all(roots.real < 0)),
            "A": lin["A"], "B": lin["B"]}  # fmt: skip

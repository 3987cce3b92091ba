"""Linearisation of a model about straight running, and its Nomoto parameters.

About the trimmed straight run: at speed u0, the propeller speed n (models with n terms) and in
still air (wind models: the apparent wind of the ship's own motion), the drift v0 and rudder δ0
that hold a straight course (v̇ = ṙ = 0 at r = 0), by central differences of the model's
accelerations: the surge–sway–yaw state matrix A (3 × 3, states u, v, r), the rudder column B,
and from the sway–yaw block the transfer function r/δ = K (1 + T3 s) / ((1 + T1 s)(1 + T2 s))
(Nomoto's second-order model) with its first-order approximation T = T1 + T2 − T3, K.

Why the trim: a single-screw ship goes straight with rudder and drift (the Esso Osaka's model
holds 0.48° and −0.013 m/s at 16.7 rps), and an identified model has constant terms besides.
At (v = 0, δ = 0) such a model is not running straight, and the modulus terms (|v|v, |δ| of a
propeller's asymmetric race) have their kinks there: the Esso's K came out 5.0 1/s and T1 353 s
at rudder amidships against 0.97 1/s and 59 s at its trim (``benchmarks/study_trim.py``).
"""

from __future__ import annotations

import math

import numpy as np

from shipid.dynamics.model import sway_yaw_nomoto
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


# The trim: Newton steps on (v̇, ṙ)(v, δ) = 0 at r = 0, from (0, 0).
TRIM_ITERATIONS, TRIM_TOLERANCE = 50, 1e-12
TRIM_MAX_RUDDER = math.radians(35.0)


def trim(dynamics, speed: float, rps: float | None = None) -> tuple[float, float] | None:
    """(v0, δ0): the drift [m/s] and rudder [rad] that hold a straight course at ``speed``
    (v̇ = ṙ = 0 at r = 0), by Newton's method from (0, 0); None where there is none within
    ±35° of rudder (or the model has no sway and yaw to balance)."""
    dyn = getattr(dynamics, "dynamics", dynamics)
    dofs = getattr(getattr(dyn, "structure", None), "dofs", ("u", "v", "r"))
    if "r" not in dofs:
        return None
    sway = "v" in dofs
    x = np.zeros(2)  # v0, δ0

    def g(x):
        a = _acc(dyn, speed, x[0], 0.0, x[1], rps)[0]
        return a[1:] if sway else a[2:]

    scale = 1.0 + float(np.abs(_acc(dyn, speed, 0.0, 0.0, 0.1, rps)[0][1:]).max())
    for _ in range(TRIM_ITERATIONS):
        f = g(x)
        if float(np.abs(f).max()) <= TRIM_TOLERANCE * scale:
            break
        cols = (0, 1) if sway else (1,)
        J = np.zeros((f.size, len(cols)))
        for k, j in enumerate(cols):
            h = 1e-7 * max(abs(x[j]), speed if j == 0 else 1.0)
            plus, minus = x.copy(), x.copy()
            plus[j] += h
            minus[j] -= h
            J[:, k] = (g(plus) - g(minus)) / (2 * h)
        try:
            step = np.linalg.solve(J, -f)
        except np.linalg.LinAlgError:
            return None
        x[list(cols)] += step
        if not (np.all(np.isfinite(x)) and abs(x[1]) <= TRIM_MAX_RUDDER):
            return None
    else:
        return None
    return float(x[0]), float(x[1])


def linearise(dynamics, speed: float, rps: float | None = None, trimmed: bool = True) -> dict:
    """A (3 × 3), B (3,) about straight running at ``speed``: ν̇ ≈ A (ν − ν0) + B (δ − δ0),
    with ν0 = (speed, v0, 0) and δ0 the trim (``trim``; ``trimmed=False`` or no trim: v0 = δ0 =
    0, rudder amidships), and the residual acceleration at the point (u̇ ≠ 0 where the speed is
    not the model's steady one at that trim)."""
    dyn = getattr(dynamics, "dynamics", dynamics)
    if not (isinstance(speed, int | float) and math.isfinite(speed) and speed > 0):
        raise ShipidError(f"linearisation needs a speed > 0 m/s, got {speed!r}")
    if getattr(dyn, "uses_rps", False) and rps is None:
        raise ShipidError("the model has propeller-speed terms: give the propeller speed (rps)")
    found = trim(dyn, speed, rps) if trimmed else None
    v0, d0 = found if found is not None else (0.0, 0.0)
    x0 = np.array([speed, v0, 0.0])
    A = np.zeros((3, 3))
    for j in range(3):
        # Small: the modulus terms (|v|v, |v|r) have a kink at 0 that a step h biases by h·coef.
        h = 1e-7 * max(abs(x0[j]), 1.0)
        plus, minus = x0.copy(), x0.copy()
        plus[j] += h
        minus[j] -= h
        A[:, j] = (_acc(dyn, *plus, d0, rps)[0] - _acc(dyn, *minus, d0, rps)[0]) / (2 * h)
    hd = 1e-6
    B = (_acc(dyn, *x0, d0 + hd, rps)[0] - _acc(dyn, *x0, d0 - hd, rps)[0]) / (2 * hd)
    return {"A": A, "B": B, "states": STATES, "speed": float(speed), "rps": rps,
            "trim": None if found is None else {"v": v0, "delta": d0},
            "residual": _acc(dyn, *x0, d0, rps)[0]}  # fmt: skip


def nomoto(dynamics, speed: float, rps: float | None = None, trimmed: bool = True) -> dict:
    """Nomoto's K, T1, T2, T3 of the sway–yaw block, and the first-order T = T1 + T2 − T3
    (``shipid.dynamics.model.sway_yaw_nomoto``).

    r/δ = (b2 s + a21 b1 − a11 b2) / (s² − tr s + det) for [v̇, ṙ] = [[a11, a12], [a21, a22]]
    [v, r] + [b1, b2] δ. An oscillatory sway–yaw pair (complex poles) has no real T1, T2 (None);
    its K, T3 and first-order T are real, with the pair's natural frequency and damping ratio."""
    lin = linearise(dynamics, speed, rps, trimmed)
    return {**sway_yaw_nomoto(lin["A"][1:, 1:], lin["B"][1:]),
            "A": lin["A"], "B": lin["B"], "trim": lin["trim"], "residual": lin["residual"]}  # fmt: skip

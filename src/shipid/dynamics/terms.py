"""Regressor terms of the manoeuvring models: products of states and inputs (paper eq. 12).

Every model of this package is linear in its parameters: each acceleration is
Σ θⱼ·φⱼ(u, v, r, δ, T, n) over the terms below (T thrust [N], n propeller speed [rps]). The order
of ``TERMS`` is the column order of the coefficient matrices used by the compiled simulator, so it
must only ever be appended to.
"""

from __future__ import annotations

import numpy as np

TERMS: tuple[str, ...] = (
    "1", "u", "v", "r", "|u|u", "vr", "r^2", "ur", "uv", "|v|v", "|v|r", "|r|r", "|r|v",
    "delta", "delta^2", "T", "u^2*delta", "|n|n", "un", "|n|n*delta",
)  # fmt: skip
TERM_INDEX = {name: i for i, name in enumerate(TERMS)}

# How each term is printed in equations, in the paper's style.
TERM_DISPLAY = {
    "1": "", "u": "u", "v": "v", "r": "r", "|u|u": "|u|u", "vr": "v r", "r^2": "r²",
    "ur": "u r", "uv": "u v", "|v|v": "|v|v", "|v|r": "|v| r", "|r|r": "|r| r", "|r|v": "|r| v",
    "delta": "δ", "delta^2": "δ²", "T": "T", "u^2*delta": "u² δ", "|n|n": "|n|n", "un": "u n",
    "|n|n*delta": "|n|n δ",
}  # fmt: skip
# Log columns of the propulsion inputs some terms need (thrust T [N], propeller speed n [rps]).
TERM_INPUTS = {"T": "thrust", "|n|n": "n", "un": "n", "|n|n*delta": "n"}


def required_inputs(names) -> tuple[str, ...]:
    """Log columns ('thrust', 'n') that the terms ``names`` need besides u, v, r and δ."""
    return tuple(sorted({TERM_INPUTS[n] for n in names if n in TERM_INPUTS}))


def term_values(
    name: str,
    u: np.ndarray,
    v: np.ndarray,
    r: np.ndarray,
    delta: np.ndarray,
    thrust: np.ndarray,
    rps: np.ndarray,
) -> np.ndarray:
    """Value of one regressor term for arrays of states and inputs."""
    match name:
        case "1":
            return np.ones_like(u)
        case "u":
            return u
        case "v":
            return v
        case "r":
            return r
        case "|u|u":
            return np.abs(u) * u
        case "vr":
            return v * r
        case "r^2":
            return r * r
        case "ur":
            return u * r
        case "uv":
            return u * v
        case "|v|v":
            return np.abs(v) * v
        case "|v|r":
            return np.abs(v) * r
        case "|r|r":
            return np.abs(r) * r
        case "|r|v":
            return np.abs(r) * v
        case "delta":
            return delta
        case "delta^2":
            return delta * delta
        case "T":
            return thrust
        case "u^2*delta":
            return u * u * delta
        case "|n|n":
            return np.abs(rps) * rps
        case "un":
            return u * rps
        case "|n|n*delta":
            return np.abs(rps) * rps * delta
    raise ValueError(f"unknown model term {name!r}; known terms: {', '.join(TERMS)}")


def term_matrix(
    names: tuple[str, ...] | list[str],
    u: np.ndarray,
    v: np.ndarray,
    r: np.ndarray,
    delta: np.ndarray,
    thrust: np.ndarray | None = None,
    rps: np.ndarray | None = None,
) -> np.ndarray:
    """(n, len(names)) matrix of regressor values (absent inputs count as zero)."""
    u = np.asarray(u, dtype=float)
    thrust = np.zeros_like(u) if thrust is None else np.asarray(thrust, dtype=float)
    rps = np.zeros_like(u) if rps is None else np.asarray(rps, dtype=float)
    cols = [term_values(n, u, np.asarray(v, float), np.asarray(r, float),
                        np.asarray(delta, float), thrust, rps) for n in names]  # fmt: skip
    return np.column_stack(cols) if cols else np.empty((u.shape[0], 0))

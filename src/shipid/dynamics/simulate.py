"""Simulation of manoeuvring models driven by a rudder series: Euler (the paper's scheme, eqs. 9–10)
or RK4, zero-order-hold inputs, planar kinematics, divergence detection, batches.

State: [u, v, r, ψ, x, y] with ψ̇ = r, ẋ = u cosψ − v sinψ, ẏ = u sinψ + v cosψ (earth x north,
y east, ψ clockwise). Input sample k (rudder, thrust) is held over [t_k, t_k+1).

Any object with ``derivatives(nu (B, 3), delta (B,), thrust (B,) or None) -> (B, 3)`` and
``uses_thrust`` can be simulated; ``ManoeuvringModel`` runs on a compiled (numba) kernel.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from typing import Protocol

import numba
import numpy as np
import pandas as pd

from shipid.data.log import input_columns, make_log
from shipid.dynamics.model import ManoeuvringModel

METHODS = ("euler", "rk4")
STATE_NAMES = ("u", "v", "r", "psi", "x", "y")


class Dynamics(Protocol):
    uses_thrust: bool

    def derivatives(self, nu: np.ndarray, delta: np.ndarray, thrust=None) -> np.ndarray: ...


@dataclass(frozen=True)
class DivergenceBounds:
    """A run stops when a state is non-finite or beyond these physical bounds."""

    speed: float = math.inf  # m/s on |u| and |v|; inf → 10 × max(|u0|, 1 m/s)
    yaw_rate: float = 5.0  # rad/s

    def resolved(self, u0: float) -> tuple[float, float]:
        speed = self.speed if math.isfinite(self.speed) else 10.0 * max(abs(u0), 1.0)
        return speed, self.yaw_rate


@dataclass
class SimulationResult:
    """A simulated log (truncated where the run diverged) and the divergence report."""

    log: pd.DataFrame
    diverged: bool = False
    diverged_at: float | None = None
    reason: str = ""


@dataclass
class BatchResult:
    """Many trajectories on one time grid: states (B, N, 6), valid steps per trajectory."""

    t: np.ndarray
    delta: np.ndarray
    states: np.ndarray
    n_valid: np.ndarray
    limits: tuple[float, float] = (math.inf, math.inf)  # (speed, yaw rate) the run was held to
    meta: dict = field(default_factory=dict)

    @property
    def diverged(self) -> np.ndarray:
        return self.n_valid < len(self.t)

    def log(self, i: int) -> pd.DataFrame:
        n = int(self.n_valid[i])
        cols = {name: self.states[i, :n, j] for j, name in enumerate(STATE_NAMES)}
        return make_log({"t": self.t[:n], "delta": self.delta[i, :n], **cols}, **self.meta)


# ---------------------------------------------------------------------------- compiled kernel
@numba.njit(cache=True, inline="always")
def _linear_acc(th, i, u, v, r, d, T, n):
    # Term order of shipid.terms.TERMS; a test checks this against the NumPy evaluation.
    au, av, ar = abs(u), abs(v), abs(r)
    return (th[i, 0] + th[i, 1] * u + th[i, 2] * v + th[i, 3] * r + th[i, 4] * au * u
            + th[i, 5] * v * r + th[i, 6] * r * r + th[i, 7] * u * r + th[i, 8] * u * v
            + th[i, 9] * av * v + th[i, 10] * av * r + th[i, 11] * ar * r + th[i, 12] * ar * v
            + th[i, 13] * d + th[i, 14] * d * d + th[i, 15] * T + th[i, 16] * u * u * d
            + th[i, 17] * abs(n) * n + th[i, 18] * u * n + th[i, 19] * abs(n) * n * d)  # fmt: skip


@numba.njit(cache=True, inline="always")
def _linear_rhs(th, u, v, r, psi, d, T, n):
    c, s = math.cos(psi), math.sin(psi)
    return (_linear_acc(th, 0, u, v, r, d, T, n), _linear_acc(th, 1, u, v, r, d, T, n),
            _linear_acc(th, 2, u, v, r, d, T, n), r, u * c - v * s, u * s + v * c)  # fmt: skip


@numba.njit(cache=True, parallel=True)
def _integrate_linear(th, t, delta, thrust, rps, s0, rk4, speed_lim, yaw_lim, out, n_valid):
    n_traj, n_steps = delta.shape
    for b in numba.prange(n_traj):
        u, v, r, psi, x, y = s0[b, 0], s0[b, 1], s0[b, 2], s0[b, 3], s0[b, 4], s0[b, 5]
        out[b, 0, 0], out[b, 0, 1], out[b, 0, 2] = u, v, r
        out[b, 0, 3], out[b, 0, 4], out[b, 0, 5] = psi, x, y
        n_ok = 1
        for k in range(n_steps - 1):
            h = t[k + 1] - t[k]
            d, T, n = delta[b, k], thrust[b, k], rps[b, k]
            k1 = _linear_rhs(th, u, v, r, psi, d, T, n)
            if rk4:
                k2 = _linear_rhs(th, u + 0.5 * h * k1[0], v + 0.5 * h * k1[1], r + 0.5 * h * k1[2],
                                 psi + 0.5 * h * k1[3], d, T, n)  # fmt: skip
                k3 = _linear_rhs(th, u + 0.5 * h * k2[0], v + 0.5 * h * k2[1], r + 0.5 * h * k2[2],
                                 psi + 0.5 * h * k2[3], d, T, n)  # fmt: skip
                k4 = _linear_rhs(th, u + h * k3[0], v + h * k3[1], r + h * k3[2],
                                 psi + h * k3[3], d, T, n)  # fmt: skip
                w = h / 6.0
                u += w * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
                v += w * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
                r += w * (k1[2] + 2 * k2[2] + 2 * k3[2] + k4[2])
                psi += w * (k1[3] + 2 * k2[3] + 2 * k3[3] + k4[3])
                x += w * (k1[4] + 2 * k2[4] + 2 * k3[4] + k4[4])
                y += w * (k1[5] + 2 * k2[5] + 2 * k3[5] + k4[5])
            else:
                u += h * k1[0]
                v += h * k1[1]
                r += h * k1[2]
                psi += h * k1[3]
                x += h * k1[4]
                y += h * k1[5]
            if not (abs(u) <= speed_lim and abs(v) <= speed_lim and abs(r) <= yaw_lim
                    and math.isfinite(psi) and math.isfinite(x) and math.isfinite(y)):
                break
            out[b, k + 1, 0], out[b, k + 1, 1], out[b, k + 1, 2] = u, v, r
            out[b, k + 1, 3], out[b, k + 1, 4], out[b, k + 1, 5] = psi, x, y
            n_ok = k + 2
        n_valid[b] = n_ok


# ---------------------------------------------------------------------------- generic path
def _rhs(dyn: Dynamics, s: np.ndarray, d: np.ndarray, T: np.ndarray | None,
         n: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
    out = np.empty_like(s)
    # Only models with propeller-speed terms take n; reference ships keep the 3-argument protocol.
    out[:, :3] = dyn.derivatives(s[:, :3], d, T) if n is None else dyn.derivatives(s[:, :3], d, T, n)
    c, sn = np.cos(s[:, 3]), np.sin(s[:, 3])
    out[:, 3] = s[:, 2]
    out[:, 4] = s[:, 0] * c - s[:, 1] * sn
    out[:, 5] = s[:, 0] * sn + s[:, 1] * c
    return out


def step_state(
    dyn: Dynamics,
    s: np.ndarray,
    d: np.ndarray,
    T: np.ndarray | None,
    h: float,
    method: str,
    n: np.ndarray | None = None,
) -> np.ndarray:
    """One integration step of (B, 6) states with inputs held (used by closed-loop manoeuvres)."""
    with np.errstate(all="ignore"):  # divergence is detected and reported by the caller
        k1 = _rhs(dyn, s, d, T, n)
        if method == "euler":
            return s + h * k1
        k2 = _rhs(dyn, s + 0.5 * h * k1, d, T, n)
        k3 = _rhs(dyn, s + 0.5 * h * k2, d, T, n)
        k4 = _rhs(dyn, s + h * k3, d, T, n)
        return s + (h / 6.0) * (k1 + 2 * k2 + 2 * k3 + k4)


def within_bounds(s: np.ndarray, speed_lim: float, yaw_lim: float) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        return (np.all(np.isfinite(s), axis=1) & (np.abs(s[:, 0]) <= speed_lim)
                & (np.abs(s[:, 1]) <= speed_lim) & (np.abs(s[:, 2]) <= yaw_lim))  # fmt: skip


def _integrate_generic(dyn, t, delta, thrust, rps, s0, method, speed_lim, yaw_lim, out, n_valid):
    n_traj, n_steps = delta.shape
    s = s0.copy()
    out[:, 0] = s
    alive = np.ones(n_traj, dtype=bool)
    n_valid[:] = 1
    for k in range(n_steps - 1):
        T = None if thrust is None else thrust[alive, k]
        n = None if rps is None else rps[alive, k]
        new = step_state(dyn, s[alive], delta[alive, k], T, t[k + 1] - t[k], method, n)
        ok = within_bounds(new, speed_lim, yaw_lim)
        idx = np.flatnonzero(alive)
        s[idx[ok]] = new[ok]
        out[idx[ok], k + 1] = new[ok]
        n_valid[idx[ok]] = k + 2
        alive[idx[~ok]] = False
        if not alive.any():
            break


# ---------------------------------------------------------------------------- public API
def _as_series(values, name: str, n_traj: int, n_steps: int) -> np.ndarray:
    a = np.asarray(values, dtype=float)
    if a.ndim == 1:
        a = np.broadcast_to(a, (n_traj, a.shape[0]))
    if a.ndim != 2 or a.shape[0] != n_traj:
        raise ValueError(f"{name} must have shape ({n_steps},) or ({n_traj}, {n_steps}), "
                         f"got {np.shape(values)}")  # fmt: skip
    if a.shape[1] < n_steps:
        raise ValueError(f"{name} has {a.shape[1]} samples, shorter than the time grid "
                         f"({n_steps} samples)")  # fmt: skip
    # A fresh writable C-contiguous copy: one compiled signature for every call.
    a = np.array(a[:, :n_steps], dtype=np.float64, order="C")
    bad = ~np.isfinite(a)
    if bad.any():
        b, k = np.argwhere(bad)[0]
        raise ValueError(f"{name} contains a non-finite value at sample {k}"
                         + (f" of trajectory {b}" if n_traj > 1 else ""))
    return a


def _check_time(t) -> np.ndarray:
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise ValueError(f"t must be a 1-D time grid with at least 2 samples, got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        raise ValueError(f"t contains a non-finite value at sample {int(np.argmin(np.isfinite(t)))}")
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.argmax(dt <= 0))
        raise ValueError(f"t must be strictly increasing; t[{k + 1}] = {t[k + 1]} ≤ t[{k}] = {t[k]}")
    return t


def initial_states(initial, n_traj: int) -> np.ndarray:
    """(B, 6) initial states from a mapping {u, v, r, psi, x, y} (missing → 0 but u) or an array."""
    if isinstance(initial, Mapping):
        if "u" not in initial:
            raise ValueError("initial state needs the surge speed 'u'")
        unknown = set(initial) - set(STATE_NAMES)
        if unknown:
            raise ValueError(f"unknown initial state keys {sorted(unknown)}; use {STATE_NAMES}")
        row = [float(initial.get(k, 0.0)) for k in STATE_NAMES]
        s0 = np.tile(row, (n_traj, 1))
    else:
        s0 = np.asarray(initial, dtype=float)
        if s0.ndim == 1:
            s0 = np.tile(s0, (n_traj, 1))
        if s0.shape != (n_traj, 6):
            raise ValueError(f"initial state must be a mapping or have shape (6,) or ({n_traj}, 6), "
                             f"got {np.shape(initial)}")  # fmt: skip
    if not np.all(np.isfinite(s0)):
        raise ValueError("initial state contains a non-finite value")
    return s0


def simulate_batch(
    dynamics: Dynamics,
    t,
    delta,
    initial,
    thrust=None,
    method: str = "rk4",
    bounds: DivergenceBounds | None = None,
    n_trajectories: int | None = None,
    rps=None,
    **meta: object,
) -> BatchResult:
    """Simulate B trajectories at once on the grid ``t`` (N,).

    ``delta``, ``thrust`` and ``rps`` (propeller speed, for models with n terms) are (N,) (shared)
    or (B, N); ``initial`` is a mapping, (6,) or (B, 6).
    """
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    t = _check_time(t)
    n_steps = t.size
    if n_trajectories is None:
        shapes = [np.shape(delta), np.shape(initial) if not isinstance(initial, Mapping) else ()]
        shapes += [np.shape(x) for x in (thrust, rps) if x is not None]
        n_trajectories = max([s[0] for s in shapes if len(s) == 2] or [1])
    n_traj = n_trajectories
    delta = _as_series(delta, "delta (rudder series)", n_traj, n_steps)
    s0 = initial_states(initial, n_traj)
    if dynamics.uses_thrust and thrust is None:
        raise ValueError("this model uses thrust: give a thrust series")
    thrust = None if thrust is None else _as_series(thrust, "thrust", n_traj, n_steps)
    if getattr(dynamics, "uses_rps", False) and rps is None:
        raise ValueError("this model has propeller-speed terms: give an rps series (log column n)")
    rps = None if rps is None else _as_series(rps, "rps (propeller speed)", n_traj, n_steps)
    speed_lim, yaw_lim = (bounds or DivergenceBounds()).resolved(float(np.max(np.abs(s0[:, 0]))))
    if isinstance(dynamics, ManoeuvringModel):
        T = np.zeros_like(delta) if thrust is None else thrust
        n = np.zeros_like(delta) if rps is None else rps
        out, n_valid = integrate_coefficients(dynamics.theta, t, delta, T, n, s0, method, speed_lim,
                                              yaw_lim)  # fmt: skip
    else:
        out = np.zeros((n_traj, n_steps, 6))
        n_valid = np.zeros(n_traj, dtype=np.int64)
        uses_rps = getattr(dynamics, "uses_rps", False)
        _integrate_generic(dynamics, t, delta, thrust, rps if uses_rps else None, s0, method,
                           speed_lim, yaw_lim, out, n_valid)  # fmt: skip
    return BatchResult(t, np.asarray(delta), out, n_valid, (speed_lim, yaw_lim), dict(meta))


def divergence_report(
    states: np.ndarray, t: np.ndarray, n_valid: int, speed_lim: float, yaw_lim: float
) -> tuple[float, str]:
    """Time and reason of a divergence detected after sample n_valid − 1."""
    t_div = float(t[n_valid]) if n_valid < len(t) else float(t[-1])
    last = states[n_valid - 1]
    return t_div, (
        f"simulation diverged at t = {t_div:.2f} s (a state became non-finite or left the bounds "
        f"|u|, |v| ≤ {speed_lim:.3g} m/s, |r| ≤ {yaw_lim:.3g} rad/s; last valid state "
        f"u = {last[0]:.3g}, v = {last[1]:.3g}, r = {last[2]:.3g})"
    )


def simulate(
    dynamics: Dynamics,
    t,
    delta,
    initial,
    thrust=None,
    method: str = "rk4",
    bounds: DivergenceBounds | None = None,
    rps=None,
    **meta: object,
) -> SimulationResult:
    """Simulate one trajectory; returns the canonical log and a divergence report."""
    batch = simulate_batch(dynamics, t, delta, initial, thrust, method, bounds, n_trajectories=1,
                           rps=rps, **meta)  # fmt: skip
    log = batch.log(0)
    for column, series in (("n", rps), ("thrust", thrust)):
        if series is not None:
            log[column] = np.broadcast_to(np.asarray(series, dtype=float), batch.t.shape)[: len(log)]
    n = int(batch.n_valid[0])
    if n == len(batch.t):
        return SimulationResult(log)
    t_div, reason = divergence_report(batch.states[0], batch.t, n, *batch.limits)
    return SimulationResult(log, True, t_div, reason)


def simulate_log(
    dynamics: Dynamics,
    log: pd.DataFrame,
    method: str = "euler",
    bounds: DivergenceBounds | None = None,
) -> SimulationResult:
    """Free-run simulation from a log's measured initial state, driven by its measured rudder (and
    thrust and propeller speed where the model uses them): the paper's validation (section 4)."""
    first = log.iloc[0]
    initial = {k: float(first[k]) for k in STATE_NAMES if k in log.columns}
    for k in ("psi", "x", "y"):
        initial.setdefault(k, 0.0)
    needed = [c for c, used in (("thrust", dynamics.uses_thrust),
                                ("n", getattr(dynamics, "uses_rps", False))) if used]  # fmt: skip
    series = input_columns(log, needed)
    return simulate(dynamics, log["t"].to_numpy(), log["delta"].to_numpy(), initial,
                    series.get("thrust"), method, bounds, rps=series.get("n"), **log.attrs)


def integrate_coefficients(
    theta: np.ndarray,
    t: np.ndarray,
    delta: np.ndarray,
    thrust: np.ndarray,
    rps: np.ndarray,
    initial: np.ndarray,
    method: str,
    speed_lim: float,
    yaw_lim: float,
) -> tuple[np.ndarray, np.ndarray]:
    """The compiled kernel for a raw (3, len(TERMS)) coefficient matrix: (B, N, 6) states and the
    valid steps per trajectory. No input checks: for inner loops (refinement) that reuse
    validated arrays; everything else goes through ``simulate_batch``."""
    out = np.zeros((delta.shape[0], t.size, 6))
    n_valid = np.zeros(delta.shape[0], dtype=np.int64)
    _integrate_linear(np.ascontiguousarray(theta), t, delta, thrust, rps, initial,
                      method == "rk4", speed_lim, yaw_lim, out, n_valid)  # fmt: skip
    return out, n_valid

"""Simulation of manoeuvring models driven by input series: Euler (the paper's scheme, eqs. 9–10)
or RK4, zero-order-hold inputs, planar kinematics, divergence detection, batches.

State: [u, v, r, ψ, x, y] with ψ̇ = r, ẋ = u cosψ − v sinψ, ẏ = u sinψ + v cosψ (earth x north,
y east, ψ clockwise). Input sample k (rudder, propeller, wind) is held over [t_k, t_k+1).

``ManoeuvringModel`` runs on the compiled kernel (``shipid.dynamics.kernel``) for any term set,
the reference ships on their own compiled physics through the same integrators
(``integrate_open``). Any other object with ``derivatives(nu (B, 3), delta (B,), thrust (B,) or
None) -> (B, 3)`` and ``uses_thrust`` (e.g. a black-box estimator) runs on a vectorised NumPy path.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from os import PathLike
from typing import Protocol

import numpy as np
import pandas as pd

from shipid.data.log import column_values, input_columns, log_name, make_log, require_columns
from shipid.data.preprocess import gap_text, time_gaps
from shipid.dynamics import codegen, kernel
from shipid.dynamics.hybrid import HybridModel
from shipid.dynamics.model import ManoeuvringModel
from shipid.dynamics.terms import INPUT_SIGNALS, TermCode
from shipid.errors import ShipidError
from shipid.limits import check_samples

METHODS = ("euler", "rk4")
STATE_NAMES = ("u", "v", "r", "psi", "x", "y")


class Dynamics(Protocol):
    """What the generic simulator path needs of a dynamics object (the reference ships)."""

    uses_thrust: bool

    def derivatives(self, nu: np.ndarray, delta: np.ndarray, thrust=None) -> np.ndarray:
        """(B, 3) body accelerations at states nu (B, 3) and rudder delta (B,)."""


@dataclass(frozen=True)
class DivergenceBounds:
    """A run stops when a state is non-finite or beyond these physical bounds."""

    speed: float = math.inf  # m/s on |u| and |v|; inf → 10 × max(|u0|, 1 m/s)
    yaw_rate: float = 5.0  # rad/s

    def resolved(self, u0: float) -> tuple[float, float]:
        """(speed, yaw rate) limits for a run starting at surge speed ``u0``."""
        speed = self.speed if math.isfinite(self.speed) else 10.0 * max(abs(u0), 1.0)
        return speed, self.yaw_rate


def require_dynamics(dynamics, what: str = "model") -> None:
    """One line where a file's path or a ship's name is handed where a model or a reference
    ship belongs (``validate``, ``simulate_log``, ``output_error`` raised "'str' object has no
    attribute ..." from inside)."""
    if isinstance(dynamics, str | bytes | PathLike):
        raise ShipidError(f"a {what} is a ManoeuvringModel, a HybridModel or a reference ship "
                          f"(shipid.load_model reads a model file, shipid.get_vessel a reference "
                          f"ship by name), got {str(dynamics)!r}")  # fmt: skip


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
        """Per trajectory: whether it stopped before the end of the grid."""
        return self.n_valid < len(self.t)

    def log(self, i: int) -> pd.DataFrame:
        """Trajectory ``i`` as a canonical log (up to where it diverged)."""
        n = int(self.n_valid[i])
        cols = {name: self.states[i, :n, j] for j, name in enumerate(STATE_NAMES)}
        return make_log({"t": self.t[:n], "delta": self.delta[i, :n], **cols}, **self.meta)


# ---------------------------------------------------------------------------- generic path
def _rhs(dyn: Dynamics, s: np.ndarray, d: np.ndarray, T: np.ndarray | None,
         n: np.ndarray | None = None, other: dict | None = None) -> np.ndarray:  # fmt: skip
    out = np.empty_like(s)
    # Only models with propeller-speed (or wind) inputs take them; reference ships keep the
    # 3-argument protocol.
    if other:
        out[:, :3] = dyn.derivatives(s[:, :3], d, T, n, **other)
    elif n is None:
        out[:, :3] = dyn.derivatives(s[:, :3], d, T)
    else:
        out[:, :3] = dyn.derivatives(s[:, :3], d, T, n)
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
    other: dict | None = None,
) -> np.ndarray:
    """One integration step of (B, 6) states with inputs held (generic dynamics)."""
    with np.errstate(all="ignore"):  # divergence is detected and reported by the caller
        k1 = _rhs(dyn, s, d, T, n, other)
        if method == "euler":
            return s + h * k1
        k2 = _rhs(dyn, s + 0.5 * h * k1, d, T, n, other)
        k3 = _rhs(dyn, s + 0.5 * h * k2, d, T, n, other)
        k4 = _rhs(dyn, s + h * k3, d, T, n, other)
        return s + (h / 6.0) * (k1 + 2 * k2 + 2 * k3 + k4)


def within_bounds(s: np.ndarray, speed_lim: float, yaw_lim: float) -> np.ndarray:
    """Per row of (B, 6) states: finite and within the divergence bounds."""
    with np.errstate(invalid="ignore"):
        return (np.all(np.isfinite(s), axis=1) & (np.abs(s[:, 0]) <= speed_lim)
                & (np.abs(s[:, 1]) <= speed_lim) & (np.abs(s[:, 2]) <= yaw_lim))  # fmt: skip


def _integrate_generic(dyn, t, delta, thrust, rps, s0, method, speed_lim, yaw_lim, out, n_valid,
                       other=None):  # fmt: skip
    n_traj, n_steps = delta.shape
    s = s0.copy()
    out[:, 0] = s
    alive = np.ones(n_traj, dtype=bool)
    n_valid[:] = 1
    for k in range(n_steps - 1):
        T = None if thrust is None else thrust[alive, k]
        n = None if rps is None else rps[alive, k]
        o = {c: x[alive, k] for c, x in (other or {}).items()}
        new = step_state(dyn, s[alive], delta[alive, k], T, t[k + 1] - t[k], method, n, o)
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
    if a.ndim == 0:
        a = np.full(n_steps, float(a))
    if a.ndim == 1:
        a = np.broadcast_to(a, (n_traj, a.shape[0]))
    if a.ndim != 2 or a.shape[0] != n_traj:
        raise ShipidError(f"{name} must have shape ({n_steps},) or ({n_traj}, {n_steps}), "
                          f"got {np.shape(values)}")  # fmt: skip
    if a.shape[1] < n_steps:
        raise ShipidError(f"{name} has {a.shape[1]} samples, shorter than the time grid "
                          f"({n_steps} samples)")  # fmt: skip
    a = np.array(a[:, :n_steps], dtype=np.float64, order="C")
    bad = ~np.isfinite(a)
    if bad.any():
        b, k = np.argwhere(bad)[0]
        raise ShipidError(f"{name} contains a non-finite value at sample {k}"
                          + (f" of trajectory {b}" if n_traj > 1 else ""))
    return a


def _check_time(t) -> np.ndarray:
    t = np.asarray(t, dtype=float)
    if t.ndim != 1 or t.size < 2:
        raise ShipidError(f"t must be a 1-D time grid with at least 2 samples, got shape {t.shape}")
    if not np.all(np.isfinite(t)):
        raise ShipidError(f"t contains a non-finite value at sample {int(np.argmin(np.isfinite(t)))}")
    dt = np.diff(t)
    if np.any(dt <= 0):
        k = int(np.argmax(dt <= 0))
        raise ShipidError(f"t must be strictly increasing; t[{k + 1}] = {t[k + 1]} ≤ t[{k}] = {t[k]}")
    return t


def initial_states(initial, n_traj: int) -> np.ndarray:
    """(B, 6) initial states from a mapping {u, v, r, psi, x, y} (missing → 0 but u) or an array."""
    if isinstance(initial, Mapping):
        if "u" not in initial:
            raise ShipidError("initial state needs the surge speed 'u'")
        unknown = set(initial) - set(STATE_NAMES)
        if unknown:
            raise ShipidError(f"unknown initial state keys {sorted(unknown)}; use {STATE_NAMES}")
        row = [float(initial.get(k, 0.0)) for k in STATE_NAMES]
        s0 = np.tile(row, (n_traj, 1))
    else:
        s0 = np.asarray(initial, dtype=float)
        if s0.ndim == 1:
            s0 = np.tile(s0, (n_traj, 1))
        if s0.shape != (n_traj, 6):
            raise ShipidError(f"initial state must be a mapping or have shape (6,) or ({n_traj}, 6), "
                              f"got {np.shape(initial)}")  # fmt: skip
    if not np.all(np.isfinite(s0)):
        raise ShipidError("initial state contains a non-finite value")
    return s0


def run_kernel(code: TermCode, theta: np.ndarray, t: np.ndarray, inputs: np.ndarray,
               s0: np.ndarray, method: str, speed_lim, yaw_lim,
               n_steps: np.ndarray | None = None,
               engine: str | None = None) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """The compiled open-loop kernel on raw arrays: θ (3, T) or (B, 3, T), inputs (B, N, 5) in
    ``INPUT_SIGNALS`` order, s0 (B, 6); bounds scalars or (B,). Returns states (B, N, 6) and the
    valid samples per run. No input checks: for inner loops (refinement, selection) that reuse
    validated arrays; everything else goes through ``simulate_batch``. ``engine``: 'interpreted',
    'generated' (for ``code``), 'auto'; None: ``shipid.dynamics.codegen.use``'s."""
    B, N = inputs.shape[0], t.size
    theta = kernel.c_array(np.broadcast_to(theta, (B, *theta.shape[-2:])))
    steps = np.full(B, N, dtype=np.int64) if n_steps is None else kernel.c_array(n_steps, np.int64)
    out = np.zeros((B, N, 6))
    n_valid = np.zeros(B, dtype=np.int64)
    args = (kernel.c_array(t), kernel.c_array(inputs), steps, kernel.c_array(s0), method == "rk4",
            kernel.c_array(np.broadcast_to(np.asarray(speed_lim, float), B)),
            kernel.c_array(np.broadcast_to(np.asarray(yaw_lim, float), B)), out, n_valid)
    generated = codegen.choose(code, B * N, engine, theta)
    if generated is not None:
        generated.integrate_open(theta, *args)
    else:
        kernel.integrate_open(theta, *code.arrays(), code.uses_derived, *args)
    return out, n_valid


def run_hybrid_kernel(model: HybridModel, t: np.ndarray, inputs: np.ndarray, s0: np.ndarray,
                      method: str, speed_lim, yaw_lim) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """A hybrid's compiled open-loop runs (``shipid.dynamics.hybrid_kernel``), as ``run_kernel``."""
    from shipid.dynamics import hybrid_kernel

    B, N = inputs.shape[0], t.size
    phys = model.physical
    out = np.zeros((B, N, 6))
    n_valid = np.zeros(B, dtype=np.int64)
    hybrid_kernel.integrate_open(
        kernel.c_array(np.broadcast_to(phys.theta, (B, *phys.theta.shape))), *phys.code.arrays(),
        phys.code.uses_derived, *model.kernel_arguments, kernel.c_array(t),
        kernel.c_array(inputs), np.full(B, N, dtype=np.int64), kernel.c_array(s0),
        method == "rk4", kernel.c_array(np.broadcast_to(np.asarray(speed_lim, float), B)),
        kernel.c_array(np.broadcast_to(np.asarray(yaw_lim, float), B)), out, n_valid)  # fmt: skip
    return out, n_valid


def input_array(series: Mapping[str, np.ndarray], n_traj: int, n_steps: int) -> np.ndarray:
    """(B, N, 5) kernel inputs from {name: (N,) or (B, N)} (absent inputs are zero)."""
    out = np.zeros((n_traj, n_steps, len(INPUT_SIGNALS)))
    for j, name in enumerate(INPUT_SIGNALS):
        if series.get(name) is not None:
            out[:, :, j] = _as_series(series[name], name, n_traj, n_steps)
    return out


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
    inputs: Mapping[str, np.ndarray] | None = None,
    **meta: object,
) -> BatchResult:
    """Simulate B trajectories at once on the grid ``t`` (N,).

    ``delta``, ``thrust``, ``rps`` (propeller speed) and further ``inputs`` (e.g. wind_speed,
    wind_angle) are (N,) (shared) or (B, N); ``initial`` is a mapping, (6,) or (B, 6).
    """
    require_dynamics(dynamics)
    if method not in METHODS:
        raise ShipidError(f"method must be one of {METHODS}, got {method!r}")
    t = _check_time(t)
    n_steps = t.size
    extra = dict(inputs or {})
    if n_trajectories is None:
        shapes = [np.shape(delta), np.shape(initial) if not isinstance(initial, Mapping) else ()]
        shapes += [np.shape(x) for x in (thrust, rps, *extra.values()) if x is not None]
        n_trajectories = max([s[0] for s in shapes if len(s) == 2] or [1])
    n_traj = n_trajectories
    check_samples(float(n_traj) * n_steps, 8 * 12, f"simulating {n_traj} × {n_steps} samples")
    delta = _as_series(delta, "delta (rudder series)", n_traj, n_steps)
    s0 = initial_states(initial, n_traj)
    if dynamics.uses_thrust and thrust is None:
        raise ShipidError("this model uses thrust: give a thrust series")
    if getattr(dynamics, "uses_rps", False) and rps is None:
        raise ShipidError("this model has propeller-speed terms: give an rps series (log column n)")
    speed_lim, yaw_lim = (bounds or DivergenceBounds()).resolved(float(np.max(np.abs(s0[:, 0]))))
    if isinstance(dynamics, ManoeuvringModel):
        missing = [c for c in dynamics.inputs if c not in ("n", "thrust") and extra.get(c) is None]
        if missing:
            raise ShipidError(f"this model has terms in {', '.join(missing)}: give those series")
        series = {"delta": delta, "thrust": thrust, "n": rps, **extra}
        out, n_valid = run_kernel(dynamics.code, dynamics.theta, t,
                                  input_array(series, n_traj, n_steps), s0, method, speed_lim,
                                  yaw_lim)  # fmt: skip
    elif isinstance(dynamics, HybridModel):
        missing = [c for c in dynamics.inputs if c not in ("n", "thrust") and extra.get(c) is None]
        if missing:
            raise ShipidError(f"this model has terms in {', '.join(missing)}: give those series")
        series = {"delta": delta, "thrust": thrust, "n": rps, **extra}
        out, n_valid = run_hybrid_kernel(dynamics, t, input_array(series, n_traj, n_steps), s0,
                                         method, speed_lim, yaw_lim)  # fmt: skip
    elif hasattr(dynamics, "integrate_open"):  # a compiled reference ship: rudder (rps, wind)
        out = np.zeros((n_traj, n_steps, 6))
        n_valid = np.zeros(n_traj, dtype=np.int64)
        series = {"delta": delta, "n": rps if getattr(dynamics, "uses_rps", False) else None,
                  **{c: x for c, x in extra.items() if c in getattr(dynamics, "inputs", ())}}
        dynamics.integrate_open(kernel.c_array(t), input_array(series, n_traj, n_steps),
                                np.full(n_traj, n_steps, dtype=np.int64), s0, method == "rk4",
                                np.full(n_traj, speed_lim), np.full(n_traj, yaw_lim), out,
                                n_valid)  # fmt: skip
    else:
        thrust = None if thrust is None else _as_series(thrust, "thrust", n_traj, n_steps)
        rps = None if rps is None else _as_series(rps, "rps (propeller speed)", n_traj, n_steps)
        out = np.zeros((n_traj, n_steps, 6))
        n_valid = np.zeros(n_traj, dtype=np.int64)
        uses_rps = getattr(dynamics, "uses_rps", False)
        other = {c: _as_series(x, c, n_traj, n_steps) for c, x in extra.items() if x is not None
                 and c in getattr(dynamics, "inputs", ())}  # fmt: skip
        _integrate_generic(dynamics, t, delta, thrust, rps if uses_rps else None, s0, method,
                           speed_lim, yaw_lim, out, n_valid, other)  # fmt: skip
    # The run's own integrator, which a closed-loop replica of it runs at (a free run driven by
    # a log would otherwise carry the log's).
    step = float(np.median(np.diff(t))) if t.size > 1 else None
    meta = {**meta, "integrator": {"method": method, "step": step} if step else None}
    return BatchResult(t, np.asarray(delta), out, n_valid, (speed_lim, yaw_lim), meta)


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
    inputs: Mapping[str, np.ndarray] | None = None,
    **meta: object,
) -> SimulationResult:
    """Simulate one trajectory; returns the canonical log and a divergence report."""
    batch = simulate_batch(dynamics, t, delta, initial, thrust, method, bounds, n_trajectories=1,
                           rps=rps, inputs=inputs, **meta)  # fmt: skip
    log = batch.log(0)
    given = {"n": rps, "thrust": thrust, **(inputs or {})}
    for column, series in given.items():
        if series is not None:
            log[column] = np.broadcast_to(np.asarray(series, dtype=float), batch.t.shape)[: len(log)]
    n = int(batch.n_valid[0])
    if n == len(batch.t):
        return SimulationResult(log)
    t_div, reason = divergence_report(batch.states[0], batch.t, n, *batch.limits)
    return SimulationResult(log, True, t_div, reason)


def model_inputs(dynamics, log: pd.DataFrame, name: str | None = None) -> dict[str, np.ndarray]:
    """The log's input series that ``dynamics`` needs besides the rudder (or an error naming the
    missing column)."""
    if isinstance(dynamics, ManoeuvringModel) or hasattr(dynamics, "inputs"):
        needed = [c for c in dynamics.inputs if c != "delta"]
    else:
        needed = [c for c, used in (("thrust", dynamics.uses_thrust),
                                    ("n", getattr(dynamics, "uses_rps", False))) if used]  # fmt: skip
    return input_columns(log, needed, name)


def simulate_log(
    dynamics: Dynamics,
    log: pd.DataFrame,
    method: str = "euler",
    bounds: DivergenceBounds | None = None,
) -> SimulationResult:
    """Free-run simulation from a log's measured initial state, driven by its measured rudder (and
    thrust, propeller speed and wind where the model uses them): the paper's validation (§ 4)."""
    require_dynamics(dynamics)
    require_columns(log, ("t", "delta"), why="a log drives a free run with its time and rudder")
    gaps = time_gaps(column_values(log, "t"))
    if gaps:
        raise ShipidError(f"{log_name(log)}: {gap_text(column_values(log, 't'), gaps)}: a free run "
                          "would step across it with the rudder unknown; cut the log there "
                          "(--start/--end) or split it into two logs")  # fmt: skip
    first = log.iloc[0]
    initial = {k: float(first[k]) for k in STATE_NAMES if k in log.columns}
    for k in ("psi", "x", "y"):
        initial.setdefault(k, 0.0)
    series = model_inputs(dynamics, log)
    thrust, rps = series.pop("thrust", None), series.pop("n", None)
    return simulate(dynamics, column_values(log, "t"), column_values(log, "delta"), initial, thrust,
                    method, bounds, rps=rps, inputs=series or None, **log.attrs)

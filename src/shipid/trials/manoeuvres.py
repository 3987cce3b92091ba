"""Standard manoeuvres run closed loop on any model or reference ship: zig-zag δ/ψ, turning circle,
pull-out (IMO MSC.137(76), ITTC 7.5-04-02-01).

"Starboard" and "port" mean the same for every ship: the rudder sign is taken from the ship's (or
model's) convention. The rudder sample logged at t_k is the one held over [t_k, t_k+1), so replaying a
manoeuvre's log with ``simulate_log`` (same method and step) reproduces it exactly.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from shipid.data.log import make_log, starboard_sign
from shipid.dynamics.model import ManoeuvringModel
from shipid.dynamics.simulate import (
    METHODS,
    DivergenceBounds,
    divergence_report,
    initial_states,
    step_state,
    within_bounds,
)
from shipid.dynamics.steering import SteeringMachine
from shipid.trials.indices import turning_indices, zigzag_indices
from shipid.vessels.vessel import Vessel

SIDES = ("starboard", "port")


@dataclass
class ManoeuvreResult:
    log: pd.DataFrame
    indices: dict = field(default_factory=dict)
    diverged: bool = False
    diverged_at: float | None = None
    reason: str = ""


def as_vessel(ship: Vessel | ManoeuvringModel, speed: float | None = None,
              steering: SteeringMachine | None = None) -> Vessel:  # fmt: skip
    """A Vessel for a reference ship or an identified model (which needs an approach speed)."""
    if isinstance(ship, Vessel):
        vessel = ship
    elif isinstance(ship, ManoeuvringModel):
        if speed is None:
            raise ValueError("a manoeuvre on a model needs the approach speed (speed=...)")
        vessel = Vessel(ship.name, ship, length=float("nan"), approach_speed=speed,
                        steering=steering or SteeringMachine(),
                        rudder_positive=ship.rudder_positive_turns, source=ship.name)  # fmt: skip
    else:
        raise TypeError(f"expected a Vessel or ManoeuvringModel, got {type(ship).__name__}")
    changes = {}
    if speed is not None:
        changes["approach_speed"] = speed
    if steering is not None:
        changes["steering"] = steering
    if changes:
        vessel = dataclasses.replace(vessel, **changes)
    if not vessel.approach_speed > 0:
        raise ValueError(f"approach speed must be > 0, got {vessel.approach_speed!r}")
    return vessel


def run_closed_loop(
    vessel: Vessel,
    command: Callable[[float, np.ndarray], float],
    duration: float,
    dt: float,
    method: str = "rk4",
    bounds: DivergenceBounds | None = None,
    initial: Mapping[str, float] | None = None,
    rps: float | None = None,
) -> ManoeuvreResult:
    """Integrate from a straight approach at ``vessel.approach_speed`` (or from ``initial``, a
    mapping of u, v, r, psi, x, y and the rudder angle 'delta') with the rudder command
    ``command(t, state)`` passed through the vessel's steering machine. ``rps`` is the propeller
    speed held during the manoeuvre, needed by models with propeller-speed terms."""
    if method not in METHODS:
        raise ValueError(f"method must be one of {METHODS}, got {method!r}")
    if not dt > 0 or not duration > dt:
        raise ValueError(f"need 0 < dt < duration, got dt={dt!r}, duration={duration!r}")
    n = int(round(duration / dt)) + 1
    t = np.arange(n) * dt
    states = np.zeros((n, 6))
    rudder = np.zeros(n)
    start = {"u": vessel.approach_speed, **(initial or {})}
    s = initial_states({k: v for k, v in start.items() if k != "delta"}, 1)
    speed_lim, yaw_lim = (bounds or DivergenceBounds()).resolved(float(s[0, 0]))
    delta = float(start.get("delta", 0.0))
    dyn = vessel.dynamics
    prop = None
    if getattr(dyn, "uses_rps", False):
        if rps is None or not math.isfinite(rps):
            raise ValueError("this model has propeller-speed terms: give the propeller speed "
                             "(rps=..., --rps)")  # fmt: skip
        prop = np.array([float(rps)])
    diverged_after = None
    for k in range(n):
        delta = vessel.steering.step(delta, command(t[k], s[0]), dt)
        states[k], rudder[k] = s[0], delta
        if k == n - 1:
            break
        new = step_state(dyn, s, np.array([delta]), None, dt, method, prop)
        if not within_bounds(new, speed_lim, yaw_lim)[0]:
            diverged_after = k + 1
            break
        s = new
    m = n if diverged_after is None else diverged_after
    cols = dict(zip(("u", "v", "r", "psi", "x", "y"), states[:m].T, strict=True))
    if prop is not None:
        cols["n"] = np.full(m, prop[0])
    log = make_log({"t": t[:m], "delta": rudder[:m], **cols}, **vessel.log_metadata())
    if diverged_after is None:
        return ManoeuvreResult(log)
    t_div, reason = divergence_report(states, t, m, speed_lim, yaw_lim)
    return ManoeuvreResult(log, diverged=True, diverged_at=t_div, reason=reason)


def _check_rudder(vessel: Vessel, rudder_deg: float) -> float:
    rudder = math.radians(rudder_deg)
    if not rudder > 0:
        raise ValueError(f"rudder angle must be > 0 degrees, got {rudder_deg!r}")
    if rudder > vessel.steering.max_angle + 1e-12:
        raise ValueError(f"rudder {rudder_deg}° is beyond the steering machine's limit of "
                         f"{math.degrees(vessel.steering.max_angle):g}°")  # fmt: skip
    return rudder


def _rudder_to(side: str, vessel: Vessel, rudder_deg: float) -> float:
    """Signed rudder angle [rad] that turns ``vessel`` to ``side``."""
    return _side_sign(side) * starboard_sign(vessel.rudder_positive) * _check_rudder(vessel, rudder_deg)


def _side_sign(side: str) -> float:
    if side not in SIDES:
        raise ValueError(f"first/side must be 'starboard' or 'port', got {side!r}")
    return 1.0 if side == "starboard" else -1.0


def zigzag(
    ship: Vessel | ManoeuvringModel,
    rudder_deg: float = 20.0,
    heading_deg: float = 20.0,
    first: str = "starboard",
    duration: float = 90.0,
    dt: float = 0.05,
    approach: float = 0.0,
    speed: float | None = None,
    steering: SteeringMachine | None = None,
    method: str = "rk4",
    initial: Mapping[str, float] | None = None,
    rps: float | None = None,
) -> ManoeuvreResult:
    """δ/ψ zig-zag: rudder ``first`` at t = ``approach``, reversed whenever the heading change
    reaches ±ψ on the side the ship is turning to.

    ``initial`` (u, v, r, psi, delta) starts the run from a trial's measured state instead of a
    straight approach; the rudder is held at its initial ``delta`` until ``approach`` and the
    heading change is taken from the initial ψ.
    """
    vessel = as_vessel(ship, speed, steering)
    rudder = _check_rudder(vessel, rudder_deg)
    if not heading_deg > 0:
        raise ValueError(f"heading switch angle must be > 0 degrees, got {heading_deg!r}")
    switch = math.radians(heading_deg)
    stbd = starboard_sign(vessel.rudder_positive)
    state = {"side": _side_sign(first)}
    psi_ref = float((initial or {}).get("psi", 0.0))
    held = float((initial or {}).get("delta", 0.0))

    def command(t: float, s: np.ndarray) -> float:
        if t < approach - 1e-9:
            return held
        dpsi = s[3] - psi_ref
        if state["side"] > 0 and dpsi >= switch:
            state["side"] = -1.0
        elif state["side"] < 0 and dpsi <= -switch:
            state["side"] = 1.0
        return state["side"] * stbd * rudder

    res = run_closed_loop(vessel, command, duration, dt, method, initial=initial, rps=rps)
    res.log.attrs["manoeuvre"] = f"zigzag {rudder_deg:g}/{heading_deg:g}, first {first}"
    res.indices = zigzag_indices(res.log, heading_deg, t_order=approach,
                                 length=_finite_or_none(vessel.length))  # fmt: skip
    return res


def turning_circle(
    ship: Vessel | ManoeuvringModel,
    rudder_deg: float = 35.0,
    side: str = "starboard",
    duration: float = 240.0,
    dt: float = 0.05,
    approach: float = 0.0,
    speed: float | None = None,
    steering: SteeringMachine | None = None,
    method: str = "rk4",
    rps: float | None = None,
) -> ManoeuvreResult:
    """Turning circle: rudder to ``side`` at t = ``approach`` (the rudder execute), held."""
    vessel = as_vessel(ship, speed, steering)
    value = _rudder_to(side, vessel, rudder_deg)

    def command(t: float, s: np.ndarray) -> float:
        return value if t >= approach - 1e-9 else 0.0

    res = run_closed_loop(vessel, command, duration, dt, method, rps=rps)
    res.log.attrs["manoeuvre"] = f"turning circle {rudder_deg:g}° to {side}"
    if not res.diverged:
        res.indices = turning_indices(res.log, t_order=approach,
                                      length=_finite_or_none(vessel.length))  # fmt: skip
    return res


def pull_out(
    ship: Vessel | ManoeuvringModel,
    rudder_deg: float = 20.0,
    side: str = "starboard",
    hold: float = 60.0,
    release: float = 60.0,
    dt: float = 0.05,
    speed: float | None = None,
    steering: SteeringMachine | None = None,
    method: str = "rk4",
    rps: float | None = None,
) -> ManoeuvreResult:
    """Pull-out: rudder held for ``hold`` s, then returned to midships for ``release`` s. A
    straight-line stable ship's yaw rate decays to zero; an unstable one keeps a residual rate."""
    vessel = as_vessel(ship, speed, steering)
    value = _rudder_to(side, vessel, rudder_deg)

    def command(t: float, s: np.ndarray) -> float:
        return value if t < hold else 0.0

    res = run_closed_loop(vessel, command, hold + release, dt, method, rps=rps)
    res.log.attrs["manoeuvre"] = f"pull-out {rudder_deg:g}° to {side}"
    if not res.diverged:
        r = res.log["r"].to_numpy()
        t = res.log["t"].to_numpy()
        res.indices = {"yaw_rate_at_release": float(np.interp(hold, t, r)),
                       "residual_yaw_rate": float(r[-1]),
                       "residual_fraction": float(r[-1] / np.interp(hold, t, r))}  # fmt: skip
    return res


def _finite_or_none(x: float) -> float | None:
    return x if x is not None and math.isfinite(x) else None

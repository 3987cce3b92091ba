"""Steady straight running of a model: the speed at which its surge equation balances, and the
approach condition of a manoeuvre run on it.

An IMO manoeuvre starts from a steady straight approach (MSC.137(76)): the ship runs at the test
speed with its propeller at the rpm that holds it there. A model with propeller terms has two
knobs, the approach speed and the rps, and they must agree: started at 0.26 m/s with the
propeller of a 0.55 m/s run, the Esso Osaka model of the README accelerated by 41 % in the first
10 s of every "turning circle", and its advance and tactical diameter were those of an
accelerating ship (issue #10).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# An approach is steady when the model's speed changes by less than STEADY_SHARE in
# STEADY_WINDOW s (the rule a log's approach is held to, ``shipid.data.log.steady_start``).
from shipid.data.log import STEADY_SHARE, STEADY_WINDOW, relative_wind
from shipid.dynamics.model import ManoeuvringModel

# Another rps than the training logs' can put the steady speed far from their approach.
SEARCH_SPAN = 10.0
# The points of ``surge_equilibrium``'s grid read first to each side of the speed searched from
# (a fifth of it at the grid's 1000 points per speed), doubled each time no root is settled.
SURGE_BLOCK = 200


def still_air_accelerations(model: ManoeuvringModel, u, v, r, delta, rps,
                            wind: tuple[float, float] | None = None,
                            psi: float = 0.0) -> np.ndarray:  # fmt: skip
    """(u̇, v̇, ṙ) rows at the given states, the propeller at ``rps`` and, for models with wind
    terms, still air (the apparent wind of the ship's own motion), or a constant true ``wind``
    (speed [m/s], the direction it blows from [rad]) met on heading ``psi``, turned into the
    relative wind as the compiled closed loop turns it (``shipid.dynamics.kernel``)."""
    u = np.atleast_1d(np.asarray(u, dtype=float))
    n = None if rps is None else np.full(u.shape, rps)
    air = {}
    if model.uses_wind:
        v_ = np.broadcast_to(np.asarray(v, dtype=float), u.shape)
        speed, angle = relative_wind(u, v_, np.full(u.shape, psi), wind or (0.0, 0.0))
        air = {"wind_speed": speed, "wind_angle": angle}
    return model.accelerations(u, v, r, delta, None, n, **air)


# The reversed propeller's braking counts as none below this share of the ahead thrust's push at
# the same speed: a model whose thrust terms are zero for n < 0 (pos(n)², the only propeller term
# a selection keeps from logs that never reverse it) gives exactly 0.
NO_BRAKING_SHARE = 1e-3


def astern_braking(model, speed: float, rps: float, astern_rps: float | None = None) -> dict:
    """What the propeller reversed to ``astern_rps`` (default −``rps``) does to the surge at
    ``speed`` ahead, the rudder amidships, still air: {"braking": u̇(astern) − u̇(0) [m/s²] (< 0:
    it brakes), "ahead": u̇(rps) − u̇(0), "none": True where the braking is under
    ``NO_BRAKING_SHARE`` of the ahead push (or pushes ahead)}. A crash stop of a model without
    it is the ship coasting."""
    astern = -rps if astern_rps is None else astern_rps
    u̇ = [float(still_air_accelerations(model, speed, 0.0, 0.0, 0.0, n)[0, 0])
         for n in (astern, 0.0, rps)]  # fmt: skip
    braking, ahead = u̇[0] - u̇[1], u̇[2] - u̇[1]
    return {"braking": braking, "ahead": ahead,
            "none": bool(braking > -NO_BRAKING_SHARE * abs(ahead))}  # fmt: skip


def surge_equilibrium(model: ManoeuvringModel, speed: float, rps: float | None = None,
                      span: float = 3.0, wind: tuple[float, float] | None = None,
                      psi: float = 0.0) -> float | None:  # fmt: skip
    """Steady straight speed with the rudder amidships: the root of u̇(u, 0, 0, 0) with u̇
    falling through it, searched up to ``span`` × ``speed``, the one nearest ``speed``; None if
    there is none. ``wind``, ``psi``: a true wind met on that heading (``still_air_accelerations``),
    else still air."""
    if "u" not in model.structure.dofs:
        return None
    grid = np.linspace(0.0, span * speed, int(1000 * span) + 1)
    udot = np.full(grid.shape, np.nan)

    def evaluate(lo: int, hi: int) -> None:
        if hi > lo:
            zeros = np.zeros(hi - lo)
            udot[lo:hi] = still_air_accelerations(model, grid[lo:hi], zeros, zeros, zeros, rps,
                                                  wind, psi)[:, 0]  # fmt: skip

    # The grid is read outward from ``speed`` in widening blocks, until no pair of points left
    # unread can hold a crossing nearer than the nearest found: the roots are the whole grid's
    # (each point's u̇ is its own row), and most models balance near the speed searched from,
    # where the whole grid (10 001 points at the approach's span) was a tenth of a search's
    # time and more than half of that of the plausibility checks outside the held turns.
    if speed > 0:
        lo = hi = int(np.searchsorted(grid, speed))
        block = SURGE_BLOCK
    else:  # no speed to read outward from: the whole grid at once
        lo, hi, block = 0, 0, grid.size
    while True:
        new_lo, new_hi = max(0, lo - block), min(grid.size, hi + block)
        evaluate(new_lo, lo)
        evaluate(hi, new_hi)
        lo, hi, block = new_lo, new_hi, 2 * block
        pairs = udot[lo:hi]
        falling = lo + np.flatnonzero((pairs[:-1] > 0) & (pairs[1:] <= 0))
        nearest = float(np.min(np.abs(grid[falling] - speed))) if falling.size else math.inf
        # An unread pair (k, k + 1) has k < lo or k ≥ hi - 1; a tie goes to the lower k, as
        # argmin over the whole grid gives it.
        below = speed - grid[lo - 1] if lo > 0 else math.inf
        above = grid[hi - 1] - speed if hi < grid.size else math.inf
        if nearest < below and nearest <= above:
            break
        if lo == 0 and hi == grid.size:
            break
    if falling.size == 0:
        return None
    k = int(falling[np.argmin(np.abs(grid[falling] - speed))])
    return float(grid[k] + (grid[k + 1] - grid[k]) * udot[k] / (udot[k] - udot[k + 1]))


def vessel_straight_speed(ship, rps: float) -> float | None:
    """The straight-running speed of a reference ship whose propeller follows the run's rate
    (an MMG file's ``rps: logs``) at ``rps``: the root of u̇(u, 0, 0) with the rudder amidships,
    bracketed by doubling from 1 mm/s; None where the thrust never meets the resistance."""
    from scipy.optimize import brentq

    dyn = ship.dynamics

    def surge(u: float) -> float:
        return float(dyn.derivatives(np.array([[u, 0.0, 0.0]]), np.zeros(1), None,
                                     np.array([rps]))[0, 0])  # fmt: skip

    top = 1e-3
    while surge(top) > 0 and top < 1e3:
        top *= 2.0
    if not surge(1e-3) > 0 > surge(top):
        return None
    return float(brentq(surge, 1e-3, top, xtol=1e-10))


@dataclass(frozen=True)
class Approach:
    """The approach of a manoeuvre: speed [m/s], propeller speed [rps] (None for models without
    propeller terms), where the speed came from, and a warning when it is not a steady state."""

    speed: float
    rps: float | None
    source: str
    warning: str | None = None

    def describe(self) -> str:
        """One line for the user: the speed, the rps and where they came from."""
        at = f" at {self.rps:.4g} rps" if self.rps is not None else ""
        return f"approach: {self.speed:.4g} m/s{at} ({self.source})"


def steady_approach(model: ManoeuvringModel, trained_speed: float | None,
                    trained_rps: float | None, speed: float | None = None,
                    rps: float | None = None, window: float = STEADY_WINDOW) -> Approach:  # fmt: skip
    """The approach of a manoeuvre on ``model``; steady as ``unsteady_warning`` judges over
    ``window`` seconds (a model carried to another scale, ``time_scale``, judged over the window
    its original was, so that both start alike).

    ``rps`` (else the training logs') drives a model with propeller terms. A given ``speed`` is
    kept, with a warning when the model does not hold it (its speed changes by more than 5 % in
    10 s). Without one, a model whose surge depends on the propeller approaches at its own steady
    straight speed at that rps, found near the training approach speed: the two knobs agree. A
    model without propeller terms approaches at the training logs' speed, whose thrust its
    constant absorbed; so does a model carried from logs at one rps n₀ to every other by
    advance-ratio similarity (``similar_at_rps``) where it holds that speed at n₀, at that speed
    times n/n₀ at another rps n.
    """
    uses_rps = model.uses_rps
    n = (rps if rps is not None else trained_rps) if uses_rps else None
    if speed is not None:
        return Approach(speed, n, "given", unsteady_warning(model, speed, n, window))
    if trained_speed is None or not trained_speed > 0:
        raise ValueError("the training approach speed is unknown")
    anchor = getattr(model, "similar_at_rps", None)
    # The rps the training approach speed was run at (the first log's), where it is known.
    home = trained_rps if trained_rps is not None and trained_rps > 0 else anchor
    if anchor and n is not None and n > 0 and \
            unsteady_warning(model, trained_speed, home, window) is None:
        # The model of logs at one rps is the fit there and holds their approach: it starts
        # there (as a model without n did), elsewhere at that speed scaled with n, as its
        # forces are. Its own balance would put the MARIN KVLCC2's race structure 6 % faster
        # than the logs' approach, and its closed-loop first overshoot of the unseen −20° run
        # 1.8° high instead of 1.0°. Where it does not hold the logs' approach (logs that never
        # ran steady, a surge that balances elsewhere), its own steady speed, as below.
        if abs(n / home - 1) < 1e-9:
            return Approach(trained_speed, n, "the training logs' approach speed")
        scaled = trained_speed * n / home
        return Approach(scaled, n, f"the training logs' approach speed at {home:.4g} rps, "
                        "scaled with the propeller speed (advance-ratio similarity)",
                        unsteady_warning(model, scaled, n, window))  # fmt: skip
    if uses_rps and n is not None and "u" in model.structure.dofs:
        steady = surge_equilibrium(model, trained_speed, n, SEARCH_SPAN)
        if steady is not None and steady > 0:
            return Approach(steady, n, f"the model's steady straight speed at {n:.4g} rps")
        return Approach(trained_speed, n, "the training logs' approach speed",
                        f"the model has no steady straight speed at {n:.4g} rps: the "
                        f"manoeuvre starts from the training approach, {trained_speed:.4g} m/s, "
                        "and its speed drifts")  # fmt: skip
    return Approach(trained_speed, n, "the training logs' approach speed",
                    unsteady_warning(model, trained_speed, n, window))  # fmt: skip


def unsteady_warning(model: ManoeuvringModel, speed: float, rps: float | None,
                     window: float = STEADY_WINDOW) -> str | None:  # fmt: skip
    """A warning when ``model`` does not hold ``speed`` straight ahead with the rudder amidships:
    its speed would change by more than ``STEADY_SHARE`` in ``window`` seconds."""
    if "u" not in model.structure.dofs:
        return None
    udot = float(still_air_accelerations(model, speed, 0.0, 0.0, 0.0, rps)[0, 0])
    change = udot * window / speed
    if not math.isfinite(change) or abs(change) <= STEADY_SHARE:
        return None
    at = f" at {rps:.4g} rps" if rps is not None else ""
    steady = surge_equilibrium(model, speed, rps, SEARCH_SPAN)
    hint = (f"; its steady straight speed{at} is {steady:.4g} m/s" if steady
            else f"; it has no steady straight speed{at}")  # fmt: skip
    return (f"the approach at {speed:.4g} m/s{at} is not steady: the model's speed changes by "
            f"{100 * change:+.0f} % in the first {window:.3g} s{hint}, so the manoeuvre's "
            "indices are those of a ship still "
            + ("accelerating" if change > 0 else "slowing down"))

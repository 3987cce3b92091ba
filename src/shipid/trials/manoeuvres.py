"""Standard manoeuvres run closed loop on any model or reference ship: zig-zag δ/ψ, turning circle,
pull-out (IMO MSC.137(76), ITTC 7.5-04-02-01).

"Starboard" and "port" mean the same for every ship: the rudder sign is taken from the ship's (or
model's) convention. The rudder sample logged at t_k is the one held over [t_k, t_k+1), so replaying a
manoeuvre's log with ``simulate_log`` (same method and step) reproduces it exactly.

Identified models and reference ships run on the compiled closed loop
(``shipid.dynamics.kernel.closed_run``: rudder command, steering machine, integration); other
dynamics (black-box estimators) step their NumPy derivatives with the same compiled command and
steering machine. A model with wind terms meets a constant true wind (``wind=(speed, from_direction)``,
still air by default: the apparent wind of its own motion).
"""

from __future__ import annotations

import dataclasses
import math
from collections import Counter
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from shipid.data.log import column_values, make_log, relative_wind, starboard_sign
from shipid.dynamics import codegen, kernel
from shipid.dynamics.equilibrium import astern_braking
from shipid.dynamics.hybrid import HybridModel
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
from shipid.errors import ShipidError
from shipid.limits import check_samples
from shipid.trials.indices import pull_out_yaw_rates, turning_indices, zigzag_indices
from shipid.vessels.vessel import Vessel

SIDES = ("starboard", "port")
THRUST_REFUSED = ("manoeuvres on a model with a thrust term need a thrust model: it runs along "
                  "logs that give it its thrust (simulate, validate), not a straight run or "
                  "manoeuvre of its own; identify with propeller speed (n) terms instead")  # fmt: skip


@dataclass
class ManoeuvreResult:
    log: pd.DataFrame
    indices: dict = field(default_factory=dict)
    diverged: bool = False
    diverged_at: float | None = None
    reason: str = ""
    incomplete: str = ""  # what the run did not reach (its indices need it), with the remedy


def without_value(runs: Sequence, values: Sequence[float | None], otherwise: str = "no value"
                  ) -> tuple[int, str]:  # fmt: skip
    """How many of ``runs`` (one run on each replicate of a model: manoeuvres, or free runs
    along a log) have no value among ``values`` (an index of each), and why, most common first:
    ``(11, "6 diverged; 5 the turn is not steady within 15360 s")``. An interval over replicates
    is not bounded when more than its tail lack the value; this says whether they diverged or
    never reached the event (a manoeuvre's ``incomplete``, else ``otherwise``)."""
    reasons: Counter[str] = Counter()
    for run, x in zip(runs, values, strict=True):
        if run is not None and run.diverged:
            reasons["diverged"] += 1
        elif x is None or not math.isfinite(x):
            reasons[getattr(run, "incomplete", "") or otherwise] += 1
    return sum(reasons.values()), "; ".join(f"{n} {why}" for why, n in reasons.most_common())


# Run lengths at model scale. A larger or slower ship takes longer (√λ at Froude scale: a full-scale
# turn lasts ten times a 1:100 model's), so a run without a given length is doubled until its
# indices are complete or its yaw rate settled, up to EXTEND_MAX times the first length; a run
# still incomplete then says so (``incomplete``) instead of returning indices of a transient.
ZIGZAG_DURATION, TURNING_DURATION, PULL_OUT_PHASE, SPIRAL_HOLD = 90.0, 240.0, 60.0, 120.0
STOPPING_DURATION = 600.0
EXTEND_MAX = 64
# A yaw rate is settled when it moves less than this share of its scale over the last fifth of
# a phase (the spiral's steady rate is that fifth's mean).
SETTLED_SHARE = 0.01


def doubling(run, first: float, done, most: float = EXTEND_MAX):
    """``run(length)`` from ``first`` s, the length doubled until ``done(result)`` or it reaches
    ``most`` times ``first``: (the last result, its length). The run lengths of manoeuvres,
    plausibility checks and autopilot steps that must last until the ship has settled."""
    length = first
    while True:
        res = run(length)
        if done(res) or length >= most * first:
            return res, length
        length *= 2


def _extended(run, first: float) -> ManoeuvreResult:
    """``run(length)`` from ``first``, doubled while its result is incomplete (not diverged)."""
    return doubling(run, first, lambda res: res.diverged or not res.incomplete)[0]


def _settled(r: np.ndarray, scale: float) -> bool:
    """Whether a yaw-rate record has settled: its last fifth moves less than SETTLED_SHARE of
    ``scale`` (and of itself), and so does what is left of a slow approach. The means of the
    last three fifths, d0 and d apart, extrapolated as a geometric decay (ratio q = d/d0) put the
    limit d/(1 − q) beyond the last fifth's mean. Earlier versions took the last fifth alone,
    which a slow mode passes while far from its end: the KVLCC2 identified at full scale, in a
    spiral from 25° to 15° held 120 s, moved 0.8 % in the last 24 s and read 0.0045 rad/s,
    18 % short of the 0.0055 it settles at."""
    n = len(r)
    tail = r[int(0.8 * n):]
    if len(tail) < 2 or n < 10:
        return False
    tol = SETTLED_SHARE * max(scale, float(np.max(np.abs(tail))), 1e-12)
    if not np.ptp(tail) <= tol:
        return False
    means = [float(np.mean(r[int(a * n):int(b * n)])) for a, b in ((0.4, 0.6), (0.6, 0.8))]
    d0, d = means[1] - means[0], float(np.mean(tail)) - means[1]
    if abs(d) <= 1e-6 * tol:
        return True
    q = d / d0 if d0 != 0.0 else math.inf
    if q <= 0.0:  # turned back: no decay to extrapolate, so the last step must be small
        return abs(d) <= tol
    return bool(q < 1.0 and abs(d) / (1.0 - q) <= tol)


def _positive(value, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) \
            or not value > 0:
        raise ShipidError(f"{what} must be a finite number > 0, got {value!r}")
    return float(value)


def as_vessel(ship: Vessel | ManoeuvringModel | HybridModel, speed: float | None = None,
              steering: SteeringMachine | None = None, rps: float | None = None) -> Vessel:  # fmt: skip
    """A Vessel for a reference ship or an identified model (which needs an approach speed)."""
    if isinstance(ship, Vessel):
        vessel = ship
    elif isinstance(ship, ManoeuvringModel | HybridModel):
        if speed is None:
            raise ShipidError("a manoeuvre on a model needs the approach speed (speed=..., --speed)")
        speed = _positive(speed, "approach speed")
        vessel = Vessel(ship.name, ship, length=float("nan"), approach_speed=speed,
                        steering=steering or SteeringMachine(),
                        rudder_positive=ship.rudder_positive_turns_at(speed, rps),
                        scale=float("nan"), source=ship.name)  # fmt: skip
    else:
        from shipid.dynamics.simulate import require_dynamics

        require_dynamics(ship, "ship")  # a path or a name: which function reads it
        raise TypeError(f"expected a Vessel, ManoeuvringModel or HybridModel, got "
                        f"{type(ship).__name__}")
    changes = {}
    if speed is not None:
        changes["approach_speed"] = _positive(speed, "approach speed")
    if steering is not None:
        changes["steering"] = steering
    if changes:
        vessel = dataclasses.replace(vessel, **changes)
    _positive(vessel.approach_speed, "approach speed")
    return vessel


def manoeuvre_params(vessel: Vessel, mode: int, value: float, held: float, approach: float,
                     release: float = math.inf, switch: float = 0.0, side: float = 1.0,
                     psi_ref: float = 0.0, rps: float | None = None,
                     wind: tuple[float, float] | None = None) -> np.ndarray:  # fmt: skip
    """One row of closed-loop parameters (``shipid.dynamics.kernel``'s P_* layout) for a
    manoeuvre of ``mode`` on ``vessel``: its steering machine, rudder convention, propeller."""
    p = np.zeros(kernel.N_PARAMS)
    st = vessel.steering
    p[kernel.P_MODE], p[kernel.P_VALUE], p[kernel.P_HELD] = mode, value, held
    p[kernel.P_APPROACH], p[kernel.P_RELEASE] = approach, release
    p[kernel.P_SWITCH], p[kernel.P_SIDE], p[kernel.P_PSI_REF] = switch, side, psi_ref
    p[kernel.P_STBD] = starboard_sign(vessel.rudder_positive)
    p[kernel.P_MAX_ANGLE] = st.max_angle
    p[kernel.P_MAX_RATE] = st.max_rate or 0.0
    p[kernel.P_TIME_CONST] = st.time_constant
    p[kernel.P_RPS] = 0.0 if rps is None else rps
    p[kernel.P_RPS_TO], p[kernel.P_RPS_RAMP] = p[kernel.P_RPS], -1.0  # no propeller order
    if wind is not None:
        p[kernel.P_WIND_SPEED], p[kernel.P_WIND_DIR] = wind
    return p


def run_closed_loop(
    vessel: Vessel,
    params: np.ndarray,
    duration: float,
    dt: float,
    method: str = "rk4",
    bounds: DivergenceBounds | None = None,
    initial: Mapping[str, float] | None = None,
    rps: float | None = None,
    engine: str | None = None,
) -> ManoeuvreResult:
    """Integrate from a straight approach at ``vessel.approach_speed`` (or from ``initial``, a
    mapping of u, v, r, psi, x, y) with the rudder command of ``params`` (``kernel.command``)
    through the vessel's steering machine. ``rps`` is the propeller speed held during the
    manoeuvre, needed by models with propeller-speed terms. ``engine``: a term-set model's
    kernel, 'auto', 'generated' or 'interpreted'; None: ``shipid.dynamics.codegen.use``'s."""
    return run_closed_loops(vessel, [params], duration, dt, method, bounds, initial, rps,
                            engine)[0]  # fmt: skip


def run_closed_loops(
    vessel: Vessel,
    params: Sequence[np.ndarray],
    duration: float,
    dt: float,
    method: str = "rk4",
    bounds: DivergenceBounds | None = None,
    initial: Mapping[str, float] | Sequence[Mapping[str, float] | None] | None = None,
    rps: float | None = None,
    engine: str | None = None,
) -> list[ManoeuvreResult]:
    """``run_closed_loop`` of each row of ``params`` (from ``initial``, or from each row's own
    start where it is a sequence of them): one call of the compiled kernel for them all, which
    runs them side by side on numba's threads (the two sides of a plausibility check's held
    turn: 2.4 ms against 4.8 ms for two 6000-step runs on two cores); each the same states as
    alone."""
    if method not in METHODS:
        raise ShipidError(f"method must be one of {METHODS}, got {method!r}")
    dt = _positive(dt, "step dt")
    duration = _positive(duration, "duration")
    if not duration > dt:
        raise ShipidError(f"duration ({duration:g} s) must be longer than the step ({dt:g} s)")
    n = check_samples(duration / dt + 1, 8 * 14, f"a {duration:g} s manoeuvre at a {dt:g} s step")
    n = int(round(duration / dt)) + 1
    rows = np.array([np.asarray(p, dtype=float) for p in params])
    b = len(rows)
    starts = [initial] * b if initial is None or isinstance(initial, Mapping) else list(initial)
    if len(starts) != b:
        raise ValueError(f"{len(starts)} initial states for {b} runs")
    s0 = np.vstack([initial_states({k: v for k, v in {"u": vessel.approach_speed,
                                                      **(start or {})}.items() if k != "delta"},
                                   1) for start in starts])  # fmt: skip
    lims = [(bounds or DivergenceBounds()).resolved(float(s0[k, 0])) for k in range(b)]
    dyn = vessel.dynamics
    uses_rps = getattr(dyn, "uses_rps", False)
    if uses_rps and (rps is None or not math.isfinite(rps)):
        raise ShipidError("this model has propeller-speed terms: give the propeller speed "
                          "(rps=..., --rps)")  # fmt: skip
    states, rudder = np.zeros((b, n, 6)), np.zeros((b, n))
    n_valid = np.zeros(b, dtype=np.int64)
    limits = (np.array([lim[0] for lim in lims]), np.array([lim[1] for lim in lims]))
    rk4 = method == "rk4"
    if isinstance(dyn, ManoeuvringModel):
        if dyn.uses_thrust:
            raise ShipidError(THRUST_REFUSED)
        theta = np.repeat(dyn.theta[None], b, 0)
        # Each run's steps, as alone: the same kernel, so the same states as its own call.
        generated = codegen.choose(dyn.code, n, engine, dyn.theta)
        args = (dt, n, s0, rows, rk4, *limits, states, rudder, n_valid)
        if generated is not None:
            generated.integrate_closed(theta, *args)
        else:
            kernel.integrate_closed(theta, *dyn.code.arrays(), dyn.code.uses_derived, *args)
    elif isinstance(dyn, HybridModel):
        from shipid.dynamics import hybrid_kernel

        phys = dyn.physical
        if phys.uses_thrust:
            raise ShipidError(THRUST_REFUSED)
        hybrid_kernel.integrate_closed(
            np.repeat(phys.theta[None], b, 0), *phys.code.arrays(), phys.code.uses_derived,
            *dyn.kernel_arguments, dt, n, s0, rows, rk4, *limits, states, rudder,
            n_valid)  # fmt: skip
    elif hasattr(dyn, "integrate_closed"):  # a compiled reference ship
        dyn.integrate_closed(dt, n, s0, rows, rk4, *limits, states, rudder, n_valid)
    else:
        for k in range(b):
            states[k], rudder[k], n_valid[k] = _generic_closed_loop(
                dyn, rows[k], n, dt, s0[k:k + 1], method, *lims[k],
                rps if uses_rps else None)  # fmt: skip
    return [_closed_loop_result(vessel, rows[k], states[k], rudder[k], int(n_valid[k]), dt,
                                rps if uses_rps else None, *lims[k], method)
            for k in range(b)]  # fmt: skip


def _closed_loop_result(vessel: Vessel, params: np.ndarray, states: np.ndarray,
                        rudder: np.ndarray, m: int, dt: float, rps: float | None,
                        speed_lim: float, yaw_lim: float, method: str) -> ManoeuvreResult:  # fmt: skip
    """The log of a closed-loop run's ``m`` valid samples of ``states`` (N, 6) and ``rudder``
    (its metadata names its ``integrator``: ``method`` at ``dt``), and where it stopped short of
    N, why."""
    n = len(states)
    t = np.arange(n) * dt
    cols = dict(zip(("u", "v", "r", "psi", "x", "y"), states[:m].T, strict=True))
    if rps is not None:
        cols["n"] = propeller_series(params, t[:m])
    if getattr(vessel.dynamics, "uses_wind", False):
        # What an anemometer on the ship reads: the log replays (and validates) as it ran.
        wind = (float(params[kernel.P_WIND_SPEED]), float(params[kernel.P_WIND_DIR]))
        cols["wind_speed"], cols["wind_angle"] = relative_wind(cols["u"], cols["v"],
                                                               cols["psi"], wind)  # fmt: skip
    log = make_log({"t": t[:m], "delta": rudder[:m], **cols}, **vessel.log_metadata(),
                   integrator={"method": method, "step": dt})
    if m == n:
        return ManoeuvreResult(log)
    t_div, reason = divergence_report(states, t, m, speed_lim, yaw_lim)
    return ManoeuvreResult(log, diverged=True, diverged_at=t_div, reason=reason)


def propeller_series(params: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The propeller speed of a manoeuvre along ``t`` (``kernel.propeller`` vectorised)."""
    n0, n1 = params[kernel.P_RPS], params[kernel.P_RPS_TO]
    at, ramp = params[kernel.P_RPS_AT], params[kernel.P_RPS_RAMP]
    if ramp < 0:
        return np.full(t.shape, n0)
    frac = np.ones_like(t) if ramp == 0 else np.clip((t - at) / ramp, 0.0, 1.0)
    return np.where(t < at, n0, n0 + frac * (n1 - n0))


def _generic_closed_loop(dyn, params, n, dt, s0, method, speed_lim, yaw_lim, rps):
    states = np.zeros((n, 6))
    rudder = np.zeros(n)
    s = s0
    delta = float(params[kernel.P_HELD])
    side = float(params[kernel.P_SIDE])
    integral = 0.0
    follow = params[kernel.P_MODE] == kernel.MODE_FOLLOW
    target, leg = float(params[kernel.P_VALUE]), 0.0
    prop = None if rps is None else np.array([float(rps)])
    st = (params[kernel.P_MAX_ANGLE], params[kernel.P_MAX_RATE], params[kernel.P_TIME_CONST])
    for k in range(n):
        if follow:
            target, _, leg, _ = kernel.line_of_sight(params, s[0, 4], s[0, 5], leg)
        cmd, side, integral = kernel.command(params, k * dt, s[0, 3], s[0, 2], target, side,
                                             integral, dt)  # fmt: skip
        delta = kernel.steer(delta, cmd, dt, *st)
        states[k], rudder[k] = s[0], delta
        if k == n - 1:
            break
        if prop is not None:
            prop = np.array([kernel.propeller(params, k * dt)])
        new = step_state(dyn, s, np.array([delta]), None, dt, method, prop)
        if not within_bounds(new, speed_lim, yaw_lim)[0]:
            return states, rudder, k + 1
        s = new
    return states, rudder, n


def _check_rudder(vessel: Vessel, rudder_deg: float) -> float:
    rudder = math.radians(_positive(rudder_deg, "rudder angle [deg]"))
    if rudder > vessel.steering.max_angle + 1e-12:
        raise ShipidError(f"rudder {rudder_deg}° is beyond the steering machine's limit of "
                          f"{math.degrees(vessel.steering.max_angle):g}°")  # fmt: skip
    return rudder


def _rudder_to(side: str, vessel: Vessel, rudder_deg: float) -> float:
    """Signed rudder angle [rad] that turns ``vessel`` to ``side``."""
    return _side_sign(side) * starboard_sign(vessel.rudder_positive) * _check_rudder(vessel, rudder_deg)


def _side_sign(side: str) -> float:
    if side not in SIDES:
        raise ShipidError(f"first/side must be 'starboard' or 'port', got {side!r}")
    return 1.0 if side == "starboard" else -1.0


def _check_wind(wind) -> tuple[float, float] | None:
    if wind is None:
        return None
    try:
        speed, direction = (float(x) for x in wind)
    except (TypeError, ValueError):
        raise ShipidError(f"wind must be (speed m/s, direction rad), got {wind!r}") from None
    if not (math.isfinite(speed) and speed >= 0 and math.isfinite(direction)):
        raise ShipidError(f"wind speed must be ≥ 0 and its direction finite, got {wind!r}")
    return speed, direction


def zigzag(
    ship: Vessel | ManoeuvringModel | HybridModel,
    rudder_deg: float = 20.0,
    heading_deg: float = 20.0,
    first: str = "starboard",
    duration: float | None = None,
    dt: float = 0.05,
    approach: float = 0.0,
    speed: float | None = None,
    steering: SteeringMachine | None = None,
    method: str = "rk4",
    initial: Mapping[str, float] | None = None,
    rps: float | None = None,
    wind: tuple[float, float] | None = None,
    switches: Sequence[float] | None = None,
    indices: bool = True,
) -> ManoeuvreResult:
    """δ/ψ zig-zag: rudder ``first`` at t = ``approach``, reversed whenever the heading change
    reaches ±ψ on the side the ship is turning to; ``switches`` [deg] gives the first reversals
    their own ψ, in turn (a replica of a trial reversed unevenly), ``heading_deg`` the rest.
    ``indices=False`` (with a ``duration``): the run alone, for a caller that reads its indices
    its own way (``validate``'s replicas, as the log's are read).

    ``initial`` (u, v, r, psi, delta) starts the run from a trial's measured state instead of a
    straight approach; the rudder is held at its initial ``delta`` until ``approach`` and the
    heading change is taken from the initial ψ. ``wind``: constant true wind (speed [m/s],
    direction it blows from [rad], clockwise from north) for models with wind terms.
    ``duration`` [s]: by default 90 s, doubled until the second overshoot is reached.
    """
    vessel = as_vessel(ship, speed, steering, rps)
    rudder = _check_rudder(vessel, rudder_deg)
    switch = math.radians(_positive(heading_deg, "heading switch angle [deg]"))
    psi_ref = float((initial or {}).get("psi", 0.0))
    held = float((initial or {}).get("delta", 0.0))
    params = manoeuvre_params(vessel, kernel.MODE_ZIGZAG, rudder, held, approach, switch=switch,
                              side=_side_sign(first), psi_ref=psi_ref, rps=rps,
                              wind=_check_wind(wind))  # fmt: skip
    if switches:
        own = [math.radians(_positive(abs(h), "reversal heading [deg]")) for h in switches]
        params[kernel.P_N_SWITCHES] = len(own)
        params = np.concatenate([params, own])

    def run(length: float) -> ManoeuvreResult:
        res = run_closed_loop(vessel, params, length, dt, method, initial=initial, rps=rps)
        res.log.attrs["manoeuvre"] = f"zigzag {rudder_deg:g}/{heading_deg:g}, first {first}"
        if not indices:
            return res
        res.indices = zigzag_indices(res.log, heading_deg, t_order=approach,
                                     length=_finite_or_none(vessel.length))  # fmt: skip
        if res.indices.get("initial_turning_time") is None:
            res.incomplete = f"the heading has not reached {heading_deg:g}° within {length:g} s"
        elif res.indices.get("first_overshoot_deg") is None:
            # The counter rudder never stops the turn: an unstable loop wider than the rudder.
            res.incomplete = f"the counter rudder has not checked the yaw within {length:g} s"
        elif res.indices.get("second_overshoot_deg") is None:
            res.incomplete = f"no second overshoot within {length:g} s"
        return res

    if not indices and duration is None:
        raise ShipidError("a zig-zag without its indices needs a duration")
    return run(duration) if duration is not None else _extended(run, ZIGZAG_DURATION)


def turning_circle(
    ship: Vessel | ManoeuvringModel | HybridModel,
    rudder_deg: float = 35.0,
    side: str = "starboard",
    duration: float | None = None,
    dt: float = 0.05,
    approach: float = 0.0,
    speed: float | None = None,
    steering: SteeringMachine | None = None,
    method: str = "rk4",
    rps: float | None = None,
    wind: tuple[float, float] | None = None,
    initial: Mapping[str, float] | None = None,
    release: float = math.inf,
    indices: bool = True,
    bounds: DivergenceBounds | None = None,
) -> ManoeuvreResult:
    """Turning circle: rudder to ``side`` at t = ``approach`` (the rudder execute), held.
    ``duration`` [s]: by default 240 s, doubled until the heading has turned 180° and the turn is
    steady. ``initial`` (u, v, r, psi, delta) starts the run from a given state, the rudder held
    at its ``delta`` until ``approach`` (as ``zigzag``'s). ``release``: the time the rudder goes
    back to midships (a measured turn that ends in a pull-out; the indices are the held turn's).
    ``indices=False`` (with a ``duration``): the run alone, for a check that reads its states
    (the plausibility checks' held rudder: the indices were a third of their time).
    ``bounds``: where the run counts as diverged (default: ``DivergenceBounds``' from the
    starting speed)."""
    vessel = as_vessel(ship, speed, steering, rps)
    value = _rudder_to(side, vessel, rudder_deg)
    held = float((initial or {}).get("delta", 0.0))
    params = manoeuvre_params(vessel, kernel.MODE_HOLD, value, held, approach, release=release,
                              rps=rps, wind=_check_wind(wind))  # fmt: skip

    def run(length: float) -> ManoeuvreResult:
        res = run_closed_loop(vessel, params, length, dt, method, bounds=bounds, initial=initial,
                              rps=rps)  # fmt: skip
        res.log.attrs["manoeuvre"] = _turning_label(rudder_deg, side)
        if not res.diverged and indices:
            res.indices = turning_indices(res.log, t_order=approach,
                                          length=_finite_or_none(vessel.length))  # fmt: skip
            if res.indices.get("time_to_180") is None:
                res.incomplete = f"the heading has not turned 180° within {length:g} s"
            elif (res.indices.get("steady_yaw_rate") is None
                  or not _settled(column_values(res.log, "r"), abs(res.indices["steady_yaw_rate"]))):
                res.incomplete = f"the turn is not steady within {length:g} s"  # fmt: skip
        return res

    if not indices and duration is None:
        raise ShipidError("a turning circle without its indices needs a duration")
    return run(duration) if duration is not None else _extended(run, TURNING_DURATION)


def held_turns(ship: Vessel | ManoeuvringModel | HybridModel, rudder_deg: float,
               sides: Sequence[str], duration: float, dt: float, rps: float | None = None,
               bounds: DivergenceBounds | None = None, speed: float | None = None,
               initial: Sequence[Mapping[str, float] | None] | None = None,
               ) -> list[ManoeuvreResult]:  # fmt: skip
    """``turning_circle(ship, rudder_deg, side, duration, dt, speed=speed, rps=rps,
    indices=False, bounds=bounds, initial=...)`` for each of ``sides`` (``initial``: each side's
    start, without a rudder of its own), run together (``run_closed_loops``): the same states,
    the sides side by side on numba's threads (the plausibility checks' held turns)."""
    vessel = as_vessel(ship, speed, None, rps)
    rows = [manoeuvre_params(vessel, kernel.MODE_HOLD, _rudder_to(side, vessel, rudder_deg), 0.0,
                             0.0, rps=rps) for side in sides]  # fmt: skip
    results = run_closed_loops(vessel, rows, duration, dt, bounds=bounds, rps=rps,
                               initial=initial)  # fmt: skip
    for side, res in zip(sides, results, strict=True):
        res.log.attrs["manoeuvre"] = _turning_label(rudder_deg, side)
    return results


def _turning_label(rudder_deg: float, side: str) -> str:
    """The ``manoeuvre`` a turning circle's log carries."""
    return f"turning circle {rudder_deg:g}° to {side}"


def pull_out(
    ship: Vessel | ManoeuvringModel | HybridModel,
    rudder_deg: float = 20.0,
    side: str = "starboard",
    hold: float | None = None,
    release: float | None = None,
    dt: float = 0.05,
    speed: float | None = None,
    steering: SteeringMachine | None = None,
    method: str = "rk4",
    rps: float | None = None,
    wind: tuple[float, float] | None = None,
) -> ManoeuvreResult:
    """Pull-out: rudder held for ``hold`` s, then returned to midships for ``release`` s. A
    straight-line stable ship's yaw rate decays to zero; an unstable one keeps a residual rate.
    A phase not given lasts 60 s, doubled until the yaw rate has settled in both phases."""
    vessel = as_vessel(ship, speed, steering, rps)
    value = _rudder_to(side, vessel, rudder_deg)
    given_hold = None if hold is None else _positive(hold, "hold time")
    given_release = None if release is None else _positive(release, "release time")
    wind = _check_wind(wind)

    def run(length: float) -> ManoeuvreResult:
        held = given_hold or length
        params = manoeuvre_params(vessel, kernel.MODE_HOLD, value, 0.0, 0.0, release=held,
                                  rps=rps, wind=wind)  # fmt: skip
        res = run_closed_loop(vessel, params, held + (given_release or length), dt, method,
                              rps=rps)  # fmt: skip
        res.log.attrs["manoeuvre"] = f"pull-out {rudder_deg:g}° to {side}"
        if not res.diverged:
            r = column_values(res.log, "r")
            t = column_values(res.log, "t")
            res.indices = pull_out_yaw_rates(t, r, held)
            at_release = res.indices["yaw_rate_at_release"]
            if not (_settled(r[t <= held], abs(at_release))
                    and _settled(r[t >= held], abs(at_release))):  # fmt: skip
                res.incomplete = (f"the yaw rate has not settled within {held:g} s held and "
                                  f"{t[-1] - held:g} s released")  # fmt: skip
        return res

    if given_hold is not None and given_release is not None:
        return run(given_hold)
    return _extended(run, PULL_OUT_PHASE)


@dataclass(frozen=True)
class AsternThrust:
    """What a model's stopping test rests on (``astern_thrust_note``): ``kind`` "coasting" (its
    propeller does nothing reversed), "mirrored" (its ahead thrust mirrored astern by
    similarity) or "ratio" (its thrust astern a prior ratio of its thrust ahead,
    ``shipid.dynamics.astern``), and the note that says so."""

    kind: str
    note: str


def astern_thrust_note(ship, speed: float, rps: float,
                       astern_rps: float | None = None) -> AsternThrust | None:  # fmt: skip
    """Where a model's astern thrust is not what its logs showed
    (``shipid.dynamics.equilibrium.astern_braking``): a propeller that does not brake when
    reversed, so a full astern is the ship coasting on its resistance, a longer reach than the
    ship's own; or, for a model carried from logs at one propeller speed (advance-ratio
    similarity), its ahead thrust mirrored astern, an assumption those logs could not test. None
    for a vessel (its physics) or a model fitted on logs that reverse the propeller."""
    if not isinstance(ship, ManoeuvringModel | HybridModel) or not ship.uses_rps:
        return None
    found = astern_braking(ship, speed, rps, astern_rps)
    if found["none"]:
        from shipid.dynamics.propeller import thrust_on_the_advance_note

        why, remedy = thrust_on_the_advance_note(ship) or (
            "none of its propeller terms acts with n < 0; a selection keeps only the terms its "
            "logs excite, and logs that never reverse the propeller leave the astern thrust out",
            "logs with the propeller astern give it the terms")  # fmt: skip
        return AsternThrust("coasting", (
            "the model's propeller does not brake astern: reversed, it changes u̇ by "
            f"{found['braking']:+.3g} m/s² where ahead it gives {found['ahead']:+.3g} ({why}), "
            "so a full astern is the ship coasting to a stop on its resistance, a longer reach "
            f"than the ship's own; {remedy}"))  # fmt: skip
    if not found["ahead"] > 0:
        return None
    physical = getattr(ship, "physical", ship)
    from shipid.dynamics.terms import parse_term

    ratios = [f.k for t in physical.structure.terms.get("u", ())
              for f in parse_term(t).factors if f.propeller]  # fmt: skip
    if ratios:
        return AsternThrust("ratio", (
            f"the model brakes astern at {-100 * found['braking'] / found['ahead']:.0f} % of its "
            f"ahead push: its logs never reversed the propeller, so its thrust astern is "
            f"{ratios[0]:g} times its thrust ahead at the same |n|, a prior those logs could not "
            "test (identify --astern-thrust); logs with the propeller astern give it the terms"))
    if physical.similar_at_rps is None:
        return None
    return AsternThrust("mirrored", (
        f"the model brakes astern at {-100 * found['braking'] / found['ahead']:.0f} % of its "
        "ahead push: its logs ran the propeller at one speed ahead, and advance-ratio similarity "
        "carries the fit to every propeller speed with its thrust mirrored astern, which they "
        "could not test; a propeller astern may give less than ahead, so a full astern may stop "
        "the model short of the ship; logs with the propeller astern give it the terms"))


def stopping(
    ship: Vessel | ManoeuvringModel | HybridModel,
    rps: float,
    astern_rps: float | None = None,
    reversal_time: float = 0.0,
    duration: float | None = None,
    dt: float = 0.05,
    speed: float | None = None,
    method: str = "rk4",
    wind: tuple[float, float] | None = None,
) -> ManoeuvreResult:
    """Full-astern stopping test (IMO): from a straight approach at ``rps``, the propeller is
    ordered to ``astern_rps`` (default −``rps``) at t = 0, reaching it in ``reversal_time`` s; the
    rudder stays amidships. Indices: track reach (path length until the ship stops in the water,
    u = 0), head reach (along the original course), lateral deviation, time to stop.
    ``duration`` [s]: by default 600 s, doubled until the ship has stopped."""
    if not getattr(getattr(ship, "dynamics", ship), "uses_rps", False):
        raise ShipidError("a stopping test needs a model with propeller-speed terms (n): the "
                          "ship's thrust must respond to the astern order")  # fmt: skip
    if not (isinstance(rps, int | float) and math.isfinite(rps) and rps > 0):
        raise ShipidError(f"stopping: the approach propeller speed must be > 0 rps, got {rps!r}")
    astern = -float(rps) if astern_rps is None else float(astern_rps)
    if not (math.isfinite(astern) and astern < 0):
        raise ShipidError(f"stopping: the astern order must be < 0 rps, got {astern_rps!r}")
    if not (math.isfinite(reversal_time) and reversal_time >= 0):
        raise ShipidError(f"stopping: reversal time must be ≥ 0 s, got {reversal_time!r}")
    vessel = as_vessel(ship, speed, None, rps)
    params = manoeuvre_params(vessel, kernel.MODE_HOLD, 0.0, 0.0, 0.0, rps=rps,
                              wind=_check_wind(wind))  # fmt: skip
    params[kernel.P_RPS_TO], params[kernel.P_RPS_AT] = astern, 0.0
    params[kernel.P_RPS_RAMP] = reversal_time

    def run(length: float) -> ManoeuvreResult:
        res = run_closed_loop(vessel, params, length, dt, method, rps=rps)
        res.indices = _stopping_indices(res.log, vessel)
        if not res.diverged and not math.isfinite(res.indices["time_to_stop"]):
            res.incomplete = f"the ship has not stopped within {length:g} s"
        res.log.attrs["manoeuvre"] = f"stopping, {rps:g} → {astern:g} rps in {reversal_time:g} s"
        return res

    return run(duration) if duration is not None else _extended(run, STOPPING_DURATION)


def _stopping_indices(log: pd.DataFrame, vessel: Vessel) -> dict:
    """Track reach, head reach, lateral deviation and time to stop (u = 0) of a stopping run
    (NaN where the ship has not stopped)."""
    from shipid.trials.indices import travelled

    u, t = column_values(log, "u"), column_values(log, "t")
    stopped = np.flatnonzero(u <= 0.0)
    nan = math.nan
    out = {"track_reach": nan, "head_reach": nan, "lateral_deviation": nan, "time_to_stop": nan}
    if stopped.size:
        k = int(stopped[0])
        frac = u[k - 1] / (u[k - 1] - u[k]) if k > 0 and u[k - 1] != u[k] else 0.0
        t_stop = float(t[k - 1] + frac * (t[k] - t[k - 1])) if k > 0 else float(t[0])
        psi0 = float(log["psi"].iloc[0])
        x = np.interp(t_stop, t, log["x"]) - log["x"].iloc[0]
        y = np.interp(t_stop, t, log["y"]) - log["y"].iloc[0]
        out = {"track_reach": float(np.interp(t_stop, t, travelled(log))),
               "head_reach": float(x * math.cos(psi0) + y * math.sin(psi0)),
               "lateral_deviation": float(-x * math.sin(psi0) + y * math.cos(psi0)),
               "time_to_stop": t_stop}  # fmt: skip
    if vessel.length and math.isfinite(vessel.length):
        out["track_reach_L"] = out["track_reach"] / vessel.length
    return out


# The spiral's rudder angles to one side [deg], largest first: held from the largest to one
# side through 0 to the largest to the other and back.
SPIRAL_ANGLES = (25.0, 15.0, 10.0, 5.0, 2.0)


def spiral_angles(limit_deg: float | None = None) -> tuple[float, ...]:
    """The spiral's default rudder angles, 25° to starboard through −25° and back to 25°
    (``SPIRAL_ANGLES``), or up to ``limit_deg`` where the steering gear stops short of 25° (the
    limit itself the largest: the tanker's 10°, 5°, 2°; its spiral stopped on the 25°)."""
    top = list(SPIRAL_ANGLES)
    if limit_deg is not None and limit_deg < top[0]:
        top = [round(limit_deg, 6)] + [a for a in top if a < limit_deg - 1e-9]
    return (*top, 0.0, *(-a for a in reversed(top)), *(-a for a in top[1:]), 0.0,
            *reversed(top))


def spiral(
    ship: Vessel | ManoeuvringModel | HybridModel,
    rudders_deg=None,
    hold: float | None = None,
    dt: float = 0.05,
    speed: float | None = None,
    method: str = "rk4",
    rps: float | None = None,
    steering: SteeringMachine | None = None,
) -> ManoeuvreResult:
    """Dieudonné spiral: each rudder angle (positive = to starboard, in degrees; by default
    ``spiral_angles`` up to the steering gear's limit) held ``hold`` s
    from the state the previous one left; the steady yaw rate of each (mean over the last fifth)
    traces r(δ). A straight-line unstable ship shows a loop: at the same small rudder, a
    different steady rate coming from each side. Indices: the r(δ) table, ``loop`` (whether any
    rudder angle gave two steady rates, ``_loop_rudders``), ``loop_rudders_deg`` (those angles)
    and ``loop_yaw_rate_gap`` (the largest difference between them, rad/s). Without a
    given ``hold`` each angle is held 120 s, doubled until its yaw rate settles (a loop drawn
    from unsettled rates is a transient, not an instability); a row says whether it settled,
    ``unsettled_rudders_deg`` lists the angles that did not."""
    vessel = as_vessel(ship, speed, steering, rps)
    if rudders_deg is None:
        rudders_deg = spiral_angles(math.degrees(vessel.steering.max_angle))
    angles = [float(a) for a in rudders_deg]
    if not angles or any(not math.isfinite(a) or abs(math.radians(a)) > vessel.steering.max_angle
                         for a in angles):  # fmt: skip
        raise ShipidError("spiral: rudder angles must be finite and within the steering "
                          "machine's limit")  # fmt: skip
    stbd = starboard_sign(vessel.rudder_positive)
    initial = {"u": vessel.approach_speed}
    logs, table = [], []
    t0 = 0.0
    res = None
    if hold is not None:
        hold = _positive(hold, "hold time")
    peak = 0.0
    for a in angles:
        value = stbd * math.radians(a)
        params = manoeuvre_params(vessel, kernel.MODE_HOLD, value, initial.get("delta", 0.0),
                                  0.0, rps=rps)  # fmt: skip
        def step(length, params=params, initial=initial, peak=peak):
            res = run_closed_loop(vessel, params, length, dt, method, initial=initial, rps=rps)
            # Within 1 % of the rate itself, or of a tenth of the largest (near 0 rudder); and
            # the speed, the slow mode that carries the yaw rate after it (a full-scale ship's
            # rate from 25° to 15° first fell, then crept up for 2000 s as the ship sped up).
            speed = np.hypot(column_values(res.log, "u"), column_values(res.log, "v"))
            return res, (_settled(column_values(res.log, "r"), 0.1 * peak)
                         and _settled(speed, float(np.mean(speed))))  # fmt: skip

        (res, settled), length = doubling(
            step, hold or SPIRAL_HOLD, lambda out: hold is not None or out[0].diverged or out[1])
        seg = res.log
        seg["t"] = seg["t"] + t0
        logs.append(seg.iloc[:-1] if len(logs) < len(angles) - 1 else seg)
        tail = seg.iloc[int(0.8 * len(seg)):]
        table.append({"rudder_deg": a, "steady_yaw_rate": float(tail["r"].mean()),
                      "steady_speed": float(np.hypot(tail["u"], tail["v"]).mean()),
                      "hold": length, "settled": settled})  # fmt: skip
        peak = max(peak, abs(table[-1]["steady_yaw_rate"]))
        if res.diverged:
            break
        last = seg.iloc[-1]
        initial = {k: float(last[k]) for k in ("u", "v", "r", "psi", "x", "y")}
        initial["delta"] = float(last["delta"])
        t0 = float(last["t"])
    log = pd.concat(logs, ignore_index=True)
    log.attrs = dict(res.log.attrs)
    log.attrs["manoeuvre"] = "spiral"
    out = ManoeuvreResult(log, diverged=res.diverged, diverged_at=res.diverged_at, reason=res.reason)
    loop, gap = _loop_rudders(table)
    out.indices = {"table": table, "loop": bool(loop), "loop_rudders_deg": loop,
                   "loop_yaw_rate_gap": gap,
                   "unsettled_rudders_deg": [row["rudder_deg"] for row in table
                                             if not row["settled"]]}  # fmt: skip
    if out.indices["unsettled_rudders_deg"]:
        out.incomplete = ("no steady yaw rate at rudder "
                          + ", ".join(f"{a:g}°" for a in out.indices["unsettled_rudders_deg"])
                          + f" within {max(row['hold'] for row in table):g} s")  # fmt: skip
    return out


# A spiral's loop is hysteresis: at one rudder angle the steady yaw rates reached from either
# side differ by more than this share of the largest steady rate. The settled rates of one branch
# agree to 1 % (``SETTLED_SHARE``); the KVLCC2's MMG model differs by 38 % at 0°.
LOOP_SHARE = 0.05


def _loop_rudders(table: list[dict]) -> tuple[list[float], float]:
    """Rudder angles at which the spiral found two steady turns (the instability loop): turns
    both ways, or rates that differ by more than ``LOOP_SHARE`` of the largest, from the two
    sides; and the largest such difference [rad/s]. Only settled rows count. Earlier versions
    asked for turns both ways alone, which an asymmetric ship's loop need not hold: the KVLCC2's
    MMG model, straight-line unstable, held at 0° came to 0 rad/s from starboard and −0.0205
    rad/s from port, and its spiral read ``loop: False``."""
    by_rudder: dict[float, list[float]] = {}
    for row in table:
        if row["settled"]:
            by_rudder.setdefault(row["rudder_deg"], []).append(row["steady_yaw_rate"])
    peak = max((abs(row["steady_yaw_rate"]) for row in table), default=0.0)
    gaps = {a: max(rs) - min(rs) for a, rs in by_rudder.items()}
    loop = sorted(a for a, rs in by_rudder.items()
                  if (min(rs) < -0.01 * peak and max(rs) > 0.01 * peak)
                  or gaps[a] > LOOP_SHARE * peak)  # fmt: skip
    return loop, max((gaps[a] for a in loop), default=0.0)


def _finite_or_none(x: float) -> float | None:
    return x if x is not None and math.isfinite(x) else None

"""A heading autopilot and line-of-sight path following, run on any model or ship.

Autopilot: PID on the heading error with the steering machine's angle and rate limits,
δc = −(Kp ψ̃ + Ki ∫ψ̃ dt + Kd r), ψ̃ = ψ − ψd wrapped to (−π, π], the integral frozen while the
rudder is saturated (anti-windup). ``pid_from_nomoto`` places the closed-loop poles of Nomoto's
first-order model T ψ̈ + ψ̇ = K δ (Fossen 2021, §15.3): Kp = ωn² T / K, Kd = (2ζωn T − 1) / K,
Ki = ωn³ T / (10 K), so a controller tuned on an identified model is the same rule applied to its
K and T.

Path following: waypoints p₀, p₁, ...; on the leg from pₖ to pₖ₊₁ (course αₖ) the cross-track
error is e = −(x − xₖ) sin αₖ + (y − yₖ) cos αₖ and the line-of-sight heading
ψd = αₖ + atan(−e / Δ), Δ the lookahead distance; the next leg starts when the along-track
distance reaches the leg's length less the acceptance radius.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import pandas as pd

from shipid.data.log import column_values, make_log
from shipid.dynamics import kernel
from shipid.dynamics.equilibrium import still_air_accelerations
from shipid.dynamics.model import ManoeuvringModel
from shipid.dynamics.simulate import DivergenceBounds, initial_states, step_state, within_bounds
from shipid.dynamics.steering import SteeringMachine
from shipid.errors import ShipidError
from shipid.limits import check_samples
from shipid.trials.manoeuvres import as_vessel, doubling, manoeuvre_params, run_closed_loop


@dataclass(frozen=True)
class PID:
    """Gains of the heading autopilot (rudder in rad per rad of heading error, per rad·s, per
    rad/s of yaw rate). The signs carry the ship's rudder convention (K < 0 for a ship that
    turns to port with positive rudder)."""

    kp: float
    ki: float
    kd: float

    def __post_init__(self) -> None:
        for k in ("kp", "ki", "kd"):
            if not math.isfinite(getattr(self, k)):
                raise ShipidError(f"PID gain {k} must be finite")


def pid_from_nomoto(K: float, T: float, omega: float | None = None, zeta: float = 0.9) -> PID:
    """Pole placement on Nomoto's first-order model; ``omega`` (closed-loop natural frequency,
    rad/s) defaults to the larger of 1/|T| (as fast as the ship's own yaw response) and √|K/T|,
    the frequency at which Kp = 1 (a degree of rudder per degree of heading error): a nearly
    neutral ship's 1/|T| would barely steer it (1/345 s for the Esso Osaka model, whose heading
    then ran away to −900° on a 20° order; 1/2400 s for the MMG KVLCC2).

    A straight-line unstable ship (T < 0: KVLCC2) is stabilised by the same placement (the
    closed-loop polynomial T s² + (1 + K Kd) s + K Kp divides by T either way)."""
    if not (math.isfinite(K) and K != 0 and math.isfinite(T) and T != 0):
        raise ShipidError(f"PID tuning needs a finite K ≠ 0 and T ≠ 0, got K = {K}, T = {T}")
    w = omega if omega is not None else max(1.0 / abs(T), math.sqrt(abs(K / T)))
    return PID(kp=w * w * T / K, ki=w**3 * T / (10.0 * K), kd=(2.0 * zeta * w * T - 1.0) / K)


def _wrap(a: float) -> float:
    return (a + math.pi) % (2 * math.pi) - math.pi


@dataclass
class FollowResult:
    """The run (a canonical log with ``psi_d`` and ``cross_track`` columns added) and its
    cross-track error statistics over the path (from the first leg on)."""

    log: pd.DataFrame
    rms_cross_track: float
    max_cross_track: float
    completed: bool
    diverged: bool = False


def _follow_compiled(vessel, pid: PID, wp: np.ndarray, lookahead: float, accept: float,
                     duration: float, dt: float, rps: float | None, method: str,
                     course: float) -> FollowResult:  # fmt: skip
    """``follow_path`` in the compiled closed loop (``kernel.MODE_FOLLOW``): the run goes on past
    the end of the path and is cut there, where the step-by-step loop stops; the ordered heading
    and the cross-track error are recomputed along the track (``kernel.follow_track``)."""
    params = manoeuvre_params(vessel, kernel.MODE_FOLLOW, 0.0, 0.0, 0.0, rps=rps)
    params[kernel.P_KP], params[kernel.P_KI], params[kernel.P_KD] = pid.kp, pid.ki, pid.kd
    params[kernel.P_LOOKAHEAD], params[kernel.P_ACCEPT] = lookahead, accept
    params[kernel.P_N_WAYPOINTS] = len(wp)
    params = np.concatenate([params, (wp - wp[0]).ravel()])
    res = run_closed_loop(vessel, params, duration, dt, method, initial={"psi": course}, rps=rps)
    log = res.log
    track = np.zeros((len(log), 2))
    end = kernel.follow_track(params, column_values(log, "x"), column_values(log, "y"), track)
    done = end >= 0
    if done:
        log = log.iloc[: end + 1].copy()
    log["psi_d"], log["cross_track"] = track[: len(log), 0], track[: len(log), 1]
    log["x"] += wp[0, 0]
    log["y"] += wp[0, 1]
    e = column_values(log, "cross_track")
    return FollowResult(log, float(np.sqrt(np.mean(e * e))), float(np.max(np.abs(e))), done,
                        res.diverged and not done)  # fmt: skip


def follow_loop(ship, pid: PID, waypoints, lookahead: float, duration: float, dt: float = 0.1,
                speed: float | None = None, rps: float | None = None,
                method: str = "rk4") -> FollowResult:  # fmt: skip
    """``follow_path`` stepped in Python: the reference the compiled run is tested against."""
    import dataclasses

    vessel = as_vessel(ship, speed, None, rps)
    stepped = dataclasses.replace(vessel, dynamics=_Stepped(vessel.dynamics))
    return follow_path(stepped, pid, waypoints, lookahead, duration=duration, dt=dt, rps=rps,
                       method=method)  # fmt: skip


class _Stepped:
    """Dynamics through their derivatives alone (no compiled entry): the step-by-step loop."""

    def __init__(self, dynamics) -> None:
        self.dynamics = dynamics
        self.uses_rps = getattr(dynamics, "uses_rps", False)
        self.uses_thrust = getattr(dynamics, "uses_thrust", False)
        self.uses_wind = getattr(dynamics, "uses_wind", False)

    def derivatives(self, nu, delta, thrust=None, rps=None) -> np.ndarray:
        if rps is None:
            return self.dynamics.derivatives(nu, delta, thrust)
        return self.dynamics.derivatives(nu, delta, thrust, rps)


class _StillAir:
    """A model with wind terms in still air: the apparent wind of its own motion, from each
    integration stage's state, as the compiled closed loop has it (``kernel.terms_rhs``)."""

    def __init__(self, model) -> None:
        self.model = model
        self.uses_rps = model.uses_rps
        self.uses_thrust = model.uses_thrust

    def derivatives(self, nu, delta, thrust=None, rps=None) -> np.ndarray:
        rps = None if rps is None else float(np.asarray(rps).ravel()[0])
        return still_air_accelerations(self.model, nu[:, 0], nu[:, 1], nu[:, 2], delta, rps)


def _run(ship, pid: PID, desired, duration: float, dt: float, speed: float | None,
         rps: float | None, steering: SteeringMachine | None, method: str,
         psi0: float = 0.0):  # fmt: skip
    """Closed loop of the autopilot: ``desired(t, state) -> (ψd, cross-track or nan, done)``."""
    vessel = as_vessel(ship, speed, steering, rps)
    dyn = vessel.dynamics
    if getattr(dyn, "uses_wind", False):
        dyn = _StillAir(dyn.dynamics if isinstance(dyn, _Stepped) else dyn)
    n = check_samples(duration / dt + 1, 8 * 12, f"a {duration:g} s run at a {dt:g} s step")
    s = initial_states({"u": vessel.approach_speed, "psi": psi0}, 1)
    speed_lim, yaw_lim = DivergenceBounds().resolved(vessel.approach_speed)
    prop = np.array([float(rps)]) if getattr(dyn, "uses_rps", False) and rps is not None else None
    st = vessel.steering
    out = np.zeros((n, 9))
    delta, integral = 0.0, 0.0
    m = n
    done = False
    for k in range(n):
        t = k * dt
        psi_d, cross, done = desired(t, s[0])
        err = _wrap(float(s[0, 3]) - psi_d)
        command = -(pid.kp * err + pid.ki * integral + pid.kd * float(s[0, 2]))
        limited = min(max(command, -st.max_angle), st.max_angle)
        if limited == command:  # anti-windup: integrate only while the rudder is not saturated
            integral += err * dt
        delta = st.step(delta, limited, dt)
        out[k, :6], out[k, 6], out[k, 7], out[k, 8] = s[0], delta, psi_d, cross
        if done or k == n - 1:
            m = k + 1
            break
        new = step_state(dyn, s, np.array([delta]), None, dt, method, prop)
        if not within_bounds(new, speed_lim, yaw_lim)[0]:
            m = k + 1
            break
        s = new
    t = np.arange(m) * dt
    cols = dict(zip(("u", "v", "r", "psi", "x", "y"), out[:m, :6].T, strict=True))
    log = make_log({"t": t, "delta": out[:m, 6], **cols}, **vessel.log_metadata())
    log["psi_d"] = out[:m, 7]
    log["cross_track"] = out[:m, 8]
    return log, done, m < n and not done


# A heading step runs from HEADING_STEP_DURATION s, doubled (up to 16 times) until the heading
# has settled within SETTLED_SHARE of the step: a full-scale ship answers ten times slower than
# its 1:100 model, and a fixed 120 s showed the full-scale KVLCC2 a sixth of the way there.
HEADING_STEP_DURATION, HEADING_STEP_MAX_DOUBLINGS, SETTLED_SHARE = 120.0, 4, 0.02


def heading_step_deg(value: float) -> float:
    """``value`` as a heading step [deg]: non-zero and within ±180°, since the autopilot steers
    the heading error wrapped to half a turn (a step of 400° turned the ship 40°)."""
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value) \
            or not 0.0 < abs(value) < 180.0:
        raise ShipidError(f"the heading step (--heading) must be within ±180° other than 0 "
                          f"(positive to starboard, negative to port), got {value!r}")  # fmt: skip
    return float(value)


def heading_step(ship, pid: PID, heading_deg: float, duration: float | None = None,
                 dt: float = 0.1, speed: float | None = None, rps: float | None = None,
                 steering: SteeringMachine | None = None,
                 method: str = "rk4") -> pd.DataFrame:  # fmt: skip
    """The autopilot ordered from the initial heading to ``heading_deg`` (positive: starboard),
    for ``duration`` s or, by default, until the heading settles (see HEADING_STEP_DURATION).
    ``log.attrs['incomplete']`` says when it has not settled (or the run diverged). It runs in
    the compiled closed loop of the manoeuvres (``kernel.MODE_HEADING``), as ``heading_loop``
    does step by step in Python (the reference its tests check it against)."""
    vessel = as_vessel(ship, speed, steering, rps)
    target = math.radians(heading_step_deg(heading_deg))
    params = manoeuvre_params(vessel, kernel.MODE_HEADING, target, 0.0, 0.0, rps=rps)
    params[kernel.P_KP], params[kernel.P_KI], params[kernel.P_KD] = pid.kp, pid.ki, pid.kd
    tol = SETTLED_SHARE * max(abs(target), math.radians(1.0))

    def run(length: float):
        res = run_closed_loop(vessel, params, length, dt, method, rps=rps)
        psi = column_values(res.log, "psi")
        tail = psi[int(0.8 * len(psi)):]
        return res, bool(np.ptp(tail) <= tol and abs(psi[-1] - target) <= tol)

    (res, settled), length = doubling(
        run, duration or HEADING_STEP_DURATION,
        lambda out: duration is not None or out[0].diverged or out[1],
        2**HEADING_STEP_MAX_DOUBLINGS)  # fmt: skip
    log = res.log
    log["psi_d"] = target
    log["cross_track"] = math.nan
    log.attrs["incomplete"] = ("" if settled else
                               "diverged" if res.diverged else
                               f"the heading has not settled within {length:g} s")  # fmt: skip
    return log


def heading_loop(ship, pid: PID, heading_deg: float, duration: float, dt: float = 0.1,
                 speed: float | None = None, rps: float | None = None,
                 steering: SteeringMachine | None = None,
                 method: str = "rk4") -> pd.DataFrame:  # fmt: skip
    """``heading_step`` stepped in Python (the loop ``follow_path`` runs): the reference the
    compiled heading step is tested against, and its baseline in the benchmarks."""
    target = math.radians(heading_deg)
    log, _, _ = _run(ship, pid, lambda t, s: (target, math.nan, False), duration, dt, speed, rps,
                     steering, method)  # fmt: skip
    return log


def follow_path(
    ship,
    pid: PID,
    waypoints: Sequence[tuple[float, float]],
    lookahead: float,
    acceptance: float | None = None,
    duration: float | None = None,
    dt: float = 0.1,
    speed: float | None = None,
    rps: float | None = None,
    steering: SteeringMachine | None = None,
    method: str = "rk4",
) -> FollowResult:
    """Line-of-sight path following from the first waypoint (the ship starts there, heading
    north) along ``waypoints`` (x north, y east [m])."""
    wp = np.asarray(waypoints, dtype=float)
    if wp.ndim != 2 or wp.shape[1] != 2 or len(wp) < 2 or not np.all(np.isfinite(wp)):
        raise ShipidError("waypoints must be at least two finite (x, y) pairs")
    legs = np.diff(wp, axis=0)
    lengths = np.hypot(legs[:, 0], legs[:, 1])
    if np.any(lengths <= 0):
        raise ShipidError("two consecutive waypoints are the same point")
    if not (math.isfinite(lookahead) and lookahead > 0):
        raise ShipidError(f"lookahead must be > 0 m, got {lookahead!r}")
    accept = lookahead if acceptance is None else acceptance
    if not (math.isfinite(accept) and accept > 0):
        raise ShipidError(f"acceptance must be > 0 m, got {acceptance!r}")
    # A leg no longer than the acceptance distance is switched past as it starts: the run
    # followed the legs after it and reported their cross-track errors as the path's (a 1.25 m
    # ship on 10 m legs at the 20 m default lookahead turned back along the last leg at once).
    short = np.flatnonzero(lengths[:-1] <= accept)
    if short.size:
        k = int(short[0])
        said = "the lookahead" if acceptance is None else "acceptance"
        raise ShipidError(f"leg {k + 1} of the path ({lengths[k]:.3g} m) is no longer than the "
                          f"acceptance distance ({said}, {accept:.3g} m): the ship would be "
                          "switched past it as it starts it; give a shorter lookahead "
                          "(--lookahead) or longer legs")  # fmt: skip
    vessel = as_vessel(ship, speed, steering, rps)
    if duration is None:
        duration = 3.0 * float(lengths.sum()) / vessel.approach_speed
    courses = np.arctan2(legs[:, 1], legs[:, 0])
    dyn = vessel.dynamics
    if isinstance(dyn, ManoeuvringModel) or hasattr(dyn, "integrate_closed"):
        return _follow_compiled(vessel, pid, wp, lookahead, accept, duration, dt, rps, method,
                                float(courses[0]))  # fmt: skip
    state = {"leg": 0}
    offset = wp[0]

    def desired(t, s):
        x, y = s[4] + offset[0], s[5] + offset[1]
        k = state["leg"]
        while True:
            a = courses[k]
            dx, dy = x - wp[k, 0], y - wp[k, 1]
            along = dx * math.cos(a) + dy * math.sin(a)
            if along >= lengths[k] - accept and k + 1 < len(legs):
                k += 1
                state["leg"] = k
                continue
            break
        cross = -dx * math.sin(a) + dy * math.cos(a)
        done = k == len(legs) - 1 and along >= lengths[k]
        return a + math.atan2(-cross, lookahead), cross, done

    log, done, diverged = _run(vessel, pid, desired, duration, dt, None, rps, None, method,
                               psi0=float(courses[0]))  # fmt: skip
    log["x"] += offset[0]
    log["y"] += offset[1]
    e = column_values(log, "cross_track")
    return FollowResult(log, float(np.sqrt(np.mean(e * e))), float(np.max(np.abs(e))), done,
                        diverged)  # fmt: skip

"""Where an identified model leaves its logs: warnings for what its checks at the approach
(``plausibility``) cannot see.

A fit holds where its logs ran. ``identify`` warns, without ruling the model out, where it is
asked beyond them (``select`` of a given steady speed, the rudder's drag and the rudder
reversed; the commands that run a model file again, ``validate``, ``manoeuvre`` and
``criteria``, of the last item, on the model as they run it):

* its own steady straight speed well beyond every log's (``approach_beyond_logs``), or a
  straight speed a user gave that it does not hold (``missed_steady_speed``);
* propeller speeds below or above the logs' (``below_the_logs_rps``, ``above_the_logs_rps``)
  and the logs' other propeller speeds (``at_the_logs_other_rps``), where its held turns fail;
* a rudder drag that pushes the ship ahead (``rudder_drag_ahead``), which logs whose rudder
  rests at one angle leave undetermined;
* from rest, a surge that pushes astern (``from_rest_warning``), and speeds ahead short of the
  straight one where the rudder turns the ship the other way (``rudder_reversed_warning``).
"""

from __future__ import annotations

import numpy as np

from shipid.dynamics.equilibrium import still_air_accelerations, surge_equilibrium
from shipid.dynamics.model import ManoeuvringModel
from shipid.errors import ShipidError
from shipid.identification.plausibility import (
    astern_from_rest_note,
    disqualifying,
    from_rest,
    gross_at_other_rps,
    held_propeller_speeds,
    other_propeller_speeds,
    plausibility_at_approach,
)

# A model's own steady straight speed this much faster than every sample of its training logs
# is where its surge fit extrapolates to, not a speed any log ran.
BEYOND_LOGS = 0.10


def approach_beyond_logs(report: dict, env: dict) -> str | None:
    """A warning where the approach of ``report`` (``plausibility_at_approach``: the model's own
    steady straight speed at the training rps) is more than ``BEYOND_LOGS`` faster than the
    training envelope ``env``'s fastest sample; else None.

    Logs that start from rest and turn at once never run steady: the Esso Osaka's nine
    zig-zags read whole reach 0.544 m/s at most, and the default model of them balanced at
    0.776 m/s at 16.7 rps, where its checks, manoeuvres and criteria started, 43 % beyond any
    log (the ship's turns approach 0.35 m/s at 10 rps, 0.58 m/s at 16.7 rps by the propeller
    law)."""
    speed, fastest = report.get("approach_speed"), (env or {}).get("u", [None, None])[1]
    if not speed or not fastest or not fastest > 0 or speed <= (1 + BEYOND_LOGS) * fastest:
        return None
    at = f" at {report['rps']:.4g} rps" if report.get("rps") is not None else ""
    return (f"the model's steady straight speed{at}, {speed:.4g} m/s, is "
            f"{100 * (speed / fastest - 1):.0f} % beyond the fastest of its training logs "
            f"({fastest:.4g} m/s): no log ran steady there, so the speed its surge balances at "
            "is the fit's extrapolation, and its manoeuvres and criteria start from it; give "
            "--steady-speed U@N (a straight run's speed at N rps), or --speed to them")


# Below the logs' propeller speeds a model extrapolates: from two Esso zig-zag files at 12 and
# 15 rps the default model turned plausibly at both and diverged in a 35° turn at 10 rps (at 0.6
# of the lowest training rps, 7.2 rps, its held turns diverge too). Said where the model is
# made, as `validate` says the same of a log beyond the training range.
LOWER_RPS_SHARE = 0.6
# And above them: over the Esso's 36 pairs of zig-zag files (at 10–16.7 rps), the two models
# whose held turns end astern above their logs' rps in 8–16.7 fail a check at 1.4 times their
# highest and no other pair's does (``benchmarks/study_esso_rps_range.py``).
UPPER_RPS_SHARE = 1.4


def below_the_logs_rps(model: ManoeuvringModel, report: dict, logs) -> str | None:
    """A warning where ``model`` (with propeller terms, checked at the logs' approach in
    ``report``) fails a disqualifying check with the rudder held at ``LOWER_RPS_SHARE`` of the
    lowest rps of ``logs``, each run at a constant rps, from its own steady speed there; else
    None (also for logs whose rps varies within them: random runs cover the low rps)."""
    return _beyond_the_logs_rps(model, report, logs, LOWER_RPS_SHARE)


def above_the_logs_rps(model: ManoeuvringModel, report: dict, logs) -> str | None:
    """As ``below_the_logs_rps``, at ``UPPER_RPS_SHARE`` times the highest rps of ``logs``."""
    return _beyond_the_logs_rps(model, report, logs, UPPER_RPS_SHARE)


def _beyond_the_logs_rps(model: ManoeuvringModel, report: dict, logs, share: float
                         ) -> str | None:  # fmt: skip
    if not getattr(model, "uses_rps", False) or not report.get("approach_speed"):
        return None
    found, every_log = held_propeller_speeds(logs)
    if not every_log or not found or not report.get("rps"):
        return None
    below = share < 1
    edge = min(found) if below else max(found)
    rps = share * edge
    near = report["approach_speed"] * rps / float(report["rps"])
    try:
        there = plausibility_at_approach(model, near, rps, None, rps)[0]
    except (ShipidError, ValueError):
        return None
    reasons = [("has " + r if r.startswith("no ") else r) for r in disqualifying(there, model)]
    if not reasons:
        return None
    where = (f"below the logs' propeller speeds the model extrapolates: at {rps:.3g} rps "
             f"({share:g} of the lowest, {edge:.4g})" if below else
             f"above the logs' propeller speeds the model extrapolates: at {rps:.3g} rps "
             f"({share:g} times the highest, {edge:.4g})")  # fmt: skip
    return (f"{where} it {' and '.join(reasons[:2])}; validate it on a log at the propeller "
            "speed you need before using it there")


def at_the_logs_other_rps(model: ManoeuvringModel, report: dict, logs) -> list[str]:
    """Warnings where ``model`` (checked at the logs' approach in ``report``) holds its rudder
    at another propeller speed its logs ran at and the turn diverges, turns the other way or
    ends going astern (``gross_at_other_rps``): ``select`` rules such candidates out, a
    structure given with ``--model`` is fitted as it is."""
    speed, rps = report.get("approach_speed"), report.get("rps")
    if not speed or not rps:
        return []
    others = other_propeller_speeds(logs, rps)
    try:
        failing = gross_at_other_rps(model, speed, rps, others)
    except (ShipidError, ValueError):
        return []
    return [f"at a propeller speed its logs ran at, the model {why}: no ship does, and its "
            "logs there are not represented (another --model, or none: the default's selection "
            "rules such fits out)" for _, why in failing.values()]


def given_steady_speeds(physics) -> list[tuple[float, float]]:
    """(u, n) of the steady speeds a user gave (``--steady-speed``): the model is checked there
    too, where its manoeuvres will be asked for, not only from the first log's approach."""
    approach = getattr(physics, "approach", None) if getattr(physics, "steady_speed", False) \
        else None  # fmt: skip
    if not approach:
        return []
    items = [approach] if isinstance(approach, dict) else list(approach)
    return [(float(a.get("given_u", a["u"])), float(a.get("given_n", a.get("n", 0.0))))
            for a in items]  # fmt: skip


# A model whose straight run settles this far from a speed it was given does not hold it.
GIVEN_SPEED_TOLERANCE = 1e-3


def missed_steady_speed(model, speed: float, rps: float) -> str | None:
    """A warning where ``model`` (as the model file has it) does not hold the straight ``speed``
    a user gave at ``rps`` (``--steady-speed``; 0: none given): the fit's equality holds on the
    fit's own terms, and what the file holds may differ from them (carried to every rps, a
    kernel residual added, refined by output error)."""
    if not hasattr(model, "structure") or "u" not in model.structure.dofs:
        return None
    held = surge_equilibrium(model, speed, rps or None)
    if held is not None and abs(held - speed) <= GIVEN_SPEED_TOLERANCE * speed:
        return None
    where = "no steady speed" if held is None else f"{held:.4g} m/s"
    given, at = (f"{speed:.4g}@{rps:.4g}", f" at {rps:.4g} rps") if rps else (f"{speed:.4g}", "")
    return (f"--steady-speed {given}: the model holds {where} straight{at}, not the speed given "
            "(the fit's surge balances there on its own terms; the model file's may hold "
            "another: a kernel residual added, a refinement, or a surge without propeller-speed "
            "terms, which holds one speed at every rps)")


# A rudder drag that pushes ahead by less than this share of the particulars' drag is left
# unsaid: the average of the Esso's three random runs' candidates holds +8.8e-6 per δ² against
# the particulars' −0.0020, nothing a turn's speed rests on; the single zig-zag files' that do
# push ahead, 46–340 % of it.
DRAG_AHEAD_SHARE = 0.1


def rudder_drag_ahead(model, particulars, speed: float | None, rps: float | None,
                      std_errors: dict | None = None) -> str | None:  # fmt: skip
    """A warning where ``model``'s surge has its rudder drag push the ship ahead: its terms of
    ``physics.RUDDER_DRAG_TERMS`` and the rudder's normal force's drag (``--rudder-normal``'s
    F_N sin δ) summed at the straight approach (``speed``, ``rps``) per δ² as δ → 0
    come out > 0, which no rudder does (by more than ``DRAG_AHEAD_SHARE`` of the particulars'
    drag). A zig-zag holds its rudder at one angle most of the time,
    where δ² is one with the thrust, so logs at one rps hardly determine it (the Esso's single
    zig-zag files: ±0.005 to ±0.08, three of nine fitted > 0), and a turn's loss of speed rests
    on it. The warning gives the particulars' value (``priors.rudder_drag``) and the bound that
    holds a single term there: a trade on those files (``benchmarks/README.md``, *The rudder's
    drag of one zig-zag file*), so named, not applied. ``std_errors``: the fit's {term: ±} of
    u̇. None where the drag is a drag, or the particulars cannot give its value."""
    from shipid.data.particulars import Particulars
    from shipid.dynamics.terms import parse_term, rudder_normal_angle, term_matrix
    from shipid.identification.physics import RUDDER_DRAG_TERMS
    from shipid.identification.priors import rudder_drag

    if not (speed and speed > 0) or "u" not in getattr(model, "coefficients", {}):
        return None
    terms = {t: c for t, c in model.coefficients["u"].items()
             if c != 0 and (parse_term(t).text in RUDDER_DRAG_TERMS
                            or rudder_normal_angle(t) == "sin")}  # fmt: skip
    if not terms or particulars is None:
        return None
    n0 = float(rps) if rps else 0.0
    # Per δ² as δ → 0, where the normal force's drag U_R² sin α_R sin δ is U_R² δ² straight ahead.
    small = 1e-3
    values = term_matrix(list(terms), np.array([speed]), np.zeros(1), np.zeros(1),
                         {"delta": np.array([small]), "n": np.array([n0])})[0] / small**2
    at = dict(zip(terms, values.tolist(), strict=True))
    drag = sum(c * at[t] for t, c in terms.items())
    if not drag > 0:
        return None
    if not isinstance(particulars, Particulars):
        particulars = Particulars.from_mapping(particulars)
    physical = rudder_drag(particulars, speed, rps)
    if physical is None or drag <= DRAG_AHEAD_SHARE * abs(physical):
        return None
    errors = std_errors or {}
    shown = ", ".join(f"{t} {c:+.3g}" + (f" ± {errors[t]:.2g}" if t in errors else "")
                      for t, c in terms.items())  # fmt: skip
    loose = [t for t, c in terms.items() if t in errors and abs(c) < 2 * errors[t]]
    where = f"{speed:.3g} m/s" + (f" and {n0:.4g} rps" if n0 > 0 else "")
    if len(terms) == 1 and at[next(iter(terms))] > 0:
        term = next(iter(terms))
        value = physical / at[term]
        remedy = (f"--bound 'u: {term} <= {value:.3g}' --bound 'u: {term} >= {value:.3g}' "
                  "holds it there")  # fmt: skip
    else:
        remedy = "--constraints signs holds each of its terms to a drag"
    return (f"surge: the rudder's drag pushes the ship ahead ({shown}"
            + (", which these logs do not determine" if loose else "")
            + "), so its turns lose too little speed (logs whose rudder rests at one angle most "
            "of the time, as a zig-zag's does, leave δ² one with the thrust); the particulars put it "
            f"at {physical:.3g} per δ² (the rudder's normal force in its inflow at {where}): "
            f"{remedy}, a trade (benchmarks/README.md, *The rudder's drag of one zig-zag "
            "file*)")


# How far above a given speed the warnings look for the straight speed where none lies within
# ``surge_equilibrium``'s own span of it (``_straight_from``: a manoeuvre begun at 0.2 m/s).
STRAIGHT_SPAN = 30.0


def from_rest_warning(model, speed: float | None, rps: float | None) -> str | None:
    """``from_rest``'s warning for ``model`` at the propeller speed ``rps``, its straight speed
    the surge's equilibrium nearest ``speed``; None where the model gets under way, has no surge
    or no straight speed (a check of its own), or is driven by a logged thrust. ``identify``
    gives it once; the commands that run a model file again (``validate``, ``manoeuvre``,
    ``criteria``) repeat it, checked on the model as they run it (a rescaled file too), where a
    run that starts slow or stops meets it."""
    if (getattr(model, "uses_thrust", False) or "u" not in model.structure.dofs
            or not (speed and speed > 0)):  # fmt: skip
        return None
    straight = _straight_from(model, speed, rps)
    found = from_rest(model, rps, straight)
    return None if found is None else astern_from_rest_note(found, rps, straight, model)


def _straight_from(model, speed: float, rps: float | None) -> float | None:
    """The surge's equilibrium nearest ``speed`` (``surge_equilibrium``), looked for up to
    ``STRAIGHT_SPAN`` times it where none lies within its own span: a manoeuvre begun slow
    (``--speed 0.2``) balances well above the speed given, and the warnings that read from the
    straight speed were passed over for exactly the runs that start slow."""
    return (surge_equilibrium(model, speed, rps)
            or surge_equilibrium(model, speed, rps, span=STRAIGHT_SPAN))  # fmt: skip


# The speeds (shares of the straight speed, rest left out: no flow, no force) at which
# ``rudder_reversed`` reads the rudder's yaw derivative, and the share of its value at the
# straight speed that a derivative of the other sign must pass to count (not a rounding's).
RUDDER_REVERSED_SHARES = np.linspace(0.0, 1.0, 41)[1:]
RUDDER_REVERSED_FLOOR = 0.01


def rudder_reversed(model, rps: float | None, straight_speed: float | None
                    ) -> dict[str, tuple[float, float]]:  # fmt: skip
    """Where ``model``'s rudder turns the ship the other way than at its straight speed: the
    yaw derivative ∂ṙ/∂δ at straight running (v = r = 0, still air) of the other sign, by more
    than ``RUDDER_REVERSED_FLOOR`` of its value there, at speeds ahead up to ``straight_speed``
    with the propeller at ``rps`` ("at_rps") and stopped ("stopped", a model with terms in n):
    {case: (lowest, highest) such speed}, empty where it turns the ship its way throughout.

    A fit of zig-zags at one propeller speed reads the race's u², u·n and n² only over the
    logs' speeds; outside them their sum can change sign: the KVLCC2's MARIN 20/20 run fitted by
    ``blanke-race+race-damping`` turns the ship the wrong way below 0.35 m/s ahead at its 10.33
    rps (28 % of its straight speed) and at most speeds with the propeller stopped
    (``--constraints rudder-ahead`` holds the sign there)."""
    if (straight_speed is None or not straight_speed > 0 or "r" not in model.structure.dofs
            or not any("delta" in t for t in model.structure.terms.get("r", ()))):  # fmt: skip
        return {}
    h = 1e-3
    u = straight_speed * RUDDER_REVERSED_SHARES
    zero = np.zeros_like(u)

    def slope(n):
        port = np.asarray(still_air_accelerations(model, u, zero, zero, zero + h, n))[:, 2]
        stbd = np.asarray(still_air_accelerations(model, u, zero, zero, zero - h, n))[:, 2]
        return (port - stbd) / (2 * h)

    at_rps = slope(rps)
    reference = at_rps[-1]
    if not reference:
        return {}
    cases = {"at_rps": at_rps}
    if getattr(model, "uses_rps", False) and rps:
        cases["stopped"] = slope(0.0)
    out = {}
    for case, d in cases.items():
        wrong = u[d * np.sign(reference) < -RUDDER_REVERSED_FLOOR * abs(reference)]
        if wrong.size:
            out[case] = (float(wrong.min()), float(wrong.max()))
    return out


def rudder_reversed_warning(model, speed: float | None, rps: float | None) -> str | None:
    """``rudder_reversed``'s warning for ``model`` at the propeller speed ``rps``, its straight
    speed the surge's equilibrium nearest ``speed`` (``speed`` itself for a model without surge);
    None where its rudder turns the ship its way at every speed ahead up to it. ``identify``
    gives it once; ``validate``, ``manoeuvre`` and ``criteria`` repeat it (as
    ``from_rest_warning``): where a run starts slow, slows or stops its propeller."""
    if getattr(model, "uses_thrust", False) or not (speed and speed > 0):
        return None
    straight = _straight_from(model, speed, rps) if "u" in model.structure.dofs else speed
    found = rudder_reversed(model, rps, straight)
    if not found:
        return None
    at = f" at {rps:.4g} rps" if rps and getattr(model, "uses_rps", False) else ""
    parts = []
    if "at_rps" in found:
        lo, hi = found["at_rps"]
        where = (f"below {hi:.3g} m/s ahead" if lo <= straight * RUDDER_REVERSED_SHARES[0] + 1e-12
                 else f"from {lo:.3g} to {hi:.3g} m/s ahead")  # fmt: skip
        parts.append(f"{where}{at} ({100 * hi / straight:.0f} % of its straight speed "
                     f"{straight:.3g} m/s)")
    if "stopped" in found:
        lo, hi = found["stopped"]
        parts.append(f"from {lo:.3g} to {hi:.3g} m/s ahead with the propeller stopped")
    return ("the rudder turns the ship the other way " + " and ".join(parts) + ": its terms "
            "were fitted where the logs ran and their sum changes sign outside; a log at those "
            "speeds decides, or --constraints rudder-ahead holds the sign at every speed ahead "
            "(a trade: docs/physics-and-uncertainty.md)")

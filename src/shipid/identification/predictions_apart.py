"""Where structures the logs cannot tell apart predict beyond them apart.

Structures whose free-run scores on the held-out logs lie within one standard error of each
other are tied: the logs cannot choose between them. Beyond the logs they may part, and then the
choice, not the data, sets what the model predicts. ``auto_structure`` runs the tied fits
through what the logs do not hold and warns where they come apart:

* a turn with the rudder the plausibility checks hold (35°, or the gear's ``rudder_limit``):
  steady yaw rates more than ``TURNS_APART`` apart (``rates_apart``, ``held_turns_apart``);
* the IMO's 10°/10° zig-zag at the logs' rudder rate: overshoots more than
  ``OVERSHOOTS_APART_DEG`` apart (``zigzag_overshoots``, ``predictions_apart``);
* a structure ruled out by its held rudder alone, beyond the logs' rudder
  (``beyond_the_logs_rudder``), that predicted the logs better (``ruled_out_apart``).
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np

# Structures the logs cannot tell apart whose 35° turns' steady yaw rates differ by more than this
# factor: the choice, not the data, sets what the model predicts beyond the logs.
TURNS_APART = 1.25
# ... or whose 10°/10° zig-zag overshoots differ by more than this [deg]: the precision issue #10
# asks of predicted overshoots (1.5°). On the real KVLCC2's three zig-zags (MARIN ±20°, HSVA
# 20/10) blanke-speed and blanke-race+race-damping tie, with second overshoots 11.5° and 14.5°.
OVERSHOOTS_APART_DEG = 1.5
# The unseen zig-zag run on the tied fits: the IMO's 10°/10°, to starboard first.
ZIGZAG_APART = (10.0, 10.0)
# How far below the rudder the plausibility checks hold (``plausibility.held_rudder_deg``) the
# logs' largest must stay for a check there to be beyond them [deg].
BEYOND_RUDDER_DEG = 5.0


def settled_yaw_rates(reports, side: str) -> list[float | None]:
    """The steady yaw rate of each plausibility report's held turn to ``side``, None where it
    diverged or never settled: what two fits' turns are compared by (``rates_apart``)."""
    entries = (((report or {}).get("held_rudder") or {}).get(side) or {} for report in reports)
    return [e.get("steady_yaw_rate") if e.get("settled") and not e.get("diverged") else None
            for e in entries]  # fmt: skip


def rates_apart(rates) -> bool:
    """Whether fits' steady yaw rates (None: no steady turn) are more than ``TURNS_APART``
    apart, or some fit has none: what ``predictions_apart`` warns of and what ``identify``
    weighs between its output-error and LS-SVM fits."""
    known = [abs(r) for r in rates if r is not None and np.isfinite(r) and r != 0]
    return len(known) < len(rates) or max(known) > TURNS_APART * min(known)


def beyond_the_logs_rudder(held_deg: float, reach_deg: float) -> bool:
    """Whether a rudder of ``held_deg`` held lies beyond the logs' (their largest, ``reach_deg``
    of ``data.log.rudder_reach_deg``, more than ``BEYOND_RUDDER_DEG`` below it): a turn there
    is the fit's extrapolation in the rudder, not a turn the logs' rudder reached."""
    return reach_deg <= held_deg - BEYOND_RUDDER_DEG


def ruled_out_apart(chosen, name: str, score: float, ruled_out: Mapping[str, object], faults,
                     logs) -> list[str]:  # fmt: skip
    """Warnings where a structure ruled out by the held rudder's checks alone predicted the
    held-out logs better than the chosen one and runs a 10°/10° zig-zag more than
    ``OVERSHOOTS_APART_DEG`` from its: inside the logs' rudder, what the model predicts rests
    on a check beyond them. (On the MARIN KVLCC2 zig-zag, ``blanke`` is left out so and scores
    within one standard error but worse, 0.41 against 0.36: the other MARIN run confirms it.)"""
    from shipid.data.log import rudder_reach_deg
    from shipid.identification.plausibility import (
        disqualifying_at_approach,
        held_rudder_at,
        held_rudder_deg,
    )

    held, reach = held_rudder_deg(), rudder_reach_deg(logs)
    if not ruled_out or not beyond_the_logs_rudder(held, reach):
        return []  # the logs reach the held rudder: the check is theirs
    out = []
    for k, model in ruled_out.items():
        overshoots = zigzag_overshoots({name: chosen, k: model}, logs)
        if overshoots is None:
            continue
        a, b = overshoots[name], overshoots[k]
        if None in a + b or max(abs(a[0] - b[0]), abs(a[1] - b[1])) <= OVERSHOOTS_APART_DEG:
            continue
        head = (f"{k} predicts the logs better than {name} (free-run scores {faults[k][1]:.3f} "
                f"and {score:.3f}) but was left out for its {held:g}° rudder held, beyond the "
                f"logs' {reach:.3g}° ({faults[k][2]}); their {ZIGZAG_APART[0]:g}°/"
                f"{ZIGZAG_APART[1]:g}° zig-zags come apart (overshoots {name} {a[0]:.1f}°, "
                f"{a[1]:.1f}°; {k} {b[0]:.1f}°, {b[1]:.1f}°)")  # fmt: skip
        # Held just beyond the logs' rudder: a fit that fails there too is not one the check
        # far beyond them alone left out (the tanker's two 10°/10° zig-zags: the race
        # structure, 0.052 against blanke-speed's 0.192, all but stops with 15° held, where
        # the ship runs at 3.2 m/s, and its steady 10° turn loses half the ship's speed).
        with held_rudder_at(reach + BEYOND_RUDDER_DEG) as near:
            nearer = disqualifying_at_approach(logs)(model)
        if nearer:
            # At the logs' own rudder it may pass: the choice a gear that stops there makes
            # (the tanker's 10° gear: its race fit within 1.2 % of the 10° turns).
            with held_rudder_at(reach) as own:
                gear = "" if disqualifying_at_approach(logs)(model) else (
                    f"; it passes them with {own:.3g}° held, the logs' own: where the ship's gear "
                    f"stops there, its rudder_limit in --particulars holds the checks there")
            out.append(f"{head}, and it fails the checks with {near:.3g}° held too "
                       f"({'; '.join(nearer)}): near the logs' rudder as beyond it; a zig-zag "
                       f"log of that kind decides{gear}")  # fmt: skip
        else:
            out.append(f"{head}: inside the logs' rudder the choice rests on a check beyond "
                       f"them (it passes them with {near:.3g}° held); a zig-zag log of that "
                       f"kind, or --model {k}, decides (where the ship's gear stops short of "
                       f"{held:g}°, its rudder_limit in --particulars moves the check there)")
    return out


def zigzag_overshoots(models: Mapping[str, object], logs) -> dict | None:
    """{name: [first, second overshoot]} of each model's ``ZIGZAG_APART`` zig-zag from the first
    log's approach at the logs' rudder rate (None for one it does not reach); None without an
    approach speed."""
    from shipid.data.log import approach
    from shipid.dynamics.steering import SteeringMachine
    from shipid.trials.manoeuvres import zigzag
    from shipid.trials.trial import logs_rudder_rate

    speed, rps = approach(logs[0], "u"), approach(logs[0], "n")
    if not speed or not speed > 0:
        return None
    dt = float(np.median(np.diff(logs[0]["t"].to_numpy())))
    rate = logs_rudder_rate(logs)  # the gear identify records in the model file
    steering = SteeringMachine(max_rate=rate) if rate else None
    out = {}
    for name, model in models.items():
        zz = zigzag(model, *ZIGZAG_APART, speed=speed, rps=rps, steering=steering,
                    method="euler", dt=dt)  # fmt: skip
        ind = {} if zz.diverged else (zz.indices or {})
        values = [ind.get(k) for k in ("first_overshoot_deg", "second_overshoot_deg")]
        out[name] = [x if x is not None and np.isfinite(x) else None for x in values]
    return out


def predictions_apart(models: Mapping[str, object], logs) -> list[str]:
    """Warnings where structures that predict the logs alike (free-run scores within one
    standard error) predict an unseen manoeuvre far apart: a turn at the rudder the
    plausibility checks hold (35°, or the gear's ``rudder_limit``; steady yaw rates apart by more
    than ``TURNS_APART``) or a 10°/10° zig-zag (overshoots apart by more than
    ``OVERSHOOTS_APART_DEG``), each run on their fits of the comparison from the first log's
    approach (the zig-zag at the logs' rudder rate).

    On the KVLCC2's MMG model observed through noisy 20/20 zig-zags with the rps logged, the
    three inflow structures tie; fitted as ``identify`` fits them, ``blanke``'s 35° turns' steady
    yaw rates are 2.7 to 3.9 times the truth's, where ``blanke-race+race-damping`` (fitted: the
    tie's ``RACE_PREFERRED``) comes within 14 % (``benchmarks/study_auto_inflow.py``). On the
    paper's own ship with an rps logged, the tie goes the other way: ``blanke`` is the truth.
    On the real KVLCC2's three zig-zags the turns agree and the 10°/10° second overshoots do
    not. The logs cannot tell; the user is told."""
    from shipid.data.log import approach
    from shipid.identification.plausibility import held_rudder_deg
    from shipid.trials.manoeuvres import turning_circle

    overshoots = zigzag_overshoots(models, logs)
    if overshoots is None:
        return []
    speed, rps = approach(logs[0], "u"), approach(logs[0], "n")
    dt = float(np.median(np.diff(logs[0]["t"].to_numpy())))
    rudder = held_rudder_deg()  # the gear's largest (rudder_limit), as the checks hold
    rates = {}
    for name, model in models.items():
        res = turning_circle(model, rudder, speed=speed, rps=rps, method="euler", dt=dt)
        r = None if res.diverged else (res.indices or {}).get("steady_yaw_rate")
        rates[name] = abs(r) if r is not None and np.isfinite(r) else None
    alike = (f"{', '.join(models)} predict the logs alike (free-run scores within one standard "
             "error) but")  # fmt: skip
    out = []
    if rates_apart(list(rates.values())):
        shown = ", ".join(f"{k} {'no steady turn' if r is None else f'{r:.3g} rad/s'}"
                          for k, r in rates.items())  # fmt: skip
        out.append(f"{alike} a {rudder:g}° turning circle apart (steady yaw rates of the compared fits: "
                   f"{shown}): the logs cannot choose what the model predicts beyond them; a "
                   "turning log, or --model, decides")  # fmt: skip
    known = [v for v in overshoots.values() if all(x is not None and np.isfinite(x) for x in v)]
    if len(known) < len(overshoots) or any(
            max(v[j] for v in known) - min(v[j] for v in known) > OVERSHOOTS_APART_DEG
            for j in (0, 1)):  # fmt: skip
        shown = "; ".join(f"{k} " + ("no overshoots" if None in v or not np.all(np.isfinite(v))
                                     else f"{v[0]:.1f}°, {v[1]:.1f}°")
                          for k, v in overshoots.items())  # fmt: skip
        out.append(f"{alike} a {ZIGZAG_APART[0]:g}°/{ZIGZAG_APART[1]:g}° zig-zag apart "
                   f"(overshoots of the compared fits: {shown}; more than "
                   f"{OVERSHOOTS_APART_DEG:g}° apart): the logs cannot choose what the model "
                   "predicts beyond them; a zig-zag log of that kind, or --model, decides")
    return out


def held_turns_apart(first: dict | None, second: dict | None,
                      first_may_fail: bool = False) -> str | None:
    """Two plausibility reports' held turns' path radii, side by side ('starboard 3.69 m
    against 5.51 m, …'), where their steady yaw rates are far apart on a side (``rates_apart``,
    both settled; with ``first_may_fail``, also where the first has no steady turn and the
    second has: 'no steady turn against 5.51 m'); else None."""
    sides = []
    for side in ("starboard", "port"):
        rates = settled_yaw_rates((first, second), side)
        if not rates[1] or (rates[0] is None and not first_may_fail) or (
                rates[0] and not rates_apart(rates)):  # fmt: skip
            continue
        radii = [f"{x['held_rudder'][side]['steady_speed'] / abs(r):.3g} m" if r
                 else "no steady turn" for x, r in zip((first, second), rates, strict=True)]
        sides.append(f"{side} {radii[0]} against {radii[1]}")
    return ", ".join(sides) or None

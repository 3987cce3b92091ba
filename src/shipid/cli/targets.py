"""What a command runs on: a model file with its training conditions or a reference ship (built
in, an MMG file, a corrected ship), its length and scale checked against the ship the command
names, its straight approach and its steering machine; the commands' default steps."""

from __future__ import annotations

import math
from pathlib import Path

from shipid.errors import ShipidError

VESSEL_NAMES = ("scale-ship", "mariner", "kvlcc2", "cybership2", "tanker")


def _vessel_names() -> tuple[str, ...]:
    from shipid.vessels import VESSELS

    return tuple(VESSELS)


# The commands' default integration steps [s].
MANOEUVRE_STEP = CRITERIA_STEP = 0.05


CONTROL_STEP = 0.1  # autopilot, follow


def _vessel_conditions() -> dict:
    """A reference ship's "training conditions": none (no logs, no envelope, no convention of
    logs: the ship says its own)."""
    return {"speed": None, "rps": None, "envelope": {}, "particulars": None,
            "rudder_rate": None, "rudder_positive": None, "alternatives": {},
            "alternatives_fit": ""}  # fmt: skip


def _reference_ship(name: str):
    """The reference ship ``name`` says: a built-in one, or a ship's file (an MMG model,
    ``shipid correct``'s corrected ship); None for a model file."""
    if name in VESSEL_NAMES:
        from shipid.vessels import get_vessel

        return get_vessel(name)
    from shipid.identification.correction import reference_file

    return reference_file(name)


def _ship_or_model(name: str, hybrid: bool = False):
    """A reference ship (its trimmed speed applies) or a model file with its training
    conditions (approach speed, propeller speed, envelope); a model with a kernel residual
    where the command runs one (``hybrid``), else refused."""
    from shipid.reporting.modelfile import load_document, model_from_document, training_conditions
    if name not in VESSEL_NAMES and not Path(name).exists():
        raise ShipidError(f"{name}: neither a model file nor a known vessel "
                          f"({', '.join(VESSEL_NAMES)})")  # fmt: skip
    from shipid.identification.correction import ship_ensemble

    ship = _reference_ship(name)
    if ship is not None:
        # A corrected ship's bootstrap replicates, where its file has them: the bands.
        return ship, {**_vessel_conditions(), "ensemble": ship_ensemble(ship)}
    from shipid.reporting.modelfile import (
        alternatives_fit,
        alternatives_from_document,
        ensemble_from_document,
    )

    doc = load_document(name)
    model = model_from_document(doc, name, hybrid=hybrid)
    cond = training_conditions(doc)
    cond["ensemble"] = ensemble_from_document(doc, name, model)
    cond["alternatives"] = alternatives_from_document(doc, name)
    cond["alternatives_fit"] = alternatives_fit(doc)
    return model, cond


# Lengths of one ship further apart than this are two ships (another scale), not a correction.
LENGTH_SLACK = 0.05


def _check_length(name: str, target, cond: dict, given: float | None, source: str) -> None:
    """Refuse a length that is not the one of the ship ``target`` runs as: its indices in ship
    lengths were divided by another ship's (a 4 m model judged with full-scale particulars of
    67.8 m had tactical diameters of 0.19 L, and passed). ``source`` names the option."""
    own = getattr(target, "length", math.nan)
    if not (isinstance(own, float) and math.isfinite(own)):
        own = cond["particulars"].length if cond.get("particulars") is not None else None
    if own and given and abs(given / own - 1.0) > LENGTH_SLACK:
        remedy = (f"to judge a ship {given / own:.4g} times as long, carry the model over first "
                  f"(shipid rescale {name} --length {given:g} -o OUT.json)"
                  if name not in VESSEL_NAMES else "a reference ship is judged at its own")
        raise ShipidError(f"{source} gives a length of {given:g} m, but {name} runs as a ship of "
                          f"{own:g} m: its manoeuvres are that ship's, so their lengths would be "
                          f"divided by another's; {remedy}")  # fmt: skip


SCALE_SLACK = 0.01  # a scale this close to the training logs' is theirs (rounding, 45.7 vs 45.71)


def _check_scale(name: str, cond: dict, scale: float | None, source: str) -> None:
    """Refuse a scale λ that is not the one of the logs the model was identified from: its
    manoeuvres run at their ship's size and speed. A model of MARIN's full-scale KVLCC2 files
    (read without --scale, λ = 1, 8.1 m/s) judged with the 7 m model's particulars (λ = 45.7)
    ran its manoeuvres at 8.1 m/s over a 7 m ship's times and printed not one value, and its
    verdict: NOT all criteria met."""
    trained = cond.get("log_scale")
    if not trained or not scale or abs(scale / trained - 1.0) <= SCALE_SLACK:
        return
    raise ShipidError(f"{source} gives the ship at 1:{scale:g}, but {name} was identified from "
                      f"logs at 1:{trained:g}: its manoeuvres run at that ship's size and speed; "
                      f"identify from the trial files read with --scale {scale:g}, or carry the "
                      f"model over first (shipid rescale {name} --factor {trained / scale:.4g} -o "
                      "OUT.json)")  # fmt: skip


def _steady_window(cond: dict) -> float:
    """The seconds over which a model's approach is judged steady: ``STEADY_WINDOW`` at the
    scale it was identified at, √λ times as long for each Froude rescaling by λ since
    (``modelfile.time_scale``), that a rescaled model start its manoeuvres as its original."""
    from shipid.data.log import STEADY_WINDOW

    return STEADY_WINDOW * cond.get("time_scale", 1.0)


def _run_approach(target, cond: dict, speed: float | None, rps: float | None):
    """Approach speed and rps of a run on ``target``: a reference ship's own trim, or a model's
    steady straight approach (``shipid.dynamics.equilibrium.steady_approach``), printed, with a
    warning when it is not steady. Returns (speed, rps, warning or None)."""
    from shipid.dynamics.equilibrium import steady_approach
    from shipid.dynamics.hybrid import HybridModel
    from shipid.dynamics.model import ManoeuvringModel

    if not isinstance(target, ManoeuvringModel | HybridModel):
        return _ship_approach(target, speed, rps)
    if target.uses_thrust:  # its straight approach needs the thrust too
        from shipid.trials.manoeuvres import THRUST_REFUSED

        raise ShipidError(THRUST_REFUSED)
    if speed is None and not cond["speed"]:
        return None, rps if rps is not None else cond["rps"], None  # the run names what is missing
    app = steady_approach(target, cond["speed"], cond["rps"], speed, rps,
                          window=_steady_window(cond))  # fmt: skip
    print(app.describe())
    return app.speed, app.rps, app.warning


def _ship_approach(ship, speed: float | None, rps: float | None):
    """A reference ship's run: its own trim; where its propeller follows the run's rate (an MMG
    file's ``rps: logs``), the trimmed rps unless given, and at a given rps without --speed the
    ship's straight-running speed at it, printed. Returns (speed, rps, None)."""
    dyn = getattr(ship, "dynamics", None)
    if not getattr(dyn, "uses_rps", False):
        return speed, rps, None
    if rps is None:
        return speed, dyn.reference.n_prop if hasattr(dyn, "reference") else dyn.n_prop, None
    if speed is None:
        from shipid.dynamics.equilibrium import vessel_straight_speed

        speed = vessel_straight_speed(ship, rps)
        if speed is None:
            raise ShipidError(f"{ship.name}: no straight-running speed at {rps:g} rps (the "
                              "propeller's thrust does not meet the resistance); give --speed")
        print(f"approach: {speed:.4g} m/s, {ship.name}'s straight-running speed at {rps:g} rps")
    return speed, rps, None


def _steering(target, cond: dict, rate_deg_s: float | None, fallback: str = "instantaneous"):
    """The steering machine of a run and a line saying which: ``--rudder-rate`` (a reference
    ship keeps its gear's other limits), else a reference ship's own gear (None: the ship's),
    else the rate of the model's training logs (overshoots depend on it as much as on the
    model), else ``fallback``: an instantaneous rudder, said so, or 'caller' (None: the caller
    chooses, as the IMO criteria take the SOLAS rate)."""
    import dataclasses

    from shipid.dynamics.steering import SteeringMachine

    own = getattr(target, "steering", None)
    # A model's gear: 35°, or the particulars' rudder_limit where the ship's stops short of it.
    particulars = cond.get("particulars")
    largest = math.radians(particulars.largest_rudder_deg if particulars else 35.0)
    if rate_deg_s is not None:
        rate, source = math.radians(rate_deg_s), "--rudder-rate"
    elif own is not None:
        rate = own.max_rate
        return None, ("rudder: the ship's own steering gear" + (
            f", {math.degrees(rate):.3g} °/s" if rate else ", instantaneous"))
    elif cond.get("rudder_rate"):
        rate, source = float(cond["rudder_rate"]), "the training logs' rudder rate"
    elif fallback == "caller":
        return None, None
    elif cond.get("rudder_unresolved"):
        return SteeringMachine(largest), ("rudder: instantaneous (the training logs' rudder "
                                          "swings between two samples, faster than they "
                                          "resolve; give a rate with --rudder-rate DEG/S)")
    else:
        return SteeringMachine(largest), ("rudder: instantaneous (the model file has no "
                                          "training rudder rate; give one with --rudder-rate "
                                          "DEG/S)")  # fmt: skip
    steering = (SteeringMachine(largest, rate) if own is None
                else dataclasses.replace(own, max_rate=rate))  # fmt: skip
    return steering, f"rudder rate {math.degrees(rate):.3g} °/s ({source})"

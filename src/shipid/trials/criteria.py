"""IMO MSC.137(76) manoeuvrability criteria (manoeuvring-standards.md §1.3), predicted by running the
standard manoeuvres on a model or ship, or read off measured logs.

* turning: advance ≤ 4.5 L, tactical diameter ≤ 5 L (35° rudder, both sides);
* initial turning: ≤ 2.5 L travelled when the heading has changed 10° with 10° rudder (the first
  leg of the 10°/10° zig-zag);
* 10°/10° overshoots: first ≤ 10° (L/V < 10 s), 5 + ½ L/V (10–30 s), 20° (≥ 30 s); second ≤ 25°,
  17.5 + 0.75 L/V, 40°;
* 20°/20° first overshoot ≤ 25°;
* stopping: track reach ≤ 15 L (models with propeller terms).

L/V is the full-scale value: at model scale λ, L/V = (L/V)model · √λ. A reference ship turns its
rudder with its own steering gear; a model at the rate given (the CLI passes the training logs'
rate), else at the SOLAS rate 2.32 °/s at full scale (2.32·√λ °/s at model scale).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from shipid.data.log import STEADY_WINDOW
from shipid.data.particulars import Particulars
from shipid.dynamics.equilibrium import unsteady_warning
from shipid.dynamics.hybrid import HybridModel
from shipid.dynamics.model import ManoeuvringModel
from shipid.dynamics.steering import SteeringMachine
from shipid.errors import ShipidError
from shipid.trials.manoeuvres import (
    astern_thrust_note,
    stopping,
    turning_circle,
    without_value,
    zigzag,
)
from shipid.trials.trial import TURN_KINDS
from shipid.vessels.vessel import Vessel

SOLAS_RUDDER_RATE_DEG = 2.32
SIDES = ("starboard", "port")


def overshoot_limits(l_over_v: float) -> tuple[float, float]:
    """(first, second) 10°/10° overshoot limits [deg] for the full-scale L/V [s]."""
    if not (math.isfinite(l_over_v) and l_over_v > 0):
        raise ShipidError(f"L/V must be a positive time in seconds, got {l_over_v!r}")
    if l_over_v < 10.0:
        return 10.0, 25.0
    if l_over_v >= 30.0:
        return 20.0, 40.0
    return 5.0 + 0.5 * l_over_v, 17.5 + 0.75 * l_over_v


@dataclass
class Criteria:
    """The criteria table (a DataFrame: criterion, manoeuvre, value, limit, unit, margin, passed),
    the conditions they were judged at, and the manoeuvre results behind them."""

    table: pd.DataFrame
    conditions: dict
    runs: dict = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)

    @property
    def passed(self) -> bool:
        """Whether every criterion that could be judged is met."""
        judged = self.table["passed"].dropna()
        return bool(len(judged)) and bool(judged.all())

    def verdict(self) -> str:
        """One line: met, NOT met, or not judged where no manoeuvre gave its value (a model of
        full-scale logs run over a 7 m ship's times never turned far enough, and "NOT all
        criteria met" was said of it)."""
        judged, total = int(self.table["passed"].notna().sum()), len(self.table)
        if not judged:
            return "no criterion judged: no manoeuvre gave its value (see the warnings)"
        if not self.passed:
            return "NOT all criteria met"
        return "all criteria met" if judged == total else \
            f"all criteria judged met; {total - judged} of {total} gave no value"  # fmt: skip

    def to_dict(self) -> dict:
        """The criteria as JSON-ready data (``criteria --json``)."""
        return {"conditions": self.conditions, "passed": self.passed, "notes": self.notes,
                "criteria": self.table.to_dict(orient="records")}  # fmt: skip


def _row(name, manoeuvre, value, limit, unit) -> dict:
    ok = None if value is None or not math.isfinite(value) else bool(value <= limit)
    margin = None if ok is None else float(limit - value)
    return {"criterion": name, "manoeuvre": manoeuvre,
            "value": None if value is None or not math.isfinite(value) else float(value),
            "limit": float(limit), "unit": unit, "margin": margin, "passed": ok}  # fmt: skip


def imo_criteria(
    ship: Vessel | ManoeuvringModel | HybridModel,
    particulars: Particulars | None = None,
    length: float | None = None,
    speed: float | None = None,
    scale: float | None = None,
    rps: float | None = None,
    steering: SteeringMachine | None = None,
    astern_rps: float | None = None,
    dt: float = 0.05,
    method: str = "rk4",
    steady_window: float | None = None,
) -> Criteria:
    """Run the IMO standard manoeuvres on ``ship`` and judge them against MSC.137(76).

    ``length`` (Lpp [m]) and ``scale`` default to the particulars' (or the reference ship's;
    the scale, if none is known, to 1 with a note);
    ``speed`` to the ship's approach speed or the particulars' design speed; ``rps`` is the
    propeller speed of models with propeller terms (also the stopping test's approach).
    ``steady_window``: the seconds over which a model's approach is judged steady (default
    ``STEADY_WINDOW``; a model carried to another scale, √λ times its original's).
    """
    vessel_length = getattr(ship, "length", math.nan)
    L = length or (particulars.length if particulars else None) or (
        vessel_length if math.isfinite(vessel_length) else None)  # fmt: skip
    if not L or not (math.isfinite(L) and L > 0):
        raise ShipidError("the IMO criteria are in ship lengths: give the length (--length, or "
                          "particulars with the length)")  # fmt: skip
    lam = next((float(x) for x in (scale, particulars.scale if particulars else None,
                                   getattr(ship, "scale", None))
                if x is not None and math.isfinite(x) and x > 0), None)  # fmt: skip
    scale_note = None
    if lam is None:
        # Judged as full scale: a model basin's ship at λ = 1 meets the limits of a ship whose
        # L/V is √λ times shorter, with a rudder √λ times slower (the KVLCC2's 7 m model: the
        # 10/10 limits 10° and 25° instead of 20° and 40°).
        lam = 1.0
        scale_note = ("the scale λ is not known (no --scale, none in the particulars or the "
                      "training logs): judged as a full-scale ship, λ = 1; give the scale for a "
                      "model-scale ship")  # fmt: skip
    V = speed or getattr(ship, "approach_speed", None) or (
        particulars.design_speed if particulars else None)  # fmt: skip
    if not V or not V > 0:
        raise ShipidError("the IMO criteria need the test speed (--speed or the particulars' "
                          "design_speed)")  # fmt: skip
    if steering is None:
        # A reference ship has its own steering gear; a model gets the SOLAS rate at its scale.
        steering = getattr(ship, "steering", None) or SteeringMachine(
            math.radians(particulars.largest_rudder_deg if particulars else 35.0),
            math.radians(SOLAS_RUDDER_RATE_DEG * math.sqrt(lam)))  # fmt: skip
    l_over_v = L / V * math.sqrt(lam)
    first_lim, second_lim = overshoot_limits(l_over_v)
    # Long enough for any plausible ship: a turn reaches 180° within ~15 L/V, a zig-zag's second
    # overshoot within ~20 L/V (model-scale times).
    duration = max(60.0, 40.0 * L / V)
    kw = {"dt": dt, "speed": V, "steering": steering, "method": method, "rps": rps}
    rows, runs, notes = [], {}, [scale_note] if scale_note else []
    if isinstance(ship, ManoeuvringModel | HybridModel):  # a reference ship's is trimmed
        unsteady = unsteady_warning(ship, V, rps if ship.uses_rps else None,
                                    steady_window or STEADY_WINDOW)  # fmt: skip
        notes += [unsteady] if unsteady else []

    # 35°, or the largest rudder the gear allows (MSC.137(76) §4.2: the maximum rudder angle
    # permissible at the test speed; the tanker's is 10°, and `criteria tanker` stopped on it).
    turn_deg = steering.capped_deg(35.0)
    if turn_deg < 35.0:
        notes.append(f"the steering gear's largest rudder is {turn_deg:g}°: the turning circles "
                     "are run with it, the maximum rudder angle the standard allows for")
    for side in SIDES:
        res = turning_circle(ship, turn_deg, side=side, duration=duration, **kw)
        runs[f"turning {turn_deg:g}° {side}"] = res
        if res.diverged:
            notes.append(f"turning circle {turn_deg:g}° to {side}: {res.reason}")
        ind = res.indices
        rows.append(_row("advance", f"turning {turn_deg:g}° {side}", _in_l(ind.get("advance"), L),
                         4.5, "L"))  # fmt: skip
        rows.append(_row("tactical diameter", f"turning {turn_deg:g}° {side}",
                         _in_l(ind.get("tactical_diameter"), L), 5.0, "L"))  # fmt: skip
    for side in SIDES:
        res = zigzag(ship, 10.0, 10.0, first=side, duration=duration, **kw)
        runs[f"zigzag 10/10 {side}"] = res
        ind = res.indices
        rows.append(_row("initial turning (distance at 10° heading change)", f"zigzag 10/10 {side}",
                         _in_l(ind.get("distance_to_second_execute"), L), 2.5, "L"))  # fmt: skip
        rows.append(_row("10/10 first overshoot", f"zigzag 10/10 {side}",
                         ind.get("first_overshoot_deg"), first_lim, "deg"))  # fmt: skip
        rows.append(_row("10/10 second overshoot", f"zigzag 10/10 {side}",
                         ind.get("second_overshoot_deg"), second_lim, "deg"))  # fmt: skip
    for side in SIDES if turn_deg >= 20.0 else ():
        res = zigzag(ship, 20.0, 20.0, first=side, duration=duration, **kw)
        runs[f"zigzag 20/20 {side}"] = res
        rows.append(_row("20/20 first overshoot", f"zigzag 20/20 {side}",
                         res.indices.get("first_overshoot_deg"), 25.0, "deg"))  # fmt: skip
    if turn_deg < 20.0:
        notes.append(f"20/20 first overshoot not judged: the gear's {turn_deg:g}° cannot run a "
                     "20°/20° zig-zag")
    dyn = getattr(ship, "dynamics", ship)
    if getattr(dyn, "uses_rps", False) and rps and not getattr(dyn, "propeller_ahead_only", False):
        res = stopping(ship, rps, astern_rps, reversal_time=10.0 / math.sqrt(lam),
                       duration=3 * duration, dt=dt, speed=V, method=method)  # fmt: skip
        runs["full astern"] = res  # keyed as its row's manoeuvre
        row = _row("stopping track reach", "full astern", _in_l(res.indices["track_reach"], L),
                   15.0, "L")
        astern = astern_thrust_note(ship, V, rps, astern_rps)
        if astern and astern.kind == "coasting":
            # Coasting reaches further than braking: a pass holds for the ship, a fail decides
            # nothing.
            if row["passed"] is False:
                row["passed"] = row["margin"] = None
            notes.append(f"stopping ability: {astern.note}; its track reach is an upper bound: "
                         "a pass holds, a fail is not judged")  # fmt: skip
        elif astern:
            notes.append(f"stopping ability: {astern.note}")
        rows.append(row)
    else:
        # A reference ship's own physics may run a propeller, at the one speed it was set to
        # (the KVLCC2's MMG model): it takes no order to reverse it.
        name = getattr(ship, "name", "the ship")
        what = ("the model has no propeller-speed terms"
                if isinstance(ship, (ManoeuvringModel, HybridModel))
                else f"{name}'s MMG model has a propeller turning ahead only"
                if getattr(dyn, "propeller_ahead_only", False) and getattr(dyn, "uses_rps", False)
                else f"{name}'s dynamics take no propeller-speed order")  # fmt: skip
        notes.append(f"stopping ability not judged: {what}, so no full astern can be run")
    conditions = {"length": L, "speed": V, "scale": lam, "L_over_V_full_scale": l_over_v,
                  "rudder_rate_deg_s": (math.degrees(steering.max_rate) if steering.max_rate
                                        else None),
                  "rps": rps}  # fmt: skip
    return Criteria(pd.DataFrame(rows), conditions, runs, notes)


def with_intervals(criteria: Criteria, replicates: Sequence[Criteria], level: float = 0.95
                   ) -> pd.DataFrame:  # fmt: skip
    """The criteria table with, per row, the percentile interval of the value over bootstrap
    replicates of the model (``lower``, ``upper``) and the share of replicates that pass
    (``pass_share``): how sure the verdict is."""
    from shipid.identification.uncertainty import interval

    table = criteria.table.copy()
    values = np.array([[np.nan if v is None else v for v in c.table["value"]] for c in replicates],
                      dtype=float)  # fmt: skip
    passed = np.array([[p is True for p in c.table["passed"]] for c in replicates])
    bounds = [interval(values[:, i], level) for i in range(len(table))]
    table["lower"] = [b[0] for b in bounds]
    table["upper"] = [b[1] for b in bounds]
    table["pass_share"] = passed.mean(axis=0)
    table["no_value"] = np.isnan(values).sum(axis=0)
    return table


def replicate_notes(table: pd.DataFrame, replicates: Sequence[Criteria], label: str) -> list[str]:
    """What the intervals of ``with_intervals``' ``table`` leave unsaid: for each criterion some
    replicates have no value for, how many and why (diverged, or the event never reached; a share
    above the tail leaves the interval not bounded), and the criteria whose verdict the
    replicates split on (between 5 % and 95 % of them pass)."""
    notes = []
    n = len(replicates)
    for i, row in table.iterrows():
        if not row["no_value"]:
            continue
        runs = [c.runs.get(row["manoeuvre"]) for c in replicates]
        _, text = without_value(runs, [c.table["value"].iloc[i] for c in replicates])
        notes.append(f"{row['criterion']}, {row['manoeuvre']}: {int(row['no_value'])} of {n} "
                     f"{label} have no value ({text})")  # fmt: skip
    split = table[(table["pass_share"] > 0.05) & (table["pass_share"] < 0.95)]
    if len(split):
        rows = ", ".join(f"{r.criterion} ({r.manoeuvre}) {r.pass_share:.0%}"
                         for r in split.itertuples())  # fmt: skip
        notes.append(f"the {label} disagree on the verdict of {len(split)} criteria (share that "
                     f"passes): {rows}")  # fmt: skip
    return notes


def _in_l(value, L: float) -> float | None:
    return None if value is None else value / L


def measured_criteria(indices: dict, rudder_deg: float, switch_deg: float | None, L: float,
                      V: float, scale: float = 1.0) -> list[dict]:  # fmt: skip
    """The criteria a measured (or simulated) standard manoeuvre speaks to: a 35° turning circle,
    a 10°/10° or a 20°/20° zig-zag (angles within 1.5°). ``indices`` as from ``manoeuvre_indices``."""
    kind = indices.get("kind")
    rows = []
    near = lambda a, b: a is not None and abs(a - b) <= 1.5  # noqa: E731
    if kind in TURN_KINDS and near(rudder_deg, 35.0):  # a pull-out's turn before its release
        rows.append(_row("advance", "turning 35°", _in_l(indices.get("advance"), L), 4.5, "L"))
        rows.append(_row("tactical diameter", "turning 35°",
                         _in_l(indices.get("tactical_diameter"), L), 5.0, "L"))  # fmt: skip
    if kind == "zigzag" and near(rudder_deg, 10.0) and near(switch_deg, 10.0):
        first, second = overshoot_limits(L / V * math.sqrt(scale))
        rows.append(_row("initial turning (distance at 10° heading change)", "zigzag 10/10",
                         _in_l(indices.get("distance_to_second_execute"), L), 2.5, "L"))  # fmt: skip
        rows.append(_row("10/10 first overshoot", "zigzag 10/10",
                         indices.get("first_overshoot_deg"), first, "deg"))  # fmt: skip
        rows.append(_row("10/10 second overshoot", "zigzag 10/10",
                         indices.get("second_overshoot_deg"), second, "deg"))  # fmt: skip
    if kind == "zigzag" and near(rudder_deg, 20.0) and near(switch_deg, 20.0):
        rows.append(_row("20/20 first overshoot", "zigzag 20/20",
                         indices.get("first_overshoot_deg"), 25.0, "deg"))  # fmt: skip
    return rows

"""The training envelope of a model and the checks of a run against it.

A model identified from trials is only known where the trials went: the ranges of speed, sway,
yaw rate, rudder, propeller speed and wind of its training logs. A run (a manoeuvre, a free run) that
leaves them is an extrapolation, and one that ends in an implausible state (a ship that stops in a
turn, a tactical diameter under one ship length) is reported; neither is refused.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from shipid.data.log import column_values

ENVELOPE_SIGNALS = ("u", "v", "r", "delta", "n", "wind_speed")
UNITS = {"u": "m/s", "v": "m/s", "r": "rad/s", "delta": "rad", "n": "rps", "wind_speed": "m/s"}
# A run may exceed the training range by this fraction of its span, and at least this fraction
# of the range's magnitude, before it is reported: a signal held constant in training (the
# KVLCC2's 10.23 rps at HSVA) has no span, and MARIN's 10.33 rps was called an extrapolation.
# Every signal counts, those the model has no term in too: a model without propeller terms
# holds its training rps in its constant.
MARGIN = 0.1
MAGNITUDE_MARGIN = 0.05
# A turn that keeps less than this fraction of its approach speed has left any plausible regime.
MIN_SPEED_FRACTION = 0.2
# A log's propeller speed this many times the training logs' largest reads as rpm where the model
# has rps (60× at the same speed; 20× would be a propeller twenty times faster than any trained on).
RPM_RATIO = (20.0, 200.0)


def envelope(logs: Sequence[pd.DataFrame]) -> dict[str, list[float]]:
    """{signal: [min, max]} over the training logs, for the signals they have."""
    out = {}
    for s in ENVELOPE_SIGNALS:
        values = [column_values(log, s) for log in logs if s in log.columns]
        if values:
            allv = np.concatenate(values)
            out[s] = [float(np.min(allv)), float(np.max(allv))]
    return out


def allowed_ranges(env: Mapping[str, Sequence[float]]) -> dict[str, tuple[float, float, float]]:
    """{signal: (low, high, margin)}: the training range and how far beyond it, either side, a
    run's signal may go before it leaves the envelope (``MARGIN`` of the range's span, and at
    least ``MAGNITUDE_MARGIN`` of its magnitude)."""
    out = {}
    for s, bounds in (env or {}).items():
        if len(bounds) != 2:
            continue
        lo, hi = (float(b) for b in bounds)
        margin = max(MARGIN * (hi - lo), MAGNITUDE_MARGIN * max(abs(lo), abs(hi)), 1e-12)
        out[s] = (lo, hi, margin)
    return out


def outside_envelope(env: Mapping[str, Sequence[float]], log: pd.DataFrame) -> list[str]:
    """One message per signal of ``log`` that leaves the envelope by more than ``MARGIN``."""
    notes = []
    for s, (lo, hi, margin) in allowed_ranges(env).items():
        if s not in log.columns:
            continue
        x = column_values(log, s)
        if x.size == 0:
            continue
        xmin, xmax = float(np.min(x)), float(np.max(x))
        if xmin < lo - margin or xmax > hi + margin:
            unit = UNITS.get(s, "")
            notes.append(f"{s} spans {xmin:.3g}…{xmax:.3g} {unit}, outside the training range "
                         f"{lo:.3g}…{hi:.3g} {unit}: the model is extrapolating"
                         + (_rpm_hint(x, lo, hi) if s == "n" else ""))  # fmt: skip
    return notes


# The kinds of manoeuvre a model's prediction of one kind is carried from: a pull-out is a turn
# released, so the two count as one.
KIND_GROUPS = {"zigzag": ("zigzag",), "turning": ("turning", "pull-out"),
               "pull-out": ("turning", "pull-out")}  # fmt: skip
KIND_NAMES = {"zigzag": "zig-zag", "turning": "turning circle or pull-out",
              "pull-out": "turning circle or pull-out"}  # fmt: skip


def unseen_kind_note(trained: Sequence[str] | None, kind: str | None) -> str | None:
    """A note where a manoeuvre of ``kind`` is predicted by a model none of whose training logs
    (their kinds, ``trained``: the model file's ``preprocessing.manoeuvres``) is of that kind;
    None where one is, for other kinds, or for a file that does not record them. The envelope
    says where a run's signals leave the logs; a turn predicted from zig-zags can stay inside
    every signal's range and still be an extrapolation, its steady turn and its first 90° lying
    in no log (on the Esso Osaka, the intervals of such a model held its turns' advances in a
    quarter of the cases, docs/esso.md)."""
    trained = [k for k in trained or () if k]
    if not trained or kind not in KIND_GROUPS:
        return None
    if any(k in KIND_GROUPS[kind] for k in trained):
        return None
    counts = {k: list(trained).count(k) for k in dict.fromkeys(trained)}
    read = ", ".join(f"{n} {KIND_NAMES.get(k, k) if k != 'other' else 'other'}" for k, n in
                     counts.items())  # fmt: skip
    return (f"none of the model's {len(trained)} training logs is a {KIND_NAMES[kind]} (they "
            f"read as {read}): its {KIND_NAMES[kind].split(' or ')[0]} is carried from "
            "manoeuvres of other kinds, which its intervals, where it has them, do not hold "
            "(they come from those logs alone); a log of this kind among the training logs "
            "decides")


def signals_outside(env: Mapping[str, Sequence[float]], log: pd.DataFrame) -> list[str]:
    """The signals of ``log`` that leave the envelope (``outside_envelope``'s, by name)."""
    return [note.split(" ", 1)[0] for note in outside_envelope(env, log)]


def _rpm_hint(n: np.ndarray, lo: float, hi: float) -> str:
    """A hint when the log's propeller speed looks like the training logs' in rpm."""
    trained = max(abs(lo), abs(hi))
    ratio = float(np.max(np.abs(n))) / trained if trained > 0 else 0.0
    if not RPM_RATIO[0] <= ratio <= RPM_RATIO[1]:
        return ""
    return (f" (it is {ratio:.0f} times the training logs' largest: in rpm? a header 'n [rpm]' "
            "reads it as rps)")


def implausible_indices(indices: Mapping, approach_speed: float | None,
                        length: float | None = None, log: pd.DataFrame | None = None
                        ) -> list[str]:  # fmt: skip
    """Messages for turning indices no ship shows: the speed nearly lost, a circle under 1 L, a
    turn entered ahead that ends going astern (``log``: the run; the indices' steady speed is a
    magnitude, and read +0.74 m/s for an Esso fit that ended its turn at −0.74 m/s)."""
    notes = []
    if log is not None and approach_speed and approach_speed > 0 and len(log):
        end = float(np.mean(column_values(log, "u")[-max(1, len(log) // 10):]))
        if end < 0:
            notes.append(f"the ship ends the turn going astern (u = {end:.3g} m/s, entered at "
                         f"{approach_speed:.3g} m/s ahead, the propeller unchanged): implausible")
    speed = indices.get("steady_speed")
    if speed is not None and approach_speed and math.isfinite(speed) \
            and speed < MIN_SPEED_FRACTION * approach_speed:
        notes.append(f"steady turning speed {speed:.3g} m/s is under {MIN_SPEED_FRACTION:.0%} of "
                     f"the approach speed {approach_speed:.3g} m/s: implausible")
    td = indices.get("tactical_diameter")
    if length and td is not None and math.isfinite(td) and td < length:
        notes.append(f"tactical diameter {td:.3g} m is under one ship length ({length:.3g} m): "
                     "implausible")
    return notes

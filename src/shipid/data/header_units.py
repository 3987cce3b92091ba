"""Units a CSV header states in brackets (``"r [deg/s]"``), read rather than dropped.

A header that says its yaw rate is in °/s is a statement about the data: dropping it read the
column as rad/s, 57 times too large, and where no heading is logged to check r against and the
values stay under the plausibility limits (a large ship turning at 0.5 °/s) nothing said so.
Canonical columns in a unit shipid knows are converted to SI (angles to radians, rpm to rps,
knots to m/s); a unit it does not know stops the read with the column and the unit named. Other
columns' units stay documentation.
"""

from __future__ import annotations

import math
import re
from collections.abc import Iterable, Mapping

from shipid.errors import ShipidError

UNIT = re.compile(r"\s*\[([^\]]*)\]\s*$")

_DEG = math.pi / 180.0
_ANGLE = {"rad": 1.0, "deg": _DEG, "degree": _DEG, "degrees": _DEG, "°": _DEG}
_RATE = {"rad/s": 1.0, "1/s": 1.0, "deg/s": _DEG, "degree/s": _DEG, "degrees/s": _DEG,
         "°/s": _DEG}  # fmt: skip
_SPEED = {"m/s": 1.0, "kn": 1852.0 / 3600.0, "kt": 1852.0 / 3600.0, "knot": 1852.0 / 3600.0,
          "knots": 1852.0 / 3600.0, "km/h": 1.0 / 3.6}  # fmt: skip
# Factor to SI per unit, for each canonical column ("" and "-": no unit stated).
FACTORS: dict[str, dict[str, float]] = {
    "t": {"s": 1.0, "sec": 1.0, "ms": 1e-3},
    "delta": _ANGLE, "psi": _ANGLE, "wind_angle": _ANGLE,
    "r": _RATE,
    "u": _SPEED, "v": _SPEED, "wind_speed": _SPEED,
    "x": {"m": 1.0}, "y": {"m": 1.0},
    "n": {"rps": 1.0, "1/s": 1.0, "hz": 1.0, "rev/s": 1.0, "rpm": 1.0 / 60.0, "rev/min": 1.0 / 60.0},
    "thrust": {"n": 1.0, "kn": 1e3},
    # A GNSS's speed and course over ground (``shipid.data.track_velocities``).
    "sog": _SPEED, "cog": _ANGLE,
    # A GNSS's latitude and longitude are read in degrees (``shipid.data.geodetic``), not SI.
    "lat": {"deg": 1.0, "degree": 1.0, "degrees": 1.0, "°": 1.0, "rad": 1.0 / _DEG},
    "lon": {"deg": 1.0, "degree": 1.0, "degrees": 1.0, "°": 1.0, "rad": 1.0 / _DEG},
}


def split_units(names: Iterable[object]) -> tuple[list[str], dict[str, str]]:
    """Column names without their bracketed units, and name → unit as written."""
    bare, units = [], {}
    for raw in names:
        text = str(raw)
        m = UNIT.search(text)
        name = (UNIT.sub("", text) if m else text).strip()
        bare.append(name)
        if m:
            units[name] = m.group(1).strip()
    return bare, units


def _key(unit: str) -> str:
    return unit.replace(" ", "").lower()


def si_factors(units: Mapping[str, str], renames: Mapping[str, str], degrees: Iterable[str],
               path: str) -> dict[str, float]:  # fmt: skip
    """Canonical column → factor to SI from the header's units (after ``--columns`` renames),
    1 omitted. A column named in ``--degrees`` must not state another unit; its degrees are
    ``--degrees``' to convert."""
    degrees = set(degrees)
    out = {}
    for name, unit in units.items():
        column = renames.get(name, name)
        known = FACTORS.get(column)
        if known is None or _key(unit) in ("", "-"):
            continue
        factor = known.get(_key(unit))
        if factor is None:
            raise ShipidError(f"{path}: column {column!r} is in {unit!r} by its header, which "
                              f"shipid does not convert (it reads {', '.join(sorted(known))}); "
                              "convert the column, or drop the unit from its name")  # fmt: skip
        if column in degrees:
            if factor == 1.0:
                raise ShipidError(f"{path}: --degrees names {column!r}, but its header says "
                                  f"{unit!r}")  # fmt: skip
            continue  # --degrees converts it
        if factor != 1.0:
            out[column] = factor
    return out

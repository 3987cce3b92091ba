"""Ship particulars: what the IMO criteria, the prime system and physical priors need.

A small file (YAML or JSON) or options. Keys (SI units; aliases of common files in brackets)::

    length        Lpp [m]                         (L, Lpp, lpp)
    beam          B [m]                           (B)
    draught       T, mean [m]                     (T, draft)
    block_coefficient  Cb [-]                     (CB, Cb)
    mass          m [kg]                          (m, displacement_mass)
    rudder_area   A_R [m²]                        (A_R, AR)
    rudder_height  H_R, the rudder's span [m]     (H_R, HR)
    propeller_diameter  D [m]                     (D, Dp)
    scale         λ = ship length / model length (scale_factor; none: not known, where the
                  criteria read the model's training logs' scale, else full scale)
    design_speed  approach speed of the trials [m/s]   (U0, speed)
    rho           water density [kg/m³]           (default 1025; the MARIN file gives 1000)
    xg            longitudinal centre of gravity from midship [m]   (x_G)
    rudder_limit  the steering gear's largest rudder angle [deg], where it stops short of the
                  35° the plausibility checks hold (the tanker's 10°)   (max_rudder)

Only ``length`` is required (it turns indices into ship lengths); the rest is used where present.
The MARIN ``ship_data.yml`` of the KVLCC2 reads as is. Particulars travel in log metadata and model
files (``to_dict``/``from_mapping``).
"""

from __future__ import annotations

import dataclasses
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

from shipid.errors import ShipidError

ALIASES = {
    "length": ("length", "L", "Lpp", "lpp", "LPP"),
    "beam": ("beam", "B"),
    "draught": ("draught", "T", "draft"),
    "block_coefficient": ("block_coefficient", "CB", "Cb", "cb"),
    "mass": ("mass", "m", "displacement_mass"),
    "rudder_area": ("rudder_area", "A_R", "AR"),
    "rudder_height": ("rudder_height", "H_R", "HR"),
    "propeller_diameter": ("propeller_diameter", "D", "Dp"),
    "scale": ("scale", "scale_factor"),
    "design_speed": ("design_speed", "U0", "speed"),
    "rho": ("rho",),
    "xg": ("xg", "x_G"),
    "rudder_limit": ("rudder_limit", "max_rudder"),
}
# The largest rudder the standard manoeuvres and the plausibility checks hold [deg].
STANDARD_RUDDER_DEG = 35.0


def largest_rudder_deg(rudder_limit: float | None) -> float:
    """The largest rudder a standard manoeuvre holds [deg]: 35° (MSC.137(76)), or a steering
    gear's ``rudder_limit`` where it stops short of it (None: no limit given)."""
    return STANDARD_RUDDER_DEG if rudder_limit is None else min(STANDARD_RUDDER_DEG,
                                                                float(rudder_limit))
POSITIVE = ("length", "beam", "draught", "block_coefficient", "mass", "rudder_area",
            "rudder_height", "propeller_diameter", "scale", "design_speed", "rho",
            "rudder_limit")  # fmt: skip


@dataclass(frozen=True)
class Particulars:
    """Main particulars of a ship or model (SI units); see the module docstring."""

    length: float
    beam: float | None = None
    draught: float | None = None
    block_coefficient: float | None = None
    mass: float | None = None
    rudder_area: float | None = None
    rudder_height: float | None = None
    propeller_diameter: float | None = None
    scale: float | None = None  # unknown: not full scale (λ = 1), which it would claim
    design_speed: float | None = None
    rho: float = 1025.0
    xg: float = 0.0
    rudder_limit: float | None = None  # [deg]

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if value is None:
                continue
            if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
                raise ShipidError(f"particulars: {f.name} must be a finite number, got {value!r}")
            if f.name in POSITIVE and not value > 0:
                raise ShipidError(f"particulars: {f.name} must be > 0, got {value!r}")
        cb = self.block_coefficient
        if cb is not None and cb > 1.0:
            raise ShipidError(f"particulars: block_coefficient {cb:g} > 1 is impossible")
        if self.draught is not None and self.beam is not None and self.draught > self.beam:
            raise ShipidError(f"particulars: draught {self.draught:g} m > beam {self.beam:g} m "
                              "(inconsistent: beam and draught swapped?)")  # fmt: skip
        if self.beam is not None and self.beam > self.length:
            raise ShipidError(f"particulars: beam {self.beam:g} m > length {self.length:g} m")
        if self.rudder_limit is not None and not self.rudder_limit <= 90.0:
            raise ShipidError(f"particulars: rudder_limit {self.rudder_limit:g}° is beyond 90° "
                              "(it is in degrees)")  # fmt: skip
        if abs(self.xg) > 0.5 * self.length:
            raise ShipidError(f"particulars: xg {self.xg:g} m is outside the hull "
                              f"(|xg| ≤ L/2 = {0.5 * self.length:g} m)")  # fmt: skip
        if None not in (self.mass, self.beam, self.draught, self.block_coefficient):
            implied = self.rho * self.block_coefficient * self.length * self.beam * self.draught
            if not 0.8 <= self.mass / implied <= 1.25:
                raise ShipidError(f"particulars: mass {self.mass:g} kg is inconsistent with "
                                  f"ρ·Cb·L·B·T = {implied:.4g} kg (more than 25 % apart)")

    @property
    def largest_rudder_deg(self) -> float:
        """``largest_rudder_deg`` of this ship's ``rudder_limit``."""
        return largest_rudder_deg(self.rudder_limit)

    @property
    def volume(self) -> float | None:
        """Displaced volume [m³] from the mass, else from Cb·L·B·T (None if unknown)."""
        if self.mass is not None:
            return self.mass / self.rho
        if None not in (self.beam, self.draught, self.block_coefficient):
            return self.block_coefficient * self.length * self.beam * self.draught
        return None

    def to_dict(self) -> dict:
        """The particulars that are set, as a plain mapping (for JSON and metadata)."""
        return {k: v for k, v in dataclasses.asdict(self).items() if v is not None}

    def scaled(self, speed: float | None = None) -> dict:
        """The prime-system scales: length L and speed U (``speed`` or the design speed)."""
        U = speed if speed is not None else self.design_speed
        if U is None or not U > 0:
            raise ShipidError("the prime system needs a reference speed: give design_speed in "
                              "the particulars (or --speed)")  # fmt: skip
        return {"L": self.length, "U": float(U)}

    @classmethod
    def from_mapping(cls, data: Mapping, where: str = "particulars") -> Particulars:
        if not isinstance(data, Mapping):
            raise ShipidError(f"{where}: particulars must be a mapping of names to numbers")
        values = {}
        for name, aliases in ALIASES.items():
            found = [a for a in aliases if a in data]
            if len(found) > 1 and len({str(data[a]) for a in found}) > 1:
                raise ShipidError(f"{where}: {name} is given twice ({', '.join(found)})")
            if found:
                values[name] = data[found[0]]
        if "length" not in values:
            raise ShipidError(f"{where}: the particulars need the length Lpp (key 'length' or "
                              "'L')")  # fmt: skip
        for k, v in list(values.items()):
            if isinstance(v, str):
                try:
                    values[k] = float(v)
                except ValueError:
                    raise ShipidError(f"{where}: {k} must be a number, got {v!r}") from None
        try:
            return cls(**values)
        except ShipidError as exc:
            raise ShipidError(f"{where}: {str(exc).removeprefix('particulars: ')}") from None


def logs_particulars(logs) -> Particulars | None:
    """The particulars the logs carry (the first that has them: ``--particulars``, which every
    log read is given, or a known format's own), or None."""
    found = next((log.attrs["particulars"] for log in logs if log.attrs.get("particulars")), None)
    return None if found is None else Particulars.from_mapping(found)


# How far a log's rudder may read beyond the gear's ``rudder_limit`` [deg] (its sensor's noise,
# an angle logged at the stock while the gear stops the tiller) before the two disagree.
RUDDER_LIMIT_MARGIN_DEG = 1.0


def rudder_beyond_limit(log, name: str) -> str | None:
    """One line where ``log``'s rudder reaches more than ``RUDDER_LIMIT_MARGIN_DEG`` beyond the
    ``rudder_limit`` of the particulars it carries (the checks and the standard manoeuvres then
    hold a rudder the ship is seen to exceed: a limit or a rudder signal that is wrong), else
    None."""
    found = log.attrs.get("particulars")
    limit = Particulars.from_mapping(found).rudder_limit if found else None
    if limit is None or "delta" not in log.columns:
        return None
    from shipid.data.log import rudder_reach_deg

    reach = rudder_reach_deg([log])
    if not reach > limit + RUDDER_LIMIT_MARGIN_DEG:
        return None
    return (f"{name}: the rudder reaches {reach:.3g}°, beyond the particulars' rudder_limit of "
            f"{limit:g}° (the steering gear's largest), which the plausibility checks and the "
            "standard manoeuvres hold: check the limit, or the rudder signal's units and column "
            "(--degrees, --columns)")


def read_particulars(path: str | Path) -> Particulars:
    """Particulars from a YAML (``key: value`` lines, comments) or JSON file, or those a model
    file keeps (``identify``'s output, where its logs or ``--particulars`` gave them)."""
    path = Path(path)
    if not path.is_file():
        raise ShipidError(f"{path}: no such particulars file")
    text = path.read_text(encoding="utf-8", errors="replace")
    if path.suffix.lower() == ".json":
        from shipid.data.mappings import DuplicateKeyError, duplicate_key_error, load_json

        try:
            data = load_json(text)
        except DuplicateKeyError as exc:
            raise duplicate_key_error(path, exc) from None
        except json.JSONDecodeError as exc:
            raise ShipidError(f"{path}: not a JSON particulars file ({exc})") from None
        if isinstance(data, Mapping) and data.get("format") == "shipid-model":
            if not isinstance(data.get("particulars"), Mapping):
                raise ShipidError(f"{path}: the model file keeps no particulars (its logs gave "
                                  "none: identify with --particulars FILE, or give that file)")
            data = data["particulars"]
    else:
        data = _simple_yaml(text, path)
    particulars = Particulars.from_mapping(data, str(path))
    _warn_near_misses(data, path)
    return particulars


def _warn_near_misses(data: Mapping, path: Path) -> None:
    """A warning per key that is none of ours but close to one (a typo, another case): it is
    ignored, and a ``rudder_limt: 10`` left the checks at 35° without a word. Keys far from all
    of ours are the file's own business (the MARIN file's I_z, x_p, w_p0, TWIN, ...)."""
    import difflib
    import warnings

    from shipid.errors import ShipidWarning

    known = {alias: name for name, aliases in ALIASES.items() for alias in aliases}
    lowered = {alias.lower(): alias for alias in known}
    for key in data:
        if not isinstance(key, str) or key in known:
            continue
        close = difflib.get_close_matches(key.lower(), list(lowered), n=1, cutoff=0.75)
        if close:
            alias = lowered[close[0]]
            meant = alias if alias == known[alias] else f"{alias}, the {known[alias]}"
            warnings.warn(f"{path}: {key!r} is not a particulars key and is ignored: did you "
                          f"mean {meant!r}?", ShipidWarning, stacklevel=3)  # fmt: skip


def _simple_yaml(text: str, path: Path) -> dict:
    import yaml

    from shipid.data.mappings import DuplicateKeyError, duplicate_key_error, load_yaml

    try:
        data = load_yaml(text)
    except DuplicateKeyError as exc:
        raise duplicate_key_error(path, exc) from None
    except yaml.YAMLError as exc:
        raise ShipidError(f"{path}: not a YAML particulars file ({str(exc).splitlines()[0]})") \
            from None
    if not isinstance(data, dict):
        raise ShipidError(f"{path}: particulars must be a YAML mapping of names to numbers")
    return data

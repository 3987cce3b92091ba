"""A ship's own MMG standard-method model (Yasukawa & Yoshimura 2015) from a file of its
coefficients, as a reference ship: what a basin's captive tests give, for ``shipid validate``,
``manoeuvre`` and the other commands that take a ``VESSEL``, and as the reference that
``shipid correct`` keeps whole.

The formula is the built-in KVLCC2's, compiled once for any coefficients
(``shipid.vessels.mmg``, reference-ships.md §2: midship sway velocity, dimensional lever arms,
the wake in drift, flow straightening γ_R that differs with the sign of the drift at the
rudder), the propeller at a constant rps trimmed for the approach speed unless the file gives
it. The file (YAML or JSON)::

    format: shipid-mmg
    name: my-ship
    length: 7.0          # Lpp [m]
    beam: 1.27
    draught: 0.46
    volume: 3.27         # displacement [m³]
    x_g: 0.25            # [m] forward of midship
    k_zz: 0.25           # yaw radius of gyration / Lpp
    rho: 1025
    approach_speed: 1.179
    rudder_rate: 15.8    # [deg/s]; rudder_limit [deg], default 35
    scale: 45.7          # optional
    rps: 11.8            # optional: the propeller's constant rate, else trimmed for the
                         # approach; "logs": each log's measured rate (column n) and a
                         # manoeuvre's --rps (trimmed for the approach where none is given)
    hull: {m_x:, m_y:, j_z:, r0:, x_vv:, x_vr:, x_rr:, x_vvvv:, y_v:, y_r:, y_vvv:, y_vvr:,
           y_vrr:, y_rrr:, n_v:, n_r:, n_vvv:, n_vvr:, n_vrr:, n_rrr:}     # prime
    propeller: {diameter:, t_p:, w_p0:, k0:, k1:, k2:, x_p:, c1:, c2_pos:, c2_neg:}
    rudder: {area:, height:, t_r:, a_h:, x_h:, x_r:, l_r:, epsilon:, kappa:, f_alpha:,
             gamma_r_pos:, gamma_r_neg:}   # x_h, x_r, l_r prime; γ_R for β_R ≥ 0 and < 0

Positive δ turns to starboard.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from pathlib import Path

from shipid.dynamics.steering import SteeringMachine
from shipid.errors import ShipidError

from .mmg import MMGDynamics, trimmed_rps
from .vessel import Vessel

FORMAT = "shipid-mmg"
# ``rps: logs``: the propeller turns at each log's measured rate and at a manoeuvre's --rps.
FOLLOW = "logs"
TOP = ("length", "beam", "draught", "volume", "x_g", "k_zz", "rho", "approach_speed",
       "rudder_rate")  # fmt: skip
HULL = ("m_x", "m_y", "j_z", "r0", "x_vv", "x_vr", "x_rr", "x_vvvv", "y_v", "y_r", "y_vvv",
        "y_vvr", "y_vrr", "y_rrr", "n_v", "n_r", "n_vvv", "n_vvr", "n_vrr", "n_rrr")  # fmt: skip
PROPELLER = ("diameter", "t_p", "w_p0", "k0", "k1", "k2", "x_p", "c1", "c2_pos", "c2_neg")
RUDDER = ("area", "height", "t_r", "a_h", "x_h", "x_r", "l_r", "epsilon", "kappa", "f_alpha",
          "gamma_r_pos", "gamma_r_neg")  # fmt: skip
POSITIVE = ("length", "beam", "draught", "volume", "rho", "approach_speed", "rudder_rate",
            "k_zz", "diameter", "area", "height")  # fmt: skip


def _number(value, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float) or not math.isfinite(value):
        raise ShipidError(f"{where} must be a finite number, got {value!r}")
    return float(value)


def coefficients(doc: Mapping, where: str = "MMG file") -> dict:
    """The flat, checked coefficients of an MMG document (one-line errors naming the field)."""
    if not isinstance(doc, Mapping) or doc.get("format") != FORMAT:
        raise ShipidError(f"{where}: not an MMG model file (no \"format\": \"{FORMAT}\")")
    out: dict = {"name": str(doc.get("name") or "mmg")}
    for key in TOP:
        if key not in doc:
            raise ShipidError(f"{where}: missing field {key!r}")
        out[key] = _number(doc[key], f"{where}: {key}")
    for group, keys in (("hull", HULL), ("propeller", PROPELLER), ("rudder", RUDDER)):
        section = doc.get(group)
        if not isinstance(section, Mapping):
            raise ShipidError(f"{where}: missing section {group!r} ({', '.join(keys)})")
        for key in keys:
            if key not in section:
                raise ShipidError(f"{where}: missing field {group}.{key}")
            out[f"{group}.{key}"] = _number(section[key], f"{where}: {group}.{key}")
    for key in POSITIVE:
        full = key if key in out else next(k for k in out if k.endswith("." + key))
        if not out[full] > 0:
            raise ShipidError(f"{where}: {full} must be > 0, got {out[full]:g}")
    out["rudder_limit"] = _number(doc.get("rudder_limit", 35.0), f"{where}: rudder_limit")
    out["scale"] = _number(doc["scale"], f"{where}: scale") if "scale" in doc else math.nan
    rps = doc.get("rps")
    out["follow_rps"] = rps == FOLLOW
    out["rps"] = _number(rps, f"{where}: rps (a number, or \"{FOLLOW}\")") \
        if rps is not None and rps != FOLLOW else None  # fmt: skip
    if out["rps"] is not None and not out["rps"] > 0:
        raise ShipidError(f"{where}: rps must be > 0, got {out['rps']:g}")
    return out


def mmg_vessel(doc: Mapping, where: str = "MMG file") -> Vessel:
    """The reference ship of an MMG document (``coefficients``)."""
    c = coefficients(doc, where)
    n = c["rps"] if c["rps"] is not None else trimmed_rps(c, c["approach_speed"])
    dynamics = MMGDynamics(c, n, follow_rps=c["follow_rps"])
    return Vessel(name=c["name"], dynamics=dynamics, length=c["length"],
                  approach_speed=c["approach_speed"],
                  steering=SteeringMachine(math.radians(c["rudder_limit"]),
                                           math.radians(c["rudder_rate"])),
                  rudder_positive="starboard", scale=c["scale"],
                  source=f"MMG standard method, {where}")  # fmt: skip


def document_of(c: Mapping) -> dict:
    """The MMG file's document of flat coefficients ``c`` (``coefficients``' form)."""
    doc: dict = {"format": FORMAT, "name": c.get("name", "mmg")}
    for key in TOP:
        doc[key] = c[key]
    for key in ("rudder_limit", "scale"):
        if key in c and math.isfinite(c[key]):
            doc[key] = c[key]
    doc["rps"] = FOLLOW if c.get("follow_rps") else c.get("rps")
    for group, keys in (("hull", HULL), ("propeller", PROPELLER), ("rudder", RUDDER)):
        doc[group] = {k: c[f"{group}.{k}"] for k in keys}
    return doc


def sister_ship(source: Mapping, particulars, name: str, speed: float | None = None,
         rps: float | str | None = None, rudder_rate: float | None = None
         ) -> tuple[dict, list[str]]:  # fmt: skip
    """An MMG file of a ship that has no model of its own, from a similar ship's: the
    ``source``'s prime coefficients (flat, ``coefficients``' form: hull, propeller and rudder)
    with the ship's ``particulars`` (``shipid.data.particulars.Particulars``: length, beam,
    draught and mass needed; the propeller's diameter, the rudder's area and height where given,
    else the source's scaled by length, the rudder's height by the source's aspect ratio for
    the given area). The approach ``speed`` (else the particulars' design speed, else the
    source's at equal Froude number), ``rps`` (a number, "logs", or None: trimmed) and
    ``rudder_rate`` [deg/s] (else the source's at equal Froude number); the rudder's limit the
    particulars' ``rudder_limit`` where given, else the source's. Returns the document and
    notes saying what was scaled rather than given. The prime coefficients hold for the ship as
    far as the hulls are alike: the notes set both hulls' form side by side."""
    missing = [k for k in ("beam", "draught", "mass") if getattr(particulars, k) is None]
    if missing:
        raise ShipidError(f"particulars: an MMG model needs {', '.join(missing)} too")
    ratio = particulars.length / source["length"]
    froude = math.sqrt(ratio)
    notes = []

    def given_or_scaled(value, scaled: float, what: str) -> float:
        if value is not None:
            return float(value)
        notes.append(f"{what}: {scaled:.4g}, the source's scaled by length (not in the particulars)")
        return scaled

    diameter = given_or_scaled(particulars.propeller_diameter,
                               source["propeller.diameter"] * ratio, "propeller diameter")
    area = given_or_scaled(particulars.rudder_area, source["rudder.area"] * ratio**2,
                           "rudder area")  # fmt: skip
    if particulars.rudder_height is not None:
        height = float(particulars.rudder_height)
    else:
        height = math.sqrt(source["rudder.height"] ** 2 / source["rudder.area"] * area)
        notes.append(f"rudder height: {height:.4g} m, for the given area at the source's aspect "
                     "ratio (not in the particulars)")  # fmt: skip
    if speed is None and particulars.design_speed is not None:
        speed = particulars.design_speed
    if speed is None:
        speed = source["approach_speed"] * froude
        notes.append(f"approach speed: {speed:.4g} m/s, the source's at equal Froude number "
                     "(give --speed or design_speed)")  # fmt: skip
    if rudder_rate is None:
        rudder_rate = source["rudder_rate"] / froude
        notes.append(f"rudder rate: {rudder_rate:.4g} °/s, the source's at equal Froude number "
                     "(give --rudder-rate)")  # fmt: skip
    c = dict(source)
    c.update(name=name, length=particulars.length, beam=particulars.beam,
             draught=particulars.draught, volume=particulars.mass / particulars.rho,
             x_g=particulars.xg, rho=particulars.rho, approach_speed=float(speed),
             rudder_rate=float(rudder_rate),
             scale=particulars.scale if particulars.scale is not None else math.nan,
             follow_rps=rps == FOLLOW, rps=None if rps in (None, FOLLOW) else float(rps))
    c["propeller.diameter"], c["rudder.area"], c["rudder.height"] = diameter, area, height
    if particulars.rudder_limit is not None:  # the ship's own gear, not the source's
        c["rudder_limit"] = float(particulars.rudder_limit)
    doc = document_of(c)
    coefficients(doc, "the MMG model")  # the same checks as a file's
    form = {}
    for label, (L, B, T, V) in (("ship", (particulars.length, particulars.beam,
                                          particulars.draught, c["volume"])),
                                ("source", (source["length"], source["beam"], source["draught"],
                                            source["volume"]))):  # fmt: skip
        form[label] = f"Cb {V / (L * B * T):.3f}, L/B {L / B:.2f}, B/T {B / T:.2f}"
    notes.append(f"the hull's, propeller's and rudder's coefficients are {source.get('name')}'s "
                 f"(prime): they hold as far as the hulls are alike (this ship: {form['ship']}; "
                 f"{source.get('name')}: {form['source']})")  # fmt: skip
    return doc, notes


def read_document(path) -> dict:
    """The parsed MMG file (YAML or JSON), or a one-line error naming it."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise ShipidError(f"{path}: cannot read the MMG file ({exc})") from None
    from shipid.data.mappings import DuplicateKeyError, duplicate_key_error, load_json, load_yaml

    try:
        return load_json(text) if p.suffix.lower() == ".json" else load_yaml(text)
    except DuplicateKeyError as exc:
        raise duplicate_key_error(path, exc) from None
    except Exception as exc:  # noqa: BLE001 - a parser's error, named in one line
        raise ShipidError(f"{path}: not a readable MMG file ({str(exc)[:120]})") from None


def read_mmg(path) -> Vessel:
    """The reference ship of the MMG file ``path``."""
    return mmg_vessel(read_document(path), str(path))

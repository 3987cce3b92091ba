"""Non-dimensional (prime) coefficients and Froude scaling of a model.

The prime system (SNAME 1950) with ship length L and speed U: speeds over U (u′ = u/U, v′, the
derived U and the wind speed), rates times L/U (r′ = rL/U, n′ = nL/U), time t′ = tU/L, forces
over ½ρL²U²; angles (δ, β, γ_A) and sin/cos factors have no dimension. The equations of the
acceleration form scale as u̇′ = u̇ L/U², v̇′ = v̇ L/U², ṙ′ = ṙ L²/U², so a coefficient c of a
term T (ẋ = Σ c T) becomes

    c′ = c · S_T / S_ẋ,

S_T the product of its factors' scales and S_ẋ the equation's. A thrust factor is a force in
an acceleration equation (c in 1/kg), so its c′ is c · ½ρL³, a reciprocal prime mass.

Two models of geometrically similar ships at the same Froude number U/√(gL) have the same prime
coefficients; ``froude_scaled`` carries a model to another length that way (viscous, Reynolds
effects are not scaled: a model-basin fit taken to full scale keeps the model's friction).
"""

from __future__ import annotations

import math
from collections.abc import Mapping

from shipid.dynamics.model import ManoeuvringModel, ModelStructure
from shipid.dynamics.terms import CROSSFLOW, OPS, PROPELLER, RUDDER, Factor, Term, parse_term
from shipid.errors import ShipidError

SPEEDS = ("u", "v", "U", "wind_speed")
RATES = ("r", "n")
ANGLES = ("beta", "delta", "wind_angle")
RHO = 1025.0
MIN_FACTOR = 1e-4  # a 4 cm model of a 400 m ship, and back


def _factor_scale(name: str, op: str, power: int, length: float, speed: float,
                  rho: float) -> float:  # fmt: skip
    if op in (*CROSSFLOW, RUDDER):  # |w|w, w = v + x r, and U_R² sin α_R: a speed squared
        return speed ** (2 * power)
    if op == PROPELLER:  # n² (−k n² astern): a rate squared
        return (speed / length) ** (2 * power)
    if op in ("sin", "cos") or name in ANGLES:
        return 1.0
    if name in SPEEDS:
        base = speed
    elif name in RATES:
        base = speed / length
    elif name == "thrust":
        base = 0.5 * rho * length**2 * speed**2
    else:  # a new signal must be placed in one of the groups above
        raise ShipidError(f"no prime scale for the signal {name!r}")
    return base**power


def term_scale(term: Term | str, length: float, speed: float, rho: float = RHO) -> float:
    """S_T: the dimensional value of a term whose factors are all one in prime units."""
    term = parse_term(term) if isinstance(term, str) else term
    scale = 1.0
    for f in term.factors:
        scale *= _factor_scale(f.name, OPS[f.op], f.power, length, speed, rho)
    return scale


def equation_scale(dof: str, length: float, speed: float) -> float:
    """S_ẋ: U²/L for u̇ and v̇, U²/L² for ṙ."""
    return speed**2 / length ** (2 if dof == "r" else 1)


def prime_factor(dof: str, term: Term | str, length: float, speed: float,
                 rho: float = RHO) -> float:  # fmt: skip
    """c′ / c for the term of equation ``dof``."""
    _check(length, speed, rho)
    return term_scale(term, length, speed, rho) / equation_scale(dof, length, speed)


def prime_coefficients(model: ManoeuvringModel, length: float, speed: float,
                       rho: float = RHO) -> dict[str, dict[str, float]]:  # fmt: skip
    """The model's coefficients in prime form for length L [m], speed U [m/s], density ρ."""
    return {dof: {t: float(c) * prime_factor(dof, t, length, speed, rho) for t, c in terms.items()}
            for dof, terms in model.coefficients.items()}  # fmt: skip


def from_prime(structure: ModelStructure, prime: Mapping[str, Mapping[str, float]], length: float,
               speed: float, rho: float = RHO, name: str = "") -> ManoeuvringModel:  # fmt: skip
    """A dimensional model from prime coefficients at length L, speed U, density ρ."""
    coefs = {dof: {t: float(prime[dof][t]) / prime_factor(dof, t, length, speed, rho)
                   for t in terms} for dof, terms in structure.terms.items()}  # fmt: skip
    return ManoeuvringModel(structure, coefs, name=name or structure.name)


def froude_ratios(structure: ModelStructure, factor: float, rho: float = RHO,
                  to_rho: float | None = None) -> dict[str, dict[str, float]]:  # fmt: skip
    """Per coefficient, its value on a geometrically similar ship ``factor`` times as long
    over its value on this one, at equal Froude number and prime coefficients."""
    if not (math.isfinite(factor) and factor > 0):
        raise ShipidError(f"scale factor must be > 0, got {factor!r}")
    if not MIN_FACTOR <= factor <= 1 / MIN_FACTOR:
        raise ShipidError(f"scale factor {factor:g} is not between two ships: use "
                          f"{MIN_FACTOR:g}…{1 / MIN_FACTOR:g}")  # fmt: skip
    to_rho = rho if to_rho is None else to_rho
    # Any reference length and speed: they cancel between the two ships.
    return {dof: {t: prime_factor(dof, t, 1.0, 1.0, rho)
                  / prime_factor(dof, t, factor, math.sqrt(factor), to_rho) for t in terms}
            for dof, terms in structure.terms.items()}  # fmt: skip


def froude_scaled(model: ManoeuvringModel, factor: float, rho: float = RHO,
                  to_rho: float | None = None) -> ManoeuvringModel:  # fmt: skip
    """The model of a geometrically similar ship ``factor`` times as long, at equal Froude
    number (speeds × √factor, times × √factor); ``to_rho`` the other water's density (thrust
    terms only). Its cross-flow terms take the longer hull (``lengthened_terms``)."""
    out = scaled(model, froude_ratios(model.structure, factor, rho, to_rho),
                 rps_ratio=1 / math.sqrt(factor))  # fmt: skip
    renamed = lengthened_terms(model.structure.all_terms, factor)
    if not renamed:
        return out
    coefs = {d: {renamed.get(t, t): c for t, c in terms.items()}
             for d, terms in out.coefficients.items()}  # fmt: skip
    structure = ModelStructure(model.structure.name, {
        d: tuple(renamed.get(t, t) for t in ts) for d, ts in model.structure.terms.items()})
    return ManoeuvringModel(structure, coefs, name=out.name, similar_at_rps=out.similar_at_rps)


def lengthened_terms(terms, factor: float) -> dict[str, str]:
    """{term: the same term on a hull ``factor`` times as long} for the cross-flow terms among
    ``terms`` (their argument is the hull's length) and the rudder's normal force (its race's
    share c goes as the propeller's diameter squared, its position x as the length); the others
    keep their text."""

    def longer(f: Factor) -> Factor:
        if f.crossflow:
            return Factor(f.signal, f.op, f.k * factor, f.power)
        if f.rudder:
            a, c, g, x = f.params
            return Factor(f.signal, f.op, f.k, f.power, (a, c * factor**2, g, x * factor))
        return f

    out = {}
    for text in terms:
        term = parse_term(text)
        if term.crossflow or term.rudder:
            out[term.text] = Term(tuple(longer(f) for f in term.factors)).text
    return out


def renamed_terms(obj, renamed: Mapping[str, str]):
    """``obj`` (a model file's JSON data) with every key and string equal to a term of
    ``renamed`` written as its new text."""
    if isinstance(obj, Mapping):
        return {renamed.get(k, k): renamed_terms(v, renamed) for k, v in obj.items()}
    if isinstance(obj, list):
        return [renamed_terms(v, renamed) for v in obj]
    if isinstance(obj, str):
        return renamed.get(obj, obj)
    return obj


def scaled(model: ManoeuvringModel, ratios: Mapping[str, Mapping[str, float]],
           rps_ratio: float = 1.0) -> ManoeuvringModel:  # fmt: skip
    """The model with each coefficient multiplied by its ratio ({dof: {term: ratio}}); the
    propeller speed its similarity is anchored at (``similar_at_rps``) times ``rps_ratio``."""
    coefs = {dof: {t: c * ratios[dof][t] for t, c in terms.items()}
             for dof, terms in model.coefficients.items()}  # fmt: skip
    anchor = model.similar_at_rps
    return ManoeuvringModel(model.structure, coefs, name=model.name,
                            similar_at_rps=None if anchor is None else anchor * rps_ratio)


def signal_scale(signal: str, factor: float, rho: float = RHO, to_rho: float | None = None) -> float:
    """A signal's value on the ship ``factor`` times as long over its value here (Froude)."""
    to_rho = rho if to_rho is None else to_rho
    return (_factor_scale(signal, "pow", 1, factor, math.sqrt(factor), to_rho)
            / _factor_scale(signal, "pow", 1, 1.0, 1.0, rho))  # fmt: skip


def _check(length: float, speed: float, rho: float) -> None:
    for name, value in (("length", length), ("speed", speed), ("rho", rho)):
        if not (math.isfinite(value) and value > 0):
            raise ShipidError(f"prime form: {name} must be > 0, got {value!r}")

"""Manoeuvring models linear in their parameters, in continuous-time acceleration form (paper eq. 16).

A model is a structure (which terms drive which degree of freedom) plus named coefficients::

    u̇ = Σ θᵤⱼ φⱼ(u, v, r, δ, ...),   v̇ = Σ θᵥⱼ φⱼ(...),   ṙ = Σ θᵣⱼ φⱼ(...)

Terms are texts of the term algebra (``shipid.dynamics.terms``), stored canonically, so a user's
own terms round-trip through model files. Degrees of freedom without an equation are held at their
initial value (Nomoto models hold surge and sway). The discrete form of eq. (9)–(13) for a sampling
time Δk is ξ(k+1) = Γ_ξᵀ x_ξ(k) with x_ξ = [ξ(k), terms...] and Γ_ξ = [1 + Δk·θ_ξξ, Δk·θ_ξⱼ...].

Structures are named (``STRUCTURES``), combined with ``+`` (``"blanke-rps+wind"``: the union of
terms per DOF), or written out: ``"u: |u|u, v*r, 1; v: u*r, u*v, delta, 1; r: u*r, u*v, delta, 1"``.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np

from shipid.dynamics import kernel
from shipid.dynamics.terms import (
    INPUT_SIGNALS,
    OPS,
    TermCode,
    parse_term,
    parse_terms,
    required_inputs,
    term_code,
    term_matrix,
)
from shipid.errors import ShipidError

if TYPE_CHECKING:
    from shipid.dynamics.rudder import RudderInflow

DOFS = ("u", "v", "r")
DOF_DISPLAY = {"u": "u̇", "v": "v̇", "r": "ṙ"}

_BLANKE_SWAY_YAW = ("ur", "uv", "|v|v", "|v|r", "delta", "1")
_BLANKE_SPEED = ("ur", "uv", "|v|v", "|v|r", "u^2*delta", "1")
# A rudder in the race of a propeller at constant rps n (most model-basin trials), in the MMG
# form (Yasukawa & Yoshimura 2015): its inflow u_R = ε u_P √(η {1 + κ(√(1 + 8K_T/πJ²) − 1)}² +
# 1 − η), J ∝ u/n, has a square close to a quadratic form a u² + b u n + c n². At constant n the
# rudder force is u²δ, uδ and δ, and part of it does not fall as the ship slows in a turn, as u²δ
# alone would have it. (The thrust is such a form too, but a u term beside |u|u is collinear with
# it on one zig-zag (ρ 0.999 on the KVLCC2's), so the surge stays Blanke's.)
_RACE_LATERAL = ("ur", "uv", "|v|v", "|v|r", "u^2*delta", "u*delta", "delta", "1")
# Third-order Taylor expansion about straight running (Abkowitz 1964; the Mariner model's set):
# surge even in v, r, δ; sway and yaw odd, with the speed-dependent couplings.
_ABK_SURGE = ("u", "u^2", "u^3", "v^2", "r^2", "v*r", "delta^2", "u*delta^2", "v*delta",
              "u*v*delta", "1")  # fmt: skip
_ABK_LATERAL = ("v", "r", "v^3", "v^2*r", "v*r^2", "r^3", "u*v", "u*r", "delta", "delta^3",
                "u*delta", "u^2*delta", "v*delta^2", "v^2*delta", "r*delta^2", "1")  # fmt: skip
# Low and negative speed, propeller reversal (Esso random runs): hull forces in |u|, |v|, |r|
# forms that keep their sign when the ship goes astern; thrust with n⁺ and n⁻ separately (ahead
# and astern open-water curves) and its fall with advance (u|n|); the rudder's lift and drag in
# the free stream (u|u|δ, u²δ²) and in the propeller race, which only an ahead propeller throws
# on it (n⁺²δ, n⁺²δ²); the astern propeller's side force and its race on the rudder (n⁻², n⁻²δ);
# propeller-race damping of sway and yaw (v|n|, r|n|).
_LOW_SPEED_SURGE = ("|u|u", "v*r", "r^2", "v^2", "pos(n)^2", "neg(n)^2", "u*|n|", "delta^2",
                    "u^2*delta^2", "pos(n)^2*delta^2", "1")  # fmt: skip
_LOW_SPEED_LATERAL = ("u*v", "|u|*r", "|v|v", "|v|r", "|r|r", "v*|r|", "u*|u|*delta",
                      "pos(n)^2*delta", "neg(n)^2*delta", "neg(n)^2", "v*|n|", "r*|n|", "1")  # fmt: skip
# The hull's nonlinear sway and yaw damping as the structures split it, which the cross-flow drag
# (``ModelStructure.with_crossflow_hull``) takes in one term per equation.
HULL_DRAG = ("|v|v", "|v|r", "|r|r", "v*|r|")
# Wind load terms on the relative wind (Isherwood-type, to second order in the angle).
_WIND_SURGE = ("U_A^2*cos(gamma_A)",)
_WIND_LATERAL = ("U_A^2*sin(gamma_A)", "U_A^2*sin(2*gamma_A)")

STRUCTURES: dict[str, dict[str, tuple[str, ...]]] = {
    # Paper eqs. (7)–(8), (12): surge with the thrust term merged into the constant (constant
    # commanded speed, as in the paper's experiment); "blanke-thrust" keeps T as a regressor.
    "blanke": {"u": ("|u|u", "vr", "r^2", "delta^2", "1"), "v": _BLANKE_SWAY_YAW,
               "r": _BLANKE_SWAY_YAW},
    "blanke-thrust": {"u": ("|u|u", "vr", "r^2", "T", "delta^2", "1"), "v": _BLANKE_SWAY_YAW,
                      "r": _BLANKE_SWAY_YAW},
    # Trials whose speed changes (real zig-zags lose 20–30 % of it): the rudder force scales with
    # the inflow speed squared, so the sway/yaw rudder term is u²δ instead of δ.
    "blanke-speed": {"u": ("|u|u", "vr", "r^2", "delta^2", "1"), "v": _BLANKE_SPEED,
                     "r": _BLANKE_SPEED},
    # Trials at different propeller speeds (e.g. Esso Osaka at 10, 12 and 16.7 rps): the thrust
    # ∝ |n|n enters the surge equation; needs the log column n [rps].
    # The rudder in the race of a propeller at constant rps (see _RACE_LATERAL); logs at several
    # propeller speeds need the race in n (pos(n)^2*delta, the low-speed library).
    "blanke-race": {"u": ("|u|u", "vr", "r^2", "delta^2", "1"), "v": _RACE_LATERAL,
                    "r": _RACE_LATERAL},
    # The rudder's share of sway and yaw damping in the race of a propeller at constant rps,
    # added to a structure (blanke-race+race-damping): its angle of attack falls by γ_R β_R (the
    # hull-straightened drift at the rudder, β_R = β − ℓ_R r′) at an inflow the race keeps up as
    # the ship slows, so part of the damping goes as n v and n r, not u v and u r (the
    # low-speed library's v|n|, r|n|; at constant n, v and r).
    "race-damping": {"v": ("v", "r"), "r": ("v", "r")},
    "blanke-rps": {"u": ("|u|u", "vr", "r^2", "delta^2", "|n|n", "1"), "v": _BLANKE_SPEED,
                   "r": _BLANKE_SPEED},
    "abkowitz3": {"u": _ABK_SURGE, "v": _ABK_LATERAL, "r": _ABK_LATERAL},
    "low-speed": {"u": _LOW_SPEED_SURGE, "v": _LOW_SPEED_LATERAL, "r": _LOW_SPEED_LATERAL},
    "wind": {"u": _WIND_SURGE, "v": _WIND_LATERAL, "r": _WIND_LATERAL},
    # A single propeller makes the flow at the rudder asymmetric (its race swirls): a side force
    # and moment with the propeller alone (n⁺², why a single-screw ship holds a few degrees of
    # rudder to go straight; the Esso Osaka's rests near −6°), a rudder lift that differs to
    # port and starboard (n⁺²|δ|), and so a drag that does too (n⁺²δ, and n⁺²|δ|³ for its growth
    # at large angles). Added to a library (low-speed+wind+propeller-asymmetry).
    "propeller-asymmetry": {"u": ("pos(n)^2*delta", "pos(n)^2*|delta|^3"),
                            "v": ("pos(n)^2", "pos(n)^2*|delta|"),
                            "r": ("pos(n)^2", "pos(n)^2*|delta|")},
    # Going astern the hull meets the water stern first: its resistance (neg(u)², beside |u|u)
    # and the lift of its drift (neg(u) v, neg(u) r, beside u v and |u| r) are those of another
    # body. Added to a library (low-speed+wind+propeller-asymmetry+astern).
    "astern": {"u": ("neg(u)^2",), "v": ("neg(u)*v", "neg(u)*r"), "r": ("neg(u)*v", "neg(u)*r")},
    # The rudder in the race at the hull's drift (Norrbin's c²|β|β|δ| and c²βδ, van Berlekom &
    # Goddard 1972; the `tanker` vessel): in a tight turn the drift straightens the flow at the
    # rudder and changes its lift and drag far beyond what zig-zags show. sin β, not β, so the
    # terms stay bounded at low speed and astern. Opt-in: from the tanker's zig-zags and one
    # 35° turn, the four 35° turns at 50 and 80 rpm within 3 % (10–29 % short without); on the
    # Esso Osaka's zig-zags alone, the held-out turns 30–47 % long and the random runs' yaw rate
    # twice as far off (benchmarks/study_tanker.py, study_esso_extrapolation.py).
    "rudder-drift": {"u": ("sin(beta)*pos(n)^2*delta",),
                     "v": ("sin(beta)*pos(n)^2*|delta|", "sin(beta)^3*pos(n)^2*|delta|"),
                     "r": ("sin(beta)*pos(n)^2*|delta|", "sin(beta)^3*pos(n)^2*|delta|")},
    # Linear sway–yaw (Davidson–Schiff) model at the held surge speed; its yaw transfer function is
    # Nomoto's second-order model, see ``nomoto_parameters``.
    "linear-sway-yaw": {"v": ("v", "r", "delta", "1"), "r": ("v", "r", "delta", "1")},
    # Nomoto first order, T ṙ + r = K δ (+ a constant for rudder offset): ṙ = −r/T + (K/T) δ.
    "nomoto1": {"r": ("r", "delta", "1")},
}  # fmt: skip
BASE_STRUCTURES = STRUCTURES  # the name of earlier versions


@dataclass(frozen=True)
class ModelStructure:
    """Which regressor terms drive which degree of freedom (canonical term texts)."""

    name: str
    terms: Mapping[str, tuple[str, ...]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if not isinstance(self.terms, Mapping):
            raise ShipidError(f"structure {self.name!r}: terms must map u/v/r to term lists")
        canon = {}
        for dof in DOFS:
            if dof not in self.terms:
                continue
            names = self.terms[dof]
            if isinstance(names, str) or not all(isinstance(n, str) for n in names):
                raise ShipidError(f"structure {self.name!r}: the {dof} terms must be a list of "
                                  f"texts, got {names!r}")  # fmt: skip
            canon[dof] = tuple(t.text for t in parse_terms(names, f"the {dof} equation"))
        for dof in self.terms:
            if dof not in DOFS:
                raise ShipidError(f"unknown degree of freedom {dof!r}; use one of {DOFS}")
        object.__setattr__(self, "terms", canon)

    @property
    def dofs(self) -> tuple[str, ...]:
        """The degrees of freedom with an equation, in u, v, r order."""
        return tuple(d for d in DOFS if d in self.terms)

    @property
    def held(self) -> tuple[str, ...]:
        """The degrees of freedom held at their initial value."""
        return tuple(d for d in DOFS if d not in self.terms)

    @property
    def all_terms(self) -> tuple[str, ...]:
        """Every term of the structure once, in order of first appearance (u, v, r)."""
        seen: dict[str, None] = {}
        for dof in self.dofs:
            seen.update(dict.fromkeys(self.terms[dof]))
        return tuple(seen)

    def union(self, *others: Mapping[str, Sequence[str]], name: str | None = None
              ) -> ModelStructure:  # fmt: skip
        """Per equation this structure's terms, then those of ``others`` ({dof: terms}) it
        lacks, in order: the structure of an average or ensemble of structures."""
        terms = {d: list(self.terms.get(d, ())) for d in DOFS}
        for other in others:
            for d, ts in other.items():
                terms[d] += [t for t in ts if t not in terms[d]]
        return ModelStructure(name or self.name, {d: tuple(t) for d, t in terms.items() if t})

    @property
    def inputs(self) -> tuple[str, ...]:
        """Log columns besides t, u, v, r, delta the structure needs (n, thrust, wind...)."""
        return required_inputs(self.all_terms)

    @property
    def uses_thrust(self) -> bool:
        """Whether a term needs the thrust column."""
        return "thrust" in self.inputs

    @property
    def uses_rps(self) -> bool:
        """Whether a term needs the propeller-speed column n."""
        return "n" in self.inputs

    @property
    def uses_wind(self) -> bool:
        """Whether a term needs the relative wind columns."""
        return any(s in self.inputs for s in ("wind_speed", "wind_angle"))

    def lacking(self, terms: Mapping[str, Sequence[str]]) -> list[tuple[str, str]]:
        """The (dof, term) of ``terms`` ({dof: [term]}) this structure's equations do not hold,
        compared as parsed ('r^2' and 'r*r' alike): a drop or a bound on them acts on nothing."""
        out = []
        for dof, names in terms.items():
            have = {parse_term(t).text for t in self.terms.get(dof, ())}
            out += [(dof, name) for name in names if parse_term(name).text not in have]
        return out

    def without(self, drop: Mapping[str, tuple[str, ...] | list[str]],
                missing_ok: bool = False) -> ModelStructure:  # fmt: skip
        """The structure with some terms dropped, e.g. ``{"u": ["r^2"]}`` as in the paper.
        ``missing_ok``: a term (or equation) the structure lacks is passed over instead of
        refused, as when the same drop applies to whichever structure is chosen; a term that
        does not parse, or of no equation, is refused either way."""
        terms = dict(self.terms)
        dropped = {}
        for dof, names in drop.items():
            if dof not in terms and (not missing_ok or dof not in DOFS):
                raise ShipidError(f"cannot drop terms of {dof!r}: {self.name} has no {dof} equation")
            try:
                canon = [parse_term(n).text for n in names]
            except ShipidError as exc:
                raise ShipidError(f"cannot drop {list(names)} from the {dof} equation: {exc}") from None
            have = terms.get(dof, ())
            missing = [n for _, n in self.lacking({dof: names})]
            if missing and not missing_ok:
                raise ShipidError(f"cannot drop {missing} from the {dof} equation of "
                                  f"{self.name}: it has {list(terms[dof])}")
            gone = [n for n, c in zip(names, canon, strict=True) if c in have]
            if gone:
                terms[dof] = tuple(n for n in have if n not in canon)
                dropped[dof] = gone
        suffix = ",".join(f"{d}-{'-'.join(n)}" for d, n in dropped.items() if n)
        return ModelStructure(f"{self.name}[drop {suffix}]" if suffix else self.name, terms)

    def with_crossflow_hull(self, length: float) -> ModelStructure:
        """The structure with its hull's nonlinear damping in sway and yaw (``HULL_DRAG``:
        |v|v, |v|r, |r|r, v|r|, however many it splits it into) as the cross-flow drag of a
        hull ``length`` m long, one term per equation (``crossflow_sway(L)``, ``crossflow_yaw(L)``,
        in the first replaced term's place). An equation without them is left as it is: the
        terms a selection chose without them, a linear model."""
        if not (math.isfinite(length) and length > 0):
            raise ShipidError(f"the cross-flow hull needs a length > 0 m, got {length!r}")
        drag = {parse_term(t).text for t in HULL_DRAG}
        terms = dict(self.terms)
        for dof, fn in (("v", "crossflow_sway"), ("r", "crossflow_yaw")):
            if dof not in terms:
                continue
            have = terms[dof]
            at = next((i for i, t in enumerate(have) if t in drag), None)
            if at is None:
                continue
            kept = [t for t in have if t not in drag]
            terms[dof] = tuple(kept[:at] + [parse_term(f"{fn}({length:.12g})").text] + kept[at:])
        if terms == dict(self.terms):
            return self
        return ModelStructure(f"{self.name}+crossflow({length:.4g} m)", terms)

    def with_rudder_normal(self, inflow: RudderInflow) -> ModelStructure:
        """The structure with its rudder force terms (``rudder_terms``: δ, u²δ, |u|uδ, n⁺²δ,
        δ², ...) as the rudder's normal force of one inflow (a ``shipid.dynamics.rudder.
        RudderInflow``), one term per equation, in the first replaced term's place: F_N sin δ
        in surge, F_N cos δ in sway and yaw. An equation without them is left as it is."""
        terms = dict(self.terms)
        for dof, new in (("u", inflow.surge), ("v", inflow.lateral), ("r", inflow.lateral)):
            have = terms.get(dof)
            if not have:
                continue
            gone = set(rudder_terms(have, odd=dof != "u"))
            if not gone:
                continue
            at = next(i for i, t in enumerate(have) if t in gone)
            kept = [t for t in have if t not in gone]
            terms[dof] = tuple(kept[:at] + [parse_term(new).text] + kept[at:])
        if terms == dict(self.terms):
            return self
        return ModelStructure(f"{self.name}+rudder-normal", terms)

    def __add__(self, other: ModelStructure) -> ModelStructure:
        terms = {d: tuple(dict.fromkeys(self.terms.get(d, ()) + other.terms.get(d, ())))
                 for d in DOFS if d in self.terms or d in other.terms}  # fmt: skip
        return ModelStructure(f"{self.name}+{other.name}", terms)

    def to_dict(self) -> dict:
        """The structure as JSON-ready data (canonical term texts)."""
        return {"name": self.name, "terms": {d: list(t) for d, t in self.terms.items()}}

    @classmethod
    def from_dict(cls, data: Mapping) -> ModelStructure:
        return cls(str(data["name"]), {d: tuple(t) for d, t in data["terms"].items()})


def rudder_terms(terms: Sequence[str], odd: bool) -> list[str]:
    """The terms among ``terms`` that the rudder's normal force stands for: δ^p (p odd for sway
    and yaw, ``odd``; even for surge's drag) times the ahead flow's speed (u, |u|, U, n, |n|,
    n⁺, in any power). Terms of the hull's motion (v, r, β), the astern propeller's race (n⁻)
    and the rudder's asymmetry (|δ|, δ⁺) are not the normal force's and stay."""
    ahead = {("u", "pow"), ("u", "abs"), ("U", "pow"), ("n", "pow"), ("n", "abs"), ("n", "pos")}
    out = []
    for text in terms:
        factors = parse_term(text).factors
        rudder = [f for f in factors if f.name == "delta"]
        if (len(rudder) == 1 and OPS[rudder[0].op] == "pow" and rudder[0].power % 2 == odd
                and all((f.name, OPS[f.op]) in ahead for f in factors if f.name != "delta")):
            out.append(text)
    return out


@dataclass(frozen=True)
class StructureEdit:
    """What a user changes in whichever structure is fitted or chosen: terms dropped (``drop``,
    {dof: [term]}, passed over where a structure lacks them) and the hull's nonlinear damping as
    the cross-flow drag of a hull ``crossflow_length`` m long (``with_crossflow_hull``);
    ``compare_crossflow`` False keeps the drag out of the default's comparison, which otherwise
    offers it beside the terms where the logs' particulars give the length; the rudder's force
    terms as its normal force of one inflow, ``rudder`` (a ``shipid.dynamics.rudder.
    RudderInflow``, ``with_rudder_normal``)."""

    drop: Mapping[str, Sequence[str]] | None = None
    crossflow_length: float | None = None
    compare_crossflow: bool = True
    rudder: RudderInflow | None = None

    def __bool__(self) -> bool:
        return (bool(self.drop) or self.crossflow_length is not None or not self.compare_crossflow
                or self.rudder is not None)  # fmt: skip

    def apply(self, structure: ModelStructure) -> ModelStructure:
        """``structure`` so edited."""
        if self.drop:
            structure = structure.without(self.drop, missing_ok=True)
        if self.crossflow_length is not None:
            structure = structure.with_crossflow_hull(self.crossflow_length)
        if self.rudder is not None:
            structure = structure.with_rudder_normal(self.rudder)
        return structure


def parse_structure_spec(spec: str, name: str = "custom") -> ModelStructure:
    """'u: |u|u, v*r, 1; v: u*r, delta; r: u*r, delta' → a structure (DOFs separated by ';')."""
    terms: dict[str, tuple[str, ...]] = {}
    for part in spec.split(";"):
        if not part.strip():
            continue
        if ":" not in part:
            raise ShipidError(f"model terms {part.strip()!r}: expected 'dof: term, term, ...'")
        dof, body = (s.strip() for s in part.split(":", 1))
        if dof not in DOFS:
            raise ShipidError(f"model terms: unknown degree of freedom {dof!r}; use u, v or r")
        if dof in terms:
            raise ShipidError(f"model terms: the {dof} equation is given twice")
        terms[dof] = tuple(t.strip() for t in body.split(",") if t.strip())
    if not terms:
        raise ShipidError(f"model terms {spec!r}: no equations")
    return ModelStructure(name, terms)


def get_structure(name: str | ModelStructure) -> ModelStructure:
    """A structure by name ('blanke', 'abkowitz3', ...), a sum of names ('blanke-rps+wind'), or
    a written-out spec ('u: ...; v: ...; r: ...'); a structure is returned as it is."""
    if isinstance(name, ModelStructure):
        return name
    if not isinstance(name, str) or not name.strip():
        raise ShipidError(f"model must be a structure name or term spec, got {name!r}")
    if ":" in name:
        return parse_structure_spec(name)
    parts = [p.strip() for p in name.split("+")]
    if not all(parts):
        raise ShipidError(f"model {name!r}: an empty name between '+' signs")
    unknown = [p for p in parts if p not in STRUCTURES]
    if unknown:
        raise ShipidError(f"unknown model {unknown[0]!r}; known models: {', '.join(STRUCTURES)} "
                          "(combine with +, or write terms as 'u: ...; v: ...; r: ...')")
    out = ModelStructure(parts[0], STRUCTURES[parts[0]])
    for p in parts[1:]:
        out = out + ModelStructure(p, STRUCTURES[p])
    return out


class TermTable(dict):
    """{canonical term text: value} that also answers to any spelling of a term ('uv', 'u*v')."""

    def _key(self, key):
        if isinstance(key, str) and not dict.__contains__(self, key):
            try:
                return parse_term(key).text
            except ShipidError:
                return key
        return key

    def __getitem__(self, key):
        return dict.__getitem__(self, self._key(key))

    def __contains__(self, key) -> bool:
        return dict.__contains__(self, self._key(key))

    def get(self, key, default=None):
        """``dict.get`` that also accepts any spelling of the term."""
        return dict.get(self, self._key(key), default)


def _finite(value, where: str) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.floating | np.integer):
        raise ShipidError(f"coefficient {where} must be a number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise ShipidError(f"coefficient {where} is {value}; coefficients must be finite")
    return value


class ManoeuvringModel:
    """A manoeuvring model with named continuous-time coefficients.

    Parameters
    ----------
    structure : ModelStructure or str (see ``get_structure``)
    coefficients : mapping dof → {term: value}; terms of the structure that are missing are 0.
        Term texts in any spelling of the algebra ('vr' or 'v*r').
    name : str, optional
    similar_at_rps : float, optional
        The one propeller speed of the logs of a model carried to every other by advance-ratio
        similarity (``shipid.dynamics.similarity``): its manoeuvres start, as a model's without
        propeller terms do, from the training logs' approach speed, times n over this elsewhere.

    Attributes
    ----------
    term_texts : every term once (the columns of ``theta``); theta : (3, T) coefficient matrix of
    the compiled simulator (a held DOF has a zero row); code : the terms' factor table.
    """

    def __init__(
        self,
        structure: ModelStructure | str,
        coefficients: Mapping[str, Mapping[str, float]],
        name: str = "",
        similar_at_rps: float | None = None,
    ) -> None:
        self.structure = get_structure(structure) if isinstance(structure, str) else structure
        self.name = name or self.structure.name
        if similar_at_rps is not None and not (isinstance(similar_at_rps, int | float)
                                               and math.isfinite(similar_at_rps)
                                               and similar_at_rps > 0):  # fmt: skip
            raise ShipidError(f"similar_at_rps must be a positive propeller speed, got "
                              f"{similar_at_rps!r}")  # fmt: skip
        self.similar_at_rps = None if similar_at_rps is None else float(similar_at_rps)
        if not isinstance(coefficients, Mapping):
            raise ShipidError("coefficients must map u/v/r to {term: value}")
        self.coefficients: dict[str, dict[str, float]] = {}
        for dof, names in self.structure.terms.items():
            given_raw = coefficients.get(dof, {})
            if not isinstance(given_raw, Mapping):
                raise ShipidError(f"coefficients of {dof} must map terms to numbers")
            given = {parse_term(k).text: _finite(v, f"{dof}:{k}") for k, v in given_raw.items()}
            unknown = set(given) - set(names)
            if unknown:
                raise ShipidError(f"coefficients {sorted(unknown)} are not terms of the {dof} "
                                  f"equation of {self.structure.name} ({list(names)})")
            self.coefficients[dof] = TermTable({n: given.get(n, 0.0) for n in names})
        for dof in set(coefficients) - set(self.structure.terms):
            values = coefficients[dof]
            if not isinstance(values, Mapping) or any(v != 0 for v in values.values()):
                raise ShipidError(f"{self.structure.name} has no {dof} equation")
        self.term_texts = self.structure.all_terms
        index = {t: j for j, t in enumerate(self.term_texts)}
        self.theta = np.zeros((3, len(self.term_texts)))
        for i, dof in enumerate(DOFS):
            for n, val in self.coefficients.get(dof, {}).items():
                self.theta[i, index[n]] = val
        self.code: TermCode = term_code(self.term_texts)

    # ------------------------------------------------------------------ inputs
    @property
    def inputs(self) -> tuple[str, ...]:
        """Log columns besides t, u, v, r, delta the model needs."""
        return self.structure.inputs

    @property
    def uses_thrust(self) -> bool:
        """Whether the model needs a thrust series."""
        return self.structure.uses_thrust

    @property
    def uses_rps(self) -> bool:
        """Whether the model needs a propeller-speed series."""
        return self.structure.uses_rps

    @property
    def uses_wind(self) -> bool:
        """Whether the model needs the relative wind."""
        return self.structure.uses_wind

    # ------------------------------------------------------------------ evaluation
    def accelerations(self, u, v, r, delta, thrust=None, rps=None, **inputs) -> np.ndarray:
        """(n, 3) accelerations [u̇, v̇, ṙ] for arrays of states and inputs (held DOFs give 0).
        ``inputs``: further input columns by name (wind_speed, wind_angle)."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        given = {"delta": delta, "thrust": thrust, "n": rps, **inputs}
        Phi = term_matrix(self.term_texts, u, v, r, given)
        return Phi @ self.theta.T

    def derivatives(self, nu: np.ndarray, delta: np.ndarray, thrust=None, rps=None,
                    **inputs) -> np.ndarray:  # fmt: skip
        """Dynamics protocol of ``shipid.dynamics.simulate``: (B, 3) body accelerations."""
        return self.accelerations(nu[:, 0], nu[:, 1], nu[:, 2], delta, thrust, rps, **inputs)

    def compiled_accelerations(self, states: np.ndarray, inputs: np.ndarray) -> np.ndarray:
        """The compiled kernel's accelerations at states (M, 3) and inputs (M, 5) in
        ``INPUT_SIGNALS`` order; equal to ``accelerations`` (a test checks it)."""
        out = np.empty((states.shape[0], 3))
        kernel.accelerations(self.theta, *self.code.arrays(), self.code.uses_derived,
                             np.ascontiguousarray(states, dtype=float),
                             np.ascontiguousarray(inputs, dtype=float), out)  # fmt: skip
        return out

    def rudder_gain(self, speed: float = 1.0, rps: float | None = None) -> float:
        """∂ṙ/∂δ at straight running at ``speed`` (propeller ``rps``, still air), by central
        difference over ±1°."""
        h = math.radians(1.0)
        n = 1.0 if rps is None else float(rps)
        u = np.array([speed, speed])
        extra = {}
        if self.uses_wind:
            # Still air: the apparent wind of the ship's own motion, from ahead.
            extra = {"wind_speed": np.abs(u), "wind_angle": np.zeros(2)}
        acc = self.accelerations(u, np.zeros(2), np.zeros(2), np.array([h, -h]),
                                 np.full(2, n), np.full(2, n), **extra)  # fmt: skip
        return float(acc[0, 2] - acc[1, 2]) / (2 * h)

    def rudder_positive_turns_at(self, speed: float = 1.0, rps: float | None = None) -> str:
        """'port' or 'starboard': where a positive rudder angle turns this model at ``speed``."""
        return "starboard" if self.rudder_gain(speed, rps) > 0 else "port"

    @property
    def rudder_positive_turns(self) -> str:
        """Where a positive rudder angle turns this model (at 1 m/s, n = 1 rps)."""
        return self.rudder_positive_turns_at()

    # ------------------------------------------------------------------ presentation
    def equations(self, precision: int = 4, std_errors: Mapping | None = None) -> str:
        """The model as equations in the paper's style (eq. 16); with ``std_errors``
        ({dof: {term: σ}}), each coefficient is followed by ± its standard error: ± ∞ where the
        error is infinite or recorded as null (a model file's JSON keeps an infinite one as
        null), the coefficient the data do not determine."""
        lines = []
        for dof in self.structure.dofs:
            errors = (std_errors or {}).get(dof) or {}
            parts = []
            for n, c in self.coefficients[dof].items():
                # Coefficients of large regressors (|n|n ~ 100 rps²) are tiny: keep their digits.
                small = 0 < abs(c) < 10 ** (1 - precision)
                mag = f"{abs(c):.{precision - 1}e}" if small else f"{abs(c):.{precision}f}"
                if n in errors:
                    se = errors[n]
                    finite = se is not None and math.isfinite(se)
                    mag = f"({mag} ± {f'{se:.2g}' if finite else '∞'})"
                term = parse_term(n).display()
                sign = "−" if c < 0 else "+"
                parts.append((sign, f"{mag} {term}".rstrip()))
            body = " ".join(f"{s} {p}" for s, p in parts)
            body = body[2:] if body.startswith("+ ") else "−" + body[2:]
            lines.append(f"{DOF_DISPLAY[dof]} = {body}")
        for dof in self.structure.held:
            lines.append(f"{DOF_DISPLAY[dof]} = 0   (held)")
        return "\n".join(lines)

    def __repr__(self) -> str:
        return f"ManoeuvringModel({self.name!r}, {self.coefficients})"

    # ------------------------------------------------------------------ discrete form
    def regressor_names(self, dof: str) -> list[str]:
        """Names of x_ξ(k) of eq. (12): ξ(k) first, then the terms (the self term merged)."""
        return [dof] + [n for n in self.structure.terms[dof] if n != dof]

    def to_discrete(self, dt: float) -> dict[str, np.ndarray]:
        """Γ_ξ of eq. (13) for sampling time Δk, in the order of ``regressor_names``."""
        out = {}
        for dof in self.structure.dofs:
            c = self.coefficients[dof]
            out[dof] = np.array([1.0 + dt * c.get(dof, 0.0)]
                                + [dt * c[n] for n in self.regressor_names(dof)[1:]])
        return out

    @classmethod
    def from_discrete(
        cls,
        structure: ModelStructure | str,
        gammas: Mapping[str, np.ndarray],
        dt: float,
        name: str = "",
    ) -> ManoeuvringModel:
        """Invert ``to_discrete``. A ξ(k) coefficient ≠ 1 becomes a linear self term (e.g. "u" in
        the u̇ equation), added to the structure if it is not there, so no information is lost."""
        structure = get_structure(structure) if isinstance(structure, str) else structure
        terms = dict(structure.terms)
        coefs: dict[str, dict[str, float]] = {}
        for dof, g in gammas.items():
            names = [dof] + [n for n in structure.terms[dof] if n != dof]
            if len(g) != len(names):
                raise ValueError(f"Γ_{dof} has {len(g)} entries, the structure needs {len(names)}")
            c = coefficients_from_gamma(dof, names, g, dt)
            if c[dof] == 0.0 and dof not in structure.terms[dof]:
                del c[dof]
            elif dof not in terms[dof]:
                terms[dof] = (dof, *terms[dof])
            coefs[dof] = c
        new_structure = (
            structure if terms == dict(structure.terms) else ModelStructure(structure.name, terms)
        )
        return cls(new_structure, coefs, name=name)

    # ------------------------------------------------------------------ serialisation
    def to_dict(self) -> dict:
        """The model as JSON-ready data (what model files store)."""
        out = {"name": self.name, "structure": self.structure.to_dict(),
               "coefficients": self.coefficients}  # fmt: skip
        if self.similar_at_rps is not None:
            out["similar_at_rps"] = self.similar_at_rps
        return out

    @classmethod
    def from_dict(cls, data: Mapping) -> ManoeuvringModel:
        """The model of ``to_dict`` data (term texts in any spelling)."""
        return cls(ModelStructure.from_dict(data["structure"]), data["coefficients"],
                   name=str(data.get("name", "")),
                   similar_at_rps=data.get("similar_at_rps"))  # fmt: skip

    def save(self, path, particulars: Mapping | None = None):
        """Write the model alone as a model file (no identification record), atomically;
        ``shipid.load_model`` and every command read it."""
        import json

        from shipid import __version__
        from shipid.outputs import atomic_write_text
        from shipid.reporting.modelfile import FORMAT, VERSION, json_safe

        doc = {"format": FORMAT, "version": VERSION, "shipid": __version__,
               "model": self.to_dict(), "particulars": particulars, "identification": None,
               "provenance": {"training_files": []}}  # fmt: skip
        return atomic_write_text(path, json.dumps(json_safe(doc), indent=2, ensure_ascii=False)
                                 + "\n")  # fmt: skip


def coefficients_from_gamma(
    dof: str, names: list[str], gamma, dt: float
) -> dict[str, float]:
    """Continuous-time coefficients of one equation from its Γ_ξ (eq. 13), ``names[0]`` being ξ(k):
    θ_ξξ = (Γ₀ − 1)/Δk (a linear self term) and θⱼ = Γⱼ/Δk."""
    c = {dof: (float(gamma[0]) - 1.0) / dt}
    c.update({n: float(v) / dt for n, v in zip(names[1:], gamma[1:], strict=True)})
    return c


def sway_yaw_nomoto(A: np.ndarray, b: np.ndarray) -> dict:
    """Nomoto's parameters of the sway–yaw pair [v̇, ṙ] = A [v, r] + b δ.

    r/δ = K (1 + T3 s) / ((1 + T1 s)(1 + T2 s)) = (b2 s + a21 b1 − a11 b2) / (s² − tr s + det),
    and the first-order T = T1 + T2 − T3 of the low-frequency response K / (1 + T s) (T =
    −G′(0)/G(0)). Where the poles are a complex pair (an oscillatory sway–yaw mode, as the fit of
    one Esso Osaka zig-zag file has) T1 and T2 are not real and are None; their sum −tr/det is,
    and with it K, T3 and T. ``natural_frequency`` √det [rad/s] and ``damping_ratio``
    −tr/(2√det) (≥ 1 for real stable poles) where det > 0, else None; ``poles`` [1/s]."""
    A, b = np.asarray(A, dtype=float), np.asarray(b, dtype=float)
    det, tr = float(np.linalg.det(A)), float(np.trace(A))
    if det == 0:
        raise ShipidError("the sway–yaw dynamics are singular at this speed: no Nomoto model")
    roots = np.roots([1.0, -tr, det])
    num0 = float(A[1, 0] * b[0] - A[0, 0] * b[1])
    K = num0 / det
    T3 = float(b[1]) / num0 if num0 != 0 else math.nan
    oscillatory = bool(np.any(np.abs(roots.imag) > 1e-12))
    if oscillatory:
        T1 = T2 = None
        T = -tr / det - T3
    else:
        T1, T2 = sorted((-1.0 / roots.real).tolist(), reverse=True)
        T = T1 + T2 - T3
    omega = math.sqrt(det) if det > 0 else None
    return {"K": float(K), "T1": T1, "T2": T2, "T3": float(T3), "T": float(T),
            "oscillatory": oscillatory, "poles": [complex(p) for p in roots],
            "natural_frequency": omega,
            "damping_ratio": -tr / (2.0 * omega) if omega else None,
            "stable": bool(np.all(roots.real < 0))}  # fmt: skip


def nomoto_parameters(model: ManoeuvringModel) -> dict:
    """Nomoto's second-order parameters K, T1, T2, T3 of a linear sway–yaw model
    (``sway_yaw_nomoto``: T1 and T2 None where its poles are a complex pair).

    r/δ = K (1 + T3 s) / ((1 + T1 s)(1 + T2 s)) for v̇ = a11 v + a12 r + b1 δ, ṙ = a21 v + a22 r + b2 δ.
    """
    if set(model.structure.dofs) != {"v", "r"}:
        raise ValueError("Nomoto parameters need a model with sway and yaw equations only")
    cv, cr = model.coefficients["v"], model.coefficients["r"]
    A = np.array([[cv.get("v", 0.0), cv.get("r", 0.0)], [cr.get("v", 0.0), cr.get("r", 0.0)]])
    found = sway_yaw_nomoto(A, np.array([cv.get("delta", 0.0), cr.get("delta", 0.0)]))
    return {k: found[k] for k in ("K", "T1", "T2", "T3")}


INPUT_COLUMNS = INPUT_SIGNALS

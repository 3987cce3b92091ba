"""Manoeuvring models linear in their parameters, in continuous-time acceleration form (paper eq. 16).

A model is a structure (which terms drive which degree of freedom) plus named coefficients::

    u̇ = Σ θᵤⱼ φⱼ(u, v, r, δ, T),   v̇ = Σ θᵥⱼ φⱼ(...),   ṙ = Σ θᵣⱼ φⱼ(...)

Degrees of freedom without an equation are held at their initial value (Nomoto models hold surge and
sway). The discrete form of eq. (9)–(13) for a sampling time Δk is ξ(k+1) = Γ_ξᵀ x_ξ(k) with
x_ξ = [ξ(k), terms...] and Γ_ξ = [1 + Δk·θ_ξξ, Δk·θ_ξⱼ...].
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from shipid.dynamics.terms import TERM_DISPLAY, TERM_INDEX, TERMS, required_inputs, term_matrix

DOFS = ("u", "v", "r")
# Terms linear in the rudder angle; their coefficient signs say which way a positive rudder turns.
RUDDER_GAIN_TERMS = ("delta", "u^2*delta", "|n|n*delta")
DOF_DISPLAY = {"u": "u̇", "v": "v̇", "r": "ṙ"}

_BLANKE_SWAY_YAW = ("ur", "uv", "|v|v", "|v|r", "delta", "1")
_BLANKE_SPEED = ("ur", "uv", "|v|v", "|v|r", "u^2*delta", "1")
BASE_STRUCTURES: dict[str, dict[str, tuple[str, ...]]] = {
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
    "blanke-rps": {"u": ("|u|u", "vr", "r^2", "delta^2", "|n|n", "1"), "v": _BLANKE_SPEED,
                   "r": _BLANKE_SPEED},
    # Linear sway–yaw (Davidson–Schiff) model at the held surge speed; its yaw transfer function is
    # Nomoto's second-order model, see ``nomoto_parameters``.
    "linear-sway-yaw": {"v": ("v", "r", "delta", "1"), "r": ("v", "r", "delta", "1")},
    # Nomoto first order, T ṙ + r = K δ (+ a constant for rudder offset): ṙ = −r/T + (K/T) δ.
    "nomoto1": {"r": ("r", "delta", "1")},
}  # fmt: skip


@dataclass(frozen=True)
class ModelStructure:
    """Which regressor terms drive which degree of freedom."""

    name: str
    terms: Mapping[str, tuple[str, ...]] = field(default_factory=dict)

    def __post_init__(self) -> None:
        for dof, names in self.terms.items():
            if dof not in DOFS:
                raise ValueError(f"unknown degree of freedom {dof!r}; use one of {DOFS}")
            for n in names:
                if n not in TERM_INDEX:
                    raise ValueError(f"unknown model term {n!r}; known terms: {', '.join(TERMS)}")
            if len(set(names)) != len(names):
                raise ValueError(f"duplicate terms in the {dof} equation: {names}")

    @property
    def dofs(self) -> tuple[str, ...]:
        return tuple(d for d in DOFS if d in self.terms)

    @property
    def held(self) -> tuple[str, ...]:
        return tuple(d for d in DOFS if d not in self.terms)

    @property
    def inputs(self) -> tuple[str, ...]:
        """Log columns of the propulsion inputs the structure needs: 'n' [rps], 'thrust' [N]."""
        return required_inputs([n for names in self.terms.values() for n in names])

    @property
    def uses_thrust(self) -> bool:
        return "thrust" in self.inputs

    @property
    def uses_rps(self) -> bool:
        return "n" in self.inputs

    def without(self, drop: Mapping[str, tuple[str, ...] | list[str]]) -> ModelStructure:
        """The structure with some terms dropped, e.g. ``{"u": ["r^2"]}`` as in the paper."""
        terms = dict(self.terms)
        for dof, names in drop.items():
            if dof not in terms:
                raise ValueError(f"cannot drop terms of {dof!r}: {self.name} has no {dof} equation")
            missing = set(names) - set(terms[dof])
            if missing:
                raise ValueError(f"cannot drop {sorted(missing)} from the {dof} equation of "
                                 f"{self.name}: it has {list(terms[dof])}")
            terms[dof] = tuple(n for n in terms[dof] if n not in names)
        suffix = ",".join(f"{d}-{'-'.join(n)}" for d, n in drop.items() if n)
        return ModelStructure(f"{self.name}[drop {suffix}]" if suffix else self.name, terms)

    def to_dict(self) -> dict:
        return {"name": self.name, "terms": {d: list(t) for d, t in self.terms.items()}}

    @classmethod
    def from_dict(cls, data: Mapping) -> ModelStructure:
        return cls(str(data["name"]), {d: tuple(t) for d, t in data["terms"].items()})


def get_structure(name: str) -> ModelStructure:
    """A named base structure: 'blanke', 'blanke-thrust', 'blanke-speed', 'blanke-rps',
    'linear-sway-yaw' or 'nomoto1'."""
    if name not in BASE_STRUCTURES:
        raise ValueError(f"unknown model {name!r}; known models: {', '.join(BASE_STRUCTURES)}")
    return ModelStructure(name, BASE_STRUCTURES[name])


class ManoeuvringModel:
    """A manoeuvring model with named continuous-time coefficients.

    Parameters
    ----------
    structure : ModelStructure or str
    coefficients : mapping dof → {term: value}; terms of the structure that are missing are 0.
    name : str, optional
    """

    def __init__(
        self,
        structure: ModelStructure | str,
        coefficients: Mapping[str, Mapping[str, float]],
        name: str = "",
    ) -> None:
        self.structure = get_structure(structure) if isinstance(structure, str) else structure
        self.name = name or self.structure.name
        self.coefficients: dict[str, dict[str, float]] = {}
        for dof, names in self.structure.terms.items():
            given = dict(coefficients.get(dof, {}))
            unknown = set(given) - set(names)
            if unknown:
                raise ValueError(f"coefficients {sorted(unknown)} are not terms of the {dof} "
                                 f"equation of {self.structure.name} ({list(names)})")
            self.coefficients[dof] = {n: float(given.get(n, 0.0)) for n in names}
        for dof in set(coefficients) - set(self.structure.terms):
            if any(v != 0 for v in coefficients[dof].values()):
                raise ValueError(f"{self.structure.name} has no {dof} equation")
        # (3, len(TERMS)) coefficient matrix of the compiled simulator; held DOFs have zero rows.
        self.theta = np.zeros((3, len(TERMS)))
        for i, dof in enumerate(DOFS):
            for n, val in self.coefficients.get(dof, {}).items():
                self.theta[i, TERM_INDEX[n]] = val

    # ------------------------------------------------------------------ evaluation
    @property
    def uses_thrust(self) -> bool:
        return self.structure.uses_thrust

    @property
    def uses_rps(self) -> bool:
        return self.structure.uses_rps

    @property
    def rudder_positive_turns(self) -> str:
        """'port' or 'starboard': where a positive rudder angle turns this model (sign of ∂ṙ/∂δ,
        read from the first rudder term of the yaw equation: δ, u² δ or |n|n δ)."""
        yaw = self.coefficients.get("r", {})
        gain = next((yaw[n] for n in RUDDER_GAIN_TERMS if yaw.get(n, 0.0) != 0.0), 0.0)
        return "starboard" if gain > 0 else "port"

    def accelerations(self, u, v, r, delta, thrust=None, rps=None) -> np.ndarray:
        """(n, 3) accelerations [u̇, v̇, ṙ] for arrays of states and inputs (held DOFs give 0)."""
        u = np.atleast_1d(np.asarray(u, dtype=float))
        out = np.zeros((u.shape[0], 3))
        for i, dof in enumerate(DOFS):
            coefs = self.coefficients.get(dof)
            if coefs:
                Phi = term_matrix(list(coefs), u, v, r, delta, thrust, rps)
                out[:, i] = Phi @ np.fromiter(coefs.values(), float)
        return out

    def derivatives(self, nu: np.ndarray, delta: np.ndarray, thrust=None, rps=None) -> np.ndarray:
        """Dynamics protocol of ``shipid.simulate``: (B, 3) body accelerations."""
        return self.accelerations(nu[:, 0], nu[:, 1], nu[:, 2], delta, thrust, rps)

    # ------------------------------------------------------------------ presentation
    def equations(self, precision: int = 4) -> str:
        """The model as equations in the paper's style (eq. 16)."""
        lines = []
        for dof in self.structure.dofs:
            parts = []
            for n, c in self.coefficients[dof].items():
                # Coefficients of large regressors (|n|n ~ 100 rps²) are tiny: keep their digits.
                small = 0 < abs(c) < 10 ** (1 - precision)
                mag = f"{abs(c):.{precision - 1}e}" if small else f"{abs(c):.{precision}f}"
                term = TERM_DISPLAY[n]
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
        return {"name": self.name, "structure": self.structure.to_dict(),
                "coefficients": self.coefficients}  # fmt: skip

    @classmethod
    def from_dict(cls, data: Mapping) -> ManoeuvringModel:
        return cls(ModelStructure.from_dict(data["structure"]), data["coefficients"],
                   name=str(data.get("name", "")))  # fmt: skip


def coefficients_from_gamma(
    dof: str, names: list[str], gamma, dt: float
) -> dict[str, float]:
    """Continuous-time coefficients of one equation from its Γ_ξ (eq. 13), ``names[0]`` being ξ(k):
    θ_ξξ = (Γ₀ − 1)/Δk (a linear self term) and θⱼ = Γⱼ/Δk."""
    c = {dof: (float(gamma[0]) - 1.0) / dt}
    c.update({n: float(v) / dt for n, v in zip(names[1:], gamma[1:], strict=True)})
    return c


def nomoto_parameters(model: ManoeuvringModel) -> dict[str, float]:
    """Nomoto's second-order parameters K, T1, T2, T3 of a linear sway–yaw model.

    r/δ = K (1 + T3 s) / ((1 + T1 s)(1 + T2 s)) for v̇ = a11 v + a12 r + b1 δ, ṙ = a21 v + a22 r + b2 δ.
    """
    if set(model.structure.dofs) != {"v", "r"}:
        raise ValueError("Nomoto parameters need a model with sway and yaw equations only")
    cv, cr = model.coefficients["v"], model.coefficients["r"]
    A = np.array([[cv.get("v", 0.0), cv.get("r", 0.0)], [cr.get("v", 0.0), cr.get("r", 0.0)]])
    b1, b2 = cv.get("delta", 0.0), cr.get("delta", 0.0)
    det, tr = np.linalg.det(A), np.trace(A)
    # Characteristic polynomial s² − tr s + det = det (1 + T1 s)(1 + T2 s).
    roots = np.roots([1.0, -tr, det])
    T1, T2 = sorted((-1.0 / roots).real, reverse=True)
    K = (A[1, 0] * b1 - A[0, 0] * b2) / det
    # Numerator of r/δ: b2 s + (a21 b1 − a11 b2) = K det (1 + T3 s)/… → T3 = b2 / (a21 b1 − a11 b2).
    T3 = b2 / (A[1, 0] * b1 - A[0, 0] * b2)
    return {"K": float(K), "T1": float(T1), "T2": float(T2), "T3": float(T3)}

"""What physics adds to the regression (issue #10): a prior model the LS-SVM is drawn toward,
sign constraints on damping and rudder terms, user bounds, and steady speed on the approaches.

All act on the continuous-time coefficients of the increment form (the default), inside the
solver (``shipid.lssvm.solvers.solve_primal_constrained``): bounds by bounded least squares, the
steady-speed conditions as linear equalities. Nothing is clipped after the fit.

Sign table (``SIGN_RULES``; accelerations in the body frame, forward speed u > 0, "rudder sign"
s = +1 when a positive rudder angle turns the ship to starboard, −1 when to port):

* u̇: |u|u ≤ 0 (hull resistance grows with speed); δ², u²δ² ≤ 0 (rudder drag); |n|n, pos(n)²,
  thrust ≥ 0 (propeller thrust ahead); neg(n)² ≤ 0 (propeller astern pulls back).
* v̇: uv, |u|v, Uv, |v|v, v|n|, v ≤ 0 (sway damping).
* ṙ: ur, |u|r, Ur, |r|r, r|n|, r ≤ 0 (yaw damping).
* ṙ: δ, uδ, |u|δ, Uδ, u²δ, |u|uδ, U²δ, pos(n)²δ have the sign s (the rudder turns the ship its
  way); in v̇ the same terms have the sign −s (the rudder pushes the stern the other way).

The rudder rows need the logs' rudder sign convention (metadata ``rudder_positive``); without it
they are left out, with a note. Terms not in the table are free.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from shipid.dynamics.terms import parse_term, term_matrix
from shipid.errors import ShipidError

RUDDER = "rudder"


def _canonical(*texts: str) -> frozenset[str]:
    return frozenset(parse_term(t).text for t in texts)


_RUDDER_TERMS = _canonical("delta", "u*delta", "|u|*delta", "U*delta", "u^2*delta", "|u|*u*delta",
                           "U^2*delta", "pos(n)^2*delta")  # fmt: skip
# (equation, terms, sign, why): sign −1 (≤ 0), +1 (≥ 0), or RUDDER / "-" + RUDDER (s, −s).
SIGN_RULES: tuple[tuple[str, frozenset[str], object, str], ...] = (
    ("u", _canonical("|u|*u"), -1, "hull resistance grows with speed"),
    ("u", _canonical("delta^2", "u^2*delta^2"), -1, "rudder drag"),
    ("u", _canonical("|n|*n", "pos(n)^2", "thrust"), 1, "propeller thrust ahead"),
    ("u", _canonical("neg(n)^2"), -1, "propeller astern pulls back"),
    ("v", _canonical("u*v", "|u|*v", "U*v", "|v|*v", "v*|n|", "v"), -1, "sway damping"),
    ("r", _canonical("u*r", "|u|*r", "U*r", "|r|*r", "r*|n|", "r"), -1, "yaw damping"),
    ("r", _RUDDER_TERMS, RUDDER, "the rudder turns the ship its way"),
    ("v", _RUDDER_TERMS, "-" + RUDDER, "the rudder pushes the stern the other way"),
)
CONSTRAINTS = ("signs", "steady-speed")


@dataclass(frozen=True)
class PhysicsOptions:
    """Physics in the fit (one options object for ``identify`` and ``select``).

    Attributes
    ----------
    prior : {dof: {term: value}} continuous-time coefficients the regularisation draws the fit
        toward (½‖ω − ω₀‖² instead of ½‖ω‖²); terms left out are drawn toward 0 as before. See
        ``shipid.identification.priors`` (Clarke et al. 1983 from the particulars, or a model).
    signs : apply ``SIGN_RULES``.
    bounds : {dof: {term: (lower, upper)}} further bounds (use ±inf for one-sided).
    steady_speed : u̇ = 0 on the straight approach (u0, n0, rudder amidships, no wind) of every
        training log: the surge equation reproduces the speed each propeller speed holds.
    approach : {"u": u0, "n": n0}: the one approach for ``steady_speed`` (default: each
        training log's start).
    rudder_positive : 'port' or 'starboard' (default: the logs' metadata).
    """

    prior: Mapping[str, Mapping[str, float]] | None = None
    signs: bool = False
    bounds: Mapping[str, Mapping[str, tuple[float, float]]] | None = None
    steady_speed: bool = False
    approach: Mapping[str, float] | None = None
    rudder_positive: str | None = None

    @property
    def active(self) -> bool:
        """Whether the options change the plain fit."""
        return bool(self.prior or self.signs or self.bounds or self.steady_speed)

    def describe(self) -> dict:
        """A JSON-safe record for the model file."""
        return {"prior": {d: dict(v) for d, v in (self.prior or {}).items()},
                "signs": self.signs, "steady_speed": self.steady_speed,
                "bounds": {d: {t: list(b) for t, b in v.items()}
                           for d, v in (self.bounds or {}).items()},
                "approach": dict(self.approach or {}),
                "rudder_positive": self.rudder_positive}  # fmt: skip


def parse_constraints(text: str | None) -> tuple[bool, bool]:
    """(signs, steady_speed) from a comma list such as ``signs,steady-speed``."""
    if not text:
        return False, False
    items = [t.strip() for t in text.split(",") if t.strip()]
    unknown = [t for t in items if t not in CONSTRAINTS]
    if unknown:
        raise ShipidError(f"--constraints: unknown {', '.join(map(repr, unknown))}; use a comma "
                          f"list of {', '.join(CONSTRAINTS)}")  # fmt: skip
    return "signs" in items, "steady-speed" in items


@dataclass
class DofPhysics:
    """The solver's inputs for one equation: prior, bounds, tied bias, and what they mean."""

    prior: np.ndarray | None
    lower: np.ndarray
    upper: np.ndarray
    equalities: tuple[np.ndarray, np.ndarray] | None = None  # (E over [ω; b], f)
    approaches: list[tuple[float, float]] = field(default_factory=list)  # (u0, n0) of the above
    reasons: dict[str, str] = field(default_factory=dict)  # term → why it is bounded
    notes: list[str] = field(default_factory=list)
    active: np.ndarray | None = None  # after the fit: which coefficients sit on a bound


def rudder_sign(logs: Sequence[pd.DataFrame], given: str | None = None) -> float | None:
    """+1 if a positive rudder turns the logs' ship to starboard, −1 if to port, None if unknown
    or the logs disagree."""
    conventions = {given} if given else {log.attrs.get("rudder_positive") for log in logs}
    if len(conventions) != 1 or None in conventions:
        return None
    side = conventions.pop()
    if side not in ("port", "starboard"):
        raise ShipidError(f"rudder_positive must be 'port' or 'starboard', got {side!r}")
    return 1.0 if side == "starboard" else -1.0


def _sign_bounds(dof: str, term: str, s: float | None) -> tuple[float, float, str] | None:
    for eq, terms, sign, why in SIGN_RULES:
        if eq != dof or term not in terms:
            continue
        if sign in (RUDDER, "-" + RUDDER):
            if s is None:
                return None
            sign = s if sign == RUDDER else -s
        return (0.0, math.inf, why) if sign > 0 else (-math.inf, 0.0, why)
    return None


def _approach_rows(dof_terms: Sequence[str], fixed: Mapping[str, float], has_constant: bool,
                   options: PhysicsOptions, logs: Sequence[pd.DataFrame],
                   ) -> tuple[np.ndarray, np.ndarray, list]:  # fmt: skip
    """Equalities u̇ = 0 at the approach state (u0, n0, rudder amidships, no wind) of every
    training log (or at ``options.approach``): rows over [free terms; bias], targets."""
    texts = list(dof_terms) + list(fixed)
    needs = {i for t in texts for i in parse_term(t).inputs}
    if "thrust" in needs:
        raise ShipidError("steady-speed constraint: the surge equation has a thrust term, whose "
                          "value on the approach is not known; identify with propeller-speed "
                          "(n) terms")  # fmt: skip
    if options.approach:
        states = [(float(options.approach["u"]), float(options.approach.get("n", 0.0)))]
    else:
        states = sorted({(float(log["u"].iloc[0]),
                          float(log["n"].iloc[0]) if "n" in log.columns else 0.0) for log in logs})
    if not all(u0 > 0 for u0, _ in states):
        raise ShipidError("steady-speed constraint: a training log starts without headway; trim "
                          "it to the approach (--start) or give the approach with --speed")  # fmt: skip
    u0 = np.array([s[0] for s in states])
    n0 = np.array([s[1] for s in states])
    zero = np.zeros(len(states))
    given = {"delta": zero, "n": n0, "wind_speed": zero, "wind_angle": zero}
    rows = term_matrix(texts, u0, zero, zero, given)
    k = len(dof_terms)
    E = np.column_stack([rows[:, :k], np.full(len(states), 1.0 if has_constant else 0.0)])
    f = -(rows[:, k:] @ np.array([fixed[t] for t in fixed])) if fixed else np.zeros(len(states))
    return E, f, states


def dof_physics(options: PhysicsOptions | None, dof: str, names: Sequence[str], has_constant: bool,
                fixed: Mapping[str, float], logs: Sequence[pd.DataFrame]) -> DofPhysics:  # fmt: skip
    """Prior, bounds and the steady-speed tie of one equation whose free regressors are
    ``names`` (canonical term texts, the constant excluded)."""
    p = len(names)
    out = DofPhysics(None, np.full(p, -math.inf), np.full(p, math.inf))
    if options is None or not options.active:
        return out
    if options.prior and options.prior.get(dof):
        given = {parse_term(t).text: float(v) for t, v in options.prior[dof].items()}
        out.prior = np.array([given.get(n, 0.0) for n in names])
    s = rudder_sign(logs, options.rudder_positive) if options.signs else None
    if options.signs and s is None and any(n in _RUDDER_TERMS for n in names):
        out.notes.append(f"{dof}: rudder terms left unconstrained: the logs do not state (or "
                         "disagree on) the rudder sign convention (--rudder-positive)")
    user = {parse_term(t).text: b for t, b in ((options.bounds or {}).get(dof) or {}).items()}
    unknown = sorted(set(user) - set(names))
    if unknown:
        raise ShipidError(f"bounds: {dof}: {', '.join(unknown)} is not a free term of the "
                          f"{dof} equation ({', '.join(names) or 'none'})")  # fmt: skip
    for j, name in enumerate(names):
        lo, hi, why = -math.inf, math.inf, []
        rule = _sign_bounds(dof, name, s) if options.signs else None
        if rule:
            lo, hi = max(lo, rule[0]), min(hi, rule[1])
            why.append(rule[2])
        if name in user:
            ulo, uhi = (float(x) for x in user[name])
            if math.isnan(ulo) or math.isnan(uhi) or ulo > uhi:
                raise ShipidError(f"bounds: {dof}: {name}: lower {ulo:g} > upper {uhi:g}")
            lo, hi = max(lo, ulo), min(hi, uhi)
            why.append(f"bound [{ulo:g}, {uhi:g}]")
        if lo > hi:
            raise ShipidError(f"constraints conflict on {dof}: {name}: " + " and ".join(why)
                              + f" leave no value (lower {lo:g} > upper {hi:g})")  # fmt: skip
        out.lower[j], out.upper[j] = lo, hi
        if why:
            out.reasons[name] = "; ".join(why)
    if out.prior is not None:
        # A prior outside the bounds would pull against them: start from the feasible point.
        out.prior = np.clip(out.prior, out.lower, out.upper)
    if options.steady_speed and dof == "u":
        E, f, out.approaches = _approach_rows(names, fixed, has_constant, options, logs)
        out.equalities = (E, f)
        where = ", ".join(f"{a:.4g} m/s at {b:.4g} rps" for a, b in out.approaches)
        out.notes.append(f"u: steady speed imposed on the approach ({where})")
    return out

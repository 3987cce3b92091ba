"""What physics adds to the regression (issue #10): a prior model the LS-SVM is drawn toward,
sign constraints on damping and rudder terms, user bounds, steady speed on the approaches and
straight-line stability.

All act on the continuous-time coefficients of the increment form (the default), inside the
solver (``shipid.lssvm.solvers.solve_primal_constrained``): bounds by bounded least squares, the
steady-speed conditions as linear equalities, stability as linear inequalities. Nothing is
clipped after the fit.

Straight-line stability (``stable``): the sway–yaw block A = [[a11, a12], [a21, a22]] of the
model linearised about straight running (u0, v = r = 0, rudder amidships, still air) at each
training log's approach has eigenvalues with real parts ≤ 0 iff tr A ≤ 0 and det A ≥ 0. The
equations are fitted one after the other, so the yaw equation is fitted given the sway one:
a11 = ∂v̇/∂v and a12 = ∂v̇/∂r are then numbers, a21 = ∂ṙ/∂v and a22 = ∂ṙ/∂r linear in the yaw
coefficients, and both conditions are linear inequalities on them (with a margin μ:
real parts ≤ −μ ⇔ tr A ≤ −2μ and det A + μ tr A + μ² ≥ 0). A ship the logs show unstable is
then fitted barely stable, which is a choice, not a finding: full-form ships (the KVLCC2's MMG
model) can be slightly unstable.

Sign table (``SIGN_RULES``; accelerations in the body frame, forward speed u > 0, "rudder sign"
s = +1 when a positive rudder angle turns the ship to starboard, −1 when to port):

* u̇: |u|u ≤ 0 (hull resistance grows with speed); δ², u²δ², |u|uδ², n⁺²δ² ≤ 0 (rudder drag, in
  the free stream and in the propeller's race); |n|n, pos(n)²,
  thrust ≥ 0 (propeller thrust ahead); neg(n)² ≤ 0 (propeller astern pulls back); u|n|,
  u·pos(n) ≤ 0 (thrust falls with the advance: K_T(J) falls with J ahead, and astern the inflow
  brakes the reversed propeller harder; of the other sign the surge feeds on its own speed,
  astern as ahead: the default model of two Esso Osaka zig-zag files, 13_29_19 and 13_42_53,
  has it at +0.0044 and, with its sway's |u|·v > 0, ran away astern in two random runs).
* v̇: uv, |u|v, Uv, |v|v, v|n|, v ≤ 0 (sway damping).
* ṙ: ur, |u|r, Ur, |r|r, r|n|, r ≤ 0 (yaw damping).
* v̇: crossflow_sway(L) ≤ 0, ṙ: crossflow_yaw(L) ≤ 0 (cross-flow drag opposes the hull's lateral
  motion), whatever the length L.
* ṙ: δ, uδ, |u|δ, Uδ, u²δ, |u|uδ, U²δ, pos(n)²δ have the sign s (the rudder turns the ship its
  way); in v̇ the same terms have the sign −s (the rudder pushes the stern the other way).
* The rudder's normal force (``rudder_normal``, whatever its inflow): its drag F_N sin δ ≤ 0 in
  u̇; its side force F_N cos δ, of δ's sign, as δ in ṙ (s) and v̇ (−s).

The rudder rows need the logs' rudder sign convention (metadata ``rudder_positive``); without it
they are left out, with a note. Terms not in the table are free.
"""

from __future__ import annotations

import dataclasses
import functools
import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

import numpy as np
import pandas as pd

from shipid.dynamics.propeller import ADVANCE_TERMS, THRUST_TERMS
from shipid.dynamics.terms import OPS, parse_term, rudder_normal_angle, term_matrix
from shipid.errors import InfeasibleConstraintsError, ShipidError

if TYPE_CHECKING:
    from shipid.dynamics.model import ModelStructure

RUDDER = "rudder"


def _canonical(*texts: str) -> frozenset[str]:
    return frozenset(parse_term(t).text for t in texts)


_RUDDER_TERMS = _canonical("delta", "u*delta", "|u|*delta", "U*delta", "u^2*delta", "|u|*u*delta",
                           "U^2*delta", "pos(n)^2*delta")  # fmt: skip
# The rudder's drag in u̇, in the free stream and in the propeller's race.
RUDDER_DRAG_TERMS = _canonical("delta^2", "u^2*delta^2", "|u|*u*delta^2", "pos(n)^2*delta^2")
# (equation, terms, sign, why): sign −1 (≤ 0), +1 (≥ 0), or RUDDER / "-" + RUDDER (s, −s).
SIGN_RULES: tuple[tuple[str, frozenset[str], object, str], ...] = (
    ("u", _canonical("|u|*u"), -1, "hull resistance grows with speed"),
    ("u", RUDDER_DRAG_TERMS, -1, "rudder drag"),
    ("u", _canonical(*THRUST_TERMS, "thrust"), 1, "propeller thrust ahead"),
    ("u", _canonical("neg(n)^2"), -1, "propeller astern pulls back"),
    ("u", _canonical(*ADVANCE_TERMS), -1, "thrust falls with the advance"),
    ("v", _canonical("u*v", "|u|*v", "U*v", "|v|*v", "v*|n|", "v"), -1, "sway damping"),
    ("r", _canonical("u*r", "|u|*r", "U*r", "|r|*r", "r*|n|", "r"), -1, "yaw damping"),
    ("r", _RUDDER_TERMS, RUDDER, "the rudder turns the ship its way"),
    ("v", _RUDDER_TERMS, "-" + RUDDER, "the rudder pushes the stern the other way"),
)
CONSTRAINTS = ("signs", "steady-speed", "stable", "derivatives", "rudder-ahead")
# ``stable``: the sway–yaw eigenvalues' real parts at most −μ, μ this share of the sway damping
# rate |∂v̇/∂v| (a scale the model itself sets): held at the limit, the slowest mode still decays,
# slowly, also about a steady approach a little off the log's start.
STABILITY_MARGIN = 0.05


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
    stable : straight-line stability at every training log's approach (the yaw equation given
        the sway one; see the module's notes).
    derivatives : the linearised damping and rudder derivatives keep their physical sign at
        every training log's approach, whatever terms carry them (``DERIVATIVE_RULES``).
    rudder_ahead : the rudder's derivatives (∂v̇/∂δ, ∂ṙ/∂δ at straight running) keep their
        physical sign at every speed ahead from rest to each training log's approach, at its
        propeller speed, beyond it, and with the propeller stopped (``RUDDER_AHEAD_SHARES``):
        the rudder turns the ship its way wherever it moves ahead, not only where the logs ran.
    approach : {"u": u0, "n": n0}, or a sequence of them: the approaches ``steady_speed``,
        ``derivatives`` and ``stable`` hold at (default: each training log's start;
        ``with_approaches`` resolves them once for fits that repeat, as ``select``'s).
    rudder_positive : 'port' or 'starboard' (default: the logs' metadata).
    prior_source : where the prior comes from, in words (the model file keeps it).
    bounds_where_present : a bound on a term the fitted structure lacks is not refused: the
        structure was chosen (``select``'s candidates, the default's choice), not given; the
        lacking structure holds it at 0, which meets a bound around 0 (a sign) and is infeasible
        for one that excludes 0 (``select`` drops such a candidate).
    """

    prior: Mapping[str, Mapping[str, float]] | None = None
    signs: bool = False
    bounds: Mapping[str, Mapping[str, tuple[float, float]]] | None = None
    steady_speed: bool = False
    approach: Mapping[str, float] | Sequence[Mapping[str, float]] | None = None
    rudder_positive: str | None = None
    stable: bool = False
    derivatives: bool = False
    rudder_ahead: bool = False
    prior_source: str = ""
    bounds_where_present: bool = False

    @property
    def active(self) -> bool:
        """Whether the options change the plain fit."""
        return bool(self.prior or self.signs or self.bounds or self.steady_speed or self.stable
                    or self.derivatives or self.rudder_ahead)

    def describe(self) -> dict:
        """A JSON-safe record for the model file."""
        return {"prior": {d: dict(v) for d, v in (self.prior or {}).items()},
                **({"prior_source": self.prior_source} if self.prior_source else {}),
                "signs": self.signs, "steady_speed": self.steady_speed,
                "bounds": {d: {t: list(b) for t, b in v.items()}
                           for d, v in (self.bounds or {}).items()},
                "approach": (dict(self.approach) if isinstance(self.approach, Mapping)
                             else [dict(a) for a in self.approach] if self.approach else {}),
                "rudder_positive": self.rudder_positive, "stable": self.stable,
                "derivatives": self.derivatives, "rudder_ahead": self.rudder_ahead}  # fmt: skip


def parse_constraints(text: str | None) -> dict[str, bool]:
    """The ``PhysicsOptions`` flags (signs, steady_speed, stable, derivatives, rudder_ahead) of
    a comma list such as ``signs,steady-speed``."""
    if not text:
        return {c.replace("-", "_"): False for c in CONSTRAINTS}
    items = [t.strip() for t in text.split(",") if t.strip()]
    unknown = [t for t in items if t not in CONSTRAINTS]
    if unknown:
        raise ShipidError(f"--constraints: unknown {', '.join(map(repr, unknown))}; use a comma "
                          f"list of {', '.join(CONSTRAINTS)}")  # fmt: skip
    return {c.replace("-", "_"): c in items for c in CONSTRAINTS}


def parse_steady_speeds(items: Sequence[str] | None) -> list[dict[str, float]]:
    """``--steady-speed U@N`` values (repeatable; ``U`` alone for a model without propeller
    terms) as approaches ``{"u": U, "n": N}``: where the ship is known to hold U m/s straight."""
    out = []
    for text in items or ():
        speed, _, rps = str(text).partition("@")
        try:
            u, n = float(speed), float(rps) if rps else 0.0
        except ValueError:
            raise ShipidError(f"--steady-speed expects U@N (m/s at rps, e.g. 0.35@10), got "
                              f"{text!r}") from None  # fmt: skip
        if not (math.isfinite(u) and u > 0 and math.isfinite(n)):
            raise ShipidError(f"--steady-speed: the speed must be > 0 and both finite, got {text!r}")
        out.append({"u": u, "n": n})
    return out


# Given steady speeds that similarity puts this far apart at the logs' one rps are one speed
# given twice, rounded; further apart, no straight run of one model holds them.
SIMILAR_SPEEDS_TOLERANCE = 0.01


def similar_steady_speeds(approaches: Sequence[Mapping[str, float]], rps: float | None
                          ) -> list[dict[str, float]]:  # fmt: skip
    """``--steady-speed`` approaches for a fit to logs that all run at one ``rps``, which the
    model file carries to every rps by advance-ratio similarity (``shipid.dynamics.similarity``:
    its straight speed ∝ rps): U at N is imposed as U·rps/N at ``rps``, where the fit's terms
    stand for the logs' propeller (the given U and N kept as ``given_u``, ``given_n``). Imposed
    with the fit's terms at N instead, a speed given at 12 rps to a fit of logs at 10 was held
    at 10 rps, and the model ran 20 % faster at 12. ``rps`` None: as given."""
    out = [dict(a) for a in approaches]
    if rps is None or not out:
        return out
    for a in out:
        if a.get("n") and a["n"] != rps:
            a.update(given_u=a["u"], given_n=a["n"], u=a["u"] * rps / a["n"], n=rps)
        elif not a.get("n"):
            a["n"] = rps  # a model with propeller terms runs at the logs' rps
    speeds = [a["u"] for a in out]
    if max(speeds) > (1.0 + SIMILAR_SPEEDS_TOLERANCE) * min(speeds):
        said = ", ".join(f"{a.get('given_u', a['u']):.4g}@{a.get('given_n', a['n']):.4g}"
                         for a in out)  # fmt: skip
        at = ", ".join(f"{u:.4g}" for u in speeds)
        raise ShipidError(f"--steady-speed {said}: the logs run at one {rps:.4g} rps, from which "
                          f"the model is carried to other rps by advance-ratio similarity (its "
                          f"straight speed ∝ rps); these are {at} m/s at {rps:.4g} rps, which one "
                          "straight run cannot all hold: give the one at the rps the model is "
                          "for, or train on logs at several propeller speeds")  # fmt: skip
    return [{**out[0], "u": float(np.mean(speeds))}] if len(out) > 1 else out


@dataclass
class DofPhysics:
    """The solver's inputs for one equation: prior, bounds, tied bias, and what they mean."""

    prior: np.ndarray | None
    lower: np.ndarray
    upper: np.ndarray
    equalities: tuple[np.ndarray, np.ndarray] | None = None  # (E over [ω; b], f)
    inequalities: tuple[np.ndarray, np.ndarray] | None = None  # (G over [ω; b], h): G z ≥ h
    inequality_labels: list[str] = field(default_factory=list)  # what each row holds
    approaches: list[tuple[float, float]] = field(default_factory=list)  # (u0, n0) of the above
    reasons: dict[str, str] = field(default_factory=dict)  # term → why it is bounded
    notes: list[str] = field(default_factory=list)
    active: np.ndarray | None = None  # after the fit: which coefficients sit on a bound
    # The equation has no constant term "1": the LS-SVM's bias is held at 0 in the fit (the
    # lssvm and ols estimators), not fitted and then dropped from the model.
    no_constant: bool = False

    def solver_equalities(self) -> tuple[np.ndarray, np.ndarray] | None:
        """The equality rows over [ω; b] the solver holds: ``equalities``, and b = 0 for an
        equation without a constant."""
        if not self.no_constant:
            return self.equalities
        p = len(self.lower)
        row, zero = np.eye(1, p + 1, p), np.zeros(1)
        if self.equalities is None:
            return row, zero
        E, f = self.equalities
        return np.vstack([E, row]), np.concatenate([f, zero])


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


# The hull's cross-flow drag, whatever the length, opposes each section's lateral motion: ≤ 0 in
# the equation of its own kind (its sway force in v̇, its yaw moment in ṙ).
CROSSFLOW_SIGNS = {"v": "crossflow_sway", "r": "crossflow_yaw"}


def _rudder_normal_sign(dof: str, term: str) -> tuple[str, object] | None:
    """The sign rule of the rudder's normal force terms (their inflow's parameters vary): its
    drag F_N sin δ ≤ 0 in u̇; its side force F_N cos δ, which has δ's sign (the factor's γ_R is
    signed by the convention), as δ's rudder terms in v̇ and ṙ."""
    angle = rudder_normal_angle(term)
    if dof == "u" and angle == "sin":
        return "rudder drag", -1
    if dof in ("v", "r") and angle == "cos":
        return next((why, sign) for eq, terms, sign, why in SIGN_RULES
                    if eq == dof and terms is _RUDDER_TERMS)  # fmt: skip
    return None


def _sign_bounds(dof: str, term: str, s: float | None) -> tuple[float, float, str] | None:
    factors = parse_term(term).factors
    if len(factors) == 1 and OPS[factors[0].op] == CROSSFLOW_SIGNS.get(dof):
        return (-math.inf, 0.0, "cross-flow drag opposes the hull's lateral motion")
    rule = _rudder_normal_sign(dof, term) or next(
        ((why, sign) for eq, terms, sign, why in SIGN_RULES if eq == dof and term in terms), None)
    if rule is None:
        return None
    why, sign = rule
    if sign in (RUDDER, "-" + RUDDER):
        if s is None:
            return None
        sign = s if sign == RUDDER else -s
    return (0.0, math.inf, why) if sign > 0 else (-math.inf, 0.0, why)


def approach_states(options: PhysicsOptions, logs: Sequence[pd.DataFrame], what: str
                    ) -> list[tuple[float, float]]:  # fmt: skip
    """(u0, n0) of every training log's start (or ``options.approach``); of a log that starts
    without headway (a random run begun at rest), its running condition
    (``shipid.data.log.approach``)."""
    from shipid.data.log import approach, starts_without_headway

    def state(log: pd.DataFrame) -> tuple[float, float]:
        if starts_without_headway(log):
            return float(approach(log, "u")), float(approach(log, "n") or 0.0)
        return (float(log["u"].iloc[0]),
                float(log["n"].iloc[0]) if "n" in log.columns else 0.0)  # fmt: skip

    if isinstance(options.approach, Mapping):
        states = [(float(options.approach["u"]), float(options.approach.get("n", 0.0)))]
    elif options.approach:
        states = [(float(a["u"]), float(a.get("n", 0.0))) for a in options.approach]
    else:
        if "steady-speed" in what:
            logs = _steady_starts(logs)
        states = sorted({state(log) for log in logs})
    if not all(u0 > 0 for u0, _ in states):
        raise ShipidError(f"{what} constraint: a training log starts without headway; trim it to "
                          "the approach (--start) or give the approach with --speed")  # fmt: skip
    return states


def _steady_starts(logs: Sequence[pd.DataFrame]) -> list[pd.DataFrame]:
    """The logs whose start can be a steady state: u̇ = 0 imposed where a log starts speeding up
    (the Esso Osaka's zig-zags: +15 to +52 % per 10 s) put the surge's balance at its start; a
    log that clearly speeds up, slows down or turns there is left out, and none left is an
    error."""
    from shipid.data.log import log_name, steady_start

    judged = [(log, steady_start(log)) for log in logs]
    kept = [log for log, start in judged if start.steady is not False]
    if not kept:
        log, start = judged[0]
        raise ShipidError(
            f"steady-speed constraint: no training log starts on a steady straight approach "
            f"({log_name(log)}: its speed changes by {100 * start.change:+.0f} % per 10 s before "
            "its first rudder order); give the speed the ship holds straight at a propeller "
            "speed with --steady-speed U@N")  # fmt: skip
    return kept


def still_air(u, v, delta, n) -> dict[str, np.ndarray]:
    """The inputs of ``term_matrix`` at states (u, v) in still air: the relative wind an
    anemometer reads is then the ship's own motion, as ``shipid.data.log.relative_wind`` gives
    it with no true wind and the closed loop and ``surge_equilibrium`` run the model. (A
    steady-speed equality with the wind's terms at 0 put a wind model's straight run off the
    speed it was given.)"""
    from shipid.data.log import relative_wind

    speed, angle = relative_wind(u, v, 0.0, (0.0, 0.0))
    return {"delta": np.asarray(delta, dtype=float), "n": np.asarray(n, dtype=float),
            "wind_speed": speed, "wind_angle": angle}


def _straight_running_slopes(texts: Sequence[str], u0: float, n0: float,
                             wrt: Sequence[str] = ("v", "r")) -> np.ndarray:
    """(len(wrt), len(texts)): ∂/∂x of each term for x in ``wrt`` (of u, v, r, delta) at
    straight running (u0, v = r = 0, rudder amidships, propeller n0, still air: the apparent wind
    of the ship's own motion); see ``_term_slopes``."""
    return _slopes_at(texts, ((float(u0), float(n0)),), wrt)[:, :, 0]


def _slopes_at(texts: Sequence[str], states: Sequence[tuple[float, float]],
               wrt: Sequence[str] = ("v", "r")) -> np.ndarray:
    """(len(wrt), len(texts), len(states)): ``_straight_running_slopes`` at each straight-running
    state (u0, n0) of ``states``, each term's at all of them in one evaluation."""
    key = (tuple((float(u), float(n)) for u, n in states), tuple(wrt))
    if not len(texts):
        return np.zeros((len(wrt), 0, len(key[0])))
    return np.stack([_term_slopes(t, *key) for t in texts], axis=1)


@functools.lru_cache(maxsize=4096)
def _term_slopes(text: str, states: tuple[tuple[float, float], ...], wrt: tuple[str, ...]
                 ) -> np.ndarray:  # fmt: skip
    """One term's slopes (len(wrt), len(states)) of ``_slopes_at`` (cached, read-only: ``select``
    asks for the same terms at the same approaches in every fold of every candidate, and
    ``rudder_ahead`` at 36 speeds of each).

    Central differences at steps h and 2h, combined (2 D(h) − D(2h)) so that the kink of a
    modulus term at 0 (|v|v, |r|r: slope 0, but h from a central difference) counts nothing: a
    fit would otherwise buy stability with an |r|r coefficient of 10⁶. One term at one state at
    a time (and the per-state entries overflowing the cache), `identify --constraints
    rudder-ahead` of the tanker's four zig-zags at two rps took 237 s, 10 s now."""
    u0, n0 = (np.array(column, dtype=float) for column in zip(*states, strict=True))

    def value(du, dv, dr, dd) -> np.ndarray:
        u, v, r = u0 + du, np.zeros_like(u0) + dv, np.zeros_like(u0) + dr
        return term_matrix([text], u, v, r, still_air(u, v, np.zeros_like(u0) + dd, n0))[:, 0]

    def central(h: np.ndarray) -> np.ndarray:
        out = np.zeros((len(wrt), len(u0)))
        zero = np.zeros_like(h)
        for i, x in enumerate(wrt):
            step = [h if x == name else zero for name in ("u", "v", "r", "delta")]
            out[i] = (value(*step) - value(*(-d for d in step))) / (2 * h)
        return out

    h = 1e-6 * np.maximum(np.abs(u0), 1.0)
    out = 2.0 * central(h) - central(2.0 * h)
    out.flags.writeable = False
    return out


def with_approaches(options: PhysicsOptions | None, logs: Sequence[pd.DataFrame]
                    ) -> PhysicsOptions | None:  # fmt: skip
    """``options`` with the training logs' approaches resolved (``approach_states``), for fits
    that repeat on the same logs; ``options`` itself when it needs none or has them."""
    if options is None or options.approach or not (
            options.steady_speed or options.derivatives or options.stable
            or options.rudder_ahead):
        return options
    what = "/".join(n for n, on in (("steady-speed", options.steady_speed),
                                    ("derivatives", options.derivatives),
                                    ("rudder-ahead", options.rudder_ahead),
                                    ("stable", options.stable)) if on)  # fmt: skip
    states = approach_states(options, logs, what)
    return dataclasses.replace(options, approach=tuple({"u": u, "n": n} for u, n in states))


# ``derivatives``: (equation, state, sign, why): the linearised derivative at straight running
# keeps its sign whatever terms carry it (−1: ≤ 0; RUDDER / "-" + RUDDER: s, −s).
DERIVATIVE_RULES = (
    ("u", "u", -1, "surge damping ∂u̇/∂u ≤ 0"),
    ("v", "v", -1, "sway damping ∂v̇/∂v ≤ 0"),
    ("v", "delta", "-" + RUDDER, "the rudder pushes the stern the other way (∂v̇/∂δ)"),
    ("r", "r", -1, "yaw damping ∂ṙ/∂r ≤ 0"),
    ("r", "delta", RUDDER, "the rudder turns the ship its way (∂ṙ/∂δ)"),
)


# ``rudder_ahead``: the speeds at which the rudder's rows hold at each approach's propeller
# speed, as shares of the approach speed: from rest to it evenly, then beyond it up to where the
# u² terms alone count (by advance-ratio similarity, the approach speed with the propeller all but
# stopped: a fit at one rps has no n to stop), and, where the model has terms in n, the same
# speeds with the propeller stopped. A quadratic in u (the race's u², u·n, n²) that keeps its
# sign at points h apart can go past it between two by at most |q''| h²/8.
RUDDER_AHEAD_SHARES = (*np.linspace(0.0, 1.0, 11).tolist(), 1.5, 2.0, 3.0, 5.0, 10.0, 100.0,
                       1000.0)


def _derivative_states(options: PhysicsOptions, u0: float, n0: float
                       ) -> list[tuple[float, float, bool]]:  # fmt: skip
    """(u, n, rudder rules only) of one approach at which ``derivative_rows`` holds its rules."""
    states = [(u0, n0, False)] if options.derivatives else []
    if options.rudder_ahead:
        speeds = [share * u0 for share in RUDDER_AHEAD_SHARES]
        states += [(u, n0, True) for u in speeds if not (options.derivatives and u == u0)]
        if n0:
            states += [(u, 0.0, True) for u in speeds[1:]]
    return states


def derivative_rows(options: PhysicsOptions, dof: str, names: Sequence[str],
                    fixed: Mapping[str, float], logs: Sequence[pd.DataFrame],
                    ) -> tuple[np.ndarray, np.ndarray, list[str]] | None:  # fmt: skip
    """The ``derivatives`` and ``rudder_ahead`` constraints of one equation: rows G over [free
    terms ``names``; bias], h and a label per row, G z ≥ h for each rule of ``DERIVATIVE_RULES``
    at each training log's approach, and for its rudder rules at the speeds ahead from rest to
    it and beyond, the propeller at the approach's rate and stopped (``_derivative_states``; a
    row that repeats one already held is left out). None when no free term carries a rule's
    derivative. The rudder's rows need the logs' rudder convention."""
    s = rudder_sign(logs, options.rudder_positive)
    rules = [(x, sign, why) for eq, x, sign, why in DERIVATIVE_RULES if eq == dof
             and (s is not None or sign not in (RUDDER, "-" + RUDDER))]  # fmt: skip
    if not rules or not names:
        return None
    wrt = [x for x, _, _ in rules]
    what = "/".join(n for n, on in (("derivatives", options.derivatives),
                                    ("rudder-ahead", options.rudder_ahead)) if on)  # fmt: skip
    states = [(u0, n0, *state) for u0, n0 in approach_states(options, logs, what)
              for state in _derivative_states(options, u0, n0)]  # fmt: skip
    points = [(u, n) for _, _, u, n, _ in states]
    slopes = _slopes_at(names, points, wrt)  # every state at once: (wrt, names, states)
    fixed_slopes = (np.einsum("wts,t->ws", _slopes_at(list(fixed), points, wrt),
                              np.array(list(fixed.values()))) if fixed
                    else np.zeros((len(wrt), len(points))))  # fmt: skip
    # Each (state, rule) pair's row, in that order, at unit size (far ahead a u² slope is 10⁶
    # times the rest), those no free term carries left out, each row held once.
    pairs = [(k, i) for k, state in enumerate(states) for i, (_, sign, _) in enumerate(rules)
             if not (state[4] and sign in (1, -1))]  # fmt: skip
    if not pairs:
        return None
    ks, rs = (np.array(column) for column in zip(*pairs, strict=True))
    sigma = np.array([float(sign) if sign in (1, -1) else (s if sign == RUDDER else -s)
                      for _, sign, _ in rules])[rs]  # fmt: skip
    G = sigma[:, None] * slopes[rs, :, ks]
    h = -sigma * fixed_slopes[rs, ks]
    carried = np.any(G != 0, axis=1)
    ks, rs, G, h = ks[carried], rs[carried], G[carried], h[carried]
    if not len(ks):
        return None
    scale = np.hypot(np.linalg.norm(G, axis=1), h)
    G, h = G / scale[:, None], h / scale
    keys = np.round(np.column_stack([rs, G, h]), 12)
    _, first, inverse = np.unique(keys, axis=0, return_index=True, return_inverse=True)
    inverse = inverse.reshape(-1)
    kept = np.sort(first)
    repeated = np.zeros(len(ks), dtype=bool)  # a row a rudder-only state repeats: every speed
    for j in np.flatnonzero(np.isin(np.arange(len(ks)), first, invert=True)):
        if states[ks[j]][4]:
            repeated[first[inverse[j]]] = True
    rows, rhs, labels = [], [], []
    for j in kept:
        u0, n0, u, n, _ = states[ks[j]]
        why = rules[rs[j]][2]
        if repeated[j]:
            where = "at every speed ahead"
        elif u > RUDDER_AHEAD_SHARES[-3] * u0:
            where = "far ahead, where its u² terms rule (the propeller all but stopped)"
        else:
            where = f"at {u:.3g} m/s" + (" with the propeller stopped" if n0 and not n else "")
        rows.append(np.append(G[j], 0.0))
        rhs.append(h[j])
        labels.append(f"{why} {where}")
    if not rows:
        return None
    return np.array(rows), np.array(rhs), labels


def stability_rows(options: PhysicsOptions, sway: Mapping[str, float], names: Sequence[str],
                   fixed: Mapping[str, float], logs: Sequence[pd.DataFrame],
                   ) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Straight-line stability of the yaw equation given the fitted sway equation ``sway``
    ({term: coefficient}): rows G over [free yaw terms ``names``; bias] and h with G z ≥ h for
    tr A ≤ −2μ and det A + μ tr A + μ² ≥ 0 (real parts ≤ −μ, μ = ``STABILITY_MARGIN`` |a11|) at
    each approach (``fixed`` yaw terms count as known)."""
    sway_terms = [t for t in sway if t != "1"]
    sway_coef = np.array([sway[t] for t in sway_terms])
    rows, rhs = [], []
    for u0, n0 in approach_states(options, logs, "stable"):
        a11, a12 = _straight_running_slopes(sway_terms, u0, n0) @ sway_coef
        g21, g22 = _straight_running_slopes(names, u0, n0)
        f21, f22 = (_straight_running_slopes(list(fixed), u0, n0) @ np.array(list(fixed.values()))
                    if fixed else (0.0, 0.0))  # fmt: skip
        # Both eigenvalues' real parts ≤ −μ ⇔ tr A ≤ −2μ and det A + μ tr A + μ² ≥ 0, with
        # tr A = a11 + g22·θ + f22 and det A = a11 (g22·θ + f22) − a12 (g21·θ + f21).
        mu = STABILITY_MARGIN * abs(a11)
        rows += [np.append(-g22, 0.0), np.append((a11 + mu) * g22 - a12 * g21, 0.0)]
        rhs += [a11 + f22 + 2 * mu,
                -((a11 + mu) * f22 - a12 * f21) - mu * a11 - mu * mu]
    return np.array(rows), np.array(rhs)


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
    states = approach_states(options, logs, "steady-speed")
    u0 = np.array([s[0] for s in states])
    n0 = np.array([s[1] for s in states])
    zero = np.zeros(len(states))
    rows = term_matrix(texts, u0, zero, zero, still_air(u0, zero, zero, n0))
    k = len(dof_terms)
    E = np.column_stack([rows[:, :k], np.full(len(states), 1.0 if has_constant else 0.0)])
    f = -(rows[:, k:] @ np.array([fixed[t] for t in fixed])) if fixed else np.zeros(len(states))
    return E, f, states


def held_note(dof: str, term: str, value: float, why: str | None, given: bool,
              past: str) -> str:
    """The note of a coefficient its bounds hold: given (the two bounds equal) or at a bound
    the ``past`` fit ("unconstrained fit", "unbounded refinement") would go past. The LS-SVM fit,
    output error and the refinement say it alike."""
    where = f"at {value:.4g}" if given else f"at its bound {value:.4g}"
    what = "given, not fitted" if given else f"the {past} goes past it"
    return (f"{dof}: {parse_term(term).display() or '1'} held {where}"
            + (f" ({why})" if why else "") + f": {what}")


def _unmet_at_zero(dof: str, term: str, bound: tuple[float, float], who: str
                   ) -> InfeasibleConstraintsError | None:  # fmt: skip
    """A structure (``who``) without ``term`` holds it at 0: None where 0 meets ``bound``, else
    the error that it cannot."""
    lo, hi = bound
    if lo <= 0.0 <= hi:
        return None
    return InfeasibleConstraintsError(f"bounds: {dof}: {term} [{lo:g}, {hi:g}] cannot be met: "
                                      f"{who} has no such term, so its coefficient is 0")


def bounds_held_by(options: PhysicsOptions | None,
                   structure: ModelStructure) -> PhysicsOptions | None:  # fmt: skip
    """``options`` for fitting ``structure`` where it was chosen, not given: a bound on a term
    it lacks is left out where 0 meets it (the structure holds the term at 0), and makes it
    infeasible where 0 does not (``InfeasibleConstraintsError``)."""
    if options is None or not options.bounds:
        return options
    kept: dict[str, dict[str, tuple[float, float]]] = {}
    for dof, terms in options.bounds.items():
        have = {parse_term(t).text for t in structure.terms.get(dof, ())}
        for term, (lo, hi) in terms.items():
            text = parse_term(term).text
            if text in have:
                kept.setdefault(dof, {})[term] = (lo, hi)
            elif (error := _unmet_at_zero(dof, text, (lo, hi), structure.name)) is not None:
                raise error
    return dataclasses.replace(options, bounds=kept or None)


def dof_physics(options: PhysicsOptions | None, dof: str, names: Sequence[str], has_constant: bool,
                fixed: Mapping[str, float], logs: Sequence[pd.DataFrame]) -> DofPhysics:  # fmt: skip
    """Prior, bounds and the steady-speed tie of one equation whose free regressors are
    ``names`` (canonical term texts, the constant excluded)."""
    p = len(names)
    out = DofPhysics(None, np.full(p, -math.inf), np.full(p, math.inf),
                     no_constant=not has_constant)
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
    if unknown and not options.bounds_where_present:
        raise ShipidError(f"bounds: {dof}: {', '.join(unknown)} is not a free term of the "
                          f"{dof} equation ({', '.join(names) or 'none'})")  # fmt: skip
    # A chosen structure without the term holds it at 0: within its bound, or outside it.
    for term in unknown:
        if (error := _unmet_at_zero(dof, term, user[term], "the structure")) is not None:
            raise InfeasibleConstraintsError(f"{error} (give a structure with it, --model)")
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
    if (options.rudder_ahead and dof in ("v", "r") and any("delta" in n for n in names)
            and rudder_sign(logs, options.rudder_positive) is None):  # fmt: skip
        out.notes.append(f"{dof}: rudder-ahead holds nothing: the logs do not state (or disagree "
                         "on) the rudder sign convention (--rudder-positive)")
    if options.derivatives or options.rudder_ahead:
        found = derivative_rows(options, dof, names, fixed, logs)
        if found is not None:
            out.inequalities, out.inequality_labels = found[:2], found[2]
        rudder_whys = tuple(why for eq, _, sign, why in DERIVATIVE_RULES
                            if eq == dof and sign in (RUDDER, "-" + RUDDER))  # fmt: skip
        if (options.rudder_ahead and rudder_whys
                and rudder_sign(logs, options.rudder_positive) is not None
                and not any(label.startswith(rudder_whys) for label in out.inequality_labels)):
            # Said, not silent: a structure whose free terms leave out δ took the flag and
            # held nothing (its held turns then go straight).
            out.notes.append(f"{dof}: rudder-ahead holds nothing: no free term of the {dof} "
                             "equation carries the rudder (∂/∂δ = 0 at every speed)")
    if options.steady_speed and dof == "u":
        E, f, out.approaches = _approach_rows(names, fixed, has_constant, options, logs)
        out.equalities = (E, f)
        where = ", ".join(f"{a:.4g} m/s at {b:.4g} rps" for a, b in out.approaches)
        carried = [a for a in ([options.approach] if isinstance(options.approach, Mapping)
                               else options.approach or ()) if "given_n" in a]  # fmt: skip
        if carried:
            where += ", the logs' one rps, where advance-ratio similarity puts the " + ", ".join(
                f"{a['given_u']:.4g} m/s at {a['given_n']:.4g} rps" for a in carried) + " given"
        out.notes.append(f"u: steady speed imposed on the approach ({where})")
    return out


# The constraints that are rows G z ≥ h on a fit's coefficients alone (no prior, no equality,
# not the stability rows, which hold the yaw equation given the sway one's fit): any model's
# coefficients can be checked against them after the fit, output error's too.
ROW_CONSTRAINTS = (("derivatives", "--constraints derivatives"),
                   ("rudder_ahead", "--constraints rudder-ahead"))


def without_rows(options: PhysicsOptions | None) -> PhysicsOptions | None:
    """``options`` less ``ROW_CONSTRAINTS``: what an output-error fit holds of them (its box
    bounds), to be checked against the rows after (``rows_unmet``)."""
    if options is None:
        return None
    return dataclasses.replace(options, **{name: False for name, _ in ROW_CONSTRAINTS})


def rows_unmet(options: PhysicsOptions, model, logs: Sequence[pd.DataFrame]) -> list[str]:
    """The rows of ``options``' ``derivatives`` and ``rudder_ahead`` that ``model``'s
    coefficients go past (labels as the fit names them, with the equation), beyond a rounding's
    size against the whole row: what a fit that does not hold them (output error, from the
    LS-SVM fit that does) must be checked against before it replaces that fit."""
    unmet = []
    for dof in model.structure.dofs:
        coef = model.coefficients[dof]
        names = [t for t in coef if t != "1"]
        found = derivative_rows(options, dof, names, {}, logs)
        if found is None:
            continue
        G, h, labels = found
        z = np.append([coef[t] for t in names], coef.get("1", 0.0))
        tol = 1e-7 * (np.linalg.norm(G, axis=1) * np.linalg.norm(z) + np.abs(h)) + 1e-300
        unmet += [f"{dof}: {label}" for label, slack, t in zip(labels, G @ z - h, tol,
                                                              strict=True) if slack < -t]
    return list(dict.fromkeys(unmet))


def unboxed(options) -> list[str]:
    """The options of ``options`` (a ``PhysicsOptions``, or anything with its ``prior``,
    ``steady_speed``, ``stable``, ``derivatives`` and ``rudder_ahead``: the command line checks
    its flags before it reads the logs) that are not box bounds on the coefficients (the
    command-line flags that give them), which an output-error fit does not hold: they are
    conditions on the equation-error regression (a prior on its weights, rows of its solver)."""
    if options is None:
        return []
    flags = (("prior", "--prior"), ("steady_speed", "--steady-speed"),
             ("stable", "--constraints stable"), *ROW_CONSTRAINTS)
    return [flag for name, flag in flags if getattr(options, name)]


def coefficient_bounds(options: PhysicsOptions | None, model, logs: Sequence[pd.DataFrame]
                       ) -> tuple[dict[str, dict[str, tuple[float, float]]],
                                  dict[str, dict[str, str]], list[str]]:  # fmt: skip
    """The sign rules and user bounds of ``options`` on every coefficient of ``model`` (a
    ``ManoeuvringModel``), as {dof: {term: (lower, upper)}} for the bounded ones, why each is
    bounded ({dof: {term: reason}}) and notes; the same table and errors as the LS-SVM fit's
    (``dof_physics``). Refused for options that are not box bounds (``unboxed``)."""
    left = unboxed(options)
    if left:
        raise ShipidError(f"an output-error fit holds sign constraints and --bound (box bounds on "
                          f"the coefficients), not {left[0]}")  # fmt: skip
    if options is None or not options.active:
        return {}, {}, []
    bounds: dict[str, dict[str, tuple[float, float]]] = {}
    reasons: dict[str, dict[str, str]] = {}
    notes: list[str] = []
    for dof, terms in model.coefficients.items():
        names = [t for t in terms if t != "1"]
        extra = dof_physics(options, dof, names, "1" in terms, {}, logs)
        notes += extra.notes
        for j, name in enumerate(names):
            if math.isfinite(extra.lower[j]) or math.isfinite(extra.upper[j]):
                bounds.setdefault(dof, {})[name] = (float(extra.lower[j]), float(extra.upper[j]))
                reasons.setdefault(dof, {})[name] = extra.reasons.get(name, "bound")
    return bounds, reasons, notes


def with_stability(extra: DofPhysics, options: PhysicsOptions | None, dof: str,
                   names: Sequence[str], fixed: Mapping[str, float],
                   fitted: Mapping[str, Mapping[str, float]], logs: Sequence[pd.DataFrame],
                   ) -> DofPhysics:  # fmt: skip
    """``extra`` with the straight-line stability rows of the yaw equation (``options.stable``,
    ``dof`` 'r', free terms ``names``, ``fixed`` ones), given the sway equation already in
    ``fitted`` ({dof: {term: coefficient}}); ``extra`` itself otherwise. A copy: the
    bootstrap's refits reuse ``extra``."""
    if options is None or not options.stable or dof != "r":
        return extra
    if "v" not in fitted:
        raise ShipidError("stable constraint: straight-line stability needs the sway equation "
                          "(v) fitted with the yaw one")  # fmt: skip
    G, h = stability_rows(options, fitted["v"], names, fixed, logs)
    labels = [STABILITY_LABEL] * len(h)
    if extra.inequalities is not None:
        G, h = np.vstack([extra.inequalities[0], G]), np.concatenate([extra.inequalities[1], h])
        labels = extra.inequality_labels + labels
    return dataclasses.replace(extra, inequalities=(G, h), inequality_labels=labels)


STABILITY_LABEL = "straight-line stability"


def inequality_notes(dof: str, extra: DofPhysics, coef: np.ndarray, bias: float) -> list[str]:
    """What the inequalities of ``extra`` did to the fit (coef, bias): a note per constraint that
    holds (the fit without it goes past it), none for those the fit meets freely."""
    if extra.inequalities is None:
        return []
    G, h = extra.inequalities
    z = np.append(coef, bias)
    # A row held at its limit has a slack of rounding size against the whole fit's (a held
    # coefficient is itself near 0, so its own size says nothing).
    tol = 1e-7 * (np.linalg.norm(G, axis=1) * np.linalg.norm(z) + np.abs(h)) + 1e-300
    held = [label for label, slack, t in zip(extra.inequality_labels, G @ z - h, tol,
                                             strict=True) if slack <= t]  # fmt: skip
    notes = []
    if STABILITY_LABEL in held:
        notes.append(f"{dof}: the fit without the stability constraint is straight-line unstable "
                     "at the approach; the yaw equation is held at its limit, given the sway "
                     f"equation (the slowest sway–yaw mode decays at {STABILITY_MARGIN:.0%} of "
                     "the sway damping rate |∂v̇/∂v|: barely stable)")  # fmt: skip
    notes += [f"{dof}: {label} held at 0: the unconstrained fit goes past it"
              for label in dict.fromkeys(held) if label != STABILITY_LABEL]  # fmt: skip
    return notes

"""Prior models for the physics-informed fit: from the ship's particulars (Clarke et al. 1983),
from a reference ship of ``shipid.vessels`` carried to the ship's length (``reference_prior``),
or from another model (an earlier fit of the same ship).

Clarke, D., Gedling, P. and Hine, G. (1983), The application of manoeuvring criteria in hull design
using linear theory, Trans. RINA 125, 45–68: regressions of the linear sway–yaw derivatives on
T/L, B/T, B/L and Cb over merchant hulls, in the prime system with ½ρL²U (forces) and ½ρL³U
(moments, and forces per r), S = π(T/L)²::

    Y′v = −S (1 + 0.40 Cb B/T)            Y′r = −S (−1/2 + 2.2 B/L − 0.08 B/T)
    N′v = −S (1/2 + 2.4 T/L)              N′r = −S (1/4 + 0.039 B/T − 0.56 B/L)
    Y′v̇ = −S (1 + 0.16 Cb B/T − 5.1 (B/L)²)      Y′ṙ = −S (0.67 B/L − 0.0033 (B/T)²)
    N′v̇ = −S (1.1 B/L − 0.041 B/T)               N′ṙ = −S (1/12 + 0.017 Cb B/T − 0.33 B/L)

The rudder: normal force F = ½ρ A_R U² f_α δ with f_α = 6.13 Λ/(Λ + 2.25) (Fujii), aspect ratio
Λ = 1.5, the rudder at x_R = −L/2 with hull interaction a_H = 0.2 at x_H = −0.45 L (MMG
standard method, Yasukawa & Yoshimura 2015), no propeller slipstream (the data correct that):
Yδ = −(1 + a_H) F/δ, Nδ = −(x_R + a_H x_H) F/δ for a rudder turning to starboard.

The linear model M (v̇, ṙ) = F(v, r, δ) with M = [[m − Yv̇, m x_G − Yṙ], [m x_G − Nv̇, I_z − Nṙ]]
and the rigid-body terms −m u r, −m x_G u r, solved for (v̇, ṙ), gives the acceleration-form
coefficients of u·v, u·r and u²·δ (or v, r, δ at the approach speed) of any structure that has
them; other terms get no prior (drawn toward 0 as without one). I_z = m (0.25 L)² + m x_G².

The rudder's normal force of one inflow (``rudder_normal``, U_R² sin α_R, ``--rudder-normal``)
is F/(½ρ A_R f_α): its side force cos δ·F takes the u²·δ coefficients above, and its drag sin δ·F
in u̇ takes −(1 − t_R) ½ρ A_R f_α / m with t_R = 0.3 (MMG's published values 0.2–0.4; the
KVLCC2's 0.387) and the surge's added mass left out (2–8 % of m on merchant hulls).
"""

from __future__ import annotations

import math
from functools import lru_cache

import numpy as np

from shipid.data.particulars import Particulars
from shipid.dynamics.model import ManoeuvringModel, ModelStructure
from shipid.dynamics.terms import parse_term, rudder_normal_angle
from shipid.errors import ShipidError

ASPECT_RATIO = 1.5
F_ALPHA = 6.13 * ASPECT_RATIO / (ASPECT_RATIO + 2.25)  # Fujii's normal-force slope [1/rad]
A_H, X_H, X_R = 0.2, -0.45, -0.5  # hull interaction, its position and the rudder's, in L
T_R = 0.3  # the rudder's drag less its resistance deduction: −(1 − t_R) F sin δ
# Terms of the acceleration form each linear coefficient maps to, with the power of the approach
# speed U0 the coefficient is multiplied by (v·U: power 0 on u·v, 1 on v alone, ...).
SPEED_TERMS = {
    "v": (("u*v", 0), ("|u|*v", 0), ("v*U", 0), ("v", 1)),
    "r": (("u*r", 0), ("|u|*r", 0), ("r*U", 0), ("r", 1)),
    "delta": (("u^2*delta", 0), ("|u|*u*delta", 0), ("U^2*delta", 0), ("delta", 2)),
}


def clarke_derivatives(p: Particulars) -> dict[str, float]:
    """Clarke et al. (1983) prime derivatives Y′v … N′ṙ from the particulars."""
    missing = [k for k in ("beam", "draught", "block_coefficient") if getattr(p, k) is None]
    if missing:
        raise ShipidError(f"the Clarke prior needs the particulars {', '.join(missing)}")
    L, B, T, Cb = p.length, p.beam, p.draught, p.block_coefficient
    S = math.pi * (T / L) ** 2
    return {
        "Yv": -S * (1 + 0.40 * Cb * B / T), "Yr": -S * (-0.5 + 2.2 * B / L - 0.08 * B / T),
        "Nv": -S * (0.5 + 2.4 * T / L), "Nr": -S * (0.25 + 0.039 * B / T - 0.56 * B / L),
        "Yvdot": -S * (1 + 0.16 * Cb * B / T - 5.1 * (B / L) ** 2),
        "Yrdot": -S * (0.67 * B / L - 0.0033 * (B / T) ** 2),
        "Nvdot": -S * (1.1 * B / L - 0.041 * B / T),
        "Nrdot": -S * (1 / 12 + 0.017 * Cb * B / T - 0.33 * B / L),
    }  # fmt: skip


def clarke_linear(p: Particulars, rudder_positive: str | None) -> dict[str, dict[str, float]]:
    """Acceleration-form linear coefficients {v, r} × {v, r, delta} per unit u (v̇ ≈ c_v u v +
    c_r u r + c_δ u² δ), the rudder's sign by ``rudder_positive`` (None: no rudder prior)."""
    d = clarke_derivatives(p)
    rho, L = p.rho, p.length
    m = p.mass if p.mass is not None else rho * p.volume
    xg = p.xg
    Iz = m * (0.25 * L) ** 2 + m * xg**2
    q = 0.5 * rho
    M = np.array([[m - q * L**3 * d["Yvdot"], m * xg - q * L**4 * d["Yrdot"]],
                  [m * xg - q * L**4 * d["Nvdot"], Iz - q * L**5 * d["Nrdot"]]])  # fmt: skip
    F = np.array([[q * L**2 * d["Yv"], q * L**3 * d["Yr"] - m],
                  [q * L**3 * d["Nv"], q * L**4 * d["Nr"] - m * xg]])  # fmt: skip
    acc = np.linalg.solve(M, F)
    out = {"v": {"v": acc[0, 0], "r": acc[0, 1]}, "r": {"v": acc[1, 0], "r": acc[1, 1]}}
    if rudder_positive is not None and p.rudder_area is not None:
        force = q * p.rudder_area * F_ALPHA  # per u² δ, for a rudder turning to starboard
        sign = 1.0 if rudder_positive == "starboard" else -1.0
        rud = np.linalg.solve(M, sign * force * np.array([-(1 + A_H), -(X_R + A_H * X_H) * L]))
        out["v"]["delta"], out["r"]["delta"] = rud[0], rud[1]
        out["u"] = {"drag": -(1 - T_R) * force / m}  # per U_R² sin α_R sin δ, either convention
    return {k: {kk: float(vv) for kk, vv in v.items()} for k, v in out.items()}


def clarke_prior(p: Particulars, structure: ModelStructure, speed: float,
                 rudder_positive: str | None = None) -> dict[str, dict[str, float]]:  # fmt: skip
    """Prior coefficients of ``structure`` from the particulars: its terms among
    ``SPEED_TERMS`` (at approach speed ``speed`` for the speed-free ones)."""
    if not speed > 0:
        raise ShipidError("the Clarke prior needs the approach speed (> 0)")
    linear = clarke_linear(p, rudder_positive)
    prior: dict[str, dict[str, float]] = {}
    for dof, terms in structure.terms.items():  # the rudder's normal force, of any inflow
        for text in terms:
            angle = rudder_normal_angle(text)
            if angle == "cos" and dof in ("v", "r") and "delta" in linear[dof]:
                prior.setdefault(dof, {})[text] = linear[dof]["delta"]
            elif angle == "sin" and dof == "u" and "u" in linear:
                prior.setdefault(dof, {})[text] = linear["u"]["drag"]
    for dof in ("v", "r"):
        if dof not in structure.terms:
            continue
        texts = {parse_term(t).text for t in structure.terms[dof]}
        for signal, options in SPEED_TERMS.items():
            if signal not in linear[dof]:
                continue
            # The first form the structure has takes the whole derivative: a structure with
            # two (u²δ and δ, u·v and v) would otherwise get it twice.
            for text, power in options:
                if parse_term(text).text in texts:
                    prior.setdefault(dof, {})[parse_term(text).text] = \
                        linear[dof][signal] * speed**power
                    break
    if not prior:
        raise ShipidError(f"the Clarke prior gives the u·v, u·r and u²·δ terms (or v, r, δ, or "
                          f"the rudder's normal force) of v̇ and ṙ; the structure "
                          f"{structure.name} has none of them")
    return prior


def rudder_drag(p: Particulars, speed: float, rps: float | None) -> float | None:
    """The surge's rudder drag per δ² [m/s² per rad², as u̇ = c δ²] at the straight approach
    (``speed`` [m/s], ``rps``): −(1 − t_R) ½ρ A_R f_α U_R² / m, the rudder's normal force of the
    module's note in the inflow U_R² = a u² + c n⁺² (``shipid.dynamics.rudder.inflow_speed``),
    sin α_R sin δ ≈ δ² straight ahead; None where the particulars lack the rudder's area, the
    propeller's diameter, the block coefficient or the mass."""
    from shipid.dynamics.rudder import inflow_speed

    mass = p.mass if p.mass is not None else (None if p.volume is None else p.rho * p.volume)
    if None in (p.rudder_area, p.propeller_diameter, p.block_coefficient, mass):
        return None
    a, c = inflow_speed(p)
    inflow = a * speed**2 + c * max(rps or 0.0, 0.0) ** 2
    return -(1 - T_R) * 0.5 * p.rho * p.rudder_area * F_ALPHA * inflow / mass


def rudder_parity(texts) -> dict[str, int]:
    """Per term, how it answers the rudder's sign (δ → −δ): +1 even (unchanged), −1 odd
    (negated), 0 neither (``pos(delta)``: one side of the rudder)."""
    from shipid.dynamics.terms import INPUT_SIGNALS, term_matrix

    texts = list(texts)
    rng = np.random.default_rng(0)
    n = 16
    signals = {s: rng.uniform(0.2, 1.5, n) * rng.choice([-1.0, 1.0], n)
               for s in ("u", "v", "r", *INPUT_SIGNALS)}  # fmt: skip
    inputs = {k: v for k, v in signals.items() if k in INPUT_SIGNALS}
    plus = term_matrix(texts, signals["u"], signals["v"], signals["r"], inputs)
    minus = term_matrix(texts, signals["u"], signals["v"], signals["r"],
                        {**inputs, "delta": -inputs["delta"]})  # fmt: skip
    return {t: 1 if np.allclose(minus[:, j], plus[:, j])
            else -1 if np.allclose(minus[:, j], -plus[:, j]) else 0
            for j, t in enumerate(texts)}  # fmt: skip


def mirrored_rudder(model: ManoeuvringModel) -> tuple[ManoeuvringModel, list[str]]:
    """``model`` in the other rudder convention (δ → −δ): the coefficients of terms odd in δ
    negate, of terms even in δ stay; a term neither (``rudder_parity`` 0) has no such twin and
    is dropped, named in the returned list."""
    parity = rudder_parity(model.structure.all_terms)
    dropped = [t for t, p in parity.items() if not p]
    keep = {d: tuple(t for t in ts if parity[t]) for d, ts in model.structure.terms.items()}
    coefs = {d: {t: parity[t] * c for t, c in model.coefficients[d].items() if parity[t]}
             for d in keep}  # fmt: skip
    return ManoeuvringModel(ModelStructure(model.structure.name, keep), coefs,
                            name=model.name), dropped  # fmt: skip


def prior_at_rps(prior: dict[str, dict[str, float]], structure: ModelStructure,
                 rps: float) -> dict[str, dict[str, float]]:  # fmt: skip
    """``prior`` with a value for each term of ``structure`` fitted at the one propeller speed
    ``rps`` that the prior holds in its advance-ratio similar form (a model file written for every
    rps: δ as n⁺²δ, the constant as |n|n; ``shipid.dynamics.similarity``): that term's value at
    ``rps``. Without it those terms had no prior, and were drawn toward 0."""
    from shipid.dynamics.similarity import similar_term

    def similar(dof: str, text: str) -> list[tuple[str, float]]:
        form, k = similar_term(text)
        return [(t, rps**k) for t in (form, *_thrust_twins(prior, dof, form))] if k else []

    return _from_twins(prior, structure, similar)


def _thrust_twins(prior: dict[str, dict[str, float]], dof: str, text: str) -> list[str]:
    """The prior's other forms of the surge's thrust ``text`` (``shipid.dynamics.astern``: a
    model file of logs that never reverse the propeller writes pos(n)² or |n|·n as
    propeller(k), the same term ahead); [] for any other term."""
    from shipid.dynamics.astern import AHEAD_THRUST

    if dof != "u":
        return []
    names = list(prior.get("u", {}))
    if text in AHEAD_THRUST:
        return [t for t in names if any(f.propeller for f in parse_term(t).factors)]
    if any(f.propeller for f in parse_term(text).factors):
        return [t for t in names if t in AHEAD_THRUST]
    return []


def prior_in_forms(prior: dict[str, dict[str, float]], structure: ModelStructure
                   ) -> dict[str, dict[str, float]]:  # fmt: skip
    """``prior`` with a value for each term of ``structure`` that the prior holds in its other
    ahead form (``shipid.dynamics.astern``: u·v and |u|·v in v̇, ..., the thrust pos(n)² or
    |n|·n and propeller(k)), the same term on logs that run ahead. A model file of such logs is
    written in the one form; a fit in the other had no prior on those terms, and drew them
    toward 0."""
    from shipid.dynamics.astern import AHEAD_FORMS, astern_form

    def other_form(dof: str, text: str) -> list[tuple[str, float]]:
        fitted = [f for (d, f), w in AHEAD_FORMS.items() if w == text and d in (dof, None)]
        return [(t, 1.0) for t in (astern_form(dof, text), *fitted,
                                   *_thrust_twins(prior, dof, text)) if t != text]

    return _from_twins(prior, structure, other_form)


def _from_twins(prior: dict[str, dict[str, float]], structure: ModelStructure, twins
                ) -> dict[str, dict[str, float]]:  # fmt: skip
    """``prior`` with, for each term of ``structure`` it lacks, the value of its first twin
    (``twins(dof, term)``: [(another form, factor)]) that the prior holds and the equation does
    not, times the factor."""
    out = {d: dict(v) for d, v in prior.items()}
    for dof, terms in structure.terms.items():
        given = out.get(dof, {})
        for text in terms:
            if text in given:
                continue
            found = next(((t, f) for t, f in twins(dof, text) if t in given and t not in terms),
                         None)  # fmt: skip
            if found is not None:
                out.setdefault(dof, {})[text] = given[found[0]] * found[1]
    return out


def prior_from_model(model: ManoeuvringModel) -> dict[str, dict[str, float]]:
    """A model's coefficients as a prior (e.g. a fit of other trials of the same ship)."""
    return {d: {parse_term(t).text: float(c) for t, c in model.coefficients[d].items()}
            for d in model.structure.dofs}  # fmt: skip


# The reference ship's trials a reference prior is fitted on: (kind, rudder [deg], heading
# [deg]) to each side, run for this many ship lengths' travel at the approach speed, sampled at
# this fraction of L/U. Noise-free, from the ship's own approach, with its own steering gear.
REFERENCE_TRIALS = (("zigzag", 10.0, 10.0), ("zigzag", 20.0, 20.0), ("turning", 35.0, None))
REFERENCE_LENGTHS = {"zigzag": 40.0, "turning": 30.0}
REFERENCE_STEP = 1 / 40


@lru_cache(maxsize=8)
def _reference_trials(name: str) -> tuple:
    """The reference ship's trials (``REFERENCE_TRIALS``, both sides) as canonical logs, and
    the ship; computed once per process."""
    from shipid.identification.correction import reference_file
    from shipid.trials.manoeuvres import turning_circle, zigzag
    from shipid.vessels import VESSELS, get_vessel

    ship = None if name in VESSELS else reference_file(name)  # an MMG file, a corrected ship
    if ship is None:
        try:
            ship = get_vessel(name)
        except ValueError as exc:
            raise ShipidError(str(exc)) from None
    # A propeller that follows the runs' rate turns at its trim for the approach.
    rps = {"rps": ship.dynamics.n_prop} if getattr(ship.dynamics, "uses_rps", False) else {}
    lu = ship.length / ship.approach_speed
    dt = lu * REFERENCE_STEP
    limit = math.degrees(ship.steering.max_angle) if ship.steering.max_angle else 35.0
    logs = []
    # Euler, the one-step regression's own discretisation: a ship whose dynamics are in the
    # structure gives its own coefficients back (from RK4 logs the paper's ship's v·r came 9 %
    # off, r² 0.28 where it has none: the regression's O(Δt) bias on near-collinear terms).
    for kind, rudder, heading in REFERENCE_TRIALS:
        rudder = min(rudder, limit)
        for side in ("starboard", "port"):
            duration = REFERENCE_LENGTHS[kind] * lu
            if kind == "zigzag":
                res = zigzag(ship, rudder, heading, first=side, duration=duration, dt=dt,
                             method="euler", **rps)  # fmt: skip
            else:
                res = turning_circle(ship, rudder, side=side, duration=duration, dt=dt,
                                     method="euler", **rps)  # fmt: skip
            if res.diverged:
                raise ShipidError(f"the reference ship {name}'s {res.log.attrs.get('manoeuvre')} "
                                  "diverged")  # fmt: skip
            logs.append(res.log)
    return tuple(logs), ship


def reference_prior(name: str, structure: ModelStructure, length: float,
                    rudder_positive: str | None = None) -> dict[str, dict[str, float]]:  # fmt: skip
    """Prior coefficients of ``structure`` for a ship ``length`` m long from the reference ship
    ``name`` of ``shipid.vessels`` (e.g. the KVLCC2 for a full-form tanker), or of a reference
    ship's file (an MMG model, ``shipid mmg``; a corrected ship, ``shipid correct``): the
    structure's
    terms fitted (LS-SVM, γ = 1e4) on the reference's noise-free 10°/10° and 20°/20° zig-zags
    and 35° turns to both sides, carried to ``length`` at equal Froude number
    (``shipid.dynamics.prime.froude_scaled``), the rudder in the ship's convention
    (``rudder_positive``; None, not known: the terms that change sign with the rudder's get no
    prior, as the Clarke prior's rudder without it).

    Only the terms the reference can give and whose prime coefficient does not depend on the
    speed it is taken at get a prior: those of u, v, r and δ alone (no propeller speed, wind or
    thrust: the reference's propeller and superstructure are not the ship's) of the second
    degree in speed (|u|u, v·r, r², u·v, u²·δ, the cross-flow drag, ...; not δ², δ or the
    constant, which hold the reference's own propeller loading). The others get none (drawn
    toward 0 as without a prior); those of them the reference's logs give, and each equation's
    constant, are fitted on the reference too, that the rest be unbiased."""
    from shipid.dynamics.prime import froude_scaled, lengthened_terms, prime_factor
    from shipid.identification.identify import identify

    if not (math.isfinite(length) and length > 0):
        raise ShipidError(f"a reference prior needs the ship's length (> 0), got {length!r}")
    logs, ship = _reference_trials(name)
    factor = length / ship.length
    # The structure's cross-flow terms on the reference's hull, and back.
    to_reference = lengthened_terms(structure.all_terms, 1 / factor)
    back = {v: k for k, v in to_reference.items()}

    def transferable(text: str) -> bool:
        term = parse_term(text)
        return math.isclose(prime_factor("r", term, 1.0, 1.0), prime_factor("r", term, 1.0, 2.0))

    # Fitted: every term the reference's logs give (the untransferable ones too, that the
    # others be unbiased), and the constant; a prior: the transferable ones.
    given = {d: tuple(to_reference.get(t, t) for t in ts if not parse_term(t).inputs)
             for d, ts in structure.terms.items()}  # fmt: skip
    terms = {d: ts + (("1",) if "1" not in ts else ()) for d, ts in given.items()
             if any(transferable(t) for t in ts)}  # fmt: skip
    if not terms:
        raise ShipidError(f"the structure {structure.name} has no term a reference ship can give "
                          "a prior for (second-degree terms of u, v, r and δ: |u|u, u·v, u²·δ, "
                          "...)")  # fmt: skip
    fit = identify(list(logs), model=ModelStructure(f"{name} reference", terms), gamma=1e4,
                   force=True).model  # fmt: skip
    scaled = froude_scaled(fit, factor)
    # In the ship's rudder convention, as a log of the other is converted; not known: only the
    # terms the rudder's sign leaves alone.
    if rudder_positive is not None and rudder_positive != ship.rudder_positive:
        scaled = mirrored_rudder(scaled)[0]
    parity = rudder_parity(scaled.structure.all_terms)
    prior: dict[str, dict[str, float]] = {}
    for dof, coefs in scaled.coefficients.items():
        for text, value in coefs.items():
            original = back.get(text, text)
            if original in structure.terms.get(dof, ()) and transferable(original) and (
                    rudder_positive is not None or parity[text] == 1):
                prior.setdefault(dof, {})[original] = float(value)
    return prior

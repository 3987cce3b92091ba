"""Semiphysical identification: per degree of freedom, the paper's regression (eqs. 11–12) fitted by a
linear-kernel LS-SVM (eqs. 14–15), mapped back to continuous-time coefficients (eq. 16 form)."""

from __future__ import annotations

import math
import warnings
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from shipid.data.log import (
    column_values,
    common_rudder_convention,
    refuse_other_ships,
    require_states,
    true_air_velocity,
)
from shipid.dynamics.model import (
    ManoeuvringModel,
    ModelStructure,
    coefficients_from_gamma,
    get_structure,
)
from shipid.dynamics.terms import parse_term, term_matrix
from shipid.errors import ShipidError
from shipid.evaluation.envelope import envelope
from shipid.identification.estimators import check_estimator_name, fit_linear
from shipid.identification.physics import (
    PhysicsOptions,
    dof_physics,
    held_note,
    inequality_notes,
    still_air,
    with_stability,
)
from shipid.identification.regression import (
    FORMS,
    RegressionProblem,
    per_log,
    regression_problem,
    shared_term_columns,
)
from shipid.lssvm.solvers import NumericalWarning

COLLINEAR_CORRELATION = 0.999
CONSTANT_VARIATION = 1e-3
# Equations per unknown (terms + the bias b) below which a fit is refused, and below which it is
# reported as thin: with fewer, the residual has too few degrees of freedom to mean anything.
MIN_EQUATIONS_PER_UNKNOWN = 3
FEW_EQUATIONS_PER_UNKNOWN = 10
# Condition number of the centred, equilibrated regressors above which the coefficients are not
# determined by the data (well-posed trials give 1.5–110: demo, KVLCC2, Esso).
MAX_CONDITION = 1e6


@dataclass
class Identification:
    """An identified model with the raw LS-SVM solution and its diagnostics."""

    model: ManoeuvringModel
    form: str
    gamma: float
    dt: float
    discrete: dict[str, dict] = field(default_factory=dict)  # dof → {"names", "gamma", "bias"}
    diagnostics: dict[str, dict] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)
    envelope: dict[str, list[float]] = field(default_factory=dict)  # training ranges
    estimator: str = "lssvm"
    physics: dict | None = None  # PhysicsOptions.describe() when priors/constraints were used


def _display(name: str) -> str:
    return parse_term(name).display() or "1"


def _diagnose(p: RegressionProblem, coef: np.ndarray, bias: float, gamma: float
              ) -> tuple[dict, list[str]]:  # fmt: skip
    """Conditioning, collinearity, standard errors and one-step R² of one DOF's regression."""
    X, y = p.X, p.y
    notes: list[str] = []
    mean, std = X.mean(axis=0), X.std(axis=0)
    constant = std <= CONSTANT_VARIATION * np.maximum(np.abs(mean), 1e-12)
    for j in np.flatnonzero(constant):
        notes.append(f"{p.dof}: term {_display(p.names[j])} is (nearly) constant in the data and "
                     "cannot be told apart from the constant term: not identifiable; drop or fix it")
    Xc = X - mean
    norms = np.linalg.norm(Xc, axis=0)
    scaled = Xc[:, ~constant] / norms[~constant]
    # Constant terms are reported above; the condition number is that of the varying ones.
    sv = np.linalg.svd(scaled, compute_uv=False) if scaled.shape[1] else np.array([1.0])
    rank_deficient = scaled.shape[1] > 0 and scaled.shape[0] - 1 < scaled.shape[1]
    cond = math.inf if rank_deficient or not sv[-1] > 0 else float(sv[0] / sv[-1])
    pairs = []
    if X.shape[1] >= 2:
        with np.errstate(invalid="ignore", divide="ignore"):
            C = np.corrcoef(X, rowvar=False)
        for i in range(X.shape[1]):
            for j in range(i + 1, X.shape[1]):
                if np.isfinite(C[i, j]):
                    pairs.append((p.names[i], p.names[j], float(C[i, j])))
        pairs.sort(key=lambda t: -abs(t[2]))
        for a, b, c in pairs:
            if abs(c) > COLLINEAR_CORRELATION:
                notes.append(f"{p.dof}: terms {_display(a)} and {_display(b)} are collinear in the "
                             f"data (ρ = {c:.4f}): their coefficients are poorly determined")
    fitted = X @ coef + bias
    resid = y - fitted
    dof_resid = max(len(y) - X.shape[1] - 1, 1)
    sigma2 = float(resid @ resid) / dof_resid
    G = Xc.T @ Xc
    A_inv = np.linalg.pinv(G + np.eye(G.shape[0]) / gamma)
    cov = sigma2 * A_inv @ G @ A_inv
    # A constant term's column is all bias: the data say nothing of its coefficient, which the
    # regulariser alone sets (to ~0, with a covariance of ~0). Its error is infinite, not tiny.
    se = np.where(constant, np.inf, np.sqrt(np.clip(np.diag(cov), 0, None)))
    increment = y - X[:, 0] if p.form == "paper" else y
    pred_increment = fitted - (X[:, 0] if p.form == "paper" else 0.0)
    ss_tot = float(np.sum((increment - increment.mean()) ** 2))
    r2 = 1.0 - float(np.sum((increment - pred_increment) ** 2)) / ss_tot if ss_tot > 0 else math.nan
    # Paper form: every continuous coefficient is Γ/Δk (the self term (Γ₀ − 1)/Δk), so is its error.
    scale = p.dt if p.form == "paper" else 1.0
    std_errors = {n: float(s) / scale for n, s in zip(p.names, se, strict=True)}
    return {
        "n_samples": int(len(y)),
        "constant_terms": [p.names[j] for j in np.flatnonzero(constant)],
        "condition_number": cond,
        "most_collinear": [{"terms": [a, b], "correlation": c} for a, b, c in pairs[:3]],
        "std_errors": std_errors,
        "one_step_r2": r2,
        "residual_std": math.sqrt(sigma2),
    }, notes


# Residual growth from the steady-speed equalities above which they are reported as a misfit.
EQUALITY_COST = 1.25
EQUALITY_TIME_CONSTANT_LOGS = 10.0


def _equality_cost(p: RegressionProblem, g, b, estimator, gamma, extra) -> list[str]:
    """A note when the equalities (steady speed) cost much of the equation's fit: the logs'
    approaches are then not steady states of one such equation."""
    import dataclasses

    free = dataclasses.replace(extra, equalities=None)
    g0, b0 = fit_linear(p.X, p.y, estimator, gamma, physics=free)
    ss = float(np.sum((p.y - p.X @ g - b) ** 2))
    ss0 = float(np.sum((p.y - p.X @ g0 - b0) ** 2))
    hint = ("the logs' approaches are not steady states of one surge equation (start the logs "
            "on a steady approach, or give one with --speed/--rps)")  # fmt: skip
    if ss0 > 0 and ss > EQUALITY_COST * ss0:
        return [f"{p.dof}: the steady-speed constraint raises the equation's residual "
                f"{ss / ss0:.3g}-fold: {hint}"]
    # Speed stability: ∂u̇/∂u < 0 on each approach, with a time constant 1/|∂u̇/∂u| within ten
    # times the logs' duration; else the speed has no equilibrium to return to.
    h = 1e-4
    longest = EQUALITY_TIME_CONSTANT_LOGS * p.dt * len(p.y)
    for u0, n0 in extra.approaches:
        speeds = np.array([u0 + h, u0 - h])
        rows = term_matrix(p.names, speeds, np.zeros(2), np.zeros(2),
                           still_air(speeds, np.zeros(2), np.zeros(2), np.full(2, n0)))
        slope = float((rows[0] - rows[1]) @ g / (2 * h))
        if not slope < -1.0 / longest:
            return [f"{p.dof}: with the steady-speed constraint the surge equation has no speed "
                    f"stability at {u0:.4g} m/s (∂u̇/∂u = {slope:.3g} 1/s): {hint}"]
    return []


def _check_sample_count(p: RegressionProblem, logs) -> list[str]:
    """Refuse a regression with too few equations for its unknowns (terms and the bias)."""
    unknowns = p.X.shape[1] + 1
    equations = len(p.y)
    need = MIN_EQUATIONS_PER_UNKNOWN * unknowns
    if equations < need:
        samples = need + len(logs)
        raise ShipidError(f"{p.dof}: {equations} equations ({equations + len(logs)} samples) for "
                          f"{unknowns} unknowns ({', '.join(_display(n) for n in p.names)} and the "
                          f"bias); identification needs at least {need} equations: {samples} "
                          f"samples, {samples * p.dt:.3g} s of log at Δk = {p.dt:g} s")
    if equations < FEW_EQUATIONS_PER_UNKNOWN * unknowns:
        return [f"{p.dof}: only {equations} equations for {unknowns} unknowns: the coefficients "
                "rest on little data"]
    return []


# An input varies when its 5–95 % range over the training logs exceeds this share of its
# 95th-percentile magnitude (the Esso Osaka's zig-zags at 10–16.7 rps: 0.40; a basin run's
# constant rps with its ripple: 0.004).
VARYING_INPUT = 0.1
_PROPULSION_INPUTS = (("n", "the propeller speed n", "rps", "--model blanke-rps or low-speed"),
                      ("thrust", "the thrust T", "N", "--model blanke-thrust"))  # fmt: skip


def spread(values: np.ndarray) -> float:
    """A signal's 5–95 % range over its typical magnitude (the 95th percentile of |x|); 0 for
    a signal that is zero or has no finite sample."""
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    if values.size == 0:
        return 0.0
    lo, hi = np.percentile(values, [5, 95])
    typical = float(np.percentile(np.abs(values), 95))
    return float(hi - lo) / typical if typical > 0 else 0.0


def varies(values: np.ndarray) -> bool:
    """Whether an input's ``spread`` exceeds ``VARYING_INPUT`` (non-finite samples ignored)."""
    return spread(values) > VARYING_INPUT


@dataclass(frozen=True)
class VaryingInput:
    """A propulsion input that varies in the training logs (``varies``)."""

    signal: str  # 'n' or 'thrust'
    what: str  # 'the propeller speed n'
    low: float
    high: float
    unit: str
    remedy: str  # the structures that hold it

    def describe(self) -> str:
        """'the propeller speed n varies (10 to 16.67 rps)'."""
        return f"{self.what} varies ({self.low:.4g} to {self.high:.4g} {self.unit})"


def varying_propulsion(logs) -> list[VaryingInput]:
    """The propulsion inputs that vary in ``logs``: n, and the thrust where no rps is logged (at
    a logged rps the thrust follows the ship's speed, as in HSVA's KVLCC2 run)."""
    has_rps = any("n" in log.columns for log in logs)
    out = []
    for signal, what, unit, remedy in _PROPULSION_INPUTS:
        columns = [column_values(log, signal, float) for log in logs if signal in log.columns]
        if not columns or (signal == "thrust" and has_rps):
            continue
        values = np.concatenate(columns)
        if varies(values):
            values = values[np.isfinite(values)]
            out.append(VaryingInput(signal, what, float(np.min(values)), float(np.max(values)),
                                    unit, remedy))  # fmt: skip
    return out


def _signals(structure: ModelStructure) -> set[str]:
    """The signals (states and inputs) the structure's terms read."""
    return {s for names in structure.terms.values() for n in names for s in parse_term(n).signals}


def unmodelled_inputs(logs, structure: ModelStructure) -> list[str]:
    """Notes for a propulsion input (n; the thrust where no rps is logged) that varies in the
    training logs while no term of the structure holds it: its effect is then spread over the
    other terms, and the model cannot follow a change of it (the paper's ``blanke`` fitted to
    the Esso Osaka's zig-zags at 10–16.7 rps and three random runs finds no steady speed, and
    turning circles 2.5–3.4 times too wide)."""
    used = _signals(structure)
    notes = [f"{found.describe()} in the training logs but no term of the structure holds it: "
             "its effect is lumped into the others and the model cannot follow a change of it; "
             f"use a structure with it ({found.remedy}), or choose terms with shipid select"
             for found in varying_propulsion(logs) if found.signal not in used]  # fmt: skip
    if not used & {"wind_speed", "wind_angle"}:
        wind = material_wind(logs)
        if wind is not None:
            notes.append(f"the logs carry a wind (true wind {wind[0]:.3g} m/s against the ship's "
                         f"{wind[1]:.3g} m/s, medians) but no term of the structure holds it: "
                         "its gusts are lumped into the others; add wind terms (+wind), or "
                         "choose terms with shipid select")  # fmt: skip
    return notes


def one_log_wind_note(logs, structure: ModelStructure) -> list[str]:
    """A note where one log with a material wind (``material_wind``) fits the structure's wind
    terms: its coefficients then rest on that log's gusts alone. Fitted from one Esso Osaka
    zig-zag file at a time they differ 4 to 13 times in magnitude from file to file (the
    surge's and the yaw's sin γ_A of the other sign than the nine files' fit in two files
    each), and the other logs' predictions with them. Held at Blendermann's published
    loaded-tanker coefficients (the lateral centroid at midships, 0.013 m from the model's), one
    file's fit predicted the other files' yaw rate closer (0.30 of its spread against 0.34) but
    not their turns (tactical diameters 30 % off in the median against 22 %); from two files the
    fitted wind did better than the textbook estimate held
    (``benchmarks/study_esso_wind_terms.py``). (A textbook estimate came closer on both, 0.26 and
    15 %, but its yaw lever was set after the nine files' fit had shown its sign.)"""
    used = _signals(structure)
    if len(logs) != 1 or not used & {"wind_speed", "wind_angle"}:
        return []
    wind = material_wind(logs)
    if wind is None:
        return []
    return [f"the wind's load is fitted from one log's gusts (true wind {wind[0]:.3g} m/s against "
            f"the ship's {wind[1]:.3g} m/s): from one Esso Osaka zig-zag file at a time its "
            "coefficients differ 4 to 13 times from file to file, and the other logs' predictions "
            "with them (benchmarks/study_esso_wind_terms.py); fit several logs (from two files "
            "the fitted wind predicted the others better than an estimate held), or hold the "
            "wind's terms at an estimate (--bound, both ways: Blendermann's published one "
            "brought the Esso's other zig-zags closer and its turns not)"]  # fmt: skip


# A true wind of at least this share of the ship's speed (medians over the logs) is named.
MATERIAL_WIND = 0.5


def material_wind(logs) -> tuple[float, float] | None:
    """(true wind, ship speed) [m/s], medians over the logs, when the logs carry a relative wind
    that is more than the ship's own motion: the true wind, −U_A (cos γ_A, sin γ_A) + (u, v) in
    the body frame, has a median of at least ``MATERIAL_WIND`` times the ship's speed (the Esso
    Osaka's pond: 1.0–2.2 m/s against 0.07–0.47 m/s; still air: 0); else None. Fitted on them
    with ``low-speed``, the held-out random runs' r error is 0.86 of their spread (four folds'
    mean), with ``low-speed+wind`` 0.53."""
    with_wind = [log for log in logs if {"wind_speed", "wind_angle"} <= set(log.columns)]
    if not with_wind:
        return None
    true, ship = [], []
    for log in with_wind:
        true.append(np.hypot(*true_air_velocity(log)))
        ship.append(np.hypot(column_values(log, "u", float), column_values(log, "v", float)))
    wind, speed = float(np.nanmedian(np.concatenate(true))), float(np.nanmedian(np.concatenate(ship)))
    if not wind >= MATERIAL_WIND * speed or not wind > 0:
        return None
    return wind, speed


def _check_rudder_excitation(logs, structure: ModelStructure, fixed: Mapping) -> None:
    """Refuse training data whose rudder never moves: no rudder term can be identified."""
    rudder_terms = sorted({n for dof, names in structure.terms.items() for n in names
                           if "delta" in parse_term(n).signals and n not in fixed.get(dof, {})})
    if not rudder_terms:
        return
    span = max(float(np.ptp(column_values(log, "delta"))) for log in logs)
    if span < math.radians(0.1):
        shown = ", ".join(_display(n) for n in rudder_terms)
        raise ShipidError(f"the rudder never moves in the training logs (range "
                          f"{math.degrees(span):.3g}°): no excitation, so {shown} cannot be "
                          "identified; train on a manoeuvre (zig-zag, turning circle) or drop/fix "
                          "the rudder terms")


# Ranges below which a log's sway velocity or yaw rate did not change [m/s, rad/s]: no sensor
# resolves them, so such a column was filled with a constant (v = 0 from a GNSS that gives only
# the speed over ground). A constant u is a run at constant speed, which a sway-yaw model may
# well be fitted to; v = r = 0 with the rudder amidships is a straight run, simulated exactly.
STILL_V, STILL_R, STILL_DELTA = 1e-6, 1e-8, math.radians(0.1)


def _check_states_measured(logs, structure: ModelStructure, names) -> None:
    """Refuse a training log that turns with a constant v, or whose rudder or sway moves with a
    constant r: that state was not measured. Alone, every term of it would be 0 ± ∞; beside
    other logs, its false values would pull the fit."""
    used = set(structure.dofs) | _signals(structure)
    names = names or [f"log {i + 1}" for i in range(len(logs))]
    for log, name in zip(logs, names, strict=False):
        span = per_log(log, "span of delta, v, r", lambda log=log: {
            c: float(np.ptp(column_values(log, c, float))) for c in ("delta", "v", "r")})
        if "v" in used and span["v"] < STILL_V and span["r"] >= STILL_R:
            why, hint = "v", ("the ship turns, so it drifts: derive u, v from the track (x, y "
                              "or lat, lon) with --velocities-from-track")  # fmt: skip
        elif "r" in used and span["r"] < STILL_R and (span["v"] >= STILL_V
                                                      or span["delta"] >= STILL_DELTA):
            why, hint = "r", ("the ship is steered, so it turns: give the gyro's or the IMU's "
                              "yaw rate")  # fmt: skip
        else:
            continue
        raise ShipidError(f"{name}: column {why!r} is {float(log[why].iloc[0]):.4g} throughout: "
                          f"it was not measured, and its terms cannot be identified; {hint}")


def _prepare(logs, model, form, gamma, drop, fixed, names, estimator, physics):
    """identify's checks and its per-equation regression problems: (logs in one rudder
    convention, structure, fixed terms, problems by DOF, notes)."""
    if isinstance(logs, pd.DataFrame):
        logs = [logs]
    if not logs:
        raise ShipidError("no training logs given")
    require_states(logs, names, "training log")  # the regressors read every state
    refuse_other_ships(logs, names)
    logs, convention_notes = common_rudder_convention(list(logs))
    if form not in FORMS:
        raise ShipidError(f"unknown form {form!r}; use one of {', '.join(FORMS)}")
    if not (isinstance(gamma, int | float) and math.isfinite(gamma) and gamma > 0):
        raise ShipidError(f"--gamma must be > 0, got {gamma!r}")
    check_estimator_name(estimator)
    if physics is not None and physics.active and form != "increment":
        raise ShipidError("priors and constraints act on the continuous-time coefficients of "
                          "the increment form; use --form increment")  # fmt: skip
    try:
        structure = get_structure(model) if isinstance(model, str) else model
        if drop:
            structure = structure.without(drop)
    except ValueError as exc:
        raise ShipidError(str(exc)) from None
    fixed = {d: {parse_term(k).text: float(c) for k, c in v.items()}
             for d, v in (fixed or {}).items()}  # fmt: skip
    _check_states_measured(logs, structure, names)
    notes: list[str] = list(convention_notes)
    problems = {}
    for dof in structure.dofs:
        p = regression_problem(logs, structure, dof, form, fixed.get(dof), names)
        if p.X.shape[1] == 0:
            raise ShipidError(f"{dof}: no free terms to identify")
        notes += _check_sample_count(p, logs)
        problems[dof] = p
    _check_rudder_excitation(logs, structure, fixed)
    notes += unmodelled_inputs(logs, structure) + one_log_wind_note(logs, structure)
    return logs, structure, fixed, problems, notes


def _check_weights(sample_weight, problems) -> np.ndarray | None:
    if sample_weight is None:
        return None
    rows = next(iter(problems.values())).X.shape[0]
    sample_weight = np.asarray(sample_weight, dtype=float)
    if sample_weight.shape != (rows,) or not np.all(np.isfinite(sample_weight)) \
            or np.any(sample_weight < 0):
        raise ShipidError(f"sample_weight must be {rows} finite weights ≥ 0 (one per "
                          "equation), got shape " + str(sample_weight.shape))  # fmt: skip
    return sample_weight


def _model_name(structure: ModelStructure, form: str) -> str:
    return f"identified ({structure.name}, {form} form)"


def _dof_coefficients(dof: str, p: RegressionProblem, g: np.ndarray, b: float, form: str,
                      fixed_dof: Mapping[str, float] | None, structure: ModelStructure,
                      ) -> tuple[tuple[str, ...], dict[str, float], float]:  # fmt: skip
    """One equation's terms and continuous-time coefficients from the fitted Γ and b (eq. 14:
    the paper form's Γ divided by Δk), and the constant the bias gives."""
    c: dict[str, float] = dict(fixed_dof or {})
    if form == "paper":
        c.update(coefficients_from_gamma(dof, p.names, g, p.dt))
        bias_const = b / p.dt
    else:
        c.update(dict(zip(p.names, g.tolist(), strict=True)))
        bias_const = b
    if p.has_constant:
        c["1"] = bias_const
    order = list(structure.terms[dof])
    if dof in c and dof not in order:
        order.insert(0, dof)
    return tuple(order), {n: c.get(n, 0.0) for n in order}, bias_const


def weighted_refit(
    logs: Sequence[pd.DataFrame] | pd.DataFrame,
    model: str | ModelStructure = "blanke",
    form: str = "increment",
    gamma: float = 1e4,
    drop: Mapping[str, Sequence[str]] | None = None,
    fixed: Mapping[str, Mapping[str, float]] | None = None,
    names: Sequence[str] | None = None,
    estimator="lssvm",
    physics: PhysicsOptions | None = None,
) -> Callable[[np.ndarray | None], ManoeuvringModel]:
    """The ``fit(weights) -> model`` a bootstrap calls (``shipid.identification.uncertainty``):
    ``identify(..., force=True, sample_weight=weights).model`` to the bit, with the checks, the
    regression problems and the physics built once (rebuilding the problems from the logs'
    columns was most of a refit's time) and no diagnostics per refit."""
    logs, structure, fixed, problems, _ = _prepare(logs, model, form, gamma, drop, fixed, names,
                                                   estimator, physics)  # fmt: skip
    extras = {dof: dof_physics(physics, dof, p.names, p.has_constant, p.fixed, logs)
              for dof, p in problems.items()}  # fmt: skip

    def fit(weights: np.ndarray | None) -> ManoeuvringModel:
        weights = _check_weights(weights, problems)
        terms, coefs = {}, {}
        for dof, p in problems.items():
            extra = with_stability(extras[dof], physics, dof, p.names, p.fixed, coefs, logs)
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", NumericalWarning)  # the point fit reports them
                g, b = fit_linear(p.X, p.y, estimator, gamma, weights, physics=extra)
            terms[dof], coefs[dof], _ = _dof_coefficients(dof, p, g, b, form, fixed.get(dof),
                                                          structure)  # fmt: skip
        return ManoeuvringModel(ModelStructure(structure.name, terms), coefs,
                                name=_model_name(structure, form))  # fmt: skip

    return fit


def identify(
    logs: Sequence[pd.DataFrame] | pd.DataFrame,
    model: str | ModelStructure = "blanke",
    form: str = "increment",
    gamma: float = 1e4,
    drop: Mapping[str, Sequence[str]] | None = None,
    fixed: Mapping[str, Mapping[str, float]] | None = None,
    names: Sequence[str] | None = None,
    force: bool = False,
    estimator="lssvm",
    physics: PhysicsOptions | None = None,
    sample_weight: np.ndarray | None = None,
) -> Identification:
    """Identify a manoeuvring model from one or several canonical logs.

    Parameters
    ----------
    logs : canonical log(s) with the same uniform sampling time Δk.
    model : structure name (see ``shipid.model.BASE_STRUCTURES``) or a structure.
    form : 'increment' (default; the ξ(k) coefficient fixed to 1) or 'paper' (eqs. 11–12 as printed).
    gamma : LS-SVM regularisation γ > 0 (the paper selects 10⁴).
    drop : terms to leave out, e.g. {"u": ["r^2"]} as in the paper.
    fixed : terms held at given continuous-time values, e.g. {"u": {"delta^2": 0.0}}.
    force : keep a fit whose regressors are nearly dependent (condition number > ``MAX_CONDITION``)
        instead of refusing it; it is still reported.
    estimator : 'lssvm' (the paper's, default), 'ols', 'ridge', 'lasso', 'svr' or a
        scikit-learn linear regressor (see ``shipid.identification.estimators``).
    physics : a prior, sign constraints, bounds, steady speed (``PhysicsOptions``; increment
        form, lssvm or ols). Coefficients held at a bound are reported.
    sample_weight : a weight per equation (the logs' samples but the last of each, in order):
        bootstrap multiplicities (``shipid.identification.uncertainty``).

    Fewer than ``MIN_EQUATIONS_PER_UNKNOWN`` equations per unknown are always refused.
    """
    logs, structure, fixed, problems, notes = _prepare(logs, model, form, gamma, drop, fixed,
                                                       names, estimator, physics)  # fmt: skip
    sample_weight = _check_weights(sample_weight, problems)
    coefs: dict[str, dict[str, float]] = {}
    terms: dict[str, tuple[str, ...]] = {}
    discrete: dict[str, dict] = {}
    diagnostics: dict[str, dict] = {}
    dt = math.nan
    for dof, p in problems.items():
        dt = p.dt
        extra = with_stability(dof_physics(physics, dof, p.names, p.has_constant, p.fixed, logs),
                               physics, dof, p.names, p.fixed, coefs, logs)  # fmt: skip
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", NumericalWarning)
            g, b = fit_linear(p.X, p.y, estimator, gamma, sample_weight, physics=extra)
        diagnostics[dof], dof_notes = _diagnose(p, g, b, gamma)
        notes += inequality_notes(dof, extra, g, b)
        held = [] if extra.active is None else [n for n, a in zip(p.names, extra.active,
                                                                   strict=True) if a]  # fmt: skip
        diagnostics[dof]["at_bound"] = held
        notes += extra.notes + [
            held_note(dof, n, g[j], extra.reasons.get(n, "bound"),
                      extra.lower[j] == extra.upper[j], "unconstrained fit")
            for j, n in ((p.names.index(n), n) for n in held)]  # fmt: skip
        if extra.equalities is not None and sample_weight is None:
            notes += _equality_cost(p, g, b, estimator, gamma, extra)
        cond = diagnostics[dof]["condition_number"]
        if not cond <= MAX_CONDITION:
            message = (f"{dof}: the regressors {', '.join(_display(n) for n in p.names)} are "
                       f"nearly linearly dependent in these logs (condition number {cond:.3g} > "
                       f"{MAX_CONDITION:g}): their coefficients are not determined by the data; "
                       "train on more varied trials or drop terms")  # fmt: skip
            if not force:
                raise ShipidError(message + " (or insist with --force)")
            notes.append(message + " (kept: --force)")
        notes += dof_notes + [f"{dof}: {w.message}" for w in caught
                              if issubclass(w.category, NumericalWarning)]  # fmt: skip
        terms[dof], coefs[dof], bias_const = _dof_coefficients(dof, p, g, b, form,
                                                               fixed.get(dof), structure)
        if not p.has_constant and abs(bias_const) > 0:
            notes.append(f"{dof}: the model has no constant term; the LS-SVM bias "
                         f"b = {b:.4g} is reported but not part of the model")
        # Γ as fitted; the constant regressor's weight is Σα = 0, the bias b carries it (eq. 5).
        const = ["1"] if p.has_constant else []
        discrete[dof] = {"names": list(p.names) + const, "gamma": g.tolist() + [0.0] * len(const),
                         "bias": b}  # fmt: skip
    model = ManoeuvringModel(ModelStructure(structure.name, terms), coefs,
                             name=_model_name(structure, form))  # fmt: skip
    return Identification(model, form, float(gamma), dt, discrete, diagnostics, notes,
                          _envelope(logs), estimator if isinstance(estimator, str)
                          else type(estimator).__name__,
                          physics.describe() if physics is not None and physics.active
                          else None)  # fmt: skip


def _envelope(logs: Sequence[pd.DataFrame]) -> dict[str, list[float]]:
    """``envelope(logs)`` from each log's own, computed once per log where the logs are fitted
    again and again (``shared_term_columns``): the smallest of the minima, the largest of the
    maxima."""
    out: dict[str, list[float]] = {}
    for log in logs:
        for s, (lo, hi) in per_log(log, "envelope", lambda log=log: envelope([log])).items():
            bounds = out.setdefault(s, [lo, hi])
            bounds[0], bounds[1] = min(bounds[0], lo), max(bounds[1], hi)
    return out


def averaged_model(
    logs: Sequence[pd.DataFrame] | pd.DataFrame,
    members: Sequence[tuple[ModelStructure, float, float]],
    first: ModelStructure | None = None,
    name: str = "",
    **options,
) -> ManoeuvringModel:
    """The candidates ``members`` ((structure, γ, weight) each) fitted on ``logs`` by
    ``identify(logs, model=structure, gamma=γ, force=True, **options)``, their coefficients
    averaged with the weights (a candidate's coefficient of a term it lacks is 0): bagging the
    choice of terms, as ``select --average`` does. Terms: ``first``'s, then the others'. Each
    member is fitted by ``weighted_refit`` (the same model to the bit, without the diagnostics
    no one reads here: a third of an average's time)."""
    if not members:
        raise ShipidError("an average of candidates needs at least one candidate")
    total = float(sum(w for _, _, w in members))
    if not total > 0:
        raise ShipidError("the candidates' weights must add up to more than 0")
    weights = options.pop("sample_weight", None)
    with shared_term_columns():
        fits = [(weighted_refit(logs, model=s, gamma=g, **options)(weights), w / total)
                for s, g, w in members]  # fmt: skip
    return average_models(fits, first, name)


def average_models(fits: Sequence[tuple[ManoeuvringModel, float]],
                   first: ModelStructure | None = None, name: str = "") -> ManoeuvringModel:
    """The weighted average of fitted models ((model, weight) each, weights adding up to 1) on
    the union of their terms (``first``'s first); a term a model lacks counts 0."""
    structure = (first or fits[0][0].structure).union(*(m.structure.terms for m, _ in fits),
                                                      name=name or "average")  # fmt: skip
    coefficients = {d: {t: sum(w * m.coefficients.get(d, {}).get(t, 0.0) for m, w in fits)
                        for t in ts} for d, ts in structure.terms.items()}  # fmt: skip
    return ManoeuvringModel(structure, coefficients, name=name or "average")

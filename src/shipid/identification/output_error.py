"""Maximum-likelihood output error: coefficients, their standard errors and an ensemble for
prediction bands, from the free-run fit of the model to the measured states.

The LS-SVM (paper eqs. 11–12) regresses accelerations differenced from the measured states on
regressors built from the same noisy states. Noise in the regressors biases every such estimate
(errors in variables), and no prefilter removes the bias without adding its own; a bootstrap of
the equations then measures the variance around the biased value, so its intervals miss the truth
(36 % coverage on the paper's ship; ``benchmarks/study_uncertainty.py``).

Output error has no noisy regressor. The model is simulated from estimated initial states, driven
by the measured rudder (and propeller) inputs, and compared with the measured states: with white
measurement noise ε on state ξ,

    ξ_meas(k) = ξ_sim(k; θ, x₀) + ε_ξ(k),    ε_ξ ~ N(0, σ_ξ²)

and the maximum-likelihood estimate minimises

    J(θ, x₀) = Σ_logs Σ_k Σ_ξ ((ξ_meas(k) − ξ_sim(k; θ, x₀)) / σ_ξ)²

with each log's initial state x₀ = (u, v, r)(t₀) a nuisance parameter (a measured initial state
carries its noise into the whole run). σ_ξ is estimated from the residuals (two passes: first
from the first differences of the measurements). Started from the LS-SVM model, minimised by
Levenberg–Marquardt (``scipy.optimize.least_squares``) with a finite-difference Jacobian whose
columns are simulated in one compiled batch.

Standard errors are those of the Gauss–Newton covariance s² (JᵀJ)⁻¹ (s² the residual variance
per degree of freedom). They assume white residuals; where the residuals are correlated (model
error rather than sensor noise, e.g. on real ships) the covariance is multiplied by
(1 + ρ)/(1 − ρ), ρ the largest lag-1 autocorrelation of the states' residuals, the variance
inflation of a mean of AR(1) errors, and a warning says so. Ensemble members for prediction bands
and index intervals are Gaussian draws from the coefficient covariance.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence

import numpy as np
import pandas as pd

from shipid.blas import blas_threads
from shipid.data.log import column_values
from shipid.dynamics.model import DOFS, ManoeuvringModel
from shipid.dynamics.simulate import METHODS, DivergenceBounds, run_kernel
from shipid.errors import ShipidError
from shipid.identification.refine import (
    DIVERGED_RESIDUAL,
    SHOT_STATES,
    FreeCoefficients,
    Refinement,
    bound_vectors,
    compare_free_runs,
    cut_logs,
    with_coefficients,
)
from shipid.identification.uncertainty import LEVEL, Ensemble

METHOD = "maximum-likelihood output error"
DRAWS_METHOD = "Gaussian draws from the output-error covariance"
# Covariance inflation above which the residuals are reported as model error, not noise.
INFLATION_WARNING = 2.0
# Where the equation-error fit's free runs stay within this many times the sensors' white noise
# in every state of every training log, what is left is noise, and output error (maximum
# likelihood under white noise) is the fit ``identify`` makes by default. On the paper's ship
# at its sensor noise the LS-SVM's free runs are 0.96–1.29 times it; on real logs 3.5–4000
# times (model error: the KVLCC2's and the Esso Osaka's), where output error's residuals are
# correlated and its fit no better than the LS-SVM's.
NOISE_DOMINATES = 2.0
# Relative forward-difference step of the Jacobian (coefficients; initial states absolute).
REL_STEP = 1e-6


def _noise_from_differences(measured: np.ndarray, mask: np.ndarray) -> np.ndarray:
    """First guess of the noise std per state: first differences of a smooth signal are noise
    (√2 σ) plus a small change of the state itself."""
    d = np.concatenate([np.diff(measured[b, mask[b]], axis=0) for b in range(measured.shape[0])])
    return np.maximum(np.std(d, axis=0) / math.sqrt(2.0), 1e-12)


def noise_ratios(model: ManoeuvringModel, logs: Sequence[pd.DataFrame],
                 method: str = "euler") -> pd.DataFrame:
    """Per log and state (u, v, r the model fits), the free-run error std of ``model`` from
    the log's measured start over the white noise of the measured state (its std from second
    differences, ``shipid.data.preprocess.white_noise_variance``): 1 where the model explains
    the log down to its noise; inf for a noise-free state the model misses, 1 where it does
    not; a run that diverges counts inf."""
    from shipid.data.preprocess import white_noise_variance
    from shipid.dynamics.simulate import simulate_log

    states = [s for s in SHOT_STATES if s in model.structure.dofs]
    rows = []
    for log in logs:
        run = simulate_log(model, log, method=method)
        row = {}
        for s in states:
            measured = column_values(log, s, float)
            noise = math.sqrt(white_noise_variance(measured))
            err = float(np.std(measured[: len(run.log)] - column_values(run.log, s)))
            if run.diverged:
                row[s] = math.inf
            elif noise > 0:
                row[s] = err / noise
            else:
                row[s] = 1.0 if err <= 1e-12 * max(1.0, float(np.abs(measured).max())) else math.inf
        rows.append(row)
    return pd.DataFrame(rows, index=[log.attrs.get("name", f"log {i}")
                                     for i, log in enumerate(logs)])  # fmt: skip


def noise_dominates(ratios: pd.DataFrame) -> bool:
    """Whether what the equation-error fit leaves is the sensors' noise (``NOISE_DOMINATES``)."""
    return bool(np.isfinite(ratios.to_numpy()).all() and ratios.to_numpy().max() <= NOISE_DOMINATES)


def output_error(
    model: ManoeuvringModel,
    logs: Sequence[pd.DataFrame] | pd.DataFrame,
    method: str = "euler",
    max_nfev: int = 200,
    names: Sequence[str] | None = None,
    draws: int = 200,
    seed: int = 0,
    bounds: Mapping[str, Mapping[str, tuple[float, float]]] | None = None,
    reasons: Mapping[str, Mapping[str, str]] | None = None,
) -> tuple[Refinement, Ensemble]:
    """Maximum-likelihood output-error estimate of ``model``'s coefficients from ``logs``.

    Parameters
    ----------
    model : the starting model (the LS-SVM fit); its structure is kept, all coefficients fitted.
    logs : the training logs, unfiltered (the estimate needs the noise as it was measured).
    method : the model's integration scheme, 'euler' (the paper's, eq. 11) or 'rk4'.
    max_nfev : cap on cost evaluations of each of the two passes.
    draws : members of the ensemble drawn from the coefficient covariance (≥ 10).
    seed : random seed of the draws.
    bounds : {dof: {term: (lower, upper)}} box bounds on coefficients (sign constraints, user
        bounds: ``shipid.identification.physics.coefficient_bounds``), held by a trust-region
        reflective fit instead of Levenberg–Marquardt. A coefficient the fit holds at its bound
        keeps the standard error of the unbounded information matrix; its interval and the
        ensemble's draws are cut at the bound.
    reasons : {dof: {term: why}} of the bounds, named in the note of a coefficient held at one.

    Returns
    -------
    The fit as a ``Refinement`` (``method`` and ``statistics``: noise, standard errors,
    covariance, initial states, residual autocorrelation) and the ensemble of draws.
    """
    from shipid.data.log import require_frames
    from shipid.dynamics.simulate import require_dynamics

    require_dynamics(model)
    logs = require_frames(logs, names, "log to fit")
    if not logs:
        raise ShipidError("no training logs given for the output-error fit")
    if method not in METHODS:
        raise ShipidError(f"method must be one of {METHODS}, got {method!r}")
    if not (isinstance(draws, int) and draws >= 10):
        raise ShipidError(f"the output-error ensemble needs at least 10 draws, got {draws!r}")
    names = list(names or [log.attrs.get("name", f"log {i}") for i, log in enumerate(logs)])
    states = tuple(d for d in SHOT_STATES if d in model.structure.dofs)
    if not states:
        raise ShipidError("the model fits none of u, v, r: nothing to compare a free run with")
    for s in states:
        missing = [n for n, log in zip(names, logs, strict=True) if s not in log.columns]
        if missing:
            raise ShipidError(f"{missing[0]}: no {s!r} column to fit")
    seg, dt, seg_len = cut_logs(logs, names, None, states, model)
    B, L = seg.inputs.shape[:2]
    n_states = len(states)
    state_col = [SHOT_STATES.index(s) for s in states]

    slots = FreeCoefficients.of(model, bounds)
    rows, cols = slots.rows, slots.cols
    n_coef = len(rows)
    x0 = np.concatenate([model.theta[rows, cols], seg.shot0[:, state_col].ravel()])
    p = x0.size
    lower, upper = bound_vectors(model, rows, cols, bounds, p, skip=slots.given)
    bounded = bool(np.isfinite(lower).any() or np.isfinite(upper).any())
    x0 = np.clip(x0, lower, upper)  # an unconstrained start moved onto the feasible set
    n_obs = int(seg.mask.sum()) * n_states
    if n_obs <= p:
        raise ShipidError(f"the logs hold {n_obs} measured values for {p} parameters (the "
                          "coefficients and each log's initial state); give longer logs")  # fmt: skip
    s0_base = np.zeros((B, 6))
    s0_base[:, :3] = seg.shot0
    s0_base[:, 3] = seg.psi0
    speed_lim, yaw_lim = DivergenceBounds().resolved(float(np.max(np.abs(seg.shot0[:, 0]))))
    alive_grid = np.arange(L)[None, None, :]

    def simulate(X: np.ndarray) -> np.ndarray:
        """States (K, B, L, n_states) of K parameter vectors; diverged samples NaN."""
        K = X.shape[0]
        theta = np.broadcast_to(slots.theta, (K, B, *model.theta.shape)).copy()
        theta[:, :, rows, cols] = X[:, None, :n_coef]
        s0 = np.broadcast_to(s0_base, (K, B, 6)).copy()
        s0[:, :, state_col] = X[:, n_coef:].reshape(K, B, n_states)
        inputs = np.broadcast_to(seg.inputs, (K, *seg.inputs.shape)).reshape(K * B, L, -1)
        out, n_valid = run_kernel(model.code, theta.reshape(K * B, *model.theta.shape), seg.t,
                                  inputs, s0.reshape(K * B, 6), method, speed_lim,
                                  yaw_lim)  # fmt: skip
        sim = out.reshape(K, B, L, 6)[..., state_col]
        sim[alive_grid >= n_valid.reshape(K, B)[:, :, None]] = np.nan
        return sim

    def weighted(sim: np.ndarray, sigma: np.ndarray) -> np.ndarray:
        res = (sim - seg.measured) / sigma
        res[np.isnan(res)] = DIVERGED_RESIDUAL
        res[..., ~seg.mask, :] = 0.0
        return res.reshape(sim.shape[0], -1)

    def residuals(z: np.ndarray, sigma: np.ndarray) -> np.ndarray:
        return weighted(simulate(z[None]), sigma)[0]

    def jacobian(z: np.ndarray, sigma: np.ndarray) -> np.ndarray:
        """Forward differences, every column's free run in one batch."""
        h = np.concatenate([REL_STEP * np.maximum(np.abs(z[:n_coef]), 1e-3),
                            np.full(p - n_coef, 1e-7)])  # fmt: skip
        r = weighted(simulate(np.vstack([z, z + np.diag(h)])), sigma)
        return ((r[1:] - r[0]) / h[:, None]).T

    from scipy.optimize import least_squares  # 0.2 s of import: only when asked

    sigma = _noise_from_differences(seg.measured, seg.mask)
    x, nfev = x0, 0
    solver = {"method": "trf", "bounds": (lower, upper)} if bounded else {"method": "lm"}
    for _ in range(2):  # the second pass with the noise the first one's residuals show
        # The trust-region steps are BLAS SVDs: OpenBLAS's threads, left spinning between them,
        # slowed the compiled free runs on 2 cores 4-fold (the bounded fit took 10 times the
        # free one's 0.025 s on the paper's zig-zag; ``benchmarks/bench_physics.py``).
        with blas_threads(1):
            fit = least_squares(residuals, x, jac=jacobian, x_scale="jac", max_nfev=max_nfev,
                                args=(sigma,), **solver)  # fmt: skip
        x, nfev = fit.x, nfev + int(fit.nfev)
        raw = simulate(x[None])[0] - seg.measured
        raw[..., ~seg.mask, :] = np.nan
        per_state = np.sum(seg.mask) - p / n_states
        sigma = np.maximum(np.sqrt(np.nansum(raw**2, axis=(0, 1)) / per_state), 1e-12)
    # The bounds the trust-region fit holds active, put exactly on them (it keeps iterates a
    # hair inside, 1e-10 relative).
    active = np.asarray(getattr(fit, "active_mask", np.zeros(p)))
    at_bound = active[:n_coef] != 0
    x = np.where(active < 0, lower, np.where(active > 0, upper, x))

    # Costs, Jacobian and covariance with the final noise estimate; the start's cost from its
    # measured initial states.
    res = residuals(x, sigma)
    cost_initial = 0.5 * float(np.sum(residuals(x0, sigma) ** 2))
    cost_final = 0.5 * float(res @ res)
    s2 = float(res @ res) / (n_obs - p)
    rho = _lag1_autocorrelation(raw, seg.mask, states)
    worst = float(np.clip(max(rho.values()), 0.0, 0.99))
    inflation = (1.0 + worst) / (1.0 - worst)
    notes: list[str] = []
    cov, undetermined, rank_notes = _covariance(jacobian(x, sigma), s2 * inflation, rows, cols,
                                                model)  # fmt: skip
    notes += rank_notes
    cov_coef = cov[:n_coef, :n_coef]
    se = np.where(undetermined[:n_coef], np.inf, np.sqrt(np.clip(np.diag(cov_coef), 0.0, None)))

    fitted = with_coefficients(model, slots.all_rows, slots.all_cols, slots.values(x[:n_coef]),
                               f"output error ({model.structure.name})")  # fmt: skip
    std_errors: dict[str, dict[str, float]] = {dof: {} for dof in model.structure.dofs}
    labels = []
    for i, j, value in zip(rows, cols, se, strict=True):
        std_errors[DOFS[i]][model.term_texts[j]] = float(value)
        labels.append([DOFS[i], model.term_texts[j]])

    for (dof, term) in slots.given:
        std_errors[dof][term] = 0.0  # known, not estimated: its interval is the value
    notes += slots.notes(model, x[:n_coef], at_bound, reasons, "output-error fit")
    if fit.status == 0:
        notes.append(f"output error stopped at the evaluation cap ({max_nfev}) before converging")
    if inflation > INFLATION_WARNING:
        notes.append(f"the free-run residuals are correlated (lag-1 ρ = {worst:.2f}): model error, "
                     f"not sensor noise, dominates; the standard errors are widened "
                     f"×{math.sqrt(inflation):.2g} for it")  # fmt: skip
    runs = compare_free_runs(model, fitted, logs, names, method, notes)
    x0_fit = x[n_coef:].reshape(B, n_states)
    statistics = {
        "level": LEVEL, "observations": n_obs, "parameters": p,
        "noise": {s: float(sigma[j]) for j, s in enumerate(states)},
        "residual_autocorrelation": rho, "covariance_inflation": inflation,
        "standard_errors": std_errors,
        "covariance": {"terms": labels, "matrix": cov_coef.tolist()},
        "initial_states": [{"log": n, **{s: float(x0_fit[b, j]) for j, s in enumerate(states)}}
                           for b, n in enumerate(names)],
        "bounds": {dof: {t: [float(lo), float(hi)] for t, (lo, hi) in b.items()}
                   for dof, b in (bounds or {}).items() if b},
        "at_bound": [[DOFS[rows[j]], model.term_texts[cols[j]]] for j in np.flatnonzero(at_bound)],
    }  # fmt: skip
    result = Refinement(fitted, model, seg_len, B, states, cost_initial, cost_final, nfev,
                        bool(fit.success), str(fit.message), runs, notes, METHOD,
                        statistics)  # fmt: skip
    return result, gaussian_ensemble(fitted, rows, cols, cov_coef, draws, seed,
                                     (lower[:n_coef], upper[:n_coef]) if bounded else None)


def _lag1_autocorrelation(raw: np.ndarray, mask: np.ndarray, states: Sequence[str]
                          ) -> dict[str, float]:  # fmt: skip
    """Lag-1 autocorrelation of each fitted state's residual (raw[..., j] is ``states[j]``),
    pooled over the logs."""
    out = {}
    for j, s in enumerate(states):
        num = den = 0.0
        for b in range(raw.shape[0]):
            e = raw[b, mask[b], j]
            e = e[np.isfinite(e)]
            if e.size < 3:
                continue
            e = e - e.mean()
            num += float(e[1:] @ e[:-1])
            den += float(e @ e)
        out[s] = num / den if den > 0 else 0.0
    return out


def _covariance(jac: np.ndarray, scale: float, rows: np.ndarray, cols: np.ndarray,
                model: ManoeuvringModel) -> tuple[np.ndarray, np.ndarray, list[str]]:  # fmt: skip
    """scale · (JᵀJ)⁺ by eigendecomposition, and which parameters the logs do not determine
    (a loading on a direction of (numerically) zero information): their variance is infinite."""
    # Columns scaled to unit norm: coefficients span orders of magnitude.
    norms = np.linalg.norm(jac, axis=0)
    norms[norms == 0] = 1.0
    w, V = np.linalg.eigh((jac / norms).T @ (jac / norms))
    tiny = w <= max(w.max(), 0.0) * 1e-12
    undetermined = np.any(np.abs(V[:, tiny]) > 0.1, axis=1)
    notes = []
    if np.any(undetermined[: len(rows)]):
        which = [f"{DOFS[rows[j]]}: {model.term_texts[cols[j]]}"
                 for j in np.flatnonzero(undetermined[: len(rows)])]  # fmt: skip
        notes.append("the logs do not determine " + ", ".join(which) + " (the output-error "
                     "information matrix is singular); their standard errors are infinite")
    inv_w = np.where(tiny, 0.0, 1.0 / np.where(tiny, 1.0, w))
    cov = scale * ((V * inv_w) @ V.T) / np.outer(norms, norms)
    return cov, undetermined, notes


def gaussian_ensemble(model: ManoeuvringModel, rows: np.ndarray, cols: np.ndarray,
                      cov: np.ndarray, draws: int, seed: int,
                      bounds: tuple[np.ndarray, np.ndarray] | None = None) -> Ensemble:  # fmt: skip
    """``draws`` coefficient sets θ ~ N(θ̂, cov) over the fitted coefficients (at ``rows``,
    ``cols`` of θ; the rest as θ̂), cut at ``bounds`` (lower, upper) of those coefficients: a
    member past a sign constraint would be a ship the fit ruled out."""
    rng = np.random.default_rng(seed)
    w, V = np.linalg.eigh(cov)
    root = V * np.sqrt(np.clip(w, 0.0, None))
    delta = rng.standard_normal((draws, len(rows))) @ root.T
    thetas = np.broadcast_to(model.theta, (draws, *model.theta.shape)).copy()
    thetas[:, rows, cols] += delta
    if bounds is not None:
        thetas[:, rows, cols] = np.clip(thetas[:, rows, cols], bounds[0], bounds[1])
    return Ensemble(model, thetas, 0.0, int(seed), DRAWS_METHOD)


def coefficient_intervals(fit: Refinement, level: float = LEVEL) -> pd.DataFrame:
    """One row per coefficient of an output-error fit: estimate, standard error and the normal
    interval estimate ± z·SE (z = 1.96 at 95 %), cut at the coefficient's bounds if it has any."""
    from statistics import NormalDist

    if not fit.statistics:
        raise ShipidError("not a maximum-likelihood output-error fit: it has no standard errors")
    z = NormalDist().inv_cdf(0.5 + level / 2.0)
    se = fit.statistics["standard_errors"]
    bounds = fit.statistics.get("bounds") or {}
    rows = []
    for dof, terms in fit.model.coefficients.items():
        for term, value in terms.items():
            s = se[dof][term]
            lo, hi = (bounds.get(dof) or {}).get(term, (None, None))  # a file's JSON: null
            lo, hi = -math.inf if lo is None else lo, math.inf if hi is None else hi
            rows.append({"equation": dof, "term": term, "value": value,
                         "lssvm": fit.initial.coefficients[dof].get(term, math.nan),
                         "std_error": s, "lower": max(value - z * s, lo),
                         "upper": min(value + z * s, hi)})  # fmt: skip
    return pd.DataFrame(rows)

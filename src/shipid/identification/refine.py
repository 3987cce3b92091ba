"""Output-error refinement of an identified model: from the LS-SVM estimate, minimise the free-run
simulation error over the training logs, log by log or segment by segment.

The one-step regression of the paper (eqs. 11–12) fits accelerations; a model that fits them well can
still drift or diverge when simulated over a whole trial, which is what users run it for. Refinement
fits the simulation itself. Each training log is cut into segments of ``segment_s`` seconds (or kept
whole); every segment starts from the measured state (u, v, r, ψ) at its first sample, is simulated
with the model's scheme driven by the measured rudder (and propeller inputs), and is compared with
the measured states. The cost is

    J(θ) = Σ_seg Σ_k Σ_ξ ((ξ̂_k − ξ_k)/σ_ξ)²            simulation error
         + Σ_dof Σ_j (θ_j / (√γ σ_e,dof))²              the LS-SVM prior

σ_ξ is the spread of state ξ in the training data, σ_e,dof the one-step equation-error spread of the
LS-SVM model: the last term is the LS-SVM's ½‖w‖² kept at its weight 1/γ relative to a unit-variance
error term (eq. 4). A segment that diverges scores a large residual on each of its remaining
samples, so the fit is pushed away from unstable models. Minimised by
``scipy.optimize.least_squares`` (trust-region reflective, finite-difference Jacobian).

Initial states are measured, not estimated: with free initial states an unstable model can fit a
segment by fine-tuning where it starts, and then fails any free run (seen on the Esso Osaka data).
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from shipid.data.log import column_values, input_columns, require_columns
from shipid.dynamics.model import DOFS, ManoeuvringModel
from shipid.dynamics.simulate import METHODS, DivergenceBounds, run_kernel
from shipid.dynamics.terms import INPUT_SIGNALS
from shipid.errors import ShipidError
from shipid.evaluation.validate import free_run
from shipid.identification.physics import held_note
from shipid.identification.regression import common_sampling_time

SHOT_STATES = ("u", "v", "r")
METHOD = "output error, measured initial states, LS-SVM prior"
# Residual given to every state of every sample after a segment diverged: far beyond any fit.
DIVERGED_RESIDUAL = 100.0


@dataclass
class Refinement:
    """The refined model, the LS-SVM model it started from, and how the fit went."""

    model: ManoeuvringModel
    initial: ManoeuvringModel
    segment_s: float
    n_segments: int
    states: tuple[str, ...]
    cost_initial: float
    cost_final: float
    nfev: int
    success: bool
    message: str
    free_run: list[dict] = field(default_factory=list)  # per training log: both models' errors
    warnings: list[str] = field(default_factory=list)
    method: str = METHOD
    statistics: dict | None = None  # maximum likelihood only: noise, standard errors, covariance

    def to_dict(self) -> dict:
        """The refinement as JSON-ready data (kept in the model file)."""
        return {"initial_model": self.initial.to_dict(), "refined_model": self.model.to_dict(),
                "segment_s": self.segment_s,
                "n_segments": self.n_segments, "states": list(self.states),
                "cost_initial": self.cost_initial, "cost_final": self.cost_final,
                "nfev": self.nfev, "success": self.success, "message": self.message,
                "free_run": self.free_run, "warnings": self.warnings, "method": self.method,
                "statistics": self.statistics}  # fmt: skip


@dataclass
class _Segments:
    """Training logs cut into B segments, padded to one length for the batch simulator."""

    t: np.ndarray  # (L,) common grid from 0
    inputs: np.ndarray  # (B, L, 5) in INPUT_SIGNALS order
    measured: np.ndarray  # (B, L, n_states)
    mask: np.ndarray  # (B, L) True on real samples
    psi0: np.ndarray  # (B,)
    shot0: np.ndarray  # (B, 3) measured u, v, r at each segment's start
    sigma: np.ndarray  # (n_states,)


def cut_logs(
    logs: Sequence[pd.DataFrame],
    names: Sequence[str],
    segment_s: float | None,
    states: tuple[str, ...],
    model: ManoeuvringModel,
) -> tuple[_Segments, float, float]:
    """The logs cut into segments of ``segment_s`` seconds (None: each log whole), padded to one
    length for the batch simulator; returns them, the logs' Δk and the segment length [s]."""
    for log, name in zip(logs, names, strict=True):
        require_columns(log, ("t", "delta"), name, "the free runs are driven by its rudder")
    dt = common_sampling_time(logs, names)
    longest = max(len(log) for log in logs) - 1
    if segment_s is None:
        steps = longest
    else:
        if not (math.isfinite(segment_s) and segment_s > 0):
            raise ShipidError(f"--segment must be > 0 s, got {segment_s!r}")
        steps = max(int(round(segment_s / dt)), 2)
    inputs = [{"delta": column_values(log, "delta"), **input_columns(log, model.inputs, name)}
              for log, name in zip(logs, names, strict=True)]  # fmt: skip
    bounds = []  # (log index, first sample, last sample)
    for i, log in enumerate(logs):
        n = len(log) - 1
        count = max(1, int(round(n / steps)))
        edges = np.linspace(0, n, count + 1).round().astype(int)
        bounds += [(i, int(a), int(b)) for a, b in zip(edges[:-1], edges[1:], strict=True)]
    L = max(b - a for _, a, b in bounds) + 1
    B = len(bounds)
    seg = _Segments(
        t=np.arange(L) * dt, inputs=np.zeros((B, L, len(INPUT_SIGNALS))),
        measured=np.zeros((B, L, len(states))), mask=np.zeros((B, L), dtype=bool),
        psi0=np.zeros(B), shot0=np.zeros((B, 3)), sigma=np.ones(len(states)),
    )  # fmt: skip
    for b, (i, a, e) in enumerate(bounds):
        log = logs[i]
        m = e - a + 1
        for j, column in enumerate(INPUT_SIGNALS):
            if column in inputs[i]:
                x = inputs[i][column][a : e + 1]
                seg.inputs[b, :m, j], seg.inputs[b, m:, j] = x, x[-1]
        for j, s in enumerate(states):
            seg.measured[b, :m, j] = _signal(log, s)[a : e + 1]
        seg.mask[b, :m] = True
        seg.psi0[b] = _signal(log, "psi")[a] if "psi" in log.columns else 0.0
        seg.shot0[b] = [float(log[s].iloc[a]) for s in SHOT_STATES]
    for j, s in enumerate(states):
        values = np.concatenate([_signal(log, s) - (_signal(log, s).mean() if s == "psi" else 0.0)
                                 for log in logs])  # fmt: skip
        spread = float(np.std(values))
        if not spread > 0:
            raise ShipidError(f"state {s} does not vary in the training logs: nothing to fit it to")
        seg.sigma[j] = spread
    return seg, dt, steps * dt


def _signal(log: pd.DataFrame, s: str) -> np.ndarray:
    x = column_values(log, s, float)
    return np.unwrap(x) if s == "psi" else x


def _equation_error_spread(model: ManoeuvringModel, logs: Sequence[pd.DataFrame], dt: float) -> dict:
    """One-step equation-error std per DOF of ``model`` on the logs (the increment-form residual)."""
    errors: dict[str, list] = {d: [] for d in model.structure.dofs}
    for log in logs:
        inputs = input_columns(log, model.inputs)
        acc = model.accelerations(log["u"], log["v"], log["r"], log["delta"],
                                  inputs.pop("thrust", None), inputs.pop("n", None),
                                  **inputs)[:-1]  # fmt: skip
        for i, dof in enumerate(DOFS):
            if dof in errors:
                x = column_values(log, dof)
                errors[dof].append((x[1:] - x[:-1]) / dt - acc[:, i])
    return {d: max(float(np.std(np.concatenate(e))), 1e-12) for d, e in errors.items()}


def refine(
    model: ManoeuvringModel,
    logs: Sequence[pd.DataFrame] | pd.DataFrame,
    segment_s: float | None = None,
    gamma: float = 1e4,
    states: Sequence[str] | None = None,
    method: str = "euler",
    max_nfev: int = 100,
    names: Sequence[str] | None = None,
    progress: bool = False,
    bounds: Mapping[str, Mapping[str, tuple[float, float]]] | None = None,
    reasons: Mapping[str, Mapping[str, str]] | None = None,
) -> Refinement:
    """Refine ``model`` (e.g. ``identify(...).model``) by output-error fitting to ``logs``.

    Parameters
    ----------
    model : the LS-SVM model; its structure is kept, every coefficient is refined.
    logs : the training logs (one Δk; trim them to the manoeuvre first).
    segment_s : length of the shooting segments [s]; None simulates each log whole (single shooting).
        Short segments make the fit robust, long ones weigh the long-run drift; 20–60 s suit
        zig-zags of scale models.
    gamma : LS-SVM γ of the prior (the identification's γ).
    states : measured states compared with the simulation; default the model's u, v, r (the
        states of the validation metrics). Adding "psi" also weighs the heading.
    method : 'euler' (the paper's scheme and ``validate``'s default) or 'rk4'.
    max_nfev : cap on the number of cost evaluations of ``least_squares``.
    progress : a progress bar of the free-run simulations (on a terminal only).
    bounds : {dof: {term: (lower, upper)}} box bounds on coefficients (sign constraints, user
        bounds: ``shipid.identification.physics.coefficient_bounds``), held by the trust-region
        fit; equal bounds give the coefficient (held there, not fitted), as in
        ``output_error``. ``reasons`` ({dof: {term: why}}) name them in the notes.
    """
    from shipid.data.log import require_frames
    from shipid.dynamics.simulate import require_dynamics

    require_dynamics(model)
    logs = require_frames(logs, names, "log to refine on")
    if not logs:
        raise ShipidError("no training logs given for the refinement")
    if method not in METHODS:
        raise ShipidError(f"method must be one of {METHODS}, got {method!r}")
    if not (math.isfinite(gamma) and gamma > 0):
        raise ShipidError(f"--gamma must be > 0, got {gamma!r}")
    names = list(names or [log.attrs.get("name", f"log {i}") for i, log in enumerate(logs)])
    dofs = model.structure.dofs
    if states is None:
        states = tuple(d for d in SHOT_STATES if d in dofs)
    states = tuple(states)
    for s in states:
        if s not in (*SHOT_STATES, "psi"):
            raise ShipidError(f"cannot fit state {s!r}; use u, v, r or psi")
        missing = [n for n, log in zip(names, logs, strict=True) if s not in log.columns]
        if missing:
            raise ShipidError(f"{missing[0]}: no {s!r} column to fit")
    seg, dt, seg_len = cut_logs(logs, names, segment_s, states, model)
    B, L = seg.inputs.shape[:2]

    slots = FreeCoefficients.of(model, bounds)
    rows, cols = slots.rows, slots.cols
    lower, upper = bound_vectors(model, rows, cols, bounds, len(rows), skip=slots.given)
    x0 = np.clip(model.theta[rows, cols], lower, upper)
    sigma_e = _equation_error_spread(model, logs, dt)
    prior_scale = np.array([1.0 / (math.sqrt(gamma) * sigma_e[DOFS[i]]) for i in rows])
    state_col = [SHOT_STATES.index(s) if s != "psi" else 3 for s in states]
    s0 = np.zeros((B, 6))
    s0[:, :3] = seg.shot0
    s0[:, 3] = seg.psi0
    speed_lim, yaw_lim = DivergenceBounds().resolved(float(np.max(np.abs(seg.shot0[:, 0]))))
    alive_grid = np.arange(L)[None, :]

    from shipid.progress import progress_bar

    # Each cost evaluation and each column of the finite-difference Jacobian is one simulation.
    bar = progress_bar(max_nfev * (len(x0) + 1), "refinement", "sim",
                       shown=bool(progress))  # fmt: skip

    def residuals(x: np.ndarray) -> np.ndarray:
        bar.update()
        theta = slots.theta.copy()
        theta[rows, cols] = x
        out, n_valid = run_kernel(model.code, theta, seg.t, seg.inputs, s0, method, speed_lim,
                                  yaw_lim)  # fmt: skip
        res = (out[:, :, state_col] - seg.measured) / seg.sigma
        res[alive_grid >= n_valid[:, None]] = DIVERGED_RESIDUAL
        res[~seg.mask] = 0.0
        return np.concatenate([res.ravel(), x * prior_scale])

    # Relative steps and scales: coefficients span orders of magnitude (|n|n ~ 1e-5, δ ~ 1e-2).
    scale = np.maximum(np.abs(x0), 1e-3 * (np.abs(x0).max() or 1.0))
    cost_initial = 0.5 * float(np.sum(residuals(x0) ** 2))
    try:
        from scipy.optimize import least_squares  # 0.37 s of import: only when fitting

        fit = least_squares(residuals, x0, method="trf", x_scale=scale, max_nfev=max_nfev,
                            bounds=(lower, upper))  # fmt: skip
    finally:
        bar.close()
    # The bounds the trust-region fit holds active, put exactly on them.
    active = np.asarray(getattr(fit, "active_mask", np.zeros(len(x0))))
    x = np.where(active < 0, lower, np.where(active > 0, upper, fit.x))
    refined = with_coefficients(model, slots.all_rows, slots.all_cols, slots.values(x),
                                f"refined ({model.structure.name})")  # fmt: skip

    notes = slots.notes(model, x, active != 0, reasons, "refinement")
    if fit.status == 0:
        notes.append(f"refinement stopped at the evaluation cap ({max_nfev}) before converging; "
                     "raise max_nfev or shorten the segments")  # fmt: skip
    runs = compare_free_runs(model, refined, logs, names, method, notes)
    return Refinement(refined, model, seg_len, B, states, cost_initial, float(fit.cost),
                      int(fit.nfev), bool(fit.success), str(fit.message), runs, notes)  # fmt: skip


@dataclass
class FreeCoefficients:
    """The coefficients an output-error fit varies and those its bounds give: ``rows``,
    ``cols`` (``coefficient_slots`` of the free ones), ``free`` (mask over ``all_rows``,
    ``all_cols``, every slot), ``given`` ({(dof, term): value}, equal bounds) and ``theta``
    (the model's θ shape, the given values in place, zero elsewhere)."""

    all_rows: np.ndarray
    all_cols: np.ndarray
    free: np.ndarray
    given: dict[tuple[str, str], float]
    theta: np.ndarray

    @property
    def rows(self) -> np.ndarray:
        """The DOF rows of θ of the free coefficients."""
        return self.all_rows[self.free]

    @property
    def cols(self) -> np.ndarray:
        """The term columns of θ of the free coefficients."""
        return self.all_cols[self.free]

    @classmethod
    def of(cls, model: ManoeuvringModel,
           bounds: Mapping[str, Mapping[str, tuple[float, float]]] | None) -> FreeCoefficients:
        """A coefficient whose two bounds are equal is given, not fitted: held in every free
        run, outside the parameters (SciPy's trust-region fit refuses an empty box)."""
        all_rows, all_cols = coefficient_slots(model)
        given = given_coefficients(model, bounds)
        free = np.array([(DOFS[i], model.term_texts[j]) not in given
                         for i, j in zip(all_rows, all_cols, strict=True)], dtype=bool)  # fmt: skip
        theta = np.zeros_like(model.theta)
        for (dof, term), value in given.items():
            theta[DOFS.index(dof), model.term_texts.index(term)] = value
        return cls(all_rows, all_cols, free, given, theta)

    def values(self, x: np.ndarray) -> np.ndarray:
        """Every slot's value: the free ones ``x``, the given ones theirs."""
        out = self.theta[self.all_rows, self.all_cols].copy()
        out[self.free] = x
        return out

    def notes(self, model: ManoeuvringModel, x: np.ndarray, at_bound: np.ndarray,
              reasons: Mapping[str, Mapping[str, str]] | None, fit: str) -> list[str]:
        """A note per free coefficient held at its bound (``at_bound``, over the free ones, the
        value in ``x``) and per given one; ``fit`` names the fit that would go past the bound."""
        held = [((DOFS[self.rows[j]], model.term_texts[self.cols[j]]), x[j], False)
                for j in np.flatnonzero(at_bound)]
        held += [(key, value, True) for key, value in self.given.items()]
        return [held_note(dof, term, value, ((reasons or {}).get(dof) or {}).get(term), given,
                          f"unbounded {fit}") for (dof, term), value, given in held]


def given_coefficients(model: ManoeuvringModel,
                        bounds: Mapping[str, Mapping[str, tuple[float, float]]] | None
                        ) -> dict[tuple[str, str], float]:  # fmt: skip
    """{(dof, term): value} of the coefficients whose lower and upper bounds are equal."""
    return {(dof, term): float(lo) for dof, terms in (bounds or {}).items()
            for term, (lo, hi) in terms.items()
            if lo == hi and math.isfinite(lo) and term in model.coefficients.get(dof, {})}


def bound_vectors(model: ManoeuvringModel, rows: np.ndarray, cols: np.ndarray,
                   bounds: Mapping[str, Mapping[str, tuple[float, float]]] | None, p: int,
                   skip: Mapping[tuple[str, str], float] = ()) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper bounds of the p parameters (the coefficients at ``rows``, ``cols``, then
    the initial states, never bounded), refusing a bound on a term the model lacks; those in
    ``skip`` (given, not fitted) are left out."""
    lower, upper = np.full(p, -np.inf), np.full(p, np.inf)
    index = {(DOFS[i], model.term_texts[j]): k for k, (i, j) in enumerate(zip(rows, cols,
                                                                              strict=True))}
    for dof, terms in (bounds or {}).items():
        for term, (lo, hi) in terms.items():
            if (dof, term) in skip:
                continue
            k = index.get((dof, term))
            if k is None:
                raise ShipidError(f"bounds: {dof}: {term} is not a term of the model's {dof} "
                                  "equation")  # fmt: skip
            if not lo < hi:
                raise ShipidError(f"bounds: {dof}: {term}: lower {lo:g} is not below upper {hi:g}")
            lower[k], upper[k] = lo, hi
    return lower, upper


def coefficient_slots(model: ManoeuvringModel) -> tuple[np.ndarray, np.ndarray]:
    """Where the model's coefficients sit in its θ (3, T), in ``model.coefficients`` order:
    the rows (DOFs) and columns (terms) of the fitted parameters."""
    index = {t: j for j, t in enumerate(model.term_texts)}
    slots = [(i, index[n]) for i, dof in enumerate(DOFS) for n in model.coefficients.get(dof, {})]
    return (np.array([i for i, _ in slots], dtype=int),
            np.array([j for _, j in slots], dtype=int))  # fmt: skip


def with_coefficients(model: ManoeuvringModel, rows: np.ndarray, cols: np.ndarray,
                      values: np.ndarray, name: str) -> ManoeuvringModel:  # fmt: skip
    """``model``'s structure with the coefficients at ``coefficient_slots`` set to ``values``."""
    coefs: dict[str, dict[str, float]] = {dof: {} for dof in model.structure.dofs}
    for i, j, value in zip(rows, cols, values, strict=True):
        coefs[DOFS[i]][model.term_texts[j]] = float(value)
    return ManoeuvringModel(model.structure, coefs, name=name)


def compare_free_runs(initial: ManoeuvringModel, refined: ManoeuvringModel,
                      logs: Sequence[pd.DataFrame], names: Sequence[str], method: str,
                      notes: list[str]) -> list[dict]:  # fmt: skip
    """Per training log, both models' free-run error std; a refined run that diverges is noted."""
    runs = []
    for name, log in zip(names, logs, strict=True):
        (sim0, m0), (sim1, m1) = free_run(initial, log, method), free_run(refined, log, method)
        runs.append({"name": name,
                     "initial": {s: m0[s]["std"] for s in SHOT_STATES},
                     "refined": {s: m1[s]["std"] for s in SHOT_STATES},
                     "initial_diverged": sim0.diverged, "refined_diverged": sim1.diverged})  # fmt: skip
        if sim1.diverged:
            notes.append(f"{name}: the refined model diverges in a free run over the whole log "
                         f"({sim1.reason})")  # fmt: skip
    return runs

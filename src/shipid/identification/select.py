"""Structure and γ chosen by cross-validated free-run error on logs the model was not fitted to.

The one-step regression of the paper (eqs. 11–12) is fitted per degree of freedom; what users run a
model for is the free run. So every candidate (a subset of a term library, a γ) is scored by
**leave-one-log-out** (or k-fold by log, or contiguous blocks of long logs): fitted on the other
logs, simulated over the held-out one from its measured initial state with its measured inputs,
and its error per state divided by that state's spread in the held-out log (1 ≈ predicting the
mean). A fold that diverges scores ``divergence_penalty`` on every sample after the divergence.
The CV score is the mean over folds and states.

Search (``search``):

* ``stepwise`` (default): terms of each DOF ranked by forward orthogonal least squares (FROLS, the
  error-reduction ratio of Billings); the number of leading terms of each DOF is scanned one DOF at
  a time, keeping the best free-run CV score, until a round improves nothing.
* ``frols``: the nested models that keep, in every DOF, the terms needed to reach a share
  1 − ρ of the library's error reduction, over a grid of ρ.
* ``stlsq``: sequentially thresholded least squares (SINDy) on standardised regressors, over a grid
  of thresholds.
* ``none``: the library as it is (γ only; what ``identify --gamma auto`` runs).

γ: the exact leave-one-out of the linear LS-SVM (closed form, ``shipid.lssvm.loo``) over the
grid pre-screens; the free-run CV decides among the values within 1.5× of the best LOO error, for
the full library and again for the chosen structure.

Candidates must be plausible (``plausibility.disqualifying``): the chosen one, fitted on all logs,
has a steady speed and turns the right way, bounded, with the rudder held, at the first log's
propeller speed and, held alone, at every other its logs ran at
(``plausibility.gross_at_other_rps``); implausible candidates stay in the table, marked, and are
not chosen.

How firm the choice is: the choice rule (the best plausible score, then the one-standard-error
rule) is repeated on ``RESAMPLES`` bootstrap resamples of the held-out logs, among the candidates
the search evaluated (bagging the selection, Breiman 1996; as E-SINDy bags SINDy's). Each
candidate's ``share`` is how often it is chosen; ``shipid.identification.selection_ensemble``
draws the terms of its replicates from these shares.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from shipid.data.log import (
    approach,
    column_array,
    column_values,
    common_rudder_convention,
    input_columns,
    refuse_copies,
    refuse_other_ships,
    require_states,
)
from shipid.dynamics.model import DOFS, ManoeuvringModel, ModelStructure, get_structure
from shipid.dynamics.similarity import similar_library
from shipid.dynamics.simulate import DivergenceBounds, input_array, run_kernel
from shipid.dynamics.terms import INPUT_SIGNALS, parse_term, term_code
from shipid.errors import InfeasibleConstraintsError, ShipidError
from shipid.evaluation.error_band import ErrorBand, error_band, key_indices
from shipid.identification.cross_validation import (
    folds as _folds,
)
from shipid.identification.cross_validation import (
    normalised_error,
    parse_cv,
    split_blocks,
)
from shipid.identification.estimators import LINEAR_ESTIMATORS, check_estimator_name, fit_linear
from shipid.identification.physics import (
    PhysicsOptions,
    dof_physics,
    with_approaches,
    with_stability,
)
from shipid.identification.regression import common_sampling_time, log_terms
from shipid.lssvm.solvers import solve_primal_constrained

SEARCHES = ("stepwise", "frols", "stlsq", "none")
STATES = ("u", "v", "r")
RESAMPLES = 200  # resamples of the held-out logs for the choice's shares
FEW_FOLDS = 4  # fewer folds than this: the choice is reported as weak
RHO_GRID = (0.3, 0.1, 0.03, 0.01, 3e-3, 1e-3, 3e-4, 1e-4, 1e-5, 0.0)
STLSQ_GRID = (0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3)


@dataclass(frozen=True)
class SelectOptions:
    """How ``select`` searches.

    library : term library (a structure name, sum or spec; see ``shipid.dynamics.model``);
        None (default): ``DEFAULT_LIBRARY`` less the terms whose log columns the logs lack
        (``default_library``, said in the notes).
    search : 'stepwise', 'frols', 'stlsq' or 'none'.
    gammas : the γ grid.
    cv : 'logo' (leave one log out), 'kfold:K' (K folds of whole logs) or 'blocks:K' (every log
        cut into K contiguous blocks, then leave one block out: for one or two long logs).
    estimator : equation-error estimator ('lssvm', 'ols', 'ridge', 'lasso', 'svr').
    method : integration scheme of the free runs ('euler', the paper's, or 'rk4').
    divergence_penalty : normalised error given to each sample after a fold diverged.
    max_evaluations : cap on candidate evaluations (each one: a fit and a free run per fold).
    plausibility : restrict the choice to plausible models.
    one_standard_error : choose the sparsest candidate within one standard error of the best
        CV score (else the best).
    speed, rps : condition of the plausibility checks (default: each candidate's steady approach
        at the first log's rps, near its approach speed; ``plausibility_at_approach``).
    progress : show a progress bar.
    physics : prior, sign constraints, bounds, steady speed (``PhysicsOptions``) in every fit.
    average : the model is the average of the candidates the choice rule picks on resampled
        held-out logs, each fitted on all logs and weighted by its share (bagging the selection),
        instead of the chosen candidate alone (kept as ``Selection.chosen_model``).
    keep : terms every candidate holds, whatever the cross-validation says (a structure name,
        sum or spec 'v: u*v, u*r; r: u*v, u*r'): the terms physics says a ship has, which logs
        of one kind of manoeuvre may not tell from the rest. Added to the library where it
        lacks them; the search chooses among the other terms.
    """

    library: str | ModelStructure | None = None
    search: str = "stepwise"
    gammas: tuple[float, ...] = (1e2, 1e3, 1e4, 1e5, 1e6)
    cv: str = "logo"
    estimator: str = "lssvm"
    method: str = "euler"
    divergence_penalty: float = 2.0
    max_evaluations: int = 400
    plausibility: bool = True
    speed: float | None = None
    rps: float | None = None
    one_standard_error: bool = True
    progress: bool = False
    physics: PhysicsOptions | None = None
    average: bool = False
    keep: str | ModelStructure | None = None

    def __post_init__(self) -> None:
        if self.search not in SEARCHES:
            raise ShipidError(f"--search must be one of {', '.join(SEARCHES)}, got {self.search!r}")
        gammas = tuple(float(g) for g in self.gammas)
        if not gammas or not all(math.isfinite(g) and g > 0 for g in gammas):
            raise ShipidError(f"--gammas must be numbers > 0, got {self.gammas!r}")
        object.__setattr__(self, "gammas", tuple(sorted(set(gammas))))
        check_estimator_name(self.estimator)
        if self.estimator not in LINEAR_ESTIMATORS:
            raise ShipidError(f"select fits named terms: estimator must be one of "
                              f"{', '.join(LINEAR_ESTIMATORS)}, got {self.estimator!r}")
        parse_cv(self.cv)
        if not (isinstance(self.max_evaluations, int) and self.max_evaluations >= 1):
            raise ShipidError(f"--max-evaluations must be ≥ 1, got {self.max_evaluations!r}")
        if not (math.isfinite(self.divergence_penalty) and self.divergence_penalty > 0):
            raise ShipidError("divergence_penalty must be > 0")
        if self.keep is not None:
            kept = get_structure(self.keep)
            if "1" in kept.all_terms:
                raise ShipidError("--keep: the constant '1' is not chosen by the search (it is "
                                  "in every candidate whose library has it); leave it out")
            object.__setattr__(self, "keep", kept)


@dataclass
class Candidate:
    terms: dict[str, tuple[str, ...]]
    gamma: float
    score: float = math.inf
    state_scores: dict[str, float] = field(default_factory=dict)
    fold_scores: list[float] = field(default_factory=list)
    folds_diverged: int = 0
    plausible: bool | None = None
    note: str = ""
    stage: str = ""
    share: float = 0.0  # how often the choice rule picks it on resampled held-out logs

    @property
    def standard_error(self) -> float:
        """Standard error of the CV score over the folds."""
        f = np.asarray(self.fold_scores)
        return float(f.std(ddof=1) / math.sqrt(f.size)) if f.size > 1 else 0.0

    @functools.cached_property
    def key(self) -> tuple:
        """Identity of the candidate: its terms per DOF and γ (a candidate's terms and γ are
        set once: the key is looked up hundreds of thousands of times in a search)."""
        return (tuple((d, tuple(sorted(t))) for d, t in sorted(self.terms.items())), self.gamma)

    def n_terms(self) -> int:
        """Number of terms over all equations."""
        return sum(len(t) for t in self.terms.values())


@dataclass
class Selection:
    """The chosen model (fitted on all logs), its identification, and the record of the search."""

    model: ManoeuvringModel
    identification: object  # Identification of the chosen structure on all logs
    gamma: float
    score: float
    candidates: pd.DataFrame
    folds: list[dict]
    options: SelectOptions
    library: ModelStructure
    ranking: dict[str, list[tuple[str, float]]]
    warnings: list[str] = field(default_factory=list)
    shares: list[Candidate] = field(default_factory=list)  # share > 0, most often chosen first
    # What the model's free runs missed on the logs it was not fitted to.
    error_band: ErrorBand | None = None
    # The chosen candidate fitted on all logs (``model`` too, unless ``options.average``).
    chosen_model: ManoeuvringModel | None = None
    # The plausibility checks of ``model`` from its steady approach, and their warnings.
    plausibility: dict | None = None
    plausibility_notes: list[str] = field(default_factory=list)
    # Why the best-scoring candidate is ruled out by the plausibility checks ('' where it passes
    # or is the chosen one): the logs then prefer a fit that physics rejects, a sign that the
    # library lacks what the ship does beyond them (``auto_structure`` widens it).
    best_ruled_out: str = ""
    # The chosen candidate's score on each held-out fold (log or block), plausible or not.
    fold_scores: list[float] = field(default_factory=list)

    @property
    def chosen_share(self) -> float:
        """How often the chosen candidate is chosen again on resampled held-out logs."""
        keyed = self.candidates[self.candidates["chosen"]]
        return float(keyed["share"].iloc[0]) if len(keyed) else 0.0

    def to_dict(self) -> dict:
        """The search record as JSON-ready data (kept in the model file)."""
        opts = {k: getattr(self.options, k) for k in ("search", "gammas", "cv", "estimator",
                                                       "method", "divergence_penalty", "average")}
        kept = self.options.keep
        opts["keep"] = {d: list(t) for d, t in kept.terms.items()} if kept else None
        return {"options": {**opts, "library": self.library.to_dict()}, "gamma": self.gamma,
                "score": self.score, "ranking": {d: [[t, e] for t, e in r]
                                                 for d, r in self.ranking.items()},
                "candidates": self.candidates.to_dict(orient="records"), "folds": self.folds,
                "warnings": self.warnings,
                "error_band": self.error_band.to_dict() if self.error_band else None,
                "chosen_model": (self.chosen_model.to_dict()
                                 if self.chosen_model is not None
                                 and self.chosen_model is not self.model else None)}  # fmt: skip


# ---------------------------------------------------------------------------- the data, once
@dataclass
class _Data:
    names: list[str]
    dt: float
    library: ModelStructure
    texts: tuple[str, ...]  # library terms, the kernel's columns ("1" excluded)
    phi: list[np.ndarray]  # per log (N_i − 1, T)
    targets: list[dict[str, np.ndarray]]  # per log, per DOF: increments (N_i − 1,)
    gram: list[np.ndarray]  # per log (T + 1, T + 1): [Φ 1]ᵀ[Φ 1]
    cross: list[dict[str, np.ndarray]]  # per log, per DOF: [Φ 1]ᵀ y
    inputs: list[np.ndarray]  # per log (N_i, 5)
    measured: list[np.ndarray]  # per log (N_i, 3) u, v, r
    s0: np.ndarray  # (L, 6)
    logs: list[pd.DataFrame] = field(default_factory=list)  # for the physics (rudder sign, approach)
    library_note: str = ""  # the default library's terms left out for the logs' columns
    _fold_sums: dict = field(default_factory=dict, init=False, repr=False, compare=False)

    def fold_sums(self, train: Sequence[int]) -> tuple[np.ndarray, dict[str, np.ndarray]]:
        """[Φ 1]ᵀ[Φ 1] and, per DOF, [Φ 1]ᵀy summed over the logs ``train``: once per fold for
        the hundreds of candidates fitted on it (each fit summed its blocks log by log, 244 000
        sums in five test files). The same floating-point sums, in the same order: a block of
        the sum is the sum of the blocks."""
        key = tuple(train)
        if key not in self._fold_sums:
            self._fold_sums[key] = (sum(self.gram[j] for j in key),
                                    {d: sum(self.cross[j][d] for j in key) for d in DOFS})
        return self._fold_sums[key]


def _prepare(logs: Sequence[pd.DataFrame], names: Sequence[str], library: ModelStructure) -> _Data:
    texts = tuple(t for t in library.all_terms if t != "1")
    for log, name in zip(logs, names, strict=True):
        missing = [c for c in library.inputs if c not in log.columns]
        if missing:
            term = next(t for t in texts if missing[0] in parse_term(t).inputs)
            hint = " (the wind library needs the relative wind: read the Osaka files with " \
                   "--format osaka-frt)" if missing[0].startswith("wind") else ""
            raise ShipidError(f"{name}: the library term {term!r} needs the log column "
                              f"{missing[0]!r}, which this log does not have{hint}")
    dt = common_sampling_time(logs, names)
    data = _Data(list(names), dt, library, texts, [], [], [], [], [], [], np.zeros((len(logs), 6)),
                 list(logs))
    for i, (log, name) in enumerate(zip(logs, names, strict=True)):
        phi = log_terms(log, texts, name)
        ext = np.column_stack([phi[:-1], np.ones(len(log) - 1)])
        data.phi.append(phi[:-1])
        y = {d: np.diff(column_values(log, d)) / dt for d in DOFS}
        data.targets.append(y)
        data.gram.append(ext.T @ ext)
        data.cross.append({d: ext.T @ y[d] for d in DOFS})
        series = {"delta": column_values(log, "delta"), **input_columns(log, library.inputs, name)}
        data.inputs.append(input_array(series, 1, len(log))[0])
        data.measured.append(column_array(log, STATES))
        first = log.iloc[0]
        data.s0[i] = [float(first.get(k, 0.0)) if k in log.columns else 0.0
                      for k in ("u", "v", "r", "psi", "x", "y")]  # fmt: skip
    return data


def _bounds_in_library(physics: PhysicsOptions | None,
                       library: ModelStructure) -> PhysicsOptions | None:  # fmt: skip
    """``physics`` with its bounds held by the candidates that have their terms, after refusing
    a bound on a term the library lacks (no candidate could hold it). A candidate without the
    term holds it at 0: it meets a bound around 0 (a sign), and is dropped where the bound
    excludes 0 (an average with it would pull the term toward 0, out of its bound). Such a
    candidate was refused the bound ("not a free term"), which stopped the search at its first."""
    if physics is None or not physics.bounds:
        return physics
    for dof, terms in physics.bounds.items():
        have = [t for t in library.terms.get(dof, ()) if t != "1"]
        missing = sorted({parse_term(t).text for t in terms} - set(have))
        if missing:
            raise ShipidError(f"bounds: {dof}: {', '.join(missing)} is not a term of the "
                              f"library's {dof} equation ({', '.join(have) or 'none'}): no "
                              "candidate can hold it")  # fmt: skip
    return dataclasses.replace(physics, bounds_where_present=True)


# ---------------------------------------------------------------------------- fits
def _fit_theta(data: _Data, terms: Mapping[str, Sequence[str]], gamma: float, train: Sequence[int],
               estimator: str, physics: PhysicsOptions | None = None) -> np.ndarray:  # fmt: skip
    """θ (3, T) over the library columns, fitted on the logs ``train``."""
    index = {t: j for j, t in enumerate(data.texts)}
    theta = np.zeros((3, len(data.texts) + 1))  # last column: "1" (the bias)
    T = len(data.texts)
    for i, dof in enumerate(DOFS):
        if dof not in terms:
            continue
        names = [t for t in terms[dof] if t != "1"]
        cols = [index[t] for t in names]
        has_const = "1" in terms[dof]
        extra = dof_physics(physics, dof, names, has_const, {}, data.logs)
        if physics is not None and physics.stable and dof == "r" and "v" in terms:
            sway = {t: float(theta[1, T if t == "1" else index[t]]) for t in terms["v"]}
            extra = with_stability(extra, physics, dof, names, {}, {"v": sway}, data.logs)
        if estimator in ("lssvm", "ols"):
            sel = cols + [T]
            gram, cross = data.fold_sums(train)
            A, b = gram[np.ix_(sel, sel)], cross[dof][sel]
            w, bias, _ = solve_primal_constrained(
                A, b, gamma if estimator == "lssvm" else math.inf, extra.prior, extra.lower,
                extra.upper, extra.solver_equalities(), extra.inequalities,
                extra.inequality_labels)
        else:
            X = np.vstack([data.phi[j][:, cols] for j in train])
            y = np.concatenate([data.targets[j][dof] for j in train])
            w, bias = fit_linear(X, y, estimator, gamma, physics=extra)
        theta[i, cols] = w
        if has_const:
            theta[i, T] = bias
    return theta


def _model_from_theta(data: _Data, terms, theta: np.ndarray, name: str) -> ManoeuvringModel:
    texts = (*data.texts, "1")
    index = {t: j for j, t in enumerate(texts)}
    coefs = {d: {t: float(theta[DOFS.index(d), index[t]]) for t in terms[d]} for d in terms}
    return ManoeuvringModel(ModelStructure(name, {d: tuple(terms[d]) for d in terms}), coefs,
                            name=name)  # fmt: skip


# ---------------------------------------------------------------------------- scoring
class _Scorer:
    def __init__(self, data: _Data, options: SelectOptions, folds: list[list[int]]):
        self.data, self.options, self.folds = data, options, folds
        self.code = term_code((*data.texts, "1"))
        held = [h for f in folds for h in f]
        self.held = held
        n_max = max(len(data.measured[h]) for h in held)
        B = len(held)
        self.t = np.arange(n_max) * data.dt
        self.inputs = np.zeros((B, n_max, len(INPUT_SIGNALS)))
        self.n_steps = np.zeros(B, dtype=np.int64)
        for b, h in enumerate(held):
            n = len(data.measured[h])
            self.inputs[b, :n] = data.inputs[h]
            self.inputs[b, n:] = data.inputs[h][-1]
            self.n_steps[b] = n
        self.s0 = data.s0[held]
        speed_lim, yaw_lim = DivergenceBounds().resolved(float(np.max(np.abs(data.s0[:, 0]))))
        self.bounds = (speed_lim, yaw_lim)
        self.cache: dict[tuple, Candidate] = {}
        self.evaluations = 0

    def thetas(self, terms, gamma) -> np.ndarray:
        n_logs = len(self.data.phi)
        out = []
        for fold in self.folds:
            train = [j for j in range(n_logs) if j not in fold]
            theta = _fit_theta(self.data, terms, gamma, train, self.options.estimator,
                               self.options.physics)
            out += [theta] * len(fold)
        return np.array(out)

    def free_runs(self, terms, gamma):
        thetas = self.thetas(terms, gamma)
        out, n_valid = run_kernel(self.code, thetas, self.t, self.inputs, self.s0,
                                  self.options.method, *self.bounds, n_steps=self.n_steps)
        return out, n_valid

    def score(self, cand: Candidate) -> Candidate:
        if cand.key in self.cache:
            return self.cache[cand.key]
        self.evaluations += 1
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                out, n_valid = self.free_runs(cand.terms, cand.gamma)
            except InfeasibleConstraintsError:
                # (a yaw equation without v and r terms cannot be straight-line stable)
                cand.score, cand.note = math.inf, "the constraints cannot be met with these terms"
                self.cache[cand.key] = cand
                return cand
        P = self.options.divergence_penalty
        per_fold = np.zeros((len(self.held), 3))
        diverged = 0
        for b, h in enumerate(self.held):
            n, m = int(self.n_steps[b]), int(n_valid[b])
            per_fold[b] = normalised_error(self.data.measured[h], out[b, :m, :3], P)
            diverged += m < n
        cand.state_scores = dict(zip(STATES, per_fold.mean(axis=0).round(6).tolist(), strict=True))
        cand.fold_scores = per_fold.mean(axis=1).tolist()
        cand.score = float(per_fold.mean())
        cand.folds_diverged = diverged
        if diverged == len(self.held):
            cand.note = "diverged in every fold"
        self.cache[cand.key] = cand
        return cand


# ---------------------------------------------------------------------------- rankings
def frols_ranking(X: np.ndarray, y: np.ndarray, names: Sequence[str], centred: bool = True
                  ) -> list[tuple[str, float]]:  # fmt: skip
    """Terms in the order of forward orthogonal least squares, with their error-reduction ratio
    (share of the centred target variance each term explains, orthogonally to the ones before).
    ``centred=False`` for an equation without a constant: its terms then explain the target's
    mean too (its sum of squares about 0), which a constant would take first."""
    Xc = X - X.mean(axis=0) if centred else X
    yc = y - y.mean() if centred else y
    yy = float(yc @ yc)
    if yy <= 0:
        return [(n, 0.0) for n in names]
    remaining = list(range(X.shape[1]))
    basis: list[np.ndarray] = []
    out = []
    norms0 = np.maximum(np.linalg.norm(Xc, axis=0), 1e-300)
    while remaining:
        best, best_err, best_w = None, -1.0, None
        for j in remaining:
            w = Xc[:, j].copy()
            for q in basis:
                w -= (q @ w) * q
            nw = float(np.linalg.norm(w))
            if nw < 1e-8 * norms0[j]:
                err = 0.0
            else:
                g = float(w @ yc) / nw
                err = g * g / yy
            if err > best_err:
                best, best_err, best_w = j, err, (w / nw if nw >= 1e-8 * norms0[j] else None)
        out.append((names[best], float(best_err)))
        remaining.remove(best)
        if best_w is not None:
            basis.append(best_w)
    return out


def _stlsq_terms(X: np.ndarray, y: np.ndarray, names: Sequence[str], threshold: float,
                 gamma: float) -> tuple[str, ...]:  # fmt: skip
    """Sequentially thresholded ridge on standardised regressors (SINDy): drop terms whose
    standardised coefficient is below ``threshold`` × the largest, refit, until stable."""
    mean, scale = X.mean(axis=0), X.std(axis=0)
    scale[scale == 0] = 1.0
    Z = (X - mean) / scale
    yc = y - y.mean()
    keep = np.ones(X.shape[1], dtype=bool)
    for _ in range(10):
        if not keep.any():
            break
        Zk = Z[:, keep]
        w = np.linalg.solve(Zk.T @ Zk + np.eye(Zk.shape[1]) * len(y) / gamma, Zk.T @ yc)
        big = np.abs(w) >= threshold * np.max(np.abs(w))
        if big.all():
            break
        idx = np.flatnonzero(keep)
        keep[idx[~big]] = False
    return tuple(n for n, k in zip(names, keep, strict=True) if k)


# ---------------------------------------------------------------------------- γ pre-screen
def _loo_gamma_scores(data: _Data, terms, gammas) -> dict[float, float]:
    """Sum over DOFs of the exact LOO MSE of the linear LS-SVM / var(target), per γ."""
    from shipid.lssvm.loo import PrimalLOOPath

    scores = dict.fromkeys(gammas, 0.0)
    for dof in terms:
        names, X, y = _stacked(data, dof, terms[dof])
        if not names:
            continue
        var = float(np.var(y)) or 1.0
        path = PrimalLOOPath(X, y[:, None], np.ones(len(y)))
        for g, mse in zip(gammas, path.mse_grid(gammas), strict=True):
            scores[g] += mse / var
    return scores


# ---------------------------------------------------------------------------- fixed structures
def cross_validate(
    logs: Sequence[pd.DataFrame],
    structure: str | ModelStructure,
    gammas: Sequence[float] = (1e4,),
    names: Sequence[str] | None = None,
    cv: str = "logo",
    estimator: str = "lssvm",
    method: str = "euler",
    divergence_penalty: float = 2.0,
) -> pd.DataFrame:
    """Free-run CV of one structure at each γ: one row per (γ, held-out log) with the normalised
    error per state (see ``normalised_error``) and whether the fold diverged."""
    options = SelectOptions(library=structure, search="none", gammas=tuple(gammas), cv=cv,
                            estimator=estimator, method=method,
                            divergence_penalty=divergence_penalty)  # fmt: skip
    require_states(logs, names, "log to select on")  # its free runs score every state
    logs, names, data, folds, scorer = _setup(logs, names, options)
    full = {d: tuple(data.library.terms[d]) for d in data.library.dofs}
    rows = []
    for g in options.gammas:
        out, n_valid = scorer.free_runs(full, g)
        for b, h in enumerate(scorer.held):
            m = int(n_valid[b])
            e = normalised_error(data.measured[h], out[b, :m, :3], divergence_penalty)
            rows.append({"gamma": g, "held_out": names[h], "diverged": m < len(data.measured[h]),
                         **dict(zip(STATES, e.tolist(), strict=True)), "score": float(e.mean())})
    return pd.DataFrame(rows)


# The README's library for free-running trials: four-quadrant propeller and rudder, wind, a single
# propeller's asymmetry, and the hull going stern first (``shipid.dynamics.model``); the astern
# terms are zero, and left out, for logs that never go astern. Where random runs go astern, they
# predict a held-out random run's yaw rate better (0.46 of its spread, 0.51 without, over four
# folds of the Esso Osaka logs; benchmarks/README.md).
DEFAULT_LIBRARY = "low-speed+wind+propeller-asymmetry+astern"


def default_library(logs: Sequence[pd.DataFrame], name: str = DEFAULT_LIBRARY,
                    similar: Sequence[str] = DOFS) -> tuple[ModelStructure, str]:  # fmt: skip
    """``DEFAULT_LIBRARY`` (or the library ``name``) less the terms that need a log column some
    log lacks (the wind of a basin's logs, the propeller speed of a log without it) and the
    terms that are zero along every log (astern propeller terms where the propeller never
    reverses), and a note saying which were left out ('' when none): the library asked for by
    name refuses such logs instead. A term the logs never excite has no coefficient to find;
    kept, it made every fit of the library singular (condition number 5.7e14 on zig-zags at 8
    and 12 rps). Where each log runs at one propeller speed, its constant and δ² are written as
    advance-ratio similarity has them, n|n| and n⁺²δ², which it already holds
    (``shipid.dynamics.similarity.similar_library``): no candidate holds a force that stays the
    same at every propeller speed (``similar``: the equations so written; ``SIDE_FORCE``, the
    side force's alone; () keeps them). Logs at a few propeller speeds
    tell a constant from the thrust only across those few, and the constant is then what
    carries a model wrong beyond them (the Esso's pairs of zig-zag files: 17 of 360 held turns
    at 8–16.7 rps failed with it, none without); a log whose rps varies (a random run) shows
    within itself how the forces go with n, and there the constant stays (with it the Esso's
    thirteen logs predict the other turn 4.4 % off, without it 5.1 %)."""
    from shipid.identification.identify import varying_propulsion

    library = get_structure(name)
    missing = sorted({c for log in logs for c in library.inputs if c not in log.columns})
    every_log_has_thrust = all("thrust" in log.columns for log in logs)
    thrust = [v for v in varying_propulsion(logs) if v.signal == "thrust" and every_log_has_thrust]
    if thrust:
        # The thrust as logged, where no rps is (blanke-thrust's, as identify's default fits).
        library = library.union({"u": ["T"]})
    replaced: tuple[str, ...] = ()
    if similar and "n" not in missing and _each_at_one_rps(logs):
        library, replaced = similar_library(library, similar)
    drop = {d: [t for t in ts if set(parse_term(t).inputs) & set(missing)]
            for d, ts in library.terms.items()}  # fmt: skip
    notes = []
    if thrust:
        notes.append(f"{thrust[0].describe()}, and no rps is logged: the surge holds it as "
                     "logged, T")  # fmt: skip
    if replaced and set(similar) >= set(DOFS):
        notes.append(f"{', '.join(replaced)} are written as advance-ratio similarity has them "
                     "(n|n|, n⁺²δ², which the library holds): a force that stays the same at "
                     "every propeller speed is no ship's")  # fmt: skip
    elif replaced:
        notes.append(f"the constant of {', '.join(similar)} is written as advance-ratio "
                     "similarity has it (n|n|, which the library holds): a side force that "
                     "stays the same at every propeller speed is no ship's")  # fmt: skip
    if missing:
        n = sum(len(ts) for ts in drop.values())
        notes.append(f"the default library's {n} term(s) that need the log column(s) "
                     f"{', '.join(missing)}, which these logs lack, are left out")
    zero = sorted({t for d, ts in library.terms.items() for t in ts if t not in drop[d]
                   and all(not np.any(log_terms(log, [t])) for log in logs)})  # fmt: skip
    if zero:
        for d, ts in library.terms.items():
            drop[d] += [t for t in ts if t in zero]
        notes.append(f"{', '.join(zero)} are zero along every log, which never excite them, "
                     "and are left out")  # fmt: skip
    if not notes:
        return library, ""
    trimmed = library.without({d: ts for d, ts in drop.items() if ts})
    return trimmed, "; ".join(notes) + " (--library chooses the candidates)"


def _each_at_one_rps(logs: Sequence[pd.DataFrame]) -> bool:
    """Whether every log runs at one propeller speed (``plausibility.held_propeller_speeds``)."""
    from shipid.identification.plausibility import held_propeller_speeds

    return held_propeller_speeds(logs)[1]


def _setup(logs, names, options: SelectOptions):
    if isinstance(logs, pd.DataFrame):
        logs = [logs]
    logs, _ = common_rudder_convention(list(logs))  # select() converts first, with notes
    names = list(names or [log.attrs.get("name", f"log {i}") for i, log in enumerate(logs)])
    refuse_other_ships(logs, names)
    refuse_copies(logs, names)
    kind, k = parse_cv(options.cv)
    if kind == "blocks":
        logs, names = split_blocks(logs, names, k)
    if len(logs) < 2:
        raise ShipidError("cross-validation needs at least 2 logs to hold one out; give more "
                          "logs, or cut one into blocks with --cv blocks:K")  # fmt: skip
    note = ""
    try:
        if options.library is None:
            library, note = default_library(logs)
        elif isinstance(options.library, str):
            library = get_structure(options.library)
        else:
            library = options.library
    except ValueError as exc:
        raise ShipidError(str(exc)) from None
    if options.keep is not None:
        library = _with_kept(library, options.keep, logs, names)
    data = _prepare(logs, names, library)
    data.library_note = note
    folds = _folds(len(logs), options.cv)
    options = dataclasses.replace(options, physics=_bounds_in_library(options.physics, library))
    return logs, names, data, folds, _Scorer(data, options, folds)


def _with_kept(library: ModelStructure, keep: ModelStructure, logs, names) -> ModelStructure:
    """The library with the terms to keep added (a term zero along every log refused: its
    column would make every fit singular; one whose column a log lacks is named by
    ``_prepare``, as a library's term is)."""
    for dof, terms in keep.terms.items():
        if dof not in library.terms:
            raise ShipidError(f"--keep: the library {library.name} has no {dof} equation")
        for term in terms:
            if any(c not in log.columns for log in logs for c in parse_term(term).inputs):
                continue
            if all(not np.any(log_terms(log, [term], name))
                   for log, name in zip(logs, names, strict=True)):  # fmt: skip
                raise ShipidError(f"--keep: the term {term!r} ({dof}) is zero along every log, "
                                  "which never excite it: it has no coefficient to find")
    added = {d: [t for t in ts if t not in library.terms[d]] for d, ts in keep.terms.items()}
    if not any(added.values()):
        return library
    extra = ModelStructure("kept", {d: tuple(ts) for d, ts in added.items() if ts})
    return ModelStructure(library.name, (library + extra).terms)


# ---------------------------------------------------------------------------- the search
def select(
    logs: Sequence[pd.DataFrame],
    options: SelectOptions | None = None,
    names: Sequence[str] | None = None,
    **overrides,
) -> Selection:
    """Choose the structure (from ``options.library``) and γ by cross-validated free-run error.

    ``options`` (a ``SelectOptions``) or its fields as keywords. Logs share one Δk (resample with
    ``dt=`` when reading) and are trimmed to what the model should reproduce.
    """
    import dataclasses

    from shipid.identification.beyond_the_logs import given_steady_speeds
    from shipid.identification.identify import identify
    from shipid.identification.plausibility import (
        crash_stop,
        disqualifying,
        disqualifying_checks,
        failed_checks,
        gross_at_other_rps,
        other_propeller_speeds,
        plausibility_at_approach,
        sharpest_curvature,
    )

    options = dataclasses.replace(options or SelectOptions(), **overrides)
    require_states(logs, names, "log to select on")  # its free runs score every state
    given = given_steady_speeds(options.physics)  # before the logs' approaches fill them in
    # The constraints' approaches, resolved once for the thousand fits of the search.
    options = dataclasses.replace(options, physics=with_approaches(
        options.physics, [logs] if isinstance(logs, pd.DataFrame) else list(logs)))
    # Converted once here, for the notes; _setup's own pass then finds one convention.
    logs, notes = common_rudder_convention([logs] if isinstance(logs, pd.DataFrame) else list(logs))
    logs, names, data, folds, scorer = _setup(logs, names, options)
    library = data.library
    options = dataclasses.replace(options, physics=_bounds_in_library(options.physics, library))
    if data.library_note:
        notes.append(data.library_note)
    # The first log's approach; each candidate is checked from its own steady approach there.
    speed = options.speed if options.speed is not None else approach(logs[0], "u")
    rps = options.rps if options.rps is not None else approach(logs[0], "n")
    if speed is None or not speed > 0:
        raise ShipidError(f"{names[0]}: starts without headway; give the plausibility condition "
                          "(speed=..., --speed)")  # fmt: skip
    curvature = sharpest_curvature(logs, speed)
    other_rps = other_propeller_speeds(logs, rps) if options.plausibility else []
    bar = _progress(options)

    def evaluate(terms, gamma, stage) -> Candidate:
        cand = Candidate({d: tuple(t) for d, t in terms.items()}, float(gamma), stage=stage)
        if scorer.evaluations >= options.max_evaluations and cand.key not in scorer.cache:
            cand.note = "not evaluated (--max-evaluations reached)"
            return cand
        out = scorer.score(cand)
        bar.update()
        return out

    plausibility_cache: dict[tuple, tuple[bool, str]] = {}

    def plausible(cand: Candidate) -> bool:
        if not options.plausibility or cand.score == math.inf:
            return cand.score < math.inf
        if cand.key not in plausibility_cache:
            try:
                theta = _fit_theta(data, cand.terms, cand.gamma, range(len(logs)),
                                   options.estimator, options.physics)  # fmt: skip
            except InfeasibleConstraintsError:
                plausibility_cache[cand.key] = (False, "the constraints cannot be met on all logs")
            else:
                model = _model_from_theta(data, cand.terms, theta, "candidate")
                report, _ = plausibility_at_approach(model, speed, rps, options.speed, options.rps,
                                                     curvature)  # fmt: skip
                reasons = disqualifying(report, model)
                for u, n in given:  # where the user says the ship runs steady
                    at = plausibility_at_approach(model, u, n, u, n)[0]
                    reasons += [f"{r} at {u:.3g} m/s, {n:.3g} rps"
                                for r in disqualifying(at, model)]  # fmt: skip
                if not reasons:  # no ship fails so at a propeller speed its logs ran at
                    reasons = [why for _, why in
                               gross_at_other_rps(model, speed, rps, other_rps).values()]
                plausibility_cache[cand.key] = (not reasons, "; ".join(reasons))
        ok, why = plausibility_cache[cand.key]
        cand.plausible = ok
        if not ok:
            cand.note = f"implausible: {why}"
        return ok

    def best(cands: list[Candidate]) -> Candidate | None:
        for c in sorted(cands, key=lambda c: c.score):
            if c.score < math.inf and plausible(c):
                return c
        return None

    full = {d: tuple(library.terms[d]) for d in library.dofs}
    # γ: exact LOO pre-screen, free-run CV the arbiter.
    loo = _loo_gamma_scores(data, full, options.gammas)
    best_loo = min(loo.values())
    gammas = [g for g in options.gammas if loo[g] <= 1.5 * best_loo] or [min(loo, key=loo.get)]
    start = best([evaluate(full, g, "γ on the library") for g in gammas])
    if start is None:
        start = min((scorer.cache[k] for k in scorer.cache), key=lambda c: c.score)
        notes.append("no plausible model with the whole library; the search starts from the "
                     "best-scoring one")  # fmt: skip
    gamma = start.gamma
    kept = {d: tuple(options.keep.terms.get(d, ())) if options.keep else () for d in full}
    ranking = _rankings(data, full, kept)
    current = start
    if options.search == "stepwise":
        current = _stepwise(full, ranking, gamma, evaluate, best, current, kept)
    elif options.search == "frols":
        cands = [evaluate(_by_rho(full, ranking, rho, kept), gamma, f"frols ρ = {rho:g}")
                 for rho in RHO_GRID]  # fmt: skip
        current = best(cands + [current]) or current
    elif options.search == "stlsq":
        cands = [evaluate(_stlsq(data, full, thr, gamma, kept), gamma, f"stlsq threshold {thr:g}")
                 for thr in STLSQ_GRID]  # fmt: skip
        current = best(cands + [current]) or current
    # γ again, for the chosen structure.
    if options.search != "none":
        current = best([current] + [evaluate(current.terms, g, "γ on the chosen structure")
                                    for g in options.gammas]) or current  # fmt: skip
    bar.close()
    if options.one_standard_error:
        current = _one_standard_error(scorer.cache.values(), current, plausible)
    shares = selection_shares(list(scorer.cache.values()), plausible, options.one_standard_error)
    for cand in scorer.cache.values():
        cand.share = shares.get(cand.key, 0.0)
    if not plausible(current):
        notes.append(f"the chosen model is implausible ({current.note}); no candidate passed "
                     "the checks")  # fmt: skip
    scored = [c for c in scorer.cache.values() if c.score < math.inf]
    top = min(scored, key=lambda c: c.score) if scored else current
    best_ruled_out = "" if top is current or plausible(top) else top.note.removeprefix(
        "implausible: ")
    structure = ModelStructure(f"selected from {library.name}", current.terms)
    ident = identify(logs, model=structure, gamma=current.gamma, names=names, force=True,
                     estimator=options.estimator, physics=options.physics)  # fmt: skip
    shared = sorted((c for c in scorer.cache.values() if c.share > 0), key=lambda c: -c.share)
    weights = [(current, 1.0)]
    model = ident.model
    checked = None  # (report, notes) of the model's plausibility, when computed here
    if options.average and shared:
        weights = [(c, c.share) for c in shared]
        averaged = _averaged_model(data, weights, current, range(len(logs)), options,
                                   f"average of {len(shared)} candidates from {library.name}")
        checked = plausibility_at_approach(averaged, speed, rps, options.speed, options.rps,
                                           curvature)  # fmt: skip
        failing = ({**disqualifying_checks(checked[0], averaged),
                    **gross_at_other_rps(averaged, speed, rps, other_rps)}
                   if options.plausibility else {})  # fmt: skip
        if failing:
            # Check by check: the chosen candidate only where it fails them less badly.
            own = {**disqualifying_checks(plausibility_at_approach(
                model, speed, rps, options.speed, options.rps, curvature)[0], model),
                **gross_at_other_rps(model, speed, rps, other_rps)}  # fmt: skip
            failing = {k: f for k, f in failing.items() if f[0] > own.get(k, (0, ""))[0]}
        if failing:
            notes.append(f"the average of the candidates is implausible "
                         f"({'; '.join(r for _, r in failing.values())}); the model is the "
                         "chosen candidate")  # fmt: skip
            weights = [(current, 1.0)]
            checked = None
        else:
            model = averaged
    if checked is None:
        checked = plausibility_at_approach(model, speed, rps, options.speed, options.rps,
                                           curvature)  # fmt: skip
    # The model handed out is also run through a crash stop (a warning: the thousands of
    # candidates above are not).
    checked[0]["astern"] = crash_stop(model, checked[0]["approach_speed"], checked[0]["rps"],
                                      checked[0].get("duration"))  # fmt: skip
    checked = (checked[0], [note for _, note in failed_checks(checked[0], model).values()])
    folds_report, held_out_runs = _fold_report(data, scorer, weights, current, logs, names)
    table = _table(scorer.cache.values(), current)
    failed = [c for c in scorer.cache.values() if c.folds_diverged == len(scorer.held)]
    if len(scorer.folds) < FEW_FOLDS:
        notes.append(f"only {len(scorer.folds)} folds: the CV scores and their standard error "
                     "rest on so few held-out runs that the choice among close candidates is "
                     "weak; give more logs, or cut long ones with --cv blocks:K")  # fmt: skip
    if failed:
        notes.append(f"{len(failed)} candidate(s) diverged in every fold (kept in the table)")
    held = "blocks" if parse_cv(options.cv)[0] == "blocks" else "logs"
    band = error_band([run for _, run, _ in held_out_runs], held_out=held,
                      names=[name for name, _, _ in held_out_runs],
                      indices=[ind for _, _, ind in held_out_runs]) if held_out_runs else None
    return Selection(model, ident, current.gamma, current.score, table, folds_report,
                     options, library, ranking, notes + ident.warnings, shared, band,
                     ident.model, *checked, best_ruled_out=best_ruled_out,
                     fold_scores=list(current.fold_scores))  # fmt: skip


def _averaged_model(data: _Data, weights, first: Candidate, train, options: SelectOptions,
                    name: str) -> ManoeuvringModel:  # fmt: skip
    """The candidates fitted on the logs ``train``, their coefficients averaged with the weights
    (``average_models``: a candidate's coefficient of a term it lacks is 0); terms: ``first``'s,
    then the others'."""
    from shipid.identification.identify import average_models

    total = sum(w for _, w in weights)
    fits = [(_model_from_theta(data, c.terms, _fit_theta(data, c.terms, c.gamma, train,
                                                         options.estimator, options.physics),
                               name), w / total) for c, w in weights]  # fmt: skip
    return average_models(fits, ModelStructure("first", first.terms), name)


def selection_shares(cands: Sequence[Candidate], plausible, one_standard_error: bool = True,
                     resamples: int = RESAMPLES, seed: int = 0) -> dict[tuple, float]:
    """Per candidate key: the share of ``resamples`` bootstrap resamples of the held-out logs
    (folds drawn with replacement; each candidate's score the mean of its resampled fold scores)
    on which the choice rule picks it: the best plausible score, then, with
    ``one_standard_error``, the sparsest plausible candidate within one standard error of it."""
    pool = [c for c in cands if c.score < math.inf and c.fold_scores]
    if not pool:
        return {}
    F = np.array([c.fold_scores for c in pool])  # (C, K)
    K = F.shape[1]
    sizes = np.array([c.n_terms() for c in pool])
    rng = np.random.default_rng(seed)
    counts = np.zeros(len(pool))
    checked: dict[int, bool] = {}  # asked only where a resample reaches it: a check is a fit

    def ok(i) -> bool:
        if i not in checked:
            checked[i] = plausible(pool[i])
        return checked[i]

    for _ in range(resamples):
        f = F[:, rng.integers(0, K, K)]
        score = f.mean(axis=1)
        best = next((i for i in np.argsort(score, kind="stable") if ok(i)), None)
        if best is None:
            continue
        if one_standard_error and K > 1:
            limit = score[best] + f[best].std(ddof=1) / math.sqrt(K)
            within = np.flatnonzero(score <= limit)
            within = within[np.lexsort((score[within], sizes[within]))]
            best = next(i for i in within if ok(i))
        counts[best] += 1
    total = counts.sum()
    return {c.key: float(n / total) for c, n in zip(pool, counts, strict=True) if n} if total \
        else {}  # fmt: skip


def _one_standard_error(cands, best: Candidate, plausible) -> Candidate:
    """The sparsest plausible candidate whose CV score is within one standard error (over the
    folds) of the best one's (Breiman et al. 1984): as good as the data can tell, and simpler."""
    limit = best.score + best.standard_error
    pool = sorted((c for c in cands if c.score <= limit), key=lambda c: (c.n_terms(), c.score))
    return next((c for c in pool if plausible(c)), best)


def _progress(options: SelectOptions):
    from shipid.progress import progress_bar

    return progress_bar(None, "candidates", "cand", shown=bool(options.progress))


def _stacked(data: _Data, dof: str, terms) -> tuple[list[str], np.ndarray, np.ndarray]:
    """The regression of one DOF over all logs: term names (the constant excluded), X, y."""
    index = {t: j for j, t in enumerate(data.texts)}
    names = [t for t in terms if t != "1"]
    X = np.vstack([p[:, [index[t] for t in names]] for p in data.phi])
    y = np.concatenate([t[dof] for t in data.targets])
    return names, X, y


# The hull's resistance: first in the surge's ranking of a propelled ship, so that every candidate
# holds it (see _rankings).
HULL_RESISTANCE = "|u|*u"


def _rankings(data: _Data, full, kept: Mapping[str, Sequence[str]] | None = None
              ) -> dict[str, list[tuple[str, float]]]:  # fmt: skip
    """Per equation, the terms ranked by forward orthogonal least squares, the terms to keep
    (``kept``) first; in the surge of a
    library with propeller terms, the hull's resistance |u|u first. The ranking decides which
    terms a candidate of k terms holds, and on equation error alone u·|n| (the propeller's
    thrust falling with advance) can stand in for it: the Esso Osaka's surge chosen at the
    logs' 0.1 s damped the ship by u·|n| alone, balanced at 0.52 m/s at 10 rps where the ship
    holds 0.35 and, with the propeller stopped, lost speed at an almost constant 0.4 mm/s²
    whatever its speed."""
    out = {}
    for dof, terms in full.items():
        names, X, y = _stacked(data, dof, terms)
        ranked = frols_ranking(X, y, names, centred="1" in terms)
        propelled = any("n" in parse_term(t).inputs for t in terms)
        if dof == "u" and propelled and any(t == HULL_RESISTANCE for t, _ in ranked):
            ranked = sorted(ranked, key=lambda item: item[0] != HULL_RESISTANCE)
        if kept and kept.get(dof):
            ranked = sorted(ranked, key=lambda item: item[0] not in kept[dof])
        out[dof] = ranked
    return out


def _with_const(full, dof, names) -> tuple[str, ...]:
    return tuple(names) + (("1",) if "1" in full[dof] else ())


def _stepwise(full, ranking, gamma, evaluate, best, current: Candidate,
              kept: Mapping[str, Sequence[str]] | None = None) -> Candidate:  # fmt: skip
    sizes = {d: len(ranking[d]) for d in full}
    fewest = {d: max(1, len((kept or {}).get(d, ()))) for d in full}  # the kept rank first

    def terms_for(s):
        return {d: _with_const(full, d, [t for t, _ in ranking[d][: s[d]]]) for d in full}

    for _ in range(3):
        improved = False
        for dof in full:
            trials = []
            for k in range(fewest[dof], len(ranking[dof]) + 1):
                s = dict(sizes, **{dof: k})
                trials.append((k, evaluate(terms_for(s), gamma, f"stepwise {dof} ≤ {k} terms")))
            chosen = best([c for _, c in trials] + [current])
            if chosen is not None and chosen.score < current.score - 1e-12:
                current = chosen
                sizes[dof] = next(k for k, c in trials if c is chosen)
                improved = True
        if not improved:
            break
    return current


def _by_rho(full, ranking, rho: float, kept: Mapping[str, Sequence[str]] | None = None):
    out = {}
    for dof, ranked in ranking.items():
        total = sum(e for _, e in ranked)
        acc, keep = 0.0, []
        for t, e in ranked:
            if acc >= (1.0 - rho) * total and keep and t not in (kept or {}).get(dof, ()):
                break
            keep.append(t)
            acc += e
        out[dof] = _with_const(full, dof, keep)
    return out


def _stlsq(data: _Data, full, threshold: float, gamma: float,
           kept: Mapping[str, Sequence[str]] | None = None):  # fmt: skip
    out = {}
    for dof, terms in full.items():
        names, X, y = _stacked(data, dof, terms)
        chosen = _stlsq_terms(X, y, names, threshold, gamma)
        held = [t for t in (kept or {}).get(dof, ()) if t not in chosen]
        out[dof] = _with_const(full, dof, [t for t in names if t in chosen or t in held])
    return out


def _table(cands, chosen: Candidate) -> pd.DataFrame:
    rows = []
    for c in cands:
        rows.append({"chosen": c is chosen, "score": c.score, "score_se": c.standard_error,
                     **{f"score_{s}": c.state_scores.get(s, math.nan) for s in STATES},
                     "gamma": c.gamma, "n_terms": c.n_terms(),
                     **{f"terms_{d}": ", ".join(t) for d, t in c.terms.items()},
                     "folds_diverged": c.folds_diverged, "plausible": c.plausible,
                     "share": c.share, "stage": c.stage, "note": c.note})  # fmt: skip
    df = pd.DataFrame(rows)
    return df.sort_values("score", kind="stable").reset_index(drop=True)


def _fold_report(data, scorer: _Scorer, weights, chosen: Candidate, logs, names):
    """Per held-out log: the model (the candidates of ``weights`` averaged; the chosen one
    alone: [(chosen, 1)]) fitted without it, its free-run errors (the ``validate`` metrics) and
    indices; and each run's name, the (measured, simulated) u, v, r of it and its
    (measured, predicted) ``key_indices``."""
    from shipid.evaluation.validate import validate_log

    out, runs = [], []
    n_logs = len(logs)
    for fold in scorer.folds:
        train = [j for j in range(n_logs) if j not in fold]
        model = _averaged_model(data, weights, chosen, train, scorer.options, "fold model")
        for h in fold:
            try:
                # The report keeps the errors and indices, not how the closed loop's indices
                # move with its start's noise: those ten runs per log were drawn for nothing.
                v = validate_log(model, logs[h], names[h], scorer.options.method,
                                 start_draws=False)  # fmt: skip
                out.append({"held_out": names[h], "diverged": v.simulation.diverged,
                            "metrics": {s: v.metrics[s]["std"] for s in STATES},
                            "spread": {s: float(np.std(logs[h][s])) for s in STATES},
                            "kind": v.kind, "indices": v.indices})  # fmt: skip
                runs.append((names[h], (data.measured[h],
                                        column_array(v.simulation.log, STATES)),
                             key_indices(v.kind, v.indices)))  # fmt: skip
            except ShipidError as exc:
                out.append({"held_out": names[h], "error": str(exc)})
    return out, runs

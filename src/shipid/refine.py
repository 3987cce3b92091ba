"""Output-error refinement of an identified model: from the LS-SVM estimate, minimise the free-run
simulation error over the training logs by multiple shooting.

The one-step regression of the paper (eqs. 11–12) fits accelerations; a model that fits them well can
still drift or diverge when simulated over a whole trial, which is what users run it for. Refinement
fits the simulation itself. Each training log is cut into segments of ``segment_s`` seconds; every
segment starts from its own estimated initial state (u, v, r), is simulated with the model's scheme
driven by the measured rudder, and is compared with the measured states. The cost is

    J(θ, s₀) = Σ_seg Σ_k Σ_ξ ((ξ̂_k − ξ_k)/σ_ξ)²                 simulation error
             + ρ Σ_seams Σ_ξ ((ξ̂_end,i − ξ̂_0,i+1)/σ_ξ)²          continuity of the shooting
             + Σ_dof Σ_j (θ_j / (√γ σ_e,dof))²                     the LS-SVM prior

σ_ξ is the spread of state ξ in the training data, σ_e,dof the one-step equation-error spread of the
LS-SVM model: the last term is the LS-SVM's ½‖w‖² kept at its weight 1/γ relative to a unit-variance
error term (eq. 4). Minimised by ``scipy.optimize.least_squares`` (trust-region reflective, sparse
finite-difference Jacobian: an initial state only moves its own segment).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np
import pandas as pd
from scipy.optimize import least_squares
from scipy.sparse import lil_matrix

from .errors import ShipidError
from .model import DOFS, ManoeuvringModel
from .regression import sampling_time
from .simulate import METHODS, DivergenceBounds, integrate_coefficients
from .terms import TERM_INDEX, TERMS
from .validate import validate

SHOT_STATES = ("u", "v", "r")  # estimated at the start of every segment
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

    def to_dict(self) -> dict:
        return {"initial_model": self.initial.to_dict(), "segment_s": self.segment_s,
                "n_segments": self.n_segments, "states": list(self.states),
                "cost_initial": self.cost_initial, "cost_final": self.cost_final,
                "nfev": self.nfev, "success": self.success, "message": self.message,
                "free_run": self.free_run, "warnings": self.warnings}  # fmt: skip


@dataclass
class _Segments:
    """Training logs cut into B segments, padded to one length for the batch simulator."""

    t: np.ndarray  # (L,) common grid from 0
    delta: np.ndarray  # (B, L)
    thrust: np.ndarray  # (B, L)
    measured: np.ndarray  # (B, L, n_states)
    mask: np.ndarray  # (B, L) True on real samples
    psi0: np.ndarray  # (B,)
    shot0: np.ndarray  # (B, 3) measured u, v, r at each segment's start
    seams: list[tuple[int, int]]  # (segment i, segment i + 1) of the same log
    sigma: np.ndarray  # (n_states,)


def _cut(logs: Sequence[pd.DataFrame], names: Sequence[str], segment_s: float | None,
         states: tuple[str, ...], uses_thrust: bool) -> tuple[_Segments, float, float]:  # fmt: skip
    dts = [sampling_time(log, n) for log, n in zip(logs, names, strict=True)]
    dt = dts[0]
    for d, n in zip(dts[1:], names[1:], strict=True):
        if abs(d - dt) > 1e-6 * dt:
            raise ShipidError(f"{n}: sampling time {d:.6g} s differs from {dt:.6g} s; resample the "
                              "logs to one Δk with --dt")  # fmt: skip
    longest = max(len(log) for log in logs) - 1
    if segment_s is None:
        steps = longest
    else:
        if not (math.isfinite(segment_s) and segment_s > 0):
            raise ShipidError(f"--segment must be > 0 s, got {segment_s!r}")
        steps = max(int(round(segment_s / dt)), 2)
    bounds = []  # (log index, first sample, last sample)
    for i, log in enumerate(logs):
        if uses_thrust and "thrust" not in log.columns:
            raise ShipidError(f"{names[i]}: the model has a thrust term T but the log has no "
                              "'thrust' column")  # fmt: skip
        n = len(log) - 1
        count = max(1, int(round(n / steps)))
        edges = np.linspace(0, n, count + 1).round().astype(int)
        bounds += [(i, int(a), int(b)) for a, b in zip(edges[:-1], edges[1:], strict=True)]
    L = max(b - a for _, a, b in bounds) + 1
    B = len(bounds)
    seg = _Segments(
        t=np.arange(L) * dt, delta=np.zeros((B, L)), thrust=np.zeros((B, L)),
        measured=np.zeros((B, L, len(states))), mask=np.zeros((B, L), dtype=bool),
        psi0=np.zeros(B), shot0=np.zeros((B, 3)), seams=[], sigma=np.ones(len(states)),
    )  # fmt: skip
    for b, (i, a, e) in enumerate(bounds):
        log = logs[i]
        m = e - a + 1
        d = log["delta"].to_numpy()[a : e + 1]
        seg.delta[b, :m], seg.delta[b, m:] = d, d[-1]
        if uses_thrust:
            th = log["thrust"].to_numpy()[a : e + 1]
            seg.thrust[b, :m], seg.thrust[b, m:] = th, th[-1]
        for j, s in enumerate(states):
            seg.measured[b, :m, j] = _signal(log, s)[a : e + 1]
        seg.mask[b, :m] = True
        seg.psi0[b] = _signal(log, "psi")[a] if "psi" in log.columns else 0.0
        seg.shot0[b] = [float(log[s].iloc[a]) for s in SHOT_STATES]
        if b > 0 and bounds[b - 1][0] == i:
            seg.seams.append((b - 1, b))
    for j, s in enumerate(states):
        values = np.concatenate([_signal(log, s) - (_signal(log, s).mean() if s == "psi" else 0.0)
                                 for log in logs])  # fmt: skip
        spread = float(np.std(values))
        if not spread > 0:
            raise ShipidError(f"state {s} does not vary in the training logs: nothing to fit it to")
        seg.sigma[j] = spread
    return seg, dt, steps * dt


def _signal(log: pd.DataFrame, s: str) -> np.ndarray:
    x = log[s].to_numpy(dtype=float)
    return np.unwrap(x) if s == "psi" else x


def _equation_error_spread(model: ManoeuvringModel, logs: Sequence[pd.DataFrame], dt: float) -> dict:
    """One-step equation-error std per DOF of ``model`` on the logs (the increment-form residual)."""
    errors: dict[str, list] = {d: [] for d in model.structure.dofs}
    for log in logs:
        thrust = log["thrust"].to_numpy() if model.uses_thrust else None
        acc = model.accelerations(log["u"], log["v"], log["r"], log["delta"], thrust)[:-1]
        for i, dof in enumerate(DOFS):
            if dof in errors:
                x = log[dof].to_numpy()
                errors[dof].append((x[1:] - x[:-1]) / dt - acc[:, i])
    return {d: max(float(np.std(np.concatenate(e))), 1e-12) for d, e in errors.items()}


def refine(
    model: ManoeuvringModel,
    logs: Sequence[pd.DataFrame] | pd.DataFrame,
    segment_s: float | None = 30.0,
    gamma: float = 1e4,
    states: Sequence[str] | None = None,
    continuity: float = 1.0,
    method: str = "euler",
    max_nfev: int = 100,
    names: Sequence[str] | None = None,
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
    continuity : weight ρ of the seams between consecutive segments.
    method : 'euler' (the paper's scheme and ``validate``'s default) or 'rk4'.
    max_nfev : cap on the number of cost evaluations of ``least_squares``.
    """
    if isinstance(logs, pd.DataFrame):
        logs = [logs]
    if not logs:
        raise ShipidError("no training logs given for the refinement")
    if method not in METHODS:
        raise ShipidError(f"method must be one of {METHODS}, got {method!r}")
    if not (math.isfinite(gamma) and gamma > 0):
        raise ShipidError(f"--gamma must be > 0, got {gamma!r}")
    if not (math.isfinite(continuity) and continuity >= 0):
        raise ShipidError(f"continuity weight must be ≥ 0, got {continuity!r}")
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
    seg, dt, seg_len = _cut(logs, names, segment_s, states, model.uses_thrust)
    B, L = seg.delta.shape

    # Parameters: the model's coefficients, then (u, v, r) at the start of every segment.
    slots = [(i, TERM_INDEX[n]) for i, dof in enumerate(DOFS)
             for n in model.coefficients.get(dof, {})]  # fmt: skip
    n_theta = len(slots)
    rows = np.array([i for i, _ in slots], dtype=int)
    cols = np.array([j for _, j in slots], dtype=int)
    theta0 = model.theta[rows, cols].copy()
    x0 = np.concatenate([theta0, seg.shot0.ravel()])
    held = [s for s in SHOT_STATES if s not in dofs]  # held states keep their measured value

    sigma_e = _equation_error_spread(model, logs, dt)
    prior_scale = np.array([1.0 / (math.sqrt(gamma) * sigma_e[DOFS[i]]) for i in rows])
    state_col = [SHOT_STATES.index(s) if s != "psi" else 3 for s in states]
    speed_lim, yaw_lim = DivergenceBounds().resolved(float(np.max(np.abs(seg.shot0[:, 0]))))
    sqrt_rho = math.sqrt(continuity)
    n_res = B * L * len(states) + len(seam_pairs := seg.seams) * 3 + n_theta
    seam_a = np.array([a for a, _ in seam_pairs], dtype=int)
    seam_b = np.array([b for _, b in seam_pairs], dtype=int)
    last = seg.mask.sum(axis=1) - 1
    shot_sigma = np.array([seg.sigma[states.index(s)] if s in states else 1.0
                           for s in SHOT_STATES])  # fmt: skip

    def simulate(x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        theta = np.zeros_like(model.theta)
        theta[rows, cols] = x[:n_theta]
        s0 = np.zeros((B, 6))
        s0[:, :3] = x[n_theta:].reshape(B, 3)
        s0[:, 3] = seg.psi0
        return integrate_coefficients(theta, seg.t, seg.delta, seg.thrust, s0, method,
                                      speed_lim, yaw_lim)  # fmt: skip

    def residuals(x: np.ndarray) -> np.ndarray:
        out, n_valid = simulate(x)
        sim = out[:, :, state_col]
        res = (sim - seg.measured) / seg.sigma
        alive = np.arange(L)[None, :] < n_valid[:, None]
        res[~alive] = DIVERGED_RESIDUAL
        res[~seg.mask] = 0.0
        s = x[n_theta:].reshape(B, 3)
        end = out[seam_a, last[seam_a], :3]
        seams = sqrt_rho * (end - s[seam_b]) / shot_sigma
        seams[~(n_valid[seam_a] > last[seam_a])] = DIVERGED_RESIDUAL
        return np.concatenate([res.ravel(), seams.ravel(), x[:n_theta] * prior_scale])

    # A segment's initial state moves its own samples and its two seams only.
    sparsity = lil_matrix((n_res, x0.size), dtype=int)
    sparsity[:, :n_theta] = 1
    per_seg = L * len(states)
    for b in range(B):
        sparsity[b * per_seg : (b + 1) * per_seg, n_theta + 3 * b : n_theta + 3 * b + 3] = 1
    base = B * per_seg
    for k, (a, b) in enumerate(seam_pairs):
        sparsity[base + 3 * k : base + 3 * k + 3, n_theta + 3 * a : n_theta + 3 * a + 3] = 1
        sparsity[base + 3 * k : base + 3 * k + 3, n_theta + 3 * b : n_theta + 3 * b + 3] = 1
    sparsity[-n_theta:, :n_theta] = np.eye(n_theta, dtype=int)
    lower = np.full(x0.size, -np.inf)
    upper = np.full(x0.size, np.inf)
    for s in held:  # a held state is not estimated: pin it (bounds need lower < upper)
        k = SHOT_STATES.index(s)
        idx = n_theta + 3 * np.arange(B) + k
        lower[idx], upper[idx] = x0[idx] - 1e-12, x0[idx] + 1e-12
    scale = np.concatenate([np.maximum(np.abs(theta0), 1e-3 * (np.abs(theta0).max() or 1.0)),
                            np.tile(shot_sigma, B)])  # fmt: skip

    cost_initial = 0.5 * float(np.sum(residuals(x0) ** 2))
    fit = least_squares(residuals, x0, jac_sparsity=sparsity, method="trf", x_scale=scale,
                        max_nfev=max_nfev, bounds=(lower, upper))  # fmt: skip
    coefs = {dof: {} for dof in dofs}
    for (i, j), value in zip(slots, fit.x[:n_theta], strict=True):
        coefs[DOFS[i]][TERMS[j]] = float(value)
    refined = ManoeuvringModel(model.structure, coefs, name=f"refined ({model.structure.name})")

    notes = []
    if fit.status == 0:
        notes.append(f"refinement stopped at the evaluation cap ({max_nfev}) before converging; "
                     "raise max_nfev or shorten the segments")  # fmt: skip
    free_run = []
    before = validate(model, logs, names, method=method)
    after = validate(refined, logs, names, method=method)
    for name, b0, b1 in zip(names, before, after, strict=True):
        free_run.append({"name": name,
                         "initial": {s: b0.metrics[s]["std"] for s in SHOT_STATES},
                         "refined": {s: b1.metrics[s]["std"] for s in SHOT_STATES},
                         "initial_diverged": b0.simulation.diverged,
                         "refined_diverged": b1.simulation.diverged})  # fmt: skip
        if b1.simulation.diverged:
            notes.append(f"{name}: the refined model diverges in a free run over the whole log "
                         f"({b1.simulation.reason})")  # fmt: skip
    return Refinement(refined, model, seg_len, B, states, cost_initial, float(fit.cost),
                      int(fit.nfev), bool(fit.success), str(fit.message), free_run, notes)  # fmt: skip

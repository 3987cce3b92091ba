"""Linear-algebra cores of the LS-SVM: the dense dual KKT solve and the primal ridge solve.

Both solve the same problem (paper eqs. 2–6) with per-sample regularisation γᵢ = γ·wᵢ:

    min ½‖ω‖² + ½ Σ γ wᵢ eᵢ²   subject to   yᵢ = ωᵀφ(xᵢ) + b + eᵢ.

*Dual*: with H = K + diag(1/(γw)), solve H ν = y and H η = 1; then b = 1ᵀν / 1ᵀη and α = ν − η b.
This is the bordered KKT system of the paper eliminated by one SPD (Cholesky) factorisation.

*Primal*: with explicit features φ (the inputs themselves for the linear kernel, Nyström features
for fixed-size), the normal equations of the same problem are the (p+1)×(p+1) bordered system

    [ Σ w φφᵀ + I/γ   Σ w φ ] [ω]   [ Σ w φ y ]
    [ Σ w φᵀ          Σ w   ] [b] = [ Σ w y   ]
"""

from __future__ import annotations

import warnings
from collections.abc import Iterable, Sequence

import numpy as np
from scipy import linalg

from shipid.blas import blas_threads, threads_for
from shipid.errors import InfeasibleConstraintsError
from shipid.limits import available_memory_bytes

# SciPy's bundled OpenBLAS has crashed in a threaded Cholesky on 16 000 × 16 000 matrices on the
# 2-core machines this project targets; above this size the factorisation runs single-threaded.
SINGLE_THREAD_CHOLESKY_ABOVE = 12_000


class NumericalWarning(UserWarning):
    """An ill-conditioned or otherwise suspicious linear solve."""


def check_dense_size(n_samples: int, max_dense_samples: int, n_copies: float = 1.5) -> None:
    """Refuse a dense N×N dual solve that is over the limit or would not fit in memory."""
    hint = (
        "use solver='fixed-size' (Nyström features on n_landmarks points, never N×N) "
        "or raise max_dense_samples"
    )
    if n_samples > max_dense_samples:
        raise ValueError(
            f"solver='dense' needs an {n_samples}×{n_samples} kernel matrix, above "
            f"max_dense_samples={max_dense_samples}; {hint}"
        )
    need = n_copies * 8.0 * n_samples * n_samples
    avail = available_memory_bytes()
    if avail is not None and need > 0.8 * avail:
        raise ValueError(
            f"solver='dense' with {n_samples} samples needs about {need / 2**30:.1f} GiB, "
            f"only {avail / 2**30:.1f} GiB available; {hint}"
        )


def solve_dual(
    K: np.ndarray, Y: np.ndarray, inv_reg: np.ndarray, positive_definite: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """Solve the LS-SVM KKT system; K is overwritten.

    Parameters
    ----------
    K : (N, N) kernel matrix (overwritten by its factor).
    Y : (N, q) targets.
    inv_reg : (N,) diagonal 1/(γ wᵢ) added to K.
    positive_definite : whether the kernel is Mercer for its parameters, so that H is SPD and a
        Cholesky factorisation applies; otherwise a symmetric indefinite (LDLᵀ) solve is used.

    Returns
    -------
    alpha : (N, q) support values; intercept : (q,) bias b.
    """
    n, q = Y.shape
    K.flat[:: n + 1] += inv_reg
    rhs = np.empty((n, q + 1))
    rhs[:, :q] = Y
    rhs[:, q] = 1.0
    threads = 1 if n > SINGLE_THREAD_CHOLESKY_ABOVE else threads_for(n)
    with blas_threads(threads):
        if positive_definite:
            try:
                factor = linalg.cho_factor(K, lower=True, overwrite_a=True, check_finite=False)
            except linalg.LinAlgError as exc:
                raise np.linalg.LinAlgError(
                    "K + I/γ is not positive definite to working precision "
                    f"({exc}); lower gamma or scale the inputs"
                ) from None
            sol = linalg.cho_solve(factor, rhs, overwrite_b=True, check_finite=False)
        else:
            sol = linalg.solve(K, rhs, assume_a="sym", overwrite_a=True, check_finite=False)
    nu, eta = sol[:, :q], sol[:, q]
    intercept = nu.sum(axis=0) / eta.sum()
    alpha = nu - eta[:, None] * intercept[None, :]
    return alpha, intercept


def accumulate_normal_equations(
    blocks: Iterable[tuple[np.ndarray, np.ndarray, np.ndarray]], n_features: int, n_outputs: int
) -> tuple[np.ndarray, np.ndarray]:
    """Sum the bordered normal equations over (features, targets, weights) row blocks.

    Returns A (p+1, p+1) without the I/γ term and B (p+1, q); the last row/column is the bias.
    """
    p = n_features
    A = np.zeros((p + 1, p + 1))
    B = np.zeros((p + 1, n_outputs))
    for F, Yb, w in blocks:
        # FᵀWF as (√W F)ᵀ(√W F): NumPy computes a product of an array with its own transpose
        # by a symmetric rank-k update, half the work of a general product. Weights are ≥ 0,
        # and unit weights (the common case) skip the scaling pass.
        if np.all(w == 1.0):
            Fs, Ys, s = F, Yb, w
        else:
            s = np.sqrt(w)
            Fs, Ys = F * s[:, None], Yb * s[:, None]
        A[:p, :p] += Fs.T @ Fs
        A[:p, p] += s @ Fs
        A[p, p] += w.sum()
        B[:p] += Fs.T @ Ys
        B[p] += w @ Yb
    A[p, :p] = A[:p, p]
    return A, B


def solve_primal(
    A: np.ndarray, B: np.ndarray, gamma: float
) -> tuple[np.ndarray, np.ndarray, float]:
    """Solve the bordered primal normal equations.

    Returns
    -------
    coef : (q, p) primal weights ω; intercept : (q,) bias b; condition : 2-norm condition number
    of the equilibrated system (reported in diagnostics; a warning is raised above 1e12).
    """
    p = A.shape[0] - 1
    M = A.copy()
    M[np.arange(p), np.arange(p)] += 1.0 / gamma
    # Jacobi equilibration: regressors of very different scale (|u|u vs δ) must not cost digits.
    d = 1.0 / np.sqrt(np.diag(M))
    Ms = M * d[:, None] * d[None, :]
    eig = np.linalg.eigvalsh(Ms)
    condition = float(eig[-1] / eig[0]) if eig[0] > 0 else float("inf")
    if not np.isfinite(condition) or condition > 1e12:
        warnings.warn(
            f"primal LS-SVM system is ill-conditioned (condition number {condition:.3g}); "
            "the regressors are nearly collinear for this γ",
            NumericalWarning,
            stacklevel=3,
        )
    try:
        z = solve_positive(Ms, B * d[:, None])
    except linalg.LinAlgError:
        z = linalg.lstsq(Ms, B * d[:, None], check_finite=False)[0]
    x = z * d[:, None]
    return x[:p].T.copy(), x[p].copy(), condition


def solve_positive(M: np.ndarray, b: np.ndarray) -> np.ndarray:
    """x of M x = b for a symmetric positive definite M (Cholesky: LAPACK's ``posv``).

    ``scipy.linalg.solve(..., assume_a="pos")`` runs the same routine, the same x to the bit
    (from 2 × 2 on: it divides a 1 × 1 system), behind about 20 µs of checks a call: ``select`` solves
    thousands of small systems (about 3800 in the README's Esso recipe). Raises ``LinAlgError`` where
    M is not positive definite.
    """
    _, x, info = linalg.lapack.dposv(M, b)
    if info != 0:
        raise linalg.LinAlgError(f"the system is not positive definite (LAPACK posv: {info})")
    return x


# Weight of the equality rows, relative to the equilibrated normal equations (unit diagonal), when
# bounds force the penalty form: equalities then hold to about 1e-8 of the data's scale.
EQUALITY_PENALTY = 1e8


def solve_primal_constrained(
    A: np.ndarray,
    b: np.ndarray,
    gamma: float,
    prior: np.ndarray | None = None,
    lower: np.ndarray | None = None,
    upper: np.ndarray | None = None,
    equalities: tuple[np.ndarray, np.ndarray] | None = None,
    inequalities: tuple[np.ndarray, np.ndarray] | None = None,
    labels: Sequence[str] | None = None,
) -> tuple[np.ndarray, float, np.ndarray]:
    """One output of the primal LS-SVM with physics: a prior, bounds, linear equalities and
    linear inequalities.

    Solves ``min ½‖ω − ω₀‖² + ½ Σ γ wᵢ eᵢ²`` (the LS-SVM regularisation drawn toward the prior
    ω₀ instead of 0) subject to ``lower ≤ ω ≤ upper`` and ``E [ω; b] = f`` (e.g. the fitted
    equation vanishing at approach states: steady speed). A coefficient whose lower and upper
    bounds are equal is held at that value (an equality).

    Parameters
    ----------
    A, b : the bordered normal equations of ``accumulate_normal_equations`` (without I/γ), A
        (p+1, p+1) and b (p+1,); the last row is the bias.
    gamma : γ > 0; ``math.inf`` for least squares (no regularisation, the prior unused).
    equalities : (E (k, p+1), f (k,)), the last column of E multiplying the bias.
    inequalities : (G (m, p+1), h (m,)) for ``G [ω; b] ≥ h`` (e.g. straight-line stability of
        the yaw equation given the sway one). Where the solution without them meets them it is
        returned as is; else the quadratic program with them is solved by SciPy's SLSQP from that
        solution and solved exactly again with the inequalities and bounds it holds as equalities.
    labels : what each inequality row holds, in words: where the rows cannot be met, the first
        that no point of the bounds and equalities meets on its own is named in the error.

    Returns
    -------
    coef (p,), bias, and the boolean mask of the coefficients held at a bound.

    Without bounds the problem is solved exactly (the KKT system of the equilibrated normal
    equations, least-squares in case equalities repeat). With bounds it is the quadratic program
    of the equilibrated normal equations, solved as the least-squares problem of its square root
    by SciPy's bounded-variable least squares (the equalities as rows of weight
    ``EQUALITY_PENALTY``), then solved exactly again with the bounds it found active held as
    equalities (kept if it stays within the other bounds).
    """
    lower, upper, equalities, held = _held_as_equalities(A.shape[0] - 1, lower, upper,
                                                         equalities)
    x, bias, active = _solve_boxed(A, b, gamma, prior, lower, upper, equalities)
    if inequalities is not None:
        G = np.atleast_2d(np.asarray(inequalities[0], dtype=float))
        h = np.atleast_1d(np.asarray(inequalities[1], dtype=float))
        if not np.all(G @ np.append(x, bias)
                      >= h - INEQUALITY_TOLERANCE * _row_scale(G, x, bias, h)):
            x, bias, active = _solve_with_inequalities(A, b, gamma, prior, lower, upper,
                                                       equalities, G, h, np.append(x, bias),
                                                       labels)  # fmt: skip
    if held is not None:
        mask, values = held
        x[mask], active[mask] = values, True  # on the value itself, not its solve's rounding
    return x, bias, active


def _held_as_equalities(p: int, lower, upper, equalities):
    """Coefficients whose lower and upper bounds are equal (``--bound`` both ways: a value
    held) as equality rows: the bounded solvers (SciPy's BVLS, SLSQP) refuse an empty box.
    Returns the bounds without them, the equalities with them, and (mask, values) or None."""
    if lower is None or upper is None:
        return lower, upper, equalities, None
    lo, hi = np.array(lower, dtype=float), np.array(upper, dtype=float)
    mask = np.isfinite(lo) & (lo == hi)
    if not mask.any():
        return lower, upper, equalities, None
    values = lo[mask]
    rows = np.eye(p + 1)[np.flatnonzero(mask)]
    if equalities is None:
        E, f = rows, values
    else:
        E = np.vstack([np.atleast_2d(np.asarray(equalities[0], dtype=float)), rows])
        f = np.concatenate([np.atleast_1d(np.asarray(equalities[1], dtype=float)), values])
    lo[mask], hi[mask] = -np.inf, np.inf
    return lo, hi, (E, f), (mask, values)


def _row_scale(G: np.ndarray, x: np.ndarray, bias: float, h: np.ndarray) -> np.ndarray:
    """The size each inequality row is judged against: |G||[x; b]| + |h| (relative tolerance)."""
    return np.abs(G) @ np.abs(np.append(x, bias)) + np.abs(h) + 1e-300


# An inequality met to this share of its terms' size counts as met (and as active when solved).
INEQUALITY_TOLERANCE = 1e-9


def _objective_terms(A, b, gamma, prior):
    """M, c of the quadratic ½ zᵀ M z − cᵀ z over [ω; b] that the LS-SVM with a prior minimises."""
    p = A.shape[0] - 1
    M = A.astype(float).copy()
    c = np.asarray(b, dtype=float).reshape(-1).copy()
    if np.isfinite(gamma):
        M[np.arange(p), np.arange(p)] += 1.0 / gamma
        if prior is not None:
            c[:p] += np.asarray(prior, dtype=float) / gamma
    return M, c


def _conflicting_rows(G, h, lower, upper, equalities, labels) -> str:
    """What to name of an infeasible ``G z ≥ h`` within the box and the equalities: the first
    row that no point of the box and the equalities meets on its own (a linear program per row:
    the largest G_i z there), by its label; else the rows together. The point an infeasible
    SLSQP stops at says nothing of which row is to blame."""
    from scipy.optimize import linprog

    named = labels is not None and len(labels) == len(h)
    E, f = (None, None) if equalities is None else (
        np.atleast_2d(np.asarray(equalities[0], dtype=float)),
        np.atleast_1d(np.asarray(equalities[1], dtype=float)))  # fmt: skip
    bounds = [(None if not np.isfinite(lo) else lo, None if not np.isfinite(hi) else hi)
              for lo, hi in zip(lower, upper, strict=True)]  # fmt: skip
    for i in range(len(h)):
        res = linprog(-G[i], A_eq=E, b_eq=f, bounds=bounds, method="highs")
        if res.status == 0 and -res.fun < h[i] - 1e-9 * (np.abs(G[i]).sum() + abs(h[i]) + 1.0):
            return labels[i] if named else f"inequality row {i + 1}"
    return ("the inequality rows together" + (f" ({', '.join(dict.fromkeys(labels))})"
                                              if named else ""))  # fmt: skip


def _solve_with_inequalities(A, b, gamma, prior, lower, upper, equalities, G, h, start,
                             labels=None):
    """The quadratic program of ``solve_primal_constrained`` with ``G z ≥ h`` (SLSQP on the
    equilibrated problem, from ``start``), then solved exactly with what it holds active."""
    from scipy.optimize import minimize

    p = A.shape[0] - 1
    M, c = _objective_terms(A, b, gamma, prior)
    d = 1.0 / np.sqrt(np.maximum(np.diag(M), 1e-300))
    Ms, cs = M * d[:, None] * d[None, :], c * d
    lo = np.append(np.full(p, -np.inf) if lower is None else np.asarray(lower, dtype=float), -np.inf)
    hi = np.append(np.full(p, np.inf) if upper is None else np.asarray(upper, dtype=float), np.inf)
    Gs = G * d[None, :]
    norms = np.linalg.norm(Gs, axis=1)
    norms[norms == 0] = 1.0
    Gs, hs = Gs / norms[:, None], h / norms
    cons = [{"type": "ineq", "fun": lambda z: Gs @ z - hs, "jac": lambda z: Gs}]
    if equalities is not None:
        E = np.atleast_2d(np.asarray(equalities[0], dtype=float)) * d[None, :]
        f = np.atleast_1d(np.asarray(equalities[1], dtype=float))
        cons.append({"type": "eq", "fun": lambda z: E @ z - f, "jac": lambda z: E})
    res = minimize(lambda z: 0.5 * z @ Ms @ z - cs @ z, start / d, jac=lambda z: Ms @ z - cs,
                   bounds=list(zip(lo / d, hi / d, strict=True)), constraints=cons,
                   method="SLSQP", options={"ftol": 1e-15, "maxiter": 500})  # fmt: skip
    z = res.x
    slack = Gs @ z - hs
    # SLSQP can report success on an infeasible set: judge the point itself (unit rows).
    if np.any(slack < -1e-6):
        raise InfeasibleConstraintsError(
            f"constraints conflict: {_conflicting_rows(G, h, lo, hi, equalities, labels)} cannot "
            "be met within the bounds and equalities (signs, --bound, steady-speed)")
    # Polish: the rows and bounds SLSQP holds, as equalities of the exact problem; its KKT
    # multipliers certify the optimum (≤ 0 on held inequalities and lower bounds, ≥ 0 on upper
    # bounds, with ∇f + Cᵀμ = 0), which SLSQP's own status does not (it stops with "positive
    # directional derivative" at an optimum it cannot improve to 1e-15).
    held = np.abs(slack) <= 1e-7
    lo_s, hi_s = lo / d, hi / d
    at_lo, at_hi = np.isfinite(lo_s), np.isfinite(hi_s)
    at_lo[at_lo] = z[at_lo] <= lo_s[at_lo] + 1e-9 * (1 + np.abs(lo_s[at_lo]))
    at_hi[at_hi] = z[at_hi] >= hi_s[at_hi] - 1e-9 * (1 + np.abs(hi_s[at_hi]))
    bound = at_lo | at_hi
    rows = [Gs[held], np.eye(p + 1)[bound]]
    rhs = [hs[held], np.where(at_lo, lo_s, hi_s)[bound]]
    signs = [np.full(int(held.sum()), -1.0), np.where(at_lo, -1.0, 1.0)[bound]]
    if equalities is not None:
        rows.insert(0, E)
        rhs.insert(0, f)
        signs.insert(0, np.zeros(len(f)))
    C, g, sign = np.vstack(rows), np.concatenate(rhs), np.concatenate(signs)
    certified = False
    if len(g):
        K = np.block([[Ms, C.T], [C, np.zeros((len(g), len(g)))]])
        solution = linalg.lstsq(K, np.concatenate([cs, g]), check_finite=False)[0]
        exact, mu = solution[: p + 1], solution[p + 1:]
        feasible = (np.all(Gs @ exact - hs >= -1e-9) and np.all(exact >= lo_s - 1e-9)
                    and np.all(exact <= hi_s + 1e-9))  # fmt: skip
        if feasible:
            z = exact
            scale = 1e-8 * max(1.0, float(np.max(np.abs(mu))) if mu.size else 1.0)
            certified = bool(np.all(sign * mu >= -scale))
    if not certified:
        warnings.warn(f"the fit with inequality constraints may not be the best one (SLSQP: "
                      f"{res.message}); its solution meets them", NumericalWarning,
                      stacklevel=3)  # fmt: skip
    x = z * d
    return x[:p], float(x[p]), (at_lo | at_hi)[:p]


def _solve_boxed(A, b, gamma, prior, lower, upper, equalities):
    """``solve_primal_constrained`` without inequalities."""
    p = A.shape[0] - 1
    M, c = _objective_terms(A, b, gamma, prior)
    lo = np.append(np.full(p, -np.inf) if lower is None else np.asarray(lower, dtype=float), -np.inf)
    hi = np.append(np.full(p, np.inf) if upper is None else np.asarray(upper, dtype=float), np.inf)
    d = 1.0 / np.sqrt(np.maximum(np.diag(M), 1e-300))
    Ms, cs = M * d[:, None] * d[None, :], c * d
    E = f = None
    if equalities is not None:
        E = np.atleast_2d(np.asarray(equalities[0], dtype=float)) * d[None, :]
        f = np.atleast_1d(np.asarray(equalities[1], dtype=float))
    bounded = not (np.all(np.isneginf(lo)) and np.all(np.isposinf(hi)))
    active = np.zeros(p + 1, dtype=bool)
    if bounded:
        # Imported where bounds are given: SciPy's optimize package costs 0.1-0.3 s to import,
        # which fits with equalities alone (the Esso's default searches) never need.
        from scipy.optimize import lsq_linear

        Mp, cp = Ms, cs
        if E is not None:
            Mp = Ms + EQUALITY_PENALTY * E.T @ E
            cp = cs + EQUALITY_PENALTY * E.T @ f
        # ½ zᵀ M z − cᵀ z = ½ ‖R z − R⁻ᵀ c‖² + const with M = RᵀR (eigen-square-root if M is
        # only semi-definite, as least squares with dependent regressors can be).
        vals, vecs = np.linalg.eigh(Mp)
        keep = vals > vals[-1] * 1e-15
        R = np.sqrt(vals[keep])[:, None] * vecs[:, keep].T
        rhs = (vecs[:, keep].T @ cp) / np.sqrt(vals[keep])
        res = lsq_linear(R, rhs, bounds=(lo / d, hi / d), method="bvls", tol=1e-13)
        z, active = res.x, res.active_mask != 0
        if E is None:
            x = z * d
            return x[:p], float(x[p]), active[:p]
    # Exact: the KKT system with the equalities and the bounds found active held as equalities.
    held = np.flatnonzero(active)
    rows = [] if E is None else [E]
    rhs_eq = [] if E is None else [f]
    if held.size:
        rows.append(np.eye(p + 1)[held])
        rhs_eq.append(np.where(z[held] <= (lo / d)[held], (lo / d)[held], (hi / d)[held]))
    if rows:
        C, g = np.vstack(rows), np.concatenate(rhs_eq)
        K = np.block([[Ms, C.T], [C, np.zeros((len(g), len(g)))]])
        exact = linalg.lstsq(K, np.concatenate([cs, g]), check_finite=False)[0][: p + 1]
        if not bounded or np.all((exact >= lo / d - 1e-9) & (exact <= hi / d + 1e-9)):
            z = exact
            if held.size:  # on the bound itself, not within the KKT solve's rounding of it
                z[held] = rhs_eq[-1]
    else:
        try:
            z = solve_positive(Ms, cs)
        except linalg.LinAlgError:
            z = linalg.lstsq(Ms, cs, check_finite=False)[0]
    x = z * d
    return x[:p], float(x[p]), active[:p]

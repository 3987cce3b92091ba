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
from collections.abc import Iterable

import numpy as np
from scipy import linalg
from threadpoolctl import threadpool_limits

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
    threads = 1 if n > SINGLE_THREAD_CHOLESKY_ABOVE else None
    with threadpool_limits(limits=threads):
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
        Fw = F * w[:, None]
        A[:p, :p] += F.T @ Fw
        A[:p, p] += Fw.sum(axis=0)
        A[p, p] += w.sum()
        B[:p] += Fw.T @ Yb
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
        z = linalg.solve(Ms, B * d[:, None], assume_a="pos", check_finite=False)
    except linalg.LinAlgError:
        z = linalg.lstsq(Ms, B * d[:, None], check_finite=False)[0]
    x = z * d[:, None]
    return x[:p].T.copy(), x[p].copy(), condition


def solve_primal_constrained(
    A: np.ndarray,
    b: np.ndarray,
    gamma: float,
    prior: np.ndarray | None = None,
    lower: np.ndarray | None = None,
    upper: np.ndarray | None = None,
    bias_row: np.ndarray | None = None,
    bias_offset: float = 0.0,
) -> tuple[np.ndarray, float, np.ndarray]:
    """One output of the primal LS-SVM with physics: a prior, bounds and a tied bias.

    Solves ``min ½‖ω − ω₀‖² + ½ Σ γ wᵢ eᵢ²`` (the LS-SVM regularisation drawn toward the prior
    ω₀ instead of 0) subject to ``lower ≤ ω ≤ upper`` and, with ``bias_row`` φ₀,
    ``b = −φ₀ᵀω − bias_offset`` (the fitted equation, plus terms held fixed worth
    ``bias_offset`` there, vanishes at the state φ₀: e.g. steady speed on the approach).

    Parameters
    ----------
    A, b : the bordered normal equations of ``accumulate_normal_equations`` (without I/γ), A
        (p+1, p+1) and b (p+1,); the last row is the bias.
    gamma : γ > 0; ``math.inf`` for least squares (no regularisation, the prior unused).

    Returns
    -------
    coef (p,), bias, and the boolean mask of the coefficients held at a bound.

    The bounded problem is the quadratic program of the equilibrated normal equations, solved as
    the least-squares problem of its Cholesky factor by SciPy's bounded-variable least squares.
    """
    from scipy.optimize import lsq_linear

    p = A.shape[0] - 1
    M = A.astype(float).copy()
    c = np.asarray(b, dtype=float).reshape(-1).copy()
    if np.isfinite(gamma):
        M[np.arange(p), np.arange(p)] += 1.0 / gamma
        if prior is not None:
            c[:p] += np.asarray(prior, dtype=float) / gamma
    lo = np.full(p, -np.inf) if lower is None else np.asarray(lower, dtype=float)
    hi = np.full(p, np.inf) if upper is None else np.asarray(upper, dtype=float)
    if bias_row is not None:
        # x = T ω + e with T = [I; −φ₀ᵀ], e = (0, …, 0, −offset): the bias is eliminated exactly.
        T = np.vstack([np.eye(p), -np.asarray(bias_row, dtype=float)[None, :]])
        e = np.zeros(p + 1)
        e[p] = -bias_offset
        M, c = T.T @ M @ T, T.T @ (c - M @ e)
    else:
        lo, hi = np.append(lo, -np.inf), np.append(hi, np.inf)
    n = M.shape[0]
    d = 1.0 / np.sqrt(np.maximum(np.diag(M), 1e-300))
    Ms, cs = M * d[:, None] * d[None, :], c * d
    if np.all(np.isneginf(lo)) and np.all(np.isposinf(hi)):
        try:
            z = linalg.solve(Ms, cs, assume_a="pos", check_finite=False)
        except linalg.LinAlgError:
            z = linalg.lstsq(Ms, cs, check_finite=False)[0]
        active = np.zeros(n, dtype=bool)
    else:
        # ½ zᵀ Ms z − csᵀ z = ½ ‖R z − R⁻ᵀ cs‖² + const with Ms = RᵀR (eigen-square-root if Ms is
        # only semi-definite, as least squares with dependent regressors can be).
        vals, vecs = np.linalg.eigh(Ms)
        keep = vals > vals[-1] * 1e-14
        R = np.sqrt(vals[keep])[:, None] * vecs[:, keep].T
        rhs = (vecs[:, keep].T @ cs) / np.sqrt(vals[keep])
        res = lsq_linear(R, rhs, bounds=(lo / d, hi / d), method="bvls", tol=1e-12)
        z = res.x
        active = res.active_mask != 0
    x = z * d
    if bias_row is not None:
        coef = x
        bias = float(-np.asarray(bias_row, dtype=float) @ coef) - bias_offset
        return coef, bias, active
    return x[:p], float(x[p]), active[:p]

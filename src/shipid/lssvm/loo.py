"""Exact leave-one-out residuals of the LS-SVM in closed form, for a whole γ grid.

Dual form (Cawley & Talbot 2004): with C the bordered KKT matrix, the LOO residual of sample i is
αᵢ / (C⁻¹)ᵢᵢ, and the α-block of C⁻¹ is H⁻¹ − ηηᵀ/1ᵀη with H = K + diag(1/(γw)), η = H⁻¹1. One
eigendecomposition of W^½ K W^½ = V Λ Vᵀ gives H⁻¹ = W^½ V (Λ + I/γ)⁻¹ Vᵀ W^½ for every γ.

Primal form (linear kernel, fixed-size features): ridge with an unpenalised bias is a linear
smoother; the LOO residual is eᵢ / (1 − hᵢᵢ) with leverage hᵢᵢ = wᵢ/Σw + wᵢ x̃ᵢᵀ(G + I/γ)⁻¹x̃ᵢ,
x̃ the weighted-centred features and G = X̃ᵀ W X̃ = Q Λ Qᵀ, again one eigendecomposition per grid.

Apart from the estimators (``shipid.lssvm.selection``): ``select``'s γ pre-screen needs the
paths alone, and scikit-learn, which the estimators are built on, took 0.9 s to import in every
``identify`` and ``select`` that searched.
"""

from __future__ import annotations

import numba
import numpy as np
from scipy import linalg


class DualLOOPath:
    """Exact LOO residuals of the dense dual LS-SVM for any γ, one eigendecomposition."""

    def __init__(self, K: np.ndarray, Y: np.ndarray, w: np.ndarray) -> None:
        s = np.sqrt(w)
        K *= s[:, None]
        K *= s[None, :]
        # Divide and conquer ('evd') is the fastest LAPACK driver for all eigenvectors.
        self.lam, V = linalg.eigh(K, overwrite_a=True, check_finite=False, driver="evd")
        self.V = V
        self.V2 = V * V
        self.s, self.w = s, w
        self.a = V.T @ s
        self.Yt = V.T @ (s[:, None] * Y)

    def mse(self, gamma: float) -> float:
        """Mean squared exact LOO residual at ``gamma``."""
        return float(np.mean(self.residuals(gamma) ** 2))

    def mse_grid(self, gammas) -> np.ndarray:
        """Mean squared exact LOO residual at each of ``gammas``."""
        return np.array([self.mse(float(g)) for g in np.asarray(gammas, dtype=float).ravel()])

    def residuals(self, gamma: float) -> np.ndarray:
        """Exact LOO residuals at ``gamma``, (N, q)."""
        d = 1.0 / (self.lam + 1.0 / gamma)
        eta = self.s * (self.V @ (d * self.a))
        nu = self.s[:, None] * (self.V @ (d[:, None] * self.Yt))
        intercept = nu.sum(axis=0) / eta.sum()
        alpha = nu - eta[:, None] * intercept
        diag = self.w * (self.V2 @ d) - eta * eta / eta.sum()
        return alpha / diag[:, None]


# Rows per block of the γ-grid LOO pass: its (rows × γ·q) products stay in cache (4096 × 60
# doubles, 2 MB, for 20 γ and 3 outputs).
ROW_BLOCK = 4096


@numba.njit(cache=True)
def _block_loo_sse(fitted, leverage, Yc, w, inv_sw, sse):
    """Add Σᵢ Σₖ (eᵢₖ/(1 − hᵢᵢ))² of a block of rows to ``sse`` (γ,), every γ in one pass:
    ``fitted`` (rows, γ·q) the smoother's fits, ``leverage`` (rows, γ) x̃ᵢᵀ(G + I/γ)⁻¹x̃ᵢ."""
    n, n_gamma = leverage.shape
    q = Yc.shape[1]
    # Serial on purpose: right after the block's BLAS calls, OpenBLAS threads still spin and a
    # parallel loop competing with them measured twice as slow on 2 cores.
    for i in range(n):
        for g in range(n_gamma):
            inv = 1.0 / (1.0 - w[i] * (inv_sw + leverage[i, g]))
            row = 0.0
            for c in range(q):
                e = (Yc[i, c] - fitted[i, g * q + c]) * inv
                row += e * e
            sse[g] += row


class PrimalLOOPath:
    """Exact LOO residuals of the primal (linear-in-features) LS-SVM for any γ."""

    def __init__(self, F: np.ndarray, Y: np.ndarray, w: np.ndarray) -> None:
        self.sw = w.sum()
        Fc = F - (w @ F) / self.sw
        self.y_mean = (w @ Y) / self.sw
        G = Fc.T @ (Fc * w[:, None])
        self.lam, Q = np.linalg.eigh(G)
        self.P = np.ascontiguousarray(Fc @ Q)
        self.Yc = np.ascontiguousarray(Y - self.y_mean)
        self.PtWY = self.P.T @ (w[:, None] * self.Yc)
        self.w = np.ascontiguousarray(w)

    def _d(self, gamma: float) -> np.ndarray:
        return 1.0 / (self.lam + 1.0 / gamma)

    def residuals(self, gamma: float) -> np.ndarray:
        """Exact LOO residuals at ``gamma``, (N, q)."""
        d = self._d(gamma)
        fitted = self.P @ (d[:, None] * self.PtWY)
        leverage = self.w * (1.0 / self.sw + (self.P * self.P) @ d)
        return (self.Yc - fitted) / (1.0 - leverage)[:, None]

    def mse(self, gamma: float) -> float:
        """Mean squared LOO residual at ``gamma``."""
        return float(self.mse_grid([gamma])[0])

    def mse_grid(self, gammas) -> np.ndarray:
        """Mean squared LOO residual at each of ``gammas``: one pass over the rows for the whole
        grid, the fits and leverages of a block of rows for every γ as two BLAS products."""
        gammas = np.asarray(gammas, dtype=float).ravel()
        D = 1.0 / (self.lam[None, :] + 1.0 / gammas[:, None])  # (γ, k)
        k, q = self.PtWY.shape
        # Column g·q + c: the smoother's coefficients of output c at γ_g.
        B = np.ascontiguousarray((D[:, :, None] * self.PtWY[None]).transpose(1, 0, 2)
                                 .reshape(k, -1))  # fmt: skip
        Dt = np.ascontiguousarray(D.T)
        sse = np.zeros(len(gammas))
        for a in range(0, self.P.shape[0], ROW_BLOCK):
            Pb = self.P[a : a + ROW_BLOCK]
            _block_loo_sse(Pb @ B, (Pb * Pb) @ Dt, self.Yc[a : a + ROW_BLOCK],
                           self.w[a : a + ROW_BLOCK], 1.0 / self.sw, sse)  # fmt: skip
        return sse / self.Yc.size

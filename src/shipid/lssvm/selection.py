"""Model selection for the LS-SVM: exact leave-one-out residuals in closed form and a γ/σ search.

Dual form (Cawley & Talbot 2004): with C the bordered KKT matrix, the LOO residual of sample i is
αᵢ / (C⁻¹)ᵢᵢ, and the α-block of C⁻¹ is H⁻¹ − ηηᵀ/1ᵀη with H = K + diag(1/(γw)), η = H⁻¹1. One
eigendecomposition of W^½ K W^½ = V Λ Vᵀ gives H⁻¹ = W^½ V (Λ + I/γ)⁻¹ Vᵀ W^½ for every γ.

Primal form (linear kernel, fixed-size features): ridge with an unpenalised bias is a linear
smoother; the LOO residual is eᵢ / (1 − hᵢᵢ) with leverage hᵢᵢ = wᵢ/Σw + wᵢ x̃ᵢᵀ(G + I/γ)⁻¹x̃ᵢ,
x̃ the weighted-centred features and G = X̃ᵀ W X̃ = Q Λ Qᵀ, again one eigendecomposition per grid.
"""

from __future__ import annotations

import numba
import numpy as np
from scipy import linalg
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.model_selection import KFold
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_is_fitted
from tqdm.auto import tqdm

from .estimator import LSSVR
from .kernels import kernel_matrix
from .nystrom import NystromMap, choose_landmarks
from .solvers import check_dense_size
from .validation import check_positive, validated_training_data


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


def loo_path(
    estimator: LSSVR, X: np.ndarray, Y: np.ndarray, w: np.ndarray
) -> DualLOOPath | PrimalLOOPath:
    """The closed-form LOO path matching ``estimator``'s kernel and solver (γ free)."""
    n, p = X.shape
    solver = estimator._resolve_solver(n, p)
    if solver == "primal":
        return PrimalLOOPath(X, Y, w)
    params = estimator._kernel_params()
    if solver == "fixed-size":
        seed = int(check_random_state(estimator.random_state).randint(2**31))
        landmarks = choose_landmarks(X, estimator.n_landmarks, np.random.default_rng(seed))
        return PrimalLOOPath(NystromMap(landmarks, estimator.kernel, **params).features(X), Y, w)
    check_dense_size(n, estimator.max_dense_samples, n_copies=3.0)
    return DualLOOPath(kernel_matrix(X, X, estimator.kernel, **params), Y, w)


def _validated(X, y, sample_weight) -> tuple[np.ndarray, np.ndarray, np.ndarray, bool]:
    X, y, w = validated_training_data(LSSVR(), X, y, sample_weight)
    if np.any(w <= 0):
        raise ValueError("sample_weight must be > 0 for leave-one-out residuals")
    return X, y.reshape(y.shape[0], -1), w, y.ndim == 1


def loo_residuals(estimator: LSSVR, X, y, sample_weight=None) -> np.ndarray:
    """Exact leave-one-out residuals yᵢ − ŷ₋ᵢ(xᵢ) of ``estimator``'s (unfitted) configuration.

    No refits: one factorisation (see module docstring). Robust weighting is not applied (the
    residuals are those of the weighted LS-SVM with the given ``sample_weight``). For
    ``solver="fixed-size"`` the landmarks are held fixed across the left-out fits.
    """
    estimator._check_params()
    X, Y, w, ravel = _validated(X, y, sample_weight)
    res = loo_path(estimator, X, Y, w).residuals(float(estimator.gamma))
    return res[:, 0] if ravel else res


class LSSVRCV(RegressorMixin, BaseEstimator):
    """LS-SVM regression with γ (and σ) chosen over a grid by exact LOO or k-fold CV.

    With ``cv="loo"`` each σ costs one eigendecomposition and every γ of the grid is then
    O(N²) (dense) or O(N p) (primal), with no refits. With an integer ``cv`` the grid is refitted
    on ``KFold(cv, shuffle=True)`` splits. The selected model is refitted on all data as
    ``best_estimator_``.

    Parameters
    ----------
    gammas : array-like, default=logspace(-2, 6, 20)
    sigmas : array-like or None
        RBF widths to try (ignored by the linear and poly kernels); None keeps ``sigma`` of
        ``estimator_params``.
    cv : "loo" or int, default="loo"
    progress : bool, default=False
        Show a progress bar over the grid.
    **estimator_params
        Other ``LSSVR`` parameters (kernel, solver, n_landmarks, ...).

    Attributes
    ----------
    cv_results_ : dict with arrays "gamma", "sigma", "mse" (mean squared CV residual).
    best_params_ : dict; best_score_ : the smallest "mse"; best_estimator_ : fitted ``LSSVR``.
    """

    def __init__(
        self,
        gammas=None,
        sigmas=None,
        cv="loo",
        progress: bool = False,
        kernel: str = "rbf",
        sigma: float = 1.0,
        degree: int = 3,
        coef0: float = 1.0,
        solver: str = "auto",
        n_landmarks: int = 500,
        random_state=None,
        max_dense_samples: int = 20_000,
    ) -> None:
        self.gammas = gammas
        self.sigmas = sigmas
        self.cv = cv
        self.progress = progress
        self.kernel = kernel
        self.sigma = sigma
        self.degree = degree
        self.coef0 = coef0
        self.solver = solver
        self.n_landmarks = n_landmarks
        self.random_state = random_state
        self.max_dense_samples = max_dense_samples

    def _base(self, **overrides) -> LSSVR:
        params = dict(
            kernel=self.kernel, sigma=self.sigma, degree=self.degree, coef0=self.coef0,
            solver=self.solver, n_landmarks=self.n_landmarks, random_state=self.random_state,
            max_dense_samples=self.max_dense_samples,
        )
        params.update(overrides)
        return LSSVR(**params)

    def fit(self, X, y, sample_weight=None) -> LSSVRCV:
        """Search the grid, then refit the best parameters on all data."""
        gammas = np.logspace(-2, 6, 20) if self.gammas is None else np.asarray(self.gammas, float)
        for g in gammas.ravel():
            check_positive(g, "gammas")
        uses_sigma = self.kernel == "rbf" and self.sigmas is not None
        sigmas = np.asarray(self.sigmas, float).ravel() if uses_sigma else np.array([self.sigma])
        for s in sigmas:
            check_positive(s, "sigmas")
        if not (self.cv == "loo" or (isinstance(self.cv, int) and self.cv >= 2)):
            raise ValueError(f"cv must be 'loo' or an integer ≥ 2, got {self.cv!r}")
        self._base()._check_params()
        X, Y, w, ravel = _validated(X, y, sample_weight)

        grid = [(s, g) for s in sigmas for g in gammas]
        mse = np.empty(len(grid))
        with tqdm(total=len(grid), disable=not self.progress, desc="LS-SVM grid") as bar:
            for i_s, s in enumerate(sigmas):
                first = i_s * len(gammas)
                if self.cv == "loo":
                    path = loo_path(self._base(sigma=s), X, Y, w)
                    mse[first : first + len(gammas)] = path.mse_grid(gammas)
                    bar.update(len(gammas))
                else:
                    folds = list(KFold(self.cv, shuffle=True, random_state=0).split(X))
                    for k, g in enumerate(gammas):
                        sq = 0.0
                        for train, test in folds:
                            est = self._base(sigma=s, gamma=float(g))
                            est.fit(X[train], Y[train], w[train])
                            sq += np.sum((est.predict(X[test]) - Y[test]) ** 2)
                        mse[first + k] = sq / Y.size
                        bar.update()
        self.cv_results_ = {
            "sigma": np.array([s for s, _ in grid]),
            "gamma": np.array([g for _, g in grid]),
            "mse": mse,
        }
        best = int(np.argmin(mse))
        self.best_params_ = {"gamma": float(grid[best][1]), "sigma": float(grid[best][0])}
        self.best_score_ = float(mse[best])
        self.best_estimator_ = self._base(**self.best_params_).fit(
            X, Y[:, 0] if ravel else Y, w
        )
        self.n_features_in_ = X.shape[1]
        return self

    def predict(self, X) -> np.ndarray:
        """Predictions of the refitted best estimator."""
        check_is_fitted(self, "best_estimator_")
        return self.best_estimator_.predict(X)

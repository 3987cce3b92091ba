"""Model selection for the LS-SVM estimators: exact leave-one-out residuals of an estimator's
configuration (the closed-form paths of ``shipid.lssvm.loo``) and ``LSSVRCV``'s γ/σ search.
"""

from __future__ import annotations

import numpy as np
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.model_selection import KFold
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_is_fitted

from shipid.progress import progress_bar

from .estimator import LSSVR
from .kernels import kernel_matrix
from .loo import DualLOOPath, PrimalLOOPath
from .nystrom import NystromMap, choose_landmarks
from .solvers import check_dense_size
from .validation import check_positive, validated_training_data


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
        with progress_bar(len(grid), "LS-SVM grid", shown=bool(self.progress)) as bar:
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

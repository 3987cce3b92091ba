"""The LS-SVM regressor (paper section 1) as a scikit-learn estimator."""

from __future__ import annotations

import warnings

import numpy as np
from sklearn.base import BaseEstimator, RegressorMixin, clone
from sklearn.exceptions import ConvergenceWarning
from sklearn.utils import check_random_state
from sklearn.utils.validation import check_is_fitted, validate_data

from .kernels import KERNELS, kernel_matrix, row_blocks
from .nystrom import NystromMap, choose_landmarks
from .robust import WEIGHTINGS, robust_weights
from .solvers import accumulate_normal_equations, check_dense_size, solve_dual, solve_primal
from .validation import (
    check_choice,
    check_finite,
    check_positive,
    check_positive_int,
    validated_training_data,
)

SOLVERS = ("auto", "dense", "primal", "fixed-size")


class LSSVR(RegressorMixin, BaseEstimator):
    """Least-squares support vector machine regression with bias (Suykens et al. 2002).

    Solves the KKT system of the paper (section 1, eqs. 2–6) exactly, or its primal form where that
    is cheaper, for one or several outputs.

    Parameters
    ----------
    gamma : float, default=1.0
        Regularisation γ > 0 of the paper (eq. 2): larger γ fits the data more closely.
        scikit-learn's ``KernelRidge`` solves the same problem *without* the bias b with
        ``alpha = 1/γ``; LS-SVMlab calls γ ``gam``.
    kernel : {"linear", "rbf", "poly"}, default="rbf"
        ``"rbf"`` is K(x, z) = exp(−‖x − z‖²/σ²): LS-SVMlab's ``sig2`` is σ² and scikit-learn's
        ``gamma`` (of ``rbf_kernel``/``KernelRidge``) is 1/σ². ``"poly"`` is (xᵀz + coef0)^degree.
    sigma : float, default=1.0
        RBF width σ > 0.
    degree : int, default=3
        Degree of the polynomial kernel.
    coef0 : float, default=1.0
        Constant of the polynomial kernel.
    solver : {"auto", "dense", "primal", "fixed-size"}, default="auto"
        ``"dense"``: Cholesky solve of the N×N dual (H = K + I/γ; H ν = y, H η = 1,
        b = 1ᵀν/1ᵀη, α = ν − η b). ``"primal"`` (linear kernel): the (p+1)×(p+1) normal equations,
        same ``coef_``/``intercept_`` as the dual. ``"fixed-size"`` (rbf/poly, large N): Nyström
        features on ``n_landmarks`` points and the primal solve, in row blocks, never N×N.
        ``"auto"``: primal for the linear kernel when N > p, dense otherwise.
    weighting : {None, "huber", "hampel"}, default=None
        Robust LS-SVM: refit with γᵢ = γ·vᵢ, vᵢ from the residuals standardised by 1.483·MAD, until
        the weights change by less than ``tol`` or ``max_iter`` refits.
    max_iter : int, default=50
        Cap on robust refits.
    tol : float, default=1e-4
        Convergence tolerance on the largest change of a robust weight.
    n_landmarks : int, default=500
        Number m of Nyström landmarks for ``solver="fixed-size"``.
    random_state : int, RandomState or None
        Seeds the choice of landmarks.
    max_dense_samples : int, default=20000
        The dense dual refuses more samples than this (it needs an N×N matrix).

    Attributes
    ----------
    alpha_ : ndarray (n_used,) or (n_used, n_outputs)
        Support values αᵢ = γ wᵢ eᵢ of the samples with non-zero weight (dense and primal solvers).
    intercept_ : float or ndarray (n_outputs,)
        The bias b.
    coef_ : ndarray (n_features,) or (n_outputs, n_features)
        Linear kernel only: Σ αᵢ xᵢ, the paper's Γ (eq. 15).
    solver_ : str
        The solver actually used.
    condition_number_ : float
        Condition number of the equilibrated primal system (primal and fixed-size solvers).
    robust_weights_ : ndarray
        Final robust weights vᵢ (robust fits only).
    n_iter_ : int
        Number of LS-SVM solves: 1, plus the robust refits with ``weighting``.
    """

    def __init__(
        self,
        gamma: float = 1.0,
        kernel: str = "rbf",
        sigma: float = 1.0,
        degree: int = 3,
        coef0: float = 1.0,
        solver: str = "auto",
        weighting: str | None = None,
        max_iter: int = 50,
        tol: float = 1e-4,
        n_landmarks: int = 500,
        random_state: int | np.random.RandomState | None = None,
        max_dense_samples: int = 20_000,
    ) -> None:
        self.gamma = gamma
        self.kernel = kernel
        self.sigma = sigma
        self.degree = degree
        self.coef0 = coef0
        self.solver = solver
        self.weighting = weighting
        self.max_iter = max_iter
        self.tol = tol
        self.n_landmarks = n_landmarks
        self.random_state = random_state
        self.max_dense_samples = max_dense_samples

    # ------------------------------------------------------------------ parameters
    def _check_params(self) -> None:
        check_positive(self.gamma, "gamma")
        check_choice(self.kernel, "kernel", KERNELS)
        check_positive(self.sigma, "sigma")
        check_positive_int(self.degree, "degree")
        if not np.isfinite(self.coef0):
            raise ValueError(f"coef0 must be finite, got {self.coef0!r}")
        check_choice(self.solver, "solver", SOLVERS)
        if self.weighting is not None:
            check_choice(self.weighting, "weighting", WEIGHTINGS)
        check_positive_int(self.max_iter, "max_iter")
        check_positive(self.tol, "tol")
        check_positive_int(self.n_landmarks, "n_landmarks")
        check_positive_int(self.max_dense_samples, "max_dense_samples", minimum=2)
        if self.solver == "primal" and self.kernel != "linear":
            raise ValueError("solver='primal' needs kernel='linear'; use 'fixed-size' for rbf/poly")
        if self.solver == "fixed-size" and self.kernel == "linear":
            raise ValueError(
                "solver='fixed-size' is for the rbf and poly kernels; the linear kernel's "
                "solver='primal' is exact and never forms an N×N matrix"
            )

    def _kernel_params(self) -> dict[str, float]:
        return {"sigma": self.sigma, "degree": self.degree, "coef0": self.coef0}

    def _resolve_solver(self, n_samples: int, n_features: int) -> str:
        if self.solver != "auto":
            return self.solver
        if self.kernel == "linear" and n_samples > n_features:
            return "primal"
        return "dense"

    def _is_mercer(self) -> bool:
        return self.kernel != "poly" or self.coef0 >= 0

    # ------------------------------------------------------------------ fitting
    def fit(self, X, y, sample_weight=None) -> LSSVR:
        """Fit on X (n_samples, n_features) and y (n_samples,) or (n_samples, n_outputs).

        ``sample_weight`` wᵢ ≥ 0 gives the weighted LS-SVM (γᵢ = γ·wᵢ); samples with wᵢ = 0 are
        left out.
        """
        X, Y, w, seed = self._prepare(X, y, sample_weight)
        if self.weighting is None:
            self._fit_weighted(X, Y, w, seed)
            self.n_iter_ = 1
        elif Y.shape[1] == 1:
            self._fit_robust(X, Y, w, seed)
        else:
            self._fit_robust_per_output(X, Y, w, seed)
        self._publish()
        return self

    def fit_path(self, X, y, gammas, sample_weight=None) -> list[LSSVR]:
        """One fitted estimator per γ of ``gammas`` (the other parameters as set), each the model
        ``clone(self).set_params(gamma=g).fit(X, y)`` gives, with what does not depend on γ
        computed once: the kernel matrix (dense), the normal equations (primal), the Nyström
        features on the same landmarks and their normal equations (fixed-size). Not with
        ``weighting``, whose refits depend on γ."""
        if self.weighting is not None:
            raise ValueError("fit_path needs weighting=None: robust refits depend on γ")
        gammas = [float(g) for g in gammas]
        for g in gammas:
            check_positive(g, "gamma")
        X, Y, w, seed = self._prepare(X, y, sample_weight)
        solve = self._system(X, Y, w, seed, reuse=True)
        fitted = [k for k in ("n_features_in_", "feature_names_in_") if hasattr(self, k)]
        out = []
        for g in gammas:
            est = clone(self).set_params(gamma=g)
            for k in (*fitted, "_ravel_output", "n_outputs_", "support_", "solver_"):
                setattr(est, k, getattr(self, k))
            solve(est, g)
            est.n_iter_ = 1
            est._publish()
            out.append(est)
        return out

    def _prepare(self, X, y, sample_weight) -> tuple[np.ndarray, np.ndarray, np.ndarray, int]:
        """Checked inputs of a fit: the used rows of X, Y (2-D) and w, and the landmark seed."""
        self._check_params()
        X, y, w = validated_training_data(self, X, y, sample_weight)
        if np.any(w < 0):
            raise ValueError(f"sample_weight must be ≥ 0; row {int(np.argmax(w < 0))} is negative")
        used = np.flatnonzero(w > 0)
        if used.size < 2:
            raise ValueError(f"need at least 2 samples with positive weight, got {used.size}")
        Y = y.reshape(y.shape[0], -1)
        self._ravel_output = y.ndim == 1
        self.n_outputs_ = Y.shape[1]
        self.support_ = used
        X, Y, w = X[used], Y[used], w[used]
        self.solver_ = self._resolve_solver(*X.shape)
        return X, Y, w, int(check_random_state(self.random_state).randint(2**31))

    def _fit_weighted(self, X: np.ndarray, Y: np.ndarray, w: np.ndarray, seed: int) -> None:
        """One weighted LS-SVM fit; sets the private 2-D solution arrays."""
        self._system(X, Y, w, seed)(self, float(self.gamma))

    def _system(self, X: np.ndarray, Y: np.ndarray, w: np.ndarray, seed: int,
                reuse: bool = False):  # fmt: skip
        """What a fit computes whatever γ is, and ``solve(estimator, γ)``, which sets that
        estimator's private 2-D solution arrays from it; ``reuse``: for more than one solve (the
        dense solve factors the kernel matrix in place, so each then takes a copy)."""
        if self.solver_ == "primal":
            A, B = accumulate_normal_equations([(X, Y, w)], X.shape[1], Y.shape[1])

            def solve(est: LSSVR, gamma: float) -> None:
                est._landmark_coef = None
                est._coef, est._intercept, est.condition_number_ = solve_primal(A, B, gamma)
                residual = Y - X @ est._coef.T - est._intercept
                est._alpha = gamma * w[:, None] * residual

            return solve
        if self.solver_ == "dense":
            check_dense_size(X.shape[0], self.max_dense_samples)
            K = kernel_matrix(X, X, self.kernel, **self._kernel_params())
            mercer = self._is_mercer()

            def solve(est: LSSVR, gamma: float) -> None:
                est._coef = est._landmark_coef = None
                H = K.copy() if reuse else K
                est._alpha, est._intercept = solve_dual(H, Y, 1.0 / (gamma * w), mercer)
                if est.kernel == "linear":
                    est._coef = est._alpha.T @ X
                else:
                    est.X_fit_ = X

            return solve
        landmarks = choose_landmarks(X, self.n_landmarks, np.random.default_rng(seed))
        fmap = NystromMap(landmarks, self.kernel, **self._kernel_params())
        blocks = ((phi, Y[rows], w[rows]) for rows, phi in fmap.feature_blocks(X))
        A, B = accumulate_normal_equations(blocks, fmap.n_components, Y.shape[1])

        def solve(est: LSSVR, gamma: float) -> None:
            est._coef = est._alpha = None
            coef, est._intercept, est.condition_number_ = solve_primal(A, B, gamma)
            est.landmarks_ = landmarks
            est._landmark_coef = fmap.transform @ coef.T
            est.n_components_ = fmap.n_components

        return solve

    def _training_residuals(self, X: np.ndarray, Y: np.ndarray, w: np.ndarray) -> np.ndarray:
        if self._alpha is not None:  # α = γ w e (KKT condition, eq. 5)
            return self._alpha / (self.gamma * w[:, None])
        return Y - self._decision(X)

    def _fit_robust(self, X: np.ndarray, Y: np.ndarray, w: np.ndarray, seed: int) -> None:
        """Iteratively reweighted LS-SVM on one output (Suykens et al. 2002)."""
        v = np.ones(X.shape[0])
        self._fit_weighted(X, Y, w, seed)
        self.n_iter_ = 1
        for _ in range(self.max_iter):
            e = self._training_residuals(X, Y, w * v)[:, 0]
            v_new = robust_weights(e, self.weighting)
            if v_new is None:  # residuals all equal: an exact fit, nothing to downweight
                break
            self.n_iter_ += 1
            change = float(np.max(np.abs(v_new - v)))
            v = v_new
            self._fit_weighted(X, Y, w * v, seed)
            if change < self.tol:
                break
        else:
            warnings.warn(
                f"robust LS-SVM ({self.weighting}) did not converge in max_iter={self.max_iter} "
                "refits; raise max_iter or check the data for structure the kernel cannot fit",
                ConvergenceWarning,
                stacklevel=3,
            )
        self.robust_weights_ = v

    def _fit_robust_per_output(
        self, X: np.ndarray, Y: np.ndarray, w: np.ndarray, seed: int
    ) -> None:
        # Each output has its own residuals, hence its own robust weights and its own system.
        fits = [
            clone(self).set_params(random_state=seed).fit(X, Y[:, j], w) for j in range(Y.shape[1])
        ]
        first = fits[0]
        self._intercept = np.array([f._intercept[0] for f in fits])
        self.robust_weights_ = np.column_stack([f.robust_weights_ for f in fits])
        self.n_iter_ = max(f.n_iter_ for f in fits)
        def stack(name: str) -> np.ndarray | None:
            parts = [getattr(f, name) for f in fits]
            return None if parts[0] is None else np.hstack(parts)

        self._alpha = stack("_alpha")
        self._landmark_coef = stack("_landmark_coef")
        self._coef = None if first._coef is None else np.vstack([f._coef for f in fits])
        for attr in ("X_fit_", "landmarks_", "n_components_"):
            if hasattr(first, attr):
                setattr(self, attr, getattr(first, attr))
        if hasattr(first, "condition_number_"):
            self.condition_number_ = max(f.condition_number_ for f in fits)

    def _publish(self) -> None:
        """Public fitted attributes, 1-D where y was 1-D (scikit-learn convention)."""
        r = self._ravel_output
        self.intercept_ = float(self._intercept[0]) if r else self._intercept.copy()
        if self._alpha is not None:
            self.alpha_ = self._alpha[:, 0] if r else self._alpha
        if self._coef is not None:
            self.coef_ = self._coef[0] if r else self._coef
        if self._landmark_coef is not None:
            self.landmark_coef_ = self._landmark_coef[:, 0] if r else self._landmark_coef

    # ------------------------------------------------------------------ prediction
    def _decision(self, X: np.ndarray) -> np.ndarray:
        """(n, q) model output Σ αᵢ K(x, xᵢ) + b (eq. 6), in row blocks for kernel models."""
        if self._coef is not None:
            return X @ self._coef.T + self._intercept
        if self._landmark_coef is not None:
            centres, weights = self.landmarks_, self._landmark_coef
        else:
            centres, weights = self.X_fit_, self._alpha
        out = np.empty((X.shape[0], weights.shape[1]))
        for rows in row_blocks(X.shape[0], centres.shape[0]):
            K = kernel_matrix(X[rows], centres, self.kernel, **self._kernel_params())
            out[rows] = K @ weights
        out += self._intercept
        return out

    def predict(self, X) -> np.ndarray:
        """Predicted outputs, (n_samples,) or (n_samples, n_outputs) as y was at fit."""
        check_is_fitted(self, "intercept_")
        X = validate_data(self, X, reset=False, ensure_all_finite=False, dtype=np.float64)
        check_finite(X, "X")
        out = self._decision(X)
        return out[:, 0] if self._ravel_output else out

    def __sklearn_tags__(self):
        tags = super().__sklearn_tags__()
        tags.target_tags.multi_output = True
        tags.target_tags.single_output = True
        return tags

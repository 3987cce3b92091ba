"""Equation-error estimators: which regressor fits the per-DOF regression (paper eqs. 11–12).

Semiphysical (the model keeps its named terms; any estimator with ``coef_`` and ``intercept_``):

* ``lssvm`` (default): the paper's linear-kernel LS-SVM, ½‖w‖² + γ/2 Σe² with an unpenalised
  bias (eqs. 2–6, 14–15). On the raw regressors it equals ridge regression with α = 1/γ.
* ``ols``: ordinary least squares (γ → ∞).
* ``ridge``: ridge on standardised regressors, α = 1/γ (every term shrunk alike, whatever its
  scale: |n|n ~ 100 and δ ~ 0.3 are penalised the same).
* ``lasso``: ℓ1 on standardised regressors, α = 1/γ (sparse: zero coefficients drop terms).
* ``svr``: ε-insensitive support vector regression, linear kernel, C = γ, ε half the spread of
  the least-squares residual (the noise level: errors inside it are not fitted).
* any scikit-learn regressor object with ``coef_`` after ``fit`` (API only).

Black-box (no physical structure; a dynamics model of the accelerations on u, v, r and the
inputs, simulated by the generic path): ``elm`` (extreme learning machine, scikit-elm) and
``lssvm-rbf`` (RBF LS-SVM, fixed-size for large N). They are for comparisons (``shipid compare``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from shipid.errors import ShipidError

LINEAR_ESTIMATORS = ("lssvm", "ols", "ridge", "lasso", "svr")
BLACK_BOX_ESTIMATORS = ("elm", "lssvm-rbf")
ESTIMATORS = LINEAR_ESTIMATORS + BLACK_BOX_ESTIMATORS


def check_estimator_name(name) -> str:
    """``name`` if it is a known estimator (or an estimator object), else an error."""
    if isinstance(name, str) and name not in ESTIMATORS:
        raise ShipidError(f"unknown estimator {name!r}; use one of {', '.join(ESTIMATORS)}")
    return name


def fit_linear(X: np.ndarray, y: np.ndarray, estimator="lssvm", gamma: float = 1e4,
               sample_weight: np.ndarray | None = None, physics=None,
               ) -> tuple[np.ndarray, float]:  # fmt: skip
    """Coefficients and bias of one DOF's regression y ≈ X w + b with ``estimator``.

    ``physics``: a ``shipid.identification.physics.DofPhysics`` (prior, bounds, tied bias),
    for the ``lssvm`` and ``ols`` estimators; the bounds held are in ``physics.active``. An
    equation without a constant term (``physics.no_constant``) is fitted with b = 0 by those
    two; the other estimators fit a bias, which the model then leaves out."""
    if physics is not None and (_changes_fit(physics) or physics.no_constant
                                and estimator in ("lssvm", "ols")):
        if estimator not in ("lssvm", "ols"):
            raise ShipidError(f"priors and constraints need the lssvm or ols estimator, not "
                              f"{estimator if isinstance(estimator, str) else type(estimator).__name__}")
        from shipid.lssvm.solvers import accumulate_normal_equations, solve_primal_constrained

        w = np.ones(len(y)) if sample_weight is None else np.asarray(sample_weight, float)
        A, B = accumulate_normal_equations([(X, y[:, None], w)], X.shape[1], 1)
        coef, bias, physics.active = solve_primal_constrained(
            A, B[:, 0], gamma if estimator == "lssvm" else math.inf, physics.prior,
            physics.lower, physics.upper, physics.solver_equalities(), physics.inequalities,
            physics.inequality_labels)
        return coef, 0.0 if physics.no_constant else bias
    fit_kw = {} if sample_weight is None else {"sample_weight": sample_weight}
    if not isinstance(estimator, str):
        from sklearn.base import clone

        est = clone(estimator).fit(X, y, **fit_kw)
        return _coef_and_bias(est, X.shape[1])
    check_estimator_name(estimator)
    if estimator in BLACK_BOX_ESTIMATORS:
        raise ShipidError(f"estimator {estimator!r} is a black-box model without named terms; "
                          "use it with shipid compare")  # fmt: skip
    if estimator == "lssvm":
        # LSSVR(kernel="linear", solver="primal") without the estimator class (and scikit-learn).
        from shipid.lssvm.solvers import accumulate_normal_equations, solve_primal

        w = np.ones(len(y)) if sample_weight is None else np.asarray(sample_weight, float)
        A, B = accumulate_normal_equations([(X, y[:, None], w)], X.shape[1], 1)
        coef, intercept, _ = solve_primal(A, B, gamma)
        return coef[0], float(intercept[0])
    if estimator == "ols":
        sw = np.ones(len(y)) if sample_weight is None else np.sqrt(np.asarray(sample_weight, float))
        A = np.column_stack([X, np.ones(len(X))]) * sw[:, None]
        sol = np.linalg.lstsq(A, y * sw, rcond=None)[0]
        return sol[:-1], float(sol[-1])
    # Standardised regressors: the penalty treats every term alike whatever its units.
    mean, scale = X.mean(axis=0), X.std(axis=0)
    scale[scale == 0] = 1.0
    Z = (X - mean) / scale
    if estimator == "ridge":
        from sklearn.linear_model import Ridge

        est = Ridge(alpha=len(y) / gamma).fit(Z, y, **fit_kw)
    elif estimator == "lasso":
        from sklearn.linear_model import Lasso

        est = Lasso(alpha=float(np.std(y)) / np.sqrt(gamma), max_iter=20_000).fit(Z, y, **fit_kw)
    else:
        from sklearn.svm import LinearSVR

        A = np.column_stack([Z, np.ones(len(y))])
        noise = float(np.std(y - A @ np.linalg.lstsq(A, y, rcond=None)[0]))
        est = LinearSVR(C=gamma, epsilon=0.5 * noise, max_iter=50_000, dual="auto",
                        loss="squared_epsilon_insensitive").fit(Z, y, **fit_kw)  # fmt: skip
    coef, bias = _coef_and_bias(est, X.shape[1])
    w = coef / scale
    return w, float(bias - w @ mean)


def _changes_fit(physics) -> bool:
    return (physics.prior is not None or physics.equalities is not None
            or physics.inequalities is not None
            or bool(np.isfinite(physics.lower).any() or np.isfinite(physics.upper).any()))


def _coef_and_bias(est, p: int) -> tuple[np.ndarray, float]:
    coef = np.ravel(getattr(est, "coef_", None) if hasattr(est, "coef_") else [])
    if coef.size != p:
        raise ShipidError(f"estimator {type(est).__name__} has no coef_ of the {p} terms after "
                          "fit: only linear estimators can fit named terms")  # fmt: skip
    return coef.astype(float), float(np.ravel(getattr(est, "intercept_", 0.0))[0])


class RegressorDynamics:
    """A black-box dynamics model: one regressor per DOF maps (u, v, r, inputs) to the
    acceleration. Follows the simulator's Dynamics protocol (generic path)."""

    uses_thrust = False

    def __init__(self, estimators: Sequence, inputs: Sequence[str], name: str = "black box"):
        self.estimators = list(estimators)
        self.inputs = tuple(inputs)
        self.uses_rps = "n" in self.inputs
        self.name = name

    def features(self, u, v, r, given: dict) -> np.ndarray:
        """(N, 3 + inputs) regressor inputs: u, v, r and the input signals."""
        cols = [u, v, r] + [np.broadcast_to(np.asarray(given[c], float), np.shape(u))
                            for c in self.inputs]  # fmt: skip
        return np.column_stack(cols)

    def derivatives(self, nu, delta, thrust=None, rps=None, **inputs) -> np.ndarray:
        """(B, 3) accelerations predicted by the three regressors."""
        given = {"delta": delta, "n": rps, "thrust": thrust, **inputs}
        X = self.features(nu[:, 0], nu[:, 1], nu[:, 2], given)
        return np.column_stack([est.predict(X) for est in self.estimators])


def make_black_box(name: str, gamma: float = 1e4, n_neurons: int = 200, seed: int = 0):
    """An unfitted regressor of a black-box estimator name."""
    if name == "elm":
        try:
            from skelm import ELMRegressor
        except ImportError as exc:  # pragma: no cover - a dependency of shipid
            raise ShipidError(f"the ELM estimator needs scikit-elm ({exc})") from None
        return ELMRegressor(n_neurons=n_neurons, ufunc="tanh", alpha=1.0 / gamma,
                            include_original_features=True, random_state=seed)  # fmt: skip
    if name == "lssvm-rbf":
        from sklearn.pipeline import make_pipeline
        from sklearn.preprocessing import StandardScaler

        from shipid.lssvm import LSSVR

        return make_pipeline(StandardScaler(), LSSVR(gamma=gamma, kernel="rbf", sigma=3.0,
                                                     solver="fixed-size", n_landmarks=400,
                                                     random_state=seed))  # fmt: skip
    raise ShipidError(f"{name!r} is not a black-box estimator ({', '.join(BLACK_BOX_ESTIMATORS)})")

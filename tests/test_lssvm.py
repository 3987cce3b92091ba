"""LS-SVM core against independent truths: the bordered KKT system solved by numpy, brute-force
leave-one-out refits, repeated samples, and the dense solution for the fixed-size solver."""

import numpy as np
import pytest

from shipid.lssvm import LSSVR, LSSVRCV, kernel_matrix, loo_residuals


def problem(n=40, p=3, q=1, seed=0):
    rng = np.random.default_rng(seed)
    X = rng.normal(size=(n, p))
    W = rng.normal(size=(p, q))
    Y = np.sin(X) @ W + 0.1 * rng.normal(size=(n, q)) + 2.0
    return X, (Y[:, 0] if q == 1 else Y), rng.uniform(0.2, 3.0, size=n)


def bordered_kkt_solution(X, Y, gamma, w, **kernel):
    """The paper's KKT system [[0, 1ᵀ], [1, K + diag(1/(γw))]] [b; α] = [0; y], solved by numpy."""
    n = X.shape[0]
    Y2 = Y.reshape(n, -1)
    C = np.zeros((n + 1, n + 1))
    C[0, 1:] = C[1:, 0] = 1.0
    C[1:, 1:] = kernel_matrix(X, X, **kernel) + np.diag(1.0 / (gamma * w))
    sol = np.linalg.solve(C, np.vstack([np.zeros((1, Y2.shape[1])), Y2]))
    return sol[1:], sol[0]


KERNEL_CASES = [
    {"kernel": "linear"},
    {"kernel": "rbf", "sigma": 1.3},
    {"kernel": "poly", "degree": 2, "coef0": 1.0},
]


@pytest.mark.parametrize("kernel", KERNEL_CASES, ids=lambda k: k["kernel"])
@pytest.mark.parametrize("q", [1, 3])
@pytest.mark.parametrize("weighted", [False, True])
def test_dense_dual_matches_bordered_kkt_solve(kernel, q, weighted):
    X, y, w = problem(q=q)
    w = w if weighted else np.ones(len(y))
    est = LSSVR(gamma=7.0, solver="dense", **kernel).fit(X, y, sample_weight=w)
    full = {"sigma": 1.0, "degree": 3, "coef0": 1.0} | kernel
    alpha, b = bordered_kkt_solution(X, y, 7.0, w, **full)
    np.testing.assert_allclose(est.alpha_.reshape(alpha.shape), alpha, rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(np.ravel(est.intercept_), b, rtol=1e-9)
    # Prediction is eq. (6): Σ αᵢ K(x, xᵢ) + b.
    Xt = problem(n=7, seed=5)[0]
    expected = kernel_matrix(Xt, X, **full) @ alpha + b
    np.testing.assert_allclose(est.predict(Xt).reshape(expected.shape), expected, rtol=1e-9)


@pytest.mark.parametrize("q", [1, 3])
@pytest.mark.parametrize("weighted", [False, True])
def test_primal_and_dual_agree_for_linear_kernel(q, weighted):
    X, y, w = problem(n=60, p=5, q=q, seed=1)
    w = w if weighted else None
    dual = LSSVR(gamma=30.0, kernel="linear", solver="dense").fit(X, y, sample_weight=w)
    primal = LSSVR(gamma=30.0, kernel="linear").fit(X, y, sample_weight=w)
    assert primal.solver_ == "primal"
    np.testing.assert_allclose(primal.coef_, dual.coef_, rtol=1e-9)
    np.testing.assert_allclose(primal.intercept_, dual.intercept_, rtol=1e-9)
    np.testing.assert_allclose(primal.alpha_, dual.alpha_, rtol=1e-8, atol=1e-10)
    np.testing.assert_allclose(primal.predict(X), dual.predict(X), rtol=1e-9)


def test_linear_coef_is_sum_of_support_values_times_inputs():
    """The paper's Γ = Σ αᵢ xᵢ (eq. 15) and Σ αᵢ = 0 (eq. 5)."""
    X, y, _ = problem(n=30, p=4)
    est = LSSVR(gamma=100.0, kernel="linear", solver="dense").fit(X, y)
    np.testing.assert_allclose(est.coef_, est.alpha_ @ X, rtol=1e-12)
    assert abs(est.alpha_.sum()) < 1e-9 * np.abs(est.alpha_).sum()


def test_sample_weight_equals_repeated_samples():
    X, y, _ = problem(n=25)
    reps = np.arange(25) % 3 + 1
    weighted = LSSVR(gamma=5.0).fit(X, y, sample_weight=reps)
    repeated = LSSVR(gamma=5.0).fit(np.repeat(X, reps, axis=0), np.repeat(y, reps))
    np.testing.assert_allclose(weighted.predict(X), repeated.predict(X), rtol=1e-9)


@pytest.mark.parametrize(
    "params",
    [
        {"kernel": "linear"},
        {"kernel": "linear", "solver": "dense"},
        {"kernel": "rbf", "sigma": 0.8},
        {"kernel": "poly", "degree": 2},
        {"kernel": "rbf", "sigma": 1.5, "solver": "fixed-size", "n_landmarks": 12},
    ],
    ids=["linear-primal", "linear-dense", "rbf", "poly", "fixed-size"],
)
@pytest.mark.parametrize("q", [1, 2])
def test_closed_form_loo_equals_brute_force_refits(params, q):
    X, y, w = problem(n=30, q=q, seed=3)
    est = LSSVR(gamma=20.0, random_state=0, **params)
    loo = loo_residuals(est, X, y, sample_weight=w)
    brute = np.empty_like(loo)
    landmarks = None
    if params.get("solver") == "fixed-size":
        landmarks = est.fit(X, y).landmarks_  # the closed form holds the landmarks fixed
    for i in range(len(y)):
        keep = np.arange(len(y)) != i
        if landmarks is None:
            fit = LSSVR(gamma=20.0, **params).fit(X[keep], y[keep], sample_weight=w[keep])
        else:
            fit = _fixed_landmark_fit(X[keep], y[keep], w[keep], landmarks, 20.0, 1.5)
        brute[i] = y[i] - fit.predict(X[i : i + 1])[0]
    np.testing.assert_allclose(loo, brute, rtol=1e-7, atol=1e-10)


def _fixed_landmark_fit(X, y, w, landmarks, gamma, sigma):
    """Primal LS-SVM on Nyström features of given landmarks (brute-force reference)."""
    from shipid.lssvm.nystrom import NystromMap

    fmap = NystromMap(landmarks, "rbf", sigma=sigma, degree=3, coef0=1.0)
    est = LSSVR(gamma=gamma, kernel="linear", solver="primal").fit(fmap.features(X), y, w)

    class Fitted:
        def predict(self, Xn):
            return est.predict(fmap.features(Xn))

    return Fitted()


def test_robust_fit_recovers_a_line_under_gross_outliers():
    rng = np.random.default_rng(4)
    x = np.linspace(-3, 3, 200)[:, None]
    y = 1.5 * x[:, 0] - 0.7 + 0.05 * rng.normal(size=200)
    bad = rng.choice(200, size=20, replace=False)  # 10 % gross outliers
    y[bad] += rng.choice([-1, 1], size=20) * rng.uniform(5, 15, size=20)
    plain = LSSVR(gamma=1e3, kernel="linear").fit(x, y)
    for weighting in ("huber", "hampel"):
        robust = LSSVR(gamma=1e3, kernel="linear", weighting=weighting).fit(x, y)
        assert abs(robust.coef_[0] - 1.5) < 0.02 and abs(robust.intercept_ + 0.7) < 0.05
        assert robust.n_iter_ >= 2
        assert robust.robust_weights_[bad].max() < 0.2  # the outliers were downweighted
    assert abs(plain.coef_[0] - 1.5) > 0.05 or abs(plain.intercept_ + 0.7) > 0.1


def test_robust_multi_output_fits_each_output_separately():
    X, Y, _ = problem(n=50, q=2, seed=6)
    both = LSSVR(gamma=10.0, weighting="huber").fit(X, Y)
    for j in range(2):
        single = LSSVR(gamma=10.0, weighting="huber").fit(X, Y[:, j])
        np.testing.assert_allclose(both.predict(X)[:, j], single.predict(X), rtol=1e-10)


def test_fixed_size_with_all_points_as_landmarks_is_the_dense_solution():
    X, y, _ = problem(n=80, p=2, seed=7)
    dense = LSSVR(gamma=10.0, sigma=0.7).fit(X, y)
    fixed = LSSVR(gamma=10.0, sigma=0.7, solver="fixed-size", n_landmarks=80).fit(X, y)
    Xt = problem(n=20, p=2, seed=8)[0]
    np.testing.assert_allclose(fixed.predict(Xt), dense.predict(Xt), rtol=1e-7, atol=1e-9)


def test_fixed_size_with_few_landmarks_stays_close_to_dense():
    """m = 100 of N = 3000 on a smooth 2-D function: predictions within 1 % RMS of the exact
    dense LS-SVM (relative to the spread of the targets)."""
    rng = np.random.default_rng(9)
    X = rng.uniform(-2, 2, size=(3000, 2))
    y = np.sin(2 * X[:, 0]) * np.cos(X[:, 1]) + 0.05 * rng.normal(size=3000)
    dense = LSSVR(gamma=100.0, sigma=1.0).fit(X, y)
    fixed = LSSVR(gamma=100.0, sigma=1.0, solver="fixed-size", n_landmarks=100, random_state=0)
    fixed.fit(X, y)
    Xt = rng.uniform(-2, 2, size=(500, 2))
    rel = np.sqrt(np.mean((fixed.predict(Xt) - dense.predict(Xt)) ** 2)) / np.std(y)
    assert rel < 0.01


def test_dense_refuses_large_n_and_names_the_fixed_size_solver():
    X, y, _ = problem(n=50)
    with pytest.raises(ValueError, match="fixed-size"):
        LSSVR(max_dense_samples=40).fit(X, y)


def test_lssvrcv_picks_the_gamma_with_smallest_brute_force_loo_error():
    X, y, _ = problem(n=40, seed=10)
    gammas = np.logspace(-1, 4, 6)
    cv = LSSVRCV(gammas=gammas, sigmas=[0.5, 2.0]).fit(X, y)
    brute = {}
    for s in (0.5, 2.0):
        for g in gammas:
            est = LSSVR(gamma=g, sigma=s)
            brute[(s, g)] = np.mean(loo_residuals(est, X, y) ** 2)
    best = min(brute, key=brute.get)
    assert (cv.best_params_["sigma"], cv.best_params_["gamma"]) == pytest.approx(best)
    np.testing.assert_allclose(np.sort(cv.cv_results_["mse"]), np.sort(list(brute.values())))
    assert cv.best_estimator_.gamma == pytest.approx(best[1])
    assert cv.predict(X).shape == y.shape


@pytest.mark.parametrize("block", [4096, 16])  # one block of rows, and several with a rest
def test_fused_loo_mse_equals_mean_of_residuals(monkeypatch, block):
    from shipid.lssvm import loo
    from shipid.lssvm.loo import PrimalLOOPath

    monkeypatch.setattr(loo, "ROW_BLOCK", block)
    X, Y, w = problem(n=50, q=3, seed=12)
    path = PrimalLOOPath(X, Y, w)
    gammas = (0.1, 10.0, 1e5)
    grid = path.mse_grid(gammas)
    for g, mse in zip(gammas, grid, strict=True):
        assert mse == pytest.approx(np.mean(path.residuals(g) ** 2), rel=1e-12)
        assert path.mse(g) == pytest.approx(mse, rel=1e-12)


def test_lssvrcv_kfold_and_linear_kernel():
    X, y, _ = problem(n=60, seed=11)
    cv = LSSVRCV(gammas=[0.01, 1.0, 100.0], kernel="linear", cv=3).fit(X, y)
    assert cv.best_params_["gamma"] in (0.01, 1.0, 100.0)
    assert cv.cv_results_["mse"].shape == (3,)


@pytest.mark.parametrize(
    ("params", "match"),
    [
        ({"gamma": 0.0}, "gamma"),
        ({"gamma": -1.0}, "gamma"),
        ({"sigma": 0.0}, "sigma"),
        ({"kernel": "sigmoid"}, "kernel"),
        ({"solver": "cg"}, "solver"),
        ({"kernel": "rbf", "solver": "primal"}, "primal"),
        ({"weighting": "tukey"}, "weighting"),
    ],
)
def test_bad_parameters_name_themselves(params, match):
    X, y, _ = problem()
    with pytest.raises(ValueError, match=match):
        LSSVR(**params).fit(X, y)


def test_bad_data_errors_name_the_row_and_column():
    X, y, _ = problem(n=10)
    Xn = X.copy()
    Xn[4, 2] = np.nan
    with pytest.raises(ValueError, match="X contains NaN at row 4, column 2"):
        LSSVR().fit(Xn, y)
    yi = y.copy()
    yi[7] = np.inf
    with pytest.raises(ValueError, match="y contains inf at row 7"):
        LSSVR().fit(X, yi)
    with pytest.raises(ValueError, match="inconsistent numbers of samples"):
        LSSVR().fit(X, y[:-1])
    with pytest.raises(ValueError, match="1 sample"):
        LSSVR().fit(X[:1], y[:1])
    fitted = LSSVR().fit(X, y)
    with pytest.raises(ValueError, match="X contains NaN at row 4, column 2"):
        fitted.predict(Xn)


@pytest.mark.parametrize("solver", ["primal", "dense"])
def test_constant_and_collinear_features_are_legal(solver):
    X, y, _ = problem(n=30)
    Xc = np.column_stack([X, np.ones(30), 2.0 * X[:, 0], np.zeros(30)])
    est = LSSVR(gamma=1e3, kernel="linear", solver=solver).fit(Xc, y)
    assert np.all(np.isfinite(est.coef_))
    # Σα = 0 makes the weight of a constant column exactly zero: the bias carries the constant.
    assert abs(est.coef_[3]) < 1e-8
    assert est.score(Xc, y) > 0.5


# On the test, not in pyproject.toml: a filter there names its class, so pytest imported
# scikit-learn (and NumPy with it) before conftest.py could hold BLAS to one thread per worker.
@pytest.mark.filterwarnings("ignore::sklearn.exceptions.SkipTestWarning")
def test_passes_scikit_learn_estimator_checks():
    # scikit-learn's checks and model selection imported in the two tests that use them: at
    # the top they cost every test worker 0.8 s of its collection.
    from sklearn.utils.estimator_checks import check_estimator

    failures = [
        (r["check_name"], str(r["exception"]))
        for r in check_estimator(LSSVR(), on_fail=None)
        if r["status"] == "failed"
    ]
    assert failures == []


def test_works_in_pipeline_and_grid_search():
    from sklearn.model_selection import GridSearchCV
    from sklearn.pipeline import make_pipeline
    from sklearn.preprocessing import StandardScaler

    X, y, _ = problem(n=60)
    pipe = make_pipeline(StandardScaler(), LSSVR(kernel="rbf"))
    search = GridSearchCV(pipe, {"lssvr__gamma": [0.1, 10.0], "lssvr__sigma": [1.0, 3.0]}, cv=3)
    search.fit(X, y)
    assert search.best_score_ > 0.5
    assert set(search.best_params_) == {"lssvr__gamma", "lssvr__sigma"}


@pytest.mark.parametrize("sigma", [0.3, 1.0, 5.0])
def test_rbf_kernel_is_the_brute_force_distance(sigma):
    rng = np.random.default_rng(11)
    X = rng.normal(size=(37, 4))
    Z = np.vstack([rng.normal(size=(20, 4)), X[:5]])  # identical points: distance exactly 0
    brute = np.exp(-((X[:, None, :] - Z[None, :, :]) ** 2).sum(axis=-1) / sigma**2)
    K = kernel_matrix(X, Z, "rbf", sigma=sigma)
    np.testing.assert_allclose(K, brute, rtol=1e-12, atol=1e-300)
    assert np.all(K <= 1.0)
    np.testing.assert_allclose(np.diag(kernel_matrix(X, X, "rbf", sigma=sigma)), 1.0, rtol=1e-13)


@pytest.mark.parametrize("weights", ["ones", "bootstrap", "real"])
def test_normal_equations_are_the_weighted_products(weights):
    from shipid.lssvm.solvers import accumulate_normal_equations

    rng = np.random.default_rng(12)
    F, Y = rng.normal(size=(300, 6)), rng.normal(size=(300, 2))
    w = {"ones": np.ones(300), "bootstrap": rng.poisson(1.0, 300).astype(float),
         "real": rng.uniform(0, 3, 300)}[weights]  # fmt: skip
    blocks = [(F[s], Y[s], w[s]) for s in (slice(0, 120), slice(120, 300))]
    A, B = accumulate_normal_equations(blocks, 6, 2)
    Fb = np.column_stack([F, np.ones(300)])
    np.testing.assert_allclose(A, Fb.T @ (w[:, None] * Fb), rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(B, Fb.T @ (w[:, None] * Y), rtol=1e-12, atol=1e-12)
    assert np.array_equal(A, A.T)


@pytest.mark.parametrize("params", [
    {"kernel": "rbf", "sigma": 1.5},
    {"kernel": "linear"},  # the primal solver
    {"kernel": "rbf", "sigma": 1.5, "solver": "fixed-size", "n_landmarks": 20, "random_state": 3},
])  # fmt: skip
def test_a_gamma_path_is_the_fits_at_each_gamma(params):
    rng = np.random.default_rng(7)
    X = rng.normal(size=(80, 3))
    y = np.column_stack([np.sin(X[:, 0]) + 0.1 * rng.normal(size=80), X[:, 1] * X[:, 2]])
    w = rng.uniform(0.5, 2.0, size=80)
    gammas = (0.1, 3.0, 100.0)
    path = LSSVR(**params).fit_path(X, y, gammas, sample_weight=w)
    X_new = rng.normal(size=(10, 3))
    for gamma, est in zip(gammas, path, strict=True):
        one = LSSVR(gamma=gamma, **params).fit(X, y, sample_weight=w)
        assert est.gamma == gamma
        np.testing.assert_allclose(est.predict(X_new), one.predict(X_new), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(est.intercept_, one.intercept_, rtol=1e-12, atol=1e-12)
    with pytest.raises(ValueError, match="weighting=None"):
        LSSVR(weighting="huber").fit_path(X, y[:, 0], gammas)
    with pytest.raises(ValueError, match="gamma"):
        LSSVR().fit_path(X, y, (1.0, -1.0))


def test_the_gamma_prescreen_does_not_import_scikit_learn():
    """``select``'s γ pre-screen (every ``identify`` and ``select`` that searches) imported
    scikit-learn with the LOO paths, 0.9 s of every such command; the paths are apart now."""
    from cli_helpers import fresh_python

    code = ("import sys; from shipid.lssvm.loo import PrimalLOOPath; "
            "import shipid.identification.select; print('sklearn' in sys.modules)")
    assert fresh_python(code).strip() == "False"


def test_a_fit_with_equalities_alone_does_not_import_scipy_optimize():
    """The constrained solve imported ``scipy.optimize`` (0.1–0.3 s) on every call, though only
    bounds use it: the Esso's default searches, whose fits hold equalities alone, paid it."""
    from cli_helpers import fresh_python

    code = ("import sys, numpy as np; from shipid.lssvm.solvers import solve_primal_constrained; "
            "A = np.eye(3) + 0.1; b = np.ones(3); "
            "x, bias, _ = solve_primal_constrained(A, b, 1e4, equalities=(np.array([[1.0, 0, 0]]),"
            " np.array([0.5]))); "
            "print(round(float(x[0]), 12), 'scipy.optimize' in sys.modules)")
    assert fresh_python(code).split() == ["0.5", "False"]


@pytest.mark.parametrize("seed", range(3))
def test_the_positive_definite_solve_is_scipys_to_the_bit(seed):
    """``solve_positive`` (LAPACK's posv, called directly: select solves thousands of small
    systems) gives SciPy's ``solve(assume_a="pos")`` bit for bit, one right-hand side or many,
    for the bordered systems' two unknowns or more (SciPy divides a 1 × 1 one), and refuses a
    matrix that is not positive definite as SciPy does."""
    from scipy import linalg

    from shipid.lssvm.solvers import solve_positive

    rng = np.random.default_rng(seed)
    for p in (2, 4, 17, 40):
        F = rng.normal(size=(3 * p + 5, p)) * np.logspace(-3, 3, p)
        M = F.T @ F + 1e-6 * np.eye(p)
        for b in (rng.normal(size=p), rng.normal(size=(p, 3))):
            assert np.array_equal(solve_positive(M, b),
                                  linalg.solve(M, b, assume_a="pos", check_finite=False))
    indefinite = np.diag([1.0, -1.0, 2.0])
    with pytest.raises(linalg.LinAlgError):
        solve_positive(indefinite, np.ones(3))
    with pytest.raises(linalg.LinAlgError):
        linalg.solve(indefinite, np.ones(3), assume_a="pos", check_finite=False)

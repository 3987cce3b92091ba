"""LS-SVM performance against baselines run in the same process (issue: LS-SVM core).

Prints a Markdown table: measured times and the ratio to the baseline, with the target.
Run: .venv/bin/python benchmarks/bench_lssvm.py [--quick]
"""

from __future__ import annotations

import argparse
import multiprocessing as mp
import os
import time

import numpy as np
from scipy import linalg
from sklearn.kernel_ridge import KernelRidge
from timing import best_of

from shipid.lssvm import LSSVR, LSSVRCV, kernel_matrix
from shipid.lssvm.loo import DualLOOPath, PrimalLOOPath


def smooth_target(X: np.ndarray) -> np.ndarray:
    return np.sin(X[:, 0]) + 0.5 * np.cos(2 * X[:, 1]) + 0.2 * X[:, 2:].sum(axis=1)


def linear_kernel_rows(sizes, repeats):
    rows = []
    rng = np.random.default_rng(0)
    for n in sizes:
        X = rng.normal(size=(n, 8))
        Y = X @ rng.normal(size=(8, 3)) + 0.1 * rng.normal(size=(n, 3))
        Xb = np.column_stack([X, np.ones(n)])
        t_ls = best_of(lambda: np.linalg.lstsq(Xb, Y, rcond=None), repeats)  # noqa: B023
        est = LSSVR(gamma=1e4, kernel="linear")
        t_fit = best_of(lambda: est.fit(X, Y), repeats)  # noqa: B023
        rows.append(
            (f"linear kernel fit, N={n:.0e}, p=8, 3 outputs", t_fit, "numpy.linalg.lstsq", t_ls,
             "≤ 3×")
        )
    return rows


def dense_rbf_rows(sizes, repeats):
    rows = []
    rng = np.random.default_rng(1)
    sigma, gamma = 2.0, 10.0
    for n in sizes:
        X = rng.normal(size=(n, 8))
        y = smooth_target(X) + 0.1 * rng.normal(size=n)
        kr = KernelRidge(alpha=1.0 / gamma, kernel="rbf", gamma=1.0 / sigma**2)
        t_kr = best_of(lambda: kr.fit(X, y), repeats)  # noqa: B023
        est = LSSVR(gamma=gamma, sigma=sigma)
        t_fit = best_of(lambda: est.fit(X, y), repeats)  # noqa: B023
        rows.append((f"dense RBF fit, N={n}", t_fit, "sklearn KernelRidge", t_kr, "≤ 1.0×"))
    return rows


def rbf_predict_rows(sizes, repeats):
    """Prediction of a fitted dense RBF model on 2e5 new points, against KernelRidge's."""
    rows = []
    rng = np.random.default_rng(2)
    sigma, gamma = 2.0, 10.0
    Xt = rng.normal(size=(200_000, 8))
    for n in sizes:
        X = rng.normal(size=(n, 8))
        y = smooth_target(X) + 0.1 * rng.normal(size=n)
        kr = KernelRidge(alpha=1.0 / gamma, kernel="rbf", gamma=1.0 / sigma**2).fit(X, y)
        est = LSSVR(gamma=gamma, sigma=sigma).fit(X, y)
        t_kr = best_of(lambda: kr.predict(Xt), repeats)  # noqa: B023
        t_est = best_of(lambda: est.predict(Xt), repeats)  # noqa: B023
        rows.append((f"dense RBF predict, N={n}, 2e5 points", t_est, "sklearn KernelRidge", t_kr,
                     "≤ 1.0×"))  # fmt: skip
    return rows


def nystroem_rows(sizes, repeats):
    """Fixed-size fit (row blocks) against scikit-learn's Nystroem + Ridge (all features held)."""
    from sklearn.kernel_approximation import Nystroem
    from sklearn.linear_model import Ridge
    from sklearn.pipeline import make_pipeline

    rows = []
    rng = np.random.default_rng(3)
    sigma, gamma, m = 1.0, 100.0, 500
    for n in sizes:
        X = rng.uniform(-2, 2, size=(n, 3))
        y = smooth_target(X) + 0.1 * rng.normal(size=n)
        pipe = make_pipeline(Nystroem(gamma=1.0 / sigma**2, n_components=m, random_state=0),
                             Ridge(alpha=1.0 / gamma))  # fmt: skip
        t_sk = best_of(lambda: pipe.fit(X, y), repeats)  # noqa: B023
        est = LSSVR(gamma=gamma, sigma=sigma, solver="fixed-size", n_landmarks=m)
        t_est = best_of(lambda: est.fit(X, y), repeats)  # noqa: B023
        rows.append((f"fixed-size fit, N={n:.0e}, m={m}", t_est, "sklearn Nystroem + Ridge", t_sk,
                     "≤ 0.8×"))  # fmt: skip
    return rows


def high_water_mark_bytes() -> int:
    """Peak resident set of this process (VmHWM; unlike ru_maxrss it is not inherited on exec)."""
    with open("/proc/self/status") as fh:
        for line in fh:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) * 1024
    raise RuntimeError("VmHWM not found in /proc/self/status")


def _fixed_size_child(n: int, queue) -> None:
    rng = np.random.default_rng(2)
    X = rng.uniform(-2, 2, size=(n, 3))
    y = smooth_target(X) + 0.1 * rng.normal(size=n)
    Xt = rng.uniform(-2, 2, size=(2000, 3))
    rss0 = high_water_mark_bytes()
    t0 = time.perf_counter()
    est = LSSVR(gamma=100.0, sigma=1.0, solver="fixed-size", n_landmarks=500, random_state=0)
    est.fit(X, y)
    t_fit = time.perf_counter() - t0
    peak = high_water_mark_bytes()
    # Exact dense LS-SVM on a 10 000-point subset, same hyper-parameters: the reference.
    exact = LSSVR(gamma=100.0, sigma=1.0).fit(X[:10_000], y[:10_000])
    truth = smooth_target(Xt)
    queue.put(
        {
            "time": t_fit,
            "peak_gib": peak / 2**30,
            "fit_extra_gib": (peak - rss0) / 2**30,
            "rmse_fixed": float(np.sqrt(np.mean((est.predict(Xt) - truth) ** 2))),
            "rmse_exact_subset": float(np.sqrt(np.mean((exact.predict(Xt) - truth) ** 2))),
            "diff_to_exact": float(np.sqrt(np.mean((est.predict(Xt) - exact.predict(Xt)) ** 2))),
        }
    )


def fixed_size_rows(sizes):
    out = []
    ctx = mp.get_context("spawn")
    for n in sizes:
        q = ctx.Queue()
        p = ctx.Process(target=_fixed_size_child, args=(n, q))
        p.start()
        r = q.get()
        p.join()
        out.append((n, r))
    return out


def grid_only(path_factory, gammas) -> None:
    path_factory().mse_grid(gammas)


def naive_dense_loo_grid(X, y, gammas, sigma) -> None:
    """Per-γ baseline without the eigendecomposition: Cholesky, explicit inverse, LOO formula."""
    K = kernel_matrix(X, X, "rbf", sigma=sigma)
    n = len(y)
    for g in gammas:
        H = K + np.eye(n) / g
        Hinv = linalg.cho_solve(linalg.cho_factor(H), np.eye(n))
        eta, nu = Hinv.sum(axis=1), Hinv @ y
        b = nu.sum() / eta.sum()
        alpha = nu - eta * b
        np.mean((alpha / (np.diag(Hinv) - eta**2 / eta.sum())) ** 2)


def loo_grid_rows(repeats):
    rows = []
    rng = np.random.default_rng(3)
    gammas = np.logspace(-2, 6, 20)
    X = rng.normal(size=(100_000, 8))
    Y = X @ rng.normal(size=(8, 3)) + 0.1 * rng.normal(size=(100_000, 3))
    w = np.ones(len(X))
    PrimalLOOPath(X[:100], Y[:100], w[:100]).mse(1.0)  # compile / load the cached kernel
    t_one = best_of(lambda: LSSVR(gamma=1e4, kernel="linear").fit(X, Y), repeats)
    t_grid = best_of(lambda: grid_only(lambda: PrimalLOOPath(X, Y, w), gammas), repeats)
    t_cv = best_of(lambda: LSSVRCV(gammas=gammas, kernel="linear").fit(X, Y), repeats)
    rows.append(("20-γ exact-LOO grid, linear N=1e5 p=8, 3 outputs", t_grid, "one fit", t_one,
                 "≤ 3×"))
    rows.append(("LSSVRCV (grid + validation + refit), same", t_cv, "one fit", t_one, "–"))
    X = rng.normal(size=(2000, 8))
    y = smooth_target(X)
    w = np.ones(len(X))
    t_one = best_of(lambda: LSSVR(gamma=10.0, sigma=2.0).fit(X, y), repeats)
    K_path = lambda: DualLOOPath(kernel_matrix(X, X, "rbf", sigma=2.0), y[:, None], w)  # noqa: E731
    t_grid = best_of(lambda: grid_only(K_path, gammas), repeats)
    t_naive = best_of(lambda: naive_dense_loo_grid(X, y, gammas, 2.0), 1)
    rows.append(("20-γ exact-LOO grid, dense RBF N=2000", t_grid, "one fit", t_one, "≤ 3×"))
    rows.append(("20-γ exact-LOO grid, dense RBF N=2000", t_grid,
                 "per-γ Cholesky + inverse", t_naive, "–"))
    return rows


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--quick", action="store_true", help="small sizes only")
    args = ap.parse_args()
    repeats = 3
    lin = [10_000, 100_000] if args.quick else [10_000, 100_000, 1_000_000]
    dense = [2000] if args.quick else [2000, 4000, 8000]
    fixed = [100_000] if args.quick else [100_000, 1_000_000]
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")

    rows = linear_kernel_rows(lin, repeats) + dense_rbf_rows(dense, repeats)
    rows += rbf_predict_rows([2000] if args.quick else [2000, 8000], repeats)
    rows += nystroem_rows([100_000] if args.quick else [100_000, 1_000_000], 2)
    rows += loo_grid_rows(repeats)
    print("| case | shipid (s) | baseline | baseline (s) | ratio | target |")
    print("|---|---|---|---|---|---|")
    for name, t, base, tb, target in rows:
        print(f"| {name} | {t:.4f} | {base} | {tb:.4f} | {t / tb:.2f}× | {target} |")
    print()
    print("| fixed-size RBF, m=500, 3 inputs | fit (s) | peak RSS (GiB) | RSS added by fit (GiB) "
          "| test RMSE vs truth | exact dense on 10k subset: RMSE vs truth | RMS(fixed − exact) |")
    print("|---|---|---|---|---|---|---|")
    for n, r in fixed_size_rows(fixed):
        print(f"| N={n:.0e} | {r['time']:.2f} | {r['peak_gib']:.2f} | {r['fit_extra_gib']:.2f} | "
              f"{r['rmse_fixed']:.4f} | {r['rmse_exact_subset']:.4f} | {r['diff_to_exact']:.4f} |")


if __name__ == "__main__":
    main()

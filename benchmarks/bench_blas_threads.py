"""Where BLAS gains from a second thread: the dense LS-SVM solve (Cholesky of K + I/γ and its
back substitution, as ``shipid.lssvm.solvers.solve_dual`` does it) of n equations on one and on
two threads, in the same process. ``shipid.blas`` runs the commands on one thread and asks for
every core from ``MULTITHREADED_FROM`` equations on.

Run: .venv/bin/python benchmarks/bench_blas_threads.py
"""

from __future__ import annotations

import os

import numpy as np
from scipy import linalg
from threadpoolctl import threadpool_limits
from timing import best_of

from shipid.blas import MULTITHREADED_FROM


def main() -> None:
    rng = np.random.default_rng(0)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; shipid.blas asks "
          f"for every core from {MULTITHREADED_FROM} equations\n")
    print("| equations | one thread (s) | two threads (s) | two against one |")
    print("|---|---|---|---|")
    for n in (250, 500, 1000, 2000, 4000):
        a = rng.standard_normal((n, n))
        k = a @ a.T + n * np.eye(n)
        rhs = np.ones((n, 2))
        times = {}
        for threads in (1, 2):
            with threadpool_limits(limits=threads, user_api="blas"):
                times[threads] = best_of(lambda k=k, rhs=rhs: linalg.cho_solve(
                    linalg.cho_factor(k, lower=True), rhs), 5)  # fmt: skip
        print(f"| {n} | {times[1]:.4f} | {times[2]:.4f} | {times[1] / times[2]:.2f}× |")


if __name__ == "__main__":
    main()

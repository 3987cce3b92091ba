"""The small positive definite solves of ``select``: LAPACK's posv called directly
(``shipid.lssvm.solvers.solve_positive``) against ``scipy.linalg.solve(assume_a="pos")``, the
same routine behind its checks (issue #13).

Per call on a 15 × 15 system, and ``select --average`` with the README's library on the Esso's
nine zig-zag files and three random runs as read (``--format osaka-frt``, Δk 0.5 s) in this
process, warm, the two solves alternated round by round, with the model files compared.

Run: .venv/bin/python benchmarks/bench_small_solves.py
"""

from __future__ import annotations

import contextlib
import io
import os
import tempfile
import time
import timeit
import warnings

import numpy as np
from esso_logs import DATA, README_HELD
from scipy import linalg

import shipid.lssvm.solvers as solvers
from shipid.cli import main

ROUNDS = 8


def _scipy(M, b):
    return linalg.solve(M, b, assume_a="pos", check_finite=False)


def main_() -> None:
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    rng = np.random.default_rng(0)
    F = rng.normal(size=(60, 15))
    M, b = F.T @ F, rng.normal(size=15)
    n = 20000
    print("| solve | µs a call (15 × 15) |")
    print("|---|---|")
    for label, f in (("scipy.linalg.solve(assume_a='pos')", _scipy),
                     ("solve_positive (posv)", solvers.solve_positive)):  # fmt: skip
        print(f"| {label} | {timeit.timeit(lambda f=f: f(M, b), number=n) / n * 1e6:.1f} |")
    if not DATA.is_dir():
        print("\n../shared/data is absent: the Esso recipe is not timed")
        return
    zigzags = sorted(str(p) for p in (DATA / "zigzag").glob("*.csv"))
    randoms = sorted(str(p) for p in (DATA / "random").glob("*.csv") if README_HELD not in p.name)
    fast = solvers.solve_positive
    times: dict[str, list[float]] = {"scipy": [], "posv": []}
    with tempfile.TemporaryDirectory() as scratch:
        def once(f, out):
            solvers.solve_positive = f
            argv = ["select", "--format", "osaka-frt", "--dt", "0.5", "--quiet", "--average",
                    "--library", "low-speed+wind+propeller-asymmetry", *zigzags, *randoms,
                    "-o", out]  # fmt: skip
            with contextlib.redirect_stdout(io.StringIO()), \
                    contextlib.redirect_stderr(io.StringIO()):  # fmt: skip
                start = time.perf_counter()
                code = main(argv)
                elapsed = time.perf_counter() - start
            assert code == 0
            return elapsed

        once(fast, f"{scratch}/warm.json")
        for _ in range(ROUNDS):
            times["scipy"].append(once(_scipy, f"{scratch}/scipy.json"))
            times["posv"].append(once(fast, f"{scratch}/posv.json"))
        with open(f"{scratch}/scipy.json", "rb") as a, open(f"{scratch}/posv.json", "rb") as b_:
            same = a.read() == b_.read()
    solvers.solve_positive = fast
    print(f"\nselect --average on the Esso's 12 files, warm, {ROUNDS} rounds alternated (the two "
          f"model files {'the same bytes' if same else 'differ'}):\n")
    print("| solve | select (s), each round | median | fastest |")
    print("|---|---|---|---|")
    for label, key in (("scipy.linalg.solve", "scipy"), ("solve_positive", "posv")):
        print(f"| {label} | " + ", ".join(f"{t:.3f}" for t in times[key])
              + f" | {np.median(times[key]):.3f} | {min(times[key]):.3f} |")


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    main_()

"""A 200-trial Monte Carlo study (issue #13 item 6): in this process, on a local Dask cluster
of 1 and of 2 worker processes, and, as the simple alternative on one machine, on a standard
library process pool of 2. Wall times include starting the processes (each imports shipid and
loads the compiled kernels once: the first trial of each process is slower); the trial-time
column is the sum of the trials' own times (the work, wherever it ran).

Run: .venv/bin/python benchmarks/bench_study.py [SEEDS]
"""

from __future__ import annotations

import os
import sys
import time

import pandas as pd

from shipid.evaluation.study import StudySpec, run_study, run_trial


def process_pool(spec: StudySpec, processes: int) -> pd.DataFrame:
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor

    # spawned, as Dask's workers: fork is unsafe once numba's OpenMP threads exist
    with ProcessPoolExecutor(processes, mp_context=multiprocessing.get_context("spawn")) as pool:
        rows = list(pool.map(run_trial, spec.trials()))
    return pd.DataFrame(rows).drop(columns="index")


def main(seeds: int = 200) -> None:
    spec = StudySpec(seeds=tuple(range(seeds)))  # the default grid point: prefilter auto
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; {seeds} trials "
          "(the paper's experiment, prefilter chosen from the data)\n")  # fmt: skip
    runs = {}
    for label, scheduler, workers in (("serial (this process, no Dask)", "serial", None),
                                      ("Dask LocalCluster, 1 worker", None, 1),
                                      ("Dask LocalCluster, 2 workers", None, 2)):  # fmt: skip
        t0 = time.perf_counter()
        runs[label] = (run_study(spec, scheduler, workers, progress=False),
                       time.perf_counter() - t0)  # fmt: skip
    t0 = time.perf_counter()
    runs["process pool of 2 (concurrent.futures)"] = (process_pool(spec, 2),
                                                       time.perf_counter() - t0)  # fmt: skip
    base = runs["Dask LocalCluster, 1 worker"][1]
    serial = runs["serial (this process, no Dask)"][1]
    print("| run | wall [s] | trial time [s] | speed-up vs 1 Dask worker | vs serial |")
    print("|---|---|---|---|---|")
    for label, (res, wall) in runs.items():
        print(f"| {label} | {wall:.1f} | {res['seconds'].sum():.1f} | {base / wall:.2f}× | "
              f"{serial / wall:.2f}× |")
    ref = runs["serial (this process, no Dask)"][0].drop(columns="seconds")
    same = all(r.drop(columns="seconds").equals(ref) for r, _ in runs.values())
    print(f"\nResults identical to the serial run: {same}")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:2]))

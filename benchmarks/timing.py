"""Timing shared by the benchmark scripts (run as scripts: this folder is on their path)."""

from __future__ import annotations

import time


def best_of(fn, repeats: int = 3) -> float:
    """The fastest of ``repeats`` wall-clock runs of ``fn()`` [s] (the least disturbed one)."""
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return min(times)

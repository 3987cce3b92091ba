"""One Esso Osaka zig-zag file's fit made otherwise (issue #10): output-error refinement on
whole logs and on segments (multiple shooting, each segment from its measured state), other
γ, and ridge, each judged as ``study_crossflow.esso`` judges one file's fit (the other
zig-zags and the two 35° turns, the turns' closed-loop indices, the random runs).

Run: .venv/bin/python benchmarks/study_esso_one_file_options.py
"""

from __future__ import annotations

import os
import time
import warnings

from study_crossflow import esso

OPTIONS = {"default": [],
           "output-error refinement, whole logs": ["--refine"],
           "the same on 10 s segments": ["--refine", "--segment", "10"],
           "the same on 30 s segments": ["--refine", "--segment", "30"],
           "--gamma auto": ["--gamma", "auto"],
           "--gamma 100": ["--gamma", "100"],
           "--gamma 10": ["--gamma", "10"],
           "--estimator ridge": ["--estimator", "ridge"]}  # fmt: skip

if __name__ == "__main__":
    warnings.simplefilter("ignore")
    start = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    esso(False, OPTIONS)
    print(f"\n{time.perf_counter() - start:.0f} s")

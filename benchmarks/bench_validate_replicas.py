"""What the closed loop's finer steps cost ``validate`` (``shipid.evaluation.validate
.replica_step``): the README's Esso Osaka recipe (``select --average --bootstrap 100`` on the
nine zig-zags and three random runs at Δk 0.5 s) validated on the two turns and the held-out
random run (``--json``, no figures), each replica of the model and of its 100 replicates stepped
as now against stepped at the log's own 0.5 s (the code before the finer steps, and the
strongest simple alternative: no substeps at all). Alternated rounds in one process, warm.

Run: .venv/bin/python benchmarks/bench_validate_replicas.py
"""

from __future__ import annotations

import contextlib
import io
import os
import statistics
import tempfile
import time

import numpy as np
from esso_logs import DATA, README_HELD

import shipid.evaluation.validate as validate_module
from shipid.cli import main as shipid

ROUNDS = 4
LIBRARY = "low-speed+wind+propeller-asymmetry"


def _quiet(argv: list[str]) -> int:
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        return shipid(argv)


def _at_the_logs_step(log) -> float:
    return float(np.median(np.diff(log["t"].to_numpy())))


def main() -> None:
    if not DATA.is_dir():
        print("../shared/data is absent")
        return
    zigzags = sorted(str(p) for p in (DATA / "zigzag").glob("*.csv"))
    randoms = {p.stem[7:]: str(p) for p in sorted((DATA / "random").glob("*.csv"))}
    turns = sorted(str(p) for p in (DATA / "turning").glob("*.csv"))
    train = zigzags + [p for k, p in randoms.items() if k != README_HELD]
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    with tempfile.TemporaryDirectory() as tmp:
        model = f"{tmp}/esso.json"
        if _quiet(["select", *train, "--format", "osaka-frt", "--library", LIBRARY, "--dt", "0.5",
                   "--quiet", "--average", "--bootstrap", "100", "-o", model]):  # fmt: skip
            raise SystemExit("select failed")
        argv = ["validate", model, *turns, randoms[README_HELD], "--format", "osaka-frt",
                "--dt", "0.5", "--quiet", "--json", f"{tmp}/v.json"]  # fmt: skip
        steps = {"replica_step (now)": validate_module.replica_step,
                 "the log's step (0.5 s)": _at_the_logs_step}
        times: dict[str, list[float]] = {k: [] for k in steps}
        _quiet(argv)  # warm: imports and compiled kernels
        try:
            for _ in range(ROUNDS):
                for name, step in steps.items():
                    validate_module.replica_step = step
                    t0 = time.perf_counter()
                    if _quiet(argv):
                        raise SystemExit("validate failed")
                    times[name].append(time.perf_counter() - t0)
        finally:
            validate_module.replica_step = steps["replica_step (now)"]
    base = statistics.median(times["the log's step (0.5 s)"])
    print("| replicas stepped at | validate (s), median | range | ratio to the log's step |")
    print("|---|---|---|---|")
    for name, ts in times.items():
        print(f"| {name} | {statistics.median(ts):.2f} | {min(ts):.2f}–{max(ts):.2f} | "
              f"{statistics.median(ts) / base:.2f} |")


if __name__ == "__main__":
    main()

"""Issue #10: the Esso Osaka's logs as a user who has them all would train on them.

Every fold trains on the nine zig-zags, one of the two 35° turns and three of the four random
runs, and is judged on the other turn (closed loop, as ``validate`` runs it: tactical diameter,
advance and steady yaw rate against the measured) and on the random run left out (free-run
error std of r and u over the run's own std): eight folds. Two ways to make the model, both by
the command line on the raw files (``--format osaka-frt --dt 0.5``, which cut them as ``shipid
import`` does): a plain ``shipid identify`` (its default structure: ``select`` from its default
library, the candidates averaged) and the README's recipe (``shipid select --library
low-speed+wind+propeller-asymmetry --average``). Run as a script: ``python
benchmarks/study_esso_turn_in_training.py``.
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cli_models import model_by_cli  # noqa: E402
from esso_logs import held_out_files  # noqa: E402

from shipid.evaluation.validate import validate_log  # noqa: E402

FORMAT = ["--format", "osaka-frt", "--dt", "0.5"]
MAKERS = {"identify": ["identify", *FORMAT],
          "select (README)": ["select", *FORMAT, "--library",
                              "low-speed+wind+propeller-asymmetry", "--quiet", "--average"]}
KEYS = ("tactical_diameter", "advance", "steady_yaw_rate")


def main() -> None:
    files = held_out_files()
    if files is None:
        return
    zigzags, turns, randoms, logs = files
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("Trained on the nine zig-zags, one 35° turn and three random runs; judged on the other "
          "turn (closed loop: errors of the tactical diameter, advance, steady yaw rate) and the "
          "random run left out (free-run error std over the run's std)\n")  # fmt: skip
    print("| made by | turn trained on | random run held out | TD | advance | steady r | "
          "random run: r, u | diverged | seconds |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|")
    t0 = time.perf_counter()
    summary: dict[str, list] = {m: [] for m in MAKERS}
    with tempfile.TemporaryDirectory() as scratch:
        for maker, argv in MAKERS.items():
            for turn in turns:
                other = next(t for t in turns if t != turn)
                for held in randoms:
                    train = [*zigzags, turn, *(r for r in randoms if r != held)]
                    t1 = time.perf_counter()
                    model = model_by_cli(argv, [str(p) for p in train], f"{scratch}/m.json")
                    seconds = time.perf_counter() - t1
                    label = f"| {maker} | {turn.stem[5:]} | {held.stem[7:]} |"
                    if model is None:
                        print(f"{label} failed | | | | | | {seconds:.1f} |")
                        continue
                    judged = validate_log(model, logs[other], other.name, start_draws=False)
                    random = validate_log(model, logs[held], held.name, start_draws=False)
                    cl, me = judged.indices.get("closed_loop") or {}, judged.indices["measured"]
                    errors = [100 * (cl[k] / me[k] - 1) if cl.get(k) is not None else np.nan
                              for k in KEYS]  # fmt: skip
                    run = logs[held]
                    ratios = [random.metrics[s]["std"] / float(np.std(run[s])) for s in "ru"]
                    diverged = bool(judged.simulation.diverged or random.simulation.diverged)
                    summary[maker].append((errors, ratios, diverged))
                    print(f"{label} " + " | ".join(f"{e:+.0f} %" for e in errors)
                          + f" | {ratios[0]:.2f}, {ratios[1]:.2f} | {'yes' if diverged else 'no'}"
                          f" | {seconds:.1f} |")  # fmt: skip
    print("\nMean over the folds: |error| of the held-out turn's indices, the random runs' r and "
          "u error over their std, runs diverged\n")  # fmt: skip
    print("| made by | folds | TD | advance | steady r | random runs: r, u | diverged |")
    print("|---|---|---|---|---|---|---|")
    for maker, rows in summary.items():
        if not rows:
            continue
        err = np.abs(np.array([r[0] for r in rows]))
        rat = np.array([r[1] for r in rows])
        print(f"| {maker} | {len(rows)} | "
              + " | ".join(f"{np.nanmean(err[:, i]):.1f} %" for i in range(len(KEYS)))
              + f" | {rat[:, 0].mean():.2f}, {rat[:, 1].mean():.2f} | "
              f"{sum(r[2] for r in rows)} of {len(rows)} |")  # fmt: skip
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()

"""The rudder's normal force of one inflow (``--rudder-normal``, issue #10) on the Esso Osaka: the
default ``shipid identify`` with and without it, trained on every pair of zig-zag files and on
the nine, judged on what they were not fitted to: the two 35° turns (closed loop, as ``validate``
runs them: tactical diameter and steady yaw rate against the measured) and the four random runs
(free-run yaw-rate error std over the run's own std). The particulars are the Esso files' own
(``shipid.data.formats.ESSO_OSAKA_MODEL``: no rudder height, so η = 0.7).

Run: .venv/bin/python benchmarks/study_esso_rudder_normal.py
"""

from __future__ import annotations

import itertools
import os
import tempfile
import time
import warnings

import numpy as np
from cli_models import model_by_cli
from esso_logs import held_out_files

from shipid.evaluation.validate import validate_log

FORMAT = ["--format", "osaka-frt", "--dt", "0.5"]
MAKERS = {"identify": ["identify", *FORMAT],
          "identify --rudder-normal": ["identify", *FORMAT, "--rudder-normal"]}  # fmt: skip
KEYS = ("tactical_diameter", "steady_yaw_rate")


def _judged(model, turns, randoms, logs) -> tuple[list[float], list[float], bool]:
    """(the turns' TD and steady r errors [%], the random runs' r error / std, any diverged)."""
    errors, diverged = [], False
    for path in turns:
        run = validate_log(model, logs[path], path.name, start_draws=False)
        closed, measured = run.indices.get("closed_loop") or {}, run.indices["measured"]
        errors += [100 * (closed[k] / measured[k] - 1) if closed.get(k) is not None else np.nan
                   for k in KEYS]  # fmt: skip
        diverged |= bool(run.simulation.diverged)
    ratios = []
    for path in randoms:
        run = validate_log(model, logs[path], path.name, start_draws=False)
        ratios.append(run.metrics["r"]["std"] / float(np.std(logs[path]["r"])))
        diverged |= bool(run.simulation.diverged)
    return errors, ratios, diverged


def main() -> None:
    files = held_out_files()
    if files is None:
        return
    zigzags, turns, randoms, logs = files
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    trainings = {"nine zig-zags": [list(zigzags)],
                 "two zig-zag files (36 pairs)": [list(p) for p in
                                                  itertools.combinations(zigzags, 2)]}
    print("| trained on | made by | 35° turns' TD off: median, mean |abs| [%] | steady r off: "
          "median, mean |abs| [%] | random runs' r error / std: median, mean | diverged | "
          "seconds |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as scratch:
        for label, sets in trainings.items():
            for maker, argv in MAKERS.items():
                td, r, rand, diverged, failed, seconds = [], [], [], 0, 0, 0.0
                for train in sets:
                    t1 = time.perf_counter()
                    model = model_by_cli(argv, [str(p) for p in train], f"{scratch}/m.json")
                    seconds += time.perf_counter() - t1
                    if model is None:
                        failed += 1
                        continue
                    errors, ratios, div = _judged(model, turns, randoms, logs)
                    td += errors[0::2]
                    r += errors[1::2]
                    rand += ratios
                    diverged += div
                cells = [f"{np.nanmedian(x):+.0f}, {np.nanmean(np.abs(x)):.0f}"
                         for x in (np.array(td), np.array(r))]  # fmt: skip
                cells.append(f"{np.median(rand):.2f}, {np.mean(rand):.2f}")
                note = f" ({failed} failed)" if failed else ""
                print(f"| {label} | {maker} | " + " | ".join(cells)
                      + f" | {diverged} of {len(sets)}{note} | {seconds / len(sets):.1f} |")
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    main()

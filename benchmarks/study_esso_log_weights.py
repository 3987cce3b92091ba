"""Each log weighed alike: the README's recipe with every training log given the same weight in
the fit instead of each sample (issue #10).

The README's recipe trains on the nine zig-zags (about 150 samples each at Δk 0.5 s) and three
random runs (1250–2100 each): the random runs hold three quarters of the equations. Weighed per
log instead (each log's normal equations scaled by the mean log's length over its own), the
zig-zags count as much as the runs. ``select --average`` on the library of the README, each random
run held out in turn with the two 35° turns (as ``study_esso.py``), by samples (the default) and
by logs.

Not an option of the library: the study scales the per-log normal equations ``select`` sums for
its folds and its averaged model, in this process.

Run: .venv/bin/python benchmarks/study_esso_log_weights.py
"""

from __future__ import annotations

import os
import time
import warnings

import numpy as np
from esso_logs import esso_logs
from study_esso import TURN_KEYS, judged_fold

import shipid.identification.select as select_module

LIBRARY = "low-speed+wind+propeller-asymmetry"
PER_LOG = {"on": False}
_by_samples = select_module._Data.fold_sums


def _by_logs(self, train):
    """``_Data.fold_sums`` with each log's sums scaled by the mean log's weight over its own."""
    if not PER_LOG["on"]:
        return _by_samples(self, train)
    train = list(train)
    last = self.gram[0].shape[0] - 1
    n = np.array([self.gram[j][last, last] for j in train])
    weights = n.sum() / (len(train) * n)
    gram = sum(w * self.gram[j] for w, j in zip(weights, train, strict=True))
    cross = {d: sum(w * self.cross[j][d] for w, j in zip(weights, train, strict=True))
             for d in self.cross[0]}  # fmt: skip
    return gram, cross


def main() -> None:
    data = esso_logs()
    if data is None:
        return
    zz, randoms, turns = data
    zigzags = list(zz.values())
    select_module._Data.fold_sums = _by_logs
    t0 = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| weighed by | held-out random run | TD +35°, −35° | steady r +35°, −35° | advance "
          "+35°, −35° | random run: r error / spread | u error / spread |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    summary = {}
    for per_log in (False, True):
        PER_LOG["on"] = per_log
        how = "logs" if per_log else "samples (default)"
        rows = []
        for held, random in randoms.items():
            train = zigzags + [x for k, x in randoms.items() if k != held]
            _, _, errors, *ratios = judged_fold(train, random, turns, LIBRARY, True)
            rows.append((errors, *ratios))
            print(f"| {how} | {held} | "
                  + " | ".join(", ".join(f"{x:+.0f} %" for x in errors[k]) for k in TURN_KEYS)
                  + f" | {ratios[0]:.2f} | {ratios[1]:.2f} |", flush=True)  # fmt: skip
        summary[how] = rows
    print("\nMean over the four folds: |error| of the turns' tactical diameters, steady yaw rates "
          "and advances; the random runs' r and u error over their spread\n")  # fmt: skip
    print("| weighed by | TD | steady r | advance | r / spread | u / spread |")
    print("|---|---|---|---|---|---|")
    for how, rows in summary.items():
        mean = {k: np.mean([abs(x) for r in rows for x in r[0][k]]) for k in TURN_KEYS}
        print(f"| {how} | {mean['tactical_diameter']:.1f} % | {mean['steady_yaw_rate']:.1f} % | "
              f"{mean['advance']:.1f} % | {np.mean([r[1] for r in rows]):.2f} | "
              f"{np.mean([r[2] for r in rows]):.2f} |")  # fmt: skip
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    main()

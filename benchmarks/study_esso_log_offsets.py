"""Each log's own constant force: the Esso Osaka's zig-zag files as fixed effects (issue #10).

The files were run on different days and hours of an outdoor pond (wind, current, trim, a gyro's
offset), which a single constant per equation cannot follow. Here each log keeps its own constant
in every equation of the fit (the within-log estimator of a linear model: each log's regressors
and targets moved to the pooled means), and the model keeps their weighted mean, which is all a
log it never saw can be given. The default ``identify`` (Δk 0.5 s) on the nine zig-zag files and
on each eight of them, as ``study_esso_eight_files.py`` judges it: the two 35° turns (closed loop)
and the four random runs (free run, the yaw rate's error std over its std), with the pooled
constant (the default) and with the logs' own.

Not an option of the library: the study swaps the pooled normal equations of ``select``'s folds
and the regression problems of ``identify`` for their within-log forms in this process.

Run: .venv/bin/python benchmarks/study_esso_log_offsets.py
"""

from __future__ import annotations

import os
import tempfile
import time
import warnings

import numpy as np
from cli_models import model_by_cli
from esso_logs import held_out_files
from study_esso_rudder_normal import FORMAT
from study_esso_side_constant import _judged

import shipid.identification.identify as identify_module
import shipid.identification.select as select_module
from shipid.identification.regression import regression_problem

OWN = {"on": False}
_pooled_sums = select_module._Data.fold_sums


def _within_sums(self, train):
    """``_Data.fold_sums`` of the logs ``train`` with each log's mean moved to the pooled one:
    Σ Gⱼ − Σ nⱼμⱼμⱼᵀ + Nμ̄μ̄ᵀ (and the same for the targets), whose bordered solve gives the
    within-log coefficients and the bias ȳ − μ̄ᵀw."""
    gram, cross = _pooled_sums(self, train)
    if not OWN["on"]:
        return gram, cross
    gram, cross = gram.copy(), {d: c.copy() for d, c in cross.items()}
    last = gram.shape[0] - 1
    total, sums = gram[last, last], gram[:last, last].copy()
    gram[:last, :last] += np.outer(sums, sums) / total
    for d in cross:
        cross[d][:last] += sums * cross[d][last] / total
    for j in train:
        n, m = self.gram[j][last, last], self.gram[j][:last, last]
        gram[:last, :last] -= np.outer(m, m) / n
        for d in cross:
            cross[d][:last] -= m * self.cross[j][d][last] / n
    return gram, cross


def _within_problem(logs, structure, dof, form="increment", fixed=None, names=None, known=None):
    """``regression_problem`` with each log's rows moved to the pooled means."""
    p = regression_problem(logs, structure, dof, form, fixed, names, known)
    if not OWN["on"] or len(logs) < 2 or form != "increment":
        return p
    X, y = p.X.copy(), p.y.copy()
    means, mean_y, start = X.mean(axis=0), y.mean(), 0
    for log in logs:
        rows = slice(start, start + len(log) - 1)
        X[rows] += means - X[rows].mean(axis=0)
        y[rows] += mean_y - y[rows].mean()
        start += len(log) - 1
    p.X, p.y = X, y
    return p


def main() -> None:
    files = held_out_files()
    if files is None:
        return
    zigzags, turns, randoms, logs = files
    select_module._Data.fold_sums = _within_sums
    identify_module.regression_problem = _within_problem
    t0 = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| left out | constant | 35° TD off, stbd, port [%] | steady r off, stbd, port [%] | "
          "random runs' r error std / r std (mean) |")  # fmt: skip
    print("|---|---|---|---|---|")
    summary: dict[str, dict[str, list[float]]] = {}
    with tempfile.TemporaryDirectory() as scratch:
        for left in [None, *zigzags]:
            kept = [str(p) for p in zigzags if p != left]
            label = "none" if left is None else left.stem[-8:]
            for own in (False, True):
                OWN["on"] = own
                how = "each log's own" if own else "pooled (default)"
                model = model_by_cli(["identify", *FORMAT], kept, f"{scratch}/m.json")
                if model is None:
                    print(f"| {label} | {how} | failed | | |")
                    continue
                errors, ratios = _judged(model, turns, randoms, logs)
                std = [a for a, _ in ratios]
                if left is not None:
                    row = summary.setdefault(how, {"td": [], "r": [], "std": []})
                    row["td"] += [abs(x) for x in errors[0::2]]
                    row["r"] += [abs(x) for x in errors[1::2]]
                    row["std"].append(float(np.mean(std)))
                print(f"| {label} | {how} | " + ", ".join(f"{x:+.0f}" for x in errors[0::2])
                      + " | " + ", ".join(f"{x:+.0f}" for x in errors[1::2]) + " | "
                      + ", ".join(f"{x:.2f}" for x in std) + f" ({np.mean(std):.2f}) |",
                      flush=True)  # fmt: skip
    print("\nThe nine sets of eight: |error| median (largest) of the 35° turns' tactical diameters "
          "and steady yaw rates; the random runs' mean over the four, median (range) over the "
          "sets\n")  # fmt: skip
    print("| constant | 35° TD off [%] | steady r off [%] | r error std / r std |")
    print("|---|---|---|---|")
    for how, row in summary.items():
        print(f"| {how} | {np.median(row['td']):.0f} ({np.max(row['td']):.0f}) | "
              f"{np.median(row['r']):.0f} ({np.max(row['r']):.0f}) | "
              f"{np.median(row['std']):.2f} ({np.min(row['std']):.2f}–{np.max(row['std']):.2f}) |")
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    main()

"""Identifiability study on the paper's ship (issue #10): over seeds of the demo's noisy trials,
how well the default identification (prefilter chosen from the data) predicts the held-out
manoeuvres against the true model's own error, and how often the bootstrap's 95 % intervals
cover the true coefficients.

Run: .venv/bin/python benchmarks/study_uncertainty.py [SEEDS] [REPLICATES]
"""

from __future__ import annotations

import os
import sys
import time

import numpy as np

from shipid.data.preprocess import lowpass
from shipid.demo import GAMMA, PAPER_TABLE, TRAINING, synthesise_trials
from shipid.evaluation.validate import validate
from shipid.identification.identify import identify
from shipid.identification.prefilter import choose_prefilter
from shipid.identification.uncertainty import bootstrap
from shipid.vessels import scale_ship_model

DROP = {"u": ["r^2"]}


def fit(logs):
    return identify(logs, gamma=GAMMA, drop=DROP).model


def main(seeds: int = 20, replicates: int = 100) -> None:
    truth = scale_ship_model()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; {seeds} seeds, "
          f"{replicates} bootstrap replicates each\n")  # fmt: skip
    t0 = time.perf_counter()
    ratios, beats, covered, wrong_sign_outside, widths = [], [], [], 0, []
    cutoffs = []
    for seed in range(seeds):
        logs = synthesise_trials(seed)
        cutoff, _ = choose_prefilter([logs[TRAINING]], fit)
        cutoffs.append(cutoff)
        train = logs[TRAINING] if cutoff is None else lowpass(logs[TRAINING], cutoff)
        model = fit([train])
        held = [k for k in logs if k != TRAINING]
        ours = validate(model, [logs[k] for k in held], held)
        true = validate(truth, [logs[k] for k in held], held)
        ratios.append([[a.metrics[s]["std"] / b.metrics[s]["std"] for s in "uvr"]
                       for a, b in zip(ours, true, strict=True)])  # fmt: skip
        beats.append([all(v.metrics[s]["std"] <= p for s, p in zip("uvr", PAPER_TABLE[v.name],
                                                                   strict=True)) for v in ours])
        ens = bootstrap([train], lambda w, t=train: identify(t, gamma=GAMMA, drop=DROP,
                                                             sample_weight=w).model,
                        replicates=replicates, seed=seed)  # fmt: skip
        table = ens.coefficient_table()
        for _, row in table.iterrows():
            if row["term"] == "r^2":
                continue
            true_value = truth.coefficients[row["equation"]][row["term"]]
            inside = row["lower"] <= true_value <= row["upper"]
            covered.append(inside)
            widths.append(row["upper"] - row["lower"])
            if not inside and np.sign(row["value"]) != np.sign(true_value):
                wrong_sign_outside += 1
    ratios = np.array(ratios)
    beats = np.array(beats)
    names = [k for k in synthesise_trials(0) if k != TRAINING]
    print("| held-out manoeuvre | error std / true model's, u v r (median) | (largest) | "
          "seeds beating the paper |")
    print("|---|---|---|---|")
    for i, name in enumerate(names):
        med = " / ".join(f"{x:.2f}" for x in np.median(ratios[:, i], axis=0))
        big = " / ".join(f"{x:.2f}" for x in ratios[:, i].max(axis=0))
        print(f"| {name} | {med} | {big} | {int(beats[:, i].sum())} of {seeds} |")
    print(f"\nPrefilter cut-offs chosen: {sorted({c for c in cutoffs}, key=str)}")
    print(f"95 % bootstrap intervals cover the true coefficient in {np.mean(covered):.0%} of "
          f"{len(covered)} coefficient × seed pairs; wrong sign outside the interval: "
          f"{wrong_sign_outside}")  # fmt: skip
    print(f"time {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:3]))

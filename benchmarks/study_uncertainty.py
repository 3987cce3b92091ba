"""Identifiability study on the paper's ship (issue #10): over seeds of the demo's noisy trials,
the default identification (LS-SVM, prefilter chosen from the data, bootstrap intervals) against
maximum-likelihood output error from it (covariance intervals): how well each predicts the
held-out manoeuvres against the true model's own error, and how often its 95 % intervals cover
the true coefficients. Runs as a ``shipid study`` (``shipid.evaluation.study``).

Run: .venv/bin/python benchmarks/study_uncertainty.py [SEEDS] [REPLICATES]
"""

from __future__ import annotations

import os
import sys
import time

from shipid.evaluation.study import StudySpec, run_study, summary


def main(seeds: int = 40, replicates: int = 100) -> None:
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; {seeds} seeds, "
          f"{replicates} bootstrap replicates for the LS-SVM\n")  # fmt: skip
    t0 = time.perf_counter()
    spec = StudySpec(seeds=tuple(range(seeds)), estimator=("lssvm", "output-error"),
                     bootstrap=replicates)  # fmt: skip
    results = run_study(spec, workers=2, progress=False)
    table = summary(results).drop(columns=["noise", "gamma", "structure", "filter"])
    print(table.set_index("estimator").T.to_markdown())
    from shipid.demo import PAPER_TABLE

    one = results[results["estimator"] == "lssvm"]
    for name in [k for k in PAPER_TABLE if f"{k}: beats paper" in results]:
        truth_beats = sum(all(row[f"{name}: {s} truth error std"] <= p
                              for s, p in zip("uvr", PAPER_TABLE[name], strict=True))
                          for _, row in one.iterrows())  # fmt: skip
        print(f"\nthe true model itself beats the paper on {name} in {truth_beats} of {len(one)}",
              end="")
    print()
    cutoffs = sorted(set(results["cutoff_hz"].round(3)))
    print(f"\nPrefilter cut-offs chosen (LS-SVM and the output-error start): {cutoffs}")
    print(f"time {time.perf_counter() - t0:.1f} s (2 Dask workers)")


if __name__ == "__main__":
    main(*(int(a) for a in sys.argv[1:3]))

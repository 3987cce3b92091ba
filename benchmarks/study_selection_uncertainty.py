"""Do the intervals of a selected model cover what it was not trained on? (issue #10, item 5)

On the Esso Osaka logs, in seven folds (three beyond the training conditions, each random run
held out in turn; ``esso_logs.py``), ``select`` (the README's library) and three ensembles of 100
replicates of its model:

* ``terms held``: the selected terms and γ refitted on moving-block resamples of the equations
  (``bootstrap`` of ``weighted_refit``, 10 s blocks);
* ``terms resampled``: ``select --bootstrap N --block 10``'s ensemble (``selection_ensemble``):
  each replicate draws a candidate by how often the choice rule picks it on resampled held-out
  logs, then refits it on a block resample.
* ``terms and logs resampled``: the same with whole logs resampled instead of blocks
  (``select --bootstrap N``'s default from five logs on, ``--block log``): each replicate draws
  as many training logs as there are, with replacement, so the replicates differ as the logs
  differ from one another.

Judged on the held-out logs: whether the measured tactical diameter and steady yaw rate of each
±35° turn lie in the 95 % intervals of the replay (28 checks in all), and its advance and
transfer (28 more), the intervals' mean width over the prediction, and the share of the
held-out zig-zags' and random runs' samples whose measured r and u lie in the 95 % prediction
bands. A calibrated 95 % interval covers 95 % of them.

Then the cross-validated 95 % error band of each fold's model, the chosen candidate and the
average of ``select --average`` (``Selection.error_band``: the conformal quantile of the
free-run errors of select's leave-one-log-out folds) and the share of the held-out logs' samples
inside it, as ``validate`` reports it.

Run: .venv/bin/python benchmarks/study_selection_uncertainty.py
"""

from __future__ import annotations

import os
import time
import warnings

import numpy as np
from esso_logs import condition_folds, esso_logs, random_run_folds

from shipid.evaluation.validate import validate
from shipid.identification.identify import weighted_refit
from shipid.identification.select import select
from shipid.identification.selection_ensemble import selection_ensemble
from shipid.identification.uncertainty import bootstrap

LIBRARY = "low-speed+wind+propeller-asymmetry"
REPLICATES = 100
KEYS = ("tactical_diameter", "steady_yaw_rate")
EARLY = ("advance", "transfer")  # the first 90° of the turn


def _band_share(v, log, state: str) -> float:
    lo, hi = v.bands[state]
    x = log[state].to_numpy()[: len(lo)]
    return float(np.mean((x >= lo) & (x <= hi)))


def main() -> None:
    data = esso_logs()
    if data is None:
        return
    zz, rnd, turns = data
    folds = {**condition_folds(rnd), **random_run_folds(rnd)}
    folds.pop("README")  # the same fold as "random 31-Jul-2020_12_29_58"
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; library {LIBRARY}; "
          f"{REPLICATES} replicates\n")  # fmt: skip
    print("| fold | chosen share | replicates | turns' TD and steady r in the 95 % interval | "
          "advance and transfer | interval width / prediction (TD, steady r) | held-out samples "
          "in the r, u bands |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    cv_rows = []
    t0 = time.perf_counter()
    totals = {"terms held": [], "terms resampled": [], "terms and logs resampled": []}
    early = {k: [] for k in totals}
    widths = {k: [] for k in totals}
    bands = {k: [] for k in totals}
    for fold, (zk, rk, zig_held, rnd_held) in folds.items():
        train = [zz[k] for k in zk] + [rnd[k] for k in rk]
        held = [zz[k] for k in zig_held] + [rnd[k] for k in rnd_held]
        sel = select(train, library=LIBRARY, cv="logo")
        for label, model_of in (("chosen", sel), ("--average", select(train, library=LIBRARY,
                                                                        average=True))):
            band = model_of.error_band
            cv_rows.append((fold, label, band, [validate(model_of.model, [lg], error_band=band)[0]
                                                .band_shares for lg in held + turns]))  # fmt: skip
        refit = weighted_refit(train, model=sel.model.structure, gamma=sel.gamma)
        ensembles = {"terms held": bootstrap(train, refit, replicates=REPLICATES, block_s=10.0),
                     "terms resampled": selection_ensemble(train, sel, replicates=REPLICATES,
                                                           block_s=10.0),
                     "terms and logs resampled": selection_ensemble(
                         train, sel, replicates=REPLICATES, block_s="log")}  # fmt: skip
        for label, ens in ensembles.items():
            inside, width, first = [], [], []
            for v in validate(sel.model, turns, ensemble=ens):
                meas, pred = v.indices["measured"], v.indices["simulated"]
                for key in KEYS:
                    lo, hi = v.intervals["simulated"][key]
                    inside.append(bool(lo <= meas[key] <= hi))
                    width.append(abs((hi - lo) / pred[key]))
                for key in EARLY:
                    lo, hi = v.intervals["simulated"][key]
                    first.append(bool(lo <= meas[key] <= hi))
            runs = validate(sel.model, held, ensemble=ens) if held else []
            r_share, u_share = (float(np.mean([_band_share(v, lg, s)
                                                for v, lg in zip(runs, held, strict=True)]))
                                if held else float("nan") for s in ("r", "u"))  # fmt: skip
            totals[label] += inside
            early[label] += first
            widths[label] += width
            bands[label].append((r_share, u_share))
            print(f"| {fold} | {100 * sel.chosen_share:.0f} % | {label} | {sum(inside)} of "
                  f"{len(inside)} | {sum(first)} of {len(first)} | {np.mean(width[0::2]):.2f}, "
                  f"{np.mean(width[1::2]):.2f} | "
                  f"{r_share:.2f}, {u_share:.2f} |")  # fmt: skip
    print("\n| replicates | turns' TD and steady r in the 95 % interval | advance and transfer | "
          "mean width / prediction (TD, steady r) | held-out samples in the r, u bands (mean "
          "over folds) |")  # fmt: skip
    print("|---|---|---|---|---|")
    for label, inside in totals.items():
        w = widths[label]
        b = np.array(bands[label])
        e = early[label]
        print(f"| {label} | {sum(inside)} of {len(inside)} ({100 * np.mean(inside):.0f} %) | "
              f"{sum(e)} of {len(e)} ({100 * np.mean(e):.0f} %) | "
              f"{np.mean(w[0::2]):.2f}, {np.mean(w[1::2]):.2f} | {np.mean(b[:, 0]):.2f}, "
              f"{np.mean(b[:, 1]):.2f} |")  # fmt: skip
    print("\nThe cross-validated 95 % error band of each fold's model (select's leave-one-log-"
          "out free runs; ± half-width of r and u) and the share of the held-out logs' samples "
          "inside it\n")  # fmt: skip
    print("| fold | model | band r [rad/s], u [m/s] | held-out zig-zags and random runs: r, u | "
          "turns: r, u |")
    print("|---|---|---|---|---|")
    inside = {(m, k): [] for m in ("chosen", "--average") for k in ("runs", "turns")}
    for fold, label, band, shares in cv_rows:
        runs, turn_shares = shares[:-2], shares[-2:]
        cells = []
        for key, group in (("runs", runs), ("turns", turn_shares)):
            inside[label, key] += group
            cells.append(f"{np.mean([g['r'] for g in group]):.2f}, "
                         f"{np.mean([g['u'] for g in group]):.2f}" if group else "–")
        print(f"| {fold} | {label} | ±{band.half_width['r']:.4f}, ±{band.half_width['u']:.3f} | "
              + " | ".join(cells) + " |")
    for label in ("chosen", "--average"):
        print(f"| all folds | {label} | | " + " | ".join(
            f"{np.mean([g['r'] for g in inside[label, k]]):.2f}, "
            f"{np.mean([g['u'] for g in inside[label, k]]):.2f}" for k in ("runs", "turns")) + " |")
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # envelope and plausibility warnings of the candidates
    main()

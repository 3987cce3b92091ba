"""The Esso Osaka's unseen manoeuvres (issue #10, the principal push): ``select`` on the nine
zig-zags and three of the four random runs, judged on the two ±35° turning circles and the
random run left out, each random run left out in turn; for the README's library, with the
single propeller's asymmetry added (``propeller-asymmetry``), with the hull's astern terms
(``astern``), and each with ``--average``
(the README's recipe: the candidates averaged by how often the choice rule picks them on
resampled held-out logs). For the README's fold (random run 12_29_58 held out), the turns' 95 %
intervals over 100 replicates of the model: its terms refitted on block resamples, and
``select --bootstrap 100``'s ensemble, whose replicates also draw their terms (as ``validate``
gives them).

Run: .venv/bin/python benchmarks/study_esso.py
"""

from __future__ import annotations

import os
import time
import warnings

import numpy as np
from esso_logs import README_HELD, esso_logs

from shipid.evaluation.validate import validate
from shipid.identification.identify import weighted_refit
from shipid.identification.select import select
from shipid.identification.selection_ensemble import selection_ensemble
from shipid.identification.uncertainty import bootstrap
from shipid.trials.trial import describe_trial

# (library, select --average): the README's library before and after the asymmetry terms, and
# the README's recipe, which writes the average of the candidates by their shares.
CONFIGURATIONS = (("low-speed+wind", False), ("low-speed+wind+propeller-asymmetry", False),
                  ("low-speed+wind+propeller-asymmetry", True),
                  ("low-speed+wind+propeller-asymmetry+astern", False),
                  ("low-speed+wind+propeller-asymmetry+astern", True))
TURN_KEYS = ("tactical_diameter", "steady_yaw_rate", "advance")


def judged_fold(train, random, turns, library: str, average: bool):
    """``select`` on ``train`` (leave one log out), judged on the two turns and the held-out
    random run: (the selection, the validations, {turn index: [error of each turn, %]}, the
    run's r and u error std over its spread)."""
    sel = select(train, library=library, cv="logo", average=average)
    results = validate(sel.model, turns + [random])
    errors = {k: [_error(v, k) for v in results[:2]] for k in TURN_KEYS}
    m = results[2].metrics
    return (sel, results, errors, m["r"]["std"] / float(np.std(random["r"])),
            m["u"]["std"] / float(np.std(random["u"])))  # fmt: skip


def _error(v, key: str) -> float:
    meas, pred = v.indices["measured"], v.indices["simulated"]
    return 100 * (pred[key] / meas[key] - 1)


def _early_yaw_ratio(v, log, after_s: float = 10.0) -> float:
    """Measured over simulated yaw rate ``after_s`` after the rudder execute: how much faster
    the ship answers the rudder than the model."""
    t = log["t"].to_numpy()
    i = int(np.searchsorted(t, describe_trial(log, "turning").execute_time + after_s))
    return float(log["r"].iloc[i] / v.simulation.log["r"].iloc[i])


def main() -> None:
    data = esso_logs()
    if data is None:
        return
    zz, randoms, turns = data
    zigzags = list(zz.values())
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("Held out: the ±35° turns (errors of the tactical diameter, steady yaw rate and "
          "advance) and one random run (free-run r and u error std over the run's spread); "
          "select on the nine zig-zags and the other three random runs\n")  # fmt: skip
    print("| library | held-out random run | terms | TD +35°, −35° | steady r +35°, −35° | "
          "advance +35°, −35° | random run: r error / spread | u error / spread |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    t0 = time.perf_counter()
    summary, readme = {}, {}
    for library, average in CONFIGURATIONS:
        label = library + (" --average" if average else "")
        rows = []
        for held, random in randoms.items():
            train = zigzags + [x for k, x in randoms.items() if k != held]
            sel, results, errors, r_ratio, u_ratio = judged_fold(train, random, turns, library,
                                                                 average)  # fmt: skip
            early = [_early_yaw_ratio(v, lg) for v, lg in zip(results[:2], turns, strict=True)]
            rows.append((errors, r_ratio, u_ratio, early))
            n_terms = sum(len(t) for t in sel.model.structure.terms.values())
            print(f"| {label} | {held} | {n_terms} | "
                  + " | ".join(", ".join(f"{x:+.0f} %" for x in errors[k]) for k in TURN_KEYS)
                  + f" | {r_ratio:.2f} | {u_ratio:.2f} |")  # fmt: skip
            if held == README_HELD:
                readme[label] = (train, sel, results, average)
        summary[label] = rows
    print("\nMean over the four folds: |TD error|, |steady r error|, advance error of each turn, "
          "r and u error / spread, and the measured yaw rate 10 s after the execute over the "
          "model's (each turn)\n")  # fmt: skip
    print("| library | TD | steady r | advance +35°, −35° | r / spread | u / spread | "
          "yaw rate at 10 s, measured / model, +35°, −35° |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    for library, rows in summary.items():
        td = np.mean([abs(x) for r in rows for x in r[0]["tactical_diameter"]])
        yr = np.mean([abs(x) for r in rows for x in r[0]["steady_yaw_rate"]])
        adv = [[r[0]["advance"][i] for r in rows] for i in range(2)]
        early = [[r[3][i] for r in rows] for i in range(2)]
        print(f"| {library} | {td:.1f} % | {yr:.1f} % | "
              + ", ".join(f"{min(a):+.0f}…{max(a):+.0f} %" for a in adv)
              + f" | {np.mean([r[1] for r in rows]):.2f} | {np.mean([r[2] for r in rows]):.2f} | "
              + ", ".join(f"{min(e):.2f}…{max(e):.2f}" for e in early) + " |")  # fmt: skip
    print(f"\nThe README's fold ({README_HELD} held out): the turns' indices with the 95 % "
          "intervals of 100 replicates: the selected terms refitted on 10 s block resamples (terms "
          "held), and select --bootstrap 100 --block 10's ensemble, whose replicates also draw "
          "their terms from the choices on resampled held-out logs (terms resampled)\n")  # fmt: skip
    print("| library | replicates | turn | tactical diameter: measured, predicted [95 %] | "
          "steady yaw rate: measured, predicted [95 %] |")  # fmt: skip
    print("|---|---|---|---|---|")
    for library, (train, sel, results, average) in readme.items():
        # The average has no terms of its own to hold: its replicates are the resampled ones.
        # 10 s blocks, as select --bootstrap resampled before it drew whole logs from 5 logs on
        # (study_selection_uncertainty.py compares the two).
        ensembles = {} if average else {"terms held": bootstrap(
            train, weighted_refit(train, model=sel.model.structure, gamma=sel.gamma), 100,
            block_s=10.0)}
        ensembles["terms resampled"] = selection_ensemble(train, sel, replicates=100,
                                                          block_s=10.0)
        for label, ens in ensembles.items():
            for v, turn, side in zip(results[:2], turns, ("+35°", "−35°"), strict=True):
                again = validate(sel.model, [turn], ensemble=ens)[0]
                cells = []
                for key, fmt in (("tactical_diameter", ".2f"), ("steady_yaw_rate", ".4f")):
                    lo, hi = again.intervals["simulated"][key]
                    cells.append(f"{v.indices['measured'][key]:{fmt}}, "
                                 f"{v.indices['simulated'][key]:{fmt}} [{lo:{fmt}}, {hi:{fmt}}]")
                print(f"| {library} | {label} | {side} | " + " | ".join(cells) + " |")
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # envelope and plausibility warnings of the candidates
    main()

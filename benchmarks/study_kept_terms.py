"""Terms kept in every candidate (``select --keep``, issue #10): does holding the hull's linear
sway and yaw derivatives, which zig-zags alone may not tell from the other terms, predict the
logs a selection was not fitted to better? ``select`` with and without them on the same folds:

* Esso Osaka, the README's library at Δk 0.5 s: the three folds beyond the training conditions
  of ``study_esso_extrapolation.py`` and each random run held out in turn (the README's fold
  among them); and the nine zig-zags
  alone at their own 0.1 s with the default library (as ``shipid identify`` searches them);
  judged on the two ±35° turns (tactical diameter, advance and steady yaw rate as the log's
  rudder replays them) and the held-out zig-zags and random runs (free-run error over spread).
* KVLCC2, ``blanke-speed+abkowitz3`` at Δk 0.2 s: each of the three real zig-zags held out,
  trained on the other two, and trained on each one alone (four blocks) judged on the other two.

Columns: the CV score of the chosen candidate (its own folds), the turns' errors, and the mean
free-run error over the held-out logs' spread (r / v / u) or their error std.

Run: .venv/bin/python benchmarks/study_kept_terms.py
"""

from __future__ import annotations

import os
import time
import warnings
from pathlib import Path

import numpy as np
from esso_logs import condition_folds, esso_logs, random_run_folds
from kvlcc2_logs import kvlcc2_logs

from shipid.evaluation.validate import validate
from shipid.identification.select import select

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
ESSO_LIBRARY = "low-speed+wind+propeller-asymmetry"
ESSO_KEEP = "v: u*v, |u|*r; r: u*v, |u|*r"  # the library's own forms of Yv, Yr, Nv, Nr
KVLCC2_LIBRARY = "blanke-speed+abkowitz3"
KVLCC2_KEEP = "v: u*v, u*r; r: u*v, u*r"


def _over_spread(results, logs) -> str:
    if not logs:
        return "–"
    ratios = [[v.metrics[s]["std"] / float(np.std(log[s])) for s in "rvu"]
              for v, log in zip(results, logs, strict=True)]  # fmt: skip
    r, v, u = np.mean(ratios, axis=0)
    return f"{r:.2f} / {v:.2f} / {u:.2f}"


def _turns(results) -> str:
    cells = []
    for key in ("tactical_diameter", "advance", "steady_yaw_rate"):
        errs = [100 * (x.indices["simulated"][key] / x.indices["measured"][key] - 1)
                for x in results]  # fmt: skip
        cells.append(", ".join(f"{e:+.0f} %" for e in errs))
    return " | ".join(cells)


def esso() -> None:
    data = esso_logs()
    if data is None:
        return
    zz, rnd, turns = data
    print("Esso Osaka: TD, advance, steady r of the +35° and −35° turns; held-out zig-zags and "
          "random runs: mean free-run error over spread, r / v / u\n")  # fmt: skip
    print("| fold | kept | terms | CV score | TD | advance | steady r | held-out zig-zags | "
          "held-out random runs |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|")
    # The README's fold by condition is the random run 12_29_58's: once.
    folds = {**{k: f for k, f in condition_folds(rnd).items() if k != "README"},
             **random_run_folds(rnd)}
    runs = [(name, fold, ESSO_LIBRARY, zz, rnd, turns) for name, fold in folds.items()]
    own = esso_logs(dt=None)
    runs.append(("zig-zags only, Δk 0.1 s, default library", (list(zz), [], [], list(rnd)), None,
                 own[0], own[1], own[2]))  # fmt: skip
    for name, (zz_train, rnd_train, zz_held, rnd_held), library, zzs, rnds, trn in runs:
        train = [zzs[k] for k in zz_train] + [rnds[k] for k in rnd_train]
        held_zz, held_rnd = [zzs[k] for k in zz_held], [rnds[k] for k in rnd_held]
        for keep in (None, ESSO_KEEP):
            sel = select(train, library=library, keep=keep)
            results = validate(sel.model, trn + held_zz + held_rnd)
            n_terms = sum(len(t) for t in sel.model.structure.terms.values())
            print(f"| {name} | {'yes' if keep else 'no'} | {n_terms} | {sel.score:.3f} | "
                  f"{_turns(results[:2])} | {_over_spread(results[2:2 + len(held_zz)], held_zz)} "
                  f"| {_over_spread(results[2 + len(held_zz):], held_rnd)} |")  # fmt: skip


def kvlcc2() -> None:
    logs = kvlcc2_logs()
    print(f"\nKVLCC2, {KVLCC2_LIBRARY}: held-out logs' free-run error std u / v / r and "
          "closed-loop overshoots (measured)\n")  # fmt: skip
    print("| trained on | held out | kept | terms | CV score | u / v / r error std | overshoots "
          "(measured) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    folds = [([k for k in logs if k != h], [h]) for h in logs]
    folds += [([k], [h for h in logs if h != k]) for k in logs]
    for train, held in folds:
        cv = "blocks:4" if len(train) == 1 else "logo"
        for keep in (None, KVLCC2_KEEP):
            sel = select([logs[k] for k in train], library=KVLCC2_LIBRARY, keep=keep, cv=cv)
            n_terms = sum(len(t) for t in sel.model.structure.terms.values())
            for h, v in zip(held, validate(sel.model, [logs[h] for h in held]), strict=True):
                m, closed, meas = v.metrics, v.indices["closed_loop"], v.indices["measured"]
                print(f"| {', '.join(train)} | {h} | {'yes' if keep else 'no'} | {n_terms} | "
                      f"{sel.score:.3f} | {m['u']['std']:.4f} / {m['v']['std']:.4f} / "
                      f"{m['r']['std']:.4f} | {closed['first_overshoot_deg']:.1f}°, "
                      f"{closed['second_overshoot_deg']:.1f}° ({meas['first_overshoot_deg']:.1f}°, "
                      f"{meas['second_overshoot_deg']:.1f}°) |")  # fmt: skip


def main() -> None:
    if not DATA.is_dir():
        print("../shared/data is absent")
        return
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    t0 = time.perf_counter()
    esso()
    kvlcc2()
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # envelope and plausibility warnings of the candidates
    main()

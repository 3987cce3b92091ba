"""How far the README's Esso recipe carries beyond its training conditions (issue #10).

``study_esso.py`` holds out the turns and one random run from a training set that covers every
zig-zag amplitude and propeller speed. Unseen trials of a real ship are often further away: a
larger rudder, another rps, or zig-zags only to learn from. Each fold below trains ``select``
(``low-speed+wind+propeller-asymmetry``, leave-one-log-out) on a subset chosen by condition and
judges it on what it left out, for the three searches of ``select`` and for the README's recipe
(stepwise with ``--average``):

* ``30° zig-zags``: trained on the 15° and 20° zig-zags and the four random runs; held out the
  three 30° zig-zags and the two ±35° turns (rudder amplitude extrapolation);
* ``15-16.7 rps``: trained on the zig-zags at 10 and 12 rps and the random runs; held out the
  three zig-zags at 15 and 16.7 rps and the turns (propeller speed extrapolation);
* ``zig-zags only``: trained on the nine zig-zags; held out the four random runs (astern,
  propeller reversal) and the turns;
* ``README``: the README's fold (nine zig-zags and three random runs; turns and 12_29_58 out).

Columns: free-run r error std over the held-out log's spread of r (mean over the held-out
zig-zags or random runs; 1 ≈ predicting the mean), the same for u, and the turns' tactical
diameter and steady yaw rate errors (+35°, −35°). The Esso zig-zags were switched by hand at
irregular headings, so their overshoots are not compared.

Run: .venv/bin/python benchmarks/study_esso_extrapolation.py [LIBRARY]
"""

from __future__ import annotations

import os
import sys
import time
import warnings

import numpy as np
from esso_logs import condition_folds, esso_logs

from shipid.evaluation.validate import validate
from shipid.identification.select import select

LIBRARY = sys.argv[1] if len(sys.argv) > 1 else "low-speed+wind+propeller-asymmetry"
# (search, --average): each search of select, and the README's recipe (stepwise, averaged).
CONFIGURATIONS = (("stepwise", False), ("stepwise", True), ("frols", False), ("none", False))


def _ratio(validations, logs, state: str) -> float:
    """Mean over the logs of the free-run error std of ``state`` over its spread."""
    return float(np.mean([v.metrics[state]["std"] / np.std(lg[state])
                          for v, lg in zip(validations, logs, strict=True)]))  # fmt: skip


def main() -> None:
    data = esso_logs()
    if data is None:
        return
    zz, rnd, turns = data
    folds = condition_folds(rnd)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; library {LIBRARY}\n")
    print("| fold | search | terms | held-out zig-zags r / u error over spread | held-out random "
          "runs r / u | turns: TD +35°, −35° | steady r +35°, −35° | diverged |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    t0 = time.perf_counter()
    for fold, (zk, rk, zig_held, rnd_held) in folds.items():
        train = [zz[k] for k in zk] + [rnd[k] for k in rk]
        held = [zz[k] for k in zig_held] + [rnd[k] for k in rnd_held] + turns
        for search, average in CONFIGURATIONS:
            sel = select(train, library=LIBRARY, cv="logo", search=search, average=average)
            res = validate(sel.model, held)
            diverged = sum(v.error is not None or v.simulation.diverged for v in res)

            n_zz = len(zig_held)
            cells = []
            for a, b in ((0, n_zz), (n_zz, n_zz + len(rnd_held))):
                vs, logs = res[a:b], held[a:b]
                cells.append(f"{_ratio(vs, logs, 'r'):.2f} / {_ratio(vs, logs, 'u'):.2f}"
                             if vs else "–")  # fmt: skip
            for key in ("tactical_diameter", "steady_yaw_rate"):
                errs = []
                for v in res[-2:]:
                    m, p = v.indices.get("measured", {}), v.indices.get("simulated", {})
                    errs.append(f"{100 * (p[key] / m[key] - 1):+.0f} %" if key in p else "–")
                cells.append(", ".join(errs))
            n_terms = sum(len(t) for t in sel.model.structure.terms.values())
            label = search + (" --average" if average else "")
            print(f"| {fold} | {label} | {n_terms} | " + " | ".join(cells) + f" | {diverged} |")
    print(f"\n{time.perf_counter() - t0:.0f} s")


def random_runs_inside_and_outside(horizon_s: float = 10.0) -> None:
    """Why zig-zags alone predict the random runs poorly: the held-out random runs cut into
    windows of ``horizon_s``, each free-run from its measured state, split by whether the window
    stays inside the training logs' envelope (every signal): ``validate --horizon``'s columns,
    ``shipid.evaluation.horizon`` with the envelope; the r error over the run's spread in each
    part. The README's recipe (stepwise, ``--average``), trained on the zig-zags alone and on
    the README's fold."""
    from shipid.evaluation.envelope import envelope
    from shipid.evaluation.horizon import horizon_errors

    data = esso_logs()
    if data is None:
        return
    zz, rnd, _ = data
    folds = condition_folds(rnd)
    print(f"\nHeld-out random runs in windows of {horizon_s:g} s, inside and outside the "
          "training envelope (r error over the run's spread)\n")
    print("| fold | random run | windows inside | r inside | r outside |")
    print("|---|---|---|---|---|")
    for fold in ("zig-zags only", "README"):
        zk, rk, _, rnd_held = folds[fold]
        train = [zz[k] for k in zk] + [rnd[k] for k in rk]
        model = select(train, library=LIBRARY, cv="logo", search="stepwise", average=True).model
        env = envelope(train)
        for key in rnd_held:
            found = horizon_errors(model, rnd[key], horizon_s, envelope=env)
            cells = [f"{x:.2f}" if x == x else "–" for x in
                     (found.over_spread_inside["r"], found.over_spread_outside["r"])]  # fmt: skip
            print(f"| {fold} | {key} | {found.inside} of {found.windows} | {cells[0]} | "
                  f"{cells[1]} |")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # envelope and plausibility warnings of the candidates
    main()
    random_runs_inside_and_outside()

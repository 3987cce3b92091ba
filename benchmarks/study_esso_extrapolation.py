"""How far the README's Esso recipe carries beyond its training conditions (issue #10).

``study_esso.py`` holds out the turns and one random run from a training set that covers every
zig-zag amplitude and propeller speed. Unseen trials of a real ship are often further away: a
larger rudder, another rps, or zig-zags only to learn from. Each fold below trains ``select``
(``low-speed+wind+propeller-asymmetry``, leave-one-log-out) on a subset chosen by condition and
judges it on what it left out, for the three searches of ``select``:

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

Run: .venv/bin/python benchmarks/study_esso_extrapolation.py
"""

from __future__ import annotations

import os
import time
import warnings
from pathlib import Path

import numpy as np

from shipid.data.io import read_log
from shipid.evaluation.validate import validate
from shipid.identification.select import select

LIBRARY = "low-speed+wind+propeller-asymmetry"
SEARCHES = ("stepwise", "frols", "none")
# Rudder amplitude [deg] and propeller speed [rps] of each zig-zag (the data README's table).
ZIGZAGS = {"13_04_24": (20, 16.7), "13_14_21": (30, 16.7), "13_22_52": (15, 10),
           "13_29_19": (15, 12), "13_42_53": (30, 10), "13_50_28": (30, 12),
           "13_57_45": (20, 15), "14_03_39": (20, 12), "14_10_05": (20, 12)}  # fmt: skip
README_HELD = "31-Jul-2020_12_29_58"


def _ratio(validations, logs, state: str) -> float:
    """Mean over the logs of the free-run error std of ``state`` over its spread."""
    return float(np.mean([v.metrics[state]["std"] / np.std(lg[state])
                          for v, lg in zip(validations, logs, strict=True)]))  # fmt: skip


def main() -> None:
    esso = Path(__file__).resolve().parents[2] / "shared" / "data" / "esso-osaka"
    if not esso.is_dir():
        print("../shared/data is absent")
        return

    def read(path, trim):
        kw = {"start": "auto", "end": "auto"} if trim else {}
        return read_log(path, fmt="osaka-frt", dt=0.5, **kw)

    zz = {p.stem[-8:]: read(p, True) for p in sorted((esso / "zigzag").glob("*.csv"))}
    rnd = {p.stem[7:]: read(p, False) for p in sorted((esso / "random").glob("*.csv"))}
    turns = [read(p, True) for p in sorted((esso / "turning").glob("*.csv"))]
    folds = {
        "30° zig-zags": ([k for k, (a, _) in ZIGZAGS.items() if a < 30], list(rnd),
                         [k for k, (a, _) in ZIGZAGS.items() if a == 30], []),
        "15-16.7 rps": ([k for k, (_, n) in ZIGZAGS.items() if n < 14], list(rnd),
                        [k for k, (_, n) in ZIGZAGS.items() if n > 14], []),
        "zig-zags only": (list(ZIGZAGS), [], [], list(rnd)),
        "README": (list(ZIGZAGS), [k for k in rnd if k != README_HELD], [], [README_HELD]),
    }  # fmt: skip
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; library {LIBRARY}\n")
    print("| fold | search | terms | held-out zig-zags r / u error over spread | held-out random "
          "runs r / u | turns: TD +35°, −35° | steady r +35°, −35° | diverged |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    t0 = time.perf_counter()
    for fold, (zk, rk, zig_held, rnd_held) in folds.items():
        train = [zz[k] for k in zk] + [rnd[k] for k in rk]
        held = [zz[k] for k in zig_held] + [rnd[k] for k in rnd_held] + turns
        for search in SEARCHES:
            sel = select(train, library=LIBRARY, cv="logo", search=search)
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
            print(f"| {fold} | {search} | {n_terms} | " + " | ".join(cells) + f" | {diverged} |")
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # envelope and plausibility warnings of the candidates
    main()

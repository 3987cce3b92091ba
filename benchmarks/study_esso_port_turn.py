"""Can the Esso Osaka's structure represent its −35° turn at all? The README's model predicts the
port turn's advance 27-31 % long: the ship answers the port rudder faster than the model. Here
the README's recipe (``select --average`` on the nine zig-zags and three random runs) gives the
structure, which is then refitted with the two turns added to its training logs, and on the −35°
turn alone. If even the fit on that turn misses its first seconds, no coefficient of this
structure represents them, and more data of the same kind will not help.

Printed: measured and simulated (free run) yaw rate 2, 4, 6, 10 and 20 s after each turn's rudder
execute, for the structure fitted without and with the turns.

Run: .venv/bin/python benchmarks/study_esso_port_turn.py
"""

from __future__ import annotations

import os
import warnings

import numpy as np
from esso_logs import README_HELD, esso_logs

from shipid.dynamics.model import ModelStructure
from shipid.evaluation.validate import free_run
from shipid.identification.identify import identify
from shipid.identification.select import select
from shipid.trials.trial import describe_trial

AFTER_S = (2.0, 4.0, 6.0, 10.0, 20.0)
LIBRARY = "low-speed+wind+propeller-asymmetry"


def main() -> None:
    data = esso_logs()
    if data is None:
        return
    warnings.simplefilter("ignore")
    zz, randoms, turns = data
    train = list(zz.values()) + [x for k, x in randoms.items() if k != README_HELD]
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    sel = select(train, library=LIBRARY, cv="logo", average=True)
    structure = ModelStructure("README's averaged model", sel.model.structure.terms)
    print("| fitted on | turn | " + " | ".join(f"r at {a:g} s: measured / model" for a in AFTER_S)
          + " |")  # fmt: skip
    print("|---|---|" + "---|" * len(AFTER_S))
    for label, logs in (("zig-zags + 3 random runs", train),
                        ("the same + both turns", train + turns),
                        ("the −35° turn alone", turns[1:])):  # fmt: skip
        model = identify(logs, model=structure, gamma=sel.gamma, force=True).model
        for side, log in zip(("+35°", "−35°"), turns, strict=True):
            sim, _ = free_run(model, log)
            t = log["t"].to_numpy()
            execute = describe_trial(log, "turning").execute_time
            cells = []
            for after in AFTER_S:
                i = int(np.searchsorted(t, execute + after))
                measured, simulated = float(log["r"].iloc[i]), float(sim.log["r"].iloc[i])
                change = 100 * (simulated / measured - 1)
                cells.append(f"{measured:.4f} / {simulated:.4f} ({change:+.0f} %)")
            print(f"| {label} | {side} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main()

"""``select --average`` on the KVLCC2's three real zig-zags (issue #10): trained on two, judged
on the third, for three libraries (the default one among them), the chosen candidate against
the average of the candidates the choice rule picks on resampled held-out logs (weighted by how
often), and the chosen candidate with the sign constraints on each term (``--constraints signs``)
and on the linearised derivatives (``--constraints derivatives``). Columns:
free-run error std of u, v, r on the held-out log and its overshoots, measured and from the
zig-zag run closed loop on the model.

Run: .venv/bin/python benchmarks/study_kvlcc2_average.py
"""

from __future__ import annotations

import os
import time
import warnings
from pathlib import Path

from kvlcc2_logs import kvlcc2_logs

from shipid.evaluation.validate import validate
from shipid.identification.physics import PhysicsOptions
from shipid.identification.select import select

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
LIBRARIES = ("blanke-race+race-damping", "blanke-speed+abkowitz3", None)  # None: the default


def main() -> None:
    if not DATA.is_dir():
        print("../shared/data is absent")
        return
    logs = kvlcc2_logs()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| library | held out | overshoots measured | chosen: u / v / r error std, overshoots | "
          "--average: u / v / r error std, overshoots | --constraints signs: u / v / r error "
          "std, overshoots | --constraints derivatives: u / v / r error std, overshoots |")
    print("|---|---|---|---|---|---|---|")
    t0 = time.perf_counter()
    for library in LIBRARIES:
        for held, log in logs.items():
            train = [x for k, x in logs.items() if k != held]
            cells, measured = [], None
            for average, physics in ((False, None), (True, None),
                                     (False, PhysicsOptions(signs=True)),
                                     (False, PhysicsOptions(derivatives=True))):  # fmt: skip
                model = select(train, library=library, average=average, physics=physics).model
                v = validate(model, [log])[0]
                m, closed = v.metrics, v.indices["closed_loop"]
                measured = v.indices["measured"]
                # A model with propeller terms runs its zig-zag from its own steady speed at the
                # log's rps (as shipid manoeuvre does): said where it is not the log's.
                own, log_speed = closed["approach_speed"], measured["approach_speed"]
                start = f" from {own:.3g} m/s" if abs(own / log_speed - 1) > 0.005 else ""
                cells.append(f"{m['u']['std']:.4f} / {m['v']['std']:.4f} / {m['r']['std']:.4f}, "
                             f"{closed['first_overshoot_deg']:.1f}°, "
                             f"{closed['second_overshoot_deg']:.1f}°{start}")  # fmt: skip
            print(f"| {library or 'default'} | {held} | {measured['first_overshoot_deg']:.1f}°, "
                  f"{measured['second_overshoot_deg']:.1f}° | " + " | ".join(cells) + " |")
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # envelope and plausibility warnings of the candidates
    main()

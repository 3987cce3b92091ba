"""The Esso Osaka's unseen manoeuvres (issue #10, the principal push): ``select`` on the nine
zig-zags and three of the four random runs, judged on the two ±35° turning circles and the
random run left out, each random run left out in turn; for the README's library and with the
single propeller's asymmetry added (``propeller-asymmetry``).

Run: .venv/bin/python benchmarks/study_esso.py
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

LIBRARIES = ("low-speed+wind", "low-speed+wind+propeller-asymmetry")


def main() -> None:
    esso = Path(__file__).resolve().parents[2] / "shared" / "data" / "esso-osaka"
    if not esso.is_dir():
        print("../shared/data is absent")
        return

    def log(path, trim):
        kw = {"start": "auto", "end": "auto"} if trim else {}
        return read_log(path, fmt="osaka-frt", dt=0.5, **kw)

    zigzags = [log(p, True) for p in sorted((esso / "zigzag").glob("*.csv"))]
    randoms = {p.name: log(p, False) for p in sorted((esso / "random").glob("*.csv"))}
    turns = [log(p, True) for p in sorted((esso / "turning").glob("*.csv"))]
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("Held out: the ±35° turns (errors of the tactical diameter and the steady yaw rate) "
          "and one random run (free-run r error std over the run's r spread); select on the "
          "nine zig-zags and the other three random runs\n")  # fmt: skip
    print("| library | held-out random run | terms | TD +35°, −35° | steady r +35°, −35° | "
          "random run: r error / spread | u error / spread |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    t0 = time.perf_counter()
    summary = {}
    for library in LIBRARIES:
        rows = []
        for held, random in randoms.items():
            train = zigzags + [x for k, x in randoms.items() if k != held]
            sel = select(train, library=library, cv="logo")
            results = validate(sel.model, turns + [random])
            td, yr = [], []
            for v in results[:2]:
                meas, pred = v.indices["measured"], v.indices["simulated"]
                td.append(100 * (pred["tactical_diameter"] / meas["tactical_diameter"] - 1))
                yr.append(100 * (pred["steady_yaw_rate"] / meas["steady_yaw_rate"] - 1))
            m = results[2].metrics
            r_ratio = m["r"]["std"] / float(np.std(random["r"]))
            u_ratio = m["u"]["std"] / float(np.std(random["u"]))
            rows.append((td, yr, r_ratio, u_ratio))
            n_terms = sum(len(t) for t in sel.model.structure.terms.values())
            print(f"| {library} | {held[7:-4]} | {n_terms} | "
                  + ", ".join(f"{x:+.0f} %" for x in td) + " | "
                  + ", ".join(f"{x:+.0f} %" for x in yr)
                  + f" | {r_ratio:.2f} | {u_ratio:.2f} |")  # fmt: skip
        summary[library] = rows
    print("\nMean over the four folds: |TD error|, |steady r error|, r error / spread, "
          "u error / spread\n")  # fmt: skip
    print("| library | TD | steady r | r / spread | u / spread |")
    print("|---|---|---|---|---|")
    for library, rows in summary.items():
        td = np.mean([abs(x) for r in rows for x in r[0]])
        yr = np.mean([abs(x) for r in rows for x in r[1]])
        print(f"| {library} | {td:.1f} % | {yr:.1f} % | {np.mean([r[2] for r in rows]):.2f} | "
              f"{np.mean([r[3] for r in rows]):.2f} |")
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # envelope and plausibility warnings of the candidates
    main()

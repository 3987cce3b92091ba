"""Cost of structure and γ selection (issue #9): how it grows with the library and the logs.

Synthetic trials of the paper's scale ship (paper noise, 0.5 Hz prefilter), 90 s zig-zags at
Δk = 0.2 s (451 samples each). Libraries of 10, 20 and 30 candidate terms per lateral equation
(Blanke, Blanke + part of Abkowitz, Blanke + all of it); 3, 5 and 10 training logs; the default
search (stepwise along the FROLS ranking, γ pre-screened by exact LOO, one-SE rule). The baseline
in the same run is one plain ``identify`` of the full library on the same logs: the ratio says
how many identifications' worth the whole cross-validated search costs.

Then the search's fits summing each fold's Gram and cross blocks once (``_Data.fold_sums``)
against summing them log by log in every candidate's fit (the code before, patched back in), in
the same process, alternated, the chosen candidates compared.

Run: .venv/bin/python benchmarks/bench_select.py
"""

from __future__ import annotations

import os
import time

from shipid.data.preprocess import lowpass
from shipid.dynamics.model import STRUCTURES, ModelStructure
from shipid.dynamics.terms import parse_term
from shipid.identification.identify import identify
from shipid.identification.select import select
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import PAPER_IMU, scale_ship

ANGLES = [(20, 20), (15, 15), (25, 25), (30, 30), (20, 10), (35, 5), (10, 10), (25, 10),
          (30, 20), (15, 5)]  # fmt: skip


def _pool(*groups) -> list[str]:
    """Canonical terms of the groups, once each, without propeller terms (no n in these logs)."""
    out = {}
    for g in groups:
        for t in g:
            term = parse_term(t)
            if "n" not in term.signals:
                out.setdefault(term.text, None)
    return list(out)


EXTRA = ("v*delta", "r*delta", "|r|*v", "U*r", "U*v", "v^2*delta^2", "r*|u|", "delta*|v|",
         "u*v*r", "v*r*delta")  # fmt: skip


def library(n_lateral: int) -> ModelStructure:
    lateral = _pool(*(STRUCTURES[k]["v"] for k in ("blanke", "abkowitz3", "low-speed")), EXTRA)
    surge = _pool(STRUCTURES["blanke"]["u"], STRUCTURES["abkowitz3"]["u"])
    lateral = lateral[:n_lateral]
    surge = surge[: max(5, n_lateral // 2)]
    return ModelStructure(f"{n_lateral} lateral terms", {"u": surge, "v": lateral, "r": lateral})


def main() -> None:
    ship = scale_ship(rudder_rate_deg=9.6)
    logs = [lowpass(PAPER_IMU.apply(zigzag(ship, a, h, duration=90, dt=0.2, method="euler",
                                           approach=2.0, first=("port", "starboard")[i % 2]).log,
                                    seed=i), 0.5) for i, (a, h) in enumerate(ANGLES)]  # fmt: skip
    select(logs[:3], library="blanke")  # compile / load caches
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| lateral terms | total terms | logs | candidates evaluated | select (s) | "
          "one identify (s) | ratio |")
    print("|---|---|---|---|---|---|---|")
    for n_terms in (10, 20, 30):
        lib = library(n_terms)
        total = sum(len(t) for t in lib.terms.values())
        for n_logs in (3, 5, 10):
            train = logs[:n_logs]
            t0 = time.perf_counter()
            sel = select(train, library=lib)
            ts = time.perf_counter() - t0
            t0 = time.perf_counter()
            identify(train, model=lib, force=True)
            ti = time.perf_counter() - t0
            print(f"| {n_terms} | {total} | {n_logs} | {len(sel.candidates)} | {ts:.2f} | "
                  f"{ti:.3f} | {ts / ti:.0f}× |")
    fold_sum_cost(logs)


def fold_sum_cost(logs, repeats: int = 3) -> None:
    """select on 10 logs and the 30-term library with the fold sums cached and summed per fit."""
    import numpy as np

    from shipid.dynamics.model import DOFS
    from shipid.identification import select as select_module

    cached = select_module._Data.fold_sums

    def per_fit(self, train):  # every fit sums its fold's blocks anew, as the code before did
        key = tuple(train)
        return (sum(self.gram[j] for j in key),
                {d: sum(self.cross[j][d] for j in key) for d in DOFS})

    lib, train = library(30), logs[:10]
    times: dict[str, list[float]] = {"cached once per fold": [], "summed per fit": []}
    chosen = {}
    for _ in range(repeats):
        for label, method in (("cached once per fold", cached), ("summed per fit", per_fit)):
            select_module._Data.fold_sums = method
            try:
                t0 = time.perf_counter()
                sel = select(train, library=lib)
                times[label].append(time.perf_counter() - t0)
            finally:
                select_module._Data.fold_sums = cached
            chosen[label] = np.asarray(sel.model.theta)
    same = np.array_equal(chosen["cached once per fold"], chosen["summed per fit"])
    base = min(times["summed per fit"])
    print(f"\nselect, 30 lateral terms, 10 logs ({repeats} runs each, alternated; the same model: "
          f"{same})\n")
    print("| fits' Gram blocks | select (s), best | mean | against per fit |")
    print("|---|---|---|---|")
    for label, ts in times.items():
        print(f"| {label} | {min(ts):.2f} | {np.mean(ts):.2f} | {base / min(ts):.2f}× |")


if __name__ == "__main__":
    main()

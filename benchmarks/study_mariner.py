"""The Mariner: a truth of another structure (Abkowitz's third order), identified from zig-zags
and judged on the manoeuvres the logs do not hold, the 35° turns above all.

Trials of the reference Mariner (full scale, 160.93 m, 7.7 m/s, its 5 °/s steering gear) at
Δk 0.5 s through the paper's sensors at a fraction of their noise (its 0.35 °/s on r would be
the yaw rate's whole swing on this ship). Each row trains on two zig-zags and is judged on what
they do not hold: the 35° turns to both sides (tactical diameter, steady yaw rate) and the 20°
turn to starboard against the Mariner's own, from the same approach speed, and the 10°/10°
zig-zag's overshoots (errors in degrees). Three ways a user gets a model, each by the command
line itself (``shipid.cli.main``) from the logs written as files:

- ``identify`` (no flags: here ``blanke``, the logs holding nothing it cannot);
- ``select`` (its default library, less what the logs lack);
- ``select --library abkowitz3+blanke`` (the truth's own terms among the candidates).

Run: .venv/bin/python benchmarks/study_mariner.py [noise factors, default 0.1,0.3] [seeds, 3]
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
import warnings

import numpy as np
from cli_models import judged, judged_header, model_by_cli, noisy_files, truth_indices

from shipid.trials.criteria import imo_criteria
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import PAPER_IMU, mariner

DT = 0.5
METHODS = {"identify": ["identify"], "select": ["select", "--quiet"],
           "select abkowitz3+blanke": ["select", "--quiet", "--library", "abkowitz3+blanke"]}
TRAINING = {"20/20 both sides": ("zz20", "zz-20"), "20/20 and 10/10": ("zz20", "zz10"),
            "10/10 both sides": ("zz10", "zz-10")}  # fmt: skip
TURNS = ((35.0, "starboard"), (35.0, "port"), (20.0, "starboard"))


def trials(ship) -> dict:
    """The noise-free zig-zags the training logs are drawn from (10 s straight approach)."""
    out = {}
    for a in (20, 10):
        for first, sign in (("starboard", ""), ("port", "-")):
            out[f"zz{sign}{a}"] = zigzag(ship, a, a, first=first, duration=600, dt=DT,
                                         approach=10.0).log  # fmt: skip
    return out


def main_study(noises=(0.1, 0.3), seeds=3) -> None:
    warnings.simplefilter("ignore")
    ship = mariner()
    clean = trials(ship)
    truth = truth_indices(ship, TURNS, DT, 900.0)
    crit = imo_criteria(ship, dt=DT).table.set_index(["criterion", "manoeuvre"])
    speed = float(np.median(clean["zz20"]["u"].to_numpy()[:10]))
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    print(f"\nMariner: 35° tactical diameters {truth[TURNS[0]][0]:.0f} m, "
          f"{truth[TURNS[1]][0]:.0f} m (IMO 5 L: "
          f"{'pass' if crit.loc[('tactical diameter', 'turning 35° starboard'), 'passed'] else 'FAIL'}"
          f"), 20° {truth[TURNS[2]][0]:.0f} m; 10°/10° overshoots {truth['zz10'][0]:.1f}°, "
          f"{truth['zz10'][1]:.1f}°\n")
    print(judged_header(["noise × paper", "seed", "trained on", "made by", "terms"]))
    start = time.perf_counter()
    rows: dict[tuple[str, str], list[list[str]]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        for noise in noises:
            for seed in range(seeds):
                paths = noisy_files(clean, PAPER_IMU.scaled(noise), seed, tmp)
                for label, names in TRAINING.items():
                    for method, argv in METHODS.items():
                        model = model_by_cli(argv, [paths[n] for n in names],
                                             f"{tmp}/model.json")  # fmt: skip
                        if model is None:
                            print(f"| {noise:g} | {seed} | {label} | {method} | failed |")
                            continue
                        n = sum(len(t) for t in model.structure.terms.values())
                        cells = judged(model, truth, speed, ship.steering, DT, 900.0)
                        rows.setdefault((label, method), []).append(cells)
                        print(f"| {noise:g} | {seed} | {label} | {method} | {n} | "
                              + " | ".join(cells) + " |", flush=True)
    print(f"\n{time.perf_counter() - start:.0f} s")
    summary(rows)


def summary(rows: dict) -> None:
    """Per training set and way of making the model, over the seeds and noise levels: the 35°
    turns' |tactical diameter error| (median, range), their |steady yaw rate error| (median,
    largest) and the 10°/10° zig-zag's worst |overshoot error| (median, largest), read back
    from the rows' cells (a turn that did not come round counts as infinite)."""
    import re

    print("\n| trained on | made by | 35° tactical diameter, abs error: median (range) | 35° "
          "steady yaw rate, abs error: median (largest) | 10°/10° worst overshoot error: median "
          "(largest) |")
    print("|---|---|---|---|---|")
    for (label, method), cases in rows.items():
        td, r, zz = [], [], []
        for cells in cases:
            for cell in cells[:2]:  # the 35° turns
                found = re.match(r"([+-]\d+) % \(r ([+-]\d+) %\)", cell)
                td.append(abs(float(found[1])) if found else np.inf)
                r.append(abs(float(found[2])) if found else np.inf)
            found = re.match(r"([+-][\d.]+)°, ([+-][\d.]+)°", cells[-1])
            zz.append(max(abs(float(found[1])), abs(float(found[2]))) if found else np.inf)
        print(f"| {label} | `{method}` | {np.median(td):.0f} % ({min(td):.0f}–{max(td):.0f} %) | "
              f"{np.median(r):.0f} % ({max(r):.0f} %) | {np.median(zz):.1f}° ({max(zz):.1f}°) |")


if __name__ == "__main__":
    args = sys.argv[1:]
    main_study(tuple(float(x) for x in args[0].split(",")) if args else (0.1, 0.3),
               int(args[1]) if len(args) > 1 else 3)

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

import contextlib
import io
import os
import sys
import tempfile
import time
import warnings

import numpy as np

from shipid.cli import main
from shipid.data.io import write_log
from shipid.reporting.modelfile import load_model
from shipid.trials.criteria import imo_criteria
from shipid.trials.manoeuvres import turning_circle, zigzag
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


def judged(model, truth: dict, speed: float, steering) -> list[str]:
    """The cells of one row: each turn's tactical diameter and steady yaw rate (error against the
    Mariner's), and the 10°/10° overshoots' errors, the model run with the Mariner's own gear
    (without it the model's rudder moved at once, and its overshoots came 2–3° low)."""
    cells = []
    for angle, side in TURNS:
        res = turning_circle(model, angle, side=side, dt=DT, speed=speed, steering=steering)
        ind = {} if res.diverged else (res.indices or {})
        td, r = ind.get("tactical_diameter"), ind.get("steady_yaw_rate")
        if td is None or r is None:
            cells.append("no turn")
            continue
        td0, r0 = truth[(angle, side)]
        cells.append(f"{100 * (td / td0 - 1):+.0f} % (r {100 * (r / r0 - 1):+.0f} %)")
    zz = zigzag(model, 10, 10, duration=900, dt=DT, speed=speed, steering=steering)
    ind = {} if zz.diverged else (zz.indices or {})
    first, second = ind.get("first_overshoot_deg"), ind.get("second_overshoot_deg")
    cells.append("–" if first is None or second is None else
                 f"{first - truth['zz10'][0]:+.1f}°, {second - truth['zz10'][1]:+.1f}°")
    return cells


def main_study(noises=(0.1, 0.3), seeds=3) -> None:
    warnings.simplefilter("ignore")
    ship = mariner()
    clean = trials(ship)
    truth = {}
    for angle, side in TURNS:
        ind = turning_circle(ship, angle, side=side, dt=DT).indices
        truth[(angle, side)] = (ind["tactical_diameter"], ind["steady_yaw_rate"])
    zz = zigzag(ship, 10, 10, duration=900, dt=DT).indices
    truth["zz10"] = (zz["first_overshoot_deg"], zz["second_overshoot_deg"])
    crit = imo_criteria(ship, dt=DT).table.set_index(["criterion", "manoeuvre"])
    speed = float(np.median(clean["zz20"]["u"].to_numpy()[:10]))
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    print(f"\nMariner: 35° tactical diameters {truth[TURNS[0]][0]:.0f} m, "
          f"{truth[TURNS[1]][0]:.0f} m (IMO 5 L: "
          f"{'pass' if crit.loc[('tactical diameter', 'turning 35° starboard'), 'passed'] else 'FAIL'}"
          f"), 20° {truth[TURNS[2]][0]:.0f} m; 10°/10° overshoots {truth['zz10'][0]:.1f}°, "
          f"{truth['zz10'][1]:.1f}°\n")
    print("| noise × paper | seed | trained on | made by | terms | 35° starboard: tactical "
          "diameter (steady r) | 35° port | 20° starboard | 10°/10° overshoots |")
    print("|---|---|---|---|---|---|---|---|---|")
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        for noise in noises:
            for seed in range(seeds):
                paths = {}
                for i, (name, log) in enumerate(clean.items()):
                    noisy = PAPER_IMU.scaled(noise).apply(log, seed=100 * seed + i)
                    paths[name] = str(write_log(noisy, f"{tmp}/{name}_{seed}.csv"))
                for label, names in TRAINING.items():
                    for method, argv in METHODS.items():
                        out = f"{tmp}/model.json"
                        with contextlib.redirect_stdout(io.StringIO()), \
                                contextlib.redirect_stderr(io.StringIO()):  # fmt: skip
                            code = main([*argv, *(paths[n] for n in names), "-o", out])
                        if code:
                            print(f"| {noise:g} | {seed} | {label} | {method} | failed |")
                            continue
                        model = load_model(out)
                        n = sum(len(t) for t in model.structure.terms.values())
                        cells = judged(model, truth, speed, ship.steering)
                        print(f"| {noise:g} | {seed} | {label} | {method} | {n} | "
                              + " | ".join(cells) + " |", flush=True)
    print(f"\n{time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    args = sys.argv[1:]
    main_study(tuple(float(x) for x in args[0].split(",")) if args else (0.1, 0.3),
               int(args[1]) if len(args) > 1 else 3)

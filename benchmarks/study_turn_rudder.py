"""Turning circles at another rudder angle than the logs' turns (issue #10): does a model
identified from zig-zags carry a 20° turn as well as a 35° one, and at another propeller speed?

The real Esso Osaka's 20° turns and its turns at 8 rps are not among the logs here (its 35°
turns at 10 rps are). Two truths whose turns are known stand in for them:

1. The KVLCC2's MMG model, its 20/20 zig-zags to both sides at its approach's rps (a quarter of
   the paper's IMU noise, as ``study_structure.py``), the default ``shipid identify``; judged
   on its 20° and 35° turns to both sides.
2. The KVLCC2's prime coefficients on the Esso Osaka's particulars (``shipid mmg kvlcc2``: the
   "sister" of ``study_esso_sister_mmg.py``), its propeller at each log's rate: zig-zags at the
   rudder, side and rps of the nine Esso zig-zag files (white noise 3 mm/s in u, v and 5e-4
   rad/s in r), the default ``identify`` of the nine; judged on its 20° and 35° turns to
   starboard at 8 and 10 rps, from each model's own straight speed there.

4. The sister's zig-zags again, each alone (as one real Esso file is fitted).

Then the real Esso Osaka: the default ``identify`` of its nine zig-zag files and the README's
``select`` (twelve logs) hold 20° and 35° at 8 and 10 rps, against the sister's turns and the
two measured 35° turns at 10 rps.

Run: .venv/bin/python benchmarks/study_turn_rudder.py [SEEDS]
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
from shipid.data.particulars import Particulars
from shipid.dynamics.equilibrium import surge_equilibrium, vessel_straight_speed
from shipid.reporting.modelfile import load_document, load_model, training_conditions
from shipid.trials.indices import turning_indices
from shipid.trials.manoeuvres import turning_circle, zigzag
from shipid.trials.reading import read_trial_log
from shipid.vessels import kvlcc2
from shipid.vessels.kvlcc2 import trimmed_revolutions
from shipid.vessels.mmg_file import mmg_vessel, sister_ship

ESSO = Particulars(length=3.0, beam=0.489, draught=0.201, block_coefficient=0.83, mass=244.6,
                   rudder_area=0.0106, propeller_diameter=0.084, xg=0.094, rho=1000.0,
                   scale=108.3)  # the data README's  # fmt: skip
# The nine Esso zig-zag files' rudder [deg] and rps (esso_logs.ZIGZAGS), sides alternating.
ESSO_ZIGZAGS = ((20, 16.67), (30, 16.67), (15, 10.0), (15, 12.0), (30, 10.0), (30, 12.0),
                (20, 15.0), (20, 12.0), (20, 12.0))  # fmt: skip
STEP = 0.05


def _identified(paths: list[str], folder: str, *extra: str):
    """The default ``shipid identify`` of ``paths`` (quiet): (model, training conditions)."""
    out = f"{folder}/m.json"
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(["identify", *paths, *extra, "-o", out]) == 0
    return load_model(out), training_conditions(load_document(out))


def _turn(target, rudder: float, side: str, speed: float, rps: float | None):
    """(tactical diameter [m], steady yaw rate [rad/s]) of a turn, NaN where it has none."""
    wind = (0.0, 0.0) if getattr(target, "uses_wind", False) else None
    t = turning_circle(target, rudder, side, speed=speed, rps=rps, dt=STEP, duration=600,
                       wind=wind)  # fmt: skip
    return (float(t.indices.get("tactical_diameter", np.nan)),
            abs(float(t.indices.get("steady_yaw_rate", np.nan))))  # fmt: skip


def _off(got: float, truth: float) -> str:
    return f"{100 * (got / truth - 1):+.0f} %" if np.isfinite(got) else "none"


def mmg_kvlcc2(seeds: int) -> None:
    from study_structure import PAPER_IMU, _zigzag

    ship = kvlcc2()
    rps = trimmed_revolutions(ship.approach_speed)
    cases = [(rud, side) for rud in (20, 35) for side in ("starboard", "port")]
    truth = {c: _turn(ship, *c, ship.approach_speed, rps) for c in cases}
    print("\n1. The KVLCC2's MMG model: default identify of its 20/20 zig-zags, turns from its "
          f"approach ({ship.approach_speed:.4g} m/s, {rps:.4g} rps)\n")
    print("| seed | " + " | ".join(f"{r}° {s}: TD, steady r" for r, s in cases)
          + " | TD 20° / TD 35° (stbd) |")  # fmt: skip
    print("|---" * (len(cases) + 2) + "|")
    print("| truth | " + " | ".join(f"{truth[c][0]:.2f} m, {truth[c][1]:.4f}" for c in cases)
          + f" | {truth[cases[0]][0] / truth[cases[2]][0]:.2f} |")  # fmt: skip
    sensor = PAPER_IMU.scaled(0.25)
    with tempfile.TemporaryDirectory() as folder:
        for seed in range(seeds):
            paths = [str(write_log(sensor.apply(_zigzag(ship, 20, 20, side).log,
                                                seed=100 * seed + i).assign(n=rps),
                                   f"{folder}/{i}.csv"))
                     for i, side in enumerate(("starboard", "port"))]  # fmt: skip
            model, _ = _identified(paths, folder)
            got = {c: _turn(model, *c, ship.approach_speed, rps) for c in cases}
            print(f"| {seed} | " + " | ".join(f"{_off(got[c][0], truth[c][0])}, "
                                              f"{_off(got[c][1], truth[c][1])}" for c in cases)
                  + f" | {got[cases[0]][0] / got[cases[2]][0]:.2f} |", flush=True)  # fmt: skip


def _sister():
    doc, _ = sister_ship(kvlcc2().dynamics.c, ESSO, "sister", rps="logs")  # x_G 0.094 m
    return mmg_vessel(doc, "the sister")


def sister_truth(seeds: int) -> None:
    ship = _sister()
    rng_noise = {"u": 0.003, "v": 0.003, "r": 5e-4}
    cases = [(rud, rps) for rps in (8.0, 10.0) for rud in (20, 35)]
    truth = {}
    for rud, rps in cases:
        speed = _sister_speed(ship, rps)
        truth[(rud, rps)] = _turn(ship, rud, "starboard", speed, rps)
    print("\n2. The sister (the KVLCC2's prime coefficients, the Esso Osaka's particulars): the "
          "default identify of zig-zags like the nine Esso files; turns to starboard from each "
          "model's own straight speed\n")
    print("| seed | " + " | ".join(f"{r}° at {n:g} rps: TD, steady r" for r, n in cases)
          + " | TD 20° / TD 35° (10 rps) |")  # fmt: skip
    print("|---" * (len(cases) + 2) + "|")
    print("| truth | " + " | ".join(f"{truth[c][0]:.2f} m, {truth[c][1]:.4f}" for c in cases)
          + f" | {truth[(20, 10.0)][0] / truth[(35, 10.0)][0]:.2f} |")  # fmt: skip
    with tempfile.TemporaryDirectory() as folder:
        for seed in range(seeds):
            rng = np.random.default_rng(seed)
            paths = []
            for i, (rud, rps) in enumerate(ESSO_ZIGZAGS):
                side = ("starboard", "port")[i % 2]
                log = zigzag(ship, rud, rud, side, rps=rps, speed=_sister_speed(ship, rps),
                             duration=150, dt=0.1).log  # fmt: skip
                for s, sd in rng_noise.items():
                    log[s] = log[s] + rng.normal(0.0, sd, len(log))
                paths.append(str(write_log(log.assign(n=rps), f"{folder}/{i}.csv")))
            model, _ = _identified(paths, folder)
            got = {}
            for rud, rps in cases:
                speed = surge_equilibrium(model, _sister_speed(ship, rps), rps)
                got[(rud, rps)] = _turn(model, rud, "starboard", speed, rps)
            print(f"| {seed} | " + " | ".join(f"{_off(got[c][0], truth[c][0])}, "
                                              f"{_off(got[c][1], truth[c][1])}" for c in cases)
                  + f" | {got[(20, 10.0)][0] / got[(35, 10.0)][0]:.2f} |", flush=True)  # fmt: skip


def sister_single_files(seed: int = 1) -> None:
    """Each of the nine Esso-like zig-zags of the sister alone, as one real file is fitted."""
    ship = _sister()
    truth = {rud: _turn(ship, rud, "starboard", _sister_speed(ship, 10.0), 10.0)
             for rud in (20, 35)}  # fmt: skip
    print("\n4. The sister again, each of those zig-zags alone (the default identify of one "
          "file); turns to starboard at 10 rps from each model's own straight speed\n")
    print("| zig-zag | rps | structure | 20°: TD, steady r | 35°: TD, steady r |")
    print("|---|---|---|---|---|")
    print(f"| truth | | | {truth[20][0]:.2f} m, {truth[20][1]:.4f} | {truth[35][0]:.2f} m, "
          f"{truth[35][1]:.4f} |")  # fmt: skip
    rng = np.random.default_rng(seed)
    off = []
    with tempfile.TemporaryDirectory() as folder:
        for i, (rud, rps) in enumerate(ESSO_ZIGZAGS):
            log = zigzag(ship, rud, rud, ("starboard", "port")[i % 2], rps=rps,
                         speed=_sister_speed(ship, rps), duration=150, dt=0.1).log  # fmt: skip
            for state, sd in (("u", 0.003), ("v", 0.003), ("r", 5e-4)):
                log[state] = log[state] + rng.normal(0.0, sd, len(log))
            path = str(write_log(log.assign(n=rps), f"{folder}/{i}.csv"))
            model, _ = _identified([path], folder)
            speed = surge_equilibrium(model, _sister_speed(ship, 10.0), 10.0)
            got = {r: _turn(model, r, "starboard", speed, 10.0) for r in (20, 35)}
            off += [abs(got[r][0] / truth[r][0] - 1) for r in (20, 35)]
            print(f"| {rud}/{rud} | {rps:g} | {model.structure.name} | "
                  f"{_off(got[20][0], truth[20][0])}, {_off(got[20][1], truth[20][1])} | "
                  f"{_off(got[35][0], truth[35][0])}, {_off(got[35][1], truth[35][1])} |",
                  flush=True)  # fmt: skip
    print(f"\ntactical diameters' |error| over the 18 turns: median {100 * np.median(off):.0f} %, "
          f"largest {100 * np.max(off):.0f} %")  # fmt: skip


def _sister_speed(ship, rps: float) -> float:
    """The sister's straight-running speed at ``rps`` (its propeller follows the run's rate),
    as ``shipid manoeuvre SHIP.yml --rps N`` finds it."""
    return vessel_straight_speed(ship, rps)


def real_esso() -> None:
    from esso_logs import DATA

    if not DATA.is_dir():
        print("\n3. ../shared/data is absent")
        return
    zigzags = sorted(str(p) for p in (DATA / "zigzag").glob("*.csv"))
    random = [str(DATA / "random" / f"random_{t}.csv") for t in
              ("03-Aug-2020_11_04_37", "31-Jul-2020_12_48_39", "31-Jul-2020_14_52_18")]
    ship = _sister()
    rows = {"the sister (fitted to nothing)": ship}
    with tempfile.TemporaryDirectory() as folder, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        measured = {p.stem: turning_indices(read_trial_log(p, fmt="osaka-frt"))
                    for p in sorted((DATA / "turning").glob("*.csv"))}  # fmt: skip
        rows["identify, the nine zig-zag files"] = _identified(
            zigzags, folder, "--format", "osaka-frt")[0]  # fmt: skip
        out = f"{folder}/s.json"
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            assert main(["select", "--format", "osaka-frt",
                         *zigzags, *random, "--library", "low-speed+wind+propeller-asymmetry",
                         "--dt", "0.5", "--quiet", "--average", "-o", out]) == 0  # fmt: skip
        rows["select --average, the README's twelve logs"] = load_model(out)
    shown = ", ".join(f"{name[5:]} {ind['tactical_diameter']:.3g} m (steady r "
                      f"{ind['steady_yaw_rate']:+.4f})" for name, ind in measured.items())  # fmt: skip
    print(f"\n3. The real Esso Osaka (its 35° turns at 10 rps, measured: tactical diameters "
          f"{shown}): turns to starboard in still air from each model's straight speed\n")
    cases = [(rud, rps) for rps in (8.0, 10.0) for rud in (20, 35)]
    print("| model | " + " | ".join(f"{r}° at {n:g} rps: TD [m], steady r" for r, n in cases)
          + " | TD 20° / TD 35° (10 rps) |")  # fmt: skip
    print("|---" * (len(cases) + 2) + "|")
    for name, target in rows.items():
        got = {}
        for rud, rps in cases:
            speed = (_sister_speed(ship, rps) if target is ship
                     else surge_equilibrium(target, 0.35 * rps / 10.0, rps))  # fmt: skip
            got[(rud, rps)] = _turn(target, rud, "starboard", speed, rps)
        print(f"| {name} | " + " | ".join(f"{got[c][0]:.2f}, {got[c][1]:.4f}" for c in cases)
              + f" | {got[(20, 10.0)][0] / got[(35, 10.0)][0]:.2f} |", flush=True)  # fmt: skip


def main_study(seeds: int = 4) -> None:
    t0 = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        mmg_kvlcc2(seeds)
        sister_truth(max(1, seeds - 1))
        sister_single_files()
        real_esso()
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main_study(int(sys.argv[1]) if len(sys.argv) > 1 else 4)

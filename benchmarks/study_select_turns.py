"""Does ``select``'s warning of a turn its terms set apart from ``identify``'s default mark the
fits whose unseen turns miss? (issue #10)

The paper's scale ship (the demo's trials, ``synthesise_trials``), seeds 0–9: ``select`` (the
default library, leave one log out) and the default ``identify`` on the two zig-zags 20/20 and
10/10, the IMU's noise; each judged on the demo's ±20° turns neither saw (closed loop, from each
log's approach: tactical diameter and steady yaw rate against the measured; free run: the yaw
rate's rms error over its std). Then the KVLCC2's MMG model as the truth, seeds 0–3: its 20/20
zig-zags to both sides at its approach's rps (a quarter of the IMU's noise), judged on its 35°
turns to both sides. ``select`` warns where its held 35° turns and those of what
``identify`` fits by default are more than 1.25 times apart in yaw rate
(``auto_structure.turns_apart_from_the_default``).

Run: .venv/bin/python benchmarks/study_select_turns.py [SEEDS]
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
from shipid.demo import TRAINING, synthesise_trials
from shipid.evaluation.validate import validate
from shipid.reporting.modelfile import load_model

TURNS = ("turning δ = −20°", "turning δ = +20°")


def _made(argv: list[str]) -> tuple[object, str]:
    """``shipid ARGV``, quiet: (the model written, its stderr)."""
    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        code = main(argv)
    assert code == 0, err.getvalue()
    return load_model(argv[argv.index("-o") + 1]), err.getvalue()


def _judged(model, turns) -> list[float]:
    """Per turn: the tactical diameter's and steady yaw rate's error [%] (closed loop) and the
    yaw rate's rms error over its std (free run)."""
    out = []
    for v, turn in zip(validate(model, turns), turns, strict=True):
        closed, measured = v.indices["closed_loop"], v.indices["measured"]
        out += [100 * (closed.get(k, np.nan) / measured[k] - 1)
                for k in ("tactical_diameter", "steady_yaw_rate")]  # fmt: skip
        out.append(v.metrics["r"]["rmse"] / float(np.std(turn["r"].to_numpy())))
    return out


def paper_ship(seed: int, folder: str) -> tuple[list[str], list]:
    """The demo's two zig-zags written as files, and its two turns."""
    logs = synthesise_trials(seed)
    paths = [str(write_log(logs[n], f"{folder}/{i}.csv"))
             for i, n in enumerate((TRAINING, "zigzag 10/10"))]  # fmt: skip
    return paths, [logs[n] for n in TURNS]


def mmg_truth(seed: int, folder: str) -> tuple[list[str], list]:
    """The KVLCC2 MMG model's 20/20 zig-zags to both sides written as files (the rps logged),
    and its 35° turns to both sides, through the same sensors."""
    from study_structure import PAPER_IMU, _turn, _zigzag

    from shipid.vessels import kvlcc2
    from shipid.vessels.kvlcc2 import trimmed_revolutions

    ship = kvlcc2()
    rps = trimmed_revolutions(ship.approach_speed)
    sensor = PAPER_IMU.scaled(0.25)
    paths = [str(write_log(sensor.apply(_zigzag(ship, 20, 20, side).log, seed=100 * seed + i)
                           .assign(n=rps), f"{folder}/{i}.csv"))
             for i, side in enumerate(("starboard", "port"))]  # fmt: skip
    turns = [sensor.apply(_turn(ship, side).log, seed=100 * seed + 7 + i).assign(n=rps)
             for i, side in enumerate(("starboard", "port"))]  # fmt: skip
    return paths, turns


def main_study(seeds: int = 10) -> None:
    t0 = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    for title, make, n in (("The paper's ship (turns ±20°)", paper_ship, seeds),
                           ("The KVLCC2's MMG model (turns 35° to starboard, port)", mmg_truth,
                            max(1, seeds // 2 - 1))):  # fmt: skip
        print(f"\n{title}\n")
        _study(make, n)
    print(f"\n{time.perf_counter() - t0:.0f} s")


def _study(make, seeds: int) -> None:
    print("| seed | made by | warned | TD off [%] | steady r off [%] | r rms / r std |")
    print("|---|---|---|---|---|---|")
    rows = {"select": [], "identify": []}
    warned = []
    with tempfile.TemporaryDirectory() as folder, warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for seed in range(seeds):
            paths, turns = make(seed, folder)
            sel, err = _made(["select", *paths, "--quiet", "-o", f"{folder}/s.json"])
            fired = "far from" in err and "what identify fits" in err
            warned.append(fired)
            ident, _ = _made(["identify", *paths, "-o", f"{folder}/i.json"])
            for name, model in (("select", sel), ("identify", ident)):
                e = _judged(model, turns)
                rows[name].append(e)
                print(f"| {seed} | {name} | {'yes' if fired and name == 'select' else ''} | "
                      f"{e[0]:+.0f}, {e[3]:+.0f} | {e[1]:+.0f}, {e[4]:+.0f} | "
                      f"{e[2]:.2f}, {e[5]:.2f} |", flush=True)
    fired = np.array(warned)
    print("\nMedian (largest) over the seeds of |TD error| and |steady r error| [%] of both "
          "turns, and the yaw rate's rms error over its std, by whether select warned:\n")
    print("| made by | seeds | TD off | steady r off | r rms / r std |")
    print("|---|---|---|---|---|")
    for name in rows:
        e = np.abs(np.array(rows[name]))
        for label, mask in (("warned", fired), ("not warned", ~fired)):
            if not mask.any():
                continue
            td, sr, rr = (e[mask][:, [j, j + 3]].ravel() for j in range(3))
            print(f"| {name} | {label} ({mask.sum()}) | {np.nanmedian(td):.0f} "
                  f"({np.nanmax(td):.0f}) | {np.nanmedian(sr):.0f} ({np.nanmax(sr):.0f}) | "
                  f"{np.nanmedian(rr):.2f} ({np.nanmax(rr):.2f}) |")


if __name__ == "__main__":
    main_study(int(sys.argv[1]) if len(sys.argv) > 1 else 10)

"""Is a wind-driven surface current what the Esso Osaka's models miss? (issue #10)

The pond's true wind (1.3–2.4 m/s in the zig-zag files) is three to eleven times the ship's
speed; a wind over open water drives the surface layer at a few per cent of its speed, which at
the 3 m model's 0.2 m draught would be a tenth of its speed or more. The logs' u and v are over
the ground, while the hull's forces go with the velocity through the water. Here each log is
given a current ``k`` times its mean true wind, downwind and fixed in the earth frame, taken off
its u and v (the body-frame current turns with the heading, so the accelerations change too),
and the default ``identify --dt 0.5`` is fitted to the zig-zags so read; each held-out log is
read with its own current and judged by its yaw rate, which a uniform current leaves as it is
(free-run rms error over the log's std; the turns' closed-loop steady yaw rate in the log's
wind against the measured). Folds: the nine zig-zags judged on the two turns and four random
runs, and each zig-zag left out of the other eight.

Run: .venv/bin/python benchmarks/study_esso_current.py [k,k,...]
"""

from __future__ import annotations

import math
import os
import sys
import tempfile
import time
import warnings

import numpy as np
import pandas as pd
from cli_models import model_by_cli
from esso_logs import DATA, read

from shipid.data.io import write_log
from shipid.evaluation.validate import validate
from shipid.trials.indices import turning_indices
from shipid.trials.reading import read_trial_log

KS = (0.0, 0.01, 0.02, 0.03)


def mean_true_wind(path, log) -> tuple[float, float]:
    """The mean true wind [m/s] over the log's span as the vector it blows toward (earth frame:
    x north, y east; the file gives the direction it comes from, clockwise from north)."""
    raw = pd.read_csv(path)
    t = raw["t [s]"]
    span = (t >= log["t"].iloc[0]) & (t <= log["t"].iloc[-1])
    speed, came = raw["wind_velo_true [m/s]"][span], raw["wind_dir_true [rad]"][span]
    return float((-speed * np.cos(came)).mean()), float((-speed * np.sin(came)).mean())


def through_water(log, current: tuple[float, float]):
    """``log`` with a current fixed in the earth frame taken off its body-frame u and v."""
    out = log.copy()
    out.attrs = dict(log.attrs)
    psi = log["psi"].to_numpy()
    cx, cy = current
    out["u"] = log["u"] - (cx * np.cos(psi) + cy * np.sin(psi))
    out["v"] = log["v"] - (-cx * np.sin(psi) + cy * np.cos(psi))
    return out


def judged(train, held, files: dict, read_so: dict, folder: str) -> dict:
    """{held log: (free-run r rms error over its std, closed-loop steady yaw rate or None)} of
    the default ``identify --dt 0.5`` of the ``train`` files, each log read through the water."""
    model = model_by_cli(["identify", "--dt", "0.5"], [files[p] for p in train],
                         f"{folder}/model.json")  # fmt: skip
    runs = validate(model, [read_so[p] for p in held], [p.stem for p in held])
    return {p: (v.metrics["r"]["rmse"] / float(read_so[p]["r"].std()),
                (v.indices.get("closed_loop") or {}).get("steady_yaw_rate"))
            for p, v in zip(held, runs, strict=True)}  # fmt: skip


def main(ks=KS) -> None:
    if not DATA.is_dir():
        print("../shared/data is absent")
        return
    t0 = time.perf_counter()
    zigzags = sorted((DATA / "zigzag").glob("*.csv"))
    turns = sorted((DATA / "turning").glob("*.csv"))
    randoms = sorted((DATA / "random").glob("*.csv"))
    logs = {p: read(p, trim=p not in randoms) for p in zigzags + turns + randoms}
    wind = {p: mean_true_wind(p, log) for p, log in logs.items()}
    measured = {p: turning_indices(read_trial_log(p, fmt="osaka-frt"))["steady_yaw_rate"]
                for p in turns}  # fmt: skip
    speeds = [math.hypot(*wind[p]) / float(logs[p]["u"].abs().mean()) for p in zigzags]
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; the zig-zags' "
          f"mean true wind {min(math.hypot(*wind[p]) for p in zigzags):.2f}–"
          f"{max(math.hypot(*wind[p]) for p in zigzags):.2f} m/s, "
          f"{min(speeds):.1f}–{max(speeds):.1f} times the ship's mean |u|\n")
    print("| k (current / wind) | the nine zig-zags: turns' r error / std | turns' steady r "
          f"(measured {', '.join(f'{measured[p]:+.4f}' for p in turns)}) | random runs' r "
          "error / std | each zig-zag left out: r error / std, median (mean) |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        for k in ks:
            read_so = {p: through_water(log, (k * wind[p][0], k * wind[p][1]))
                       for p, log in logs.items()}  # fmt: skip
            files = {p: str(write_log(log, f"{folder}/{p.stem}_{k}.csv"))
                     for p, log in read_so.items()}  # fmt: skip

            nine = judged(zigzags, turns + randoms, files, read_so, folder)
            left_out = [judged([q for q in zigzags if q != p], [p], files, read_so, folder)[p][0]
                        for p in zigzags]  # fmt: skip
            print(f"| {k:g} | " + ", ".join(f"{nine[p][0]:.3f}" for p in turns) + " | "
                  + ", ".join("–" if nine[p][1] is None else f"{nine[p][1]:+.4f}" for p in turns)
                  + " | " + ", ".join(f"{nine[p][0]:.3f}" for p in randoms)
                  + f" | {np.median(left_out):.3f} ({np.mean(left_out):.3f}) |")
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # the turns' gyro scale (study_gyro_offset.py)
    main(tuple(float(k) for k in sys.argv[1].split(",")) if len(sys.argv) > 1 else KS)

"""Models from the logs a small craft's GNSS and compass give (positions and heading, no u, v or
r), judged on manoeuvres the logs do not hold, against models from an IMU's u, v, r.

CyberShip II (reference-ships.md §5, a 1:70 model ship at 0.3 m/s) runs the 20°/20° zig-zag to
both sides at Δk 0.1 s (10 Hz, an RTK receiver's rate). Three sets of training logs, each read
by the command line itself (``shipid identify``, no flags, and ``--model blanke-speed`` so that
the structure is held while the data change):

- IMU: u, v, r, ψ, x, y through the paper's sensors at 0.15 of their noise (the study of
  ``study_cybership2.py``);
- GNSS at the reference point: t, δ, x, y, ψ only (RTK positions, 0.02 m; heading 0.2°), u, v
  and r read off the track (``shipid.data.track_velocities``, the window chosen from the log);
- GNSS 0.3 m forward: the antenna a quarter of the ship's length ahead of the reference point,
  read with ``--antenna 0.3,0`` and without it;
- GNSS SOG/COG: t, δ, speed and course over ground and ψ, the ground velocity's components with
  white noise of 0.01 and 0.05 m/s (``SOG_NOISE``), u, v their turn by ψ, r off ψ.

Judged as ``study_cybership2.py`` judges: the 35° turns to both sides and the 20° turn to
starboard (tactical diameter and steady yaw rate against the ship's own), and the 10°/10°
zig-zag's overshoots (errors in degrees).

Run: .venv/bin/python benchmarks/study_gnss_logs.py [seeds, default 3]
"""

from __future__ import annotations

import math
import os
import sys
import tempfile
import time
import warnings

import numpy as np
from cli_models import judged_header, judged_row, noisy_files, truth_indices

from shipid.trials.manoeuvres import zigzag
from shipid.vessels import PAPER_IMU, cybership2
from shipid.vessels.sensors import SensorModel

DT = 0.1
NOISE = 0.15
GNSS = SensorModel(white={"x": 0.02, "y": 0.02, "psi": math.radians(0.2)})
ANTENNA = 0.3  # m forward of the reference point
# White noise on each component of a Doppler ground velocity [m/s]: an RTK receiver's and a
# consumer one's (u-blox F9P: 0.05 m/s).
SOG_NOISE = (0.01, 0.05)
TURNS = ((35.0, "starboard"), (35.0, "port"), (20.0, "starboard"))


def gnss_files(clean: dict, seed: int, folder: str, fore: float) -> dict[str, str]:
    """Plain CSVs of t, δ, x, y, ψ as a receiver ``fore`` m ahead of the reference point and a
    compass log them."""
    paths = {}
    for i, (name, log) in enumerate(clean.items()):
        noisy = GNSS.apply(log, seed=100 * seed + i)
        psi = noisy["psi"].to_numpy()
        out = noisy[["t", "delta", "x", "y", "psi"]].copy()
        out["x"] = noisy["x"].to_numpy() + fore * np.cos(psi)
        out["y"] = noisy["y"].to_numpy() + fore * np.sin(psi)
        paths[name] = f"{folder}/{name}_gnss{fore:g}_{seed}.csv"
        out.to_csv(paths[name], index=False)
    return paths


def ground_velocity_files(clean: dict, seed: int, folder: str, sigma: float) -> dict[str, str]:
    """Plain CSVs of t, δ, SOG [kn], COG [deg], ψ [deg] as a receiver at the reference point and a
    compass log them: white noise of ``sigma`` m/s on each of the ground velocity's north and
    east components (a Doppler's), the compass's on ψ."""
    rng = np.random.default_rng(1000 + seed)
    paths = {}
    for i, (name, log) in enumerate(clean.items()):
        noisy = GNSS.apply(log, seed=100 * seed + i)
        psi, u, v = (log[c].to_numpy() for c in ("psi", "u", "v"))
        north = u * np.cos(psi) - v * np.sin(psi) + rng.normal(0.0, sigma, len(psi))
        east = u * np.sin(psi) + v * np.cos(psi) + rng.normal(0.0, sigma, len(psi))
        out = noisy[["t", "delta"]].copy()
        out["sog [kn]"] = np.hypot(north, east) / (1852.0 / 3600.0)
        out["cog [deg]"] = np.degrees(np.arctan2(east, north)) % 360.0
        out["psi [deg]"] = np.degrees(noisy["psi"].to_numpy()) % 360.0
        paths[name] = f"{folder}/{name}_sog{sigma:g}_{seed}.csv"
        out.to_csv(paths[name], index=False)
    return paths


def main_study(seeds: int = 3) -> None:
    warnings.simplefilter("ignore")
    ship = cybership2()
    clean = {f"zz{s}20": zigzag(ship, 20, 20, first=first, duration=120, dt=DT, approach=5.0).log
             for first, s in (("starboard", ""), ("port", "-"))}  # fmt: skip
    truth = truth_indices(ship, TURNS, DT, 120.0)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print(judged_header(["seed", "logs", "read with", "made by", "structure"]))
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        for seed in range(seeds):
            sets = [("IMU", [], noisy_files(clean, PAPER_IMU.scaled(NOISE), seed, tmp)),
                    ("GNSS at the reference point", [], gnss_files(clean, seed, tmp, 0.0)),
                    ("GNSS 0.3 m forward", ["--antenna", f"{ANTENNA:g},0"],
                     gnss_files(clean, seed, tmp, ANTENNA)),
                    ("GNSS 0.3 m forward", [], gnss_files(clean, seed, tmp, ANTENNA))]
            sets += [(f"GNSS SOG/COG, {sigma:g} m/s", [],
                      ground_velocity_files(clean, seed, tmp, sigma)) for sigma in SOG_NOISE]
            for label, read, paths in sets:
                for method, argv in (("identify", ["identify"]),
                                     ("--model blanke-speed", ["identify", "--model",
                                                               "blanke-speed"])):  # fmt: skip
                    print(judged_row([str(seed), label, " ".join(read) or "–", method],
                                     argv + read, list(paths.values()), f"{tmp}/model.json",
                                     truth, ship, DT, 120.0), flush=True)  # fmt: skip
    print(f"\n{time.perf_counter() - start:.0f} s")


if __name__ == "__main__":
    main_study(int(sys.argv[1]) if len(sys.argv) > 1 else 3)

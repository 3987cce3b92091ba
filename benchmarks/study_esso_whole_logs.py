"""The default `shipid identify` on the Esso Osaka's nine zig-zag files read whole, as a user
reads them who does not know `--start auto`, against the same files cut to the manoeuvre, and
what `identify` does with such files by default (cuts them, as `--start auto --end auto`).

The files start at rest: the ship gathers speed for 20–45 s, the helm correcting by up to 19°,
before the zig-zag's first order, and the propeller is stopped for the last 2–8 s. The README
reads them with `--start auto --end auto` and resamples to `--dt 0.5`. Each row is one way of
reading the nine files (`shipid identify --format osaka-frt ... FILES`, no `--model`: the default
structure, chosen by `select`), judged on what it was not fitted to: the two 35° turns at 10 rps
(closed loop from the model's own approach, as `validate` runs it; the turns read as the README
reads them) and the four random runs (up to their propulsion dropout; free-run r and u error std
over the run's spread). The model's steady straight speed at 16.7 rps is set against the
fastest sample of its training logs (`identify` names a speed more than 10 % beyond it).

Run: .venv/bin/python benchmarks/study_esso_whole_logs.py
"""

from __future__ import annotations

import contextlib
import io
import json
import os
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from esso_logs import DATA, esso_logs

from shipid.cli import main as shipid
from shipid.dynamics.equilibrium import surge_equilibrium
from shipid.evaluation.validate import validate
from shipid.reporting.modelfile import load_model, training_conditions

READINGS = {
    "whole (--start 0)": ["--start", "0"],
    "--start auto": ["--start", "auto"],
    "--start auto --end auto": ["--start", "auto", "--end", "auto"],
    # What identify does with zig-zags and turns from rest when no --start or --end is given:
    # the row above, to the bit.
    "default (no --start, --end)": [],
}
SAMPLING = {"0.1 s (own)": [], "0.5 s": ["--dt", "0.5"]}


def main() -> None:
    warnings.simplefilter("ignore")
    data = esso_logs()
    if data is None:
        return
    _, randoms, turns = data
    paths = sorted(str(p) for p in (DATA / "zigzag").glob("*.csv"))
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| zig-zags read | Δk | terms | 35° turns, closed loop: TD +35°, −35° (steady r) | "
          "random runs: r / u error over spread | steady speed at 16.7 rps (fastest log) |")
    print("|---|---|---|---|---|---|")
    start = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        for reading, trim in READINGS.items():
            for sampling, dt in SAMPLING.items():
                print(_row(reading, sampling, trim + dt, paths, f"{tmp}/m.json", turns, randoms))
        print("\nThe raw files a user hands `identify` (no flags but --format): the nine "
              "zig-zags and three random runs, the fourth random run held out in turn; read "
              "whole (--start 0: the random run that runs into a propulsion dropout keeps it, "
              "with a warning) or as the default reads them (the zig-zags cut to the "
              "manoeuvre, that random run up to its dropout)\n")
        print("| held-out random run | zig-zags read | terms | 35° turns, closed loop: TD +35°, "
              "−35° (steady r) | held-out random run: r / u error over spread | steady speed "
              "at 16.7 rps (fastest log) |")
        print("|---|---|---|---|---|---|")
        files = {p.stem[7:]: str(p) for p in sorted((DATA / "random").glob("*.csv"))}
        for held in files:
            train = paths + [f for k, f in files.items() if k != held]
            for reading, trim in (("whole (--start 0)", ["--start", "0"]),
                                  ("default", [])):  # fmt: skip
                print(_row(held, reading, trim, train, f"{tmp}/m.json", turns,
                           {held: randoms[held]}))  # fmt: skip
    print(f"\n{time.perf_counter() - start:.0f} s")


def _row(reading, sampling, options, paths, out, turns, randoms) -> str:
    with contextlib.redirect_stdout(io.StringIO()), \
            contextlib.redirect_stderr(io.StringIO()):  # fmt: skip
        code = shipid(["identify", "--format", "osaka-frt", *options, *paths, "-o", out])
    if code:
        return f"| {reading} | {sampling} | failed | | | |"
    model = load_model(out)
    terms = sum(len(t) for t in model.structure.terms.values())
    cells = []
    for v in validate(model, turns, start_draws=False):
        measured, closed = v.indices["measured"], v.indices.get("closed_loop") or {}
        if not closed.get("tactical_diameter"):
            cells.append("no turn")
            continue
        td = 100 * (closed["tactical_diameter"] / measured["tactical_diameter"] - 1)
        r = 100 * (closed["steady_yaw_rate"] / measured["steady_yaw_rate"] - 1)
        cells.append(f"{td:+.0f} % ({r:+.0f} %)")
    errors = []
    for log in randoms.values():
        (v,) = validate(model, log, start_draws=False)
        errors.append(f"{v.metrics['r']['std'] / np.std(log['r']):.2f} / "
                      f"{v.metrics['u']['std'] / np.std(log['u']):.2f}")  # fmt: skip
    fastest = training_conditions(json.loads(Path(out).read_text()))["envelope"]["u"][1]
    steady = surge_equilibrium(model, fastest, 50 / 3)
    speed = f"{steady:.3f} m/s ({fastest:.3f})" if steady else f"none ({fastest:.3f})"
    return (f"| {reading} | {sampling} | {terms} | {', '.join(cells)} | {'; '.join(errors)} | "
            f"{speed} |")


if __name__ == "__main__":
    main()

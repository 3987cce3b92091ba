"""Real trials cut after their order: how each is read, against the same trial read whole.

A log a user brings may start after the rudder execute (a logger started late, a file cut to
the manoeuvre by hand). Each manoeuvre log of ``../shared/data`` (the Esso Osaka's nine zig-zags
and two turns, as ``--start auto --end auto`` cuts them; MARIN's two 20°/20° runs at the 7 m
model; HSVA's 20°/10° run) is cut at its execute plus 0 to 5 s and read again: the kind, the
ship's yaw rate at the first sample as a share of its largest where the reading says the log
starts inside its manoeuvre (``Trial.turning_at_order``), and the indices against the whole
log's: a zig-zag's first and second overshoots, a turn's advance, tactical diameter and steady
yaw rate.

Printed: one row per log and cut, and a summary per cut.

Run: .venv/bin/python benchmarks/study_cut_logs.py
"""

from __future__ import annotations

import os
import time
import warnings

import numpy as np
from esso_logs import DATA

from shipid.data.io import read_log
from shipid.trials.indices import manoeuvre_indices
from shipid.trials.trial import describe_trial

SHARED = DATA.parent
CUTS = (0.0, 0.5, 1.0, 2.0, 3.0, 5.0)
ZIGZAG_KEYS = ("first_overshoot_deg", "second_overshoot_deg")
TURN_KEYS = ("advance", "tactical_diameter", "steady_yaw_rate")


def logs() -> dict:
    """{name: log} of every manoeuvre log, read as the commands read them."""
    out = {}
    for kind in ("zigzag", "turning"):
        for path in sorted((DATA / kind).glob("*.csv")):
            out[path.stem] = read_log(path, fmt="osaka-frt", start="auto", end="auto")
    for path in sorted((SHARED / "kvlcc2-marin").glob("*.dat")):
        out[path.stem] = read_log(path, fmt="simman-marin", scale=45.7, start="auto", end="auto")
    for path in sorted((SHARED / "kvlcc2-hsva").glob("*.dat")):
        out[path.stem] = read_log(path, fmt="simman-hsva", start="auto", end="auto")
    return out


def cut(log, at: float):
    part = log[log["t"] >= at].reset_index(drop=True)
    part.attrs = dict(log.attrs)
    return part


def changes(whole: dict, part: dict, keys) -> list[float]:
    """Each index of ``part`` minus the whole log's: degrees for the overshoots, per cent
    otherwise."""
    out = []
    for k in keys:
        a, b = whole.get(k), part.get(k)
        if a is None or b is None:
            out.append(float("nan"))
        elif k.endswith("_deg"):
            out.append(b - a)
        else:
            out.append(100.0 * (b / a - 1.0))
    return out


def main() -> None:
    warnings.simplefilter("ignore")
    started = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    if not DATA.is_dir():
        print("../shared/data is absent")
        return
    read = logs()
    print("| log | cut after the execute | read as | turning at the first sample | "
          "change: overshoots [°] or advance, TD, steady r [%] |")
    print("|---|---|---|---|---|")
    summary: dict[float, dict[str, list]] = {c: {"same": [], "named": [], "moved": []}
                                             for c in CUTS}  # fmt: skip
    for name, log in read.items():
        trial = describe_trial(log)
        whole = manoeuvre_indices(log, trial=trial)
        keys = ZIGZAG_KEYS if trial.kind == "zigzag" else TURN_KEYS
        for c in CUTS:
            part = cut(log, trial.execute_time + c)
            pt = describe_trial(part)
            share = "–" if pt.turning_at_order is None else f"{pt.turning_at_order:.2f}"
            if pt.kind == trial.kind:
                moved = changes(whole, manoeuvre_indices(part, trial=pt), keys)
                shown = ", ".join("–" if np.isnan(x) else f"{x:+.2f}" for x in moved)
                worst = max((abs(x) for x in moved if not np.isnan(x)), default=0.0)
                summary[c]["moved"].append(worst if trial.kind == "zigzag" else np.nan)
                summary[c]["named" if pt.turning_at_order is not None else "same"].append(name)
            else:
                shown = pt.reason[:60] + "…"
                summary[c]["named"].append(name)
            print(f"| {name} | {c:g} s | {pt.kind} | {share} | {shown} |")
    print("\nPer cut: logs read as the whole one without a word, logs named (read as none, or "
          "with the note), and the zig-zags' largest overshoot change where read as zig-zags\n")
    print("| cut after the execute | read without a word | named | zig-zags' largest "
          "overshoot change [°] |")
    print("|---|---|---|---|")
    for c, s in summary.items():
        moved = [x for x in s["moved"] if not np.isnan(x)]
        print(f"| {c:g} s | {len(s['same'])} of {len(read)} | {len(s['named'])} | "
              f"{max(moved):.2f} |" if moved else f"| {c:g} s | {len(s['same'])} of {len(read)} "
              f"| {len(s['named'])} | – |")  # fmt: skip
    print(f"\n{time.perf_counter() - started:.0f} s")


if __name__ == "__main__":
    main()

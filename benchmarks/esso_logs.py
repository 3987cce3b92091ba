"""The Esso Osaka logs of ``../shared/data`` as the README's commands read them (Δk 0.5 s;
zig-zags and turns trimmed to the manoeuvre, random runs up to a propulsion dropout), and the
folds by condition the Esso studies train and judge on."""

from __future__ import annotations

import os
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

from shipid.data.io import read_log

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "esso-osaka"
# Rudder amplitude [deg] and propeller speed [rps] of each zig-zag (the data README's table).
ZIGZAGS = {"13_04_24": (20, 16.7), "13_14_21": (30, 16.7), "13_22_52": (15, 10),
           "13_29_19": (15, 12), "13_42_53": (30, 10), "13_50_28": (30, 12),
           "13_57_45": (20, 15), "14_03_39": (20, 12), "14_10_05": (20, 12)}  # fmt: skip
README_HELD = "31-Jul-2020_12_29_58"


def read(path: Path, trim: bool, dt: float | None = 0.5):
    """One log, as ``shipid import --format osaka-frt`` with ``--start auto --end auto`` (the
    zig-zags and turns) or ``--end dropout`` (the random runs), and ``--dt 0.5`` give it (``dt``
    None: the logs' own 0.1 s)."""
    kw = {"start": "auto", "end": "auto"} if trim else {"end": "dropout"}
    return read_log(path, fmt="osaka-frt", dt=dt, **kw)


def esso_logs(dt: float | None = 0.5):
    """(zig-zags by time of day, random runs by date and time, the two turns), or None (and a
    line saying so) when ``../shared/data`` is absent."""
    if not DATA.is_dir():
        print("../shared/data is absent")
        return None
    zz = {p.stem[-8:]: read(p, True, dt) for p in sorted((DATA / "zigzag").glob("*.csv"))}
    rnd = {p.stem[7:]: read(p, False, dt) for p in sorted((DATA / "random").glob("*.csv"))}
    turns = [read(p, True, dt) for p in sorted((DATA / "turning").glob("*.csv"))]
    return zz, rnd, turns


def raw_files():
    """(zig-zag, turning, random-run files), each sorted, as ``../shared/data`` holds them, or
    None (and a line saying so) when it is absent."""
    if not DATA.is_dir():
        print("../shared/data is absent")
        return None
    return tuple(sorted((DATA / kind).glob("*.csv")) for kind in ("zigzag", "turning", "random"))


def held_out_files():
    """(zig-zag, turning, random-run files, {path: log} of the turns and random runs as the
    commands read them: the turns cut to the manoeuvre, the random runs to a dropout), or None
    (and a line saying so) when ``../shared/data`` is absent: what the studies judge on."""
    files = raw_files()
    if files is None:
        return None
    zigzags, turns, randoms = files
    return zigzags, turns, randoms, {p: read(p, trim=p not in randoms) for p in turns + randoms}


def trial_files():
    """(the zig-zag files, {path: log} of every trial file, zig-zags first, as the commands read
    it with ``--format osaka-frt``: cut to the manoeuvre, or to a propulsion dropout), or None
    (and a line saying so) when ``../shared/data`` is absent."""
    from shipid.trials.reading import read_trial_log

    if not DATA.is_dir():
        print("../shared/data is absent")
        return None
    zigzags = sorted((DATA / "zigzag").glob("*.csv"))
    others = sorted((DATA / "turning").glob("*.csv")) + sorted((DATA / "random").glob("*.csv"))
    return zigzags, {p: read_trial_log(p, fmt="osaka-frt") for p in zigzags + others}


def condition_folds(rnd) -> dict[str, tuple[list[str], list[str], list[str], list[str]]]:
    """Per fold: (training zig-zags, training random runs, held-out zig-zags, held-out random
    runs); the turns are held out in every fold. Three folds reach beyond the training
    conditions (rudder amplitude, propeller speed, zig-zags only), then the README's fold."""
    return {
        "30° zig-zags": ([k for k, (a, _) in ZIGZAGS.items() if a < 30], list(rnd),
                         [k for k, (a, _) in ZIGZAGS.items() if a == 30], []),
        "15-16.7 rps": ([k for k, (_, n) in ZIGZAGS.items() if n < 14], list(rnd),
                        [k for k, (_, n) in ZIGZAGS.items() if n > 14], []),
        "zig-zags only": (list(ZIGZAGS), [], [], list(rnd)),
        "README": (list(ZIGZAGS), [k for k in rnd if k != README_HELD], [], [README_HELD]),
    }  # fmt: skip


def random_run_folds(rnd) -> dict[str, tuple[list[str], list[str], list[str], list[str]]]:
    """Each random run held out in turn (with the turns), the rest and every zig-zag trained on."""
    return {f"random {k}": (list(ZIGZAGS), [j for j in rnd if j != k], [], [k]) for k in rnd}


def run_with_files(*studies: Callable[[Path], None]) -> None:
    """Run each study on a scratch folder for its log files, between the machine's load and the
    seconds taken; a line and exit 0 when ``../shared/data`` is absent."""
    if not DATA.is_dir():
        print("../shared/data is absent")
        sys.exit(0)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        for study in studies:
            study(Path(tmp))
    print(f"\n{time.perf_counter() - t0:.0f} s")

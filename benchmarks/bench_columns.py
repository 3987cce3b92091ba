"""What taking a log's columns without a Series saves (``shipid.data.log.column_values``),
against pandas' own ``log[name].to_numpy()`` (the code before, and the strongest simple
alternative: the public API), run in the same process.

1. One column of a canonical log (the Esso Osaka's 13_22_52 zig-zag, 0.1 s), best of five.
2. The README's Esso Osaka ``select`` (the nine zig-zags and three random runs, Δk 0.5 s,
   ``--average``, no bootstrap) and ``validate`` of its model on the two turns and the held-out
   random run, in process, warm, with every module's ``column_values`` swapped for pandas' way;
   rounds alternated.

Run: .venv/bin/python benchmarks/bench_columns.py
"""

from __future__ import annotations

import contextlib
import io
import os
import statistics
import sys
import tempfile
import time
import timeit

from esso_logs import DATA, README_HELD

import shipid.data.log as log_module
from shipid.cli import main as shipid
from shipid.data.io import read_log

ROUNDS = 3
LIBRARY = "low-speed+wind+propeller-asymmetry"


def through_a_series(frame, name, dtype=None):
    """The code before: pandas builds the column's Series, then its array."""
    return frame[name].to_numpy(dtype=dtype)


def _use(accessor) -> None:
    """``accessor`` as every loaded shipid module's ``column_values``."""
    for mod in list(sys.modules.values()):
        if getattr(mod, "__name__", "").startswith("shipid") and \
                hasattr(mod, "column_values"):  # fmt: skip
            mod.column_values = accessor


def _quiet(argv: list[str]) -> int:
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        return shipid(argv)


def main() -> None:
    if not DATA.is_dir():
        print("../shared/data is absent")
        return
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    log = read_log(DATA / "zigzag" / "zigzag_31-Jul-2020_13_22_52.csv", fmt="osaka-frt")
    fast = log_module.column_values
    one = {label: min(timeit.repeat(lambda f=f: f(log, "u"), number=20000, repeat=5)) / 20000
           for label, f in (("pandas' Series", through_a_series), ("column_values", fast))}
    zigzags = sorted(str(p) for p in (DATA / "zigzag").glob("*.csv"))
    randoms = {p.stem[7:]: str(p) for p in sorted((DATA / "random").glob("*.csv"))}
    turns = sorted(str(p) for p in (DATA / "turning").glob("*.csv"))
    train = zigzags + [p for k, p in randoms.items() if k != README_HELD]
    times: dict[tuple[str, str], list[float]] = {}
    with tempfile.TemporaryDirectory() as tmp:
        model = f"{tmp}/esso.json"
        runs = {"select": ["select", *train, "--format", "osaka-frt", "--library", LIBRARY,
                           "--dt", "0.5", "--quiet", "--average", "-o", model],
                "validate": ["validate", model, *turns, randoms[README_HELD], "--format",
                             "osaka-frt", "--dt", "0.5", "--quiet", "--json",
                             f"{tmp}/v.json"]}  # fmt: skip
        for argv in runs.values():  # warm: imports and compiled kernels
            if _quiet(argv):
                raise SystemExit(f"{argv[0]} failed")
        try:
            for _ in range(ROUNDS):
                for label, accessor in (("pandas' Series", through_a_series),
                                        ("column_values", fast)):  # fmt: skip
                    _use(accessor)
                    for command, argv in runs.items():
                        t0 = time.perf_counter()
                        _quiet(argv)
                        times.setdefault((command, label), []).append(time.perf_counter() - t0)
        finally:
            _use(fast)
    print("| case | pandas' Series | column_values | ratio |")
    print("|---|---|---|---|")
    a, b = one["pandas' Series"], one["column_values"]
    print(f"| one column of a {len(log)}-sample log (best of 5) | {a * 1e6:.2f} µs | "
          f"{b * 1e6:.2f} µs | {b / a:.2f} |")
    for command in runs:
        a = statistics.median(times[(command, "pandas' Series")])
        b = statistics.median(times[(command, "column_values")])
        print(f"| {command}, README's Esso recipe (median of {ROUNDS}) | {a:.2f} s | {b:.2f} s "
              f"| {b / a:.2f} |")


if __name__ == "__main__":
    main()

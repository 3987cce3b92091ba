"""A command's wall time against the floor its dependencies set (issue #13: ``identify`` of the
demo's training log ≤ 1 s, a data command's start-up ≤ 0.5 s).

Each case runs in a fresh process (``subprocess``, as a user's shell starts it), the cases
alternated over the rounds so that a slow minute of the machine falls on all of them; min and
median wall seconds. The baseline is what no code of ours can go below: a process that imports
the libraries ``identify`` needs (pandas for the log, SciPy's optimize for the output-error fit,
numba for the free runs) and loads one cached compiled kernel (numba's first load initialises its
compiler's target, whatever the kernel).

Run: ``.venv/bin/python benchmarks/bench_startup.py [ROUNDS]``
"""

from __future__ import annotations

import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

PY = sys.executable
SHIPID = str(Path(PY).with_name("shipid"))
KERNEL = "from shipid.dynamics.kernel import crossflow; crossflow(0.1, 0.01, 3.0)"


def _cases(folder: Path) -> dict[str, list[str]]:
    log = folder / "training.csv"
    return {
        "python -c pass": [PY, "-c", "pass"],
        "import numpy": [PY, "-c", "import numpy"],
        "import pandas": [PY, "-c", "import pandas"],
        "import scipy.optimize": [PY, "-c", "import scipy.optimize"],
        "import numba": [PY, "-c", "import numba"],
        "numba, one cached kernel loaded": [PY, "-c", KERNEL],
        "floor: pandas, scipy.optimize, numba, one cached kernel":
            [PY, "-c", f"import pandas, scipy.optimize; {KERNEL}"],
        "shipid identify (demo's training log)":
            [SHIPID, "identify", str(log), "-o", str(folder / "m.json")],
        "shipid indices (demo's training log)": [SHIPID, "indices", str(log)],
    }


def _training_log(folder: Path) -> None:
    from shipid.data.io import write_log
    from shipid.demo import TRAINING, synthesise_trials

    write_log(synthesise_trials(seed=0)[TRAINING], folder / "training.csv")


LOOP = """import time
t0 = time.perf_counter()
s = 0
for i in range(20_000_000):
    s += i
print(time.perf_counter() - t0)
"""


def _loop_seconds() -> float:
    """The machine's speed that minute: a pure-Python loop of 2·10⁷ additions at a module's top
    level (its globals), as the figures of ``benchmarks/README.md`` read it."""
    return float(subprocess.run([PY, "-c", LOOP], capture_output=True, text=True,
                                check=True).stdout)  # fmt: skip


def main(rounds: int = 5) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        _training_log(folder)
        cases = _cases(folder)
        for argv in cases.values():  # warm: bytecode, numba's cache, the OS's file cache
            subprocess.run(argv, capture_output=True, check=True)
        times: dict[str, list[float]] = {name: [] for name in cases}
        for _ in range(rounds):
            for name, argv in cases.items():
                t0 = time.perf_counter()
                subprocess.run(argv, capture_output=True, check=True)
                times[name].append(time.perf_counter() - t0)
    load = os.getloadavg()[0]
    print(f"Fresh processes, {rounds} rounds alternated; load average {load:.2f} on "
          f"{os.cpu_count()} cores; the pure-Python loop of 2·10⁷ additions {_loop_seconds():.2f} s\n")
    print("| process | min [s] | median [s] |")
    print("|---|---|---|")
    for name, ts in times.items():
        print(f"| {name} | {min(ts):.3f} | {statistics.median(ts):.3f} |")
    floor = times["floor: pandas, scipy.optimize, numba, one cached kernel"]
    ident = times["shipid identify (demo's training log)"]
    print(f"\nidentify over the floor: {min(ident) - min(floor):+.3f} s (min), "
          f"{statistics.median(ident) - statistics.median(floor):+.3f} s (median); "
          f"the floor alone is {min(floor):.3f}–{max(floor):.3f} s")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 5)

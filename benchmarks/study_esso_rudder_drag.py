"""The rudder's drag of one zig-zag file (issue #10): the default `shipid identify` on each Esso
Osaka zig-zag file alone, as it comes, then the same with the surge's rudder drag (δ²) held at
the particulars' value (``shipid.identification.priors.rudder_drag``: the rudder's normal force
in its inflow at the log's approach), the bound `identify`'s warning names where the fit's drag
pushes the ship ahead. Judged on logs the models were not fitted to: the two 35° turns (closed
loop: tactical diameter, steady yaw rate and speed against the measured), the other eight
zig-zags and the turns (free-run yaw rate error over each log's spread, the median) and the
four random runs (the same, the median; runs that diverge count as infinite).

Rows: the default; the bound where the warning names it (the fits whose drag pushes ahead),
the default elsewhere; the bound on every file.

Run: .venv/bin/python benchmarks/study_esso_rudder_drag.py
"""

from __future__ import annotations

import contextlib
import io
import os
import re
import tempfile
import time
import warnings

import numpy as np
from esso_logs import DATA, trial_files
from study_esso_single_logs import _errors, _turn_errors, _validations

from shipid.cli import main as shipid
from shipid.data.log import approach
from shipid.data.particulars import logs_particulars
from shipid.identification.priors import rudder_drag
from shipid.reporting.modelfile import load_model

BOUND = re.compile(r"(--bound 'u: delta\^2 <= \S+' --bound 'u: delta\^2 >= \S+')")


def _identify(path, flags: list[str], out: str) -> tuple[int, str]:
    said = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(said):
        code = shipid(["identify", "--format", "osaka-frt", str(path), *flags, "-o", out])
    return code, said.getvalue()


def _held(value: float) -> list[str]:
    return ["--bound", f"u: delta^2 <= {value:.3g}", "--bound", f"u: delta^2 >= {value:.3g}"]


def main() -> None:
    warnings.simplefilter("ignore")
    found = trial_files()
    if found is None:
        return
    zigzags, every = found
    turns = sorted((DATA / "turning").glob("*.csv"))
    logs = {f: log for f, log in every.items() if f in zigzags or f in turns}
    randoms = {f: log for f, log in every.items() if f not in logs}
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    start = time.perf_counter()
    rows = {"default": [], "held where the warning names it": [], "held on every file": []}
    per_file = []
    with tempfile.TemporaryDirectory() as tmp:
        out = f"{tmp}/m.json"
        for f in zigzags:
            log = logs[f]
            value = rudder_drag(logs_particulars([log]), approach(log, "u"), approach(log, "n"))
            code, said = _identify(f, [], out)
            named = BOUND.search(said)
            fits = {"default": load_model(out) if code == 0 else None}
            code, _ = _identify(f, _held(value), out)
            fits["held on every file"] = load_model(out) if code == 0 else None
            fits["held where the warning names it"] = \
                fits["held on every file"] if named else fits["default"]  # fmt: skip
            cells = []
            for label, model in fits.items():
                others = {g: x for g, x in logs.items() if g != f}
                runs = _validations(model, others)
                turn_runs = [v for g, v in zip(others, runs, strict=True) if g in turns]
                judged = (_turn_errors(turn_runs), _turn_errors(turn_runs, "steady_yaw_rate"),
                          _turn_errors(turn_runs, "steady_speed"),
                          float(np.median(_errors(runs, others))),
                          _errors(_validations(model, randoms), randoms))  # fmt: skip
                rows[label].append(judged)
                if label != "held where the warning names it":
                    cells.append(judged)
            per_file.append((f.stem[-8:], float(np.median(log["n"])), value, bool(named), cells))
    print("Each file: its rps, the particulars' rudder drag per δ² at its approach, whether the "
          "default's warning names it (its drag pushes ahead); the 35° turns' tactical diameter, "
          "steady yaw rate and speed off [%], the other zig-zags' and turns' and the random runs' "
          "r error / spread (median), default → held\n")
    print("| file | rps | drag per δ² | warned | TD [%] | steady r [%] | steady speed [%] | "
          "zig-zags and turns | random runs |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, rps, value, named, (plain, held) in per_file:
        def pair(i, a=plain, b=held):
            return f"{_signed(a[i])} → {_signed(b[i])}"

        print(f"| {name} | {rps:.4g} | {value:.3g} | {'yes' if named else 'no'} | {pair(0)} | "
              f"{pair(1)} | {pair(2)} | {plain[3]:.2f} → {held[3]:.2f} | "
              f"{np.median(plain[4]):.2f} → {np.median(held[4]):.2f} |")
    print("\nOver the nine files: |error| median / mean (largest) of the 18 turns; held-out "
          "zig-zags' and turns' r error / spread (median of the models' medians); random runs "
          "(median of the models' medians; runs diverged)\n")
    print("| made by | 35° TD | 35° steady r | 35° steady speed | zig-zags and turns | "
          "random runs |")
    print("|---|---|---|---|---|---|")
    for label, judged in rows.items():
        rnd = np.concatenate([j[4] for j in judged])
        print(f"| {label} | {_cell([j[0] for j in judged])} | {_cell([j[1] for j in judged])} | "
              f"{_cell([j[2] for j in judged])} | {np.median([j[3] for j in judged]):.3f} | "
              f"{np.median([np.median(j[4]) for j in judged]):.2f}; "
              f"{int(np.isinf(rnd).sum())} of {rnd.size} |")
    print(f"\n{time.perf_counter() - start:.0f} s")


def _signed(errors: np.ndarray) -> str:
    return ", ".join("–" if not np.isfinite(e) else f"{e:+.0f}" for e in errors)


def _cell(errors: list[np.ndarray]) -> str:
    every = np.abs(np.concatenate(errors))
    finite = every[np.isfinite(every)]
    none = every.size - finite.size
    return (f"{np.median(finite):.0f} % / {np.mean(finite):.0f} % ({finite.max():.0f} %)"
            + (f", {none} without" if none else ""))  # fmt: skip


if __name__ == "__main__":
    main()

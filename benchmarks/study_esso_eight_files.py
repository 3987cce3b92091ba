"""Leave one zig-zag file out: how much the default model of the Esso Osaka's zig-zags rests on
each file (issue #10). The default ``identify`` (Δk 0.5 s) on the nine zig-zag files and on each
eight of them, judged on the logs none of them was fitted to: the two 35° turns (closed loop,
tactical diameter and steady yaw rate against the measured), the four random runs (free run, the
yaw rate's error std over its std, as the README's table has it, and its rms over r's rms, the
mean kept), the held 10° and 35° turns at 6–16.7 rps from the model's own straight speed (the
largest ratio of a turn's tactical diameter at one rps to the same turn's at another), and which
surge the fit took: a thrust riding on the advance (u·|n| > 0 against no positive n² term) is
the from-rest warning's named cause (``shipid.dynamics.propeller.thrust_on_the_advance``). Each
set is fitted again with the bound that warning names, ``--bound 'u: u*|n| <= 0'`` (the
thrust's fall with the advance, the sign table's row alone), as a user who follows it would.

Run: .venv/bin/python benchmarks/study_esso_eight_files.py
"""

from __future__ import annotations

import os
import tempfile
import time
import warnings

import numpy as np
from cli_models import model_by_cli
from esso_logs import held_out_files
from study_esso_rudder_normal import FORMAT
from study_esso_side_constant import _across_rps, _judged

from shipid.dynamics.propeller import thrust_on_the_advance

MAKERS = {"identify": [], "identify --bound 'u: u*|n| <= 0'": ["--bound", "u: u*|n| <= 0"]}


def _cell(text: str) -> str:
    """``text`` in a Markdown table cell (its bars escaped)."""
    return text.replace("|", r"\|")


def main() -> None:
    files = held_out_files()
    if files is None:
        return
    zigzags, turns, randoms, logs = files
    t0 = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| left out | made by | 35° TD off, stbd, port [%] | steady r off, stbd, port [%] | "
          "random runs' r error std / r std (mean) | r rms error / r rms (mean) | held turns at "
          "6–16.7 rps: widest / tightest | thrust on the advance |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    summary: dict[str, dict[str, list[float]]] = {}
    with tempfile.TemporaryDirectory() as scratch:
        for left in [None, *zigzags]:
            kept = [str(p) for p in zigzags if p != left]
            label = "none" if left is None else left.stem[-8:]
            for made_by, extra in MAKERS.items():
                model = model_by_cli(["identify", *FORMAT, *extra], kept, f"{scratch}/m.json")
                if model is None:
                    print(f"| {label} | {made_by} | failed | | | | | |")
                    continue
                errors, ratios = _judged(model, turns, randoms, logs)
                std, rms = [a for a, _ in ratios], [b for _, b in ratios]
                worst, _ = _across_rps(model)
                if left is not None:
                    row = summary.setdefault(made_by, {"td": [], "r": [], "std": [], "rms": []})
                    row["td"] += [abs(x) for x in errors[0::2]]
                    row["r"] += [abs(x) for x in errors[1::2]]
                    row["std"].append(float(np.mean(std)))
                    row["rms"].append(float(np.mean(rms)))
                print(f"| {label} | {_cell(made_by)} | " + ", ".join(f"{x:+.0f}" for x in errors[0::2])
                      + " | " + ", ".join(f"{x:+.0f}" for x in errors[1::2]) + " | "
                      + ", ".join(f"{x:.2f}" for x in std) + f" ({np.mean(std):.2f}) | "
                      + ", ".join(f"{x:.2f}" for x in rms) + f" ({np.mean(rms):.2f}) | "
                      f"{worst:.2f} | " + ("no" if thrust_on_the_advance(model) is None else "yes")
                      + " |", flush=True)  # fmt: skip
    print("\nThe nine sets of eight: |error| median, mean (largest) of the 35° turns' tactical "
          "diameters and steady yaw rates; the random runs' mean over the four, median (range) "
          "over the sets\n")  # fmt: skip
    print("| made by | 35° TD off [%] | steady r off [%] | r error std / r std | "
          "r rms error / r rms |")  # fmt: skip
    print("|---|---|---|---|---|")
    for made_by, row in summary.items():
        print(f"| {_cell(made_by)} | " + " | ".join(
            f"{np.median(row[k]):.0f}, {np.mean(row[k]):.0f} ({np.max(row[k]):.0f})"
            for k in ("td", "r")) + " | " + " | ".join(
            f"{np.median(row[k]):.2f} ({np.min(row[k]):.2f}–{np.max(row[k]):.2f})"
            for k in ("std", "rms")) + " |")
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    main()

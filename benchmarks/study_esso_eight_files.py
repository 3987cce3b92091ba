"""Leave one zig-zag file out: how much the default model of the Esso Osaka's zig-zags rests on
each file (issue #10). The default ``identify`` (Δk 0.5 s) on the nine zig-zag files and on each
eight of them, judged on the logs none of them was fitted to: the two 35° turns (closed loop,
tactical diameter and steady yaw rate against the measured), the four random runs (free run, the
yaw rate's error std over its std, as the README's table has it, and its rms over r's rms, the
mean kept), the held 10° and 35° turns at 6–16.7 rps from the model's own straight speed (the
largest ratio of a turn's tactical diameter at one rps to the same turn's at another), and which
surge the fit took: a thrust riding on the advance (u·|n| > 0 against no positive n² term) is
the from-rest warning's named cause (``plausibility._thrust_on_the_advance``).

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

from shipid.identification.plausibility import _thrust_on_the_advance


def main() -> None:
    files = held_out_files()
    if files is None:
        return
    zigzags, turns, randoms, logs = files
    t0 = time.perf_counter()
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| left out | 35° TD off, stbd, port [%] | steady r off, stbd, port [%] | random runs' "
          "r error std / r std (mean) | r rms error / r rms (mean) | held turns at 6–16.7 rps: "
          "widest / tightest | thrust on the advance |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    tds, stds = [], []
    with tempfile.TemporaryDirectory() as scratch:
        for left in [None, *zigzags]:
            kept = [str(p) for p in zigzags if p != left]
            model = model_by_cli(["identify", *FORMAT], kept, f"{scratch}/m.json")
            label = "none" if left is None else left.stem[-8:]
            if model is None:
                print(f"| {label} | failed | | | | | |")
                continue
            errors, ratios = _judged(model, turns, randoms, logs)
            std, rms = [a for a, _ in ratios], [b for _, b in ratios]
            worst, _ = _across_rps(model)
            if left is not None:
                tds += [abs(x) for x in errors[0::2]]
                stds.append(float(np.mean(std)))
            print(f"| {label} | " + ", ".join(f"{x:+.0f}" for x in errors[0::2]) + " | "
                  + ", ".join(f"{x:+.0f}" for x in errors[1::2]) + " | "
                  + ", ".join(f"{x:.2f}" for x in std) + f" ({np.mean(std):.2f}) | "
                  + ", ".join(f"{x:.2f}" for x in rms) + f" ({np.mean(rms):.2f}) | {worst:.2f} | "
                  + ("yes" if _thrust_on_the_advance(model) else "no") + " |", flush=True)
    print(f"\nThe nine sets of eight: 35° tactical diameters {np.median(tds):.0f} % off in the "
          f"median (largest {np.max(tds):.0f} %); random runs' r error std / r std "
          f"{np.median(stds):.2f} in the median ({np.min(stds):.2f}–{np.max(stds):.2f}). "
          f"{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    main()

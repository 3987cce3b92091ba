"""A reference ship as the prior (``identify --prior SHIP``, issue #10 item 2): the reference's
trials fitted in the structure identified and carried to the ship's length at equal Froude
number, the LS-SVM drawn toward it. Judged on logs the models were not fitted to:

1. the Esso Osaka's nine zig-zag files one at a time (the 3 m model's length comes with its
   files), the KVLCC2 (a VLCC like the Esso) or the Mariner (a cargo liner) as the reference,
   at several γ, with the hull's cross-flow drag and with the split |v|v, |v|r; judged on the
   other eight zig-zags, the two 35° turns and the four random runs, as
   ``study_crossflow.py`` judges;
2. the real KVLCC2: identified on MARIN's 20/20 zig-zag (its particulars), judged on the −20/−20
   run and HSVA's 20/10, the KVLCC2's own MMG model as the reference.

Run: .venv/bin/python benchmarks/study_reference_prior.py
"""

from __future__ import annotations

import os
import sys
import tempfile
import time
import warnings

import numpy as np
from esso_logs import DATA
from kvlcc2_logs import kvlcc2_logs
from study_crossflow import MARIN_PARTICULARS, _fit, _median_mean
from study_esso_single_logs import _errors, _turn_errors, _validations

from shipid.data.io import write_log
from shipid.evaluation.validate import validate
from shipid.reporting.modelfile import load_model
from shipid.trials.reading import read_trial_log

CROSSFLOW = ["--model", "blanke-speed+wind", "--crossflow"]
SPLIT = ["--model", "blanke-speed+wind"]
ESSO_CONFIGS = {
    "default identify": [],
    "blanke-speed+wind --crossflow": CROSSFLOW,
    **{f"  --prior kvlcc2 --gamma {g}": [*CROSSFLOW, "--prior", "kvlcc2", "--gamma", g]
       for g in ("0.1", "1", "10", "100")},
    "  --prior mariner --gamma 1": [*CROSSFLOW, "--prior", "mariner", "--gamma", "1"],
    "blanke-speed+wind (|v|v, |v|r)": SPLIT,
    "  --prior kvlcc2 --gamma 1 ": [*SPLIT, "--prior", "kvlcc2", "--gamma", "1"],
    "  --prior kvlcc2 --gamma 100 ": [*SPLIT, "--prior", "kvlcc2", "--gamma", "100"],
}  # fmt: skip


def esso() -> None:
    zigzags = sorted((DATA / "zigzag").glob("*.csv"))
    turns = sorted((DATA / "turning").glob("*.csv"))
    held = {f: read_trial_log(f, fmt="osaka-frt") for f in zigzags + turns}
    randoms = {f: read_trial_log(f, fmt="osaka-frt") for f in sorted((DATA / "random").glob("*.csv"))}
    print("Esso Osaka, one zig-zag file at a time (9 models): held-out zig-zags' and turns' yaw "
          "rate error / spread (median of the models' medians), the two 35° turns' closed-loop "
          "tactical diameter and steady yaw rate, |error| median / mean (largest) over every "
          "model's two, the four random runs' yaw rate error / spread (median of the models' "
          "medians; diverged)\n")
    print("| made by | zig-zags and turns: r / spread | 35° TD | 35° steady r | random runs |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        out = f"{tmp}/m.json"
        for label, flags in ESSO_CONFIGS.items():
            medians, td, rate, rnd = [], [], [], []
            for z in zigzags:
                if not _fit(["identify", "--format", "osaka-frt", str(z), *flags], out):
                    print(f"| {label} | {z.name} failed | | | |")
                    continue
                model = load_model(out)
                others = {g: log for g, log in held.items() if g != z}
                runs = _validations(model, others)
                medians.append(float(np.median(_errors(runs, others))))
                turn_runs = [v for g, v in zip(others, runs, strict=True) if "turn" in g.stem]
                td.append(_turn_errors(turn_runs))
                rate.append(_turn_errors(turn_runs, "steady_yaw_rate"))
                rnd.append(_errors(_validations(model, randoms), randoms))
            rnd_all = np.concatenate(rnd)
            print(f"| {label.rstrip()} | {np.median(medians):.3f} | "
                  f"{_median_mean(np.concatenate(td))} | "
                  f"{_median_mean(np.concatenate(rate))} | "
                  f"{np.median([np.median(r) for r in rnd]):.2f}; "
                  f"{int(np.isinf(rnd_all).sum())} of {rnd_all.size} |", flush=True)  # fmt: skip


def kvlcc2() -> None:
    logs = kvlcc2_logs()
    train = "MARIN zz 20°"
    print(f"\nKVLCC2, identified on {train} (identify --dt 0.2 --crossflow, MARIN's particulars), "
          "the KVLCC2's MMG model as the reference: each held-out log's free-run error std "
          "u / v / r and closed-loop overshoots\n")
    held = [k for k in logs if k != train]
    print("| structure | prior | " + " | ".join(held) + " |")
    print("|---|---|" + "---|" * len(held))
    measured = []
    with tempfile.TemporaryDirectory() as tmp:
        path = str(write_log(logs[train], f"{tmp}/train.csv"))
        for structure in ("blanke-race+race-damping", "blanke-speed"):
            for prior in ([], ["--prior", "kvlcc2", "--gamma", "1"],
                          ["--prior", "kvlcc2", "--gamma", "100"]):  # fmt: skip
                out = f"{tmp}/m.json"
                if not _fit(["identify", path, "--model", structure, "--crossflow",
                             "--particulars", str(MARIN_PARTICULARS), *prior], out):  # fmt: skip
                    print(f"| {structure} | {' '.join(prior)} | failed |")
                    continue
                cells = []
                for name in held:
                    v = validate(load_model(out), logs[name], start_draws=False)[0]
                    m, ind = v.metrics, v.indices
                    cl, me = ind["closed_loop"], ind["measured"]
                    if len(measured) < len(held):
                        measured.append(f"{name} {me['first_overshoot_deg']:.1f}°, "
                                        f"{me['second_overshoot_deg']:.1f}°")  # fmt: skip
                    cells.append(f"{m['u']['std']:.4f} / {m['v']['std']:.4f} / "
                                 f"{m['r']['std']:.4f}, {cl['first_overshoot_deg']:.1f}°, "
                                 f"{cl['second_overshoot_deg']:.1f}°")  # fmt: skip
                print(f"| {structure} | {' '.join(prior) or 'none'} | {' | '.join(cells)} |",
                      flush=True)  # fmt: skip
    print(f"\nmeasured overshoots: {'; '.join(measured)}")


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    if not DATA.is_dir():
        print("../shared/data is absent")
        sys.exit(0)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    start = time.perf_counter()
    esso()
    kvlcc2()
    print(f"\n{time.perf_counter() - start:.0f} s")

"""The hull's cross-flow drag (``--crossflow``: one term per equation for the |v|v, |v|r, |r|r,
v|r| a structure splits the hull's nonlinear damping into) against the structures as they are,
on logs the models were not fitted to (issue #10):

1. the Esso Osaka's nine zig-zag files one at a time, as ``study_esso_single_logs.py`` reads
   them (they carry the 3 m model's length): the default ``identify`` without the drag
   (``--no-crossflow``, as before), as it is (its comparison offers the drag beside the terms and
   takes it on a tie; on one or two logs its ``select`` searches with it too) and with the drag
   in every candidate; the fixed ``blanke-speed+wind``
   without and with it; judged on the other eight zig-zags, the two 35° turns and the four
   random runs;
2. with ``pairs``: every pair of the files, the default three ways;
3. the real KVLCC2, each of its three logs left out, ``blanke-race+race-damping`` and
   ``blanke-speed`` fitted on the other two with and without it (MARIN's particulars);
4. the single-screw ``tanker`` (a truth whose hull is Norrbin's |v|v-type terms), the default
   ``identify`` three ways from its zig-zags as ``study_tanker.py`` makes them, its length
   given, 3 seeds.

Run: .venv/bin/python benchmarks/study_crossflow.py [pairs]
"""

from __future__ import annotations

import contextlib
import io
import itertools
import json
import os
import sys
import tempfile
import time
import warnings
from pathlib import Path

import numpy as np
from cli_models import model_by_cli, noisy_files
from esso_logs import DATA
from kvlcc2_logs import kvlcc2_logs
from study_esso_single_logs import _errors, _turn_errors, _validations

from shipid.cli import main as shipid
from shipid.data.io import write_log
from shipid.evaluation.validate import validate
from shipid.reporting.modelfile import load_model
from shipid.trials.reading import read_trial_log

MARIN_PARTICULARS = DATA.parent / "kvlcc2-marin" / "ship_data.yml"
# The default before the comparison offered the drag (--no-crossflow), the default, the drag in
# every candidate; then one fixed structure without and with it.
ESSO_CONFIGS = {"default --no-crossflow": ["--no-crossflow"], "default": [],
                "default --crossflow": ["--crossflow"],
                "blanke-speed+wind": ["--model", "blanke-speed+wind"],
                "blanke-speed+wind --crossflow": ["--model", "blanke-speed+wind", "--crossflow"]}


def _fit(argv: list[str], out: str) -> bool:
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        return shipid([*argv, "-o", out]) == 0


def _median_mean(errors: np.ndarray) -> str:
    finite = np.abs(errors[np.isfinite(errors)])
    none = len(errors) - len(finite)
    return (f"{np.median(finite):.0f} % / {np.mean(finite):.0f} % ({finite.max():.0f} %)"
            + (f", {none} without" if none else ""))  # fmt: skip


def esso(pairs: bool, configs: dict[str, list[str]] | None = None) -> None:
    """The Esso rows: ``configs`` ({label: identify's flags}; default ``ESSO_CONFIGS``, its
    first three for ``pairs``) from each zig-zag file alone, or from every pair."""
    zigzags = sorted((DATA / "zigzag").glob("*.csv"))
    turns = sorted((DATA / "turning").glob("*.csv"))
    held = {f: read_trial_log(f, fmt="osaka-frt") for f in zigzags + turns}
    randoms = {f: read_trial_log(f, fmt="osaka-frt") for f in sorted((DATA / "random").glob("*.csv"))}
    which = "every pair of zig-zag files (36 models)" if pairs else \
        "one zig-zag file at a time (9 models)"  # fmt: skip
    print(f"Esso Osaka, {which}: held-out zig-zags' and turns' yaw rate error / spread (median "
          "of the models' medians), the two 35° turns' closed-loop tactical diameter and steady "
          "yaw rate, |error| median / mean (largest) over every model's two, the four random "
          "runs' yaw rate error / spread (median of the models' medians; diverged)\n")
    print("| made by | zig-zags and turns: r / spread | 35° TD | 35° steady r | random runs |")
    print("|---|---|---|---|---|")
    if configs is None:
        configs = ESSO_CONFIGS if not pairs else \
            {k: ESSO_CONFIGS[k] for k in list(ESSO_CONFIGS)[:3]}  # fmt: skip
    with tempfile.TemporaryDirectory() as tmp:
        out = f"{tmp}/m.json"
        trainings = [[z] for z in zigzags]
        if pairs:
            trainings = [list(p) for p in itertools.combinations(zigzags, 2)]
        for label, flags in configs.items():
            medians, td, rate, rnd = [], [], [], []
            for files in trainings:
                if not _fit(["identify", "--format", "osaka-frt", *map(str, files), *flags], out):
                    print(f"| {label.rstrip()} | {files} failed | | | |")
                    continue
                model = load_model(out)
                others = {g: log for g, log in held.items() if g not in files}
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
    print("\nKVLCC2, each real log left out, the structure fitted on the other two (identify "
          "--dt 0.2, its prefilter): the held-out log's free-run error std u / v / r and its "
          "closed-loop overshoots\n")
    print("| structure | held out | overshoots measured | without: error std, closed loop | "
          "--crossflow: error std, closed loop |")
    print("|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        paths = {name: str(write_log(log, f"{tmp}/log{i}.csv"))
                 for i, (name, log) in enumerate(logs.items())}  # fmt: skip
        for structure in ("blanke-race+race-damping", "blanke-speed"):
            for held_out, log in logs.items():
                train = [p for n, p in paths.items() if n != held_out]
                cells, measured = [], ""
                for flags in ([], ["--crossflow", "--particulars", str(MARIN_PARTICULARS)]):
                    out = f"{tmp}/m.json"
                    if not _fit(["identify", *train, "--model", structure, *flags], out):
                        cells.append("failed")
                        continue
                    v = validate(load_model(out), log, start_draws=False)[0]
                    m, ind = v.metrics, v.indices
                    measured = (f"{ind['measured']['first_overshoot_deg']:.1f}°, "
                                f"{ind['measured']['second_overshoot_deg']:.1f}°")
                    cl = ind["closed_loop"]
                    cells.append(f"{m['u']['std']:.4f} / {m['v']['std']:.4f} / "
                                 f"{m['r']['std']:.4f}, {cl['first_overshoot_deg']:.1f}°, "
                                 f"{cl['second_overshoot_deg']:.1f}°")  # fmt: skip
                print(f"| {structure} | {held_out} | {measured} | {' | '.join(cells)} |",
                      flush=True)  # fmt: skip


def tanker(seeds: int = 3) -> None:
    import study_tanker as st

    clean, truth = st.trials(), st.truth_indices()
    print("\nThe tanker (truth of Norrbin's form; study_tanker.py's logs at the sea sensors' "
          "noise, with its length, 304.8 m, as particulars), the default identify, without the "
          f"drag, comparing it and with it in every candidate, over {seeds} seeds: 35° TD and "
          "steady r |error| median (largest), 20° TD error median, 10°/10° worst overshoot "
          "error median (largest)\n")
    print("| trained on | made by | 35° TD | 35° steady r | 20° TD | 10°/10° |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        particulars = Path(tmp) / "tanker.json"
        particulars.write_text(json.dumps({"length": 304.8}))
        rows: dict[tuple[str, str], list[dict]] = {}
        for seed in range(seeds):
            paths = noisy_files(clean, st.SEA_SENSORS, seed, tmp)
            for label in list(st.TRAINING)[:2]:
                files = [paths[f"{n}_{rpm}"] for n, rpm in st.TRAINING[label]]
                for made, flags in (("identify --no-crossflow", ["--no-crossflow"]),
                                    ("identify", []), ("identify --crossflow", ["--crossflow"])):
                    model = model_by_cli(["identify", "--particulars", str(particulars), *flags],
                                         files, f"{tmp}/model.json")  # fmt: skip
                    if model is not None:
                        rows.setdefault((label, made), []).append(st.judged(model, truth))
        for (label, made), judged in rows.items():
            print(f"| {label} | {made} | " + " | ".join(st.summary(judged)) + " |")


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    if not DATA.is_dir():
        print("../shared/data is absent")
        sys.exit(0)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    start = time.perf_counter()
    esso("pairs" in sys.argv[1:])
    kvlcc2()
    tanker()
    print(f"\n{time.perf_counter() - start:.0f} s")

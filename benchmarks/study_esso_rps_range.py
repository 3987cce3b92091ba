"""Issue #10's acceptance on the Esso Osaka: with constraints, no identified model turns the wrong
way or loses its steady speed under 35° rudder at 8–16.7 rps.

Models made by the command line on the raw files (``--format osaka-frt --dt 0.5``), each with
and without ``--constraints signs``: a plain ``shipid identify`` of every zig-zag file alone,
of every pair of them, of the nine zig-zags with three random runs (the README's fold) and of
all fifteen logs, and the README's recipe (``select --library
low-speed+wind+propeller-asymmetry --average``) on the README's fold. Each model's 35° rudder
is held to either side at 8, 10, 12, 15 and 16.7 rps, from its own steady straight speed there
(``plausibility_at_approach``, the checks ``identify`` runs at the logs' rps): a turn that
diverges, turns the other way, ends going astern, all but stops, runs away when entered
drifting, or runs on a path far wider or tighter than the logs' is counted, by what it does.
The pairs (no constraints) are also judged on the logs they were not fitted to, as
``study_esso_single_logs.py`` judges them: the other seven zig-zags and the two turns (yaw rate
error over the spread), the four random runs read whole, the turns' tactical diameters at 10 rps
(closed loop).
Run as a script: ``python benchmarks/study_esso_rps_range.py [--no-pairs]``.
"""

from __future__ import annotations

import itertools
import os
import sys
import tempfile
import time
from collections import Counter
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from cli_models import model_by_cli  # noqa: E402
from esso_logs import README_HELD, ZIGZAGS, raw_files  # noqa: E402
from study_esso_single_logs import _errors, _turn_cell, _turn_errors, _validations  # noqa: E402

from shipid.identification.plausibility import (  # noqa: E402
    WRONG_WAY,
    failed_checks,
    plausibility_at_approach,
)
from shipid.reporting.modelfile import load_document, training_conditions  # noqa: E402

RPS = (8.0, 10.0, 12.0, 15.0, 16.67)
FORMAT = ["--format", "osaka-frt", "--dt", "0.5"]
RECIPE = ["--library", "low-speed+wind+propeller-asymmetry", "--quiet", "--average"]
# What a held turn that fails does, read off its warning.
KINDS = (("diverge", "diverges"), ("other way", "turns the other way"),
         ("astern", "ends going astern"), ("all but stops", "all but stops"),
         ("runs away", "runs away"), ("path", "path far wider or tighter"))  # fmt: skip


def what_it_does(note: str) -> str:
    return next((label for key, label in KINDS if key in note), "diverges")


def judged(path: str) -> tuple[int, Counter, set[float]]:
    """(held turns judged, Counter of what the failing ones do, the rps they fail at) over
    ``RPS`` × both sides."""
    from shipid.reporting.modelfile import model_from_document

    doc = load_document(path)
    model = model_from_document(doc, path, "model")
    cond = training_conditions(doc)
    speed, rps0 = cond.get("speed"), cond.get("rps")
    failures: Counter = Counter()
    at: set[float] = set()
    for rps in RPS:
        report, _ = plausibility_at_approach(model, speed, rps0, rps=rps)
        for key, (severity, note) in failed_checks(report, model).items():
            if key.startswith("held_rudder") and severity >= WRONG_WAY:
                failures[what_it_does(note)] += 1
                at.add(rps)
    return 2 * len(RPS), failures, at


def warned(path: str, train: list[Path]) -> dict[str, bool]:
    """Whether ``identify``'s warnings below and above the logs' propeller speeds fire on the
    model of ``path`` (trained on ``train``)."""
    from shipid.identification.beyond_the_logs import above_the_logs_rps, below_the_logs_rps
    from shipid.reporting.modelfile import model_from_document
    from shipid.trials.reading import read_trial_log

    doc = load_document(path)
    model = model_from_document(doc, path, "model")
    cond = training_conditions(doc)
    report, _ = plausibility_at_approach(model, cond.get("speed"), cond.get("rps"))
    logs = [read_trial_log(p, fmt="osaka-frt") for p in train]
    return {"below": below_the_logs_rps(model, report, logs) is not None,
            "above": above_the_logs_rps(model, report, logs) is not None}  # fmt: skip


def main() -> None:
    files = raw_files()
    if files is None:
        return
    zigzags, turns, randoms = files
    readme = [*zigzags, *(r for r in randoms if README_HELD not in r.name)]
    sets = [("each zig-zag file alone", "identify", [[z] for z in zigzags])]
    if "--no-pairs" not in sys.argv:
        sets.append(("every pair of zig-zag files", "identify",
                     [list(p) for p in itertools.combinations(zigzags, 2)]))  # fmt: skip
    sets += [("nine zig-zags and three random runs", "identify", [readme]),
             ("nine zig-zags and three random runs", "select (README)", [readme]),
             ("all fifteen logs", "identify", [[*zigzags, *randoms, *turns]])]
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print(f"35° rudder held to either side at {', '.join(f'{r:g}' for r in RPS)} rps, from each "
          "model's own steady straight speed there: the held turns that fail, by what they do\n")
    print("| trained on | made by | constraints | models | held turns | failing | models with "
          "one | what the failing turns do |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    t0 = time.perf_counter()
    beyond = Counter()  # the pairs: failing beyond their logs' rps, against the warnings
    judged_on = _held_out_logs(zigzags, turns, randoms) if "--no-pairs" not in sys.argv else None
    predictions = []  # the pairs': (held-out logs' median, random runs' median, turns, diverged)
    with tempfile.TemporaryDirectory() as scratch:
        for label, maker, trainings in sets:
            for constraints in ([], ["--constraints", "signs"]):
                argv = (["identify", *FORMAT] if maker == "identify"
                        else ["select", *FORMAT, *RECIPE]) + constraints  # fmt: skip
                turns_judged, failing, models, with_one, made = 0, Counter(), 0, 0, 0
                for train in trainings:
                    out = f"{scratch}/m.json"
                    if model_by_cli(argv, [str(p) for p in train], out) is None:
                        continue
                    made += 1
                    n, fails, at = judged(out)
                    turns_judged += n
                    failing += fails
                    with_one += bool(fails)
                    if len(train) == 2 and not constraints:
                        rps = [ZIGZAGS[p.stem[-8:]][1] for p in train]
                        side = {"below": any(n < 0.95 * min(rps) for n in at),
                                "above": any(n > 1.05 * max(rps) for n in at)}  # fmt: skip
                        said = warned(out, train)
                        for k in ("below", "above"):
                            beyond[(k, side[k], said[k])] += 1
                        predictions.append(_predictions(out, train, *judged_on))
                models = f"{made}" + (f" of {len(trainings)}" if made < len(trainings) else "")
                does = ", ".join(f"{k} {v}" for k, v in failing.most_common()) or "–"
                print(f"| {label} | {maker} | {'signs' if constraints else 'none'} | {models} | "
                      f"{turns_judged} | {sum(failing.values())} | {with_one} | {does} |")
                sys.stdout.flush()
    if beyond:
        print("\nThe pairs (no constraints): models whose held turns fail beyond their logs' "
              "propeller speeds, and identify's warnings below (0.6 of the lowest) and above "
              "(1.4 times the highest) them\n")  # fmt: skip
        print("| beyond the logs' rps | fails there, warned | fails there, not warned | "
              "does not fail there, warned |")  # fmt: skip
        print("|---|---|---|---|")
        for k in ("below", "above"):
            print(f"| {k} | {beyond[(k, True, True)]} | {beyond[(k, True, False)]} | "
                  f"{beyond[(k, False, True)]} |")
    if predictions:
        held = [p[0] for p in predictions]
        turns_off = np.abs(np.concatenate([p[2] for p in predictions]))
        finite = turns_off[np.isfinite(turns_off)]
        print(f"\nThe pairs (no constraints) on the logs they were not fitted to: held-out "
              f"zig-zags and turns r error / spread {np.median(held):.3f} (median of the pairs' "
              f"medians); the random runs' {np.median([p[1] for p in predictions]):.2f}; the 35° "
              f"turns' tactical diameter {_turn_cell(turns_off)}, mean {np.mean(finite):.0f} %; "
              f"runs diverged {sum(p[3] for p in predictions)}")  # fmt: skip
    print(f"\n{time.perf_counter() - t0:.0f} s")


def _held_out_logs(zigzags, turns, randoms):
    """({path: log} of the zig-zags and turns, of the random runs), as the commands read them."""
    from shipid.trials.reading import read_trial_log

    held = {f: read_trial_log(f, fmt="osaka-frt") for f in [*zigzags, *turns]}
    return held, {f: read_trial_log(f, fmt="osaka-frt") for f in randoms}


def _predictions(path: str, train, held, randoms):
    """(held-out zig-zags' and turns' median r error / spread, the random runs' median, the
    turns' tactical diameter errors [%], runs diverged) of the model of ``path``."""
    from shipid.reporting.modelfile import load_model

    model = load_model(path)
    others = {g: log for g, log in held.items() if g not in train}
    runs = _validations(model, others)
    errors, rnd = _errors(runs, others), _errors(_validations(model, randoms), randoms)
    turns = _turn_errors([v for g, v in zip(others, runs, strict=True) if "turn" in g.stem])
    return (float(np.median(errors)), float(np.median(rnd)), turns,
            int(np.isinf(errors).sum() + np.isinf(rnd).sum()))  # fmt: skip


if __name__ == "__main__":
    main()

"""The published KVLCC2 MMG model against the models identified from the real runs (issue #10:
the baseline an identified model has to beat), and the MMG model corrected by the runs. The MMG
model (reference-ships.md §2, Yasukawa & Yoshimura 2015: a fit to captive tests, ``shipid
validate kvlcc2``), the default ``shipid identify`` on one and on two of the KVLCC2's three real
zig-zags (MARIN's ±20° at 1:45.7, HSVA's 20/10), and the MMG model with an LS-SVM correction
fitted to the same runs (``shipid correct``, `blanke-race` terms, the 1.25 Hz prefilter
``identify`` chooses for these runs; γ 1e4, 100, and chosen by the free runs of held-out blocks
or logs of the training runs), each judged on the runs it was not fitted to: the free run's
yaw-rate error std (rad/s) and the zig-zag's overshoots run closed loop, against the measured.

Run: .venv/bin/python benchmarks/study_kvlcc2_mmg_baseline.py
"""

from __future__ import annotations

import contextlib
import io
import itertools
import os
import tempfile
import time
import warnings

import numpy as np
from kvlcc2_logs import DATA, kvlcc2_logs

from shipid.cli import main as shipid
from shipid.data.io import write_log
from shipid.data.log import common_rudder_convention
from shipid.evaluation.validate import validate
from shipid.identification.correction import identify_correction
from shipid.reporting.modelfile import load_document, model_from_document, training_conditions
from shipid.vessels import get_vessel

OVERSHOOTS = ("first_overshoot_deg", "second_overshoot_deg")
# The correction's structure, prefilter (what ``identify`` chooses for these runs) and γs.
CORRECTION, CORRECTION_HZ, CORRECTION_GAMMAS = "blanke-race", 1.25, (1e4, 1e2, "auto")


def _judged(model, log, name: str, side: str | None) -> tuple[float, list[float], list[float]]:
    """(r error std, closed-loop overshoots, measured overshoots) of ``model`` on ``log``, the
    log in the model's rudder convention ``side`` (a reference ship turns it itself)."""
    if side is not None:
        (log,), _ = common_rudder_convention([log], side)
    v = validate(model, [log], [name], start_draws=False)[0]
    closed, measured = v.indices["closed_loop"], v.indices["measured"]
    return (v.metrics["r"]["std"], [closed.get(k, np.nan) for k in OVERSHOOTS],
            [measured[k] for k in OVERSHOOTS])  # fmt: skip


def _identified(paths: list[str], out: str):
    """The default ``shipid identify`` of canonical log files: (model, its rudder convention)."""
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        code = shipid(["identify", *paths, "-o", out])
    if code:
        return None, None
    doc = load_document(out)
    return model_from_document(doc, out), training_conditions(doc)["rudder_positive"]


def _label(gamma) -> str:
    return f"MMG model + correction, γ {gamma if isinstance(gamma, str) else f'{gamma:g}'}"


def _cell(r: float, closed: list[float], measured: list[float]) -> str:
    miss = ", ".join(f"{c - m:+.1f}°" for c, m in zip(closed, measured, strict=True))
    return f"{r:.5f}; {closed[0]:.1f}°, {closed[1]:.1f}° ({miss})"


def main() -> None:
    warnings.simplefilter("ignore")  # the MARIN yaw rate's offset (study_gyro_offset.py)
    if not DATA.is_dir():
        print("../shared/data is absent")
        return
    t0 = time.perf_counter()
    logs = kvlcc2_logs()
    mmg = get_vessel("kvlcc2")
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| held out | measured overshoots | MMG model: r error std [rad/s]; closed-loop "
          "overshoots (miss) | trained on | identified: r error std; closed-loop overshoots "
          "(miss) | " + " | ".join(_label(g) for g in CORRECTION_GAMMAS)
          + " |")  # fmt: skip
    print("|---|---|---|---|---|" + "---|" * len(CORRECTION_GAMMAS))
    scores: dict[str, list[tuple[float, list[float]]]] = {"MMG model": [], "one run": [],
                                                           "two runs": []}  # fmt: skip
    for gamma in CORRECTION_GAMMAS:
        scores[_label(gamma)] = []
    with tempfile.TemporaryDirectory() as folder:
        files = {name: str(write_log(log, f"{folder}/{i}.csv"))
                 for i, (name, log) in enumerate(logs.items())}  # fmt: skip
        fits = {}
        for k in (1, 2):
            for train in itertools.combinations(logs, k):
                fits[train] = _identified([files[n] for n in train], f"{folder}/m.json")
        for held, log in logs.items():
            r, closed, measured = _judged(mmg, log, held, None)
            scores["MMG model"].append((r, np.subtract(closed, measured)))
            first = True
            for train, (model, side) in fits.items():
                if held in train:
                    continue
                label = " and ".join(train)
                if model is None:
                    print(f"| {held} | | | {label} | failed |")
                    continue
                fr, fc, _ = _judged(model, log, held, side)
                scores["one run" if len(train) == 1 else "two runs"].append(
                    (fr, np.subtract(fc, measured)))  # fmt: skip
                lead = (f"| {held} | {measured[0]:.1f}°, {measured[1]:.1f}° | "
                        f"{_cell(r, closed, measured)} " if first else "| | | ")
                cells = [_cell(fr, fc, measured)]
                for gamma in CORRECTION_GAMMAS:
                    fit = identify_correction([logs[n] for n in train], mmg, CORRECTION, gamma,
                                              filter_hz=CORRECTION_HZ)  # fmt: skip
                    cr, cc, _ = _judged(fit.vessel, log, held, None)
                    scores[_label(gamma)].append(
                        (cr, np.subtract(cc, measured)))  # fmt: skip
                    cells.append(_cell(cr, cc, measured))
                print(f"{lead}| {label} | " + " | ".join(cells) + " |")
                first = False
    print("\n| model | held-out runs | r error std, mean [rad/s] | overshoots' miss, mean |abs| "
          "(largest) |")  # fmt: skip
    print("|---|---|---|---|")
    for label, rows in scores.items():
        r = np.mean([x for x, _ in rows])
        miss = np.abs(np.concatenate([m for _, m in rows]))
        print(f"| {label} | {len(rows)} | {r:.5f} | {np.nanmean(miss):.2f}° ({np.nanmax(miss):.2f}°) |")
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()

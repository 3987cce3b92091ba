"""The sign table (``--constraints signs``) on the Esso Osaka's pairs of zig-zag files (issue #10,
predicting unseen manoeuvres). Each pair's default ``identify``, with and without the table,
judged on what it was not fitted to: the four random runs (a third of their time astern, the
propeller from −10 to +10 rps), the other seven zig-zags and the two 35° turns at 10 rps (closed
loop tactical diameters), and the crash stop ``identify`` runs. Pairs at two propeller speeds
get terms chosen from the ``low-speed`` library, which holds the thrust's fall with the advance
(u·|n|); its row in the table (≤ 0) is the one this study was written for.

Run: .venv/bin/python benchmarks/study_sign_table.py
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
from esso_logs import trial_files

from shipid.cli import main as shipid
from shipid.evaluation.validate import validate
from shipid.reporting.modelfile import load_document, load_model

VARIANTS = {"default": [], "--constraints signs": ["--constraints", "signs"]}


def _judge(paths: list, extra: list[str], held: dict, out: str) -> dict | None:
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        if shipid(["identify", "--format", "osaka-frt", *map(str, paths), *extra, "-o", out]):
            return None
    model, doc = load_model(out), load_document(out)
    found = {"random": [], "ahead": [], "td": []}
    for p, log in held.items():
        if p in paths:
            continue
        run = validate(model, log, start_draws=False)[0]
        bad = run.error is not None or run.simulation is None or run.simulation.diverged
        ratio = np.inf if bad else float(run.metrics["r"]["std"] / np.std(log["r"]))
        found["random" if "random" in p.name else "ahead"].append(ratio)
        if "turn" in p.name:
            measured, closed = run.indices["measured"], run.indices.get("closed_loop") or {}
            try:
                found["td"].append(100 * (closed["tactical_diameter"]
                                          / measured["tactical_diameter"] - 1))  # fmt: skip
            except (KeyError, TypeError):
                found["td"].append(np.inf)
    astern = doc["identification"].get("plausibility", {}).get("astern") or {}
    found["stop"] = bool(astern.get("diverged"))
    found["library"] = "select" in model.structure.name  # terms select chose, or their average
    return found


def main() -> None:
    warnings.simplefilter("ignore")
    files = trial_files()
    if files is None:
        return
    zigzags, held = files
    pairs = [list(p) for p in itertools.combinations(zigzags, 2)]
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print(f"Each pair of zig-zag files ({len(pairs)} models); every figure on logs the model was "
          "not fitted to (medians over each model's logs, then over the models)\n")
    print("| fitted | random runs: r error / spread | runs diverged | zig-zags and turns: r error "
          "/ spread | 35° TD \\|error\\| median / mean (largest) | crash stops diverged | "
          "models from the library | s |")
    print("|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for label, extra in VARIANTS.items():
            t0 = time.perf_counter()
            rows = [r for r in (_judge(p, extra, held, f"{tmp}/m.json") for p in pairs) if r]
            runs = [x for r in rows for x in r["random"]]
            td = np.abs([x for r in rows for x in r["td"]])
            finite = td[np.isfinite(td)]
            print(f"| {label} | {np.median([np.median(r['random']) for r in rows]):.2f} | "
                  f"{sum(np.isinf(runs))} of {len(runs)} | "
                  f"{np.median([np.median(r['ahead']) for r in rows]):.3f} | "
                  f"{np.median(td):.0f} % / {finite.mean():.0f} % ({finite.max():.0f} %"
                  f"{f', {td.size - finite.size} without' if td.size > finite.size else ''}) | "
                  f"{sum(r['stop'] for r in rows)} of {len(rows)} | "
                  f"{sum(r['library'] for r in rows)} | {time.perf_counter() - t0:.0f} |",
                  flush=True)  # fmt: skip


if __name__ == "__main__":
    main()

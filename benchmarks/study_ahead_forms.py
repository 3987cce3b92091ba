"""Going astern on a model of logs that never do (issue #10, predicting unseen manoeuvres):
``identify`` writes such a model's u·v, u·r, u²δ, u²δ² in their ahead forms (|u|·v, |u|·r,
|u|·u·δ, |u|·u·δ²; ``shipid.dynamics.astern``), the same fit wherever u ≥ 0. Judged on the Esso
Osaka's four random runs (a third of their time astern, the propeller from −10 to +10 rps),
which no zig-zag file shows:

1. the default ``identify`` of each zig-zag file alone, with and without (``--no-ahead-forms``):
   the random runs' yaw-rate error over their spread (median of each model's four, then over
   the models), how many of the 36 runs diverge, and the zig-zags' and turns' errors, which
   must not move (ahead, the two forms are one term);
2. the same for each pair of files (36 models, 144 runs), and the nine files together;
3. the crash stop ``identify`` runs on each model (full astern from the approach).

Every figure is on logs the models were not fitted to.

Run: .venv/bin/python benchmarks/study_ahead_forms.py [pairs]
"""

from __future__ import annotations

import contextlib
import io
import itertools
import os
import sys
import tempfile
import time
import warnings

import numpy as np
from esso_logs import trial_files

from shipid.cli import main as shipid
from shipid.evaluation.validate import validate
from shipid.identification.plausibility import crash_stop
from shipid.reporting.modelfile import load_document, load_model

VARIANTS = {"ahead forms (default)": [], "fitted forms (--no-ahead-forms)": ["--no-ahead-forms"]}


def _ratio(model, log) -> float:
    """The free run's yaw-rate error std over the log's spread; inf where it diverges."""
    run = validate(model, log, start_draws=False)[0]
    if run.simulation is None or run.simulation.diverged:
        return np.inf
    return float(run.metrics["r"]["std"] / np.std(log["r"]))


def _judge(paths: list, extra: list[str], held: dict, tmp: str) -> dict | None:
    out = os.path.join(tmp, "m.json")
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        if shipid(["identify", "--format", "osaka-frt", *map(str, paths), *extra, "-o", out]):
            return None
    model = load_model(out)
    doc = load_document(out)
    prep = doc["identification"]["preprocessing"]
    names = {p.name for p in paths}
    rnd = [_ratio(model, log) for p, log in held.items() if "random" in p.name]
    ahead = [_ratio(model, log) for p, log in held.items()
             if "random" not in p.name and p.name not in names]  # fmt: skip
    stop = crash_stop(model, prep["approach_speed"], prep.get("approach_rps") or
                      float(np.median(held[paths[0]]["n"])))  # fmt: skip
    return {"random": rnd, "ahead": ahead, "stop": bool(stop and stop["diverged"]),
            "written": "ahead_forms" in doc["identification"]}


def _table(title: str, cases: list[list], held: dict) -> None:
    print(f"\n{title} ({len(cases)} models)\n")
    print("| written in | random runs: r error / spread | runs diverged | zig-zags and turns "
          "held out: r error / spread | crash stops diverged | models in ahead forms | s |")
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for label, extra in VARIANTS.items():
            t0 = time.perf_counter()
            rows = [r for r in (_judge(c, extra, held, tmp) for c in cases) if r is not None]
            rnd = [np.median(r["random"]) for r in rows]
            runs = [x for r in rows for x in r["random"]]
            ahead = [np.median(r["ahead"]) for r in rows]
            print(f"| {label} | {np.median(rnd):.2f} | {sum(np.isinf(runs))} of {len(runs)} | "
                  f"{np.median(ahead):.4f} | {sum(r['stop'] for r in rows)} of {len(rows)} | "
                  f"{sum(r['written'] for r in rows)} | {time.perf_counter() - t0:.0f} |",
                  flush=True)  # fmt: skip


def main(pairs: bool) -> None:
    warnings.simplefilter("ignore")
    files = trial_files()
    if files is None:
        return
    zigzags, held = files
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    _table("Each zig-zag file alone", [[z] for z in zigzags], held)
    _table("The nine zig-zag files together", [zigzags], held)
    if pairs:
        _table("Each pair of zig-zag files", [list(p) for p in
                                              itertools.combinations(zigzags, 2)], held)


if __name__ == "__main__":
    main("pairs" in sys.argv[1:])

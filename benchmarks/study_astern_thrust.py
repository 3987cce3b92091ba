"""The propeller reversed on a model of logs that never reverse it (issue #10, predicting unseen
manoeuvres): ``identify`` writes such a model's thrust, pos(n)² or |n|·n in the surge, as
``propeller(k)``, n² ahead and −k·n² astern (``shipid.dynamics.astern``), the same fit wherever
n ≥ 0. What k? The Esso Osaka's four random runs reverse the propeller for 16–36 % of their
samples, which no zig-zag file does; no model here is fitted to them.

1. The nine zig-zag files together (the default ``identify``, with ``--astern-thrust none``: its
   thrust as fitted, pos(n)², which coasts when reversed): each random run's rms free-run error
   over its spread (u, v, r) for k from 0 to 1.2; then k chosen by the mean error over u, v and
   r of three runs, judged on the fourth (leave one run out).
2. Each zig-zag file alone (one rps: advance-ratio similarity writes its thrust |n|·n, k = 1 as
   fitted): the same, the medians over the nine models.

Every figure is on logs the models were not fitted to; the default k
(``shipid.dynamics.propeller.ASTERN_THRUST_RATIO``) is what part 1's folds choose.

Run: .venv/bin/python benchmarks/study_astern_thrust.py
"""

from __future__ import annotations

import contextlib
import io
import os
import tempfile
import time
import warnings

import numpy as np
from esso_logs import DATA, read

from shipid.cli import main as shipid
from shipid.dynamics.astern import AsternForms
from shipid.dynamics.propeller import ASTERN_THRUST_RATIO
from shipid.evaluation.validate import validate
from shipid.reporting.modelfile import load_document, load_model

RATIOS = [round(0.1 * i, 1) for i in range(13)]
STATES = ("u", "v", "r")


def _errors(model, log) -> np.ndarray:
    """(u, v, r) rms free-run error over the log's spread; inf where the run diverges."""
    run = validate(model, log, start_draws=False)[0]
    if run.simulation is None or run.simulation.diverged:
        return np.full(3, np.inf)
    return np.array([run.metrics[s]["rmse"] / np.std(log[s].to_numpy()) for s in STATES])


def _model(paths, tmp: str):
    """The default ``identify`` of ``paths`` with its thrust as fitted, and its Δk."""
    out = os.path.join(tmp, "m.json")
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        code = shipid(["identify", "--format", "osaka-frt", *map(str, paths),
                       "--astern-thrust", "none", "-o", out])  # fmt: skip
    if code:
        raise SystemExit(f"identify failed on {[p.name for p in paths]}")
    return load_model(out), load_document(out)["identification"]["dt"]


def _grid(model, logs: dict) -> dict:
    """{k or None (as fitted): {run: (u, v, r) errors}}."""
    out = {None: {name: _errors(model, log) for name, log in logs.items()}}
    for k in RATIOS:
        written = AsternForms(thrust_ratio=k).written(model)
        out[k] = {name: _errors(written, log) for name, log in logs.items()}
    return out


def _fmt(e: np.ndarray) -> str:
    return " / ".join("∞" if not np.isfinite(x) else f"{x:.2f}" for x in e)


def _folds(grid: dict, runs: list[str]) -> list[tuple[str, float, np.ndarray]]:
    """Leave one run out: (held-out run, k chosen on the others, its errors there)."""
    out = []
    for held in runs:
        others = [r for r in runs if r != held]
        k = min(RATIOS, key=lambda k: np.mean([grid[k][r] for r in others]))
        out.append((held, k, grid[k][held]))
    return out


def main() -> None:
    warnings.simplefilter("ignore")
    if not DATA.is_dir():
        print("../shared/data is absent")
        return
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores; default ratio "
          f"{ASTERN_THRUST_RATIO:g}")
    zigzags = sorted((DATA / "zigzag").glob("*.csv"))
    randoms = sorted((DATA / "random").glob("*.csv"))
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        model, dt = _model(zigzags, tmp)
        logs = {p.stem[7:]: read(p, False, dt) for p in randoms}
        runs = list(logs)
        grid = _grid(model, logs)
        print("\n1. The nine zig-zag files' model (thrust as fitted: "
              f"{', '.join(model.structure.terms['u'])})\n")
        print("| k | " + " | ".join(runs) + " | mean |")
        print("|---|" + "---|" * (len(runs) + 1))
        for k, row in grid.items():
            mean = np.mean([row[r] for r in runs], axis=0)
            print(f"| {'as fitted' if k is None else k} | "
                  + " | ".join(_fmt(row[r]) for r in runs) + f" | {_fmt(mean)} |")
        print("\nLeave one run out (k chosen by the mean u, v, r error of the other three):\n")
        print("| held-out run | k chosen | u / v / r error / spread | as fitted | "
              f"k = {ASTERN_THRUST_RATIO:g} |")
        print("|---|---|---|---|---|")
        for held, k, e in _folds(grid, runs):
            print(f"| {held} | {k:g} | {_fmt(e)} | {_fmt(grid[None][held])} | "
                  f"{_fmt(grid[ASTERN_THRUST_RATIO][held])} |")
        print("\n2. Each zig-zag file alone (thrust as fitted: |n|·n, mirrored astern); median "
              "over the nine models of each run's error, then over the runs\n")
        grids = []
        for z in zigzags:
            one, dt_one = _model([z], tmp)
            one_logs = {p.stem[7:]: read(p, False, dt_one) for p in randoms}
            grids.append(_grid(one, one_logs))
        print("| k | u / v / r error / spread (median of 36) | runs diverged |")
        print("|---|---|---|")
        for k in [None, *RATIOS]:
            errs = np.array([g[k][r] for g in grids for r in runs])
            print(f"| {'as fitted' if k is None else k} | {_fmt(np.median(errs, axis=0))} | "
                  f"{int(np.sum(~np.isfinite(errs[:, 0])))} of {len(errs)} |")
        folds = [f for g in grids for f in _folds(g, runs)]
        chosen = [k for _, k, _ in folds]
        print(f"\nLeave one run out per model: k chosen {min(chosen):g}–{max(chosen):g} "
              f"(median {np.median(chosen):g}); the held-out runs' median error "
              f"{_fmt(np.median([e for *_, e in folds], axis=0))}")
    print(f"\n{time.perf_counter() - t0:.0f} s")


if __name__ == "__main__":
    main()

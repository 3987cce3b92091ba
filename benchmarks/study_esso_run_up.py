"""Does a zig-zag's run-up tell the surge what its cut leaves out (issue #10)? Most Esso Osaka
zig-zag files start from rest with the propeller already at its setpoint: the ship gathers speed
for 20–40 s before the first rudder order, a record of thrust against resistance that
``identify`` cuts away (``--start auto``: 5 s before the execute). Here the default model of
every pair of zig-zag files, its surge refitted (the same terms, prefilter and γ; sway and yaw
as they are) on the cut logs and on the logs from where the propeller reaches its setpoint
(the run-up kept), and the same with the thrust's fall with the advance (``u·n⁺``) added for
the low speeds of the run-up. Judged on what none was fitted to: the two 35° turns' tactical
diameters (closed loop, ``validate``), the four random runs' yaw rate (free-run error std over
the run's spread) and the straight speed the surge balances at the turns' 10 rps, against the
turns' measured approach.

Run: .venv/bin/python benchmarks/study_esso_run_up.py
"""

from __future__ import annotations

import contextlib
import io
import itertools
import json
import warnings
from pathlib import Path

import numpy as np
from esso_logs import DATA, run_with_files
from study_esso_single_logs import _errors, _turn_errors, _validations

from shipid.cli import main as shipid
from shipid.data.io import read_log
from shipid.data.preprocess import lowpass
from shipid.dynamics.equilibrium import surge_equilibrium
from shipid.dynamics.model import ManoeuvringModel, parse_structure_spec
from shipid.identification.identify import identify
from shipid.reporting.modelfile import load_model
from shipid.trials.reading import read_trial_log

# The propeller is at its setpoint where it is within this share of the manoeuvre's median.
SETPOINT_SHARE = 0.03
THRUST_SLOPE = "u*pos(n)"
VARIANTS = ("the default (identify)", "surge refitted on the cut logs",
            "surge refitted with the run-up", f"… with {THRUST_SLOPE}",
            f"surge refitted on the cut logs with {THRUST_SLOPE}")  # fmt: skip


def from_setpoint(path: Path, cut):
    """The whole log of ``path`` from the last sample before the cut whose propeller speed is
    off the cut's median by more than ``SETPOINT_SHARE`` (its time from 0)."""
    whole = read_log(path, fmt="osaka-frt")
    setpoint = float(np.median(cut["n"]))
    before = whole["t"].to_numpy() < float(cut["t"].iloc[0])
    off = np.flatnonzero(before & (np.abs(whole["n"].to_numpy() - setpoint)
                                   > SETPOINT_SHARE * setpoint))  # fmt: skip
    log = whole.iloc[off[-1] + 1 if off.size else 0:].reset_index(drop=True)
    log.attrs = dict(whole.attrs)
    log["t"] = log["t"] - log["t"].iloc[0]
    return log


def refit_surge(model, doc: dict, logs, slope: bool) -> ManoeuvringModel:
    """``model`` with its surge refitted on ``logs`` as the file's fit was made (prefilter, γ),
    ``THRUST_SLOPE`` added with ``slope``; sway and yaw kept."""
    hz = doc["identification"]["preprocessing"].get("filter_hz")
    logs = [lowpass(log, hz) if hz else log for log in logs]
    surge = list(model.structure.terms["u"])
    if slope and THRUST_SLOPE not in surge:
        surge.append(THRUST_SLOPE)
    spec = f"u: {', '.join(surge)}; v: v, r, 1; r: v, r, 1"  # sway and yaw are not used
    fit = identify(logs, parse_structure_spec(spec), gamma=doc["identification"]["gamma"],
                   force=True).model  # fmt: skip
    terms = {d: list(t) for d, t in model.structure.terms.items()}
    terms["u"] = list(fit.coefficients["u"])
    coefficients = {d: dict(c) for d, c in model.coefficients.items()}
    coefficients["u"] = dict(fit.coefficients["u"])
    structure = parse_structure_spec("; ".join(f"{d}: {', '.join(t)}" for d, t in terms.items()))
    return ManoeuvringModel(structure, coefficients, name=model.name)


def study(folder: Path) -> None:
    warnings.simplefilter("ignore")
    zigzags = sorted((DATA / "zigzag").glob("*.csv"))
    turns = {p: read_trial_log(p, fmt="osaka-frt") for p in sorted((DATA / "turning").glob("*.csv"))}
    randoms = {p: read_trial_log(p, fmt="osaka-frt")
               for p in sorted((DATA / "random").glob("*.csv"))}  # fmt: skip
    cut = {p: read_trial_log(p, fmt="osaka-frt") for p in zigzags}
    run_up = {p: from_setpoint(p, cut[p]) for p in zigzags}
    kept = [float(run_up[p]["t"].iloc[-1] - (cut[p]["t"].iloc[-1] - cut[p]["t"].iloc[0]))
            for p in zigzags]  # fmt: skip
    turn_rps = float(np.median(np.concatenate([log["n"].to_numpy() for log in turns.values()])))
    approach = None  # the turns' measured approach speed, as validate reads it
    print(f"The run-up kept: {min(kept):.0f}–{max(kept):.0f} s more per file "
          f"(median {np.median(kept):.0f} s)")
    rows: dict[str, list] = {v: [] for v in VARIANTS}
    for pair in itertools.combinations(zigzags, 2):
        out = str(folder / "pair.json")
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
            code = shipid(["identify", "--format", "osaka-frt", *map(str, pair), "-o", out])
        if code:
            continue
        model, doc = load_model(out), json.loads(Path(out).read_text(encoding="utf-8"))
        models = {VARIANTS[0]: model,
                  VARIANTS[1]: refit_surge(model, doc, [cut[p] for p in pair], False),
                  VARIANTS[2]: refit_surge(model, doc, [run_up[p] for p in pair], False),
                  VARIANTS[3]: refit_surge(model, doc, [run_up[p] for p in pair], True),
                  VARIANTS[4]: refit_surge(model, doc, [cut[p] for p in pair], True)}  # fmt: skip
        for name, m in models.items():
            runs = _validations(m, turns)
            if approach is None:
                approach = float(np.mean([v.indices["measured"]["approach_speed"] for v in runs]))
                print(f"The turns approach at {approach:.3f} m/s at {turn_rps:.3g} rps "
                      "(measured, the mean of the two)\n")
            td = _turn_errors(runs)
            random = float(np.median(_errors(_validations(m, randoms), randoms)))
            speed = surge_equilibrium(m, approach, turn_rps)
            rows[name].append((td, random, np.nan if speed is None else speed / approach - 1))
    print(f"The default `identify` of each pair of zig-zag files ({len(rows[VARIANTS[0]])} "
          "pairs) and its surge refitted; judged on the two 35° turns, the four random runs "
          f"and the straight speed at {turn_rps:.3g} rps\n")
    print("| model | 35° turns' tactical diameter, abs error median / mean (largest) | random "
          "runs' r error / spread, median | steady straight speed at the turns' rps, abs "
          "error median |")  # fmt: skip
    print("|---|---|---|---|")
    for name, got in rows.items():
        td = np.abs(np.concatenate([g[0] for g in got]))
        finite = td[np.isfinite(td)]
        none = len(td) - len(finite)
        speed = np.abs(np.array([g[2] for g in got]))
        print(f"| {name} | {np.median(finite):.0f} % / {np.mean(finite):.0f} % "
              f"({finite.max():.0f} %){f', {none} without' if none else ''} | "
              f"{np.median([g[1] for g in got]):.2f} | {100 * np.nanmedian(speed):.0f} % |")


if __name__ == "__main__":
    run_with_files(study)

"""The default `shipid identify` on the Esso Osaka logs at several sampling intervals Δk, judged on
logs it was not fitted to, and on the speed its surge balances at.

The Esso logs come at 10 Hz. The README resamples them to Δk = 0.5 s (`--dt 0.5`); a user who
does not gets the logs' own 0.1 s. Each fold trains `shipid identify` (no `--model`: the default
structure, chosen by `select`) on the nine zig-zags and three of the four random runs (each held
out in turn), or on the zig-zags alone, all written at Δk as files, and judges it on the two 35°
turns at 10 rps and the held-out random runs:

- the model's steady straight speed at 10 rps against the turns' measured steady approach (each
  turn's mean speed over its approach; the model's approach is what `shipid manoeuvre` and
  `criteria` start from);
- the turns' tactical diameters replayed from the measured state ("replay") and run closed loop
  from the model's own approach at 10 rps ("closed loop", as `validate` and `manoeuvre` do);
- the random runs' free-run r and u error std over their spread;
- the CV score of the structure `select` chose (its leave-one-log-out free-run error over the
  training logs), to see whether it could choose Δk too ("named": the search's candidates were
  all implausible and `identify` fell back to a named structure, which has no score).

Run: .venv/bin/python benchmarks/study_sampling.py
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
from esso_logs import esso_logs, run_with_files
from study_auto_structure import _identify

from shipid.data.io import write_log
from shipid.evaluation.validate import validate
from shipid.reporting.modelfile import load_model

# (Δk, the steady speed given to identify): None is the logs' own 0.1 s. The steady speed is the
# turns' own approach at 10 rps, as a user knows it from a straight run: with it the turns are
# not wholly unseen (their approach is the constraint); the random runs are.
STEADY = "0.35@10"
CASES = ((None, None), (0.2, None), (0.5, None), (1.0, None), (None, STEADY), (0.5, STEADY))


def _pct(pred, meas) -> float:
    return 100.0 * (pred / meas - 1.0)


def study(folder: Path) -> None:
    print("| Δk [s] | held out | model's speed at 10 rps (measured) | TD +35°, −35° replay | "
          "TD +35°, −35° closed loop | steady r +35°, −35° closed loop | random runs r / u "
          "error over spread | CV score |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    means = {}
    for dt, steady in CASES:
        extra = ("--steady-speed", steady) if steady else ()
        label = f"{dt or 0.1:g}" + (f", --steady-speed {steady}" if steady else "")
        data = esso_logs(dt)
        if data is None:
            return
        zz, rnd, turns = data
        files = {**{f"zz {k}": write_log(x, folder / f"zz_{k}.csv") for k, x in zz.items()},
                 **{f"rnd {k}": write_log(x, folder / f"rnd_{k}.csv") for k, x in rnd.items()}}
        folds = {"random runs (zig-zags only)": [f"zz {k}" for k in zz]}
        for held in rnd:
            folds[f"random {held[-8:]}"] = [f"zz {k}" for k in zz] + [
                f"rnd {k}" for k in rnd if k != held]  # fmt: skip
        rows = []
        for fold, keys in folds.items():
            path = folder / "model.json"
            _, seconds = _identify([files[k] for k in keys], "auto", path, extra)
            if seconds < 0:
                print(f"| {label} | {fold} | identify refused | | | | |")
                continue
            model = load_model(path)
            cv = json.loads(path.read_text())["identification"]["structure_choice"].get("score")
            held_logs = [rnd[k] for k in rnd if f"rnd {k}" not in keys]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                vals = validate(model, [*turns, *held_logs])
            meas = [v.indices["measured"] for v in vals[:2]]
            replay = [v.indices["simulated"] for v in vals[:2]]
            closed = [v.indices.get("closed_loop") or {} for v in vals[:2]]
            own = np.mean([c.get("approach_speed", np.nan) for c in closed])
            measured = np.mean([m["approach_speed"] for m in meas])
            td_r = [_pct(r.get("tactical_diameter", np.nan), m["tactical_diameter"])
                    for r, m in zip(replay, meas, strict=True)]  # fmt: skip
            td_c = [_pct(c.get("tactical_diameter", np.nan), m["tactical_diameter"])
                    for c, m in zip(closed, meas, strict=True)]  # fmt: skip
            r_c = [_pct(c.get("steady_yaw_rate", np.nan), m["steady_yaw_rate"])
                   for c, m in zip(closed, meas, strict=True)]  # fmt: skip
            err_r = np.mean([v.metrics["r"]["std"] / np.std(x["r"])
                             for v, x in zip(vals[2:], held_logs, strict=True)])  # fmt: skip
            err_u = np.mean([v.metrics["u"]["std"] / np.std(x["u"])
                             for v, x in zip(vals[2:], held_logs, strict=True)])  # fmt: skip
            rows.append((abs(_pct(own, measured)), np.mean(np.abs(td_r)), np.mean(np.abs(td_c)),
                         np.mean(np.abs(r_c)), err_r, err_u, np.nan if cv is None else cv))  # fmt: skip
            print(f"| {label} | {fold} | {own:.3f} ({measured:.3f}, "
                  f"{_pct(own, measured):+.0f} %) | {td_r[0]:+.0f} %, {td_r[1]:+.0f} % | "
                  f"{td_c[0]:+.0f} %, {td_c[1]:+.0f} % | {r_c[0]:+.0f} %, {r_c[1]:+.0f} % | "
                  f"{err_r:.2f} / {err_u:.2f} | {'named' if cv is None else f'{cv:.3f}'} |")  # fmt: skip
        means[label] = np.nanmean(rows, axis=0)
    print("\nMeans over the folds: |error| of the model's speed at 10 rps, of the tactical "
          "diameters (replay, closed loop) and of the closed loop's steady yaw rates; random "
          "runs' r and u error over spread; the CV score where select chose\n")  # fmt: skip
    print("| Δk [s] | speed at 10 rps | TD replay | TD closed loop | steady r closed loop | "
          "random runs r / u | CV score |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    for label, m in means.items():
        print(f"| {label} | {m[0]:.0f} % | {m[1]:.1f} % | {m[2]:.1f} % | {m[3]:.1f} % | "
              f"{m[4]:.2f} / {m[5]:.2f} | {m[6]:.3f} |")


if __name__ == "__main__":
    run_with_files(study)

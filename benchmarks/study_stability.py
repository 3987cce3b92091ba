"""Straight-line stability as a constraint (issue #10 item 3, ``--constraints stable``), judged on
the real KVLCC2 logs it was not fitted to: each of the three logs (MARIN zz 20°, MARIN zz −20°,
HSVA zz 20/10) held out in turn, each structure identified as ``identify`` does (prefilter chosen
from the data) on the other two, with and without the constraint. Printed: the held-out log's
free-run rms errors of u, v, r and its overshoots, measured and predicted in closed loop (the
zig-zag run on the model from the log's start with its rudder, rate and switch heading), and the
models' largest sway–yaw eigenvalue at the approach.

Run: .venv/bin/python benchmarks/study_stability.py
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from shipid.control.linear import linearise
from shipid.data.io import read_log
from shipid.data.preprocess import lowpass
from shipid.evaluation.validate import validate_log
from shipid.identification.identify import identify
from shipid.identification.physics import PhysicsOptions
from shipid.identification.prefilter import choose_prefilter

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
STRUCTURES = ("blanke-speed", "blanke-race", "blanke-race+race-damping")
OVERSHOOTS = ("first_overshoot_deg", "second_overshoot_deg")


def kvlcc2_logs():
    marin = {"format": "simman-marin", "scale": 45.7, "dt": 0.2}
    return {"MARIN zz 20°": read_log(DATA / "kvlcc2-marin" / "MARIN_FREE_KVLCC2_zz_20_m.dat",
                                     fmt=marin["format"], scale=marin["scale"], dt=marin["dt"]),
            "MARIN zz −20°": read_log(DATA / "kvlcc2-marin" / "MARIN_FREE_KVLCC2_zz_-20_m.dat",
                                      fmt=marin["format"], scale=marin["scale"], dt=marin["dt"]),
            "HSVA zz 20/10": read_log(DATA / "kvlcc2-hsva" / "HSVA_CPMC_KVLCC2_Z_20_10_P.dat",
                                      fmt="simman-hsva", dt=0.2)}  # fmt: skip


def fit_as_identify(logs, structure, physics):
    def fit(train, weights=None):
        return identify(train, model=structure, force=True, physics=physics).model

    cutoff, _ = choose_prefilter(logs, fit)
    return fit(logs if cutoff is None else [lowpass(log, cutoff) for log in logs])


def main() -> None:
    if not DATA.is_dir():
        print("../shared/data is absent")
        return
    warnings.simplefilter("ignore")
    logs = kvlcc2_logs()
    names = list(logs)
    print("| structure | stable | held out | rms u / v / r | overshoots measured | closed loop "
          "| largest eigenvalue (1/s) |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    totals: dict[tuple, list] = {}
    for structure in STRUCTURES:
        for stable in (False, True):
            physics = PhysicsOptions(stable=True) if stable else None
            for held in names:
                train = [logs[n] for n in names if n != held]
                model = fit_as_identify(train, structure, physics)
                u0 = float(train[0]["u"].iloc[0])
                eig = max(np.linalg.eigvals(linearise(model, u0)["A"][1:, 1:]).real)
                val = validate_log(model, logs[held], held)
                rms = [val.metrics[s]["rmse"] for s in "uvr"]
                meas = [val.indices["measured"][k] for k in OVERSHOOTS]
                pred = [val.indices["closed_loop"].get(k) or np.nan for k in OVERSHOOTS]
                totals.setdefault((structure, stable), []).append(
                    (rms, [abs(p - m) for p, m in zip(pred, meas, strict=True)]))
                print(f"| {structure} | {'yes' if stable else 'no'} | {held} | "
                      + " / ".join(f"{x:.4f}" for x in rms)
                      + f" | {meas[0]:.1f}°, {meas[1]:.1f}° | {pred[0]:.1f}°, {pred[1]:.1f}° | "
                      f"{eig:+.4f} |")  # fmt: skip
    print("\nMean over the three held-out logs: rms u / v / r, mean |overshoot error|")
    for (structure, stable), rows in totals.items():
        rms = np.mean([r for r, _ in rows], axis=0)
        err = np.nanmean([e for _, e in rows])
        print(f"{structure:26s} stable={'yes' if stable else 'no ':3s}  "
              + " / ".join(f"{x:.4f}" for x in rms) + f"  {err:.2f}°")


if __name__ == "__main__":
    main()

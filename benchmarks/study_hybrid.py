"""Does a kernel residual help? (issue #10 item 4, measured before building it into the tool.)

The grey-box idea taken further: the physical model plus an RBF LS-SVM per equation fitted on
the physical model's one-step equation residual, inputs (u, v, r, δ[, n]) standardised, γ and σ
by the LS-SVM's exact leave-one-out. The hybrid is run free (NumPy path) on held-out logs and
compared with the physical model alone.

KVLCC2: blanke-speed from the MARIN zz 20° (1.25 Hz prefilter), held out zz −20° and HSVA 20/10.
Esso Osaka: the model of ``shipid select`` in the README (``esso.json``, from the zig-zags and three
random runs), held out the two turns and the fourth random run. Needs ../shared/data and, for
the Esso part, the README's ``esso/`` folder and ``esso.json`` in the working directory.

Run: .venv/bin/python benchmarks/study_hybrid.py
"""

from __future__ import annotations

import glob
import os
import time
from pathlib import Path

import numpy as np

from shipid.data.io import read_log
from shipid.data.preprocess import lowpass
from shipid.dynamics.simulate import simulate_log
from shipid.identification.identify import identify
from shipid.lssvm import LSSVRCV
from shipid.reporting.modelfile import load_model

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


class Hybrid:
    """Physical model + per-DOF RBF LS-SVMs on standardised features (generic simulator path)."""

    uses_thrust = False

    def __init__(self, physical, features, mu, sd, estimators):
        self.physical, self.features, self.mu, self.sd = physical, features, mu, sd
        self.estimators = estimators
        self.uses_rps = physical.uses_rps
        self.inputs = physical.inputs

    def derivatives(self, nu, delta, thrust=None, rps=None, **inputs):
        base = self.physical.derivatives(nu, delta, thrust, rps, **inputs)
        cols = {"u": nu[:, 0], "v": nu[:, 1], "r": nu[:, 2], "delta": delta, "n": rps}
        z = (np.column_stack([cols[f] for f in self.features]) - self.mu) / self.sd
        return base + np.column_stack([e.predict(z) for e in self.estimators])


def fit_hybrid(physical, logs, features):
    X, Y = [], []
    for log in logs:
        dt = float(np.median(np.diff(log["t"])))
        given = {c: log[c].to_numpy() for c in physical.inputs if c not in ("n", "thrust")}
        acc = physical.accelerations(log["u"].to_numpy(), log["v"].to_numpy(),
                                     log["r"].to_numpy(), log["delta"].to_numpy(),
                                     rps=log["n"].to_numpy() if "n" in log else None, **given)
        X.append(np.column_stack([log[f].to_numpy() for f in features])[:-1])
        Y.append(np.column_stack([np.diff(log[s].to_numpy()) / dt for s in "uvr"]) - acc[:-1])
    X, Y = np.vstack(X), np.vstack(Y)
    mu, sd = X.mean(axis=0), X.std(axis=0)
    solver = {"solver": "fixed-size", "n_landmarks": 300, "random_state": 0} if len(X) > 3000 else {}
    estimators, loo = [], []
    for j in range(3):
        cv = LSSVRCV(gammas=np.logspace(-2, 4, 13), sigmas=[0.5, 1, 2, 4], kernel="rbf",
                     **solver).fit((X - mu) / sd, Y[:, j])  # fmt: skip
        estimators.append(cv.best_estimator_)
        loo.append(cv.best_score_ / Y[:, j].var())
    return Hybrid(physical, features, mu, sd, estimators), loo


def errors(model, log):
    sim = simulate_log(model, log, "euler")
    n = len(sim.log)
    return [float(np.std(log[s].to_numpy()[:n] - sim.log[s].to_numpy())) for s in "uvr"]


def report(name, physical, hybrid, loo, held):
    print(f"\n{name}: one-step LOO error of the residual models / residual variance (u, v, r): "
          + " / ".join(f"{x:.2f}" for x in loo))
    print("\n| held out | physical u / v / r error std | hybrid |")
    print("|---|---|---|")
    for label, log in held:
        p, h = errors(physical, log), errors(hybrid, log)
        print(f"| {label} | " + " / ".join(f"{x:.4f}" for x in p) + " | "
              + " / ".join(f"{x:.4f}" for x in h) + " |")


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    t0 = time.perf_counter()
    marin = DATA / "kvlcc2-marin"
    zz20 = read_log(marin / "MARIN_FREE_KVLCC2_zz_20_m.dat", fmt="simman-marin", scale=45.7, dt=0.2)
    zzm20 = read_log(marin / "MARIN_FREE_KVLCC2_zz_-20_m.dat", fmt="simman-marin", scale=45.7,
                     dt=0.2)  # fmt: skip
    hsva = read_log(DATA / "kvlcc2-hsva" / "HSVA_CPMC_KVLCC2_Z_20_10_P.dat", fmt="simman-hsva",
                    dt=0.2)  # fmt: skip
    train = lowpass(zz20, 1.25)
    physical = identify(train, "blanke-speed").model
    hybrid, loo = fit_hybrid(physical, [train], ["u", "v", "r", "delta"])
    report("KVLCC2", physical, hybrid, loo, [("MARIN zz −20°", zzm20), ("HSVA zz 20/10", hsva)])
    if Path("esso.json").exists():
        zz = [read_log(f, dt=0.5) for f in sorted(glob.glob("esso/zigzag/*.csv"))]
        runs = {Path(f).name: read_log(f, dt=0.5) for f in sorted(glob.glob("esso/random/*.csv"))}
        held_run = "random_31-Jul-2020_12_29_58.csv"
        physical = load_model("esso.json")
        hybrid, loo = fit_hybrid(physical, zz + [v for k, v in runs.items() if k != held_run],
                                 ["u", "v", "r", "delta", "n"])  # fmt: skip
        turns = [(Path(f).name, read_log(f, dt=0.5))
                 for f in sorted(glob.glob("esso/turning/*.csv"))]  # fmt: skip
        report("Esso Osaka", physical, hybrid, loo, turns + [(held_run, runs[held_run])])
    print(f"\ntime {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    main()

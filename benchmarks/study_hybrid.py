"""Does a kernel residual help? (issue #10 item 4: ``identify --residual rbf``, judged on logs
it was not fitted to.)

The grey-box idea taken further: the physical model plus an RBF LS-SVM fitted on the physical
model's one-step acceleration residual (``shipid.identification.residual``), run free on held-out
logs and compared with the physical model alone, with the residual's γ and σ chosen two ways:

* by the LS-SVM's exact leave-one-out of the one-step residual (what the LS-SVM offers by itself,
  ``LSSVRCV`` over the same grid);
* by free-run cross-validation (``choose_residual``, what ``identify --residual`` does): over
  the grid and "no residual", the physical model and the residual are fitted without each
  training log (KVLCC2: each of four blocks of its one log) and run free over it.

KVLCC2: blanke-speed from the MARIN zz 20° (1.25 Hz prefilter), held out zz −20° and HSVA 20/10.
Esso Osaka: the structure and γ ``select`` chooses in the README's fold (nine zig-zags and three
random runs, read as ``esso_logs.py`` reads them), held out the two turns and the fourth random
run.

Run: .venv/bin/python benchmarks/study_hybrid.py
"""

from __future__ import annotations

import os
import time
import warnings
from pathlib import Path

import numpy as np
from esso_logs import README_HELD, esso_logs

from shipid.data.io import read_log
from shipid.data.preprocess import lowpass
from shipid.dynamics.hybrid import HybridModel
from shipid.dynamics.simulate import simulate_log
from shipid.identification.identify import identify
from shipid.identification.residual import (
    DENSE_LIMIT,
    GAMMAS,
    LANDMARKS,
    SIGMAS,
    choose_residual,
    fit_residual,
    residual_data,
    residual_features,
)
from shipid.identification.select import select
from shipid.lssvm import LSSVRCV

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


def loo_choice(physical, logs):
    """(γ, σ) of the residual by the exact leave-one-out of the one-step residual, and its
    LOO error over the residual's variance per DOF."""
    features = residual_features(logs)
    X, Y = residual_data(physical, logs, features)
    Z = (X - X.mean(axis=0)) / X.std(axis=0)
    best, loo = {}, []
    solver = {} if len(Z) <= DENSE_LIMIT else {"solver": "fixed-size", "n_landmarks": LANDMARKS,
                                               "random_state": 0}  # fmt: skip
    for j in range(3):
        cv = LSSVRCV(gammas=GAMMAS, sigmas=SIGMAS, kernel="rbf", **solver).fit(Z, Y[:, j])
        best[(cv.best_params_["gamma"], cv.best_params_["sigma"])] = cv.best_score_
        loo.append(cv.best_score_ / Y[:, j].var())
    # One setting for the three outputs: the yaw equation's, whose residual the kernel explains.
    gamma, sigma = list(best)[-1]
    return gamma, sigma, loo


def hybrid_of(physical, logs, gamma, sigma):
    if gamma is None:
        return physical
    return HybridModel(physical, fit_residual(physical, logs, gamma, sigma))


def errors(model, log):
    sim = simulate_log(model, log, "euler")
    n = len(sim.log)
    return [float(np.std(log[s].to_numpy()[:n] - sim.log[s].to_numpy())) for s in "uvr"]


def report(name, physical, loo_model, loo, held, choice, cv_model):
    print(f"\n{name}: one-step LOO error of the residual models / residual variance (u, v, r): "
          + " / ".join(f"{x:.2f}" for x in loo))
    print(choice.describe())
    for note in choice.notes:
        print(f"note: {note}")
    print("\n| held out | physical u / v / r error std | hybrid, γ σ by one-step LOO | "
          "hybrid, γ σ by free-run CV |")
    print("|---|---|---|---|")
    for label, log in held:
        cells = [errors(m, log) for m in (physical, loo_model, cv_model)]
        print(f"| {label} | " + " | ".join(" / ".join(f"{x:.4f}" for x in c) for c in cells)
              + " |")


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores")
    t0 = time.perf_counter()
    marin = DATA / "kvlcc2-marin"
    zz20 = read_log(marin / "MARIN_FREE_KVLCC2_zz_20_m.dat", fmt="simman-marin", scale=45.7, dt=0.2)
    zzm20 = read_log(marin / "MARIN_FREE_KVLCC2_zz_-20_m.dat", fmt="simman-marin", scale=45.7,
                     dt=0.2)  # fmt: skip
    hsva = read_log(DATA / "kvlcc2-hsva" / "HSVA_CPMC_KVLCC2_Z_20_10_P.dat", fmt="simman-hsva",
                    dt=0.2)  # fmt: skip

    def fit_kvlcc2(logs):
        filtered = [lowpass(x, 1.25) for x in logs]
        return identify(filtered, "blanke-speed", force=True).model, filtered

    physical, train = fit_kvlcc2([zz20])
    g, s, loo = loo_choice(physical, train)
    choice = choose_residual(fit_kvlcc2, [zz20], cv="blocks:4")
    report("KVLCC2", physical, hybrid_of(physical, train, g, s), loo,
           [("MARIN zz −20°", zzm20), ("HSVA zz 20/10", hsva)], choice,
           hybrid_of(physical, train, choice.gamma, choice.sigma))  # fmt: skip
    data = esso_logs()
    if data is not None:
        zz, rnd, turns = data
        train = list(zz.values()) + [x for k, x in rnd.items() if k != README_HELD]
        sel = select(train, library="low-speed+wind+propeller-asymmetry")
        physical = sel.chosen_model

        def fit_esso(logs):
            return identify(logs, physical.structure, gamma=sel.gamma, force=True).model, logs

        g, s, loo = loo_choice(physical, train)
        choice = choose_residual(fit_esso, train)
        held = [("turn +35°", turns[0]), ("turn −35°", turns[1]), (README_HELD, rnd[README_HELD])]
        report("Esso Osaka", physical, hybrid_of(physical, train, g, s), loo, held, choice,
               hybrid_of(physical, train, choice.gamma, choice.sigma))  # fmt: skip
    print(f"\ntime {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # envelope warnings of the free runs
    main()

"""Does a kernel residual help? (issue #10 item 4, measured before building it into the tool.)

The grey-box idea taken further: the physical model plus an RBF LS-SVM per equation fitted on
the physical model's one-step equation residual, inputs (u, v, r, δ[, n]) standardised. The
hybrid is run free (NumPy path) on held-out logs and compared with the physical model alone, with
the residual's γ and σ chosen two ways:

* by the LS-SVM's exact leave-one-out of the one-step residual (what the LS-SVM offers by itself);
* by free-run cross-validation, as ``select`` chooses terms: over a grid of γ and σ and "no
  residual", the physical model and the residual are fitted without each training log (KVLCC2:
  each of four blocks of its one log) and run free over it; the lowest mean normalised error
  (``shipid.identification.select.normalised_error``) wins.

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
from shipid.dynamics.simulate import simulate_log
from shipid.identification.identify import identify
from shipid.identification.select import normalised_error, select
from shipid.lssvm import LSSVR, LSSVRCV

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


def residual_data(physical, logs, features):
    """Standardisation-free features and the one-step acceleration residual of ``physical``."""
    X, Y = [], []
    for log in logs:
        dt = float(np.median(np.diff(log["t"])))
        given = {c: log[c].to_numpy() for c in physical.inputs if c not in ("n", "thrust")}
        acc = physical.accelerations(log["u"].to_numpy(), log["v"].to_numpy(),
                                     log["r"].to_numpy(), log["delta"].to_numpy(),
                                     rps=log["n"].to_numpy() if "n" in log else None, **given)
        X.append(np.column_stack([log[f].to_numpy() for f in features])[:-1])
        Y.append(np.column_stack([np.diff(log[s].to_numpy()) / dt for s in "uvr"]) - acc[:-1])
    return np.vstack(X), np.vstack(Y)


def fit_hybrid(physical, logs, features):
    """The residual's γ and σ by the exact leave-one-out of the one-step residual."""
    X, Y = residual_data(physical, logs, features)
    mu, sd = X.mean(axis=0), X.std(axis=0)
    solver = {"solver": "fixed-size", "n_landmarks": 300, "random_state": 0} if len(X) > 3000 else {}
    estimators, loo = [], []
    for j in range(3):
        cv = LSSVRCV(gammas=np.logspace(-2, 4, 13), sigmas=[0.5, 1, 2, 4], kernel="rbf",
                     **solver).fit((X - mu) / sd, Y[:, j])  # fmt: skip
        estimators.append(cv.best_estimator_)
        loo.append(cv.best_score_ / Y[:, j].var())
    return Hybrid(physical, features, mu, sd, estimators), loo


GAMMAS, SIGMAS = (1e-3, 1e-2, 1e-1, 1.0, 10.0), (1.0, 2.0, 4.0)


def fit_residual(physical, logs, features, gamma, sigma, data=None):
    """The hybrid with a residual of given γ and σ (fixed-size, 300 landmarks, over 3000
    samples); None γ: the physical model alone. ``data``: ``residual_data`` already computed."""
    if gamma is None:
        return physical
    X, Y = data if data is not None else residual_data(physical, logs, features)
    mu, sd = X.mean(axis=0), X.std(axis=0)
    solver = {"solver": "fixed-size", "n_landmarks": 300, "random_state": 0} if len(X) > 3000 else {}
    estimators = [LSSVR(gamma=gamma, sigma=sigma, kernel="rbf", **solver).fit((X - mu) / sd, Y[:, j])
                  for j in range(3)]  # fmt: skip
    return Hybrid(physical, features, mu, sd, estimators)


def free_run_cv(structure, gamma_phys, logs, features, prefilter=None):
    """(γ, σ) of the residual (None: none) with the lowest mean normalised free-run error over
    the folds (each log held out in turn), and the table of scores. Each fold's physical model
    and residual data are computed once for the whole grid."""
    settings = [(None, None)] + [(g, sig) for g in GAMMAS for sig in SIGMAS]
    fold_scores = {key: [] for key in settings}
    for k, held in enumerate(logs):
        train = [x for j, x in enumerate(logs) if j != k]
        fit_on = [lowpass(x, prefilter) for x in train] if prefilter else train
        physical = identify(fit_on, structure, gamma=gamma_phys, force=True).model
        data = residual_data(physical, fit_on, features)
        measured = held[["u", "v", "r"]].to_numpy()
        for g, sig in settings:
            model = fit_residual(physical, fit_on, features, g, sig, data)
            sim = simulate_log(model, held, "euler").log
            fold_scores[(g, sig)].append(float(np.mean(normalised_error(
                measured, sim[["u", "v", "r"]].to_numpy(), 2.0))))
    scores = {key: float(np.mean(v)) for key, v in fold_scores.items()}
    return min(scores, key=scores.get), scores


def errors(model, log):
    sim = simulate_log(model, log, "euler")
    n = len(sim.log)
    return [float(np.std(log[s].to_numpy()[:n] - sim.log[s].to_numpy())) for s in "uvr"]


def report(name, physical, hybrid, loo, held, chosen, scores, cv_hybrid):
    print(f"\n{name}: one-step LOO error of the residual models / residual variance (u, v, r): "
          + " / ".join(f"{x:.2f}" for x in loo))
    none, best = scores[(None, None)], scores[chosen]
    largest = min(v for (g, _), v in scores.items() if g == GAMMAS[-1])
    what = "no residual" if chosen[0] is None else f"γ = {chosen[0]:g}, σ = {chosen[1]:g}"
    print(f"free-run CV over {len(scores)} settings: {what} (score {best:.4f}; no residual "
          f"{none:.4f}; the largest γ tried {largest:.4f})")
    print("\n| held out | physical u / v / r error std | hybrid, γ σ by one-step LOO | "
          "hybrid, γ σ by free-run CV |")
    print("|---|---|---|---|")
    for label, log in held:
        cells = [errors(m, log) for m in (physical, hybrid, cv_hybrid)]
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
    train = lowpass(zz20, 1.25)
    physical = identify(train, "blanke-speed").model
    features = ["u", "v", "r", "delta"]
    hybrid, loo = fit_hybrid(physical, [train], features)
    edges = np.linspace(0, len(zz20), 5).round().astype(int)
    blocks = [zz20.iloc[a:b].reset_index(drop=True) for a, b in zip(edges[:-1], edges[1:], strict=True)]
    chosen, scores = free_run_cv("blanke-speed", 1e4, blocks, features, prefilter=1.25)
    cv_hybrid = fit_residual(physical, [train], features, *chosen)
    report("KVLCC2", physical, hybrid, loo, [("MARIN zz −20°", zzm20), ("HSVA zz 20/10", hsva)],
           chosen, scores, cv_hybrid)
    data = esso_logs()
    if data is not None:
        zz, rnd, turns = data
        train = list(zz.values()) + [x for k, x in rnd.items() if k != README_HELD]
        sel = select(train, library="low-speed+wind+propeller-asymmetry")
        physical, features = sel.chosen_model, ["u", "v", "r", "delta", "n"]
        hybrid, loo = fit_hybrid(physical, train, features)
        chosen, scores = free_run_cv(physical.structure, sel.gamma, train, features)
        cv_hybrid = fit_residual(physical, train, features, *chosen)
        held = [("turn +35°", turns[0]), ("turn −35°", turns[1]), (README_HELD, rnd[README_HELD])]
        report("Esso Osaka", physical, hybrid, loo, held, chosen, scores, cv_hybrid)
    print(f"\ntime {time.perf_counter() - t0:.1f} s")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # envelope warnings of the free runs
    main()

"""Cost of the kernel residual (issue #10 item 4, ``identify --residual rbf``) at N = 1e4 and 1e5
samples: zig-zags of the paper's ship with its sensor noise (0.5 Hz prefilter), the Blanke
structure.

* fit: the residual at one (γ, σ) (fixed-size LS-SVM, 300 landmarks, three outputs) against the
  physical ``identify`` on the same log, and against scikit-learn's ``Nystroem`` (300
  components) + ``Ridge`` on the same standardised features and residual (the strongest simple
  alternative), in the same process;
* free run of the whole log: the hybrid (compiled, ``hybrid_kernel``: 300 centres a step)
  against the physical model alone (compiled kernel).

The free-run cross-validation that ``identify --residual`` adds is 16 settings × the folds of
these two steps.

Run: .venv/bin/python benchmarks/bench_residual.py
"""

from __future__ import annotations

import os

import numpy as np
from timing import best_of

from shipid.data.preprocess import lowpass
from shipid.dynamics.hybrid import HybridModel
from shipid.dynamics.simulate import simulate_log
from shipid.identification.identify import identify
from shipid.identification.residual import LANDMARKS, fit_residual, residual_data
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import PAPER_IMU, scale_ship

GAMMA, SIGMA = 0.1, 2.0


def _sklearn_fit(X: np.ndarray, Y: np.ndarray) -> None:
    from sklearn.kernel_approximation import Nystroem
    from sklearn.linear_model import Ridge

    Z = (X - X.mean(axis=0)) / X.std(axis=0)
    features = Nystroem(gamma=1.0 / SIGMA**2, n_components=LANDMARKS, random_state=0).fit_transform(Z)
    Ridge(alpha=1.0 / GAMMA).fit(features, Y)


def main() -> None:
    ship = scale_ship(rudder_rate_deg=9.6)
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| samples | physical identify (s) | residual fit (s) | Nystroem + Ridge (s) | "
          "fit vs sklearn | free run, physical (s) | free run, hybrid (s) | hybrid steps/s |")
    print("|---|---|---|---|---|---|---|---|")
    for duration in (2000, 20000):
        log = PAPER_IMU.apply(zigzag(ship, 20, 20, duration=duration, dt=0.2, method="euler").log,
                              seed=1)  # fmt: skip
        row(lowpass(log, 0.5))


def row(log) -> None:
    """One table row: the fits and free runs on ``log``."""
    physical = identify(log).model
    plain = best_of(lambda: identify(log), 3)
    features = ("u", "v", "r", "delta")
    X, Y = residual_data(physical, [log], features)
    fit = best_of(lambda: fit_residual(physical, [log], GAMMA, SIGMA, features, (X, Y)), 3)
    sk = best_of(lambda: _sklearn_fit(X, Y), 3)
    hybrid = HybridModel(physical, fit_residual(physical, [log], GAMMA, SIGMA, features))
    run_phys = best_of(lambda: simulate_log(physical, log), 3)
    run_hyb = best_of(lambda: simulate_log(hybrid, log), 3)
    print(f"| {len(log)} | {plain:.3f} | {fit:.3f} | {sk:.3f} | {fit / sk:.2f}× | "
          f"{run_phys:.4f} | {run_hyb:.2f} | {len(log) / run_hyb:.3g} |")

if __name__ == "__main__":
    main()

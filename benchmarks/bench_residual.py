"""Cost of the kernel residual (issue #10 item 4, ``identify --residual rbf``) at N = 1e4 and 1e5
samples: zig-zags of the paper's ship with its sensor noise (0.5 Hz prefilter), the Blanke
structure.

* fit: the residual at one (γ, σ) (fixed-size LS-SVM, 300 landmarks, three outputs) against the
  physical ``identify`` on the same log, and against scikit-learn's ``Nystroem`` (300
  components) + ``Ridge`` on the same standardised features and residual (the strongest simple
  alternative), in the same process;
* free run of the whole log: the hybrid (compiled, ``hybrid_kernel``: 300 centres a step)
  against a hand-written numba Euler loop of the same Blanke model and residual (the practical
  limit, same states to rounding), and the physical model alone (compiled kernel).

The free-run cross-validation that ``identify --residual`` adds is 16 settings × the folds of
these two steps.

Run: .venv/bin/python benchmarks/bench_residual.py
"""

from __future__ import annotations

import math
import os

import numba
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
BLANKE = {"u": ("|u|*u", "v*r", "r^2", "delta^2", "1"),
          "v": ("u*r", "u*v", "|v|*v", "|v|*r", "delta", "1"),
          "r": ("u*r", "u*v", "|v|*v", "|v|*r", "delta", "1")}  # fmt: skip


@numba.njit(cache=True)
def hand_written(t, delta, s0, cu, cv, cr, mean, scale, centres, weights, intercept, inv_s2,
                 inv_reach, out):  # fmt: skip
    """Euler free run of a Blanke model plus an RBF residual on (u, v, r, δ), written out."""
    u, v, r, psi, x, y = s0[0], s0[1], s0[2], s0[3], s0[4], s0[5]
    out[0, 0], out[0, 1], out[0, 2], out[0, 3], out[0, 4], out[0, 5] = u, v, r, psi, x, y
    z = np.empty(4)
    for k in range(t.size - 1):
        d = delta[k]
        au = cu[0] * abs(u) * u + cu[1] * v * r + cu[2] * r * r + cu[3] * d * d + cu[4]
        av = (cv[0] * u * r + cv[1] * u * v + cv[2] * abs(v) * v + cv[3] * abs(v) * r
              + cv[4] * d + cv[5])  # fmt: skip
        ar = (cr[0] * u * r + cr[1] * u * v + cr[2] * abs(v) * v + cr[3] * abs(v) * r
              + cr[4] * d + cr[5])  # fmt: skip
        z[0] = (u - mean[0]) / scale[0]
        z[1] = (v - mean[1]) / scale[1]
        z[2] = (r - mean[2]) / scale[2]
        z[3] = (d - mean[3]) / scale[3]
        kmax, s_u, s_v, s_r = 0.0, 0.0, 0.0, 0.0
        for i in range(centres.shape[0]):
            d2 = 0.0
            for j in range(4):
                e = z[j] - centres[i, j]
                d2 += e * e
            kv = math.exp(-d2 * inv_s2)
            kmax = max(kmax, kv)
            s_u += kv * weights[i, 0]
            s_v += kv * weights[i, 1]
            s_r += kv * weights[i, 2]
        w = min(1.0, kmax * inv_reach)
        au += w * (s_u + intercept[0])
        av += w * (s_v + intercept[1])
        ar += w * (s_r + intercept[2])
        h = t[k + 1] - t[k]
        c, sn = math.cos(psi), math.sin(psi)
        x, y = x + h * (u * c - v * sn), y + h * (u * sn + v * c)
        psi += h * r
        u, v, r = u + h * au, v + h * av, r + h * ar
        out[k + 1, 0], out[k + 1, 1], out[k + 1, 2] = u, v, r
        out[k + 1, 3], out[k + 1, 4], out[k + 1, 5] = psi, x, y


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
          "fit vs sklearn | free run, physical (s) | free run, hybrid (s) | hybrid steps/s | "
          "hand-written numba (s) | hybrid vs hand-written | largest state difference |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
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
    t, delta = log["t"].to_numpy(), log["delta"].to_numpy()
    s0 = np.array([float(log[k].iloc[0]) for k in ("u", "v", "r", "psi", "x", "y")])
    c = physical.coefficients
    cu, cv, cr = (np.array([c[d][k] for k in BLANKE[d]]) for d in "uvr")
    out = np.zeros((len(t), 6))
    args = (t, delta, s0, cu, cv, cr, *hybrid.kernel_arguments[:7], out)
    hand = best_of(lambda: hand_written(*args), 3)
    ours = simulate_log(hybrid, log).log[["u", "v", "r", "psi", "x", "y"]].to_numpy()
    diff = float(np.max(np.abs(ours - out[: len(ours)])))
    print(f"| {len(log)} | {plain:.3f} | {fit:.3f} | {sk:.3f} | {fit / sk:.2f}× | "
          f"{run_phys:.4f} | {run_hyb:.3f} | {len(log) / run_hyb:.3g} | {hand:.3f} | "
          f"{hand / run_hyb:.2f}× | {diff:.1e} |")

if __name__ == "__main__":
    main()

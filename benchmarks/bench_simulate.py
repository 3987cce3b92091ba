"""Simulation speed of the Blanke model against a naive per-step NumPy loop in the same process.

Targets (issue: models and simulator): ≥ 50× the naive loop, ≥ 1e6 steps/s for one trajectory,
≥ 1e7 state-steps/s for 1000 trajectories. Run: .venv/bin/python benchmarks/bench_simulate.py
"""

from __future__ import annotations

import time

import numpy as np

from shipid.dynamics.simulate import simulate, simulate_batch
from shipid.vessels import scale_ship_model


def naive_loop(model, t, delta, u0, method):
    """The obvious implementation: model.accelerations on length-1 arrays, one step at a time."""
    s = np.array([u0, 0.0, 0.0, 0.0, 0.0, 0.0])

    def rhs(s, d):
        acc = model.accelerations(s[0:1], s[1:2], s[2:3], np.array([d]))[0]
        c, sn = np.cos(s[3]), np.sin(s[3])
        return np.array([acc[0], acc[1], acc[2], s[2], s[0] * c - s[1] * sn, s[0] * sn + s[1] * c])

    for k in range(len(t) - 1):
        h = t[k + 1] - t[k]
        k1 = rhs(s, delta[k])
        if method == "euler":
            s = s + h * k1
            continue
        k2 = rhs(s + 0.5 * h * k1, delta[k])
        k3 = rhs(s + 0.5 * h * k2, delta[k])
        k4 = rhs(s + h * k3, delta[k])
        s = s + h / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
    return s


def timed(fn):
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


def main() -> None:
    model = scale_ship_model()
    zig = lambda t: 0.35 * np.sign(np.sin(2 * np.pi * t / 30) + 1e-9)  # noqa: E731
    simulate(model, np.arange(0, 1, 0.2), np.zeros(5), {"u": 1.9})  # compile / load cache
    simulate_batch(model, np.arange(0, 1, 0.2), np.zeros((2, 5)), {"u": 1.9})
    print("| case | method | steps | time (s) | steps/s | naive loop steps/s | speed-up | target |")
    print("|---|---|---|---|---|---|---|---|")
    for method in ("euler", "rk4"):
        n_naive = 20_000
        t = np.arange(n_naive) * 0.2
        t_naive = timed(lambda: naive_loop(model, t, zig(t), 1.9, method))  # noqa: B023
        naive_rate = (n_naive - 1) / t_naive
        n = 2_000_000
        t = np.arange(n) * 0.2
        d = zig(t)
        best = min(timed(lambda: simulate(model, t, d, {"u": 1.9}, method=method))  # noqa: B023
                   for _ in range(3))  # fmt: skip
        rate = (n - 1) / best
        print(f"| single trajectory | {method} | {n:.0e} | {best:.3f} | {rate:.3g} | "
              f"{naive_rate:.3g} | {rate / naive_rate:.0f}× | ≥ 1e6 steps/s, ≥ 50× |")
        B, n = 1000, 2000
        t = np.arange(n) * 0.2
        deltas = np.tile(zig(t), (B, 1)) * np.linspace(0.5, 1.0, B)[:, None]
        init = np.column_stack([np.linspace(1.5, 2.0, B), np.zeros((B, 5))])
        best = min(timed(lambda: simulate_batch(model, t, deltas, init, method=method))  # noqa: B023
                   for _ in range(3))  # fmt: skip
        rate = B * (n - 1) / best
        print(f"| batch of {B} | {method} | {B}×{n} | {best:.3f} | {rate:.3g} | "
              f"{naive_rate:.3g} | {rate / naive_rate:.0f}× | ≥ 1e7 state-steps/s |")


if __name__ == "__main__":
    main()

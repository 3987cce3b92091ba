"""Cost of the physics in the fit (issue #10): identify with a prior, sign constraints, steady
speed, the automatic prefilter and a bootstrap, against the plain fit on the same data in the same
process, at 450, 4 500 and 45 000 samples (zig-zags of the paper's ship with its sensor noise).

Run: .venv/bin/python benchmarks/bench_physics.py
"""

from __future__ import annotations

import os

from timing import best_of

from shipid.data.preprocess import lowpass
from shipid.identification.identify import identify, weighted_refit
from shipid.identification.physics import PhysicsOptions
from shipid.identification.prefilter import choose_prefilter
from shipid.identification.uncertainty import bootstrap
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import PAPER_IMU, scale_ship, scale_ship_model


def main() -> None:
    ship = scale_ship(rudder_rate_deg=9.6)
    prior = {d: dict(c) for d, c in scale_ship_model().coefficients.items()}
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| samples | plain identify (s) | prior | signs | signs + steady speed | "
          "prefilter auto | bootstrap 100, identify per replicate | bootstrap 100, "
          "weighted_refit |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|")
    for duration in (90, 900, 9000):
        log = PAPER_IMU.apply(zigzag(ship, 20, 20, duration=duration, dt=0.2, method="euler").log,
                              seed=1)  # fmt: skip
        log = lowpass(log, 0.5)
        plain = best_of(lambda lg=log: identify(lg))
        cases = [PhysicsOptions(prior=prior), PhysicsOptions(signs=True),
                 PhysicsOptions(signs=True, steady_speed=True)]  # fmt: skip
        times = [best_of(lambda lg=log, ph=ph: identify(lg, physics=ph)) for ph in cases]
        auto = best_of(lambda lg=log: choose_prefilter([lg], lambda ls: identify(ls).model), 1)
        boot = best_of(lambda lg=log: bootstrap([lg], lambda w: identify(lg, sample_weight=w).model,
                                                replicates=100), 1)  # fmt: skip
        fast = best_of(lambda lg=log: bootstrap([lg], weighted_refit(lg), replicates=100), 1)
        cells = " | ".join(f"{t:.3f} ({t / plain:.1f}×)" for t in [*times, auto, boot, fast])
        print(f"| {len(log)} | {plain:.3f} | {cells} |")


if __name__ == "__main__":
    main()

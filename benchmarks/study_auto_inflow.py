"""The default structure's inflow comparison (`identify` without `--model` on logs at a constant
propeller speed whose ship speed varies) against a known truth: the KVLCC2's MMG model observed
through noisy zig-zags with the propeller speed logged, as the MARIN files give it.

For each seed and training set (the 20/20 zig-zag to starboard alone, then with the 20/20 to
port and the 20/10), `auto_structure` compares `blanke`, `blanke-speed` and
`blanke-race+race-damping` by free-run cross-validation and fits the simplest within one
standard error of the best. Each of the three, fitted as `identify` fits it (prefilter chosen
from the data), is judged on what none was trained on: the 10/10 zig-zags' overshoots and the
35° turns' tactical diameter and steady yaw rate. Printed: the choice, whether the comparison
warned that the tied structures turn apart, and the held-out errors of each structure.

Run: .venv/bin/python benchmarks/study_auto_inflow.py [SEEDS]
"""

from __future__ import annotations

import os
import sys
import time
import warnings

import numpy as np
from study_structure import (
    HELD_ZIGZAGS,
    PAPER_IMU,
    TRAINING,
    _turn,
    _zigzag,
    fit_as_identify,
    held_out_errors,
)

from shipid.identification.auto_structure import RACE_CANDIDATES, auto_structure
from shipid.vessels import kvlcc2
from shipid.vessels.kvlcc2 import trimmed_revolutions

NOISE = 0.25  # × the paper's IMU, as study_structure.py


def main(seeds: int) -> None:
    ship = kvlcc2()
    truth_zz = {c: _zigzag(ship, *c).indices for c in HELD_ZIGZAGS}
    truth_tc = {s: _turn(ship, s).indices for s in ("starboard", "port")}
    sensor = PAPER_IMU.scaled(NOISE)
    rps = trimmed_revolutions(ship.approach_speed)
    print(f"MMG KVLCC2, {rps:.3g} rps logged; sensor noise {NOISE:g} × the paper's IMU; "
          f"{seeds} seeds\n")  # fmt: skip
    print("| trained on | choices | comparisons that warned (35° turns, 10/10 zig-zags) | "
          "structure | 10/10 overshoots (stbd 1st, 2nd, port 1st, 2nd) [deg] | 35° TD stbd, "
          "port [%] | 35° steady r stbd, port [%] |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    inside = []
    for n_logs, label in ((1, "20/20 to starboard"), (3, "20/20 both sides, 20/10")):
        choices: dict[str, int] = {}
        warned = zigzag_warned = 0
        errors: dict[str, list[list[float]]] = {s: [] for s in RACE_CANDIDATES}
        for seed in range(seeds):
            logs = [sensor.apply(_zigzag(ship, *case).log, seed=100 * seed + i).assign(n=rps)
                    for i, case in enumerate(TRAINING)][:n_logs]  # fmt: skip
            choice = auto_structure(logs)
            choices[choice.structure.name] = choices.get(choice.structure.name, 0) + 1
            warned += any("turning circle apart" in w for w in choice.warnings)
            zigzag_warned += any("zig-zag apart" in w for w in choice.warnings)
            for name in RACE_CANDIDATES:
                model, _ = fit_as_identify(logs, name)
                errors[name].append(held_out_errors(model, ship, truth_zz, truth_tc))
        chosen = ", ".join(f"{k} {v}" for k, v in choices.items())
        # Per seed and overshoot: does the truth lie between the three structures' fits?
        spread = np.array([e for e in errors.values()])[:, :, :4]  # (structure, seed, overshoot)
        inside.append((label, int(np.sum((spread.min(axis=0) <= 0) & (spread.max(axis=0) >= 0))),
                       spread.shape[1] * 4))  # fmt: skip
        for name, e in errors.items():
            m = np.nanmean(np.array(e), axis=0)
            print(f"| {label} | {chosen} | {warned}, {zigzag_warned} of {seeds} | {name} | "
                  + ", ".join(f"{x:+.1f}" for x in m[:4]) + f" | {m[4]:+.0f}, {m[6]:+.0f} | "
                  f"{m[5]:+.0f}, {m[7]:+.0f} |")  # fmt: skip
    print("\nThe truth's 10/10 overshoots between the three structures' fits: "
          + "; ".join(f"{label} {k} of {n}" for label, k, n in inside))


def paper_ship(seeds: int = 6) -> None:
    """The same comparison where ``blanke`` is the truth: the paper's ship (its rudder force in
    δ alone) with a constant rps logged, trained on its 20/20 zig-zag, then with the 10/10 too.
    Which structure is fitted, and the held-out 20° turns' yaw-rate error std over the true
    model's own on the same noisy trial (1 = the noise floor), the fitted one's against
    ``blanke``'s."""
    from shipid.demo import TRAINING, synthesise_trials
    from shipid.evaluation.validate import validate
    from shipid.vessels import scale_ship_model

    truth = scale_ship_model()
    held = ["turning δ = −20°", "turning δ = +20°"]
    chosen, costs = {}, []
    for seed in range(seeds):
        trials = synthesise_trials(seed)
        first = [trials[TRAINING].assign(n=10.0)]
        for logs in (first, first + [trials["zigzag 10/10"].assign(n=10.0)]):
            name = auto_structure(logs).structure.name
            chosen[name] = chosen.get(name, 0) + 1
            if name == PAPER_TRUTH:
                continue
            own = validate(truth, [trials[h] for h in held], held)
            ratio = {}
            for structure in (name, PAPER_TRUTH):
                model, _ = fit_as_identify(logs, structure)
                runs = validate(model, [trials[h].assign(n=10.0) for h in held], held)
                ratio[structure] = [v.metrics["r"]["std"] / o.metrics["r"]["std"]
                                    for v, o in zip(runs, own, strict=True)]  # fmt: skip
            costs.append((seed, len(logs), ratio))
    print(f"\nThe paper's ship (blanke the truth) with 10 rps logged, {seeds} seeds × (20/20; "
          "20/20 and 10/10): fitted " + ", ".join(f"{k} {v}" for k, v in chosen.items()))
    for seed, n, ratio in costs:
        print(f"  seed {seed}, {n} log(s): held-out 20° turns' r error over the noise floor "
              + "; ".join(f"{k} " + ", ".join(f"{x:.2f}" for x in v) for k, v in ratio.items()))


PAPER_TRUTH = "blanke"


if __name__ == "__main__":
    warnings.simplefilter("ignore")
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    t0 = time.perf_counter()
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 4)
    paper_ship()
    print(f"\n{time.perf_counter() - t0:.0f} s")

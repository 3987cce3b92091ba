"""How finely a closed-loop replica of a measured log must be stepped. ``validate`` judges a
zig-zag or turn by its replica: the trial run closed loop on the model, its rudder reversed where
its own heading reaches the log's switch. Stepped at the log's sampling, the rudder reversed up
to a step late, and Euler stepped the dynamics at that step; ``replica_step`` now steps a
measured log's replica where its fastest yaw rate turns the heading 0.1° (a simulated log's at
its own integrator's step).

Printed:
1. A truth: the scale ship's 20°/20° zig-zag run at 0.01 s (RK4), sampled as a measured log is,
   and replicated on the true ship at the log's step, at 0.1 s and at ``replica_step``; and its
   20° turn ordered between two samples, the replica's first order at the later sample or
   halfway.
2. The Esso Osaka's nine zig-zags on the README's model (``select --average`` on the zig-zags and
   three random runs at Δk 0.5 s): their closed-loop overshoots, mean over the nine, by step.
3. The same nine held out in turn (the README's structure refitted on the other eight and the
   three random runs, at Δk 0.1 and 0.5 s): the overshoots' error against the 0.1 s log's; and
   the replica's rudder up to the order, the approach's mean (``validate.approach_rudder``)
   against the log's first sample's (before 2026-11-30).
4. The Esso's two 35° turns on the README's model: tactical diameter and advance by step.
5. The KVLCC2's MARIN zig-zags, each predicted by the README's ``blanke-race+race-damping``
   identified from the other (Δk 0.2 s), and the published MMG model on HSVA's 20°/10° run.

Run: .venv/bin/python benchmarks/study_replica_step.py
"""

from __future__ import annotations

import os
import tempfile
import warnings

import numpy as np
from cli_models import model_by_cli
from esso_logs import DATA, README_HELD, esso_logs

import shipid.evaluation.validate as validate_module
from shipid.data.io import read_log
from shipid.data.log import column_values
from shipid.evaluation.validate import _indices_of, replica_step, trial_replica
from shipid.identification.identify import identify
from shipid.identification.select import select
from shipid.trials.indices import manoeuvre_indices, zigzag_indices
from shipid.trials.manoeuvres import turning_circle, zigzag
from shipid.trials.trial import describe_trial
from shipid.vessels import get_vessel, scale_ship
from shipid.vessels.sensors import sampled_as_measured

LIBRARY = "low-speed+wind+propeller-asymmetry"
KEYS = ("first_overshoot_deg", "second_overshoot_deg")
SHARED = DATA.parent


def replica(model, log, step=None) -> dict:
    """The closed-loop replica's indices, read as ``validate`` reads them."""
    trial = describe_trial(log)
    return _indices_of(trial_replica(model, log, "euler", trial, indices=False, step=step),
                       trial, log)  # fmt: skip


def first_sample_rudder(log, trial) -> float:
    """The replica's rudder up to the order before 2026-11-30: the log's first sample's."""
    return float(column_values(log, "delta", float)[0])


def measured(log) -> dict:
    return zigzag_indices(log, describe_trial(log, "zigzag").switch_heading_deg)


def pair(d: dict) -> str:
    return " / ".join(f"{d[k]:.2f}" for k in KEYS)


def truth() -> None:
    ship = scale_ship()
    fine = zigzag(ship, 20, 20, duration=80.0, dt=0.01, method="rk4", approach=5.0)
    print("1. The scale ship's 20°/20° zig-zag (RK4 at 0.01 s: overshoots "
          f"{pair(fine.indices)}°), sampled as a measured log; replicas on the true ship:\n")
    print("| sampling (s) | measured | replica at the log's step | at 0.1 s | at replica_step |")
    print("|---|---|---|---|---|")
    for every in (10, 20, 50):
        log = sampled_as_measured(fine.log, every)
        step = replica_step(log)
        print(f"| {every * 0.01:g} | {pair(measured(log))} | {pair(replica(ship, log, every * 0.01))}"
              f" | {pair(replica(ship, log, 0.1))} | {pair(replica(ship, log))} "
              f"({step:.4f} s) |")  # fmt: skip


def truth_turn_order() -> None:
    """The scale ship's 20° turn (RK4 at 0.01 s) ordered at ten times across one 0.5 s sample,
    sampled every 0.5 s as a measured log is: the replica's advance against the measured, its
    rudder ordered at the first sample it has moved at (as before, and as a simulated log's
    replica still is) or halfway from the sample before (a measured log's now)."""
    ship = scale_ship()
    longer: dict[str, list[float]] = {"at the later sample": [], "halfway": []}
    for order in np.arange(5.0, 5.5, 0.05):
        fine = turning_circle(ship, 20, duration=80.0, dt=0.01, method="rk4",
                              approach=float(order)).log  # fmt: skip
        log = sampled_as_measured(fine, 50)
        trial = describe_trial(log)
        measured_advance = manoeuvre_indices(log, trial=trial)["advance"]
        longer["halfway"].append(replica(ship, log)["advance"] - measured_advance)
        # The same step, but the log read as a simulated one: ordered at the later sample.
        as_simulated = log.copy()
        as_simulated.attrs = {**log.attrs,
                              "integrator": {"method": "euler", "step": replica_step(log)}}
        longer["at the later sample"].append(replica(ship, as_simulated)["advance"]
                                             - measured_advance)  # fmt: skip
    print("\nThe scale ship's 20° turn ordered at ten times across one 0.5 s sample, sampled "
          "every 0.5 s: the replica's advance minus the measured one (m)\n")
    print("| first order of the replica | mean | range |")
    print("|---|---|---|")
    for name, x in longer.items():
        print(f"| {name} | {np.mean(x):+.3f} | {min(x):+.3f} to {max(x):+.3f} |")


def esso() -> None:
    data = {dt: esso_logs(dt) for dt in (0.1, 0.5)}
    zz, rnd, turns = data[0.5]
    train = list(zz.values()) + [x for k, x in rnd.items() if k != README_HELD]
    model = select(train, library=LIBRARY, cv="logo", average=True).model
    steps = (0.5, 0.25, 0.1, 0.05, None, 0.01)
    print("\n2. The Esso Osaka's nine zig-zags (Δk 0.5 s) on the README's model, closed loop: "
          "overshoots, mean of the nine, by the replica's step\n")
    print("| step (s) | first / second overshoot (°) |")
    print("|---|---|")
    for step in steps:
        found = np.array([[replica(model, log, step)[k] for k in KEYS] for log in zz.values()])
        shown = "replica_step (" + ", ".join(sorted({f"{replica_step(x):.4f}" for x in
                                                     zz.values()})) + ")" if step is None \
            else f"{step:g}"  # fmt: skip
        print(f"| {shown} | {found.mean(0)[0]:.2f} / {found.mean(0)[1]:.2f} |")
    structure = model.structure
    print("\n3. Each zig-zag held out (the README's structure refitted on the other eight and "
          "three random runs), against the 0.1 s log's overshoots\n")
    print("| Δk (s) | replica | first overshoot: bias, mean abs (°) | second |")
    print("|---|---|---|---|")
    for dt in (0.1, 0.5):
        zz_dt, rnd_dt, _ = data[dt]
        errors: dict[str, list] = {"the log's step": [], "replica_step": []}
        for name, log in zz_dt.items():
            fitted_on = [x for k, x in zz_dt.items() if k != name] + \
                [x for k, x in rnd_dt.items() if k != README_HELD]  # fmt: skip
            fit = identify(fitted_on, model=structure, gamma=1e5, force=True).model
            truth_here = measured(data[0.1][0][name])
            for label, step in (("the log's step", dt), ("replica_step", None)):
                got = replica(fit, log, step)
                errors[label].append([got[k] - truth_here[k] for k in KEYS])
            # The replica's rudder up to the order as before: the log's first sample's.
            kept = validate_module.approach_rudder
            validate_module.approach_rudder = first_sample_rudder
            try:
                got = replica(fit, log)
            finally:
                validate_module.approach_rudder = kept
            errors.setdefault("replica_step, the first sample's rudder up to the order", []
                              ).append([got[k] - truth_here[k] for k in KEYS])  # fmt: skip
        for label, e in errors.items():
            e = np.array(e)
            print(f"| {dt:g} | {label} | {e[:, 0].mean():+.2f}, {np.abs(e[:, 0]).mean():.2f} | "
                  f"{e[:, 1].mean():+.2f}, {np.abs(e[:, 1]).mean():.2f} |")
    print("\n4. The Esso's 35° turns on the README's model: tactical diameter / advance (m), "
          "closed loop\n")
    print("| turn | measured | the log's step (0.5 s) | replica_step |")
    print("|---|---|---|---|")
    for log in turns:
        trial = describe_trial(log)
        meas = manoeuvre_indices(log, trial=trial)
        cells = [f"{meas['tactical_diameter']:.2f} / {meas['advance']:.2f}"]
        for step in (0.5, None):
            got = replica(model, log, step)
            cells.append(f"{got['tactical_diameter']:.2f} / {got['advance']:.2f}")
        side = "+35°" if meas["steady_yaw_rate"] > 0 else "−35°"
        print(f"| {side} | " + " | ".join(cells) + " |")


def kvlcc2() -> None:
    marin = SHARED / "kvlcc2-marin"
    runs = {a: read_log(marin / f"MARIN_FREE_KVLCC2_zz_{a}_m.dat", fmt="simman-marin",
                        scale=45.7, dt=0.2) for a in ("20", "-20")}  # fmt: skip
    print("\n5. The KVLCC2: each MARIN zig-zag predicted by the README's `shipid identify "
          "--model blanke-race+race-damping` of the other (Δk 0.2 s); the MMG model on HSVA's "
          "20°/10° run\n")
    print("| held out | measured | the log's step (0.2 s) | replica_step |")
    print("|---|---|---|---|")
    argv = ["identify", "--format", "simman-marin", "--scale", "45.7", "--dt", "0.2", "--model",
            "blanke-race+race-damping"]  # fmt: skip
    for held, other in (("-20", "20"), ("20", "-20")):
        with tempfile.TemporaryDirectory() as folder:
            fit = model_by_cli(argv, [str(marin / f"MARIN_FREE_KVLCC2_zz_{other}_m.dat")],
                               f"{folder}/m.json")  # fmt: skip
        log = runs[held]
        print(f"| MARIN zz {held}° | {pair(measured(log))} | {pair(replica(fit, log, 0.2))} | "
              f"{pair(replica(fit, log))} ({replica_step(log):.4f} s) |")
    hsva = read_log(SHARED / "kvlcc2-hsva" / "HSVA_CPMC_KVLCC2_Z_20_10_P.dat", fmt="simman-hsva",
                    dt=0.2)  # fmt: skip
    mmg = get_vessel("kvlcc2")
    print(f"| HSVA zz 20°/10° (the MMG model) | {pair(measured(hsva))} | "
          f"{pair(replica(mmg, hsva, 0.2))} | {pair(replica(mmg, hsva))} "
          f"({replica_step(hsva):.4f} s) |")


def main() -> None:
    warnings.simplefilter("ignore")
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    truth()
    truth_turn_order()
    if not DATA.is_dir():
        print("\n../shared/data is absent: the real logs' parts are skipped")
        return
    esso()
    kvlcc2()


if __name__ == "__main__":
    main()

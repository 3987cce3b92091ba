"""Where a zig-zag's rudder orders fall between samples: how much the step moves what shipid
computes and reads (issue #10's 1.5° overshoot line).

1. The closed loop gives an order at the first sample past its event (the heading past the
   switch, the execute time), and the rudder moves a whole step in it. The reference ships'
   20°/20° zig-zags (continuous models, RK4) run at steps of 0.01–1.0 s: their overshoots
   should not depend on the step, beyond the integrator's error.
2. A measured log's reversal headings are read halfway between the last sample on the plateau
   and the next. The real MARIN −20° run and the HSVA 20/10 run, read at their own sampling
   and resampled (``--dt``) to 0.05–0.5 s: the headings the trials reversed at should not
   depend on the resampling.

Run: .venv/bin/python benchmarks/study_event_timing.py
"""

from __future__ import annotations

import time
import warnings

from esso_logs import DATA as ESSO

from shipid.data.io import read_log
from shipid.trials.manoeuvres import zigzag
from shipid.trials.trial import describe_trial
from shipid.vessels import get_vessel

STEPS = (0.01, 0.05, 0.1, 0.2, 0.5, 1.0)
RESAMPLED = (None, 0.05, 0.1, 0.2, 0.5)
DATA = ESSO.parent


def reference_ships() -> None:
    print("| ship | step [s] | first overshoot [°] | second overshoot [°] |")
    print("|---|---|---|---|")
    for name in ("kvlcc2", "mariner"):
        ship = get_vessel(name)
        for dt in STEPS:
            ind = zigzag(ship, 20, 20, dt=dt).indices
            print(f"| {name} | {dt:g} | {ind['first_overshoot_deg']:.2f} | "
                  f"{ind['second_overshoot_deg']:.2f} |")  # fmt: skip
    print()


def measured_logs() -> None:
    runs = {"MARIN zz −20": (DATA / "kvlcc2-marin/MARIN_FREE_KVLCC2_zz_-20_m.dat",
                             {"fmt": "simman-marin", "scale": 45.7}),
            "HSVA 20/10": (DATA / "kvlcc2-hsva/HSVA_CPMC_KVLCC2_Z_20_10_P.dat",
                           {"fmt": "simman-hsva"})}  # fmt: skip
    print("| log | Δk [s] | reversal headings [°] | switch heading [°] | heading per sample [°] |")
    print("|---|---|---|---|---|")
    for name, (path, kw) in runs.items():
        if not path.is_file():
            print(f"| {name} | ../shared/data absent | | | |")
            continue
        for dt in RESAMPLED:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")  # the MARIN gyro's offset, named elsewhere
                trial = describe_trial(read_log(path, dt=dt, **kw), "zigzag")
            shown = ", ".join(f"{h:+.2f}" for h in trial.reversal_headings_deg[:3])
            print(f"| {name} | {'own' if dt is None else f'{dt:g}'} | {shown} | "
                  f"{trial.switch_heading_deg:.2f} | {trial.reversal_step_deg:.2f} |")  # fmt: skip
    print()


if __name__ == "__main__":
    start = time.perf_counter()
    reference_ships()
    measured_logs()
    print(f"{time.perf_counter() - start:.0f} s")

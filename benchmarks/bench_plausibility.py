"""Cost of the plausibility checks' held turns (issue #13), against the way they ran before.

1. A held turn that has not settled in 300 s is made longer (doubled, up to 4800 s). It now goes
   on from its last state and rudder; before, each longer run started again from the approach.
   Baseline in the same process: ``doubling`` over a fresh ``_held_runs`` for each length,
   which runs it from the start, the way the code before did. Both sides held, not entered
   drifting (which runs once, at the settled length, either way); the entries compared to the
   bit.
2. A model checked again (the same terms, coefficients and approach) is served from a memo of
   the reports; baseline: the same check with the memo emptied before each call (identified
   models only: a reference ship is not what a search checks).

Cases: the single-screw ``tanker`` (full scale, 10° rudder: its turns settle at 1200 s), the
paper's scale ship (settles within 300 s: no doubling, nothing to gain) and, with
``../shared/data``, the default model of one Esso Osaka zig-zag file.

Run: .venv/bin/python benchmarks/bench_plausibility.py
"""

from __future__ import annotations

import contextlib
import io
import os
import tempfile
from pathlib import Path

from timing import best_of

import shipid.identification.plausibility as plausibility
from shipid.dynamics.model import ManoeuvringModel
from shipid.trials.manoeuvres import doubling
from shipid.vessels import scale_ship_model, tanker

ESSO_FILE = (Path(__file__).resolve().parents[2] / "shared" / "data" / "esso-osaka" / "zigzag"
             / "zigzag_31-Jul-2020_13_14_21.csv")  # fmt: skip


def _cases() -> list[tuple[str, object, float, float | None, float]]:
    ship = tanker()
    cases = [("tanker (full scale, 10°)", ship, ship.approach_speed, None, 10.0),
             ("paper's scale ship (35°)", scale_ship_model(), 1.6, None, 35.0)]  # fmt: skip
    if ESSO_FILE.is_file():
        from shipid.cli import main as shipid
        from shipid.reporting.modelfile import load_model

        with tempfile.TemporaryDirectory() as tmp:
            out = f"{tmp}/m.json"
            with contextlib.redirect_stdout(io.StringIO()), \
                    contextlib.redirect_stderr(io.StringIO()):  # fmt: skip
                shipid(["identify", "--format", "osaka-frt", "--dt", "0.1", str(ESSO_FILE),
                        "-o", out])  # fmt: skip
            cases.append(("Esso, one zig-zag file's default (35°)", load_model(out), 0.36, 10.0,
                          35.0))  # fmt: skip
    return cases


def _from_the_start(model, speed, rps, rudder) -> dict:
    """The held turns as the code before ran them: each longer run from the approach."""
    dt = plausibility.held_step(model, speed, rps)
    out = {}
    for side in ("starboard", "port"):
        out[side], _ = doubling(
            lambda length, side=side: plausibility._held_runs(model, speed, rps, rudder, side,
                                                              dt)(length),
            plausibility.HELD_DURATION,
            lambda entry: entry["diverged"] or entry["settled"],
            2**plausibility.HELD_MAX_DOUBLINGS)  # fmt: skip
    return out


def main() -> None:
    print(f"load average {os.getloadavg()[0]:.2f} on {os.cpu_count()} cores\n")
    print("| case | held turns, going on (ms) | from the start (ms) | ratio | settled at | same |")
    print("|---|---|---|---|---|---|")
    cases = _cases()
    for label, model, speed, rps, rudder in cases:
        def going_on(model=model, speed=speed, rps=rps, rudder=rudder):
            return plausibility.held_rudder(model, speed, rps, rudder, drifting=False)

        def before(model=model, speed=speed, rps=rps, rudder=rudder):
            return _from_the_start(model, speed, rps, rudder)

        new, old = going_on(), before()
        t_new, t_old = best_of(going_on, 7), best_of(before, 7)
        settled = ", ".join(f"{new[s]['duration']:g} s" for s in ("starboard", "port"))
        print(f"| {label} | {1e3 * t_new:.1f} | {1e3 * t_old:.1f} | {t_new / t_old:.2f} | "
              f"{settled} | {new == old} |")  # fmt: skip

    print("\n| case | check again, from the memo (ms) | with the memo emptied (ms) | ratio |")
    print("|---|---|---|---|")
    for label, model, speed, rps, rudder in cases:
        if not isinstance(model, ManoeuvringModel):  # a reference ship: checked in no search
            continue

        def check(model=model, speed=speed, rps=rps, rudder=rudder):
            return plausibility.check_plausibility(model, speed, rps, rudder)

        def fresh(model=model, speed=speed, rps=rps, rudder=rudder):
            plausibility._CHECKED.clear()
            return check(model, speed, rps, rudder)

        check()
        t_memo, t_fresh = best_of(check, 5), best_of(fresh)
        print(f"| {label} | {1e3 * t_memo:.3f} | {1e3 * t_fresh:.1f} | {t_memo / t_fresh:.4f} |")


if __name__ == "__main__":
    main()

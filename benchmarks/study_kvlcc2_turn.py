"""What the KVLCC2's 20/20 zig-zag says of its 35° turn (issue #10): models of the MARIN 20/20
run (first rudder +20°) made by ``shipid identify`` with the structures, constraints and priors
a user has, judged on what they were not fitted to: the MARIN −20° and HSVA 20/10 runs (free-run
error std of r) and the 35° turn and 10°/10° zig-zag of the KVLCC2's MMG model (no real turn or
10/10 run is in ``../shared/data``; the MMG model is the published fit to the ship's captive
tests, and its computed turn is reference-ships.md §2.8's). A spread of the turn across models
that predict the unseen zig-zags alike is what the zig-zag cannot tell. Then the same with the
rudder's force as the normal force of one inflow (``--rudder-normal``), and that inflow's
parameters halved and doubled one at a time.

Run: .venv/bin/python benchmarks/study_kvlcc2_turn.py
"""

from __future__ import annotations

import contextlib
import io
import json
import time
import warnings
from pathlib import Path

from cli_models import model_by_cli
from esso_logs import run_with_files
from kvlcc2_logs import DATA, kvlcc2_logs

from shipid.cli import main
from shipid.evaluation.validate import validate

TRAINING = DATA / "kvlcc2-marin" / "MARIN_FREE_KVLCC2_zz_20_m.dat"
PARTICULARS = str(DATA / "kvlcc2-marin" / "ship_data.yml")
READ = ["--format", "simman-marin", "--scale", "45.7", "--dt", "0.2"]
RACE = ["--model", "blanke-race+race-damping"]
VARIANTS = {
    "identify (default)": [],
    "blanke-speed": ["--model", "blanke-speed"],
    "blanke-race": ["--model", "blanke-race"],
    "blanke-race+race-damping (README)": RACE,
    "… --crossflow": [*RACE, "--crossflow", "--particulars", PARTICULARS],
    "… --constraints signs": [*RACE, "--constraints", "signs"],
    "… --prior clarke --gamma auto": [*RACE, "--particulars", PARTICULARS, "--prior", "clarke",
                                       "--gamma", "auto"],
    "… --prior kvlcc2 --gamma auto": [*RACE, "--particulars", PARTICULARS, "--prior", "kvlcc2",
                                       "--gamma", "auto"],
    # The race's yaw damping bounded (its fit, −0.22 1/s, is three times the hull's u·r at the
    # approach speed).
    "… signs, race yaw damping ≥ −0.05": [*RACE, "--constraints", "signs", "--bound",
                                          "r: r >= -0.05"],
    # The rudder's force as its normal force of one inflow (MMG), from the particulars.
    "identify --rudder-normal": ["--rudder-normal", "--particulars", PARTICULARS],
    "blanke-speed --rudder-normal": ["--model", "blanke-speed", "--rudder-normal",
                                     "--particulars", PARTICULARS],
    "blanke-race+race-damping --rudder-normal": [*RACE, "--rudder-normal", "--particulars",
                                                 PARTICULARS],
    "… --rudder-normal --crossflow": [*RACE, "--rudder-normal", "--crossflow", "--particulars",
                                      PARTICULARS],
    "… --rudder-normal --prior clarke --gamma auto": [*RACE, "--rudder-normal", "--particulars",
                                                      PARTICULARS, "--prior", "clarke",
                                                      "--gamma", "auto"],
}  # fmt: skip
# The inflow's parameters halved and doubled one at a time (the race c, the flow straightening
# g, the rudder's position x), in blanke-race+race-damping --rudder-normal: how much of the turn
# is the defaults' (``shipid.dynamics.rudder``).
SENSITIVITY = {"c × ½": (1.0, 0.5, 1.0, 1.0), "c × 2": (1.0, 2.0, 1.0, 1.0),
               "g × ½": (1.0, 1.0, 0.5, 1.0), "g × 2": (1.0, 1.0, 2.0, 1.0),
               "x × ½": (1.0, 1.0, 1.0, 0.5), "x × 2": (1.0, 1.0, 1.0, 2.0),
               "a: w 0.25 (not 0.355)": ((0.75 / 0.645) ** 2, 1.0, 1.0, 1.0)}  # fmt: skip


def _manoeuvre(model: str, argv: list[str], folder: Path) -> dict:
    out = folder / "manoeuvre.json"
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        code = main(["manoeuvre", model, *argv, "--json", str(out)])
    return json.loads(out.read_text(encoding="utf-8"))["indices"] if code == 0 else {}


def _turn_and_zigzag(model: str, folder: Path) -> list[str]:
    turn = _manoeuvre(model, ["turning", "--rudder", "35", "--duration", "400"], folder)
    zz = _manoeuvre(model, ["zigzag", "--rudder", "10", "--duration", "300"], folder)
    cells = [f"{turn[k]:.4g}" if turn.get(k) is not None else "–"
             for k in ("advance", "tactical_diameter", "steady_speed", "steady_yaw_rate")]
    cells.append(", ".join(f"{zz[k]:.1f}" if zz.get(k) is not None else "–"
                           for k in ("first_overshoot_deg", "second_overshoot_deg")))  # fmt: skip
    return cells


def _sensitivity_variants() -> dict:
    from shipid.data.particulars import read_particulars
    from shipid.dynamics.model import get_structure
    from shipid.dynamics.rudder import RudderInflow

    base = RudderInflow.from_particulars(read_particulars(PARTICULARS), "port")
    out = {}
    for label, (fa, fc, fg, fx) in SENSITIVITY.items():
        inflow = RudderInflow(base.a * fa, base.c * fc, base.g * fg, base.x * fx)
        terms = get_structure("blanke-race+race-damping").with_rudder_normal(inflow).terms
        spec = "; ".join(f"{d}: {', '.join(t)}" for d, t in terms.items())
        out[f"… --rudder-normal, {label}"] = ["--model", spec]
    return out


def study(folder: Path) -> None:
    held = {k: v for k, v in kvlcc2_logs(0.2).items() if k != "MARIN zz 20°"}
    print("Trained on MARIN zz 20°; held out: the MARIN −20° and HSVA 20/10 runs (free-run r error "
          "std [rad/s], closed-loop overshoots, measured in brackets); the 35° starboard turn and "
          "the 10°/10° zig-zag (starboard first, the training log's rudder rate) from the "
          "model's approach, against the MMG model's\n")  # fmt: skip
    print("| model | MARIN zz −20°: r, overshoots | HSVA 20/10: r, overshoots | advance [m] | "
          "tactical diameter [m] | steady speed [m/s] | steady yaw rate [rad/s] | "
          "10°/10° overshoots [°] | seconds |")  # fmt: skip
    print("|---|---|---|---|---|---|---|---|---|")
    print("| MMG model (reference-ships.md §2) | | | " + " | ".join(_turn_and_zigzag("kvlcc2",
                                                                         folder)) + " | |")
    for label, extra in {**VARIANTS, **_sensitivity_variants()}.items():
        out = str(folder / "model.json")
        t0 = time.perf_counter()
        model = model_by_cli(["identify", *READ, *extra], [str(TRAINING)], out)
        seconds = time.perf_counter() - t0
        if model is None:
            print(f"| {label} | failed | | | | | | | |")
            continue
        cells = unseen_runs(model, held) + _turn_and_zigzag(out, folder)
        print(f"| {label} | " + " | ".join(cells) + f" | {seconds:.1f} |")


def unseen_runs(model, held: dict) -> list[str]:
    """Per held-out run: its free-run r error std and closed-loop overshoots (measured in
    brackets)."""
    cells = []
    for v in validate(model, list(held.values())):
        closed, measured = v.indices["closed_loop"], v.indices["measured"]
        os_ = ", ".join(f"{closed.get(k, float('nan')):.1f}°" for k in
                        ("first_overshoot_deg", "second_overshoot_deg"))  # fmt: skip
        meas = ", ".join(f"{measured[k]:.1f}" for k in ("first_overshoot_deg",
                                                        "second_overshoot_deg"))
        cells.append(f"{v.metrics['r']['std']:.5f}, {os_} ({meas})")
    return cells


# The MMG model's own particulars (reference-ships.md §2), as a user of its basin would give them.
MMG_PARTICULARS = {"length": 7.0, "beam": 1.27, "draught": 0.46, "block_coefficient": 0.81,
                   "propeller_diameter": 0.216, "rudder_height": 0.345, "rudder_area": 0.0539,
                   "mass": 3351.75, "xg": 0.25}  # fmt: skip


TRUTH_STRUCTURES = ("blanke-speed", "blanke-race+race-damping")


def _cell(errors, columns, fmt: str) -> str:
    """Mean error (mean |error|) over the seeds of the ``columns`` of (seed, quantity) ``errors``."""
    import numpy as np

    mean, size = np.nanmean(errors, axis=0), np.nanmean(np.abs(errors), axis=0)
    return ", ".join(f"{mean[c]:{fmt}} ({size[c]:.1f})" for c in columns)


def mmg_truth(seeds: int = 6, noise: float = 0.25) -> None:
    """A known truth of another form: the MMG model's 20/20 zig-zags through the sensor model
    (``noise`` × the paper's IMU, as study_structure.py), its propeller speed logged, written to
    files and identified by ``shipid identify --model NAME`` with and without
    ``--rudder-normal`` (the MMG model's own particulars); judged on the MMG model's 10/10
    zig-zags and 35° turns, run from its approach with its steering gear."""
    import json
    import tempfile

    import numpy as np
    from study_structure import (
        HELD_ZIGZAGS,
        PAPER_IMU,
        TRAINING,
        _turn,
        _zigzag,
        held_out_errors,
    )

    from shipid.data.io import write_log
    from shipid.vessels import kvlcc2
    from shipid.vessels.kvlcc2 import trimmed_revolutions

    ship = kvlcc2()
    rps = trimmed_revolutions(ship.approach_speed)
    truth_zz = {c: _zigzag(ship, *c).indices for c in HELD_ZIGZAGS}
    truth_tc = {s: _turn(ship, s).indices for s in ("starboard", "port")}
    keys = ("tactical_diameter", "steady_yaw_rate", "steady_speed")
    sensor = PAPER_IMU.scaled(noise)
    print(f"\nThe MMG model as the truth: its 20/20 zig-zags, {rps:.4g} rps logged, sensor noise "
          f"{noise:g} × the paper's IMU, {seeds} seeds, made by the command line; held out: its "
          "10/10 zig-zags and 35° turns. Mean error (mean |error|) over the seeds\n")  # fmt: skip
    print("| trained on | structure | 10/10 overshoots stbd 1st, 2nd, port 1st, 2nd [deg] | "
          "35° tactical diameter stbd, port [%] | steady yaw rate [%] | steady speed [%] | "
          "failed |")  # fmt: skip
    print("|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as folder:
        particulars = f"{folder}/mmg.json"
        with open(particulars, "w", encoding="utf-8") as f:
            json.dump(MMG_PARTICULARS, f)
        variants = {}
        for name in TRUTH_STRUCTURES:
            variants[name] = ["identify", "--model", name]
            variants[f"{name} --rudder-normal"] = ["identify", "--model", name, "--rudder-normal",
                                                   "--particulars", particulars]
            variants[f"{name} --rudder-normal --prior clarke --gamma auto"] = [
                *variants[f"{name} --rudder-normal"], "--prior", "clarke", "--gamma", "auto"]
        for n_logs, label in ((1, "20/20 to starboard"), (3, "20/20 both sides, 20/10")):
            files = [[str(write_log(sensor.apply(_zigzag(ship, *case).log, seed=100 * seed + i)
                                    .assign(n=rps), f"{folder}/zz{seed}_{i}.csv"))
                      for i, case in enumerate(TRAINING)][:n_logs] for seed in range(seeds)]
            for name, argv in variants.items():
                rows, failed = [], 0
                for paths in files:
                    model = model_by_cli(argv, paths, f"{folder}/m.json")
                    if model is None:
                        failed += 1
                        continue
                    rows.append(held_out_errors(model, ship, truth_zz, truth_tc, rps, keys))
                e = np.array(rows)
                print(f"| {label} | {name} | {_cell(e, range(4), '+.1f')} | "
                      f"{_cell(e, (4, 7), '+.0f')} | {_cell(e, (5, 8), '+.0f')} | "
                      f"{_cell(e, (6, 9), '+.0f')} | {failed} |")  # fmt: skip


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # the MARIN yaw rate's offset (study_gyro_offset.py)
    run_with_files(study)
    mmg_truth()

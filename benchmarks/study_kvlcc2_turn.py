"""What the KVLCC2's 20/20 zig-zag says of its 35° turn (issue #10): models of the MARIN 20/20
run (first rudder +20°) made by ``shipid identify`` with the structures, constraints and priors
a user has, judged on what they were not fitted to: the MARIN −20° and HSVA 20/10 runs (free-run
error std of r) and the 35° turn and 10°/10° zig-zag of the KVLCC2's MMG model (no real turn or
10/10 run is in ``../shared/data``; the MMG model is the published fit to the ship's captive
tests, and its computed turn is reference-ships.md §2.8's). A spread of the turn across models
that predict the unseen zig-zags alike is what the zig-zag cannot tell.

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
}  # fmt: skip


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
    for label, extra in VARIANTS.items():
        out = str(folder / "model.json")
        t0 = time.perf_counter()
        model = model_by_cli(["identify", *READ, *extra], [str(TRAINING)], out)
        seconds = time.perf_counter() - t0
        if model is None:
            print(f"| {label} | failed | | | | | | | |")
            continue
        cells = []
        for v in validate(model, list(held.values())):
            closed, measured = v.indices["closed_loop"], v.indices["measured"]
            os_ = ", ".join(f"{closed.get(k, float('nan')):.1f}°" for k in
                            ("first_overshoot_deg", "second_overshoot_deg"))  # fmt: skip
            meas = ", ".join(f"{measured[k]:.1f}" for k in ("first_overshoot_deg",
                                                            "second_overshoot_deg"))
            cells.append(f"{v.metrics['r']['std']:.5f}, {os_} ({meas})")
        cells += _turn_and_zigzag(out, folder)
        print(f"| {label} | " + " | ".join(cells) + f" | {seconds:.1f} |")


if __name__ == "__main__":
    warnings.simplefilter("ignore")  # the MARIN yaw rate's offset (study_gyro_offset.py)
    run_with_files(study)

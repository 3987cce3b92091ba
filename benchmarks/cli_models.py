"""Models made by the command line itself, as the studies of unseen manoeuvres make them (run as
scripts: this folder is on their path)."""

from __future__ import annotations

import contextlib
import io

from shipid.cli import main
from shipid.data.io import write_log
from shipid.reporting.modelfile import load_model


def noisy_files(clean: dict, sensors, seed: int, folder: str) -> dict[str, str]:
    """Each clean log through ``sensors`` (its own seed per log and seed) written as a CSV file:
    {name: path}."""
    return {name: str(write_log(sensors.apply(log, seed=100 * seed + i),
                                f"{folder}/{name}_{seed}.csv"))  # fmt: skip
            for i, (name, log) in enumerate(clean.items())}


def model_by_cli(argv: list[str], paths: list[str], out: str):
    """``shipid ARGV PATHS -o OUT``, quiet; the model file's model, or None where it failed."""
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        code = main([*argv, *paths, "-o", out])
    return None if code else load_model(out)


def truth_indices(ship, turns, dt: float, zigzag_s: float) -> dict:
    """The ship's own indices the models are judged against: {(angle, side): (tactical
    diameter, steady yaw rate)} of each turn, and 'zz10': its 10°/10° zig-zag's overshoots."""
    from shipid.trials.manoeuvres import turning_circle, zigzag

    truth = {}
    for angle, side in turns:
        ind = turning_circle(ship, angle, side=side, dt=dt).indices
        truth[(angle, side)] = (ind["tactical_diameter"], ind["steady_yaw_rate"])
    zz = zigzag(ship, 10, 10, duration=zigzag_s, dt=dt).indices
    truth["zz10"] = (zz["first_overshoot_deg"], zz["second_overshoot_deg"])
    return truth


def judged(model, truth: dict, speed: float, steering, dt: float, zigzag_s: float) -> list[str]:
    """The cells of one row: each turn of ``truth``'s tactical diameter and steady yaw rate
    (error against the ship's), and the 10°/10° overshoots' errors, the model run from the
    ship's approach with the ship's own gear (without it the model's rudder moved at once, and
    the Mariner models' overshoots came 2–3° low)."""
    from shipid.trials.manoeuvres import turning_circle, zigzag

    cells = []
    for angle, side in (key for key in truth if key != "zz10"):
        res = turning_circle(model, angle, side=side, dt=dt, speed=speed, steering=steering)
        ind = {} if res.diverged else (res.indices or {})
        td, r = ind.get("tactical_diameter"), ind.get("steady_yaw_rate")
        if td is None or r is None:
            cells.append("no turn")
            continue
        td0, r0 = truth[(angle, side)]
        cells.append(f"{100 * (td / td0 - 1):+.0f} % (r {100 * (r / r0 - 1):+.0f} %)")
    zz = zigzag(model, 10, 10, duration=zigzag_s, dt=dt, speed=speed, steering=steering)
    ind = {} if zz.diverged else (zz.indices or {})
    first, second = ind.get("first_overshoot_deg"), ind.get("second_overshoot_deg")
    cells.append("–" if first is None or second is None else
                 f"{first - truth['zz10'][0]:+.1f}°, {second - truth['zz10'][1]:+.1f}°")
    return cells


JUDGED_COLUMNS = ("35° starboard: tactical diameter (steady r)", "35° port", "20° starboard",
                  "10°/10° overshoots")


def judged_header(leading: list[str]) -> str:
    """The header and separator of a table of ``judged_row``s: ``leading`` columns, then the
    judged ones (the turns of ``TURNS`` = 35° both sides and 20° starboard, the 10°/10°)."""
    columns = [*leading, *JUDGED_COLUMNS]
    return "| " + " | ".join(columns) + " |\n" + "|" + "---|" * len(columns)


def judged_row(cells: list[str], argv: list[str], paths: list[str], out: str, truth: dict, ship,
               dt: float, zigzag_s: float, structure=None) -> str:
    """One table row: ``cells``, then the model ``shipid ARGV PATHS -o OUT`` makes (its
    structure's name, or ``structure(out, model)``) and ``judged``'s cells; 'failed' where the
    command failed."""
    model = model_by_cli(argv, paths, out)
    if model is None:
        return "| " + " | ".join([*cells, "failed"]) + " |"
    name = structure(out, model) if structure else model.structure.name
    return "| " + " | ".join([*cells, name, *judged(model, truth, ship.approach_speed,
                                                    ship.steering, dt, zigzag_s)]) + " |"  # fmt: skip

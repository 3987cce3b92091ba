"""A candidate is checked at every propeller speed its training logs ran at, not the first log's
alone: no ship ends a held turn going astern, turns the other way or diverges at a speed its own
logs ran at (issue #10: from two Esso Osaka zig-zag files at 15 and 12 rps, the model handed out
ended its 35° turns going astern at 12 rps)."""

import contextlib
import io
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from cli_helpers import run

from shipid.cli import main
from shipid.identification.plausibility import gross_at_other_rps, other_propeller_speeds
from shipid.reporting.modelfile import load_document, model_from_document, training_conditions

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
ZIGZAG = DATA / "esso-osaka" / "zigzag"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="../shared/data is not present")


def _log(n: float | None) -> pd.DataFrame:
    t = np.arange(0.0, 60.0, 0.5)
    log = pd.DataFrame({"t": t, "delta": 0.0, "u": 0.4, "v": 0.0, "r": 0.0})
    if n is not None:
        log["n"] = n
    return log


def test_the_other_propeller_speeds_are_the_logs_apart_from_the_first():
    varying = _log(8.0)
    varying["n"] = np.linspace(-10.0, 10.0, len(varying))  # a random run: no one rps
    logs = [_log(n) for n in (10.0, 16.7, 12.0, 12.3, 10.2, -5.0, 0.0, None)] + [varying]
    # 12.3 and 10.2 are within 5 % of 12 and 10; astern, stopped and unlogged are no approach.
    assert other_propeller_speeds(logs, 10.0) == [12.0, 16.7]
    assert other_propeller_speeds(logs, None) == []
    assert other_propeller_speeds([_log(10.0)], 10.0) == []


def _pair_model(tmp_path, first: str, second: str):
    """(model, training conditions) of a plain ``identify`` of two Esso zig-zag files at Δk 0.5 s."""
    files = [str(ZIGZAG / f"zigzag_31-Jul-2020_{t}.csv") for t in (first, second)]
    out = tmp_path / "pair.json"
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(["identify", "--format", "osaka-frt", "--dt", "0.5", *files,
                     "-o", str(out)]) == 0  # fmt: skip
    doc = load_document(out)
    return model_from_document(doc, str(out), "model"), training_conditions(doc)


@needs_data
def test_a_pair_of_zigzags_at_two_rps_gives_a_model_that_turns_at_both_and_beyond(tmp_path):
    """Checked at the first log's 10 rps alone, the model handed out ended its turn to port
    going astern at the second log's 12 rps (as the pair at 15 and 12 rps did to both sides).
    Then, checked at both, its library's constant, the same force at every rps, ended its 35°
    turns going astern at 15 and 16.7 rps, where the thrust had grown and the constant had not
    (the pair at 12 and 10 rps at 8 rps, where the thrust had fallen). The library's constant
    and δ² are now written as advance-ratio similarity has them (n|n|, n⁺²δ²): its turns hold
    from 8 to 16.7 rps."""
    model, cond = _pair_model(tmp_path, "13_22_52", "14_10_05")  # 10 rps read first, 12 rps
    assert round(cond["rps"]) == 10
    assert "1" not in model.structure.all_terms and "delta^2" not in model.structure.all_terms
    assert gross_at_other_rps(model, cond["speed"], cond["rps"], [8.0, 12.0, 15.0, 16.67]) == {}


def _drag_model():
    """The rudder's drag grows as n⁴δ² and the thrust as n²: at 10 rps the 35° turn keeps half
    its speed, from 11.6 rps on (n² = 5e-4 / (1e-5 δ²)) the drag wins and the turn runs
    astern, where this hull's terms make it diverge."""
    from shipid.dynamics.model import ManoeuvringModel, get_structure

    structure = get_structure("u: |u|u, pos(n)^2, pos(n)^4*delta^2; v: u*v, u*r, u*delta; "
                              "r: u*v, u*r, u*delta")  # fmt: skip
    return ManoeuvringModel(structure, {
        "u": {"|u|*u": -1.0, "pos(n)^2": 5e-4, "pos(n)^4*delta^2": -1e-5},
        "v": {"u*v": -1.5, "u*r": -0.3, "u*delta": 0.05},
        "r": {"u*v": -0.5, "u*r": -1.2, "u*delta": -0.4}})  # fmt: skip


def test_identify_warns_where_a_given_structure_fails_at_another_logs_rps():
    """A structure given with ``--model`` is fitted as it is: ``identify`` says where its held
    turn fails at a propeller speed its logs ran at."""
    from shipid.identification.beyond_the_logs import at_the_logs_other_rps
    from shipid.identification.plausibility import plausibility_at_approach

    model = _drag_model()
    report = plausibility_at_approach(model, 0.22, 10.0)[0]
    assert not [k for k in report["held_rudder"] if report["held_rudder"][k]["diverged"]]
    assert at_the_logs_other_rps(model, report, [_log(10.0)]) == []
    notes = at_the_logs_other_rps(model, report, [_log(10.0), _log(15.0)])
    assert notes and all("at 15 rps" in n and ("astern" in n or "diverges" in n) for n in notes)


@pytest.mark.parametrize(("rps", "warned"), [(10.0, True), (8.0, False)])
def test_a_model_that_fails_above_the_logs_rps_is_named(rps, warned):
    """At 1.4 times the logs' highest rps: 14 rps fails (the drag wins from 11.6), 11.2 not."""
    from shipid.identification.beyond_the_logs import above_the_logs_rps, below_the_logs_rps
    from shipid.identification.plausibility import plausibility_at_approach

    model = _drag_model()
    report = plausibility_at_approach(model, 0.0224 * rps, rps)[0]
    found = above_the_logs_rps(model, report, [_log(rps)]) or ""
    prefix = ("above the logs' propeller speeds the model extrapolates: at 14 rps (1.4 times the "
              "highest, 10) it ")  # fmt: skip
    assert found.startswith(prefix) if warned else found == ""
    assert below_the_logs_rps(model, report, [_log(rps)]) is None


@needs_data
@pytest.mark.parametrize("command", ["identify", "select"])
def test_where_nothing_similar_is_plausible_the_surge_alone_keeps_its_constant(tmp_path, capsys,
                                                                               command):
    """The nine Esso zig-zag files: every candidate of the default library with its constant and
    δ² written as advance-ratio similarity has them ends its held 35° turns astern (its thrust
    rides on u|n| against a negative n⁺², one column along runs whose speed goes with n).
    identify and select (without --library) then search the library with them as they are in
    the surge alone, the side force's constant written as similarity has it, say so, and hand
    out a plausible model. With a side force the same at every rps (the library with every
    constant, searched before) a 10° turn to starboard at 6 rps was 12 times as wide in
    lengths as at 16.7 rps; a ship's is about as wide at every speed."""
    from shipid.dynamics.equilibrium import surge_equilibrium
    from shipid.identification.plausibility import disqualifying, plausibility_at_approach
    from shipid.trials.manoeuvres import turning_circle

    files = sorted(ZIGZAG.glob("*.csv"))
    out = tmp_path / "nine.json"
    quiet = ["--quiet"] if command == "select" else []
    code, said, err = run([command, "--format", "osaka-frt", "--dt", "0.5", *quiet, *files,
                           "-o", out], capsys)  # fmt: skip
    assert code == 0, err
    assert "with its constant and δ² in the surge (logo)…" in err
    assert ("so the library with its constant and δ² in the surge was searched instead (the "
            "side force's constant written as similarity has it)") in said + err
    doc = load_document(out)
    model = model_from_document(doc, str(out), "model")
    assert "1" in model.structure.terms["u"]
    assert "1" not in model.structure.terms["v"] and "1" not in model.structure.terms["r"]
    cond = training_conditions(doc)
    report, _ = plausibility_at_approach(model, cond["speed"], cond["rps"])
    assert disqualifying(report, model) == []
    for side in ("starboard", "port"):
        across = []
        for rps in (6.0, 16.67):
            speed = surge_equilibrium(model, cond["speed"], rps)
            turn = turning_circle(model, 10.0, side, rps=rps, speed=speed, dt=0.2, wind=(0, 0))
            across.append(turn.indices["tactical_diameter"])
        assert max(across) / min(across) < 1.5, (side, across)

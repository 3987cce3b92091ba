"""The approach a model's checks and manoeuvres start from. It was the mean of the first 2 % of
the first training log: for a random run begun at rest (the Esso Osaka's), 0.02 m/s, from which
the plausibility checks said nothing of the ship, and ``select`` refused a block of it ("starts
without headway"). A log that starts without headway now gives its running condition: the median
where it runs ahead at half its typical speed or more, and a warning says so."""

import json

import numpy as np
import pandas as pd
import pytest
from cli_helpers import run

from shipid.data.io import write_log
from shipid.data.log import approach, approach_note
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import scale_ship


def _log(u: np.ndarray, n: np.ndarray) -> pd.DataFrame:
    t = np.arange(len(u)) * 0.1
    return pd.DataFrame({"t": t, "delta": 0.0, "u": u, "v": 0.0, "r": 0.0, "n": n})


def test_a_log_running_from_its_start_keeps_its_first_two_percent():
    # A guard (it passes on the old code too): the fix leaves such logs, every README log among
    # them, as they were.
    u = np.linspace(1.0, 2.0, 1000)
    log = _log(u, np.full(1000, 10.0))
    assert approach(log, "u") == pytest.approx(u[:20].mean())
    assert approach(log, "n") == 10.0 and approach_note(log, "a.csv") is None
    assert approach(log, "wind_speed") is None


def test_a_log_from_rest_gives_its_running_condition():
    # 20 s from rest at 4 rps, then 80 s running at 2 m/s, 10 rps.
    u = np.concatenate([np.linspace(0.0, 1.5, 200), np.full(800, 2.0)])
    n = np.concatenate([np.full(200, 4.0), np.full(800, 10.0)])
    log = _log(u, n)
    assert approach(log, "u") == 2.0 and approach(log, "n") == 10.0
    note = approach_note(log, "a.csv")
    assert note.startswith("a.csv starts without headway (0.0") and "2 m/s at 10 rps" in note


def test_identify_cuts_a_manoeuvre_from_rest_to_its_approach(tmp_path, capsys):
    """A zig-zag or turn that starts at rest is cut to its manoeuvre, as --start auto --end auto
    cuts it (the Esso Osaka's nine zig-zag files read whole put the default model's 35° turns
    47 % and 58 % long, cut 28 % and 2 %); --start 0 reads it whole, and the running ship is
    checked all the same."""
    log = zigzag(scale_ship(rudder_rate_deg=9.6), 20, 20, duration=90, dt=0.2, method="euler",
                 approach=20.0).log  # fmt: skip
    # The first 10 s at rest, then as simulated (no track: it would no longer follow u).
    ramp = np.clip(log["t"].to_numpy() / 10.0, 0.0, 1.0)
    log = log.drop(columns=["x", "y"]).assign(u=log["u"] * ramp)
    path = write_log(log, tmp_path / "from_rest.csv")
    flags = ["--force", "--filter", "none", "--no-output-error"]
    code, out, err = run(["identify", path, *flags, "-o", tmp_path / "m.json"], capsys)
    assert code == 0, err
    assert ("1 of the logs (from_rest.csv) is a zig-zag or turn that starts from rest: cut to "
            "the manoeuvre, from 5 s before the rudder's execute to its end") in err
    assert "starts without headway" not in err and "turn read whole, from rest" not in err
    doc = json.loads((tmp_path / "m.json").read_text())
    prep = doc["identification"]["preprocessing"]
    assert prep["cut_to_manoeuvre"] == ["from_rest.csv"]
    # The same fit as the file cut by hand.
    code, _, err = run(["identify", path, *flags, "--start", "auto", "--end", "auto",
                        "-o", tmp_path / "cut.json"], capsys)  # fmt: skip
    assert code == 0, err
    by_hand = json.loads((tmp_path / "cut.json").read_text())
    assert doc["model"]["coefficients"] == by_hand["model"]["coefficients"]
    assert by_hand["identification"]["preprocessing"]["cut_to_manoeuvre"] is None
    # Read whole on request: the running ship's condition is still the one checked.
    code, out, err = run(["identify", path, *flags, "--start", "0", "-o", tmp_path / "w.json"],
                         capsys)  # fmt: skip
    assert code == 0, err
    assert "starts without headway" in err
    assert "1 of the logs (from_rest.csv) is a zig-zag or turn read whole, from rest" in err
    prep = json.loads((tmp_path / "w.json").read_text())["identification"]["preprocessing"]
    assert prep["approach_speed"] == pytest.approx(float(np.median(log["u"][ramp >= 1])), rel=0.05)
    assert prep["cut_to_manoeuvre"] is None
    # validate reads it as it was fitted: cut, and so judged on the manoeuvre.
    tables, errs = {}, {}
    for label, trim in (("default", []), ("by hand", ["--start", "auto", "--end", "auto"])):
        code, out, errs[label] = run(["validate", tmp_path / "m.json", path, *trim,
                                      "--no-bands"], capsys)  # fmt: skip
        assert code == 0, errs[label]
        tables[label] = out.split("\n\n")[0]
    assert tables["default"] == tables["by hand"]
    assert ("is a zig-zag or turn that starts from rest: cut to the manoeuvre" in errs["default"]
            and "--start 0 validates it whole" in errs["default"])  # fmt: skip
    assert "cut to the manoeuvre" not in errs["by hand"]


@pytest.mark.parametrize("from_rest", [True, False])
def test_a_steady_speed_beyond_every_log_is_named(tmp_path, capsys, from_rest):
    """Logs that start at rest and turn at once never run steady: the Esso Osaka's nine
    zig-zags read whole reach 0.544 m/s, and their default model balanced at 0.776 m/s at 16.7
    rps, where its checks, manoeuvres and criteria started, without a word. A model's own steady
    speed more than 10 % beyond every training sample is named; from a steady approach it is
    not."""
    from test_equilibrium import PROPELLED

    from shipid.dynamics.model import ManoeuvringModel
    from shipid.identification.beyond_the_logs import approach_beyond_logs

    # u̇ = a |u|u + b n⁺²: steady at n √(−b/a), 0.632 m/s at 10 rps, reached in minutes.
    a, b, rps = -0.01, 4e-5, 10.0
    truth = ManoeuvringModel(PROPELLED.structure, {**PROPELLED.coefficients,
                                                   "u": {"|u|*u": a, "pos(n)^2": b}})
    steady = rps * np.sqrt(-b / a)
    logs = []
    for first in ("starboard", "port"):
        res = zigzag(truth, 20, 20, first=first, duration=60, dt=0.1, method="euler",
                     speed=0.05 if from_rest else steady, rps=rps, approach=3.0)  # fmt: skip
        logs.append(res.log.assign(n=rps))
    fastest = max(float(log["u"].max()) for log in logs)
    assert (fastest < 0.8 * steady) == from_rest
    paths = [write_log(log, tmp_path / f"zz{i}.csv") for i, log in enumerate(logs)]
    code, out, err = run(["identify", *paths, "--model", "blanke-rps", "--filter", "none",
                          "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    named = "beyond the fastest of its training logs" in err
    assert named == from_rest, err
    if from_rest:
        # The fit holds the truth's surge terms: its steady speed is n √(−b/a).
        assert f"at 10 rps, {steady:.4g} m/s, is" in err and f"({fastest:.4g} m/s)" in err
        note = approach_beyond_logs({"approach_speed": steady, "rps": rps}, {"u": [0.0, fastest]})
        assert f"{100 * (steady / fastest - 1):.0f} % beyond" in note
    assert approach_beyond_logs({"approach_speed": 1.09, "rps": None}, {"u": [0, 1.0]}) is None


def test_only_manoeuvres_read_whole_from_rest_are_named():
    """A zig-zag or turn that starts at rest is a file read whole (--start auto cuts it; the
    Esso Osaka's nine zig-zags read whole put the default's 35° turns 47 % and 58 % long, cut
    28 % and 2 %); a random run or straight run begun at rest is not named."""
    from shipid.trials.reading import manoeuvres_from_rest

    zz = zigzag(scale_ship(rudder_rate_deg=9.6), 20, 20, duration=90, dt=0.2, method="euler",
                approach=20.0).log  # fmt: skip
    ramp = np.clip(zz["t"].to_numpy() / 10.0, 0.0, 1.0)
    from_rest = zz.assign(u=zz["u"] * ramp)
    straight = _log(np.concatenate([np.linspace(0.0, 1.5, 200), np.full(800, 2.0)]),
                    np.full(1000, 10.0))  # fmt: skip
    assert manoeuvres_from_rest([zz, from_rest, straight]) == [1]


def test_identify_refuses_a_log_astern_before_fitting_it(tmp_path, capsys):
    """A log run astern throughout has no approach ahead for the checks and manoeuvres to start
    from. It was fitted in full (output error included) and refused only then, with its speed
    printed to 17 digits; now one line before the fit, and no model file."""
    log = zigzag(scale_ship(rudder_rate_deg=9.6), 20, 20, duration=60, dt=0.2,
                 method="euler").log  # fmt: skip
    path = write_log(log.drop(columns=["x", "y"]).assign(u=-log["u"]), tmp_path / "astern.csv")
    code, out, err = run(["identify", path, "-o", tmp_path / "m.json"], capsys)
    assert code == 1
    speed = -float(log["u"].iloc[: len(log) // 50].mean())
    assert err.strip() == (f"shipid: error: {path}: the first training log goes astern at its "
                           f"approach (u = {speed:.3g} m/s); the checks and manoeuvres start from "
                           "its approach ahead: trim it to the manoeuvre (--start), or give a log "
                           "that runs ahead first")  # fmt: skip
    assert "prefilter" not in out and "output error" not in out  # refused before the fit
    assert not (tmp_path / "m.json").exists()

"""A log's rudder convention stated wrongly, or not at all, was taken without a word (a silent
wrong result): a starboard-positive log read as a canonical file without metadata was taken as
port-positive, so `identify --constraints signs` bounded the rudder terms to the wrong side (the
paper's zig-zag mirrored that way: one-step R² of sway and yaw 0.10 and 0.001, and a model that
turns the wrong way under a held rudder), and `validate`'s closed-loop replica started its
zig-zag to the other side. The truth here is the simulated ship's own convention."""

from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from cli_helpers import run

from shipid.data.checks import RUDDER_CONVENTION_T, rudder_response
from shipid.data.io import read_log, write_log
from shipid.errors import ShipidWarning
from shipid.trials.manoeuvres import turning_circle, zigzag
from shipid.vessels import PAPER_IMU, kvlcc2, scale_ship

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="../shared/data is not present")


@pytest.fixture(scope="module")
def trials():
    paper = scale_ship(rudder_rate_deg=9.6)
    ship = kvlcc2()
    return {
        ("port", "zigzag"): zigzag(paper, 20, 20, duration=90, dt=0.2, method="euler",
                                   approach=2.0).log,
        ("port", "zigzag 10/10"): zigzag(paper, 10, 10, duration=90, dt=0.2, method="euler",
                                         approach=2.0).log,
        ("starboard", "zigzag"): zigzag(ship, 20, 20, duration=120, dt=0.1).log,
    }


def _mirror_rudder(log):
    out = log.copy()
    out["delta"] = -log["delta"]
    out.attrs = dict(log.attrs)
    return out


@pytest.mark.parametrize("key", [("port", "zigzag"), ("port", "zigzag 10/10"),
                                 ("starboard", "zigzag")])  # fmt: skip
@pytest.mark.parametrize("seed", [None, 0, 1])  # None: noise-free; else the paper's sensors
def test_the_response_names_the_ships_own_convention(trials, key, seed):
    log = trials[key] if seed is None else PAPER_IMU.apply(trials[key], seed=seed)
    found = rudder_response(log)
    assert found.side == key[0]
    assert found.decisive and abs(found.t_score) >= RUDDER_CONVENTION_T
    assert rudder_response(_mirror_rudder(log)).side != key[0]


def test_a_turning_circle_says_nothing_wrong():
    # One step of the rudder: the fit has little to go on; it must not contradict the truth.
    log = PAPER_IMU.apply(turning_circle(scale_ship(), 20.0, duration=120, dt=0.2).log, seed=0)
    found = rudder_response(log)
    assert found is None or not found.decisive or found.side == "port"


def test_astern_and_creeping_samples_are_left_out():
    # Astern the rudder turns the ship the other way: a log that is mostly astern with a
    # mirrored response there is judged on its ahead part only.
    t = np.arange(0, 400, 0.2)
    delta = np.radians(20) * np.sign(np.sin(2 * np.pi * t / 40))
    ahead = t < 160
    u = np.where(ahead, 1.0, -0.5)
    r = np.zeros_like(t)
    for i in range(1, len(t)):  # ṙ = k u δ − r/T: the sign of u flips the rudder's effect
        r[i] = r[i - 1] + 0.2 * (-0.05 * u[i - 1] * delta[i - 1] - r[i - 1] / 5.0)
    log = pd.DataFrame({"t": t, "delta": delta, "u": u, "v": 0.0, "r": r})
    assert rudder_response(log).side == "port"


def test_cli_names_a_contradicted_convention_and_takes_an_unstated_one(trials, tmp_path, capsys):
    log = PAPER_IMU.apply(trials[("port", "zigzag")], seed=3)
    log.attrs.update({"rudder_positive": "port"})
    right = write_log(log, tmp_path / "right.csv")
    code, _, err = run(["identify", right, "-o", tmp_path / "a.json"], capsys)
    assert code == 0 and "rudder convention" not in err and "rudder_positive=" not in err

    wrong = _mirror_rudder(log)  # the data now say starboard; the metadata still port
    write_log(wrong, tmp_path / "wrong.csv")
    code, _, err = run(["identify", tmp_path / "wrong.csv", "-o", tmp_path / "b.json"], capsys)
    assert code == 0
    assert "wrong.csv: where it runs ahead" in err and "--rudder-positive starboard" in err

    # Without metadata (a user's plain CSV) the data's convention is taken, and said.
    plain = tmp_path / "plain.csv"
    wrong[["t", "delta", "u", "v", "r", "psi"]].to_csv(plain, index=False)
    with pytest.warns(ShipidWarning, match="taken as rudder_positive=starboard"):
        assert read_log(plain).attrs["rudder_positive"] == "starboard"
    code, _, err = run(["identify", plain, "--constraints", "signs", "-o", tmp_path / "c.json"],
                       capsys)  # fmt: skip
    assert code == 0 and "states no rudder convention" in err
    assert "taken as rudder_positive=starboard" in err
    assert "turns the other way" not in err  # the rudder bounds on the right side


@needs_data
def test_every_real_log_answers_its_rudder_as_its_format_says():
    cases = [(p, {"fmt": "simman-marin", "scale": 45.7})
             for p in sorted((DATA / "kvlcc2-marin").glob("*.dat"))]
    cases += [(p, {"fmt": "simman-hsva"}) for p in sorted((DATA / "kvlcc2-hsva").glob("*.dat"))]
    cases += [(p, {"fmt": "osaka-frt", "start": "auto", "end": "auto"})
              for p in sorted((DATA / "esso-osaka" / "zigzag").glob("*.csv"))]
    decisive = 0
    for path, options in cases:
        log = read_log(path, **options)
        found = rudder_response(log)
        assert found.side == log.attrs["rudder_positive"], path.name
        decisive += found.decisive
    assert decisive == len(cases)


def test_plot_draws_every_rudder_in_the_first_logs_convention(trials, tmp_path, capsys,
                                                              monkeypatch):  # fmt: skip
    """A port-positive and a starboard-positive log drew the same rudder with opposite signs."""
    from shipid.reporting import plots

    drawn = {}
    monkeypatch.setattr(plots, "logs_figure", lambda logs, path, title: drawn.update(logs))
    paths = [write_log(trials[("port", "zigzag")], tmp_path / "port.csv"),
             write_log(trials[("starboard", "zigzag")], tmp_path / "starboard.csv")]
    code, _, err = run(["plot", *paths, "-o", tmp_path / "p.png"], capsys)
    assert code == 0 and "starboard.csv: a positive rudder angle turns it to starboard" in err
    np.testing.assert_array_equal(drawn["starboard.csv"]["delta"],
                                  -trials[("starboard", "zigzag")]["delta"].to_numpy())
    assert drawn["starboard.csv"].attrs["rudder_positive"] == "port"


def test_a_full_scale_turning_circle_is_not_read_as_the_other_convention(tmp_path):
    """The Mariner's 35° turn at Δk 0.5 s, its rudder ordered from the log's start (paper noise
    × 0.1): ṙ's gain on δ read t = +4.3 to starboard, since it rested on the seconds the rudder
    moved, and a plain CSV of this port-positive log had its rudder negated, the model then
    simulated turning the wrong way. One step of the rudder no longer names a convention by
    that fit; the turn it holds does, the right one."""
    from shipid.data.checks import rudder_reversals
    from shipid.vessels import mariner

    log = PAPER_IMU.scaled(0.1).apply(
        turning_circle(mariner(), 35.0, duration=900, dt=0.5).log, seed=13)
    assert log.attrs["rudder_positive"] == "port"
    assert rudder_reversals(log["delta"].to_numpy()) == 0
    found = rudder_response(log)
    assert found.side == "port" and found.held_turn and "turns to starboard" in found.held_turn
    plain = tmp_path / "plain.csv"
    log[["t", "delta", "u", "v", "r", "psi"]].to_csv(plain, index=False)
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("error", ShipidWarning)
        read = read_log(plain)
    assert read.attrs.get("rudder_positive", "port") == "port"
    np.testing.assert_allclose(read["delta"].to_numpy(), log["delta"].to_numpy(), atol=1e-12)


@pytest.mark.parametrize(("delta", "expected"), [
    ([0, -5, -20, -35, -35, -34.5, -35], 0),  # a turn, with a wobble under the hysteresis
    ([0, 10, 35, 35, 20, 0, 0], 1),  # a pull-out
    ([0, 20, 20, -20, -20, 20, 20, -20], 3),  # a zig-zag: one per execute after the first
    ([0, 0, 0], 0),
])  # fmt: skip
def test_rudder_reversals_count_the_rudder_turning_back(delta, expected):
    from shipid.data.checks import rudder_reversals

    assert rudder_reversals(np.radians(delta)) == expected


@pytest.mark.parametrize("seed", [None, 0])
def test_a_plain_csv_of_a_starboard_positive_turn_is_taken_so(tmp_path, seed):
    """A turning circle names no convention by the fit of ṙ on δ (one step of the rudder), so a
    plain CSV of a starboard-positive one (the KVLCC2's MMG convention) was read port-positive
    and its rudder mirrored against the model's. The turn it holds names it: 35° held, the ship
    turns to the side that angle turns it to, through hundreds of degrees."""
    log = turning_circle(kvlcc2(), 35.0, duration=240, dt=0.2).log
    assert log.attrs["rudder_positive"] == "starboard"
    log = log if seed is None else PAPER_IMU.apply(log, seed=seed)
    plain = tmp_path / "plain.csv"
    log[["t", "delta", "u", "v", "r", "psi"]].to_csv(plain, index=False)
    with pytest.warns(ShipidWarning, match=r"held at \+35° ahead \(from \+\d+°\) it turns to "
                      "starboard through .*taken as rudder_positive=starboard"):
        assert read_log(plain).attrs["rudder_positive"] == "starboard"
    assert rudder_response(_mirror_rudder(log)).side == "port"


@needs_data
def test_the_real_turning_circles_hold_their_turn_to_the_stated_side():
    for path in sorted((DATA / "esso-osaka" / "turning").glob("*.csv")):
        log = read_log(path, fmt="osaka-frt", start="auto", end="auto")
        found = rudder_response(log)
        assert found.held_turn and found.side == log.attrs["rudder_positive"], path.name

"""The heading changes at which a zig-zag's rudder was reversed, and the note where they spread.
The closed-loop replica reversed at their median every time, so a trial reversed unevenly
(MARIN's −20° run: +19.81°, −21.24°, +19.54°) had overshoots no replica at one switch heading
follows; it now reverses at each of them in turn. The truth here is a simulated zig-zag,
reversed where its own switch logic did."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from shipid.data.io import read_log, write_log
from shipid.errors import ShipidError
from shipid.evaluation.validate import REVERSAL_SPREAD_DEG, validate_log
from shipid.trials.manoeuvres import zigzag
from shipid.trials.trial import describe_trial
from shipid.vessels import scale_ship_model

MARIN = (Path(__file__).resolve().parents[2] / "shared" / "data" / "kvlcc2-marin"
         / "MARIN_FREE_KVLCC2_zz_-20_m.dat")  # fmt: skip


@pytest.fixture(scope="module")
def zz():
    truth = scale_ship_model()
    return truth, zigzag(truth, 20, 20, duration=90, dt=0.2, method="euler", speed=1.93,
                         approach=2.0).log  # fmt: skip


def test_the_reversals_of_a_simulated_zigzag_are_its_switch_heading(zz):
    truth, log = zz
    trial = describe_trial(log, "zigzag")
    heads = np.array(trial.reversal_headings_deg)
    # Reversed as soon as the heading change reached ±20° (within one step's turn), alternating.
    assert len(heads) >= 3 and np.all(np.sign(heads[1:]) == -np.sign(heads[:-1]))
    steps = np.degrees(np.abs(log["r"]).max()) * 0.2
    assert np.all(np.abs(np.abs(heads) - 20.0) <= steps)
    assert not [w for w in validate_log(truth, log, "zz").warnings if "reversed at" in w]


def test_an_uneven_trial_is_named():
    truth = scale_ship_model()
    log = zigzag(truth, 20, 20, duration=90, dt=0.05, method="euler", speed=1.93,
                 approach=2.0).log  # fmt: skip
    clean = describe_trial(log, "zigzag")
    assert clean.reversal_step_deg < REVERSAL_SPREAD_DEG
    assert not [w for w in validate_log(truth, log, "zz").warnings if "reversed at" in w]
    # A heading that drifts 0.06 °/s: every reversal read that much more to one side at its
    # time, as a trial reversed unevenly.
    drifting = log.assign(psi=log["psi"] + math.radians(0.06) * (log["t"] - 1.0))
    trial = describe_trial(drifting, "zigzag")
    # The orders: the last plateau sample before each swing of the rudder after the execute;
    # a reversal's heading is read half a sample after it.
    t, delta = log["t"].to_numpy(), log["delta"].to_numpy()
    moving = np.abs(np.diff(delta)) > 1e-12
    starts = [i for i in range(1, moving.size) if moving[i] and not moving[i - 1]]
    times = [t[i] + 0.025 for i in starts if i > clean.execute_index + 1]
    assert len(times) == len(clean.reversal_headings_deg)
    expected = [h + 0.06 * (tk - 1.0) for h, tk in zip(clean.reversal_headings_deg, times,
                                                       strict=True)]  # fmt: skip
    # (within the drift of the approach heading ψ0 itself, 0.0015°)
    assert trial.reversal_headings_deg == pytest.approx(expected, abs=0.005)
    sizes = np.abs(trial.reversal_headings_deg)
    assert sizes.max() - sizes.min() > REVERSAL_SPREAD_DEG
    notes = [w for w in validate_log(truth, drifting, "zz").warnings if "reversed at" in w]
    assert len(notes) == 1 and "the closed loop reverses at each of them in turn" in notes[0]


def test_the_replica_of_an_uneven_trial_reverses_as_it_did():
    """A zig-zag reversed at 17°, 23° and 18.5°, then 20°: the true model's closed-loop replica
    reproduces its overshoots to 0.01° (at the median switch heading every time it put them
    3.4° and 2.6° off)."""
    truth = scale_ship_model()
    log = zigzag(truth, 20, 20, duration=90, dt=0.05, method="euler", speed=1.93, approach=2.0,
                 switches=[17.0, 23.0, 18.5]).log  # fmt: skip
    v = validate_log(truth, log, "zz")
    measured, replica = v.indices["measured"], v.indices["closed_loop"]
    for key in ("first_overshoot_deg", "second_overshoot_deg"):
        assert replica[key] == pytest.approx(measured[key], abs=0.01)
    even = zigzag(truth, 20, 20, duration=90, dt=0.05, method="euler", speed=1.93,
                  approach=2.0).indices  # fmt: skip
    assert abs(even["first_overshoot_deg"] - measured["first_overshoot_deg"]) > 2.0
    with pytest.raises(ShipidError, match="reversal heading"):
        zigzag(truth, 20, 20, speed=1.93, switches=[0.0])


@pytest.mark.skipif(not MARIN.is_file(), reason="../shared/data is not present")
def test_marins_minus_20_run_reversed_unevenly():
    log = read_log(MARIN, fmt="simman-marin", scale=45.7, dt=0.2)
    trial = describe_trial(log, "zigzag")
    assert trial.reversal_headings_deg == pytest.approx([19.81, -21.24, 19.54], abs=0.01)
    assert trial.switch_heading_deg == pytest.approx(19.81, abs=0.01)


def test_indices_prints_and_keeps_the_reversals(tmp_path, capsys, zz):
    _, log = zz
    path = write_log(log, tmp_path / "zz.csv")
    code, text, err = run(["indices", path, "--json", tmp_path / "i.json"], capsys)
    assert code == 0, err
    heads = describe_trial(log, "zigzag").reversal_headings_deg
    assert "  reversal_headings_deg: " + ", ".join(f"{h:+.2f}" for h in heads) in text
    kept = json.loads((tmp_path / "i.json").read_text())["logs"][0]["reversal_headings_deg"]
    assert kept == pytest.approx(list(heads))


ESSO_1515 = (Path(__file__).resolve().parents[2] / "shared" / "data" / "esso-osaka" / "zigzag"
             / "zigzag_31-Jul-2020_13_22_52.csv")  # fmt: skip


@pytest.mark.parametrize("helm_deg", [7.0, -7.0, 12.0])
def test_a_first_order_from_the_helm_over_is_the_execute(zz, helm_deg):
    """The bug: a log that starts with the helm over (an operator holding the course at −7°
    before a 20°/20° zig-zag whose first order is −20°) has a first order of 13° against
    reversals of 40°, and the first reversal was taken for the execute. The same zig-zag with
    its approach rudder held off zero must read as it does from zero: the same execute, heading
    reference, first rudder and reversals (−7° and +12° failed before, +7° did not)."""
    _, log = zz
    helm = log.copy()
    before = helm["t"] < 2.0 - 1e-9  # the approach, up to the order at 2 s
    helm.loc[before, "delta"] = math.radians(helm_deg)
    plain, held = describe_trial(log, "zigzag"), describe_trial(helm, "zigzag")
    assert held.execute_index == plain.execute_index
    assert held.psi0 == plain.psi0
    # Held over by 12° against the first order's side, the helm was read as a plateau of the
    # trial's too: an order at the execute and the first rudder to the wrong side.
    assert held.first_rudder == pytest.approx(plain.first_rudder)
    assert held.amplitude == pytest.approx(plain.amplitude)
    np.testing.assert_allclose(held.reversal_headings_deg, plain.reversal_headings_deg)


@pytest.mark.skipif(not ESSO_1515.is_file(), reason="../shared/data is not present")
def test_the_esso_15_15_zigzag_from_rest_executes_at_its_first_order():
    """The Esso Osaka's 15°/15° zig-zag, trimmed as the README imports it: the helm holds about
    +7° while the ship gathers speed, the first order (+14.8° at 36 s) is a 7° swing, the first
    reversal (at 61.5 s) a 30° one."""
    log = read_log(ESSO_1515, fmt="osaka-frt", start="auto", end="auto")
    trial = describe_trial(log, "zigzag")
    assert trial.execute_time == pytest.approx(36.0, abs=0.3)
    assert trial.first_rudder > 0
    assert trial.reversal_headings_deg[:2] == pytest.approx([16.1, -13.8], abs=0.2)

"""Logs whose manoeuvre does not start from a straight, held approach: cut inside it (the
execute before the first sample), after an approach on which the ship still turns, or with a
helm correction at the first sample. A turn's steady part is still the trial's, its advance and
the rest count from where the trial starts, and the commands say so; a zig-zag's overshoots
need the approach heading, which a cut log does not hold (``test_manoeuvres.py``). The truth is
the scale ship's own manoeuvre."""

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from cli_helpers import run

from shipid.data.io import write_log
from shipid.dynamics.simulate import simulate
from shipid.dynamics.steering import SteeringMachine
from shipid.evaluation.validate import validate_log
from shipid.trials.indices import manoeuvre_indices
from shipid.trials.manoeuvres import turning_circle, zigzag
from shipid.trials.trial import describe_trial
from shipid.vessels import scale_ship

MARIN = (Path(__file__).resolve().parents[2] / "shared" / "data" / "kvlcc2-marin"
         / "MARIN_FREE_KVLCC2_zz_20_m.dat")  # fmt: skip


def _cut(log, at):
    late = log[log["t"] >= at].reset_index(drop=True)
    late.attrs = dict(log.attrs)
    return late


@pytest.fixture(scope="module")
def turn():
    return turning_circle(scale_ship(), 35, duration=120, dt=0.1).log


@pytest.mark.parametrize("at", [2.0, 10.0])
def test_a_turn_cut_after_its_execute_keeps_its_steady_part_and_says_what_it_lacks(turn, at):
    """Cut 2 s after the order, the scale ship's 35° turn read its advance 25 % short (6.3 m
    against 8.4 m) and 10 s after, its tactical diameter twice the trial's, with no word."""
    late = _cut(turn, at)
    trial = describe_trial(late)
    r = np.abs(late["r"].to_numpy())
    assert trial.kind == "turning" and trial.execute_index == 0
    assert trial.turning_at_order == pytest.approx(r[0] / r.max())
    whole, cut = manoeuvre_indices(turn), manoeuvre_indices(late, trial=trial)
    assert cut["advance"] < 0.8 * whole["advance"] or \
        cut["tactical_diameter"] > 1.5 * whole["tactical_diameter"]  # fmt: skip
    for key in ("steady_turning_diameter", "steady_yaw_rate", "steady_speed"):
        assert cut[key] == pytest.approx(whole[key], rel=1e-3)
    # The truth's replica (at the trial's own integrator) starts where the log does, so it
    # counts alike: its indices are the cut log's own, not the whole turn's.
    v = validate_log(scale_ship(), late, "cut", method="rk4")
    closed, measured = v.indices["closed_loop"], v.indices["measured"]
    for key in ("advance", "transfer", "tactical_diameter", "time_to_90"):
        assert closed[key] == pytest.approx(measured[key], rel=1e-9), key
    note = [w for w in v.warnings if "starts inside its manoeuvre" in w]
    assert len(note) == 1 and f"{100 * trial.turning_at_order:.0f} %" in note[0]
    assert "the replica, run from the same state, counts alike" in note[0]


def test_a_turn_from_its_order_or_its_approach_is_not_said_to_be_cut(turn):
    assert describe_trial(turn).turning_at_order is None
    assert not [w for w in validate_log(scale_ship(), turn, "whole").warnings
                if "starts inside" in w]  # fmt: skip
    # Cut during its rudder's swing to 35°, before the ship turns: the trial's approach.
    gear = SteeringMachine(max_rate=math.radians(20.0))
    steered = turning_circle(scale_ship(), 35, duration=60, dt=0.1, steering=gear).log
    assert describe_trial(_cut(steered, 0.5)).turning_at_order is None


def test_the_commands_name_a_log_cut_inside_its_manoeuvre(tmp_path, capsys, turn):
    write_log(_cut(turn, 2.0), tmp_path / "turn.csv")
    zz = zigzag(scale_ship(), 30, 30, duration=60, dt=0.1).log
    write_log(_cut(zz, 5.0), tmp_path / "zz.csv")
    code, out, err = run(["indices", tmp_path / "turn.csv", tmp_path / "zz.csv", "--json",
                          tmp_path / "ind.json"], capsys)  # fmt: skip
    assert code == 0, err
    records = json.loads((tmp_path / "ind.json").read_text())["logs"]
    assert "starts inside its manoeuvre" in records[0]["warnings"][0]
    assert "warnings" not in records[1]  # read as none: its reason says why
    assert f"{tmp_path / 'turn.csv'}: turning" in out
    assert f"{tmp_path / 'zz.csv'}: other (it starts inside its manoeuvre" in out
    lines = [w for w in err.splitlines() if "starts inside its manoeuvre" in w]
    assert len(lines) == 1 and "turn.csv" in lines[0] and "tactical diameter" in lines[0]
    # Forced, the zig-zag is measured from its first sample, and said to be.
    code, out, err = run(["indices", tmp_path / "zz.csv", "--kind", "zigzag"], capsys)
    assert code == 0, err
    assert "first_overshoot_deg" in out and "its overshoots count from the first sample" in err


@pytest.mark.skipif(not MARIN.is_file(), reason="../shared/data is not present")
def test_the_real_marin_zigzag_cut_after_its_order():
    """MARIN's 20°/20° run cut 3 s after its order read as a zig-zag from its first reversal,
    overshoots 1.8° and 25.7° against the run's 14.7° and 11.8°; cut 1 s after it, before the
    ship turns, it is the run it was (its first overshoot the same)."""
    from shipid.data.io import read_log

    log = read_log(MARIN, fmt="simman-marin", scale=45.7, start="auto", end="auto")
    trial = describe_trial(log)
    whole = manoeuvre_indices(log, trial=trial)
    early = _cut(log, trial.execute_time + 1.0)
    assert describe_trial(early).kind == "zigzag"
    assert manoeuvre_indices(early)["first_overshoot_deg"] == \
        pytest.approx(whole["first_overshoot_deg"], abs=0.05)  # fmt: skip
    late = describe_trial(_cut(log, trial.execute_time + 3.0))
    assert late.kind == "other" and late.reason.startswith("it starts inside its manoeuvre")


def _after_a_turning_approach(manoeuvre: str):
    """The scale ship's 35° turn after 4 s of −20° rudder (simulated whole), or its 20°/20°
    zig-zag after 3 s of −8° (run closed loop from the state the approach left it in, so each
    sample follows from the last)."""
    ship = scale_ship()
    t = np.arange(0.0, 90.0, 0.1)
    if manoeuvre == "turning":
        rudder = np.where((t >= 5.0) & (t < 9.0), math.radians(-20.0), 0.0)
        rudder[t >= 9.0] = math.radians(35.0)
        return simulate(ship.dynamics, t, rudder, {"u": ship.approach_speed}, method="rk4").log
    t = t[t <= 8.0]
    return _zigzag_after(ship, t, np.where(t >= 5.0, math.radians(-8.0), 0.0))


def _zigzag_after(ship, t, rudder):
    """The ship's 20°/20° zig-zag run closed loop from the state an approach of ``rudder`` over
    ``t`` (simulated open loop) left it in, ordered at its last time: one log, each sample
    following from the last."""
    pre = simulate(ship.dynamics, t, rudder, {"u": ship.approach_speed}, method="rk4").log
    last = pre.iloc[-1]
    zz = zigzag(ship, 20, 20, duration=60, dt=0.1,
                initial={k: float(last[k]) for k in ("u", "v", "r", "psi")}).log  # fmt: skip
    zz = zz.assign(t=zz["t"] + t[-1], x=zz["x"] + last["x"], y=zz["y"] + last["y"])
    log = pd.concat([pre.iloc[:-1], zz], ignore_index=True)
    log.attrs = dict(zz.attrs)
    return log


@pytest.mark.parametrize("manoeuvre", ["turning", "zigzag"])
def test_a_manoeuvre_after_a_turning_approach_is_judged_from_its_order(manoeuvre):
    """After an approach on which the ship still turns, the scale ship's own replica ran
    straight to the order, its rudder as at the log's first sample: the true ship was said to
    miss its turn's advance by 31 % (8.28 m against 11.99 m) and its zig-zag's overshoots
    (11.2°, 2.6° against 9.4°, 3.0°, themselves measured from a heading averaged over the
    turning approach: 4.9°, 7.4° from the order's). The trial keeps its kind, counts from the
    heading at the order, says so, and validate's replica starts from the state the ship was
    in there: the truth's indices are the log's."""
    log = _after_a_turning_approach(manoeuvre)
    trial = describe_trial(log)
    assert trial.kind == manoeuvre and trial.execute_index > 0
    assert trial.turning_at_order > 0.2
    assert trial.psi0 == pytest.approx(log["psi"].iloc[trial.execute_index], abs=1e-4)
    v = validate_log(scale_ship(), log, manoeuvre, method="rk4")
    keys = (("advance", "transfer", "tactical_diameter") if manoeuvre == "turning"
            else ("first_overshoot_deg", "second_overshoot_deg"))  # fmt: skip
    for key in keys:
        assert v.indices["closed_loop"][key] == pytest.approx(v.indices["measured"][key],
                                                              rel=1e-9), key  # fmt: skip
    note = [w for w in v.warnings if w.startswith("its approach is not straight")]
    assert len(note) == 1 and "the replica, run from the same state, counts alike" in note[0]
    assert not [w for w in v.warnings if "approach is not steady" in w]


@pytest.mark.skipif(not MARIN.is_file(), reason="../shared/data is not present")
def test_no_real_approach_is_taken_for_a_turning_one():
    """The Esso Osaka's zig-zags and turns (read whole, from rest, in the pond's wind) and the
    KVLCC2's runs approach straight enough: none is said to turn at its order."""
    from shipid.data.io import read_log

    data = MARIN.parents[1]
    files = [(p, "osaka-frt", {}) for kind in ("zigzag", "turning")
             for p in sorted((data / "esso-osaka" / kind).glob("*.csv"))]  # fmt: skip
    files += [(p, "simman-marin", {"scale": 45.7}) for p in sorted(MARIN.parent.glob("*.dat"))]
    files += [(p, "simman-hsva", {}) for p in sorted((data / "kvlcc2-hsva").glob("*.dat"))]
    assert len(files) == 14
    for path, fmt, kw in files:
        for dt in (None, 0.5):
            trial = describe_trial(read_log(path, fmt=fmt, dt=dt, **kw))
            assert trial.kind in ("zigzag", "turning") and trial.turning_at_order is None, path


def test_the_replica_holds_the_rudder_the_ship_approached_with():
    """The replica holds a rudder from the log's first sample to the order: it held the first
    sample's, on the Esso Osaka's approaches a helm correction's. After a 6° helm held for one
    0.1 s sample and 7.8 s amidships, the scale ship's own replica of its 20°/20° zig-zag held 6°
    the whole approach and put the first overshoot 26° off the log's; now the approach's mean,
    and within 1.1° (the blip's turn, which the mean does not replay)."""
    from shipid.evaluation.validate import approach_rudder, trial_replica

    ship = scale_ship()
    t = np.arange(0.0, 8.0001, 0.1)
    log = _zigzag_after(ship, t, np.where(t == 0.0, math.radians(6.0), 0.0))
    trial = describe_trial(log)
    assert trial.kind == "zigzag" and trial.turning_at_order is None
    held = approach_rudder(log, trial)
    assert held == pytest.approx(np.mean(log["delta"].to_numpy()[: trial.execute_index + 1]))
    run = trial_replica(ship, log, "rk4", trial, indices=False).log
    before = run["t"].to_numpy() < log["t"].iloc[trial.execute_index] - log["t"].iloc[0]
    assert np.allclose(run["delta"].to_numpy()[before], held)
    v = validate_log(ship, log, "zz", method="rk4")
    first = "first_overshoot_deg"
    assert abs(v.indices["closed_loop"][first] - v.indices["measured"][first]) < 1.1


@pytest.mark.parametrize("stop_deg", [60.0, 170.0])
def test_a_turn_stopped_short_of_180_degrees_says_what_it_lacks(turn, stop_deg):
    """A turning log that ends before the heading has turned 180° is no turning circle; it read
    as 'fewer than two rudder reversals', which says nothing of what it lacks. Forced, it gives
    the indices it reaches (an advance from 90°)."""
    psi = np.unwrap(turn["psi"].to_numpy())
    end = int(np.argmax(np.abs(psi - psi[0]) >= math.radians(stop_deg)))
    short = turn.iloc[:end].reset_index(drop=True)
    short.attrs = dict(turn.attrs)
    trial = describe_trial(short)
    assert trial.kind == "other"
    reached = float(np.degrees(np.max(np.abs(psi[:end] - psi[0]))))
    assert trial.reason.startswith(f"the rudder held to one side through {reached:.0f}° of "
                                   "heading and not reversed")  # fmt: skip
    forced = manoeuvre_indices(short, "turning")
    assert (forced["advance"] is not None) == (stop_deg > 90.0)
    assert forced["tactical_diameter"] is None


@pytest.mark.parametrize("noise", [1.0, 5.0])
def test_a_noisy_gyro_on_a_straight_approach_is_not_taken_for_a_turning_one(noise):
    """The scale ship's 10°/10° zig-zag through the paper's sensors: its approach turns at 5 %
    of its largest yaw rate, and the largest running median of the noisy yaw rate over it read
    above a tenth in 2 of 40 seeds at the paper's noise and 36 of 40 at five times it, which
    moved their approach heading to one noisy sample and their replica to the order. The
    noise's own spread is now allowed for."""
    from shipid.vessels import PAPER_IMU

    clean = zigzag(scale_ship(), 10, 10, duration=120, dt=0.1, approach=10.0).log
    for seed in range(10, 20):
        trial = describe_trial(PAPER_IMU.scaled(noise).apply(clean, seed=seed))
        assert trial.kind == "zigzag" and trial.turning_at_order is None, seed

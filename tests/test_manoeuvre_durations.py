"""Manoeuvres run long enough for the ship they run on. The run lengths were fixed in seconds
(90 s zig-zag, 240 s turn, 60 + 60 s pull-out, 120 s per spiral step), right for a model in a
basin and ten times too short for its full-scale sister: a rescaled Esso Osaka model gave no
tactical diameter and no overshoots, a pull-out residual of a transient and a spiral "loop"
(a false instability) without a word. The truth here is Froude similarity: the full-scale
sister of a model, run with its time step scaled, must give the model's indices scaled."""

import math

import pytest
from cli_helpers import run

from shipid.dynamics.model import ManoeuvringModel
from shipid.dynamics.prime import froude_scaled
from shipid.trials.manoeuvres import pull_out, spiral, turning_circle, zigzag

LATERAL = ("u*v", "u*r", "u^2*delta")
MODEL = ManoeuvringModel(
    f"u: |u|*u, 1; v: {', '.join(LATERAL)}; r: {', '.join(LATERAL)}",
    {"u": {"|u|*u": -0.05, "1": 0.05},
     "v": {"u*v": -0.6, "u*r": -0.3, "u^2*delta": 0.01},
     "r": {"u*v": -1.5, "u*r": -0.8, "u^2*delta": -0.008}})  # fmt: skip
FACTOR = 100.0  # a 1:100 model: times ×10, lengths ×100
K = math.sqrt(FACTOR)
SMALL = {"speed": 1.0, "dt": 0.05}
LARGE = {"speed": K, "dt": 0.05 * K}
LARGE_MODEL = froude_scaled(MODEL, FACTOR)


def test_the_full_scale_turning_circle_is_the_models_scaled():
    small = turning_circle(MODEL, 35.0, **SMALL)
    large = turning_circle(LARGE_MODEL, 35.0, **LARGE)
    assert not small.incomplete and not large.incomplete
    for key, scale in (("advance", FACTOR), ("transfer", FACTOR), ("tactical_diameter", FACTOR),
                       ("time_to_90", K), ("time_to_180", K)):  # fmt: skip
        assert large.indices[key] == pytest.approx(small.indices[key] * scale, rel=1e-9), key
    # The steady turn is averaged over what follows 180°, which the runs' lengths set.
    assert large.indices["steady_yaw_rate"] == pytest.approx(
        small.indices["steady_yaw_rate"] / K, rel=1e-3)


def test_the_full_scale_zigzag_has_the_models_overshoots():
    small = zigzag(MODEL, 20.0, 20.0, **SMALL)
    large = zigzag(LARGE_MODEL, 20.0, 20.0, **LARGE)
    for key in ("first_overshoot_deg", "second_overshoot_deg"):
        assert large.indices[key] == pytest.approx(small.indices[key], rel=1e-9), key
    assert large.indices["time_to_check_yaw"] == pytest.approx(
        small.indices["time_to_check_yaw"] * K, rel=1e-9)


def test_the_full_scale_pull_out_and_spiral_settle_as_the_models():
    small, large = pull_out(MODEL, **SMALL), pull_out(LARGE_MODEL, **LARGE)
    assert not small.incomplete and not large.incomplete
    assert large.indices["yaw_rate_at_release"] == pytest.approx(
        small.indices["yaw_rate_at_release"] / K, rel=1e-3)
    # A stable ship: the yaw rate decays away after the release at both scales.
    assert abs(large.indices["residual_fraction"]) < 0.01
    assert abs(small.indices["residual_fraction"]) < 0.01
    angles = (15, 5, 0, -5, -15, -5, 0, 5, 15)
    small, large = spiral(MODEL, angles, **SMALL), spiral(LARGE_MODEL, angles, **LARGE)
    assert not large.indices["loop"] and not large.indices["unsettled_rudders_deg"]
    for a, b in zip(small.indices["table"], large.indices["table"], strict=True):
        assert b["steady_yaw_rate"] == pytest.approx(a["steady_yaw_rate"] / K, rel=1e-2,
                                                     abs=1e-4 / K)  # fmt: skip


def test_a_given_duration_too_short_is_said_so():
    res = turning_circle(LARGE_MODEL, 35.0, duration=240.0, **LARGE)
    assert res.indices["tactical_diameter"] is None
    assert "180°" in res.incomplete and "240 s" in res.incomplete
    res = zigzag(LARGE_MODEL, 20.0, 20.0, duration=90.0, **LARGE)
    assert res.incomplete == "the heading has not reached 20° within 90 s"
    res = pull_out(LARGE_MODEL, hold=60.0, release=60.0, **LARGE)
    assert "not settled" in res.incomplete
    res = spiral(LARGE_MODEL, (10, 0, -10), hold=120.0, **LARGE)
    assert res.indices["unsettled_rudders_deg"] and "no steady yaw rate" in res.incomplete


def test_the_cli_warns_of_a_run_too_short(capsys):
    code, _, err = run(["manoeuvre", "scale-ship", "turning", "--duration", "5"], capsys)
    assert code == 0, err
    assert "give a longer --duration" in err and "180°" in err
    code, out, err = run(["manoeuvre", "scale-ship", "turning"], capsys)
    assert code == 0, err
    assert "longer --duration" not in err and "tactical_diameter: None" not in out


def test_plausibility_holds_the_rudder_until_a_full_scale_turn_settles():
    """The plausibility check held the rudder 300 s: the full-scale KVLCC2 (identified from
    MARIN's full-scale files) was 'not settled' to both sides where its model-scale twin was."""
    from shipid.identification.plausibility import check_plausibility

    small, small_notes = check_plausibility(MODEL, SMALL["speed"])
    large, large_notes = check_plausibility(LARGE_MODEL, LARGE["speed"])
    assert not any("no steady turn" in n for n in small_notes + large_notes)
    for side in ("starboard", "port"):
        a, b = small["held_rudder"][side], large["held_rudder"][side]
        assert a["settled"] and b["settled"] and b["duration"] > 300.0
        assert b["steady_yaw_rate"] == pytest.approx(a["steady_yaw_rate"] / K, rel=2e-2)
    _, notes = check_plausibility(LARGE_MODEL, LARGE["speed"], duration=300.0)
    assert any("no steady turn after 300 s" in n for n in notes)


def test_the_full_scale_stopping_test_runs_until_the_ship_stops():
    """The stopping test ran 600 s: enough for a model, not for a slow full-scale ship, whose
    track reach then came back NaN without a word."""
    from shipid.trials.manoeuvres import stopping

    truth = ManoeuvringModel(
        f"u: |u|*u, pos(n)^2, neg(n)^2; v: {', '.join(LATERAL)}; r: {', '.join(LATERAL)}",
        {"u": {"|u|*u": -0.005, "pos(n)^2": 5e-5, "neg(n)^2": -5e-5},
         "v": MODEL.coefficients["v"], "r": MODEL.coefficients["r"]})  # fmt: skip
    big = froude_scaled(truth, FACTOR)
    small = stopping(truth, 10.0, speed=1.0, dt=0.05)
    large = stopping(big, 10.0 / K, speed=K, dt=0.05 * K)
    assert not small.incomplete and not large.incomplete
    assert large.indices["time_to_stop"] > 600.0
    assert large.indices["track_reach"] == pytest.approx(small.indices["track_reach"] * FACTOR,
                                                         rel=1e-9)  # fmt: skip
    short = stopping(big, 10.0 / K, speed=K, dt=0.05 * K, duration=600.0)
    assert "has not stopped within 600 s" in short.incomplete

"""Identification when the truth has another structure: the KVLCC2's MMG model (propeller,
rudder in its race, cubic hull forces) observed through 20° zig-zags, judged on the 10/10
zig-zags and the 35° turn it was not fitted to. The MMG simulator is checked against an
independent MMG code elsewhere."""

from __future__ import annotations

import numpy as np
import pytest

from shipid.identification.identify import identify
from shipid.trials.manoeuvres import turning_circle, zigzag
from shipid.vessels import kvlcc2

RUN = {"duration": 250.0, "dt": 0.2, "approach": 5.0}


@pytest.fixture(scope="module")
def mmg_trials():
    ship = kvlcc2()
    train = [zigzag(ship, 20, 20, first="starboard", **RUN).log,
             zigzag(ship, 20, 10, first="port", **RUN).log]  # fmt: skip
    held = {side: zigzag(ship, 10, 10, first=side, **RUN).indices for side in ("starboard", "port")}
    return ship, train, held


def overshoot_errors(model, ship, held) -> list[float]:
    errors = []
    for side, truth in held.items():
        ind = zigzag(model, 10, 10, first=side, speed=ship.approach_speed, steering=ship.steering,
                     **RUN).indices  # fmt: skip
        errors += [ind[k] - truth[k] for k in ("first_overshoot_deg", "second_overshoot_deg")]
    return errors


def test_a_rudder_in_the_propeller_race_predicts_the_unseen_10_10_zigzag_and_35_degree_turn(
        mmg_trials):
    """With u²δ alone the rudder loses its force as the ship slows, which a rudder in the race
    of a propeller at constant rps does not: the 10/10 second overshoot (13.6° starboard first)
    comes out 3.0° low and the 35° turn's steady yaw rate 30 % low. With the race's inflow as a
    quadratic form in u and n (blanke-race), every overshoot of both 10/10 zig-zags is within
    1.5° (measured 0.62, −0.87, 0.74, 1.28) and the 35° turn's tactical diameter and steady yaw
    rate within 12 % (measured −10.6 %, +5.7 %)."""
    ship, train, held = mmg_trials
    speed = identify(train, model="blanke-speed").model
    race = identify(train, model="blanke-race").model
    assert overshoot_errors(speed, ship, held)[1] < -2.5  # the failure, measured −3.0°
    assert max(abs(e) for e in overshoot_errors(race, ship, held)) < 1.5
    turn = {"duration": 600.0, "dt": 0.2, "approach": 5.0}
    truth = turning_circle(ship, 35, **turn).indices
    kw = {"speed": ship.approach_speed, "steering": ship.steering, **turn}
    assert turning_circle(speed, 35, **kw).indices["steady_yaw_rate"] < 0.75 * truth["steady_yaw_rate"]
    ind = turning_circle(race, 35, **kw).indices
    for key in ("tactical_diameter", "steady_yaw_rate"):
        assert ind[key] == pytest.approx(truth[key], rel=0.12), key


def test_the_identified_linear_sway_yaw_derivatives_are_the_mmg_models(mmg_trials):
    """The coefficients themselves, not only the runs: the six linear derivatives ∂(v̇, ṙ)/∂(v, r,
    δ) of the blanke-race fit at the approach speed, against the MMG model's own by central
    differences of its accelerations, all within 30 % (measured −27, +1, −3, +17, −2, −5 %)."""
    from shipid.vessels.kvlcc2 import accelerations, trimmed_revolutions

    ship, train, _ = mmg_trials
    U, n, h = ship.approach_speed, trimmed_revolutions(ship.approach_speed), 1e-5
    model = identify(train, model="blanke-race").model

    def derivatives(f):
        out = []
        for k in (1, 2, 3):
            e = [0.0] * 4
            e[k] = h
            up = np.ravel(f(U + e[0], e[1], e[2], e[3]))
            down = np.ravel(f(U - e[0], -e[1], -e[2], -e[3]))
            out.append((up[1:3] - down[1:3]) / (2 * h))
        return np.array(out).T  # rows v̇, ṙ; columns v, r, δ

    truth = derivatives(lambda u, v, r, d: accelerations(u, v, r, d, n))
    ours = derivatives(model.accelerations)
    np.testing.assert_allclose(ours, truth, rtol=0.30)
    assert np.all(np.sign(ours) == np.sign(truth))

"""Identification when the truth has another structure: the KVLCC2's MMG model (propeller, rudder
in its race, cubic hull forces) observed through 20° zig-zags, judged on a 10/10 zig-zag it was
not fitted to. The MMG simulator is checked against an independent MMG code elsewhere."""

from __future__ import annotations

import pytest

from shipid.identification.identify import identify
from shipid.trials.manoeuvres import zigzag
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


def test_a_rudder_in_the_propeller_race_predicts_the_unseen_10_10_zigzag(mmg_trials):
    """With u²δ alone the rudder loses its force as the ship slows, which a rudder in the race
    of a propeller at constant rps does not: the 10/10 second overshoot (13.6° starboard first)
    comes out 3.0° low. With the race (δ) and the lift's saturation (δ³), every overshoot of
    both 10/10 zig-zags is within 1.2° (measured 0.84, −0.89, 0.34, 1.11)."""
    ship, train, held = mmg_trials
    speed = overshoot_errors(identify(train, model="blanke-speed").model, ship, held)
    race = overshoot_errors(identify(train, model="blanke-race").model, ship, held)
    assert speed[1] < -2.5  # the failure the structure is for, measured −3.0°
    assert max(abs(e) for e in race) < 1.2, race

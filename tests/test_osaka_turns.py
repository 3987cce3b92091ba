"""Turns of the Esso Osaka that the shared files do not hold (the FRT-DS-ESSO repository lists
±20° turns at 10 rps and turns at 8 rps beside the 35° ones at 10 rps here), as its files would
hold them: an osaka-frt CSV of a straight approach and then the turn, the rudder swung in a
second. Made by the sister ship (the KVLCC2's prime coefficients on the Esso's particulars), whose
own turning circle is the truth: ``import --start auto --end auto`` cuts them to the manoeuvre
and ``indices`` reads them as turns with the truth's indices."""

import json

import numpy as np
import pandas as pd
import pytest
from cli_helpers import run

from shipid.data.particulars import Particulars
from shipid.dynamics.equilibrium import vessel_straight_speed
from shipid.dynamics.simulate import simulate
from shipid.trials.manoeuvres import turning_circle
from shipid.vessels import kvlcc2
from shipid.vessels.mmg_file import mmg_vessel, sister_ship

ESSO = Particulars(length=3.0, beam=0.489, draught=0.201, block_coefficient=0.83, mass=244.6,
                   rudder_area=0.0106, propeller_diameter=0.084, xg=0.094, rho=1000.0,
                   scale=108.3)  # the data README's  # fmt: skip
APPROACH = 60.0  # s of straight running before the order
RATE = 20.0  # °/s: the pond's rudder swings 35° in under 2 s


@pytest.fixture(scope="module")
def sister():
    doc, _ = sister_ship(kvlcc2().dynamics.c, ESSO, "sister", rps="logs")
    return mmg_vessel(doc, "the sister")


def _osaka_file(ship, rudder_deg: float, rps: float, path, seed: int):
    """An osaka-frt CSV of ``ship``: straight at ``rps`` from its straight speed, then the rudder
    to ``rudder_deg`` (positive: to starboard, as the Esso's files have it), through its gyro's
    and log's noise; the straight speed."""
    speed = vessel_straight_speed(ship, rps)
    t = np.arange(0.0, APPROACH + 240.0, 0.1)
    delta = np.radians(np.sign(rudder_deg) * np.clip((t - APPROACH) * RATE, 0.0, abs(rudder_deg)))
    log = simulate(ship.dynamics, t, delta, np.r_[speed, np.zeros(5)], rps=np.full_like(t, rps)).log
    assert np.sign(log["r"].iloc[-1]) == np.sign(rudder_deg)  # the sister turns as the Esso does
    rng = np.random.default_rng(seed)
    n = len(t)
    pd.DataFrame({
        "t [s]": t, "x_position_mid [m]": log["x"] + rng.normal(0, 0.01, n),
        "u_velo [m/s]": log["u"] + rng.normal(0, 0.003, n),
        "y_position_mid [m]": log["y"] + rng.normal(0, 0.01, n),
        "vm_velo [m/s]": log["v"] + rng.normal(0, 0.003, n),
        "psi_hat [rad]": log["psi"] + rng.normal(0, 0.002, n),
        "r_angvelo [rad/s]": log["r"] + rng.normal(0, 0.001, n),
        "n_prop [rps]": np.full(n, rps), "delta_rudder [rad]": delta,
        "wind_velo_relative_mid [m/s]": np.zeros(n), "wind_dir_relative_mid [rad]": np.zeros(n),
    }).to_csv(path, index=False)  # fmt: skip
    return speed


@pytest.mark.parametrize(("rudder_deg", "rps"), [(20.0, 10.0), (-20.0, 8.0)])
def test_a_turn_after_a_straight_approach_reads_as_the_truths(sister, tmp_path, capsys,
                                                              rudder_deg, rps):  # fmt: skip
    raw = tmp_path / "turn.csv"
    speed = _osaka_file(sister, rudder_deg, rps, raw, seed=int(rps))
    code, _, err = run(["import", "--format", "osaka-frt", "--start", "auto", "--end", "auto",
                        raw, "-o", tmp_path / "cut.csv"], capsys)  # fmt: skip
    assert code == 0, err
    cut = pd.read_csv(tmp_path / "cut.csv", comment="#")
    # 5 s of the approach kept before the order (--lead), the rest of the straight run cut.
    assert cut["t"].iloc[0] == pytest.approx(APPROACH - 5.0, abs=0.15)
    code, out, err = run(["indices", tmp_path / "cut.csv", "--json",
                          tmp_path / "i.json"], capsys)  # fmt: skip
    assert code == 0, err
    (read,) = json.loads((tmp_path / "i.json").read_text())["logs"]
    got = read["indices"]
    assert got["kind"] == "turning"
    side = "starboard" if rudder_deg > 0 else "port"
    truth = turning_circle(sister, abs(rudder_deg), side, speed=speed, rps=rps, dt=0.1,
                           duration=240).indices  # fmt: skip
    assert got["turn_direction"] == side
    for key in ("advance", "transfer", "tactical_diameter"):
        assert got[key] == pytest.approx(truth[key], rel=0.02), key
    assert got["steady_yaw_rate"] == pytest.approx(truth["steady_yaw_rate"], rel=0.03)

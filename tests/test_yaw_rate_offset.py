"""A gyro's constant offset on the yaw rate was read without a word: on the paper ship's training
zig-zag an offset of 0.57 °/s (6 % of its rms r) made a held-out turn's free-run r error 1.8 times
as large. The heading tells it: ψ − ∫r dt drifts at the offset. The truth here is an offset added
to a simulated log."""

import math
import warnings

import pytest

from shipid.data.checks import check_units, yaw_rate_offset
from shipid.errors import ShipidWarning
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import PAPER_IMU, scale_ship


@pytest.fixture(scope="module")
def trial():
    return zigzag(scale_ship(rudder_rate_deg=9.6), 20, 20, duration=90, dt=0.2, method="euler",
                  approach=2.0).log  # fmt: skip


@pytest.mark.parametrize("seed", [None, 0, 1])
@pytest.mark.parametrize("offset_deg_s", [0.0, 0.3, 0.6, -1.2])
def test_the_offset_is_measured(trial, seed, offset_deg_s):
    log = trial if seed is None else PAPER_IMU.apply(trial, seed=seed)
    log = log.assign(r=log["r"] + math.radians(offset_deg_s))
    b = yaw_rate_offset(*(log[c].to_numpy() for c in ("t", "psi", "r")))
    # The paper's sensors (gyro noise, 0.05° heading) leave it within 0.03 °/s.
    assert math.degrees(b) == pytest.approx(offset_deg_s, abs=0.03 if seed is not None else 0.01)


def test_a_large_offset_is_named_and_a_clean_log_is_not(trial):
    with warnings.catch_warnings():
        warnings.simplefilter("error", ShipidWarning)
        check_units(PAPER_IMU.apply(trial, seed=0), "zz.csv")
    biased = trial.assign(r=trial["r"] + math.radians(0.6))
    named = r"zz\.csv: the yaw rate 'r' runs \+0\.(599|6\d*) °/s off"
    with pytest.warns(ShipidWarning, match=named):
        check_units(biased, "zz.csv")

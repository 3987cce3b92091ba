"""A noisy heading (a MEMS compass's 1°) fused with the yaw rate for the indices.

Bug: the heading's noise was counted as overshoot: the Mariner's 20/20 first overshoot, 7.8°,
read as 11.4° with 1° of white noise on ψ (and 8.5° with 0.2°)."""

import math

import numpy as np
import pytest

from shipid.trials.indices import manoeuvre_indices
from shipid.trials.manoeuvres import turning_circle, zigzag
from shipid.trials.trial import HEADING_NOISE_FLOOR, unwrapped_heading
from shipid.vessels import scale_ship

SHIP = scale_ship(rudder_rate_deg=9.6)


def _noisy_heading(log, sigma_deg, seed):
    out = log.copy()
    out["psi"] = out["psi"] + math.radians(sigma_deg) * np.random.default_rng(seed).normal(
        size=len(out))
    return out


@pytest.fixture(scope="module")
def clean_zigzag():
    return zigzag(SHIP, 10, 10, duration=40, dt=0.05, approach=2.0).log


def test_a_clean_or_barely_noisy_heading_is_read_as_it_is(clean_zigzag):
    assert np.array_equal(unwrapped_heading(clean_zigzag), np.unwrap(clean_zigzag["psi"]))
    # The Esso Osaka's logs show 0.06-0.1° of heading noise: read as they are.
    low = _noisy_heading(clean_zigzag, 0.5 * math.degrees(HEADING_NOISE_FLOOR), 0)
    assert np.array_equal(unwrapped_heading(low), np.unwrap(low["psi"]))


@pytest.mark.parametrize("seed", range(3))
def test_overshoots_of_a_1_degree_noisy_heading_match_the_clean_log(clean_zigzag, seed):
    want = manoeuvre_indices(clean_zigzag, heading_deg=10)
    noisy = _noisy_heading(clean_zigzag, 1.0, seed)
    got = manoeuvre_indices(noisy, heading_deg=10)
    for name in ("first_overshoot_deg", "second_overshoot_deg"):
        assert got[name] == pytest.approx(want[name], abs=0.3), name
    # The heading the indices read is within a tenth of the noise of the true one.
    err = unwrapped_heading(noisy) - np.unwrap(clean_zigzag["psi"])
    assert math.degrees(np.std(err)) < 0.25


def test_turn_event_times_of_a_noisy_heading():
    """A guard, not a bug: the turn crosses 90° and 180° fast, so the raw heading's noise barely
    moves these times (0.07 s at most over 5 seeds at 5 Hz); the fusion must not move them more."""
    clean = turning_circle(SHIP, 35, duration=60, dt=0.05, approach=2.0).log
    want = manoeuvre_indices(clean)
    got = manoeuvre_indices(_noisy_heading(clean, 1.0, 0))
    for name in ("time_to_90", "time_to_180"):
        assert got[name] == pytest.approx(want[name], abs=0.05), name


@pytest.mark.parametrize("seed", range(3))
def test_the_heading_read_without_unwrap_and_medians_is_numpys_and_the_medians_verdict(seed):
    """``unwrapped_heading`` skips np.unwrap where no step reaches π and heading_noise's medians
    where the steps' range settles the floor: the same heading to the bit, and the same choice
    of raw or fused, on clean, barely noisy, noisy and wrapped headings."""
    import pandas as pd

    from shipid.data.preprocess import cumulative_integral
    from shipid.trials.trial import heading_noise

    rng = np.random.default_rng(seed)
    n = 2000
    t = np.arange(n) * 0.1
    r = 0.05 * np.sin(t / 7.0)
    integral = cumulative_integral(r, t, initial=0.0)
    psi = integral + 1e-9 * np.cumsum(rng.normal(size=n))  # an integrator's own small drift
    for sigma in (0.0, 0.2 * HEADING_NOISE_FLOOR, HEADING_NOISE_FLOOR, 3 * HEADING_NOISE_FLOOR):
        for wrapped in (False, True):
            heading = psi + sigma * rng.normal(size=n)
            if wrapped:  # a compass's [-π, π): steps of 2π
                heading = (heading + 3.0 + np.pi) % (2 * np.pi) - np.pi
            log = pd.DataFrame({"t": t, "r": r, "psi": heading})
            got = unwrapped_heading(log)
            raw = np.unwrap(heading)
            if heading_noise(raw, integral) <= HEADING_NOISE_FLOOR:
                assert np.array_equal(got, raw), (sigma, wrapped)
            else:
                assert not np.array_equal(got, raw), (sigma, wrapped)

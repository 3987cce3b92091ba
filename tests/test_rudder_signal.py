"""A noisy rudder sensor: the manoeuvre's events read as from the clean rudder.

Bug: with 0.1° of white noise on the rudder a held 35° turn was "other (the rudder is not
held)", a 20/20 zig-zag "not one zig-zag angle", and the rudder rate (the replicas' steering
machine) measured the noise: 24°/s from 0.5° on a 5°/s rudder."""

import math
from pathlib import Path

import numpy as np
import pytest

from shipid.data.rudder_signal import dead_band, median_filtered, rudder_for_events, rudder_noise
from shipid.data.trim import rudder_execute_time
from shipid.trials.indices import manoeuvre_indices
from shipid.trials.manoeuvres import turning_circle, zigzag
from shipid.trials.trial import describe_trial
from shipid.vessels import scale_ship

RATE_DEG = 5.0
SHIP = scale_ship(rudder_rate_deg=RATE_DEG)


def _noisy(log, sigma_deg, seed=0):
    out = log.copy()
    rng = np.random.default_rng(seed)
    out["delta"] = out["delta"] + math.radians(sigma_deg) * rng.normal(size=len(out))
    return out


@pytest.fixture(scope="module", params=[0.05, 0.2], ids=["20 Hz", "5 Hz"])
def clean_logs(request):
    dt = request.param
    turn = turning_circle(SHIP, 35, duration=120, dt=dt, approach=3.0).log
    zz = zigzag(SHIP, 20, 20, duration=60, dt=dt, approach=3.0).log
    return dt, {"turning": turn, "zigzag": zz}


def test_noise_level_is_read_off_ramps_and_plateaus_alone():
    t = np.arange(0, 60, 0.05)
    clean = np.radians(np.clip(5.0 * (t - 10), 0, 35))  # a 5 °/s order to 35°, held
    assert rudder_noise(clean) == 0.0
    quantised = np.round(clean / math.radians(0.56)) * math.radians(0.56)  # the Esso's steps
    assert rudder_noise(quantised) == 0.0
    assert rudder_for_events(t, quantised)[0] is quantised  # clean logs are read as they are
    rng = np.random.default_rng(1)
    noisy = clean + math.radians(0.1) * rng.normal(size=t.size)
    assert math.degrees(rudder_noise(noisy)) == pytest.approx(0.1, rel=0.1)


def test_median_and_dead_band_keep_a_ramp_and_flatten_a_plateau():
    x = np.concatenate([np.zeros(20), np.arange(1, 41) * 0.5, np.full(40, 20.0)])
    assert np.array_equal(median_filtered(x, 7), x)  # monotone: untouched
    rng = np.random.default_rng(2)
    wavering = 20.0 + 0.1 * rng.uniform(-1, 1, 200)
    held = dead_band(np.concatenate([x, wavering]), 0.15)
    # The noise never turns it back (it only follows a new highest value, by less than the
    # noise), and the ramp stays monotone.
    assert np.all(np.diff(held) >= 0)
    assert np.ptp(held[100:]) <= 0.1
    assert np.count_nonzero(np.diff(held[100:])) <= 5


@pytest.mark.parametrize("sigma_deg", [0.1, 0.3])
@pytest.mark.parametrize("kind", ["turning", "zigzag"])
def test_a_noisy_rudder_gives_the_clean_logs_kind_indices_and_rudder_rate(clean_logs, kind,
                                                                           sigma_deg):
    dt, logs = clean_logs
    clean = logs[kind]
    noisy = _noisy(clean, sigma_deg)
    truth, trial = describe_trial(clean), describe_trial(noisy)
    assert trial.kind == truth.kind == kind
    assert abs(trial.execute_time - truth.execute_time) <= 2 * dt + 1e-9
    assert math.degrees(trial.rudder_rate) == pytest.approx(RATE_DEG, rel=0.05)
    assert math.degrees(trial.amplitude) == pytest.approx(math.degrees(truth.amplitude), abs=0.3)
    want, got = manoeuvre_indices(clean), manoeuvre_indices(noisy)
    if kind == "turning":
        assert trial.held_end_index == truth.held_end_index
        for name in ("advance", "transfer", "tactical_diameter", "steady_yaw_rate"):
            assert got[name] == pytest.approx(want[name], rel=0.01), name
    else:
        # The switch heading read at the orders: within the heading one sample sweeps of the
        # nominal 20° (the clean log's reading is too: the order falls between two samples).
        one_sample = math.degrees(np.abs(clean["r"]).max()) * dt
        assert trial.switch_heading_deg == pytest.approx(20.0, abs=one_sample)
        assert truth.switch_heading_deg == pytest.approx(20.0, abs=one_sample)
        want, got = manoeuvre_indices(clean, heading_deg=20), manoeuvre_indices(noisy, heading_deg=20)
        for name in ("first_overshoot_deg", "second_overshoot_deg"):
            assert got[name] == pytest.approx(want[name], abs=0.05), name


def test_auto_trim_finds_the_execute_of_a_noisy_rudder(clean_logs):
    dt, logs = clean_logs
    clean = logs["turning"]
    want = rudder_execute_time(clean)
    assert rudder_execute_time(_noisy(clean, 0.3)) == pytest.approx(want, abs=2 * dt + 1e-9)


def _three_digits(x):
    """``%.2E``, as MARIN prints its files: three significant digits."""
    return np.array([float(f"{v:.2E}") for v in x])


@pytest.mark.parametrize("dt", [0.02, 0.1, 0.5, 1.0])
def test_the_rudder_rate_of_a_quantised_rudder_is_its_swings_not_its_steps(dt):
    """Bug: MARIN's rudder, three digits at 50 Hz, steps by 0.3° or 0.4° at its 15.7°/s; the 90th
    percentile of the steps read 20°/s (a 27 % faster gear for every closed loop and manoeuvre
    of a model identified at the log's own sampling), 16.2°/s resampled to 0.2 s."""
    rate = 15.7
    ship = scale_ship(rudder_rate_deg=rate)
    log = zigzag(ship, 20, 20, duration=80, dt=dt, approach=3.0).log
    log["delta"] = np.radians(_three_digits(np.degrees(log["delta"].to_numpy())))
    assert math.degrees(describe_trial(log).rudder_rate) == pytest.approx(rate, rel=0.01)


DATA = Path(__file__).resolve().parents[2] / "shared" / "data"


def _shared(name: str) -> Path:
    """A file of ``../shared/data``; the test is skipped without it."""
    path = DATA / name
    if not path.is_file():
        pytest.skip("../shared/data is absent")
    return path


def test_the_real_marin_rudder_rate_does_not_depend_on_the_sampling():
    from shipid.data.io import read_log

    path = _shared("kvlcc2-marin/MARIN_FREE_KVLCC2_zz_20_m.dat")
    # The data README: 2.32 °/s at full scale, 15.7 °/s Froude-scaled to the 7 m model.
    want = 2.32 * math.sqrt(45.7)
    for dt in (None, 0.2, 0.5):
        log = read_log(path, fmt="simman-marin", scale=45.7, dt=dt)
        assert math.degrees(describe_trial(log).rudder_rate) == pytest.approx(want, rel=0.03), dt


@pytest.mark.parametrize("dt", [0.2, 0.5])
@pytest.mark.parametrize("phase", [0.13, 0.37, 0.71])
def test_a_ramp_whose_corners_fall_between_samples_reads_at_its_rate(dt, phase):
    """A real log samples the gear's ramps wherever their corners fall. Bug: the line through
    the swing's 10 % and 90 % points, interpolated between samples, crossed a corner's step
    where a sample moved more than a tenth of the swing: this 15.7 °/s gear sampled at 0.2 s
    read 15.58–15.59 °/s (HSVA's real 20/10 zig-zag resampled to 0.5 s: 15.54 against its own
    15.85)."""
    from shipid.data.rudder_signal import ramp_line, rise_rate

    rate = math.radians(15.7)
    t = np.arange(0.0, 60.0, dt)
    # Swings of 40° and 20° between plateaus, each order a fraction `phase` of a step after a
    # sample (a ramp of 20° at 15.7 °/s spans 1.3 s: two samples of 0.5 s inside 10–90 %).
    orders = [(5.0 + phase * dt, 0.0, 0.35), (20.0 + phase * dt, 0.35, -0.35),
              (38.0 + phase * dt, -0.35, 0.0)]  # fmt: skip
    delta = np.zeros_like(t)
    for t0, a, b in orders:
        end = t0 + abs(b - a) / rate
        on = t >= t0
        delta[on] = np.where(t[on] >= end, b, a + np.sign(b - a) * rate * (t[on] - t0))
    assert rise_rate(t, delta) == pytest.approx(rate, rel=1e-9)
    k = int(np.searchsorted(t, orders[1][0])) - 1
    b = int(np.searchsorted(t, orders[1][0] + 0.7 / rate)) + 1
    slope, at_zero = ramp_line(t, delta, k, b)
    assert (0.35 - at_zero) / slope == pytest.approx(orders[1][0], abs=1e-9)


def test_the_real_hsva_rudder_rate_does_not_depend_on_the_sampling():
    from shipid.data.io import read_log

    path = _shared("kvlcc2-hsva/HSVA_CPMC_KVLCC2_Z_20_10_P.dat")
    own = describe_trial(read_log(path, fmt="simman-hsva")).rudder_rate
    for dt in (0.2, 0.5, 1.0):
        log = read_log(path, fmt="simman-hsva", dt=dt)
        assert describe_trial(log).rudder_rate == pytest.approx(own, rel=0.005), dt

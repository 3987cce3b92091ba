"""A long log's indices and bands, to the digit of what they were before they were made fast
(issue #13: ``validate`` of a model with 200 covariance draws on a 45 000-sample zig-zag took
12–13 s, most of it reading each replicate's hundreds of reversals and sorting its bands)."""

import numpy as np
import pytest

from shipid.identification.uncertainty import _CHUNK, conservative_percentiles
from shipid.trials.indices import zigzag_indices
from shipid.trials.manoeuvres import zigzag
from shipid.trials.trial import PLATEAU_TOLERANCE, _plateau_levels, describe_trial
from shipid.vessels import PAPER_IMU, scale_ship, scale_ship_model


@pytest.fixture(scope="module")
def long_zigzag():
    """Twelve minutes of a 20/20 zig-zag of the paper's ship, its rudder at the Froude-scaled
    SOLAS rate: dozens of reversals."""
    return zigzag(scale_ship(rudder_rate_deg=9.6), 20, 20, duration=720, dt=0.2, method="euler",
                  speed=1.93, approach=2.0).log  # fmt: skip


def test_percentiles_in_blocks_are_those_of_each_column():
    rng = np.random.default_rng(3)
    v = rng.standard_normal((200, 400, 3))
    assert v.size > _CHUNK  # computed in blocks of columns
    v[:4, 7, 1] = np.nan  # within the 2.5 % tail: still bounded
    v[:30, 11, 2] = np.nan  # beyond it: not bounded
    v[:, 13, 0] = np.nan  # no replicate has a value
    lo, hi = conservative_percentiles(v)
    assert lo.shape == hi.shape == (400, 3)
    for j in range(400):
        for k in range(3):
            expect = conservative_percentiles(v[:, j, k])  # one column: no blocks
            assert np.array_equal([lo[j, k], hi[j, k]], expect, equal_nan=True)
    # Where every replicate has a value: NumPy's own (linear) percentiles.
    finite = np.isfinite(v).all(axis=0)
    ref = np.percentile(v, [2.5, 97.5], axis=0)
    assert np.allclose(lo[finite], ref[0][finite], rtol=0, atol=1e-12)
    assert np.allclose(hi[finite], ref[1][finite], rtol=0, atol=1e-12)
    assert lo[11, 2] == -np.inf and hi[11, 2] == np.inf and np.isnan(lo[13, 0])


@pytest.mark.parametrize("noisy", [False, True])
def test_plateau_levels_are_each_runs(noisy):
    """Against each run of the rudder's side read on its own."""
    rng = np.random.default_rng(5)
    side = np.repeat(rng.choice([-1.0, 0.0, 1.0], size=60), rng.integers(1, 30, size=60))
    dev = side * 0.35 + rng.normal(0, 0.004, side.size)
    measured = dev + rng.normal(0, 0.002, side.size) if noisy else None
    expect = []
    edges = np.flatnonzero(np.diff(side)) + 1
    for run in np.split(np.arange(side.size), edges):
        s = side[run[0]]
        if s == 0:
            continue
        top = float(np.max(s * dev[run]))
        if noisy:
            on = s * dev[run] >= top - PLATEAU_TOLERANCE
            top = float(np.median(s * measured[run][on]))
        expect.append(top)
    assert _plateau_levels(side, dev, measured) == expect
    assert _plateau_levels(side[:0], dev[:0], None) == []


QUICK = ("reversal_headings_deg", "reversal_step_deg", "rudder_rate")


def test_a_trial_read_for_its_indices_has_every_other_fact(long_zigzag):
    full = describe_trial(long_zigzag, "zigzag", 20.0, 2.0)
    quick = describe_trial(long_zigzag, "zigzag", 20.0, 2.0, indices_only=True)
    assert len(full.reversal_headings_deg) > 30 and full.rudder_rate > 0
    assert quick.reversal_headings_deg == () and quick.reversal_step_deg == 0.0
    assert quick.rudder_rate is None
    fields = {k: v for k, v in vars(full).items() if k not in QUICK}
    assert fields == {k: v for k, v in vars(quick).items() if k in fields}
    # Without the switch heading the reversals are what it is inferred from: still read.
    inferred = describe_trial(long_zigzag, "zigzag", indices_only=True)
    assert inferred.reversal_headings_deg == describe_trial(long_zigzag).reversal_headings_deg


def test_a_turn_read_for_its_indices_has_every_other_fact():
    from shipid.trials.manoeuvres import turning_circle

    log = turning_circle(scale_ship_model(), 20, duration=240, dt=0.2, speed=1.93).log
    full = describe_trial(log, "turning")
    quick = describe_trial(log, "turning", indices_only=True)
    fields = {k: v for k, v in vars(full).items() if k not in QUICK}
    assert fields == {k: v for k, v in vars(quick).items() if k in fields}


@pytest.mark.parametrize("noise", [False, True])
def test_a_long_zigzags_indices_are_its_first_cycles(long_zigzag, noise):
    """The overshoots end at the fourth execute: what comes after cannot move them."""
    log = PAPER_IMU.apply(long_zigzag, seed=2) if noise else long_zigzag
    whole = zigzag_indices(log, 20.0, t_order=2.0)
    cut = zigzag_indices(log[log["t"] <= 120.0].reset_index(drop=True), 20.0, t_order=2.0)
    assert whole["second_overshoot_deg"] is not None
    assert whole == cut

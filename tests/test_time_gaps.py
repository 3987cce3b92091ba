"""Logs with samples missing in time (a logger's dropout): named, not bridged in silence.

A 20/20 zig-zag with 30 s missing was fitted through 150 samples that ``--dt`` had drawn in
straight lines (as the sampling check's own remedy said), replayed in one 30 s step that
diverged, and a gap of 7 s after its execute read its first overshoot 23.5° for 27.4°."""

import math
import warnings

import numpy as np
import pytest

from shipid.cli import main
from shipid.data.io import read_log, write_log
from shipid.data.preprocess import GAP_INTERVALS, resample, time_gaps
from shipid.data.yaw_rate import heading_drift
from shipid.dynamics.simulate import simulate_log
from shipid.errors import ShipidError, ShipidWarning
from shipid.identification.regression import sampling_time
from shipid.trials.indices import manoeuvre_indices
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import scale_ship

SHIP = scale_ship(rudder_rate_deg=9.6)


@pytest.fixture(scope="module")
def zigzag_log():
    return zigzag(SHIP, 20, 20, duration=90, dt=0.2, method="rk4", approach=2.0).log


def _without(log, start, end):
    """``log`` without its samples strictly between ``start`` and ``end``."""
    t = log["t"].round(6)
    out = log[(t <= start) | (t >= end)].reset_index(drop=True)
    out.attrs = dict(log.attrs, name="gappy.csv")
    return out


def test_a_gap_is_more_than_ten_sampling_intervals():
    t = np.concatenate([np.arange(0, 10, 0.1), 10.0 + 0.1 * GAP_INTERVALS + np.arange(0, 5, 0.1)])
    assert time_gaps(t) == [99]
    # One or a few samples missing are a sampling that varies, not a gap.
    assert time_gaps(np.delete(np.arange(0, 10, 0.1), [20, 21, 22])) == []


def test_resampling_refuses_to_draw_lines_across_a_gap_unless_asked(zigzag_log):
    gappy = _without(zigzag_log, 40.0, 60.0)
    with pytest.raises(ShipidError, match=r"gappy: no samples for 20 s \(t = 40–60, after data "
                                          r"row 201\).*cut the log there.*--fill-gaps"):
        resample(gappy, 0.2, "gappy")
    with pytest.warns(ShipidWarning, match="no samples for 20 s.*interpolated"):
        filled = resample(gappy, 0.2, "gappy", fill_gaps=True)
    assert len(filled) == len(zigzag_log)
    inside = (filled["t"] > 40.0) & (filled["t"] < 60.0)
    t0, t1 = 40.0, 60.0
    u0, u1 = (float(zigzag_log.loc[np.isclose(zigzag_log["t"], s), "u"].iloc[0]) for s in (t0, t1))
    np.testing.assert_allclose(filled.loc[inside, "u"],
                               u0 + (u1 - u0) * (filled.loc[inside, "t"] - t0) / (t1 - t0),
                               rtol=1e-12)  # fmt: skip
    # A few samples missing are still resampled without a word.
    few = _without(zigzag_log, 40.0, 40.8)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert len(resample(few, 0.2, "few")) == len(zigzag_log)


def test_the_sampling_check_names_a_gap_instead_of_suggesting_dt(zigzag_log):
    with pytest.raises(ShipidError, match=r"no samples for 20 s.*one-step regression needs "
                                          r"consecutive samples") as caught:
        sampling_time(_without(zigzag_log, 40.0, 60.0), "gappy")
    assert "resample it with --dt" not in str(caught.value)
    with pytest.raises(ShipidError, match=r"not uniform.*resample it with --dt 0.2"):
        sampling_time(_without(zigzag_log, 40.0, 40.8), "few")


def test_a_free_run_does_not_step_across_a_gap(zigzag_log):
    with pytest.raises(ShipidError, match=r"gappy.csv: no samples for 20 s.*a free run would "
                                          r"step across it with the rudder unknown"):
        simulate_log(SHIP.dynamics, _without(zigzag_log, 40.0, 60.0))
    # The same ship replayed over a log with three samples missing follows it.
    few = _without(zigzag_log, 40.0, 40.8)
    run = simulate_log(SHIP.dynamics, few, method="rk4").log
    np.testing.assert_allclose(run["r"], few["r"], atol=0.02 * np.ptp(few["r"]))


def test_the_gyro_check_reads_the_pieces_of_a_gappy_log_joined(zigzag_log):
    gappy = _without(zigzag_log, 40.0, 60.0)
    args = (gappy[c].to_numpy() for c in ("t", "psi", "r"))
    assert abs(heading_drift(*args).offset) < math.radians(0.002)  # no offset in the truth
    offset = math.radians(0.05)
    biased = heading_drift(gappy["t"].to_numpy(), gappy["psi"].to_numpy(),
                           gappy["r"].to_numpy() + offset)  # fmt: skip
    assert biased.offset == pytest.approx(offset, rel=0.05)


def test_indices_refuse_a_gap_after_the_execute(zigzag_log):
    whole = manoeuvre_indices(zigzag_log)
    with pytest.raises(ShipidError, match=r"no samples for 7 s.*after the zigzag's execute at "
                                          r"t = 1.8.*cut the log before it \(--end 10\)"):
        manoeuvre_indices(_without(zigzag_log, 10.0, 17.0))
    # A gap in the approach leaves them as they were.
    approach = _without(zigzag_log.assign(t=zigzag_log["t"] + 10.0), 0.0, 10.0)
    moved = manoeuvre_indices(approach)
    assert moved["first_overshoot_deg"] == pytest.approx(whole["first_overshoot_deg"], abs=0.05)


def test_the_command_line_names_the_gap_and_writes_nothing(zigzag_log, tmp_path, capsys):
    path = tmp_path / "gappy.csv"
    write_log(_without(zigzag_log, 40.0, 60.0), path)
    out = tmp_path / "model.json"
    assert main(["identify", str(path), "--dt", "0.2", "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert "no samples for 20 s" in err and "Traceback" not in err
    assert "yaw rate 'r' runs" not in err  # the gap is not taken for a gyro's offset
    assert not out.exists()
    with pytest.warns(ShipidWarning, match="interpolated"):
        log = read_log(path, dt=0.2, fill_gaps=True)
    assert len(log) == len(zigzag_log)

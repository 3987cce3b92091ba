"""``read_trial_log``: a trial file read as the commands fit and judge it (the trial it holds)."""

import warnings
from pathlib import Path

import pandas as pd
import pytest

from shipid import read_log, read_trial_log
from shipid.errors import ShipidWarning

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="../shared/data is not present")


@needs_data
@pytest.mark.parametrize(("path", "kw", "cut", "mark"), [
    ("esso-osaka/zigzag/zigzag_31-Jul-2020_13_22_52.csv", {"fmt": "osaka-frt"},
     {"start": "auto", "end": "auto"}, "cut_to_manoeuvre"),  # a 15/15 zig-zag from rest
    ("esso-osaka/turning/turn_14-Sep-2020_14_16_04.csv", {"fmt": "osaka-frt", "dt": 0.5},
     {"start": "auto", "end": "auto"}, "cut_to_manoeuvre"),
    ("esso-osaka/random/random_31-Jul-2020_14_52_18.csv", {"fmt": "osaka-frt"},
     {"end": "dropout"}, "cut_at_dropout"),  # its last minute logs n = 0 while it speeds up
    ("esso-osaka/random/random_31-Jul-2020_12_29_58.csv", {"fmt": "osaka-frt"}, {}, None),
    ("kvlcc2-marin/MARIN_FREE_KVLCC2_zz_20_m.dat", {"fmt": "simman-marin", "scale": 45.7}, {},
     None),  # under way from its first sample
])  # fmt: skip
def test_the_shared_trials_are_read_as_the_readme_imports_them(path, kw, cut, mark):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ShipidWarning)
        read = read_trial_log(DATA / path, **kw)
        expected = read_log(DATA / path, **kw, **cut)
        whole = read_log(DATA / path, **kw)
        # A start or an end given is the caller's: the file read as read_log reads it.
        given = read_trial_log(DATA / path, start=0.0, **kw)
    pd.testing.assert_frame_equal(read, expected)
    marks = {k for k in ("cut_to_manoeuvre", "cut_at_dropout") if read.attrs.get(k)}
    assert marks == ({mark} if mark else set())
    assert (len(read) < len(whole)) == bool(cut)
    pd.testing.assert_frame_equal(given, whole)


@needs_data
def test_a_cut_log_warns_of_the_cut_not_of_what_it_left_out():
    """The whole file's dropout is named by read_log; the log cut before it has none to name."""
    path = DATA / "esso-osaka/random/random_31-Jul-2020_14_52_18.csv"
    with pytest.warns(ShipidWarning) as whole:
        read_log(path, fmt="osaka-frt")
    assert any("the propeller is stopped or astern" in str(w.message) for w in whole)
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        read_trial_log(path, fmt="osaka-frt")
    assert not any("the propeller is stopped or astern" in str(w.message) for w in caught)

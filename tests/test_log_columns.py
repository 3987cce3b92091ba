"""A log's columns taken as arrays (``shipid.data.log.column_values``): pandas' own values,
read-only as pandas gives them, whatever the frame stores."""

import numpy as np
import pandas as pd
import pytest

from shipid.data.log import column_array, column_values, make_log
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import scale_ship


@pytest.fixture(scope="module")
def log():
    return zigzag(scale_ship(), 20, 20, duration=30, dt=0.1).log


def test_every_column_is_pandas_own_values_read_only(log):
    for name in log.columns:
        for dtype in (None, float):
            got, want = column_values(log, name, dtype), log[name].to_numpy(dtype=dtype)
            assert got.dtype == want.dtype and np.array_equal(got, want, equal_nan=True), name
            assert not got.flags.writeable  # a view of the log: writing to it would change it
            with pytest.raises(ValueError, match="read-only"):
                got[0] = 1.0
    assert np.array_equal(column_array(log, ["u", "r"]), log[["u", "r"]].to_numpy())


def test_a_column_converted_is_a_writable_copy_as_pandas_gives():
    frame = pd.DataFrame({"n": [10, 12, 14], "t": [0.0, 0.1, 0.2]})
    got = column_values(frame, "n", float)
    assert got.dtype == float and got.flags.writeable
    got[0] = -1.0
    assert frame["n"].iloc[0] == 10
    assert column_values(frame, "n").dtype == frame["n"].to_numpy().dtype


@pytest.mark.parametrize("frame", [
    pd.DataFrame({"name": ["a", "b"], "u": [1.0, 2.0]}),  # a string column: an extension array
    pd.DataFrame([[1.0, 2.0], [3.0, 4.0]], columns=["u", "u"]),  # a name given twice
    {"u": pd.Series([1.0, 2.0])},  # no DataFrame
])  # fmt: skip
def test_what_is_not_one_stored_column_goes_pandas_way(frame):
    want = frame["u"].to_numpy()
    assert np.array_equal(column_values(frame, "u"), want)
    if isinstance(frame, pd.DataFrame) and "name" in frame.columns:
        assert list(column_values(frame, "name")) == ["a", "b"]


def test_a_missing_column_is_a_key_error_as_in_pandas():
    log = make_log({"t": np.arange(3.0), "u": np.ones(3)})
    with pytest.raises(KeyError):
        column_values(log, "v")

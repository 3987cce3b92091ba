"""The memory guard reads the available memory only for requests that could need it: a small run
is every manoeuvre of a search's plausibility checks, and reading /proc/meminfo cost each a
twentieth of its time."""

import pytest

import shipid.limits as limits
from shipid.errors import ShipidError


def test_a_small_request_is_not_checked_and_a_large_one_is(monkeypatch):
    reads = []

    def little_memory():
        reads.append(1)
        return 100 * 2**20  # 100 MiB available: half of it may be asked for

    monkeypatch.setattr(limits, "available_memory_bytes", little_memory)
    assert limits.check_samples(1000.0, 8 * 14, "a small run") == 1000
    assert reads == []
    at_the_edge = limits.UNCHECKED_BYTES / (8 * 14)  # 64 MiB: unchecked, though over half of 100
    assert limits.check_samples(at_the_edge, 8 * 14, "a run at the edge") == round(at_the_edge)
    assert reads == []
    with pytest.raises(ShipidError, match=r"a long run: 6e\+06 samples would need 0.626 GiB"):
        limits.check_samples(6e6, 8 * 14, "a long run")
    assert reads == [1]


@pytest.mark.parametrize("n", [float("nan"), float("inf"), -1.0])
def test_a_request_that_is_no_number_of_samples_is_refused_however_small(n):
    with pytest.raises(ShipidError, match="asks for"):
        limits.check_samples(n, 8, "a run")

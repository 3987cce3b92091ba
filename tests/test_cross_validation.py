"""The default cross-validation of identify's choices (``choice_cv``): each log left out in turn
from three logs; one or two cut into four blocks each (two logs left out in turn are two
folds), unless one of two is too short for blocks of ten samples."""

import numpy as np
import pandas as pd
import pytest

from shipid.errors import ShipidError
from shipid.identification.cross_validation import choice_cv, split_blocks


def _log(n):
    return pd.DataFrame({"t": np.arange(n) * 0.1, "u": np.ones(n)})


@pytest.mark.parametrize(("lengths", "expected"), [
    ([200], "blocks:4"), ([200, 200], "blocks:4"), ([200] * 3, "logo"), ([200] * 12, "logo"),
    ([39, 200], "logo"), ([40, 200], "blocks:4"), ([30], "blocks:4"), ([30] * 3, "logo")])
def test_one_or_two_logs_are_cut_into_blocks(lengths, expected):
    assert choice_cv([_log(n) for n in lengths]) == expected


@pytest.mark.parametrize("n", [39, 40, 41, 44])
def test_the_choice_and_the_cut_agree_on_a_log_too_short(n):
    """39 samples cut into four blocks leave one of 9 (edges 0, 10, 20, 29, 39): both refuse it;
    40 and more, both take it."""
    fits = choice_cv([_log(n), _log(200)]) == "blocks:4"
    if fits:
        blocks, _ = split_blocks([_log(n)], ["log"], 4)
        assert min(len(b) for b in blocks) >= 10
    else:
        with pytest.raises(ShipidError, match="too short for --cv blocks:4"):
            split_blocks([_log(n)], ["log"], 4)
    assert fits == (n >= 40)

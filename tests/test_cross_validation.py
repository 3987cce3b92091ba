"""The default cross-validation of identify's choices: each log left out in turn from three
logs; one or two cut into four blocks each (two logs left out in turn are two folds)."""

import pytest

from shipid.identification.cross_validation import BLOCKS, LOGS_LEFT_OUT, choice_cv, parse_cv


@pytest.mark.parametrize(("n_logs", "expected"), [(1, "blocks:4"), (2, "blocks:4"),
                                                  (3, "logo"), (12, "logo")])
def test_one_or_two_logs_are_cut_into_blocks(n_logs, expected):
    assert (LOGS_LEFT_OUT, BLOCKS) == (3, 4)
    assert choice_cv(n_logs) == expected
    assert parse_cv(choice_cv(n_logs))[0] in ("logo", "blocks")


def test_two_logs_too_short_for_blocks_are_left_out_in_turn():
    """Two logs of 30 samples cannot be cut into four blocks of ten: each is left out in turn,
    as before, instead of an error (a single log has no other choice and says why)."""
    import numpy as np
    import pandas as pd

    def log(n):
        return pd.DataFrame({"t": np.arange(n) * 0.1, "u": np.ones(n)})

    assert choice_cv([log(30), log(200)]) == "logo"
    assert choice_cv([log(44), log(200)]) == "blocks:4"
    assert choice_cv([log(30)]) == "blocks:4"
    assert choice_cv([log(30)] * 3) == "logo"

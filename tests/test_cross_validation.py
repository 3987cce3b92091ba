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

"""Progress bars: drawn where asked, and where not, neither drawn nor imported (the searches of
every ``identify`` and ``select`` opened a disabled tqdm bar and imported tqdm for it)."""

import pytest
from cli_helpers import fresh_python

from shipid.progress import progress, progress_bar


def test_a_hidden_bar_draws_nothing_and_imports_no_tqdm():
    code = ("import sys; from shipid.progress import progress, progress_bar\n"
            "with progress_bar(3, 'fits', shown=False) as bar:\n"
            "    bar.update(); bar.update(2)\n"
            "bar.close()\n"
            "print(list(progress(range(3), 'logs', shown=False)), 'tqdm' in sys.modules)")
    assert fresh_python(code).split("\n")[0] == "[0, 1, 2] False"


@pytest.mark.parametrize("shown", [True, None])
def test_a_shown_bar_counts_its_items(capsys, shown):
    assert list(progress(iter("abc"), "logs", "log", shown=shown)) == ["a", "b", "c"]
    err = capsys.readouterr().err
    # True: always drawn; None: only on a terminal (pytest's captured stderr is not one).
    assert ("3/3" in err) is bool(shown)
    with progress_bar(4, "fits", "fit", shown=shown) as bar:
        bar.update(4)
    assert ("4/4" in capsys.readouterr().err) is bool(shown)

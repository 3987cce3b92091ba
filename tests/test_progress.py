"""Progress bars: drawn where asked, and where not, neither drawn nor imported (the searches of
every ``identify`` and ``select`` opened a disabled tqdm bar and imported tqdm for it)."""

import io
import subprocess
import sys
from pathlib import Path

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


class Terminal(io.StringIO):
    def isatty(self) -> bool:
        return True


@pytest.mark.parametrize("shown", [True, False])
@pytest.mark.parametrize("terminal", [True, False])
def test_a_shown_bar_counts_its_items_where_it_is_watched(monkeypatch, shown, terminal):
    """Drawn on a terminal where asked; into a file or a pipe (pytest's captured stream is one),
    not."""
    err = Terminal() if terminal else io.StringIO()
    monkeypatch.setattr(sys, "stderr", err)
    monkeypatch.delitem(sys.modules, "ipykernel", raising=False)
    assert list(progress(iter("abc"), "logs", "log", shown=shown)) == ["a", "b", "c"]
    assert ("3/3" in err.getvalue()) is (terminal and shown)
    with progress_bar(4, "fits", "fit", shown=shown) as bar:
        bar.update(4)
    assert ("4/4" in err.getvalue()) is (terminal and shown)


def test_validate_writes_no_bar_into_a_redirected_stderr(tmp_path):
    """Three logs or more draw a bar on a terminal; ``2> file`` holds the warnings alone."""
    from generated_logs import noisy_zigzags

    from shipid.data.io import write_log

    logs = noisy_zigzags(seed=1)[:3]
    paths = [str(write_log(log, tmp_path / f"zz{i}.csv")) for i, log in enumerate(logs)]
    from shipid.cli import main

    # The model in this process; the validate whose standard error is redirected in its own.
    assert main(["identify", paths[0], "-o", str(tmp_path / "m.json")]) == 0
    exe = Path(sys.executable).parent / "shipid"
    res = subprocess.run([str(exe), "validate", str(tmp_path / "m.json"), *paths],
                         capture_output=True, text=True, timeout=120)  # fmt: skip
    assert res.returncode == 0, res.stderr
    assert "log/s" not in res.stderr and "\r" not in res.stderr


def test_a_notebook_watches_its_stream(monkeypatch):
    """In a notebook's kernel standard error is no terminal, and is watched all the same."""
    from shipid.progress import watched

    monkeypatch.setattr(sys, "stderr", io.StringIO())
    monkeypatch.delitem(sys.modules, "ipykernel", raising=False)
    assert not watched()
    monkeypatch.setitem(sys.modules, "ipykernel", type(sys)("ipykernel"))
    assert watched()

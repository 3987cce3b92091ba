"""docs/tutorial.py runs as written: from the Esso Osaka data to an IMO criteria table."""

import runpy
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"


@pytest.mark.skipif(not DATA.is_dir(), reason="../shared/data is not present")
def test_tutorial_runs_to_the_imo_table(capsys):
    ns = runpy.run_path(str(ROOT / "docs" / "tutorial.py"), run_name="__main__")
    out = capsys.readouterr().out
    assert "stopping track reach" in out and "tactical diameter" in out
    crit = ns["criteria"]
    assert len(crit.table) == 13 and crit.conditions["scale"] == 108.3
    assert ns["results"][-1].metrics["r"]["std"] < 0.5 * ns["r_spread"]

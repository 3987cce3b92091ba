"""docs/tutorial.py runs as written: from the Esso Osaka data to an IMO criteria table."""

import runpy
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
DATA = ROOT.parent / "shared" / "data"


@pytest.mark.skipif(not DATA.is_dir(), reason="../shared/data is not present")
def test_tutorial_runs_to_the_imo_table(capsys):
    """The tutorial is the README's Esso recipe through the API, so its numbers are the
    acceptance of #9 and #10: trained on the nine zig-zags and three random runs (up to the
    propulsion dropout of 31-Jul 14_52_18), the two ±35° turning circles and one random run
    (12_29_58) held out, the candidates averaged by their shares. The tactical diameters come
    within 15 % (measured +12 %, +5 %; the chosen candidate alone +19 %, +11 %), the steady yaw
    rates within 15 % (+5 %, +2 %) and the random run's r error under half its spread (0.39); the
    measured indices inside the 95 % intervals of the ensemble over the choice of terms."""
    ns = runpy.run_path(str(ROOT / "docs" / "tutorial.py"), run_name="__main__")
    out = capsys.readouterr().out
    assert "stopping track reach" in out and "tactical diameter" in out
    crit = ns["criteria"]
    assert len(crit.table) == 13 and crit.conditions["scale"] == 108.3
    # From a steady approach: the model holds the criteria's speed at their rps.
    model, app = ns["selection"].model, ns["approach"]
    udot = model.accelerations([app.speed], [0.0], [0.0], [0.0], None, [app.rps],
                               wind_speed=[app.speed], wind_angle=[0.0])[0, 0]  # fmt: skip
    assert abs(udot) * 10 < 1e-3 * app.speed and crit.conditions["speed"] == app.speed
    results = ns["results"]
    for v in results:
        assert v.error is None and not v.simulation.diverged, v.name
    for v in results[:2]:
        meas, pred = v.indices["measured"], v.indices["simulated"]
        assert pred["tactical_diameter"] == pytest.approx(meas["tactical_diameter"], rel=0.15)
        assert np.sign(pred["steady_yaw_rate"]) == np.sign(meas["steady_yaw_rate"])
        assert pred["steady_yaw_rate"] == pytest.approx(meas["steady_yaw_rate"], rel=0.15)
        # The README's claim: the measured indices inside the 95 % intervals of the ensemble
        # whose replicates also draw their terms; those of the selected terms alone miss them
        # without the asymmetry terms (benchmarks/study_esso.py).
        for key in ("tactical_diameter", "steady_yaw_rate"):
            lo, hi = v.intervals["simulated"][key]
            assert lo <= meas[key] <= hi, (v.name, key)
    assert ns["ensemble"].varies_structure and ns["selection"].chosen_share < 0.5
    assert results[-1].metrics["r"]["std"] < 0.5 * ns["r_spread"]
    # The README: 96 % of the held-out random run's r inside the cross-validated band.
    assert results[-1].band_shares["r"] == pytest.approx(0.96, abs=0.005)
    r_ratio = results[-1].metrics["r"]["std"] / ns["r_spread"]
    assert r_ratio == pytest.approx(0.39, abs=0.005)
    assert ns["selection"].model is not ns["selection"].chosen_model
    # Its training logs end before the dropout of 31-Jul 14_52_18 (n = 0 as the ship speeds up).
    dropped = ns["randoms"]["random_31-Jul-2020_14_52_18.csv"]
    assert dropped["t"].iloc[-1] == pytest.approx(568.0) and dropped["n"].iloc[-1] > 0

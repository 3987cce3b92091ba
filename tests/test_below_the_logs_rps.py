"""identify's warning below the logs' propeller speeds (``beyond_the_logs.below_the_logs_rps``),
on a model whose surge balance has a closed form: u̇ = −a|u|u + c|n|n − d (no rudder drag), so
its steady straight speed is √((c n² − d)/a) and none where c n² < d. From logs at 10 rps, at
0.6 of it (6 rps) c n² = 0.0432 < d = 0.05: no steady straight speed, said; with d = 0 the
model is the same ship at any rps, and nothing is said."""

import math

import numpy as np
import pandas as pd
import pytest

from shipid.dynamics.model import ManoeuvringModel, get_structure
from shipid.identification.beyond_the_logs import below_the_logs_rps
from shipid.identification.plausibility import plausibility_at_approach

A, C = 0.0321, 0.0012  # |u|u and |n|n coefficients


def _model(drag: float) -> ManoeuvringModel:
    lateral_v = {"ur": -0.45, "uv": -0.53, "|v|v": 0.0, "|v|r": 0.0, "u^2*delta": 0.014, "1": 0.0}
    lateral_r = {"ur": -1.17, "uv": -0.67, "|v|v": 0.0, "|v|r": 0.0, "u^2*delta": -0.15,
                 "1": 0.0}  # fmt: skip
    surge = {"|u|u": -A, "vr": 0.0, "r^2": 0.0, "delta^2": 0.0, "|n|n": C, "1": -drag}
    return ManoeuvringModel(get_structure("blanke-rps"),
                            {"u": surge, "v": lateral_v, "r": lateral_r})  # fmt: skip


def _log(n: float, u: float) -> pd.DataFrame:
    t = np.arange(600) * 0.1
    return pd.DataFrame({"t": t, "delta": np.zeros_like(t), "u": np.full_like(t, u),
                         "v": np.zeros_like(t), "r": np.zeros_like(t), "n": np.full_like(t, n)})


@pytest.mark.parametrize(("drag", "warned"), [(0.05, True), (0.0, False)])
def test_a_model_without_a_steady_speed_below_the_logs_rps_is_named(drag, warned):
    model = _model(drag)
    speed = math.sqrt((C * 100 - drag) / A)  # its steady straight speed at 10 rps
    logs = [_log(10.0, speed)]
    report = plausibility_at_approach(model, speed, 10.0)[0]
    assert report["approach_speed"] == pytest.approx(speed, rel=1e-3)
    found = below_the_logs_rps(model, report, logs)
    if warned:
        assert found is not None and found.startswith(
            "below the logs' propeller speeds the model extrapolates: at 6 rps (0.6 of the "
            "lowest, 10) it has no steady straight speed")  # fmt: skip
    else:
        assert found is None


def test_logs_whose_rps_varies_are_not_checked():
    """Random runs cover low rps themselves: nothing is extrapolated below them."""
    model = _model(0.05)
    speed = math.sqrt((C * 100 - 0.05) / A)
    log = _log(10.0, speed)
    log["n"] = np.linspace(2.0, 10.0, len(log))
    report = plausibility_at_approach(model, speed, 10.0)[0]
    assert below_the_logs_rps(model, report, [log]) is None

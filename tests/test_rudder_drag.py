"""The surge's rudder drag from the particulars, and identify's and select's warning where a
fit's drag pushes the ship ahead (issue #10: a zig-zag at one rps holds δ² one with the thrust)."""

import importlib
import math
import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from shipid.data.particulars import Particulars
from shipid.dynamics.model import ManoeuvringModel, ModelStructure
from shipid.identification.beyond_the_logs import rudder_drag_ahead
from shipid.identification.priors import rudder_drag
from shipid.reporting.modelfile import load_model

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
ESSO = Particulars(length=3.0, beam=0.489, draught=0.201, block_coefficient=0.83, mass=244.6,
                   rudder_area=0.0106, propeller_diameter=0.084, xg=0.094, rho=1000.0)


def _closed_form(p: Particulars, u: float, n: float) -> float:
    """−(1 − t_R) ½ρ A_R f_α U_R² / m written out: Taylor's wake 0.5 C_b − 0.05, the race of
    the momentum theory at the bollard point η κ² 8 K_T0/π D² (η 0.7, κ 0.5, K_T0 0.3), Fujii's
    f_α at aspect ratio 1.5, t_R 0.3."""
    wake = 0.5 * p.block_coefficient - 0.05
    race = 0.7 * 0.25 * 8 * 0.3 / math.pi * p.propeller_diameter**2
    f_alpha = 6.13 * 1.5 / (1.5 + 2.25)
    return -0.7 * 0.5 * p.rho * p.rudder_area * f_alpha * ((1 - wake) ** 2 * u**2
                                                           + race * n**2) / p.mass


def test_the_rudder_drag_is_its_closed_form_and_the_kvlcc2_mmg_models():
    assert rudder_drag(ESSO, 0.25, 15.0) == pytest.approx(_closed_form(ESSO, 0.25, 15.0), rel=1e-12)
    assert rudder_drag(ESSO, 0.25, None) == pytest.approx(_closed_form(ESSO, 0.25, 0.0), rel=1e-12)
    # The MMG model of the KVLCC2 has its own t_R, f_α and inflow from K_T(J): its surge's drag
    # per δ² at its approach, by a central difference in δ, is the generic one's within 10 %.
    mmg = importlib.import_module("shipid.vessels.kvlcc2")
    u0, n0, d = mmg.APPROACH_SPEED, mmg.trimmed_revolutions(), math.radians(1.0)
    dynamics = mmg.KVLCC2Dynamics(n0)
    surge = [dynamics.derivatives([[u0, 0.0, 0.0]], [x])[0, 0] for x in (-d, 0.0, d)]
    per_delta2 = (surge[0] + surge[2] - 2 * surge[1]) / (2 * d**2)
    kvlcc2 = Particulars(length=mmg.L, beam=mmg.B, draught=mmg.D_DRAUGHT, block_coefficient=0.81,
                         mass=dynamics.packed.m, rudder_area=mmg.AR, propeller_diameter=mmg.DP,
                         rudder_height=mmg.HR, rho=mmg.RHO)  # fmt: skip
    assert rudder_drag(kvlcc2, u0, n0) == pytest.approx(per_delta2, rel=0.10)
    no_rudder = Particulars(length=3.0, beam=0.489, draught=0.201, block_coefficient=0.83,
                            mass=244.6, propeller_diameter=0.084)  # fmt: skip
    assert rudder_drag(no_rudder, 0.25, 15.0) is None


def _model(surge: dict) -> ManoeuvringModel:
    return ManoeuvringModel(ModelStructure("t", {"u": tuple(surge), "v": ("u*v",),
                                                 "r": ("u*r", "u^2*delta")}),
                            {"u": surge, "v": {"u*v": -0.5}, "r": {"u*r": -0.5,
                                                                   "u^2*delta": 0.3}})


def test_the_warning_names_a_drag_that_pushes_ahead_and_the_bound_that_holds_it():
    value = _closed_form(ESSO, 0.25, 15.0)
    note = rudder_drag_ahead(_model({"|u|*u": -0.05, "delta^2": 0.03, "1": 0.01}), ESSO, 0.25,
                             15.0, {"delta^2": 0.067})  # fmt: skip
    assert "pushes the ship ahead (delta^2 +0.03 ± 0.067, which these logs do not determine)" \
        in note  # fmt: skip
    assert f"--bound 'u: delta^2 <= {value:.3g}' --bound 'u: delta^2 >= {value:.3g}'" in note
    # In the race's form, per n⁺² at the approach: the bound is the drag over n0².
    note = rudder_drag_ahead(_model({"|u|*u": -0.05, "pos(n)^2*delta^2": 1e-4}), ESSO, 0.25, 15.0)
    assert f"'u: pos(n)^2*delta^2 <= {value / 225:.3g}'" in note and "±" not in note
    # The rudder's normal force (--rudder-normal): its drag's factor U_R² sin α_R sin δ is the
    # particulars' inflow itself, so the bound is −(1 − t_R) ½ρ A_R f_α / m.
    normal = "sin(delta)*rudder_normal(0.403225 0.000943318 0.5 -3)"
    note = rudder_drag_ahead(_model({"|u|*u": -0.05, normal: 0.0475}), ESSO, 0.25, 15.0)
    k = _closed_form(ESSO, 0.25, 15.0) / (0.403225 * 0.25**2 + 0.000943318 * 15.0**2)
    assert f"'u: {normal} <= {k:.3g}'" in note
    # Two forms whose sum pushes ahead: each held to a drag by the sign table.
    two = _model({"|u|*u": -0.05, "u^2*delta^2": 0.5, "pos(n)^2*delta^2": -1e-4})
    assert "--constraints signs" in rudder_drag_ahead(two, ESSO, 0.25, 15.0)


def test_a_drag_that_pushes_ahead_by_a_trifle_is_left_unsaid():
    """Against the particulars' drag: a tenth of it is the line (``DRAG_AHEAD_SHARE``)."""
    value = _closed_form(ESSO, 0.25, 15.0)
    for share, said in ((0.05, False), (0.2, True)):
        model = _model({"|u|*u": -0.05, "delta^2": -share * value})
        assert (rudder_drag_ahead(model, ESSO, 0.25, 15.0) is not None) is said


@pytest.mark.parametrize("surge, particulars, speed", [
    ({"|u|*u": -0.05, "delta^2": -0.03}, ESSO, 0.25),  # a drag
    ({"|u|*u": -0.05, "u^2*delta^2": 0.5, "pos(n)^2*delta^2": -1e-3}, ESSO, 0.25),  # summed, one
    ({"|u|*u": -0.05}, ESSO, 0.25),  # no rudder drag term
    ({"|u|*u": -0.05, "delta^2": 0.03}, None, 0.25),  # no particulars
    ({"|u|*u": -0.05, "delta^2": 0.03}, Particulars(length=3.0, mass=244.6), 0.25),  # too few
    ({"|u|*u": -0.05, "delta^2": 0.03}, ESSO, None),  # no approach speed
])
def test_no_warning_where_the_drag_is_one_or_cannot_be_told(surge, particulars, speed):
    assert rudder_drag_ahead(_model(surge), particulars, speed, 15.0) is None


@pytest.mark.skipif(not (DATA / "esso-osaka").is_dir(), reason="../shared/data is not present")
def test_identify_warns_of_the_esso_zigzag_whose_rudder_drag_pushes_ahead(tmp_path, capsys):
    """The 20°/20° zig-zag at 15 rps alone: its fit has δ² > 0 within its standard error. The
    bound the warning names is taken as given, and the warning is gone."""
    log = DATA / "esso-osaka" / "zigzag" / "zigzag_31-Jul-2020_13_57_45.csv"
    out = tmp_path / "m.json"
    code, _, err = run(["identify", "--format", "osaka-frt", "--dt", "0.5", log, "-o", out],
                       capsys)  # fmt: skip
    assert code == 0
    bound = re.search(r"--bound '(u: delta\^2 <= (\S+))' --bound '(u: delta\^2 >= \S+)'", err)
    assert bound and "surge: the rudder's drag pushes the ship ahead (delta^2 +" in err
    value = float(bound.group(2))
    assert value == pytest.approx(-0.0088, rel=0.03)
    code, _, err = run(["identify", "--format", "osaka-frt", "--dt", "0.5", log, "--bound",
                        bound.group(1), "--bound", bound.group(3), "-o", out], capsys)
    assert code == 0 and "the rudder's drag pushes" not in err
    surge = load_model(out).coefficients["u"]
    # Written to scale with the propeller (δ² → pos(n)² δ² at the logs' 15 rps).
    assert surge["pos(n)^2*delta^2"] * 15.0**2 == pytest.approx(value, rel=1e-9)
    assert np.isfinite(value)


def test_select_gives_the_warning_of_the_model_it_writes(tmp_path, capsys, monkeypatch):
    """``select`` checks the model it writes as ``identify`` does: the same function, given the
    selection's model (the fit's terms, before the file carries them anywhere), the logs'
    particulars and their approach. Its text here is a stand-in (the paper's small zig-zags
    fit a drag that is one)."""
    from generated_logs import noisy_zigzags

    import shipid.identification.beyond_the_logs as beyond_the_logs
    from shipid.data.io import write_log

    seen = []

    def spy(model, particulars, speed, rps, std_errors=None):
        seen.append((model, particulars, speed, rps))
        return "surge: (a stand-in for the rudder drag's warning)"

    monkeypatch.setattr(beyond_the_logs, "rudder_drag_ahead", spy)
    logs = noisy_zigzags(seed=3)[:2]
    for log in logs:
        log.attrs["particulars"] = ESSO.to_dict()
    paths = [write_log(log, tmp_path / f"zz{i}.csv") for i, log in enumerate(logs)]
    code, _, err = run(["select", "--quiet", *paths, "-o", tmp_path / "m.json"], capsys)
    assert code == 0, err
    assert "warning: surge: (a stand-in for the rudder drag's warning)" in err
    ((model, particulars, speed, rps),) = seen
    assert particulars == ESSO and rps is None
    assert speed == pytest.approx(float(logs[0]["u"].iloc[0]), rel=0.05)
    # The file writes it in its ahead forms (u·v → |u|·v, ...): the terms both hold agree.
    written = load_model(tmp_path / "m.json").coefficients
    shared = [(d, t) for d, terms in model.coefficients.items() for t in terms
              if t in written.get(d, {})]  # fmt: skip
    assert ("u", "|u|*u") in shared
    for d, t in shared:
        assert model.coefficients[d][t] == pytest.approx(written[d][t], rel=1e-12), (d, t)

"""The hull's cross-flow drag as a term (``crossflow_sway(L)``, ``crossflow_yaw(L)``): its closed
form against numerical quadrature of the integrals it stands for, the compiled kernel against
the vectorised path, identification of a truth that has it, its scaling with the hull (prime
form, Froude), the structure edit ``--crossflow`` and its errors."""

import json
import math

import numpy as np
import pytest
from cli_helpers import run

from shipid.data.io import write_log
from shipid.dynamics import kernel
from shipid.dynamics.model import ManoeuvringModel, ModelStructure, StructureEdit, get_structure
from shipid.dynamics.prime import froude_scaled, prime_coefficients
from shipid.dynamics.terms import (
    CROSSFLOW_SLOTS,
    OP_CODE,
    crossflow,
    parse_term,
    term_code,
    term_matrix,
)
from shipid.errors import ShipidError
from shipid.identification.identify import identify
from shipid.identification.physics import PhysicsOptions, coefficient_bounds
from shipid.trials.manoeuvres import turning_circle, zigzag

L = 4.0
# Drift alone, yaw alone, the flow keeping its sign along the hull and changing it, both signs.
STATES = [(0.3, 0.0), (0.0, 0.05), (0.2, 0.02), (-0.2, 0.02), (0.05, 0.1), (-0.05, -0.1),
          (0.01, -0.3), (0.0, 0.0), (1e-12, 1e-9), (1e-120, 1e-100)]  # fmt: skip


def _by_quadrature(v: float, r: float, length: float) -> tuple[float, float]:
    from scipy.integrate import quad  # here: 0.2 s of every worker's collection at the top

    h = length / 2
    kink = [] if r == 0 or abs(v / r) >= h else [-v / r]  # where w = v + x r changes sign
    sway = quad(lambda x: abs(v + x * r) * (v + x * r), -h, h, points=kink or None)[0]
    yaw = quad(lambda x: x * abs(v + x * r) * (v + x * r), -h, h, points=kink or None)[0]
    return sway / length, yaw / length**2


@pytest.mark.parametrize(("v", "r"), STATES)
def test_the_closed_form_is_the_integral(v, r):
    want = _by_quadrature(v, r, L)
    sway, yaw = crossflow(np.array([v]), np.array([r]), L)
    assert sway[0] == pytest.approx(want[0], rel=1e-9, abs=1e-15)
    assert yaw[0] == pytest.approx(want[1], rel=1e-9, abs=1e-15)
    # The compiled kernel's own copy, one state at a time.
    assert kernel.crossflow(v, r, L) == pytest.approx((sway[0], yaw[0]), rel=1e-12, abs=1e-18)


@pytest.mark.parametrize(("v", "r"), [(0.0, 1e-200), (-1e-300, 1e-170), (1e-160, -1e-155)])
def test_a_vanishing_flow_gives_no_drag_not_a_division_by_zero(v, r):
    # Bug: 1/r² of the sign-changing form underflowed to 0/0 (NaN in NumPy, ZeroDivisionError
    # in the compiled kernel, which stopped the run).
    sway, yaw = crossflow(np.array([v]), np.array([r]), L)
    assert (sway[0], yaw[0]) == pytest.approx((0.0, 0.0), abs=1e-200)
    assert kernel.crossflow(v, r, L) == pytest.approx((0.0, 0.0), abs=1e-200)


def test_it_is_the_drag_blanke_splits_where_the_flow_keeps_its_sign():
    # |v| ≥ |r| L/2: |w|w = sign(v) w², so the sway factor is |v|v + sign(v) r² L²/12 and the
    # yaw factor |v| r L/6: the |v|v and |v|r of Blanke's hull, in a ratio the length sets.
    v, r = np.array([0.3, -0.3]), np.array([0.05, 0.05])
    sway, yaw = crossflow(v, r, L)
    np.testing.assert_allclose(sway, np.abs(v) * v + np.sign(v) * r**2 * L**2 / 12, rtol=1e-12)
    np.testing.assert_allclose(yaw, np.abs(v) * r * L / 6, rtol=1e-12)


def test_the_terms_parse_display_and_scale_as_a_speed_squared():
    term = parse_term("crossflow_sway(4.0)")
    assert term.text == "crossflow_sway(4)" and term.crossflow
    assert term.signals == ("v", "r") and term.degree_in("v") == 2 and term.degree_in("r") == 0
    assert parse_term("u * crossflow_yaw(7.5)").display() == "u N_cf(v, r; 7.5 m)"
    # The compiled kernel reads them from the signal buffer's slots it fills once per state.
    code = term_code(["crossflow_sway(4)", "u*crossflow_yaw(4)"])
    assert code.signal.tolist() == [CROSSFLOW_SLOTS[0], 0, CROSSFLOW_SLOTS[1]]
    assert code.op.tolist() == [OP_CODE["pow"]] * 3 and code.k.tolist() == [4.0, 1.0, 4.0]
    assert (kernel.SWAY_SLOT, kernel.YAW_SLOT) == CROSSFLOW_SLOTS
    with pytest.raises(ShipidError, match="one hull length, got 3, 4 m"):
        term_code(["crossflow_sway(3)", "crossflow_yaw(4)"])
    np.testing.assert_allclose(
        term_matrix(["crossflow_sway(4)", "crossflow_yaw(4)"], [1.0], [0.2], [0.02])[0],
        [c[0] for c in crossflow(np.array([0.2]), np.array([0.02]), 4.0)])


@pytest.mark.parametrize(("text", "message"), [
    ("crossflow_sway", r"expected \(, got the end"),
    ("crossflow_sway()", r"takes the hull's length L in metres, e.g. crossflow_sway\(3\)"),
    ("crossflow_yaw(0)", "hull length must be > 0 m, got 0"),
    ("crossflow_sway(3)^2", "takes no power"),
    ("crossflow_sway(3)*crossflow_sway(3)", "appears twice"),
    ("u^1.5", "expected a whole number, got '1.5'"),
])  # fmt: skip
def test_bad_cross_flow_terms_are_named(text, message):
    with pytest.raises(ShipidError, match=message):
        parse_term(text)


def _truth() -> ManoeuvringModel:
    # The paper's scale ship with its hull's |v|v, |v|r replaced by cross-flow drag.
    return ManoeuvringModel(
        f"u: |u|u, v*r, delta^2, 1; v: u*r, u*v, crossflow_sway({L:g}), delta, 1; "
        f"r: u*r, u*v, crossflow_yaw({L:g}), delta, 1",
        {"u": {"|u|u": -0.0321, "v*r": -2.7053, "delta^2": -0.2257, "1": 0.12},
         "v": {"u*r": -0.4531, "u*v": -0.5284, f"crossflow_sway({L:g})": -0.8, "delta": 0.052,
               "1": 0.0},
         "r": {"u*r": -1.1699, "u*v": -0.6696, f"crossflow_yaw({L:g})": -1.5, "delta": -0.5503,
               "1": 0.0}})  # fmt: skip


def test_compiled_accelerations_are_the_terms():
    model = _truth()
    rng = np.random.default_rng(0)
    states = np.column_stack([rng.uniform(1, 2, 50), rng.normal(0, 0.2, 50),
                              rng.normal(0, 0.1, 50)])  # fmt: skip
    delta = rng.normal(0, 0.3, 50)
    want = np.column_stack([
        term_matrix(model.structure.terms[d], *states.T, {"delta": delta})
        @ np.array([model.coefficients[d][t] for t in model.structure.terms[d]])
        for d in "uvr"])  # fmt: skip
    inputs = np.zeros((50, 5))
    inputs[:, 0] = delta
    np.testing.assert_allclose(model.compiled_accelerations(states, inputs), want, rtol=1e-12,
                               atol=1e-15)  # fmt: skip


def test_identify_recovers_a_cross_flow_truth():
    truth = _truth()
    log = zigzag(truth, 20, 20, duration=120, dt=0.2, method="euler", speed=1.9).log
    fit = identify([log], model=truth.structure, gamma=1e10).model
    for d in "vr":
        for t, c in truth.coefficients[d].items():
            assert fit.coefficients[d][t] == pytest.approx(c, rel=1e-4, abs=1e-6), (d, t)


def test_a_froude_scaled_cross_flow_model_turns_the_similar_circle():
    truth, factor = _truth(), 10.0
    big = froude_scaled(truth, factor)
    assert f"crossflow_sway({L * factor:g})" in big.structure.terms["v"]
    small = turning_circle(truth, 20, duration=120, dt=0.1, speed=1.9)
    large = turning_circle(big, 20, duration=120 * math.sqrt(factor), dt=0.1 * math.sqrt(factor),
                           speed=1.9 * math.sqrt(factor))  # fmt: skip
    for key in ("advance", "tactical_diameter"):
        assert large.indices[key] == pytest.approx(factor * small.indices[key], rel=1e-9)
    # Equal prime coefficients: the cross-flow terms' among them.
    a = prime_coefficients(truth, L, 1.9)
    b = prime_coefficients(big, L * factor, 1.9 * math.sqrt(factor))
    assert b["v"][f"crossflow_sway({L * factor:g})"] == pytest.approx(
        a["v"][f"crossflow_sway({L:g})"], rel=1e-12)


def test_the_structure_edit_replaces_the_hulls_nonlinear_damping():
    edited = get_structure("blanke-race+race-damping").with_crossflow_hull(7.0)
    assert edited.terms["v"][:3] == ("u*r", "u*v", "crossflow_sway(7)")
    assert edited.terms["r"][:3] == ("u*r", "u*v", "crossflow_yaw(7)")
    assert not {"|v|*v", "|v|*r"} & set(edited.all_terms)
    assert edited.terms["u"] == get_structure("blanke").terms["u"]
    # Four terms of the low-speed library become one per equation; a structure without them,
    # and one already edited, are left as they are.
    low = get_structure("low-speed").with_crossflow_hull(3.0)
    assert sum(parse_term(t).crossflow for t in low.terms["v"]) == 1
    assert not {"|v|*v", "|v|*r", "|r|*r", "v*|r|"} & set(low.all_terms)
    linear = get_structure("linear-sway-yaw")
    assert linear.with_crossflow_hull(3.0) is linear
    assert edited.with_crossflow_hull(7.0) is edited
    both = StructureEdit({"u": ["r^2"]}, 7.0).apply(get_structure("blanke"))
    assert "r^2" not in both.terms["u"] and "crossflow_yaw(7)" in both.terms["r"]


def test_sign_constraints_hold_the_drag_against_the_motion():
    model = ManoeuvringModel(ModelStructure("cf", {"v": ("crossflow_sway(3)", "u*v"),
                                                   "r": ("crossflow_yaw(3)", "u*r")}),
                             {"v": {"crossflow_sway(3)": 0.1, "u*v": 0.1},
                              "r": {"crossflow_yaw(3)": 0.1, "u*r": 0.1}})  # fmt: skip
    bounds, reasons, _ = coefficient_bounds(PhysicsOptions(signs=True), model, [])
    assert bounds["v"]["crossflow_sway(3)"] == bounds["r"]["crossflow_yaw(3)"] == (-math.inf, 0.0)
    assert reasons["v"]["crossflow_sway(3)"] == "cross-flow drag opposes the hull's lateral motion"


def test_cli_crossflow_needs_the_length_and_fits_it(tmp_path, capsys):
    log = zigzag(_truth(), 20, 20, duration=90, dt=0.2, method="euler", speed=1.9).log
    path = write_log(log.drop(columns=["x", "y"]), tmp_path / "zz.csv")
    flags = ["--filter", "none", "--no-output-error", "--model", "blanke"]
    code, _, err = run(["identify", path, *flags, "--crossflow", "-o", tmp_path / "m.json"],
                       capsys)  # fmt: skip
    assert code == 1 and "--crossflow needs the hull's length: give --particulars FILE" in err
    assert not (tmp_path / "m.json").exists()
    particulars = tmp_path / "ship.json"
    particulars.write_text(json.dumps({"length": L}))
    code, out, err = run(["identify", path, *flags, "--crossflow", "--particulars", particulars,
                          "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    doc = json.loads((tmp_path / "m.json").read_text())
    assert doc["model"]["structure"]["terms"]["v"][2] == f"crossflow_sway({L:g})"
    assert "Y_cf(v, r; 4 m)" in out
    # A structure without the hull's nonlinear damping is fitted as it is, and said so.
    code, _, err = run(["identify", path, "--filter", "none", "--no-output-error", "--model",
                        "linear-sway-yaw", "--crossflow", "--particulars", particulars,
                        "-o", tmp_path / "lin.json"], capsys)  # fmt: skip
    assert code == 0 and "--crossflow: linear-sway-yaw has none of the hull's nonlinear" in err

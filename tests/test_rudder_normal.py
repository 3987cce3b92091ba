"""The rudder's normal force as a term (``rudder_normal(a c g x)``): its value against the MMG
formulas written out by hand, the compiled kernels (interpreted, generated) against the
vectorised path, identification of a truth that has it, its scaling (prime form, Froude), the
inflow from the particulars, the structure edit ``--rudder-normal``, the sign table, the
exported module and the errors."""

import importlib.util
import json
import math

import numpy as np
import pytest
from cli_helpers import run

from shipid.control.export import export_numpy
from shipid.data.io import write_log
from shipid.data.particulars import Particulars
from shipid.dynamics import codegen
from shipid.dynamics.model import ManoeuvringModel, StructureEdit, get_structure
from shipid.dynamics.prime import froude_scaled, prime_coefficients
from shipid.dynamics.rudder import RudderInflow
from shipid.dynamics.terms import RUDDER_SLOT, parse_term, term_code, term_matrix
from shipid.errors import ShipidError
from shipid.identification.identify import identify
from shipid.identification.physics import PhysicsOptions, coefficient_bounds
from shipid.trials.manoeuvres import turning_circle, zigzag

INFLOW = RudderInflow(0.42, 0.006, 0.5, -4.0)
F = INFLOW.factor
RPS = 10.0


def _by_hand(u, v, r, delta, n, a, c, g, x) -> float:
    """MMG's F_N / (½ρA_R f_α) with the quadratic race, written out: U_R² sin α_R."""
    u_r = math.sqrt(a * u**2 + c * max(n, 0.0) ** 2)
    v_r = -g * (v + x * r)
    return (u_r**2 + v_r**2) * math.sin(delta - math.atan(v_r / u_r))


STATES = [(1.0, 0.1, 0.01, 0.3, 10.0), (0.5, -0.2, 0.05, -0.35, 12.0), (1.2, 0.0, 0.0, 0.2, 0.0),
          (0.3, 0.05, -0.04, 0.6, -5.0), (0.0, 0.0, 0.0, 0.1, 8.0)]  # fmt: skip


@pytest.mark.parametrize("state", STATES)
def test_the_factor_is_the_mmg_rudder_force_by_hand(state):
    got = term_matrix([F], *(np.array([s]) for s in state[:3]),
                      {"delta": [state[3]], "n": [state[4]]})[0, 0]  # fmt: skip
    assert got == pytest.approx(_by_hand(*state, INFLOW.a, INFLOW.c, INFLOW.g, INFLOW.x),
                                rel=1e-13, abs=1e-15)  # fmt: skip


def test_the_flow_straightening_reduces_the_angle_of_attack_and_mirrors():
    # Straight running: U_R² sin δ with the race's share; a drift to port (v < 0, the stern's
    # flow from starboard) takes angle off a starboard rudder, and the mirror image is the mirror.
    u, d, n = 1.0, 0.3, 10.0
    straight = term_matrix([F], [u], [0.0], [0.0], {"delta": [d], "n": [n]})[0, 0]
    assert straight == pytest.approx((INFLOW.a * u * u + INFLOW.c * n * n) * math.sin(d))
    turning = term_matrix([F], [u], [-0.2], [0.05], {"delta": [d], "n": [n]})[0, 0]
    assert 0 < turning < straight
    mirrored = term_matrix([F], [u], [0.2], [-0.05], {"delta": [-d], "n": [n]})[0, 0]
    assert mirrored == pytest.approx(-turning, rel=1e-14)
    # The port convention's factor (g < 0) is the starboard one's of the mirrored rudder.
    port = RudderInflow(INFLOW.a, INFLOW.c, -INFLOW.g, INFLOW.x).factor
    assert term_matrix([port], [u], [-0.2], [0.05], {"delta": [-d], "n": [n]})[0, 0] \
        == pytest.approx(-turning, rel=1e-14)


def test_the_term_parses_displays_and_scales_as_a_speed_squared():
    term = parse_term(f"{F}*cos(delta)")
    assert term.text == "cos(delta)*rudder_normal(0.42 0.006 0.5 -4)"
    assert parse_term(term.text) == term
    assert term.signals == ("u", "v", "r", "delta", "n") and term.inputs == ("n",)
    assert term.degree_in("u") == 2 and term.degree_in("delta") == 0
    assert term.display() == "cos(δ) F_R(a 0.42, c 0.006 m², γ 0.5, x -4 m)"
    code = term_code([term.text, "u*v"])
    assert list(code.rudder) == [0.42, 0.006, 0.5, -4.0] and RUDDER_SLOT in code.signal
    assert not term_code(["u*v"]).rudder.any()
    # The prime form: a speed squared over U²/L.
    model = _truth()
    prime = prime_coefficients(model, 4.0, 2.0)
    text = parse_term(INFLOW.lateral).text
    assert prime["v"][text] == pytest.approx(model.coefficients["v"][text] * 4.0)


@pytest.mark.parametrize(("text", "message"), [
    ("rudder_normal(0.4 0.01 0.5)", "takes the inflow's four numbers apart by spaces"),
    ("rudder_normal(0.4, 0.01, 0.5, -3)", "takes its numbers apart by spaces"),
    ("rudder_normal(0 0.01 0.5 -3)", "a = (1 − w_R)² must be > 0"),
    ("rudder_normal(0.4 -0.01 0.5 -3)", "race share c must be ≥ 0 m²"),
    ("rudder_normal(0.4 0.01 0.5 -3)^2", "takes no power"),
    ("rudder_normal(0.4 0.01 0.5 -3)*rudder_normal(0.4 0.01 0.5 -3)", "appears twice"),
])  # fmt: skip
def test_bad_rudder_terms_are_named(text, message):
    with pytest.raises(ShipidError) as err:
        parse_term(text)
    assert message in str(err.value) and text in str(err.value)


@pytest.mark.parametrize(("params", "message"), [
    ((0.0, 0.01, 0.5, -3.0), "rudder inflow: a = (1 − w_R)² must be > 0, got 0"),
    ((0.4, -0.01, 0.5, -3.0), "rudder inflow: race share c must be ≥ 0 m², got -0.01"),
    ((0.4, 0.01, math.nan, -3.0), "rudder inflow: g must be a finite number, got nan"),
])  # fmt: skip
def test_a_bad_inflow_is_named(params, message):
    with pytest.raises(ShipidError) as err:
        RudderInflow(*params)
    assert str(err.value) == message


def test_one_model_takes_one_inflow():
    with pytest.raises(ShipidError, match="the rudder terms of one model take one inflow"):
        term_code([F, RudderInflow(0.5, 0.006, 0.5, -4.0).factor])


def _truth() -> ManoeuvringModel:
    """A ship whose rudder force is the normal force of INFLOW (coefficients of the paper's
    scale ship's order, the rudder's a tenth of its δ per U_R²; without the terms a zig-zag
    cannot tell apart from the others, r² from v r and |v| r from |v| v, ρ ≈ −0.999)."""
    surge, lateral = parse_term(INFLOW.surge).text, parse_term(INFLOW.lateral).text
    structure = get_structure("blanke").without({"u": ["r^2"], "v": ["|v|*r"], "r": ["|v|*r"]})
    structure = structure.with_rudder_normal(INFLOW)
    assert structure.terms["u"][2] == surge and structure.terms["v"][3] == lateral
    return ManoeuvringModel(structure, {
        "u": {"|u|*u": -0.0565, "v*r": 0.9, surge: -0.02, "1": 0.23},
        "v": {"u*r": -0.5, "u*v": -1.2, "|v|*v": -1.0, lateral: -0.015, "1": 0.0},
        "r": {"u*r": -1.17, "u*v": -0.67, "|v|*v": -0.3, lateral: 0.05, "1": 0.0}})  # fmt: skip


def test_compiled_accelerations_are_the_terms():
    model = _truth()
    rng = np.random.default_rng(0)
    states = np.column_stack([rng.uniform(0.3, 2, 50), rng.normal(0, 0.2, 50),
                              rng.normal(0, 0.1, 50)])  # fmt: skip
    inputs = np.zeros((50, 5))
    inputs[:, 0] = rng.normal(0, 0.3, 50)
    inputs[:, 1] = rng.uniform(-5, 15, 50)
    want = model.accelerations(*states.T, inputs[:, 0], rps=inputs[:, 1])
    np.testing.assert_allclose(model.compiled_accelerations(states, inputs), want, rtol=1e-12,
                               atol=1e-15)  # fmt: skip


def test_the_generated_kernel_is_the_interpreter():
    model = _truth()
    runs = {}
    for engine in ("interpreted", "generated"):
        with codegen.use(engine):
            runs[engine] = turning_circle(model, 30, duration=60, dt=0.1, speed=1.5, rps=RPS).log
    np.testing.assert_allclose(runs["generated"][["u", "v", "r", "psi"]].to_numpy(),
                               runs["interpreted"][["u", "v", "r", "psi"]].to_numpy(),
                               rtol=1e-12, atol=1e-14)  # fmt: skip


def test_identify_recovers_a_rudder_normal_truth():
    truth = _truth()
    logs = [zigzag(truth, a, 20, side, duration=120, dt=0.2, method="euler", speed=1.5,
                   rps=RPS).log for a, side in ((20, "starboard"), (10, "port"))]  # fmt: skip
    fit = identify(logs, model=truth.structure, gamma=1e13).model
    for d in "uvr":
        for t, c in truth.coefficients[d].items():
            assert fit.coefficients[d][t] == pytest.approx(c, rel=1e-4, abs=1e-6), (d, t)


def test_a_froude_scaled_model_turns_the_similar_circle():
    truth, factor = _truth(), 10.0
    big = froude_scaled(truth, factor)
    longer = parse_term(RudderInflow(INFLOW.a, INFLOW.c * factor**2, INFLOW.g,
                                     INFLOW.x * factor).lateral).text  # fmt: skip
    assert longer in big.structure.terms["v"] and longer in big.coefficients["r"]
    k = math.sqrt(factor)
    small = turning_circle(truth, 35, duration=200, dt=0.1, speed=1.5, rps=RPS)
    large = turning_circle(big, 35, duration=200 * k, dt=0.1 * k, speed=1.5 * k, rps=RPS / k)
    for key in ("advance", "tactical_diameter"):
        assert large.indices[key] == pytest.approx(factor * small.indices[key], rel=1e-9)


def test_the_inflow_from_the_particulars():
    kvlcc2 = Particulars(length=7.0, beam=1.27, draught=0.46, block_coefficient=0.81,
                         propeller_diameter=0.204, rudder_height=0.345)  # fmt: skip
    inflow = RudderInflow.from_particulars(kvlcc2, "port")
    w = 0.5 * 0.81 - 0.05
    eta = 0.204 / 0.345
    assert inflow.a == pytest.approx((1 - w) ** 2)
    assert inflow.c == pytest.approx(eta * 0.25 * 8 * 0.3 / math.pi * 0.204**2)
    assert (inflow.g, inflow.x) == (-0.5, -7.0)
    # No rudder height: η 0.7; starboard convention: g > 0.
    plain = RudderInflow.from_particulars(Particulars(length=3.0, block_coefficient=0.83,
                                                     propeller_diameter=0.084), "starboard")
    assert plain.c == pytest.approx(0.7 * 0.25 * 8 * 0.3 / math.pi * 0.084**2) and plain.g == 0.5
    with pytest.raises(ShipidError, match="needs the particulars' propeller_diameter and "
                                          "block_coefficient"):
        RudderInflow.from_particulars(Particulars(length=3.0), "port")
    with pytest.raises(ShipidError, match="rudder convention"):
        RudderInflow.from_particulars(kvlcc2, "up")
    with pytest.raises(ShipidError, match="rudder_height must be > 0"):
        Particulars(length=3.0, rudder_height=-1.0)


def test_the_structure_edit_replaces_the_rudder_force_terms():
    race = get_structure("blanke-race+race-damping").with_rudder_normal(INFLOW)
    surge, lateral = parse_term(INFLOW.surge).text, parse_term(INFLOW.lateral).text
    assert race.terms["u"] == ("|u|*u", "v*r", "r^2", surge, "1")
    assert race.terms["v"] == ("u*r", "u*v", "|v|*v", "|v|*r", lateral, "1", "v", "r")
    # The astern propeller's race and the rudder's asymmetry are not the normal force's.
    low = get_structure("low-speed+propeller-asymmetry").with_rudder_normal(INFLOW)
    assert {"neg(n)^2*delta", "pos(n)^2*|delta|", "pos(n)^2*delta"} <= set(low.all_terms)
    assert not {"u*|u|*delta", "pos(n)^2*delta^2", "delta^2"} & set(low.all_terms)
    assert not {"pos(n)^2*delta"} & set(low.terms["v"])
    nomoto = get_structure("nomoto1")
    assert nomoto.with_rudder_normal(INFLOW).terms["r"] == ("r", lateral, "1")
    wind = get_structure("wind")
    assert wind.with_rudder_normal(INFLOW) is wind
    both = StructureEdit({"u": ["r^2"]}, 7.0, rudder=INFLOW).apply(get_structure("blanke"))
    assert "r^2" not in both.terms["u"] and "crossflow_yaw(7)" in both.terms["r"]
    assert lateral in both.terms["r"]


@pytest.mark.parametrize(("side", "s"), [("starboard", 1.0), ("port", -1.0)])
def test_sign_constraints_hold_the_rudders_drag_and_turn(side, s):
    model = _truth()
    surge, lateral = parse_term(INFLOW.surge).text, parse_term(INFLOW.lateral).text
    bounds, reasons, _ = coefficient_bounds(PhysicsOptions(signs=True, rudder_positive=side),
                                            model, [])  # fmt: skip
    assert bounds["u"][surge] == (-math.inf, 0.0) and reasons["u"][surge] == "rudder drag"
    turn, push = (0.0, math.inf), (-math.inf, 0.0)
    assert bounds["r"][lateral] == (turn if s > 0 else push)
    assert bounds["v"][lateral] == (push if s > 0 else turn)


def test_the_exported_module_is_the_model(tmp_path):
    model = _truth()
    path = export_numpy(model, tmp_path / "ship.py", "starboard", 0.2)
    spec = importlib.util.spec_from_file_location("ship", path)
    ship = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(ship)
    u, v, r, d, n = (np.array(x) for x in ([1.0, 0.4], [0.1, -0.2], [0.02, 0.05], [0.3, -0.5],
                                            [10.0, 4.0]))  # fmt: skip
    np.testing.assert_allclose(np.column_stack(ship.accelerations(u, v, r, d, n=n)),
                               model.accelerations(u, v, r, d, rps=n), rtol=1e-13)  # fmt: skip


def test_cli_rudder_normal_needs_particulars_and_fits_it(tmp_path, capsys):
    log = zigzag(_truth(), 20, 20, duration=90, dt=0.2, method="euler", speed=1.5, rps=RPS).log
    path = write_log(log.drop(columns=["x", "y"]), tmp_path / "zz.csv")
    flags = ["--filter", "none", "--no-output-error", "--model", "blanke"]
    code, _, err = run(["identify", path, *flags, "--rudder-normal", "-o", tmp_path / "m.json"],
                       capsys)  # fmt: skip
    assert code == 1 and "--rudder-normal needs the ship's particulars" in err
    assert not (tmp_path / "m.json").exists()
    particulars = tmp_path / "ship.json"
    particulars.write_text(json.dumps({"length": 4.0, "block_coefficient": 0.7,
                                       "propeller_diameter": 0.1}))  # fmt: skip
    code, out, err = run(["identify", path, *flags, "--rudder-normal", "--particulars",
                          particulars, "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    doc = json.loads((tmp_path / "m.json").read_text())
    inflow = RudderInflow.from_particulars(Particulars(length=4.0, block_coefficient=0.7,
                                                       propeller_diameter=0.1), "starboard")
    assert parse_term(inflow.lateral).text in doc["model"]["structure"]["terms"]["v"]
    assert "F_R(a 0.49, c 0.001337 m², γ 0.5, x -4 m)" in out
    code, out, err = run(["manoeuvre", tmp_path / "m.json", "turning", "--rudder", "35",
                          "--duration", "200"], capsys)  # fmt: skip
    assert code == 0 and "tactical_diameter" in out, err
    # rescale carries the inflow to the larger ship: c with the length squared, x with it.
    code, _, err = run(["rescale", tmp_path / "m.json", "--factor", "10", "-o",
                        tmp_path / "big.json"], capsys)  # fmt: skip
    assert code == 0, err
    big = json.loads((tmp_path / "big.json").read_text())
    longer = RudderInflow(inflow.a, inflow.c * 100, inflow.g, inflow.x * 10)
    assert parse_term(longer.lateral).text in big["model"]["structure"]["terms"]["r"]
    assert big["particulars"]["length"] == pytest.approx(40.0)
    # identify's own choice of structure takes it into whichever it fits.
    code, out, err = run(["identify", path, "--filter", "none", "--no-output-error",
                          "--rudder-normal", "--particulars", particulars, "-o",
                          tmp_path / "auto.json"], capsys)  # fmt: skip
    assert code == 0, err
    auto = json.loads((tmp_path / "auto.json").read_text())["model"]["structure"]
    assert "+rudder-normal" in auto["name"] and parse_term(inflow.lateral).text in auto[
        "terms"]["v"]
    # Logs without the propeller speed: the race needs it.
    bare = write_log(log.drop(columns=["x", "y", "n"]), tmp_path / "bare.csv")
    code, _, err = run(["identify", bare, *flags, "--rudder-normal", "--particulars",
                        particulars, "-o", tmp_path / "b.json"], capsys)  # fmt: skip
    assert code == 1 and "--rudder-normal needs the propeller speed: bare.csv has no column n" in err
    # A structure without rudder force terms is fitted as it is, and said so.
    code, _, err = run(["identify", path, "--filter", "none", "--no-output-error", "--model",
                        "u: |u|u, 1; v: u*v, u*r; r: u*v, u*r", "--rudder-normal",
                        "--particulars", particulars, "-o", tmp_path / "x.json"], capsys)
    assert code == 0 and "--rudder-normal: custom has none of the rudder's force terms" in err


def test_a_hybrid_of_it_runs_compiled_as_its_numpy_derivatives():
    """The hybrid kernel (``hybrid_kernel``) takes the rudder's slot too: a kernel residual on a
    rudder-normal model, its compiled zig-zag against its NumPy derivatives integrated."""
    from shipid.dynamics import kernel
    from shipid.dynamics.hybrid import HybridModel
    from shipid.dynamics.simulate import initial_states
    from shipid.identification.residual import fit_residual
    from shipid.trials.manoeuvres import _generic_closed_loop, as_vessel, manoeuvre_params

    truth = _truth()
    log = zigzag(truth, 20, 20, duration=60, dt=0.2, speed=1.5, rps=RPS).log
    physical = ManoeuvringModel(truth.structure, {d: {t: 0.9 * c for t, c in cs.items()}
                                                  for d, cs in truth.coefficients.items()})
    model = HybridModel(physical, fit_residual(physical, [log], 10.0, 1.0))

    class NumPyPath:  # the derivatives alone, so the simulator takes its generic path
        uses_thrust, uses_rps, inputs = False, True, ("delta", "n")

        def derivatives(self, nu, delta, thrust=None, rps=None):
            return model.derivatives(nu, delta, rps=rps)

    result = zigzag(model, 20, 20, duration=40, dt=0.2, method="rk4", speed=1.5, rps=RPS)
    params = manoeuvre_params(as_vessel(model, speed=1.5, rps=RPS), kernel.MODE_ZIGZAG,
                              np.radians(20), 0.0, 0.0, switch=np.radians(20), side=1.0,
                              rps=RPS)  # fmt: skip
    states, _, m = _generic_closed_loop(NumPyPath(), params, len(result.log), 0.2,
                                        initial_states({"u": 1.5}, 1), "rk4", 1e3, 5.0, RPS)
    assert m == len(result.log)
    np.testing.assert_allclose(result.log[["u", "v", "r", "psi"]].to_numpy(), states[:, :4],
                               rtol=1e-9, atol=1e-11)  # fmt: skip


@pytest.mark.parametrize("side", ["starboard", "port"])
def test_the_clarke_prior_gives_the_rudders_normal_force(side):
    """Its side force takes the u²δ coefficients of the Clarke prior (F ≈ U_R² δ per ½ρA_R f_α),
    its drag −(1 − t_R) ½ρ A_R f_α / m, whichever the rudder convention."""
    from shipid.identification.priors import T_R, clarke_linear, clarke_prior

    p = Particulars(length=7.0, beam=1.27, draught=0.46, block_coefficient=0.81,
                    rudder_area=0.0539, propeller_diameter=0.204, mass=3300.0)  # fmt: skip
    inflow = RudderInflow.from_particulars(p, side)
    structure = get_structure("blanke-race").with_rudder_normal(inflow)
    prior = clarke_prior(p, structure, 1.2, side)
    linear = clarke_linear(p, side)
    lateral, surge = parse_term(inflow.lateral).text, parse_term(inflow.surge).text
    assert prior["v"][lateral] == linear["v"]["delta"] and prior["r"][lateral] == linear["r"]["delta"]
    f_alpha = 6.13 * 1.5 / (1.5 + 2.25)
    assert prior["u"][surge] == pytest.approx(-(1 - T_R) * 0.5 * 1025 * 0.0539 * f_alpha / 3300)
    # The side force turns the ship its convention's way; the drag brakes either way.
    assert np.sign(prior["r"][lateral]) == (1 if side == "starboard" else -1)
    assert prior["u"][surge] < 0

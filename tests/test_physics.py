"""Physics in the fit (issue #10): the constrained LS-SVM solver against a brute-force minimiser,
sign constraints and steady speed on simulated trials, the Clarke prior against hand-computed
formulas and the KVLCC2's MMG linearisation, and the CLI options."""

import json
import math
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run
from scipy.optimize import minimize

from shipid.data.io import write_log
from shipid.data.particulars import Particulars, read_particulars
from shipid.dynamics.model import get_structure
from shipid.errors import ShipidError
from shipid.identification.identify import identify
from shipid.identification.physics import PhysicsOptions, parse_constraints
from shipid.identification.priors import clarke_derivatives, clarke_linear, clarke_prior
from shipid.lssvm.solvers import accumulate_normal_equations, solve_primal_constrained
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import SensorModel, scale_ship
from shipid.vessels.kvlcc2 import accelerations, trimmed_revolutions

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="../shared/data is not present")


# ---------------------------------------------------------------------------- the solver
@pytest.fixture(scope="module")
def regression():
    rng = np.random.default_rng(3)
    X = rng.normal(size=(300, 4)) * [1.0, 3.0, 0.2, 1.0]
    y = X @ [0.8, -0.5, 2.0, 0.1] + 0.4 + 0.2 * rng.normal(size=300)
    A, B = accumulate_normal_equations([(X, y[:, None], np.ones(300))], 4, 1)
    return X, y, A, B[:, 0]


def _brute(X, y, gamma, prior=None, bounds=None, equalities=None, inequalities=None):
    """The same objective minimised over (ω, b) by SciPy's SLSQP, an independent method."""
    p = X.shape[1]
    w0 = np.zeros(p) if prior is None else np.asarray(prior)
    scale = gamma * len(y)

    def f(x):
        e = y - X @ x[:p] - x[p]
        return (0.5 * (x[:p] - w0) @ (x[:p] - w0) + 0.5 * gamma * e @ e) / scale

    def grad(x):
        e = y - X @ x[:p] - x[p]
        return np.concatenate([(x[:p] - w0) - gamma * X.T @ e, [-gamma * e.sum()]]) / scale

    cons = []
    if equalities is not None:
        E, rhs = equalities
        cons = [{"type": "eq", "fun": lambda x: E @ x - rhs, "jac": lambda x: E}]
    if inequalities is not None:
        G, h = inequalities
        cons.append({"type": "ineq", "fun": lambda x: G @ x - h, "jac": lambda x: G})
    bnds = list(bounds or [(None, None)] * p) + [(None, None)]
    x0 = np.linalg.lstsq(np.column_stack([X, np.ones(len(y))]), y, rcond=None)[0]
    res = minimize(f, x0, jac=grad, bounds=bnds, constraints=cons, method="SLSQP",
                   options={"ftol": 1e-15, "maxiter": 1000})  # fmt: skip
    assert res.success, res.message
    return res.x[:p], res.x[p]


@pytest.mark.parametrize("case", ["plain", "prior", "bounds", "equalities", "all"])
def test_constrained_solver_equals_an_independent_minimiser(regression, case):
    X, y, A, b = regression
    gamma = 5.0
    kw = {}
    if case in ("prior", "all"):
        kw["prior"] = np.array([2.0, 2.0, -3.0, 1.0])
    if case in ("bounds", "all"):
        kw["lower"] = np.array([-np.inf, -0.3, -np.inf, -np.inf])
        kw["upper"] = np.array([0.5, np.inf, np.inf, np.inf])
    if case in ("equalities", "all"):
        kw["equalities"] = (np.array([[1.0, 0.5, 0.0, 2.0, 1.0], [0.0, 0.0, 1.0, 0.0, 0.0]]),
                            np.array([-0.3, 1.5]))  # fmt: skip
    w, bias, active = solve_primal_constrained(A, b, gamma, **kw)
    bounds = None
    if "lower" in kw:
        bounds = [(None if not math.isfinite(lo) else lo, None if not math.isfinite(hi) else hi)
                  for lo, hi in zip(kw["lower"], kw["upper"], strict=True)]  # fmt: skip
    w_ref, b_ref = _brute(X, y, gamma, kw.get("prior"), bounds, kw.get("equalities"))
    np.testing.assert_allclose(w, w_ref, atol=2e-6)
    assert bias == pytest.approx(b_ref, abs=2e-6)
    if "lower" in kw:
        # The data want ω₀ ≈ 0.8 > 0.5 and ω₁ ≈ −0.5 < −0.3: both bounds hold.
        assert list(active[:2]) == [True, True] and w[0] == pytest.approx(0.5)
    if "equalities" in kw:
        E, rhs = kw["equalities"]
        np.testing.assert_allclose(E @ np.append(w, bias), rhs, atol=1e-7)


@pytest.mark.parametrize("case", ["alone", "with bounds and equalities", "with inequalities"])
def test_equal_bounds_hold_a_coefficient_at_their_value(regression, case):
    """lower = upper (``--bound`` both ways at one value): SciPy's bounded solvers refuse an
    empty box; the coefficient is held there exactly, flagged, and the rest is the minimiser
    with that value as an equality (SLSQP, independent)."""
    X, y, A, b = regression
    gamma = 5.0
    lower = np.array([-np.inf, -np.inf, -1.5, -np.inf])
    upper = np.array([np.inf, np.inf, -1.5, np.inf])
    kw, rows, rhs = {}, [[0.0, 0.0, 1.0, 0.0, 0.0]], [-1.5]
    if case == "with bounds and equalities":
        lower[1], upper[0] = -0.3, 0.5
        kw["equalities"] = (np.array([[1.0, 0.5, 0.0, 2.0, 1.0]]), np.array([-0.3]))
        rows, rhs = rows + kw["equalities"][0].tolist(), rhs + [-0.3]
    if case == "with inequalities":  # ω₀ + ω₁ ≥ 0.6, which the fit without it does not meet
        kw["inequalities"] = (np.array([[1.0, 1.0, 0.0, 0.0, 0.0]]), np.array([0.6]))
    w, bias, active = solve_primal_constrained(A, b, gamma, lower=lower, upper=upper, **kw)
    assert w[2] == -1.5 and active[2]
    bounds = [(None if not math.isfinite(lo) else lo, None if not math.isfinite(hi) else hi)
              for lo, hi in zip(lower, upper, strict=True)]  # fmt: skip
    bounds[2] = (None, None)
    w_ref, b_ref = _brute(X, y, gamma, None, bounds, (np.array(rows), np.array(rhs)),
                          kw.get("inequalities"))
    np.testing.assert_allclose(w, w_ref, atol=2e-6)
    assert bias == pytest.approx(b_ref, abs=2e-6)
    if "inequalities" in kw:
        assert w[0] + w[1] == pytest.approx(0.6, abs=1e-7)


# ---------------------------------------------------------------------------- on trials
@pytest.fixture(scope="module")
def short_zigzag():
    """A short 20/20 zig-zag of the scale ship (positive rudder turns it to port), noisy."""
    log = zigzag(scale_ship(), 20, 20, duration=25, dt=0.2).log
    return SensorModel(white={"u": 0.01, "v": 0.01, "r": 0.005}).apply(log, seed=0)


@pytest.mark.parametrize("term", ["delta^2", "u^2*delta^2", "|u|*u*delta^2", "pos(n)^2*delta^2"])
def test_the_rudders_drag_is_a_drag_in_the_free_stream_and_in_the_race(term):
    """The sign table held δ² and u²δ² ≤ 0, not the ahead form |u|uδ² nor the race's n⁺²δ²: the
    best candidate of the Esso's nine zig-zag files had n⁺²δ² at +3.5e-4, a rudder that pushes
    the ship ahead the harder it is put over."""
    from shipid.dynamics.terms import parse_term
    from shipid.identification.physics import _sign_bounds

    assert _sign_bounds("u", parse_term(term).text, None) == (-math.inf, 0.0, "rudder drag")


def test_sign_constraints_hold_and_are_reported(short_zigzag):
    free = identify(short_zigzag, "blanke-speed")
    fit = identify(short_zigzag, "blanke-speed", physics=PhysicsOptions(signs=True))
    c = fit.model.coefficients
    assert c["u"]["|u|*u"] <= 0 and c["u"]["delta^2"] <= 0
    assert c["v"]["u*v"] <= 0 and c["v"]["|v|*v"] <= 0 and c["r"]["u*r"] <= 0
    # Positive rudder turns this ship to port: ṙ's rudder term ≤ 0, v̇'s ≥ 0.
    assert c["r"]["u^2*delta"] <= 0 <= c["v"]["u^2*delta"]
    held = {(d, t) for d, diag in fit.diagnostics.items() for t in diag["at_bound"]}
    # The unconstrained fit gives the sway rudder term the wrong sign (issue #10's finding).
    assert ("v", "u^2*delta") in held
    expected = {("v", "u^2*delta"): 1, ("u", "delta^2"): -1, ("r", "u^2*delta"): -1,
                ("v", "u*v"): -1, ("v", "|v|*v"): -1, ("r", "u*r"): -1, ("u", "|u|*u"): -1}
    for d, t in held:
        assert free.model.coefficients[d][t] * expected[(d, t)] < 0  # only wrong signs held
        assert fit.model.coefficients[d][t] == 0.0
        assert any("held at its bound" in w and w.startswith(d + ":") for w in fit.warnings)
    assert fit.physics["signs"] is True


def test_the_thrust_falls_with_the_advance_under_the_sign_table():
    """u|n| ≥ 0 in the surge is a speed that feeds itself (astern too): the sign table holds it
    at ≤ 0. The truth here has it positive, so the free fit finds it so and the rule binds."""
    from shipid.dynamics.model import ManoeuvringModel
    from shipid.dynamics.simulate import simulate

    truth = ManoeuvringModel("u: |u|*u, pos(n)^2, u*|n|; v: u*v, u*r, delta; r: u*v, u*r, delta",
                             {"u": {"|u|*u": -0.05, "pos(n)^2": 1e-4, "u*|n|": 0.002},
                              "v": {"u*v": -0.4, "u*r": -0.3, "delta": 0.02},
                              "r": {"u*v": -0.2, "u*r": -0.5, "delta": -0.05}})  # fmt: skip
    t = np.arange(0.0, 400.0, 0.2)
    rps = np.select([t < 100, t < 200, t < 300], [10.0, 6.0, 12.0], 8.0)
    delta = np.radians(10.0) * np.sign(np.sin(2 * np.pi * t / 60.0))
    log = simulate(truth, t, delta, {"u": 0.69}, rps=rps).log
    log = SensorModel(white={"u": 0.002, "v": 0.002, "r": 0.001}).apply(log, seed=1)
    structure = truth.structure
    free = identify(log, structure, gamma=1e6)
    held = identify(log, structure, gamma=1e6, physics=PhysicsOptions(signs=True))
    assert 0.001 < free.model.coefficients["u"]["u*|n|"] < 0.004  # the truth 0.002, noisy
    assert held.model.coefficients["u"]["u*|n|"] == 0.0
    assert "u*|n|" in held.diagnostics["u"]["at_bound"]
    assert any(w.startswith("u: u |n| held at its bound 0 (thrust falls with the advance)")
               for w in held.warnings)  # fmt: skip


def test_steady_speed_holds_on_every_approach(short_zigzag):
    fit = identify(short_zigzag, "blanke", physics=PhysicsOptions(steady_speed=True))
    u0 = float(short_zigzag["u"].iloc[0])
    assert fit.model.accelerations(u0, 0.0, 0.0, 0.0)[0][0] == pytest.approx(0.0, abs=1e-12)
    assert any("steady speed" in w for w in fit.warnings)
    # Two approaches (the second trial run slower, its own steady state): both held, with the
    # sign constraints too (penalty form).
    slow = zigzag(scale_ship(surge_constant=0.08), 20, 20, duration=25, dt=0.2).log
    both = identify([short_zigzag, slow], "blanke",
                    physics=PhysicsOptions(steady_speed=True, signs=True))  # fmt: skip
    for log in (short_zigzag, slow):
        u = float(log["u"].iloc[0])
        assert both.model.accelerations(u, 0.0, 0.0, 0.0)[0][0] == pytest.approx(0.0, abs=1e-7)


def test_physics_bad_input_is_one_clear_error(short_zigzag):
    with pytest.raises(ShipidError, match="conflict on r: u\\*r: yaw damping and bound"):
        identify(short_zigzag, "blanke", physics=PhysicsOptions(
            signs=True, bounds={"r": {"u*r": (0.1, math.inf)}}))
    with pytest.raises(ShipidError, match="not a free term of the v equation"):
        identify(short_zigzag, "blanke", physics=PhysicsOptions(bounds={"v": {"r^3": (0, 1)}}))
    with pytest.raises(ShipidError, match="increment form"):
        identify(short_zigzag, "blanke", form="paper", physics=PhysicsOptions(signs=True))
    with pytest.raises(ShipidError, match="lssvm or ols"):
        identify(short_zigzag, "blanke", estimator="ridge", physics=PhysicsOptions(signs=True))
    with pytest.raises(ShipidError, match="unknown 'sign'"):
        parse_constraints("sign")
    structure = get_structure("blanke")
    with pytest.raises(ShipidError, match="Clarke prior needs the particulars beam"):
        clarke_prior(Particulars(length=4.0), structure, 2.0)


# ---------------------------------------------------------------------------- the Clarke prior
def test_clarke_derivatives_by_hand():
    p = Particulars(length=100.0, beam=16.0, draught=6.0, block_coefficient=0.7)
    d = clarke_derivatives(p)
    S = math.pi * 0.06**2
    assert d["Yv"] == pytest.approx(-S * (1 + 0.4 * 0.7 * 16 / 6))
    assert d["Yr"] == pytest.approx(-S * (-0.5 + 2.2 * 0.16 - 0.08 * 16 / 6))
    assert d["Nv"] == pytest.approx(-S * (0.5 + 2.4 * 0.06))
    assert d["Nr"] == pytest.approx(-S * (0.25 + 0.039 * 16 / 6 - 0.56 * 0.16))
    assert d["Nrdot"] == pytest.approx(-S * (1 / 12 + 0.017 * 0.7 * 16 / 6 - 0.33 * 0.16))



@pytest.mark.parametrize("structure", ["blanke-speed", "blanke-race", "abkowitz3"])
def test_a_clarke_prior_linearises_to_the_clarke_derivatives_once(structure):
    """Whatever forms of v, r and δ a structure has (abkowitz3 has v and u·v, blanke-race u²δ
    and δ), the prior model's sway–yaw linearisation at the approach speed is the Clarke linear
    model: each derivative is given once, not once per form (it was given twice)."""
    from shipid.dynamics.model import ManoeuvringModel

    p = Particulars(length=100.0, beam=16.0, draught=6.0, block_coefficient=0.7, rudder_area=25.0)
    U = 7.0
    prior = clarke_prior(p, get_structure(structure), U, "starboard")
    linear = clarke_linear(p, "starboard")
    model = ManoeuvringModel(get_structure(structure), prior)
    h = 1e-6
    for k, (signal, scale) in enumerate((("v", U), ("r", U), ("delta", U**2))):
        e = np.zeros(3)
        e[k] = h
        up = np.ravel(model.accelerations(U, *e))
        down = np.ravel(model.accelerations(U, *-e))
        for i, dof in ((1, "v"), (2, "r")):
            slope = (up[i] - down[i]) / (2 * h)
            assert slope == pytest.approx(linear[dof][signal] * scale, rel=1e-6), (dof, signal)

@needs_data
def test_clarke_prior_of_the_kvlcc2_is_close_to_its_mmg_linearisation():
    """The MARIN particulars file through Clarke's regressions against the linearised MMG model
    of the KVLCC2 (an independent, published model): every linear acceleration coefficient
    within 25 % (Clarke's own scatter is of that order)."""
    p = read_particulars(DATA / "kvlcc2-marin" / "ship_data.yml")
    prior = clarke_linear(p, "starboard")
    U, h = 1.179, 1e-5
    n = trimmed_revolutions(U)

    def diff(k):
        e = np.zeros(4)
        e[k] = h
        a = np.array(accelerations(U + e[0], e[1], e[2], e[3], n))
        b = np.array(accelerations(U - e[0], -e[1], -e[2], -e[3], n))
        return (a - b) / (2 * h)

    J = np.column_stack([diff(1), diff(2), diff(3)])  # columns: v, r, δ
    truth = {"v": {"v": J[1, 0] / U, "r": J[1, 1] / U, "delta": J[1, 2] / U**2},
             "r": {"v": J[2, 0] / U, "r": J[2, 1] / U, "delta": J[2, 2] / U**2}}  # fmt: skip
    for dof in ("v", "r"):
        for k in ("v", "r", "delta"):
            assert prior[dof][k] == pytest.approx(truth[dof][k], rel=0.25), (dof, k)
    # Mapped onto a structure: u·v, u·r, u²·δ per unit speed; δ alone times U0².
    mapped = clarke_prior(p, get_structure("blanke-speed"), U, "starboard")
    assert mapped["r"]["u^2*delta"] == pytest.approx(prior["r"]["delta"])
    plain = clarke_prior(p, get_structure("blanke"), U, "starboard")
    assert plain["v"]["delta"] == pytest.approx(prior["v"]["delta"] * U**2)
    assert "|v|*v" not in plain["v"]


# ---------------------------------------------------------------------------- the CLI
def test_cli_prior_constraints_and_bounds(tmp_path, capsys, short_zigzag):
    log = write_log(short_zigzag, tmp_path / "zz.csv")
    part = tmp_path / "ship.yml"
    part.write_text("length: 4.389\nbeam: 0.838\ndraught: 0.372\nblock_coefficient: 0.6\n"
                    "rudder_area: 0.05\nrho: 1000\n")  # fmt: skip
    out = tmp_path / "m.json"
    code, _, err = run(["identify", log, "--model", "blanke-speed", "--prior", "clarke",
                        "--particulars", part, "--constraints", "signs,steady-speed",
                        "--bound", "r: u*r >= -3", "-o", out], capsys)  # fmt: skip
    assert code == 0, err
    doc = json.loads(out.read_text())
    physics = doc["identification"]["physics"]
    assert physics["signs"] and physics["steady_speed"]
    # In the model's terms: written |u|·r, |u|·v, |u|·u·δ (the log runs ahead).
    assert physics["bounds"]["r"]["|u|*r"][0] == -3
    assert set(physics["prior"]["v"]) == {"|u|*v", "u*r", "|u|*u*delta"}
    for argv, message in [
        (["--bound", "r: u*r < 0"], "--bound expects"),
        (["--prior", "clarke"], "needs the ship's particulars"),
        (["--constraints", "signs,stiff"], "unknown 'stiff'"),
        (["--bound", "r: u*r >= 1", "--constraints", "signs"], "constraints conflict"),
    ]:
        code, _, err = run(["identify", log, "-o", tmp_path / "x.json", *argv], capsys)
        assert code == 1 and message in err and "Traceback" not in err, (argv, err)
        assert not (tmp_path / "x.json").exists()
    # A bound on a term the given structure lacks is refused. The default's choice (here the
    # paper's blanke, which has no |r|r) holds it at 0: within a bound around 0, and a bound
    # that excludes 0 is one line saying it cannot be met.
    code, _, err = run(["identify", log, "--model", "blanke", "--bound", "r: |r|*r <= 0", "-o",
                        tmp_path / "x.json"], capsys)  # fmt: skip
    assert code == 1 and "r: |r|*r is not a free term of the r equation" in err
    code, _, err = run(["identify", log, "--bound", "r: |r|*r <= 0", "-o", tmp_path / "y.json"],
                       capsys)  # fmt: skip
    assert code == 0 and "bounds: r" not in err, err
    code, _, err = run(["identify", log, "--bound", "r: |r|*r <= -0.5", "-o",
                        tmp_path / "z.json"], capsys)  # fmt: skip
    assert code == 1 and len(err.splitlines()) == 1 and not (tmp_path / "z.json").exists()
    assert "r: |r|*r [-inf, -0.5] cannot be met: the structure has no such term" in err


def test_a_steady_speed_the_logs_do_not_show_is_reported(short_zigzag):
    """The second trial starts at 2.5 m/s on a ship that holds 2 m/s: no surge equation of
    |u|u and a constant is steady at both, and identify says so instead of handing out a model
    without speed stability silently."""
    fast_start = zigzag(scale_ship(), 20, 20, duration=25, dt=0.2, speed=2.5).log
    fit = identify([short_zigzag, fast_start], "blanke",
                   physics=PhysicsOptions(steady_speed=True, signs=True))  # fmt: skip
    assert any("not steady states of one surge equation" in w for w in fit.warnings)

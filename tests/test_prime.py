"""Prime (non-dimensional) coefficients and Froude scaling (issue #10 item 1), against the
similarity law run through the simulator and against closed forms."""

import math

import numpy as np
import pandas as pd
import pytest

from shipid.dynamics import prime
from shipid.dynamics.model import ManoeuvringModel
from shipid.dynamics.prime import from_prime, froude_scaled, prime_coefficients, prime_factor
from shipid.dynamics.simulate import simulate_log
from shipid.dynamics.terms import SIGNALS
from shipid.errors import ShipidError

# Every kind of factor: speeds, rates, rps, thrust, angles, wind, trigonometric, constant.
TERMS = {
    "u": ["|u|*u", "v*r", "thrust", "pos(n)^2", "1"],
    "v": ["u*v", "u*r", "u^2*delta", "wind_speed^2*sin(wind_angle)", "|v|*v"],
    "r": ["u*r", "U*v", "|n|*n*delta", "U*r*cos(2*beta)", "1"],
}
COEFS = {
    "u": [-0.03, 0.8, 2.0e-4, 0.002, 0.01],
    "v": [-0.5, -0.4, 0.05, 1.0e-4, -0.6],
    "r": [-1.1, -0.6, -0.004, -0.3, -1.0e-4],
}


def _model() -> ManoeuvringModel:
    structure = "; ".join(f"{d}: {', '.join(t)}" for d, t in TERMS.items())
    coefs = {d: dict(zip(TERMS[d], COEFS[d], strict=True)) for d in TERMS}
    return ManoeuvringModel(structure, coefs, name="all factors")


def _log(factor: float = 1.0) -> pd.DataFrame:
    """A manoeuvre of the ship and, with ``factor``, of its Froude-similar sister."""
    k = math.sqrt(factor)
    t = np.arange(0, 120, 0.1)
    return pd.DataFrame({
        "t": t * k, "delta": np.radians(20) * np.sin(2 * np.pi * t / 40),
        "u": 1.2 * k, "v": 0.0, "r": 0.0,
        "n": (10 + 2 * np.sin(t / 15)) / k, "thrust": (30 + 5 * np.cos(t / 9)) * factor**3,
        "wind_speed": (3 + np.sin(t / 7)) * k, "wind_angle": np.radians(40) + 0 * t,
    })  # fmt: skip


@pytest.mark.parametrize("factor", [45.7, 0.1, 3.0])
def test_a_froude_scaled_model_runs_the_similar_manoeuvre(factor):
    model = _model()
    small = simulate_log(model, _log()).log
    large = simulate_log(froude_scaled(model, factor), _log(factor)).log
    k = math.sqrt(factor)
    for col, scale in (("u", k), ("v", k), ("r", 1 / k), ("psi", 1.0), ("x", factor),
                       ("y", factor)):  # fmt: skip
        np.testing.assert_allclose(large[col], small[col] * scale, rtol=1e-9,
                                   atol=1e-12 * scale, err_msg=col)  # fmt: skip


def test_prime_factors_are_the_closed_forms():
    L, U, rho = 320.0, 7.97, 1025.0
    assert prime_factor("u", "|u|*u", L, U) == pytest.approx(L)
    assert prime_factor("u", "1", L, U) == pytest.approx(L / U**2)
    assert prime_factor("v", "u*r", L, U) == pytest.approx(U * U / L / (U**2 / L))
    assert prime_factor("r", "u*r", L, U) == pytest.approx(L)
    assert prime_factor("r", "u^2*delta", L, U) == pytest.approx(L**2)
    assert prime_factor("r", "|n|*n*delta", L, U) == pytest.approx(1.0)  # n′ = nL/U, as r′
    assert prime_factor("u", "thrust", L, U, rho) == pytest.approx(0.5 * rho * L**3)
    assert prime.term_scale("sin(2*beta)^3", L, U) == 1.0


def test_every_signal_has_a_prime_scale():
    for s in SIGNALS:
        assert prime.term_scale(s, 2.0, 3.0) > 0


def test_prime_round_trip():
    model = _model()
    back = from_prime(model.structure, prime_coefficients(model, 7.0, 1.18, 1000.0), 7.0, 1.18,
                      1000.0)  # fmt: skip
    for d in TERMS:
        for t in TERMS[d]:
            assert back.coefficients[d][t] == pytest.approx(model.coefficients[d][t], rel=1e-14)


def test_the_clarke_prior_in_prime_form_is_the_prime_linear_solve():
    """Dimensional path (priors) against the textbook prime matrices of Clarke's derivatives."""
    from shipid.data.particulars import Particulars
    from shipid.identification.priors import clarke_derivatives, clarke_linear

    p = Particulars.from_mapping({"length": 320.0, "beam": 58.0, "draught": 20.8, "block_coefficient":
                          0.81, "mass": 3.125e8, "xg": 11.1, "rho": 1025.0})  # fmt: skip
    acc = clarke_linear(p, None)
    model = ManoeuvringModel("v: u*v, u*r; r: u*v, u*r",
                             {"v": {"u*v": acc["v"]["v"], "u*r": acc["v"]["r"]},
                              "r": {"u*v": acc["r"]["v"], "u*r": acc["r"]["r"]}})  # fmt: skip
    prime = prime_coefficients(model, p.length, 7.97, p.rho)
    d = clarke_derivatives(p)
    m = p.mass / (0.5 * p.rho * p.length**3)
    xg = p.xg / p.length
    iz = m * 0.25**2 + m * xg**2
    M = np.array([[m - d["Yvdot"], m * xg - d["Yrdot"]], [m * xg - d["Nvdot"], iz - d["Nrdot"]]])
    F = np.array([[d["Yv"], d["Yr"] - m], [d["Nv"], d["Nr"] - m * xg]])
    expected = np.linalg.solve(M, F)
    assert prime["v"]["u*v"] == pytest.approx(expected[0, 0], rel=1e-10)
    assert prime["v"]["u*r"] == pytest.approx(expected[0, 1], rel=1e-10)
    assert prime["r"]["u*v"] == pytest.approx(expected[1, 0], rel=1e-10)
    assert prime["r"]["u*r"] == pytest.approx(expected[1, 1], rel=1e-10)


@pytest.mark.parametrize("args", [(0.0, 1.0, 1025.0), (7.0, -1.0, 1025.0), (7.0, 1.0, math.nan)])
def test_bad_reference_values_are_named(args):
    with pytest.raises(ShipidError, match="prime form"):
        prime_coefficients(_model(), *args)
    with pytest.raises(ShipidError, match="scale factor"):
        froude_scaled(_model(), -2.0)


@pytest.fixture(scope="module")
def model_files(tmp_path_factory):
    """A model of the paper's scale ship from a noisy zig-zag, with particulars and bootstrap."""
    from cli_helpers import main

    from shipid.data.io import write_log
    from shipid.trials.manoeuvres import zigzag
    from shipid.vessels import PAPER_IMU, scale_ship

    d = tmp_path_factory.mktemp("prime")
    log = PAPER_IMU.apply(zigzag(scale_ship(rudder_rate_deg=9.6), 20, 20, duration=90, dt=0.2,
                                 method="euler").log, seed=3)  # fmt: skip
    write_log(log, d / "zz.csv")
    (d / "p.yml").write_text("length: 4.5\nbeam: 0.6\nrho: 1000\n", encoding="utf-8")
    assert main(["identify", str(d / "zz.csv"), "--filter", "0.5", "--drop", "u:r^2",
                 "--particulars", str(d / "p.yml"), "--bootstrap", "20",
                 "-o", str(d / "m.json")]) == 0  # fmt: skip
    return d


def test_identify_prints_and_stores_the_prime_form(model_files, capsys):
    import json

    doc = json.loads((model_files / "m.json").read_text(encoding="utf-8"))
    prime = doc["prime"]
    assert prime["length"] == 4.5 and prime["speed_basis"] == "training approach speed"
    speed = doc["identification"]["preprocessing"]["approach_speed"]
    assert prime["speed"] == speed
    c = doc["model"]["coefficients"]
    # u̇ = c|u|u → c′ = cL; ṙ = c u r → c′ = cL; u̇ = c → c′ = cL/U²
    assert prime["coefficients"]["u"]["|u|*u"] == pytest.approx(c["u"]["|u|*u"] * 4.5)
    assert prime["coefficients"]["r"]["|u|*r"] == pytest.approx(c["r"]["|u|*r"] * 4.5)
    assert prime["coefficients"]["u"]["1"] == pytest.approx(c["u"]["1"] * 4.5 / speed**2)


def test_a_rescaled_model_turns_the_similar_circle(model_files, capsys):
    import json

    from cli_helpers import run

    f = 16.95
    code, out, err = run(["rescale", model_files / "m.json", "--length", 4.5 * f, "-o",
                          model_files / "full.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "Froude scaling 4.5 m → 76.275 m" in out
    doc = json.loads((model_files / "full.json").read_text(encoding="utf-8"))
    small = json.loads((model_files / "m.json").read_text(encoding="utf-8"))
    assert doc["particulars"]["length"] == pytest.approx(4.5 * f)
    assert doc["prime"]["coefficients"]["r"]["|u|*r"] == pytest.approx(
        small["prime"]["coefficients"]["r"]["|u|*r"], rel=1e-12)
    k = math.sqrt(f)
    prep, prep0 = (x["identification"]["preprocessing"] for x in (doc, small))
    assert prep["approach_speed"] == pytest.approx(prep0["approach_speed"] * k)
    assert prep["rudder_rate"] == pytest.approx(prep0["rudder_rate"] / k)
    env, env0 = doc["identification"]["envelope"], small["identification"]["envelope"]
    assert env["r"] == pytest.approx([b / k for b in env0["r"]])
    assert env["delta"] == env0["delta"]
    # every bootstrap replicate scaled like the point estimate
    t0, t1 = (np.asarray(x["uncertainty"]["thetas"]) for x in (small, doc))
    j = small["uncertainty"]["terms"].index("|u|*r")
    np.testing.assert_allclose(t1[:, 2, j] / t0[:, 2, j], t1[0, 2, j] / t0[0, 2, j], rtol=1e-12)

    def turn(path, dt, duration):
        code, out, err = run(["manoeuvre", path, "turning", "--rudder", "20", "--dt", dt,
                              "--duration", duration, "--no-bands", "--json",
                              path.with_suffix(".turn.json")], capsys)  # fmt: skip
        assert code == 0, err
        return json.loads(path.with_suffix(".turn.json").read_text(encoding="utf-8"))["indices"]

    a = turn(model_files / "m.json", 0.1, 200)
    b = turn(model_files / "full.json", 0.1 * k, 200 * k)
    for key in ("advance", "tactical_diameter"):
        assert b[key] == pytest.approx(a[key] * f, rel=1e-6), key
    assert b["steady_yaw_rate"] == pytest.approx(a["steady_yaw_rate"] / k, rel=1e-6)


@pytest.mark.parametrize("args, message", [
    (["--factor", "2", "--length", "9"], "--factor F"),
    ([], "--factor F"),
    (["--factor", "-3"], "--factor"),
    (["--factor", "1e308"], "not between two ships"),
    (["--factor", "1e-300"], "not between two ships"),
    (["--length", "0"], "--length"),
    (["--factor", "2", "--rho", "nan"], "--rho"),
])  # fmt: skip
def test_rescale_refuses_bad_options(model_files, capsys, args, message):
    from cli_helpers import run

    code, _, err = run(["rescale", model_files / "m.json", *args, "-o", model_files / "x.json"],
                       capsys)  # fmt: skip
    assert code == 1 and message in err and len(err.strip().splitlines()) == 1
    assert not (model_files / "x.json").exists()


def test_a_rescaled_models_standard_errors_are_those_of_a_fit_at_the_new_scale(tmp_path, capsys):
    """The LS-SVM fit's standard errors, printed beside the coefficients, stayed those of the
    original scale in a rescaled file (ṙ u·v 0.0054 ± 0.0009 at ten times the length, the
    error of 0.54). The truth: the same fit on the Froude-scaled log."""
    import json

    from cli_helpers import run

    from shipid.data.io import write_log
    from shipid.trials.manoeuvres import zigzag
    from shipid.vessels import PAPER_IMU, scale_ship

    log = PAPER_IMU.apply(zigzag(scale_ship(rudder_rate_deg=9.6), 20, 20, duration=90, dt=0.2,
                                 method="euler").log, seed=5)  # fmt: skip
    f = 4.0
    k = math.sqrt(f)
    big = log.copy()
    big["t"] *= k
    for s in ("u", "v"):
        big[s] *= k
    big["r"] /= k
    for s in ("x", "y"):
        if s in big:
            big[s] *= f
    big.attrs = {a: b for a, b in log.attrs.items() if a != "scale"}
    small = log.copy()
    small.attrs = dict(big.attrs)
    # γ large: the regulariser (not scaled with the regressors) out of the comparison.
    fit = ["--filter", "none", "--no-output-error", "--error-band", "none", "--gamma", "1e9"]
    for name, data in (("small", small), ("big", big)):
        path = write_log(data, tmp_path / f"{name}.csv")
        assert run(["identify", path, *fit, "-o", tmp_path / f"{name}.json"], capsys)[0] == 0
    assert run(["rescale", tmp_path / "small.json", "--factor", f, "-o",
                tmp_path / "rescaled.json"], capsys)[0] == 0  # fmt: skip
    docs = {n: json.loads((tmp_path / f"{n}.json").read_text(encoding="utf-8"))
            for n in ("small", "big", "rescaled")}  # fmt: skip
    checked = 0
    for dof in ("u", "v", "r"):
        want = docs["big"]["identification"]["diagnostics"][dof]["std_errors"]
        got = docs["rescaled"]["identification"]["diagnostics"][dof]["std_errors"]
        before = docs["small"]["identification"]["diagnostics"][dof]["std_errors"]
        for term, se in want.items():
            if se is None:  # a term constant in the data: infinite on both
                assert got[term] is None
                continue
            assert got[term] == pytest.approx(se, rel=1e-3), (dof, term)
            checked += before[term] != pytest.approx(se, rel=0.05)
    assert checked >= 5  # most terms' errors change with the scale

"""The term algebra, user terms through model files, and the wind input (issue #9 items 1–2)."""

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from shipid.data.log import make_log
from shipid.dynamics.model import ManoeuvringModel, ModelStructure, get_structure
from shipid.dynamics.simulate import simulate, simulate_log
from shipid.dynamics.terms import canonical, parse_term, term_matrix
from shipid.errors import ShipidError
from shipid.identification.identify import identify
from shipid.reporting.modelfile import load_model, save_model
from shipid.trials.manoeuvres import turning_circle, zigzag
from shipid.vessels import scale_ship

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="../shared/data is not present")


@pytest.mark.parametrize(("text", "canon", "display"), [
    ("|u|u", "|u|*u", "|u|u"), ("vr", "v*r", "v r"), ("u^2*delta", "u^2*delta", "u² δ"),
    ("|n|n*delta", "|n|*n*delta", "|n|n δ"), ("delta*u*u", "u^2*delta", "u² δ"),
    ("U_A^2*sin(2*gamma_A)", "U^2*sin(2*wind_angle)".replace("U^2", "wind_speed^2"),
     "U_A² sin(2γ_A)"), ("r*|v|*u", "u*|v|*r", "u |v| r"), ("T", "thrust", "T"), ("1", "1", ""),
])  # fmt: skip
def test_terms_parse_to_one_canonical_text(text, canon, display):
    assert canonical(text) == canon and parse_term(canon).text == canon
    assert parse_term(text).display() == display


def test_term_values_against_hand_computation():
    u, v, r = np.array([1.0, -0.5]), np.array([0.2, -0.3]), np.array([0.05, -0.1])
    inputs = {"delta": np.array([0.3, -0.2]), "n": np.array([8.0, -5.0]),
              "wind_angle": np.array([0.4, 2.0]), "wind_speed": np.array([3.0, 1.0])}  # fmt: skip
    terms = ["u*|v|*r", "pos(n)^2*delta", "neg(n)^2", "U^2*sin(2*beta)",
             "wind_speed^2*cos(wind_angle)", "delta^3", "cos(delta)^2"]  # fmt: skip
    got = term_matrix(terms, u, v, r, inputs)
    U2, beta = u**2 + v**2, np.arctan2(-v, u)
    expected = np.column_stack([
        u * np.abs(v) * r, np.maximum(inputs["n"], 0) ** 2 * inputs["delta"],
        np.maximum(-inputs["n"], 0) ** 2, U2 * np.sin(2 * beta),
        inputs["wind_speed"] ** 2 * np.cos(inputs["wind_angle"]), inputs["delta"] ** 3,
        np.cos(inputs["delta"]) ** 2])  # fmt: skip
    np.testing.assert_allclose(got, expected, rtol=1e-14)


@pytest.mark.parametrize(("spec", "match"), [
    ("u: |u|u, w; v: delta; r: delta", "unknown signal 'w' "),
    # A word whose start reads as a signal: the rest named in the word, not alone.
    ("u: |u|u, nothing", "unknown signal 'othing' in 'nothing'"),
    ("u: |u|u, u**2", "expected a signal"),
    ("u: sin(u)", "takes an angle signal"),
    ("u: vr, v*r", "are the same term"),
    ("q: u", "unknown degree of freedom"),
    ("blanke+nothing", "unknown model 'nothing'"),
])  # fmt: skip
def test_malformed_structures_give_one_line(spec, match):
    with pytest.raises(ShipidError, match=match):
        get_structure(spec)


def test_a_users_own_terms_round_trip_through_a_model_file(tmp_path):
    ship = scale_ship(rudder_rate_deg=9.6)
    log = zigzag(ship, 20, 20, duration=90, dt=0.2, method="euler", approach=2.0).log
    spec = ("u: |u|u, v*r, delta^2, 1; v: u*r, u*v, v*|v|, |v|*r, delta, delta^3, 1; "
            "r: u*r, u*v, |v|v, |v|r, delta, cos(delta)^2*u, 1")
    fit = identify(log, model=spec)
    path = save_model(tmp_path / "m.json", fit)
    back = load_model(path)
    assert back.structure.terms == fit.model.structure.terms
    assert back.coefficients == fit.model.coefficients
    assert "u*cos(delta)^2" in back.structure.terms["r"]  # canonical order
    a, b = simulate_log(fit.model, log).log, simulate_log(back, log).log
    np.testing.assert_array_equal(a.to_numpy(), b.to_numpy())


@needs_data
def test_osaka_relative_wind_is_true_wind_minus_ship_velocity():
    """The canonical convention: the apparent wind's speed and the direction it comes from,
    clockwise from the bow; the file's true wind (from, clockwise from north) and the ship's
    velocity give it to 1e-3."""
    from shipid.data.io import read_log

    path = DATA / "esso-osaka" / "turning" / "turn_14-Sep-2020_13_39_32.csv"
    log = read_log(path, fmt="osaka-frt")
    raw = pd.read_csv(path)
    vt, dt_ = raw["wind_velo_true [m/s]"].to_numpy(), raw["wind_dir_true [rad]"].to_numpy()
    psi = log["psi"].to_numpy()
    xd = log["u"] * np.cos(psi) - log["v"] * np.sin(psi)
    yd = log["u"] * np.sin(psi) + log["v"] * np.cos(psi)
    ax, ay = -vt * np.cos(dt_) - xd, -vt * np.sin(dt_) - yd
    bx, by = ax * np.cos(psi) + ay * np.sin(psi), -ax * np.sin(psi) + ay * np.cos(psi)
    np.testing.assert_allclose(log["wind_speed"], np.hypot(bx, by), atol=1e-3)
    np.testing.assert_allclose(np.angle(np.exp(1j * (log["wind_angle"] - np.arctan2(-by, -bx)))),
                               0.0, atol=1e-3)  # fmt: skip


def _wind_model(c=-0.01):
    """Surge: a wind drag c·U_A²·cos γ_A only (and enough lateral dynamics to be a model)."""
    terms = {"u": ("wind_speed^2*cos(wind_angle)",), "v": ("u*v", "delta"), "r": ("u*r", "delta")}
    coefs = {"u": {"wind_speed^2*cos(wind_angle)": c}, "v": {"u*v": -0.5, "delta": 0.05},
             "r": {"u*r": -1.0, "delta": -0.5}}  # fmt: skip
    return ManoeuvringModel(ModelStructure("wind test", terms), coefs)


def test_manoeuvres_meet_the_apparent_wind_of_a_constant_true_wind():
    m = _wind_model()
    u0, dt = 2.0, 0.1
    # Still air: the apparent wind is the ship's own speed from ahead, u̇ = c u².
    still = turning_circle(m, 10, duration=0.2, dt=dt, speed=u0, method="euler")
    assert still.log["u"].iloc[1] == pytest.approx(u0 + dt * (-0.01) * u0**2, rel=1e-12)
    # A 3 m/s head wind (blowing from north, the ship heading north): U_A = u + 3 from ahead.
    head = turning_circle(m, 10, duration=0.2, dt=dt, speed=u0, method="euler", wind=(3.0, 0.0))
    assert head.log["u"].iloc[1] == pytest.approx(u0 + dt * (-0.01) * (u0 + 3.0) ** 2, rel=1e-12)
    # From astern (blowing from south): U_A = |u − 3| = 1 m/s, coming from astern (cos γ = −1).
    tail = turning_circle(m, 10, duration=0.2, dt=dt, speed=u0, method="euler",
                          wind=(3.0, math.pi))  # fmt: skip
    assert tail.log["u"].iloc[1] == pytest.approx(u0 + dt * 0.01 * 1.0, rel=1e-12)


def test_a_logged_wind_drives_the_free_run_like_the_rudder():
    m = _wind_model()
    t = np.arange(0, 2.0, 0.1)
    wind = {"wind_speed": np.full(t.size, 5.0), "wind_angle": np.zeros(t.size)}
    res = simulate(m, t, np.zeros(t.size), {"u": 2.0}, method="euler", inputs=wind)
    assert res.log["u"].iloc[1] == pytest.approx(2.0 + 0.1 * (-0.01) * 25.0, rel=1e-12)
    log = make_log({"t": t, "delta": np.zeros(t.size), "u": np.full(t.size, 2.0),
                    "v": np.zeros(t.size), "r": np.zeros(t.size), **wind})  # fmt: skip
    assert simulate_log(m, log).log["u"].iloc[1] == pytest.approx(res.log["u"].iloc[1])
    with pytest.raises(ShipidError, match="wind_speed"):
        simulate_log(m, log.drop(columns=["wind_speed", "wind_angle"]))

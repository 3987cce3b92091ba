"""Physical signs on the linearised derivatives, not on each term (``--constraints derivatives``).

``signs`` holds each term's sign; a structure that splits one effect over several terms (the
rudder force as u²δ and δ, as ``blanke-race`` does) needs opposite signs among them, and
``signs`` held the fit of the KVLCC2's MARIN zig-zag at three wrong zeros. ``derivatives`` holds
the sum the terms make at straight running: ∂u̇/∂u, ∂v̇/∂v, ∂ṙ/∂r ≤ 0 and the rudder's ∂v̇/∂δ,
∂ṙ/∂δ of their signs. The truths are simulated ships of known coefficients."""

import numpy as np
import pytest
from cli_helpers import run
from generated_logs import YAW_DAMPED_STRUCTURE, yaw_damped_ship

from shipid.data.io import write_log
from shipid.dynamics.model import ManoeuvringModel
from shipid.dynamics.simulate import simulate
from shipid.identification.identify import identify
from shipid.identification.physics import PhysicsOptions, _straight_running_slopes

SPLIT = "u: |u|*u, delta^2, 1; v: u*v, u*r, u^2*delta; r: u*v, u*r, u^2*delta, delta"
# The rudder's yaw moment −0.012 u²δ + 0.004 δ: −0.008 δ at 1 m/s, the sign a rudder positive to
# port must have, from two terms of opposite signs.
SPLIT_SHIP = ManoeuvringModel(SPLIT, {
    "u": {"|u|*u": -0.05, "delta^2": -0.1, "1": 0.05},
    "v": {"u*v": -0.6, "u*r": -0.3, "u^2*delta": 0.01},
    "r": {"u*v": -1.5, "u*r": -0.8, "u^2*delta": -0.012, "delta": 0.004}})  # fmt: skip


def _trial(ship, duration=300.0):
    t = np.arange(0.0, duration, 0.1)
    delta = np.radians(25) * np.sign(np.sin(2 * np.pi * t / 30)) * (1 + 0.3 * np.sin(t / 27))
    res = simulate(ship, t, delta, {"u": 1.0, "v": 0.0, "r": 0.0}, None, "euler")
    assert not res.diverged
    res.log.attrs["rudder_positive"] = "port"
    return res.log


def _derivative(model, dof, state, u0):
    c = model.coefficients[dof]
    names = [t for t in c if t != "1"]
    return float(_straight_running_slopes(names, u0, 0.0, (state,))[0]
                 @ np.array([c[t] for t in names]))  # fmt: skip


def test_a_split_rudder_term_keeps_its_sign_where_signs_would_zero_it():
    log = _trial(SPLIT_SHIP)
    by_signs = identify(log, model=SPLIT, gamma=1e8, physics=PhysicsOptions(signs=True),
                        force=True)  # fmt: skip
    assert by_signs.model.coefficients["r"]["delta"] == 0.0  # held: the split is lost
    fit = identify(log, model=SPLIT, gamma=1e8, physics=PhysicsOptions(derivatives=True),
                   force=True)  # fmt: skip
    for term, truth in SPLIT_SHIP.coefficients["r"].items():
        assert fit.model.coefficients["r"][term] == pytest.approx(truth, rel=1e-3), term
    assert not any("held" in w for w in fit.warnings)


def test_a_derivative_the_data_put_past_its_sign_is_held_at_zero():
    # Yaw "damping" u·r = +0.3 (|r|·r keeps r bounded): ∂ṙ/∂r = +0.3 u at straight running.
    log = _trial(yaw_damped_ship(0.3), duration=200.0)
    u0 = float(log["u"].iloc[0])
    free = identify(log, model=YAW_DAMPED_STRUCTURE, gamma=1e6, force=True)
    # The LS-SVM's ½‖w‖² at γ = 1e6 moves it by 0.1 % (least squares gives 0.3 to 1e-12).
    assert _derivative(free.model, "r", "r", u0) == pytest.approx(0.3 * u0, rel=2e-3)
    fit = identify(log, model=YAW_DAMPED_STRUCTURE, gamma=1e6, force=True,
                   physics=PhysicsOptions(derivatives=True))  # fmt: skip
    assert abs(_derivative(fit.model, "r", "r", u0)) < 1e-9
    assert any(w.startswith("r: yaw damping ∂ṙ/∂r ≤ 0 at 1 m/s held at 0") for w in fit.warnings)
    # The sway equation's derivatives were physical already: it is fitted as without.
    assert fit.model.coefficients["v"] == pytest.approx(free.model.coefficients["v"], rel=1e-9)


def test_cli_takes_the_derivatives_constraint(tmp_path, capsys):
    path = write_log(_trial(yaw_damped_ship(0.3), duration=200.0), tmp_path / "t.csv")
    code, _, err = run(["identify", path, "--model", YAW_DAMPED_STRUCTURE, "--gamma", "1e6",
                        "--force", "--constraints", "derivatives", "-o", tmp_path / "m.json"],
                       capsys)  # fmt: skip
    assert code == 0, err
    assert "yaw damping ∂ṙ/∂r ≤ 0 at 1 m/s held at 0" in err


def test_the_slopes_of_many_states_at_once_are_the_closed_forms():
    """``_slopes_at`` differentiates each term at every state in one evaluation (``rudder-ahead``
    asks for 36 states per approach in every fit of a search): against the terms' own
    derivatives at straight running, at rest, slow, at speed, far ahead and with the propeller
    stopped; and the one-state form is its column."""
    from shipid.identification.physics import _slopes_at

    states = [(0.0, 10.0), (0.3, 10.0), (1.2, 10.33), (12.0, 0.0), (1200.0, 10.0)]
    u, n = (np.array(c) for c in zip(*states, strict=True))
    texts = ["|u|*u*delta", "u*pos(n)*delta", "pos(n)^2*delta", "u*r", "|v|*v", "r*|n|", "u*v"]
    got = _slopes_at(texts, states, ("u", "v", "r", "delta"))
    truth = {  # (∂/∂u, ∂/∂v, ∂/∂r, ∂/∂δ) at v = r = δ = 0
        "|u|*u*delta": (0 * u, 0 * u, 0 * u, np.abs(u) * u),
        "u*pos(n)*delta": (0 * u, 0 * u, 0 * u, u * np.maximum(n, 0)),
        "pos(n)^2*delta": (0 * u, 0 * u, 0 * u, np.maximum(n, 0) ** 2),
        "u*r": (0 * u, 0 * u, u, 0 * u),
        "|v|*v": (0 * u, 0 * u, 0 * u, 0 * u),
        "r*|n|": (0 * u, 0 * u, np.abs(n), 0 * u),
        "u*v": (0 * u, u, 0 * u, 0 * u),
    }
    for j, text in enumerate(texts):
        for w in range(4):
            assert got[w, j] == pytest.approx(truth[text][w], rel=1e-7, abs=1e-7), (text, w)
    one = _straight_running_slopes(texts, 1.2, 10.33, ("r", "delta"))
    assert np.array_equal(one, _slopes_at(texts, [(1.2, 10.33)], ("r", "delta"))[:, :, 0])

"""The hull going astern (``astern`` terms): its resistance and the lift of its drift are those of
another body when the stern leads. The terms vanish ahead (closed form), and a fit recovers them
from a run that goes astern with the rudder working."""

import numpy as np
import pandas as pd
import pytest

from shipid.dynamics.model import ManoeuvringModel, get_structure
from shipid.dynamics.simulate import simulate
from shipid.identification.identify import identify

LATERAL = ("u*v", "|u|*r", "u*|u|*delta")
SPEC = (f"u: |u|*u, pos(n)^2, neg(n)^2; v: {', '.join(LATERAL)}; "
        f"r: {', '.join(LATERAL)}")  # fmt: skip
# Astern, u·v turns its sway damping into a push (−0.6 u v > 0 for u < 0): neg(u)·v restores it,
# as the stern-first hull's own lift does.
TRUTH = ManoeuvringModel(
    get_structure(SPEC) + get_structure("astern"),
    {"u": {"|u|*u": -0.08, "pos(n)^2": 3e-4, "neg(n)^2": -2e-4, "neg(u)^2": 0.05},
     "v": {"u*v": -0.6, "|u|*r": -0.3, "u*|u|*delta": 0.08, "neg(u)*v": -1.0, "neg(u)*r": 0.1},
     "r": {"u*v": -0.4, "|u|*r": -0.9, "u*|u|*delta": -0.5, "neg(u)*v": 0.6,
           "neg(u)*r": -0.3}})  # fmt: skip


def test_astern_terms_vanish_ahead_and_are_the_closed_forms_astern():
    only = ManoeuvringModel("astern", {"u": {"neg(u)^2": 2.0},
                                       "v": {"neg(u)*v": 3.0, "neg(u)*r": 5.0},
                                       "r": {"neg(u)*v": 7.0, "neg(u)*r": 11.0}})  # fmt: skip
    u = np.array([0.4, 0.0, -0.3])
    v, r = np.array([0.05, 0.02, -0.04]), np.array([0.01, -0.03, 0.02])
    acc = only.accelerations(u, v, r, np.zeros(3))
    neg = np.maximum(-u, 0.0)  # neg(x): the size of the negative part
    np.testing.assert_allclose(acc[:, 0], 2.0 * neg**2, atol=1e-15)
    np.testing.assert_allclose(acc[:, 1], 3.0 * neg * v + 5.0 * neg * r, atol=1e-15)
    np.testing.assert_allclose(acc[:, 2], 7.0 * neg * v + 11.0 * neg * r, atol=1e-15)


def test_a_run_that_goes_astern_gives_back_the_astern_coefficients():
    t = np.arange(0.0, 400.0, 0.1)
    n = np.where(t < 120, 12.0, -12.0) + np.where((t > 250) & (t < 300), 20.0, 0.0)
    delta = np.radians(25) * np.sign(np.sin(2 * np.pi * t / 37)) * (t > 10)
    run = simulate(TRUTH, t, delta, {"u": 0.6}, rps=n, method="euler")
    assert not run.diverged
    log = run.log
    assert log["u"].min() < -0.3 and log["u"].max() > 0.5  # ahead and astern
    fit = identify(log, model=TRUTH.structure, gamma=1e10)
    for dof, coefs in TRUTH.coefficients.items():
        for term, want in coefs.items():
            assert fit.model.coefficients[dof][term] == pytest.approx(want, rel=2e-3, abs=1e-7), \
                (dof, term)  # fmt: skip
    assert isinstance(log, pd.DataFrame)

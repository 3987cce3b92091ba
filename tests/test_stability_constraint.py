"""Straight-line stability as a constraint of the fit (issue #10 item 3: ``--constraints stable``).

The truths: a quadratic program with linear inequalities solved by enumerating its active sets
(its KKT conditions, exactly), and ships of known coefficients, one straight-line unstable, whose
linearisation gives the eigenvalues the constrained fit must respect."""

import itertools
import math
import warnings

import numpy as np
import pandas as pd
import pytest
from cli_helpers import run
from generated_logs import YAW_DAMPED_STRUCTURE as STRUCTURE
from generated_logs import yaw_damped_ship

from shipid.control.linear import linearise
from shipid.data.io import write_log
from shipid.identification.identify import identify, weighted_refit
from shipid.identification.physics import STABILITY_MARGIN, PhysicsOptions
from shipid.identification.uncertainty import block_weights
from shipid.lssvm.solvers import NumericalWarning, solve_primal_constrained
from shipid.trials.manoeuvres import zigzag


def _logs(ship):
    logs = [zigzag(ship, a, a, speed=1.0, dt=0.1, duration=80.0, method="euler", approach=2.0,
                   first=first).log for a, first in ((20, "starboard"), (15, "port"))]  # fmt: skip
    for log in logs:
        log.attrs["rudder_positive"] = "port"
    return logs


def _sway_yaw_eigenvalues(model, speed):
    # The constraint's point: straight running with the rudder amidships (not the trim).
    return np.linalg.eigvals(linearise(model, speed, trimmed=False)["A"][1:, 1:])


def _kkt_by_enumeration(M, c, G, h):
    """min ½ zᵀMz − cᵀz s.t. Gz ≥ h: the feasible equality-constrained minimiser of least
    objective over every subset of the rows held as equalities (M positive definite)."""
    best, best_f = None, math.inf
    for k in range(len(h) + 1):
        for rows in itertools.combinations(range(len(h)), k):
            C = G[list(rows)]
            n = M.shape[0]
            K = np.block([[M, C.T], [C, np.zeros((k, k))]])
            z = np.linalg.solve(K, np.concatenate([c, h[list(rows)]]))[:n]
            if np.all(G @ z >= h - 1e-10):
                f = 0.5 * z @ M @ z - c @ z
                if f < best_f:
                    best, best_f = z, f
    return best


@pytest.mark.parametrize("seed", range(5))
def test_inequalities_are_solved_as_the_enumerated_kkt_solution(seed):
    rng = np.random.default_rng(seed)
    p = 5
    X = rng.standard_normal((60, p))
    y = X @ rng.standard_normal(p) + 0.3 + 0.1 * rng.standard_normal(60)
    Xb = np.column_stack([X, np.ones(60)])
    A, b = Xb.T @ Xb, Xb.T @ y
    G = rng.standard_normal((3, p + 1))
    h = G @ np.linalg.lstsq(Xb, y, rcond=None)[0] + rng.uniform(0.1, 1.0, 3)  # all violated
    with warnings.catch_warnings():
        # SLSQP stops with "positive directional derivative" in some of these at the optimum;
        # the polish's KKT multipliers certify it, so no warning.
        warnings.simplefilter("error", NumericalWarning)
        coef, bias, _ = solve_primal_constrained(A, b, math.inf, inequalities=(G, h))
    expected = _kkt_by_enumeration(A, b, G, h)
    np.testing.assert_allclose(np.append(coef, bias), expected, rtol=1e-7, atol=1e-9)
    # Met already: the plain solution, untouched.
    loose = h - 10.0
    coef0, bias0, _ = solve_primal_constrained(A, b, math.inf)
    coef1, bias1, _ = solve_primal_constrained(A, b, math.inf, inequalities=(G, loose))
    np.testing.assert_array_equal(np.append(coef1, bias1), np.append(coef0, bias0))


@pytest.fixture(scope="module")
def unstable_logs():
    truth = yaw_damped_ship(-0.5)  # det A = 0.3 − 0.45 < 0 at u = 1: an eigenvalue at +0.12 1/s
    assert max(_sway_yaw_eigenvalues(truth, 1.0).real) == pytest.approx(0.1227, abs=1e-3)
    return _logs(truth)


def test_an_unstable_ship_is_fitted_barely_stable_at_the_approach(unstable_logs):
    u0 = float(unstable_logs[0]["u"].iloc[0])
    free = identify(unstable_logs, model=STRUCTURE, gamma=1e6)
    assert max(_sway_yaw_eigenvalues(free.model, u0).real) > 0.1  # the data say unstable
    fit = identify(unstable_logs, model=STRUCTURE, gamma=1e6, physics=PhysicsOptions(stable=True))
    a11 = linearise(fit.model, u0)["A"][1, 1]
    largest = max(_sway_yaw_eigenvalues(fit.model, u0).real)
    assert largest == pytest.approx(-STABILITY_MARGIN * abs(a11), rel=1e-5)
    assert any("held at its limit" in w for w in fit.warnings)
    # The sway equation is fitted as without the constraint; only the yaw one moves.
    assert fit.model.coefficients["v"] == pytest.approx(free.model.coefficients["v"], rel=1e-9)
    assert fit.physics["stable"] is True


def test_a_stable_ship_is_fitted_as_without_the_constraint():
    logs = _logs(yaw_damped_ship(-1.2))
    free = identify(logs, model=STRUCTURE, gamma=1e6)
    fit = identify(logs, model=STRUCTURE, gamma=1e6, physics=PhysicsOptions(stable=True))
    for dof in "uvr":
        assert fit.model.coefficients[dof] == pytest.approx(free.model.coefficients[dof],
                                                            rel=1e-8, abs=1e-12)  # fmt: skip
    assert not any("held at its limit" in w for w in fit.warnings)


def test_the_bootstraps_refit_keeps_the_constraint_to_the_bit(unstable_logs):
    physics = PhysicsOptions(stable=True)
    refit = weighted_refit(unstable_logs, model=STRUCTURE, gamma=1e6, physics=physics)
    weights = block_weights([len(log) - 1 for log in unstable_logs], 50, np.random.default_rng(1))
    ours = refit(weights)
    theirs = identify(unstable_logs, model=STRUCTURE, gamma=1e6, physics=physics,
                      sample_weight=weights).model  # fmt: skip
    assert ours.coefficients == theirs.coefficients


def test_cli_identify_and_select_take_the_stability_constraint(unstable_logs, tmp_path, capsys):
    paths = [write_log(log, tmp_path / f"zz{i}.csv") for i, log in enumerate(unstable_logs)]
    code, out, err = run(["identify", *paths, "--model", STRUCTURE, "--gamma", "1e6",
                          "--constraints", "stable", "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "held at its limit" in err and "straight-line stable" in out
    # The stepwise search tries yaw equations without v and r terms, which cannot be stable:
    # such a candidate is dropped (it stopped the whole search).
    code, out, err = run(["select", *paths, "--library", STRUCTURE, "--constraints", "stable",
                          "--quiet", "--table", tmp_path / "t.csv", "-o", tmp_path / "s.json"],
                         capsys)  # fmt: skip
    assert code == 0, err
    table = pd.read_csv(tmp_path / "t.csv")
    assert (table["note"] == "the constraints cannot be met with these terms").any()
    assert table.loc[table["chosen"], "score"].iloc[0] < math.inf


def test_stability_that_bounds_forbid_is_one_line(unstable_logs, tmp_path, capsys):
    paths = [write_log(log, tmp_path / f"zz{i}.csv") for i, log in enumerate(unstable_logs)]
    # u·r ≥ 1 makes ∂ṙ/∂r ≥ u0 > |∂v̇/∂v|: the trace cannot be negative.
    code, _, err = run(["identify", *paths, "--model", STRUCTURE, "--constraints", "stable",
                        "--bound", "r: u*r >= 1", "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    lines = [ln for ln in err.splitlines() if not ln.startswith("warning:")]
    assert code == 1 and len(lines) == 1 and "constraints conflict" in lines[0], err
    assert not (tmp_path / "m.json").exists()


def test_straight_running_slopes_are_the_analytic_ones_kinks_included():
    from shipid.identification.physics import _straight_running_slopes

    texts = ["|v|*v", "|r|*r", "u*v", "|v|*r", "v*|n|", "U*r", "u^2*delta", "r"]
    slopes = _straight_running_slopes(texts, 1.5, 10.0)
    np.testing.assert_allclose(slopes[0], [0, 0, 1.5, 0, 10.0, 0, 0, 0], atol=1e-8)
    np.testing.assert_allclose(slopes[1], [0, 0, 0, 0, 0, 1.5, 0, 1.0], atol=1e-8)

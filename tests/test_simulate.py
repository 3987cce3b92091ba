"""Models, simulator and steering machine against hand computations and closed forms."""

import math
import warnings

import numpy as np
import pytest

from shipid.data.log import make_log
from shipid.dynamics.model import ManoeuvringModel, get_structure, nomoto_parameters
from shipid.dynamics.simulate import simulate, simulate_batch, simulate_log
from shipid.dynamics.steering import SteeringMachine
from shipid.errors import ShipidError
from shipid.vessels import scale_ship_model

# Every operation of the term algebra, on every kind of signal (states, derived, inputs, wind).
TERMS = ("1", "u", "v", "r", "|u|u", "vr", "r^2", "ur", "uv", "|v|v", "|v|r", "|r|r", "|r|v",
         "delta", "delta^2", "T", "u^2*delta", "|n|n", "un", "|n|n*delta", "U^2", "beta*U",
         "pos(n)^2*delta", "neg(n)^2", "u*|v|*r", "delta^3", "sin(2*beta)*U",
         "U_A^2*cos(gamma_A)", "U_A^2*sin(2*gamma_A)", "cos(delta)^2*v")  # fmt: skip


class Wrapped:
    """A ManoeuvringModel seen only through the Dynamics protocol: forces the generic NumPy path."""

    def __init__(self, model):
        self.model, self.uses_thrust, self.uses_rps = model, model.uses_thrust, model.uses_rps

    def derivatives(self, nu, delta, thrust=None, rps=None, **inputs):
        return self.model.derivatives(nu, delta, thrust, rps, **inputs)


def all_terms_model(seed=0):
    rng = np.random.default_rng(seed)
    structure = get_structure("blanke")
    structure = type(structure)("all", {d: TERMS for d in ("u", "v", "r")})
    coefs = {d: {n: float(c) for n, c in zip(TERMS, 0.05 * rng.normal(size=len(TERMS)), strict=True)}
             for d in ("u", "v", "r")}  # fmt: skip
    return ManoeuvringModel(structure, coefs)


def test_euler_step_matches_hand_computation():
    m = scale_ship_model()
    u, v, r, psi, d, h = 1.9, 0.05, -0.1, 0.3, math.radians(20), 0.2
    res = simulate(m, [0.0, h], [d, d], {"u": u, "v": v, "r": r, "psi": psi}, method="euler")
    udot = -0.0321 * abs(u) * u - 2.7053 * v * r - 0.2257 * d * d + 0.12
    vdot = (-0.4531 * u * r - 0.5284 * u * v + 0.5354 * abs(v) * v - 0.4121 * abs(v) * r
            + 0.0520 * d + 0.0007)  # fmt: skip
    rdot = (-1.1699 * u * r - 0.6696 * u * v + 2.3001 * abs(v) * v + 3.9335 * abs(v) * r
            - 0.5503 * d - 0.0054)  # fmt: skip
    expected = [u + h * udot, v + h * vdot, r + h * rdot, psi + h * r,
                h * (u * math.cos(psi) - v * math.sin(psi)),
                h * (u * math.sin(psi) + v * math.cos(psi))]  # fmt: skip
    got = res.log.iloc[1][["u", "v", "r", "psi", "x", "y"]].to_numpy(float)
    np.testing.assert_allclose(got, expected, rtol=1e-14, atol=1e-15)


def test_compiled_kernel_equals_numpy_evaluation_of_every_term():
    m = all_terms_model()
    rng = np.random.default_rng(1)
    states = rng.normal(size=(200, 3)) * [1.0, 0.3, 0.1] + [0.5, 0, 0]
    inputs = rng.normal(size=(200, 5)) * [0.4, 5.0, 10.0, 3.0, 2.0]  # δ, n, T, U_A, γ_A
    compiled = m.compiled_accelerations(states, inputs)
    numpy = m.accelerations(*states.T, inputs[:, 0], inputs[:, 2], inputs[:, 1],
                            wind_speed=inputs[:, 3], wind_angle=inputs[:, 4])  # fmt: skip
    np.testing.assert_allclose(compiled, numpy, rtol=1e-12, atol=1e-14)


def test_the_kernels_table_holds_each_factor_once_and_rows_of_one_length():
    from shipid.dynamics.terms import term_code

    code = term_code(["1", "u", "|u|u", "u*|v|*r", "|v|v", "u*v"])
    rows, sig, op, k, power, _ = code.arrays()
    factors = list(zip(sig.tolist(), op.tolist(), k.tolist(), power.tolist(), strict=True))
    assert len(code.signal) == 10
    assert len(factors) == len(set(factors)) == 5  # u, |u|, |v|, r, v
    per_term = np.diff(code.start).tolist()
    assert per_term == [0, 1, 2, 3, 2, 2] and rows.shape == (6, 3)
    # Each row: the term's own factors in its order, then the index past the distinct ones
    # (the kernel's factor that reads 1).
    for j, n in enumerate(per_term):
        own = [(int(code.signal[f]), int(code.op[f]), float(code.k[f]), int(code.power[f]))
               for f in range(code.start[j], code.start[j + 1])]  # fmt: skip
        assert [factors[i] for i in rows[j, :n]] == own
        assert (rows[j, n:] == len(factors)).all()


def test_a_term_without_a_coefficient_is_never_evaluated():
    # A wind term held at 0 in every equation: a log without the wind reads it as NaN, which
    # 0·NaN would carry into every acceleration.
    terms = ("ur", "uv", "delta", "U_A^2*cos(gamma_A)")
    coefs = {"u": {"ur": 0.0, "uv": 0.0, "delta": -0.1, "U_A^2*cos(gamma_A)": 0.0},
             "v": {"ur": -0.4, "uv": -0.5, "delta": 0.05, "U_A^2*cos(gamma_A)": 0.0},
             "r": {"ur": -1.2, "uv": -0.7, "delta": -0.5, "U_A^2*cos(gamma_A)": 0.0}}
    m = ManoeuvringModel(type(get_structure("blanke"))("held", {d: terms for d in "uvr"}), coefs)
    states = np.array([[1.0, 0.1, -0.05], [0.8, -0.2, 0.1]])
    inputs = np.array([[0.3, 0.0, 0.0, np.nan, np.nan], [-0.2, 0.0, 0.0, np.nan, np.nan]])
    u, v, r = states.T
    want = np.column_stack([-0.1 * inputs[:, 0],
                            -0.4 * u * r - 0.5 * u * v + 0.05 * inputs[:, 0],
                            -1.2 * u * r - 0.7 * u * v - 0.5 * inputs[:, 0]])  # fmt: skip
    np.testing.assert_allclose(m.compiled_accelerations(states, inputs), want, rtol=1e-14)


def test_compiled_simulation_equals_the_numpy_path():
    m = ManoeuvringModel(type(get_structure("blanke"))("no wind", {
        d: tuple(x for x in TERMS if "gamma_A" not in x) for d in ("u", "v", "r")}),
        {d: {n: c for n, c in all_terms_model().coefficients[d].items() if "wind" not in n}
         for d in ("u", "v", "r")})  # fmt: skip
    t = np.arange(0, 5, 0.1)
    d = 0.3 * np.sin(t)
    thrust = 1 + 0.1 * np.cos(t)
    rps = 2 + 0.3 * np.sin(0.7 * t)
    for method in ("euler", "rk4"):
        a = simulate(m, t, d, {"u": 1.0, "v": 0.1, "r": 0.05}, thrust=thrust, method=method,
                     rps=rps)  # fmt: skip
        b = simulate(Wrapped(m), t, d, {"u": 1.0, "v": 0.1, "r": 0.05}, thrust=thrust,
                     method=method, rps=rps)  # fmt: skip
        np.testing.assert_allclose(a.log.to_numpy(), b.log.to_numpy(), rtol=1e-12, atol=1e-14)


def test_rk4_converges_at_fourth_order():
    # Smooth right-hand side: the |v| terms have a kink at v = 0, which the sway crosses.
    coefs = {dof: dict(c) for dof, c in scale_ship_model().coefficients.items()}
    for dof in ("v", "r"):
        coefs[dof]["|v|v"] = coefs[dof]["|v|r"] = 0.0
    m = ManoeuvringModel("blanke", coefs)
    d = math.radians(15)

    def final_state(h):
        t = np.linspace(0, 10, int(round(10 / h)) + 1)
        return simulate(m, t, np.full(t.size, d), {"u": 1.9}).log.iloc[-1][["u", "v", "r", "psi"]]

    ref = final_state(0.005).to_numpy(float)
    e1 = np.linalg.norm(final_state(0.1).to_numpy(float) - ref)
    e2 = np.linalg.norm(final_state(0.05).to_numpy(float) - ref)
    assert 14 < e1 / e2 < 19  # 2⁴ = 16 (measured 17.7: still approaching the asymptote)


def test_divergence_is_reported_with_its_time_and_no_nan_tail():
    unstable = ManoeuvringModel("nomoto1", {"r": {"r": 2.0, "delta": 1.0}})
    t = np.arange(0, 100, 0.1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        res = simulate(unstable, t, np.full(t.size, 0.1), {"u": 1.0})
        wrapped = simulate(Wrapped(unstable), t, np.full(t.size, 0.1), {"u": 1.0})
    assert res.diverged and 0 < res.diverged_at < 100
    assert res.diverged_at == pytest.approx(wrapped.diverged_at)
    assert np.all(np.isfinite(res.log.to_numpy()))
    assert res.log["t"].iloc[-1] < res.diverged_at
    assert "diverged at t =" in res.reason
    # r grows as e^{2t}: the yaw-rate bound of 5 rad/s is crossed near t = ln(1 + 5·2/0.1)/2.
    assert res.diverged_at == pytest.approx(math.log(1 + 5 * 2 / 0.1) / 2, abs=0.25)


def test_held_degrees_of_freedom_stay_constant_in_nomoto_models():
    m = ManoeuvringModel("nomoto1", {"r": {"r": -1 / 5.0, "delta": 0.1 / 5.0}})
    t = np.arange(0, 60, 0.05)
    res = simulate(m, t, np.full(t.size, 0.2), {"u": 2.0, "v": 0.0})
    assert np.all(res.log["u"] == 2.0) and np.all(res.log["v"] == 0.0)
    # Step response of T ṙ + r = K δ: r(t) = K δ (1 − e^{−t/T}).
    np.testing.assert_allclose(res.log["r"], 0.1 * 0.2 * (1 - np.exp(-t / 5.0)), rtol=1e-6,
                               atol=1e-9)  # fmt: skip


def test_batch_equals_single_runs():
    m = scale_ship_model()
    t = np.arange(0, 20, 0.2)
    rng = np.random.default_rng(2)
    deltas = 0.3 * rng.uniform(-1, 1, size=(5, t.size))
    u0 = rng.uniform(1.5, 2.0, size=5)
    init = np.column_stack([u0, np.zeros((5, 5))])
    batch = simulate_batch(m, t, deltas, init)
    for i in range(5):
        single = simulate(m, t, deltas[i], {"u": u0[i]}).log
        np.testing.assert_allclose(batch.log(i).to_numpy(), single.to_numpy(), rtol=1e-13)


def test_batch_on_two_numba_threads_equals_single_runs():
    """The test workers run numba on one thread (conftest); the compiled batch's ``prange``
    on the threads a user's process has is checked here, in a process of its own."""
    import os
    import subprocess
    import sys

    code = """
import numba, numpy as np
from shipid.dynamics.simulate import simulate, simulate_batch
from shipid.vessels import scale_ship_model
assert numba.get_num_threads() == 2
m, t = scale_ship_model(), np.arange(0, 20, 0.2)
rng = np.random.default_rng(2)
deltas, u0 = 0.3 * rng.uniform(-1, 1, size=(64, t.size)), rng.uniform(1.5, 2.0, size=64)
batch = simulate_batch(m, t, deltas, np.column_stack([u0, np.zeros((64, 5))]))
print(max(float(np.max(np.abs(batch.log(i).to_numpy()
                              - simulate(m, t, deltas[i], {'u': u0[i]}).log.to_numpy())))
          for i in range(64)))
"""
    env = {**os.environ, "NUMBA_NUM_THREADS": "2"}
    out = subprocess.run([sys.executable, "-c", code], env=env, capture_output=True, text=True,
                         timeout=120)  # fmt: skip
    assert out.returncode == 0, out.stderr
    assert float(out.stdout) <= 1e-12


def test_simulate_log_replays_a_log():
    m = scale_ship_model()
    t = np.arange(0, 30, 0.2)
    d = np.where(t < 15, 0.3, -0.3)
    log = simulate(m, t, d, {"u": 1.9, "psi": 0.2}, method="euler").log
    again = simulate_log(m, log, method="euler").log
    np.testing.assert_allclose(again.to_numpy(), log.to_numpy(), rtol=1e-13)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"delta": np.zeros(5)}, "shorter than the time grid"),
        ({"delta": np.r_[np.zeros(3), np.nan, np.zeros(6)]}, "non-finite value at sample 3"),
        ({"t": np.r_[0, 1, 1, 2, 3, 4, 5, 6, 7, 8]}, "strictly increasing"),
        ({"initial": {"v": 0.0}}, "surge speed 'u'"),
        ({"method": "midpoint"}, "method"),
    ],
)
def test_bad_simulation_input_names_the_argument(kwargs, match):
    args = {"t": np.arange(10.0), "delta": np.zeros(10), "initial": {"u": 1.0}} | kwargs
    with pytest.raises(ValueError, match=match):
        simulate(scale_ship_model(), args.pop("t"), args.pop("delta"), args.pop("initial"), **args)


def test_discrete_form_round_trip_and_paper_gamma():
    m = scale_ship_model()
    g = m.to_discrete(0.2)
    assert m.regressor_names("u") == ["u", "|u|*u", "v*r", "r^2", "delta^2", "1"]
    np.testing.assert_allclose(g["u"], [1.0, 0.2 * -0.0321, 0.2 * -2.7053, 0.0, 0.2 * -0.2257,
                                        0.2 * 0.12])  # fmt: skip
    back = ManoeuvringModel.from_discrete(m.structure, g, 0.2)
    for dof in ("u", "v", "r"):
        for term, c in m.coefficients[dof].items():
            assert back.coefficients[dof][term] == pytest.approx(c, rel=1e-12, abs=1e-15)
    # A ξ(k) coefficient ≠ 1 becomes an explicit linear self term.
    g["v"][0] = 1.0 - 0.2 * 0.3
    back = ManoeuvringModel.from_discrete(m.structure, g, 0.2)
    assert back.coefficients["v"]["v"] == pytest.approx(-0.3)


def test_equations_print_in_the_paper_style():
    text = scale_ship_model().equations()
    assert "u̇ = −0.0321 |u|u − 2.7053 v r" in text
    assert "ṙ = −1.1699 u r − 0.6696 u v + 2.3001 |v|v + 3.9335 |v| r − 0.5503 δ − 0.0054" in text


def test_nomoto_parameters_reproduce_the_transfer_function():
    m = ManoeuvringModel("linear-sway-yaw", {"v": {"v": -1.0568, "r": -0.9062, "delta": 0.052},
                                             "r": {"v": -1.3392, "r": -2.3398, "delta": -0.5503}})
    p = nomoto_parameters(m)
    A = np.array([[-1.0568, -0.9062], [-1.3392, -2.3398]])
    b = np.array([0.052, -0.5503])
    for s in (0.1j, 1.0j, 0.5 + 2j):
        exact = np.linalg.solve(s * np.eye(2) - A, b)[1]
        nomoto = p["K"] * (1 + p["T3"] * s) / ((1 + p["T1"] * s) * (1 + p["T2"] * s))
        assert abs(exact - nomoto) < 1e-10 * abs(exact)


def test_steering_machine_rate_limit_and_lag():
    sm = SteeringMachine(max_angle=math.radians(35), max_rate=math.radians(10))
    t = np.arange(0, 5, 0.1)
    out = sm.apply(t, np.full(t.size, math.radians(20)))
    np.testing.assert_allclose(out[:20], math.radians(10) * 0.1 * np.arange(1, 21), rtol=1e-12)
    assert out[-1] == pytest.approx(math.radians(20))
    clipped = SteeringMachine().apply(t, np.full(t.size, math.radians(50)))
    assert np.all(clipped == pytest.approx(math.radians(35)))
    lag = SteeringMachine(time_constant=2.0).apply(t, np.full(t.size, 0.5))
    np.testing.assert_allclose(lag, 0.5 * (1 - np.exp(-(t + 0.1) / 2.0)), rtol=1e-12)
    with pytest.raises(ValueError, match="max_rate"):
        SteeringMachine(max_rate=0.0)


def test_rudder_execute_found_after_helm_corrections_and_trim_auto():
    from shipid.data.trim import manoeuvre_end_time, rudder_execute_time, trim

    t = np.arange(0, 80, 0.1)
    helm = np.radians(6) * np.sin(2 * np.pi * t / 9)  # hand steering, never steady
    delta = np.where(t < 30.0, helm, 0.0)
    ramp = np.clip((t - 30.0) * np.radians(10), 0, np.radians(20))
    delta = np.where(t >= 30.0, np.where(t < 50.0, ramp, -np.radians(20)), delta)
    delta[t >= 70.0] = 0.0  # manoeuvre over, rudder amidships
    n = np.where(t < 75.0, 12.0, 0.0)
    log = make_log({"t": t, "delta": delta, "u": np.ones_like(t), "v": 0 * t, "r": 0 * t, "n": n})
    assert rudder_execute_time(log) == pytest.approx(30.0, abs=0.11)
    assert manoeuvre_end_time(log) == pytest.approx(69.9, abs=0.11)
    cut = trim(log, "auto", "auto", lead=4.0)
    assert cut["t"].iloc[0] == pytest.approx(26.0, abs=0.11)
    assert cut["t"].iloc[-1] == pytest.approx(69.9, abs=0.11)
    with pytest.raises(ShipidError, match="--start must be a time in seconds or 'auto'"):
        trim(log, "soon")


def test_gaps_are_reported_with_their_span_or_interpolated(tmp_path):
    from shipid.data.io import read_log

    t = np.arange(0, 10, 0.5)
    u = 1.0 + 0.1 * t
    rows = ["t,delta,u,v,r"] + [f"{a},0.01,{'' if 4 <= i <= 6 else b},0,0"
                                for i, (a, b) in enumerate(zip(t, u, strict=True))]
    path = tmp_path / "gap.csv"
    path.write_text("\n".join(rows) + "\n")
    with pytest.raises(ShipidError, match=r"column 'u' has 3 missing values at data rows 5–7 "
                                          r"\(t = 2–3\).*--fill-gaps"):
        read_log(path)
    filled = read_log(path, fill_gaps=True)
    np.testing.assert_allclose(filled["u"], u, rtol=1e-12)  # linear in t: exact

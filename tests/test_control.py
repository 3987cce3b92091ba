"""The model put to work (issue #12 item 7): linearisation, Nomoto parameters, autopilot, path
following on the true ship, and the exports against the simulator."""

import importlib.util
import math

import numpy as np
import pytest
from cli_helpers import run

from shipid import identify, lowpass, zigzag
from shipid.control.autopilot import follow_path, heading_step, pid_from_nomoto
from shipid.control.export import export_numpy, linearised_control, to_control
from shipid.control.linear import linearise, nomoto, trim
from shipid.dynamics.model import (
    ManoeuvringModel,
    ModelStructure,
    nomoto_parameters,
    sway_yaw_nomoto,
)
from shipid.dynamics.simulate import simulate
from shipid.errors import ShipidError
from shipid.vessels import PAPER_IMU, scale_ship, scale_ship_model

TRUTH = scale_ship(rudder_rate_deg=9.6)


def test_linearisation_of_the_paper_model_against_its_coefficients():
    """At v = r = 0 only u·v, u·r and δ have a slope: A = u0 [[Y_uv, Y_ur], [N_uv, N_ur]]
    (reference-ships.md §7.2 gives it at 2 m/s), B = [Y_δ, N_δ]; surge: ∂u̇/∂u = 2 X_|u|u u0."""
    m, u0 = scale_ship_model(), 2.0
    cv, cr = m.coefficients["v"], m.coefficients["r"]
    lin = linearise(m, u0, trimmed=False)  # the reference's point: rudder amidships
    expected = u0 * np.array([[cv["uv"], cv["ur"]], [cr["uv"], cr["ur"]]])
    np.testing.assert_allclose(lin["A"][1:, 1:], expected, rtol=1e-6)
    np.testing.assert_allclose(lin["A"][1:, 1:], [[-1.0568, -0.9062], [-1.3392, -2.3398]],
                               atol=5e-5)  # fmt: skip
    assert lin["A"][0, 0] == pytest.approx(2 * -0.0321 * u0, rel=1e-7)
    np.testing.assert_allclose(lin["B"][1:], [cv["delta"], cr["delta"]], rtol=1e-7)
    # Nomoto of the linear sway-yaw model with the same A, B (closed form in model.py).
    lsy = ManoeuvringModel("linear-sway-yaw", {
        "v": {"v": expected[0, 0], "r": expected[0, 1], "delta": cv["delta"]},
        "r": {"v": expected[1, 0], "r": expected[1, 1], "delta": cr["delta"]}})  # fmt: skip
    ref, got = nomoto_parameters(lsy), nomoto(m, u0)
    for k in ("K", "T1", "T2", "T3"):  # trimmed at 0.6° of rudder: the same to 1e-3
        assert got[k] == pytest.approx(ref[k], rel=1e-3)
    assert got["K"] == pytest.approx(-0.517, abs=0.002)  # §7.2: steady r/δ = −0.517


# A sway–yaw pair with complex poles (tr −1.1, det 1.1) and one with real poles (the paper's
# ship's at 2 m/s, reference-ships.md §7.2).
OSCILLATORY = np.array([[-0.5, -1.0], [0.8, -0.6]])
REAL = np.array([[-1.0568, -0.9062], [-1.3392, -2.3398]])


@pytest.mark.parametrize("A", [OSCILLATORY, REAL], ids=["oscillatory", "real"])
def test_nomotos_k_t3_and_first_order_t_hold_for_complex_poles_too(A):
    """Against the transfer function G(s) = r/δ = [0 1] (sI − A)⁻¹ b itself: K = G(0), the
    first-order T = −G′(0)/G(0) (central difference), T3 from G's zero at s = −1/T3, the poles' natural
    frequency and damping ratio from A's eigenvalues; T1, T2 only where the poles are real."""
    b = np.array([0.12, -0.35])

    def transfer(s):
        return np.linalg.solve(s * np.eye(2) - A, b)[1]

    got = sway_yaw_nomoto(A, b)
    h = 1e-6
    assert got["K"] == pytest.approx(transfer(0.0), rel=1e-12)
    slope = (transfer(h) - transfer(-h)) / (2 * h)
    assert got["T"] == pytest.approx(-slope / transfer(0.0), rel=1e-6)
    assert abs(transfer(-1.0 / got["T3"])) < 1e-12
    lam = np.linalg.eigvals(A)
    assert got["natural_frequency"] == pytest.approx(math.sqrt(abs(lam[0] * lam[1])), rel=1e-12)
    assert got["stable"]
    if np.iscomplexobj(lam) and abs(lam[0].imag) > 0:
        assert got["oscillatory"] and got["T1"] is None and got["T2"] is None
        assert got["damping_ratio"] == pytest.approx(-lam[0].real / abs(lam[0]), rel=1e-12)
    else:
        assert not got["oscillatory"]
        assert [got["T1"], got["T2"]] == pytest.approx(sorted(-1.0 / lam.real, reverse=True))
        assert got["T"] == pytest.approx(got["T1"] + got["T2"] - got["T3"], rel=1e-12)
        assert got["damping_ratio"] > 1.0


def test_nomoto_parameters_of_an_oscillatory_model_give_no_real_time_constants():
    """Its T1, T2 came out as the real parts of complex time constants, with no word."""
    lsy = ManoeuvringModel("linear-sway-yaw", {"v": {"v": -0.5, "r": -1.0, "delta": 0.12},
                                               "r": {"v": 0.8, "r": -0.6, "delta": -0.35}})
    got = nomoto_parameters(lsy)
    assert got["T1"] is None and got["T2"] is None
    assert got["K"] == pytest.approx(sway_yaw_nomoto(OSCILLATORY, [0.12, -0.35])["K"])


def test_cli_linearise_and_autopilot_of_a_model_whose_sway_and_yaw_oscillate(tmp_path, capsys):
    """`linearise` refused such a model outright (one Esso Osaka zig-zag file's default fit is
    one): it now gives A, B, K, T3 and the first-order T, with the poles said."""
    m = scale_ship_model()
    coefficients = {d: dict(c) for d, c in m.coefficients.items()}
    coefficients["r"]["u*v"] = abs(coefficients["r"]["u*v"])  # complex sway–yaw poles
    model = ManoeuvringModel(m.structure, coefficients)
    path = tmp_path / "m.json"
    model.save(path)
    nm = nomoto(model, 1.93)
    assert nm["oscillatory"] and nm["stable"]
    code, out, err = run(["linearise", path, "--speed", "1.93"], capsys)
    assert code == 0, err
    assert "A =" in out and "the sway–yaw poles are a complex pair" in out
    assert f"K = {nm['K']:.5g} 1/s" in out and f"first order T = T1 + T2 − T3 = {nm['T']:.5g} s" in out
    code, out, err = run(["autopilot", path, "--speed", "1.93", "--heading", "20"], capsys)
    assert code == 0, err
    assert "the PID is tuned on its first-order Nomoto approximation" in err


def test_the_linearisation_is_about_the_trimmed_straight_run():
    """Bug: about (v = 0, δ = 0), where a model with constant sway and yaw terms (every
    identified one; a single screw's race) does not run straight and the modulus terms have
    their kinks. The trim against its closed form: for v̇ = a v + c|v|v + b δ + e and
    ṙ = f v + g δ + k at r = 0, δ0 = −(k + f v0)/g with v0 the root of the quadratic."""
    a, c, b, e, f, g, k = -0.8, -2.0, 0.05, 0.002, -0.6, -0.5, -0.004
    m = ManoeuvringModel(ModelStructure("kinked", {"v": ("v", "|v|*v", "delta", "1"),
                                                   "r": ("v", "r", "delta", "1")}),
                         {"v": {"v": a, "|v|*v": c, "delta": b, "1": e},
                          "r": {"v": f, "r": -1.0, "delta": g, "1": k}})  # fmt: skip
    # v̇ = 0 with δ0 = −(k + f v0)/g: (a − b f/g) v0 + c|v0|v0 + e − b k/g = 0.
    p, q = a - b * f / g, e - b * k / g
    roots = [x for x in np.roots([c, p, q]).real if x >= 0] + \
        [x for x in np.roots([-c, p, q]).real if x < 0]  # fmt: skip
    v0 = min(roots, key=abs)
    d0 = -(k + f * v0) / g
    lin = linearise(m, 1.5)
    assert lin["trim"]["v"] == pytest.approx(v0, rel=1e-9)
    assert lin["trim"]["delta"] == pytest.approx(d0, rel=1e-9)
    assert np.abs(lin["residual"][1:]).max() < 1e-12
    assert lin["A"][1, 1] == pytest.approx(a + 2 * c * abs(v0), rel=1e-6)  # |v|v's slope there
    amidships = linearise(m, 1.5, trimmed=False)
    assert amidships["trim"] is None and amidships["A"][1, 1] == pytest.approx(a, rel=1e-6)
    assert abs(amidships["residual"][2]) > 1e-3  # not a straight run: it turns
    # A yaw moment no rudder within ±35° balances (δ0 = −k/g = 1.2 rad): no trim, amidships.
    strong = ManoeuvringModel(m.structure, {**m.coefficients,
                                            "r": {**m.coefficients["r"], "1": 0.6}})
    assert trim(strong, 1.5) is None and linearise(strong, 1.5)["trim"] is None


def test_pid_from_nomoto_places_the_closed_loop_poles():
    K, T, w, z = -0.5, 2.0, 0.4, 0.9
    pid = pid_from_nomoto(K, T, w, z)
    # T s³ + (1 + K Kd) s² + K Kp s + K Ki: roots of the closed loop with the integral.
    poly = [T, 1 + K * pid.kd, K * pid.kp, K * pid.ki]
    roots = np.roots(poly)
    # Two poles at ω(ζ ± i√(1−ζ²)), shifted by the slow integral pole (Ki = ω³T/10K).
    assert np.all(roots.real < 0)
    osc = roots[np.abs(roots.imag) > 0]
    assert np.abs(osc[0]) == pytest.approx(w, rel=0.15)
    assert pid.kp * K > 0 and pid.kd * K > 0  # the gains carry the sign of K


def test_a_heading_step_settles_on_the_ordered_heading():
    nm = nomoto(TRUTH, TRUTH.approach_speed)
    log = heading_step(TRUTH, pid_from_nomoto(nm["K"], nm["T"]), 20.0, duration=60, dt=0.05)
    assert math.degrees(log["psi"].iloc[-1]) == pytest.approx(20.0, abs=0.2)
    assert abs(math.degrees(log["delta"].iloc[-1])) < 2.0


def test_pid_tuned_on_an_identified_model_follows_a_path_on_the_true_ship():
    """Acceptance (#12): identified from one noisy 20/20 zig-zag (paper noise), the PID tuned on
    the model keeps the cross-track error of a 4-waypoint path on the true ship within 1.2× of
    the same controller tuned on the truth."""
    trial = PAPER_IMU.apply(zigzag(TRUTH, 20, 20, duration=90, dt=0.2, method="euler",
                                   approach=2.0).log, seed=1)  # fmt: skip
    model = identify(lowpass(trial, 0.5), drop={"u": ["r^2"]}).model
    u0 = TRUTH.approach_speed
    nm, nt = nomoto(model, u0), nomoto(TRUTH, u0)
    waypoints = [(0, 0), (60, 0), (60, 60), (0, 60)]
    lookahead = 2 * 4.389
    on_truth = {}
    for label, n in (("model", nm), ("truth", nt)):
        res = follow_path(TRUTH, pid_from_nomoto(n["K"], n["T"]), waypoints, lookahead, dt=0.1)
        assert res.completed and not res.diverged
        on_truth[label] = res.rms_cross_track
    assert on_truth["model"] <= 1.2 * on_truth["truth"]
    assert nm["K"] == pytest.approx(nt["K"], rel=0.1)


@pytest.mark.parametrize("method", ["euler", "rk4"])
def test_exports_reproduce_the_simulator(tmp_path, method):
    import control

    m = ManoeuvringModel(
        "u: |u|u, v*r, delta^2, |n|*n, 1; v: u*r, u*v, |v|v, pos(n)^2*delta, U^2*sin(2*beta), "
        "crossflow_sway(4); r: u*r, u*v, |v|r, delta, wind_speed^2*sin(2*wind_angle), 1, "
        "crossflow_yaw(4)",
        {"u": {"|u|u": -0.03, "v*r": -2.0, "delta^2": -0.2, "|n|*n": 1e-3, "1": 0.0},
         "v": {"u*r": -0.45, "u*v": -0.52, "|v|v": -0.5, "pos(n)^2*delta": 1e-4,
               "U^2*sin(2*beta)": 0.01, "crossflow_sway(4)": -0.3},
         "r": {"u*r": -1.17, "u*v": -0.67, "|v|r": 3.9, "delta": -0.55,
               "wind_speed^2*sin(2*wind_angle)": 1e-3, "1": -0.005,
               "crossflow_yaw(4)": -0.4}})  # fmt: skip
    t = np.arange(0, 60, 0.1)
    d, n = 0.3 * np.sign(np.sin(t / 8)), 5 + np.sin(t / 5)
    ws, wa = 2 + np.cos(t / 3), np.sin(t / 7)
    ref = simulate(m, t, d, {"u": 1.5}, rps=n, inputs={"wind_speed": ws, "wind_angle": wa},
                   method=method).log[["u", "v", "r", "psi", "x", "y"]].to_numpy()  # fmt: skip
    path = export_numpy(m, tmp_path / "exported.py")
    spec = importlib.util.spec_from_file_location("exported", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    text = path.read_text()
    assert "import shipid" not in text and "from shipid" not in text
    got = mod.simulate(t, np.column_stack([d, n, ws, wa]), [1.5, 0, 0, 0, 0, 0], method)
    np.testing.assert_allclose(got, ref, atol=1e-9, rtol=0)
    # u, v, r alone start at psi = x = y = 0; a wrong shape or method is named, not broadcast.
    short = mod.simulate(t, np.column_stack([d, n, ws, wa]), [1.5, 0, 0], method)
    np.testing.assert_array_equal(short, got)
    with pytest.raises(ValueError, match="state0: 4 values"):
        mod.simulate(t, np.column_stack([d, n, ws, wa]), [1.5, 0, 0, 0], method)
    with pytest.raises(ValueError, match=r"inputs: \(600,\) values for 600 times and 4"):
        mod.simulate(t, d, [1.5, 0, 0], method)
    with pytest.raises(ValueError, match="method must be 'euler' or 'rk4', got 'RK4'"):
        mod.simulate(t, np.column_stack([d, n, ws, wa]), [1.5, 0, 0], "RK4")
    sys = to_control(m, dt=0.1, method=method)
    resp = control.input_output_response(sys, t, np.vstack([d, n, ws, wa]), [1.5, 0, 0, 0, 0, 0])
    np.testing.assert_allclose(resp.states.T, ref, atol=1e-9, rtol=0)


def test_continuous_control_system_and_its_linearisation():
    import control

    m = scale_ship_model()
    sys = to_control(m)
    x = np.array([1.9, 0.05, -0.02, 0.3, 0.0, 0.0])
    got = sys.updfcn(0.0, x, np.array([0.1]), {})
    acc = m.accelerations(x[0], x[1], x[2], 0.1)[0]
    np.testing.assert_allclose(got[:3], acc, rtol=1e-14)
    ss = linearised_control(m, 2.0)
    assert isinstance(ss, control.StateSpace)
    np.testing.assert_allclose(ss.A, linearise(m, 2.0)["A"])


def test_cli_linearise_export_autopilot_follow(tmp_path, capsys):
    code, out, err = run(["linearise", "scale-ship"], capsys)
    assert code == 0 and "Nomoto: K = -0.53" in out
    # K's sign is the convention's (the paper's ship: positive rudder to port), said beside it.
    assert "input δ, positive to port;" in out
    path = tmp_path / "m.json"
    scale_ship_model().save(path)
    code, out, err = run(["export", path, "-o", tmp_path / "m.py"], capsys)
    assert code == 0 and (tmp_path / "m.py").exists()
    # Again, over the module it wrote: it was refused as "exists and is not a folder".
    code, out, err = run(["export", path, "-o", tmp_path / "m.py"], capsys)
    assert code == 0, err
    code, _, err = run(["export", path, "-o", tmp_path / "m.txt"], capsys)
    assert code == 1 and ".py file" in err
    code, out, err = run(["autopilot", path, "--speed", "1.93", "--truth", "scale-ship",
                          "--heading", "30", "-o", tmp_path / "ap.png"], capsys)  # fmt: skip
    assert code == 0, err
    assert "overshoot" in out and (tmp_path / "ap.png").exists()
    code, out, err = run(["follow", path, "--speed", "1.93", "--truth", "scale-ship",
                          "--waypoints", "0,0;40,0;40,40", "-o", tmp_path / "f.png",
                          "--json", tmp_path / "f.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "truth, model-tuned PID" in out and (tmp_path / "f.png").exists()
    code, _, err = run(["follow", path, "--speed", "1.93", "--waypoints", "0,0"], capsys)
    assert code == 1 and "two 'x,y' pairs" in err
    # Named before the model runs (the approach's warnings came after the error) and which.
    for bad, said in [("0,0;40,0;40,0", "waypoints 2 and 3 are the same point 40,0"),
                      ("0,0;inf,0", "must be finite")]:
        code, _, err = run(["follow", tmp_path / "absent.json", "--waypoints", bad], capsys)
        assert code == 1 and err.count("\n") == 1 and said in err, err


@pytest.mark.parametrize(("K", "T"), [(0.131, -18.58), (-31.24, -2401.0), (5.039, 344.8)])
def test_pid_from_nomoto_steers_unstable_and_nearly_neutral_ships(K, T):
    """KVLCC2 models have T < 0 (the MARIN-identified one −18.6 s, the MMG one −2401 s): tuning
    refused them. The placement holds for T < 0, at ω = max(1/|T|, √|K/T|) by default. The
    Esso Osaka model linearised at rudder amidships is nearly neutral (T = 345 s): at ω = 1/T its
    heading ran away."""
    pid = pid_from_nomoto(K, T)
    w = max(1 / abs(T), math.sqrt(abs(K / T)))
    # Without the integral: T s² + (1 + K Kd) s + K Kp = T (s² + 2ζω s + ω²).
    assert np.allclose(np.roots([T, 1 + K * pid.kd, K * pid.kp]),
                       np.roots([1, 2 * 0.9 * w, w * w]))  # fmt: skip
    assert np.all(np.roots([T, 1 + K * pid.kd, K * pid.kp, K * pid.ki]).real < 0)
    # Nomoto's model run free under the controller: ṙ = (Kδ − r)/T, δ = −(Kp ψ̃ + Ki∫ψ̃ + Kd r).
    model = ManoeuvringModel("nomoto1", {"r": {"r": -1 / T, "delta": K / T}})
    log = heading_step(model, pid, 20.0, speed=1.0, dt=0.2)
    assert not log.attrs["incomplete"]
    assert math.degrees(log["psi"].iloc[-1]) == pytest.approx(20.0, abs=0.4)


def test_a_heading_step_runs_until_a_full_scale_ship_settles():
    from shipid.dynamics.prime import froude_scaled

    big = froude_scaled(scale_ship_model(), 100.0)
    nm = nomoto(big, 19.3)
    pid = pid_from_nomoto(nm["K"], nm["T"])
    log = heading_step(big, pid, 20.0, speed=19.3, dt=0.5)
    assert not log.attrs["incomplete"] and log["t"].iloc[-1] > 120.0
    assert math.degrees(log["psi"].iloc[-1]) == pytest.approx(20.0, abs=0.4)
    short = heading_step(big, pid, 20.0, duration=60.0, speed=19.3, dt=0.5)
    assert "not settled within 60 s" in short.attrs["incomplete"]


def test_the_model_tuned_autopilot_is_mirrored_for_a_truth_of_the_other_rudder_sign(tmp_path,
                                                                                     capsys):
    """The scale ship's model turns to port with positive rudder, the reference KVLCC2 to
    starboard: its gains, unmirrored, steered the KVLCC2 to −149° for a 20° step."""
    import re

    path = tmp_path / "m.json"
    scale_ship_model().save(path)
    code, out, err = run(["autopilot", path, "--speed", "1.93", "--truth", "kvlcc2",
                          "--duration", "100"], capsys)  # fmt: skip
    assert code == 0, err
    assert "mirrored" in out
    over, final = re.search(r"kvlcc2 \(truth\): overshoot ([-\d.]+)°, final heading ([-\d.]+)°",
                            out).groups()  # fmt: skip
    # Steered toward the ordered heading (a controller for a faster ship: it overshoots), not
    # away from it (overshoot −20°, that is never beyond 0°).
    assert float(over) > 0 and float(final) > 0


def _windy_model() -> ManoeuvringModel:
    """The paper's model with wind loads: in still air, those of its own motion."""
    from shipid.dynamics.model import get_structure

    base = scale_ship_model()
    coefs = {d: dict(c) for d, c in base.coefficients.items()}
    coefs["u"]["wind_speed^2*cos(wind_angle)"] = -2e-3
    coefs["v"]["wind_speed^2*sin(wind_angle)"] = 4e-3
    coefs["r"]["wind_speed^2*sin(2*wind_angle)"] = -3e-3
    return ManoeuvringModel(base.structure + get_structure("wind"), coefs)


@pytest.mark.parametrize("ship", ["model", "windy model", "kvlcc2", "mariner"])
def test_the_compiled_heading_step_is_the_python_loop(ship):
    """The heading autopilot runs in the compiled closed loop (``kernel.MODE_HEADING``); the
    Python loop ``follow_path`` uses is its reference: same states to rounding (a 60° step)."""
    from shipid.control.autopilot import heading_loop
    from shipid.vessels import get_vessel

    target = {"model": scale_ship_model, "windy model": _windy_model}.get(ship, lambda: None)()
    speed = 1.93 if target is not None else None
    target = target if target is not None else get_vessel(ship)
    nm = nomoto(target, speed or target.approach_speed)
    pid = pid_from_nomoto(nm["K"], nm["T"])
    fast = heading_step(target, pid, 60.0, duration=150, speed=speed)
    slow = heading_loop(target, pid, 60.0, duration=150, speed=speed)
    assert len(fast) == len(slow) == 1501
    if ship == "model":  # its rudder saturates and the integral is frozen on the way
        assert np.degrees(np.abs(slow["delta"]).max()) == pytest.approx(35.0)
    for col in ("u", "v", "r", "psi", "x", "y", "delta"):
        np.testing.assert_allclose(fast[col], slow[col], rtol=1e-9, atol=1e-10, err_msg=col)


def test_path_following_runs_a_model_with_wind_terms():
    """``follow`` on the Esso Osaka model stopped with 'the model needs the input wind_speed':
    its Python loop gave a model with wind terms no wind. It now meets the apparent wind of its
    own motion, as the compiled closed loop does (the test above holds them equal)."""
    model = _windy_model()
    nm = nomoto(model, 1.93)
    res = follow_path(model, pid_from_nomoto(nm["K"], nm["T"]), [(0, 0), (60, 0), (60, 60)],
                      lookahead=15.0, speed=1.93)  # fmt: skip
    assert res.completed and not res.diverged and res.rms_cross_track < 5.0


def test_the_lookahead_follows_the_model_files_length(tmp_path, capsys):
    """A model file with particulars steered along with a 20 m lookahead whatever its size (a
    3 m model around a 20 m square: 13 m rms cross-track); the default is 2 L from them."""
    path = scale_ship_model().save(tmp_path / "m.json", particulars={"length": 5.0})
    code, out, err = run(["follow", path, "--speed", "1.93", "--waypoints", "0,0;40,0;40,40"],
                         capsys)  # fmt: skip
    assert code == 0, err
    assert "(lookahead 10 m, 2 L)" in out


@pytest.mark.parametrize("ship", ["model", "windy model", "kvlcc2", "mariner"])
def test_the_compiled_path_following_is_the_python_loop(ship):
    """Line-of-sight path following runs in the compiled closed loop (``kernel.MODE_FOLLOW``),
    cut where the path ends; the step-by-step loop is its reference: the same samples, states,
    ordered headings and cross-track errors to rounding, legs switched at the same steps."""
    from shipid.control.autopilot import follow_loop
    from shipid.vessels import get_vessel

    target = {"model": scale_ship_model, "windy model": _windy_model}.get(ship, lambda: None)()
    speed = 1.93 if target is not None else None
    target = target if target is not None else get_vessel(ship)
    scale = 30.0 if ship == "mariner" else 1.0
    waypoints = [(5.0 * scale, 5.0 * scale), (60.0 * scale, 0.0), (60.0 * scale, 60.0 * scale)]
    nm = nomoto(target, speed or target.approach_speed)
    pid = pid_from_nomoto(nm["K"], nm["T"])
    duration = 240.0 * (5.0 if ship == "mariner" else 1.0)
    fast = follow_path(target, pid, waypoints, 15.0 * scale, duration=duration, speed=speed)
    slow = follow_loop(target, pid, waypoints, 15.0 * scale, duration, speed=speed)
    assert fast.completed and slow.completed and not fast.diverged
    assert len(fast.log) == len(slow.log)
    for col in ("u", "v", "r", "psi", "x", "y", "delta", "psi_d", "cross_track"):
        np.testing.assert_allclose(fast.log[col], slow.log[col], rtol=1e-9, atol=1e-9,
                                   err_msg=col)  # fmt: skip
    assert fast.rms_cross_track == pytest.approx(slow.rms_cross_track, rel=1e-9)


def test_autopilot_and_follow_say_when_the_model_runs_beyond_its_training(tmp_path, capsys):
    """A controller tried on a model outside its trials is tried on a guess: a model from a
    10/10 zig-zag, steered through a 60° heading step with 32° of rudder, is named."""
    from shipid.data.io import write_log
    from shipid.vessels import scale_ship

    log = zigzag(scale_ship(rudder_rate_deg=9.6), 10, 10, duration=60, dt=0.2, approach=2).log
    train = write_log(log, tmp_path / "zz.csv")
    assert run(["identify", train, "-o", tmp_path / "m.json"], capsys)[0] == 0
    code, out, err = run(["autopilot", tmp_path / "m.json", "--heading", "60"], capsys)
    assert code == 0, err
    rudder = float(out.split("max rudder ")[1].split("°")[0])
    assert rudder > 1.2 * math.degrees(log["delta"].abs().max())
    assert "delta spans" in err and "outside the training range" in err
    code, out, err = run(["autopilot", tmp_path / "m.json", "--heading", "2"], capsys)
    assert code == 0 and "delta spans" not in err
    code, out, err = run(["follow", tmp_path / "m.json", "--waypoints", "0,0;60,0;60,60"],
                         capsys)  # fmt: skip
    assert code == 0 and "outside the training range" in err


def test_the_autopilot_steps_to_port_and_refuses_a_step_beyond_half_a_turn(tmp_path, capsys):
    """Its help said negative steps go to port, but --heading -20 was refused (a rule for the
    zig-zag's switch heading, > 0, read it); --heading 400 ran, turned the ship 40° and printed
    an overshoot of −359°, "not settled" after 1920 s."""
    path = tmp_path / "m.json"
    scale_ship_model().save(path)
    code, out, err = run(["autopilot", path, "--speed", "1.93", "--heading", "-20", "--duration",
                          "120"], capsys)  # fmt: skip
    assert code == 0, err
    final = float(out.split("final heading ")[1].split("°")[0])
    overshoot = float(out.split("overshoot ")[1].split("°")[0])
    assert final == pytest.approx(-20.0, abs=0.5) and 0.0 <= overshoot < 10.0
    for bad in ("400", "-180", "0", "nan"):
        code, _, err = run(["autopilot", path, "--speed", "1.93", "--heading", bad], capsys)
        assert code == 1 and "the heading step (--heading) must be within ±180° other than 0" in err, err


@pytest.mark.parametrize("side", ["port", "starboard"])
def test_the_exported_module_says_which_way_its_rudder_turns(tmp_path, capsys, side):
    """The standalone module had no word of its rudder convention, units or sampling: used
    without shipid, an Esso Osaka model (positive delta to starboard) steers a KVLCC2 user's
    autopilot (positive to port) the wrong way. It now says so, and holds it in RUDDER_POSITIVE:
    the module's own run with positive delta turns that way."""
    from shipid.data.io import write_log

    log = zigzag(scale_ship(), 20, 20, duration=60, dt=0.2, method="euler", approach=2.0).log
    if side == "starboard":  # the paper's ship turns to port with positive rudder
        log["delta"] = -log["delta"]
    log.attrs.update({"ship": "scale-ship", "rudder_positive": side})
    model = tmp_path / "m.json"
    assert run(["identify", write_log(log, tmp_path / "zz.csv"), "--model", "blanke",
                "--no-output-error", "-o", model], capsys)[0] == 0  # fmt: skip
    assert run(["export", model, "-o", tmp_path / "m.py"], capsys)[0] == 0
    spec = importlib.util.spec_from_file_location("exported_side", tmp_path / "m.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.RUDDER_POSITIVE == side
    assert f"positive delta turns the ship to {side}" in mod.__doc__
    assert "sampled at 0.2 s" in mod.__doc__
    t = np.arange(0, 30, 0.2)
    run_ = mod.simulate(t, np.full((len(t), 1), math.radians(20)), [2.0, 0, 0, 0, 0, 0])
    assert np.sign(run_[-1, 2]) == (1 if side == "starboard" else -1)


def test_a_leg_no_longer_than_the_acceptance_distance_is_refused():
    """A leg no longer than the acceptance distance (the lookahead's by default) was switched
    past as it started, and its run reported the later legs' cross-track errors as the path's:
    a model of CyberShip II (1.25 m) on 10 m legs at the 20 m default lookahead turned back
    along the last leg at once, 'completed'."""
    nm = nomoto(scale_ship_model(), 1.93)
    pid = pid_from_nomoto(nm["K"], nm["T"])
    with pytest.raises(ShipidError, match=r"leg 2 of the path \(10 m\) is no longer than the "
                       r"acceptance distance \(the lookahead, 12 m\)"):  # fmt: skip
        follow_path(scale_ship_model(), pid, [(0, 0), (40, 0), (40, 10), (0, 10)],
                    lookahead=12.0, speed=1.93)  # fmt: skip
    with pytest.raises(ShipidError, match=r"leg 1 .* \(acceptance, 50 m\)"):
        follow_path(scale_ship_model(), pid, [(0, 0), (40, 0), (40, 40)], lookahead=8.0,
                    acceptance=50.0, speed=1.93)  # fmt: skip
    # The last leg is never switched past: a short one is followed to its end.
    res = follow_path(scale_ship_model(), pid, [(0, 0), (40, 0), (40, 5)], lookahead=8.0,
                      speed=1.93)  # fmt: skip
    assert res.completed and not res.diverged


def test_a_model_without_a_length_is_steered_by_its_true_ships(tmp_path, capsys):
    """A model of CyberShip II whose file gives no length: the 20 m default lookahead made its
    10 m legs unfollowable. With --truth the true ship's length sets it (2 L = 2.51 m); without,
    the path is refused, naming --lookahead."""
    from shipid.vessels import cybership2

    ship = cybership2()
    path = ManoeuvringModel("blanke-speed", {
        "u": {"|u|u": -1.0, "vr": 3.4, "r^2": 2.7, "delta^2": -0.24, "1": 0.081},
        "v": {"ur": -1.88, "uv": -0.25, "|v|v": -1.0, "|v|r": -0.1, "u^2*delta": 0.33, "1": 0.0},
        "r": {"ur": -2.53, "uv": -2.27, "|v|v": 2.6, "|v|r": 1.0, "u^2*delta": -4.06, "1": 0.0},
    }).save(tmp_path / "cs2.json")  # fmt: skip
    assert ship.length == pytest.approx(1.255)
    square = ["--speed", "0.3", "--waypoints", "0,0;10,0;10,10;0,10"]
    code, out, err = run(["follow", path, "--truth", "cybership2", *square], capsys)
    assert code == 0, err
    assert "(lookahead 2.51 m, 2 L of cybership2, the --truth ship" in out
    rows = [line.split("|") for line in out.splitlines()
            if line.startswith(("| model ", "| truth"))]  # fmt: skip
    # rms cross-track [m] of all three runs on the 10 m square: 1.8–2.1 (7.7–8.6 at 20 m).
    assert len(rows) == 3 and all(float(row[2]) < 3.0 and "True" in row[4] for row in rows)
    code, out, err = run(["follow", path, *square], capsys)
    assert code == 1 and "leg 1 of the path (10 m) is no longer than the acceptance distance " \
        "(the lookahead, 20 m)" in err and "--lookahead" in err  # fmt: skip


@pytest.mark.parametrize(("eigenvalues", "said"), [
    ((0.0698, -0.402), "T2 -14.3 s"),  # the KVLCC2's MARIN fit: unstable, slow
    ((-0.0442, -0.9), ""),  # stable slow mode: the forms agree there (the paper's ship)
    ((0.2, -0.5), ""),  # unstable but not slow
    ((complex(0.01, 0.05), complex(0.01, -0.05)), ""),  # an oscillatory pair
    ((complex(0.05, 0.0), complex(-0.5, 0.0)), "T2 -20 s"),  # poles as complex numbers
])  # fmt: skip
def test_the_slow_mode_note_names_only_an_unstable_slow_real_mode(eigenvalues, said):
    """A fit's unstable slow mode rests on the hull terms' form (benchmarks/study_hull_form.py:
    the KVLCC2's runs T2 −14 to −19 s in moduli, −28 to −47 s cubic), said where it is one."""
    from shipid.identification.plausibility import slow_mode_note

    note = slow_mode_note(eigenvalues)
    assert (note.startswith("its slow mode, ") and said in note) if said else note == ""


def test_linearise_says_an_identified_models_slow_mode_rests_on_its_form(tmp_path, capsys):
    """A model identified from the KVLCC2's MMG zig-zag (course-unstable in a slow mode, as
    every fit of them: T2 about −25 s against the truth's −2398 s) carries the note; the
    reference ship itself, whose T2 is its published model's, does not."""
    from shipid.data.io import write_log
    from shipid.vessels import get_vessel
    from shipid.vessels.kvlcc2 import trimmed_revolutions

    ship = get_vessel("kvlcc2")
    log = zigzag(ship, 20, 20, duration=150, dt=0.2).log
    log = log.assign(n=trimmed_revolutions(ship.approach_speed))
    path = write_log(log, tmp_path / "zz.csv")
    code, out, err = run(["identify", path, "--model", "blanke-race+race-damping", "--filter",
                          "none", "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "straight-line UNSTABLE" in out and "its slow mode, T2 -2" in out
    code, out, err = run(["linearise", tmp_path / "m.json"], capsys)
    assert code == 0, err
    assert "Its slow mode, T2 -2" in out and "a spiral test measures it." in out
    code, out, err = run(["linearise", "kvlcc2"], capsys)
    assert code == 0 and "UNSTABLE" in out and "slow mode" not in out

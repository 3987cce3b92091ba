"""Logs with a measured thrust and no propeller speed: the default ``identify`` fits
``blanke-thrust`` (the thrust an input, as logged), and the commands that run the model along a
log take it, those that need a run of its own say why they cannot.

Before, a plain ``identify`` of such a log chose ``blanke-thrust`` and then failed in its own
checks ("the model needs the input 'thrust', which was not given"): the held turns and the
straight approach ran the model without a thrust. ``validate`` refused the log for its
closed-loop replica, and ``manoeuvre`` failed with the same message as ``identify``.
"""

import json

import numpy as np
import pytest
from cli_helpers import run

from shipid.data.io import read_log, write_log
from shipid.dynamics.model import ManoeuvringModel
from shipid.dynamics.simulate import simulate
from shipid.trials.manoeuvres import THRUST_REFUSED

# A ship whose surge balances its resistance against a thrust it is given (T in N, per its mass).
TRUTH = ManoeuvringModel(
    "u: |u|*u, T; v: u*v, u*r, u^2*delta; r: u*v, u*r, u^2*delta",
    {"u": {"|u|*u": -0.05, "T": 5e-4},
     "v": {"u*v": -0.6, "u*r": -0.3, "u^2*delta": 0.01},
     "r": {"u*v": -1.5, "u*r": -0.8, "u^2*delta": -0.008}})  # fmt: skip


def _log(phase: float, seconds: float = 150.0, dt: float = 0.1):
    """A 20°/20° zig-zag of the truth (first rudder positive, 10 °/s) under a thrust
    swinging 70–130 N: its rudder reversed where a hand-stepped run (Euler, ψ̇ = r) reaches
    ±20°, then the log simulated with that rudder."""
    t = np.arange(0.0, seconds, dt)
    thrust = 100.0 + 30.0 * np.sin(2 * np.pi * t / 55.0 + phase)
    order, rate = np.radians(20.0), np.radians(10.0) * dt
    nu, psi, delta, side = np.array([1.0, 0.0, 0.0]), 0.0, 0.0, 1.0
    rudder = np.zeros_like(t)
    for k in range(len(t)):
        if t[k] >= 5.0 and -side * psi >= order:  # positive rudder turns this ship to port
            side = -side
        target = side * order if t[k] >= 5.0 else 0.0
        delta += np.clip(target - delta, -rate, rate)
        rudder[k] = delta
        nu = nu + dt * TRUTH.accelerations(*nu, delta, thrust[k])[0]
        psi += dt * nu[2]
    return simulate(TRUTH, t, rudder, [1.0, 0, 0, 0, 0, 0], thrust=thrust, method="rk4").log


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("thrust")
    return [write_log(_log(p), folder / f"log{i}.csv") for i, p in enumerate((0.0, 1.3))]


def test_identify_fits_the_thrust_and_says_its_checks_need_one(files, tmp_path, capsys):
    out_file = tmp_path / "m.json"
    code, out, err = run(["identify", files[0], "--filter", "none", "--no-output-error", "-o",
                          out_file], capsys)  # fmt: skip
    assert code == 0, err
    assert "structure: blanke-thrust" in out
    assert "plausibility: not checked: the model is driven by the logs' thrust" in err
    surge = json.loads(out_file.read_text(encoding="utf-8"))["model"]["coefficients"]["u"]
    # Noise-free: the truth's thrust and resistance back, its absent terms near zero.
    assert surge["thrust"] == pytest.approx(5e-4, rel=0.02)
    assert surge["|u|*u"] == pytest.approx(-0.05, rel=0.02)
    # Judged on the other log, replayed with its thrust: no closed loop of its own.
    code, out, err = run(["validate", out_file, files[1]], capsys)
    assert code == 0, err
    assert "no closed-loop replica: the model is driven by the log's thrust" in err
    rmse_r = float(out.split("\n")[2].split("|")[4])
    assert rmse_r < 0.2 * np.std(read_log(files[1])["r"])
    # What needs a run of its own is refused in one line, and writes nothing.
    for argv in (["manoeuvre", out_file, "turning", "--json", tmp_path / "t.json"],
                 ["criteria", out_file, "--length", "3"], ["linearise", out_file]):  # fmt: skip
        code, out, err = run(argv, capsys)
        assert code == 1 and err.strip() == f"shipid: error: {THRUST_REFUSED}"
    assert not (tmp_path / "t.json").exists()


def test_two_thrust_logs_give_their_held_out_band(files, tmp_path, capsys):
    """From two logs the default band: each log replayed with its own thrust on the fit
    without it; a held-out zig-zag's indices measured, none predicted (no closed loop)."""
    code, out, err = run(["identify", *files, "--filter", "none", "--no-output-error", "-o",
                          tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    band = json.loads((tmp_path / "m.json").read_text(encoding="utf-8"))["identification"][
        "error_band"]  # fmt: skip
    assert [r["name"] for r in band["runs"]] == [str(f) for f in files]
    assert all(r["error_over_spread"]["r"] < 0.3 for r in band["runs"])
    zigzag = band["runs"][1]["indices"]
    assert set(zigzag) == {"first_overshoot_deg", "second_overshoot_deg"}
    assert all(measured > 0 and predicted is None for measured, predicted in zigzag.values())
    assert "overshoots 30, 51.1 → –, –" in out


def test_select_s_default_library_holds_the_logged_thrust(files, tmp_path, capsys):
    """Without --library, ``select`` of thrust logs without rps adds the thrust as logged (T)
    to its surge candidates, as ``identify``'s default fits ``blanke-thrust``: before, no
    candidate held it, the chosen model was implausible and predicted the held-out logs with
    0.8 of their spread; now the truth's surge comes back."""
    code, out, err = run(["select", *files, "-o", tmp_path / "s.json"], capsys)
    assert code == 0, err
    assert "the thrust T varies (70 to 130 N), and no rps is logged: the surge holds it" in err
    surge = json.loads((tmp_path / "s.json").read_text(encoding="utf-8"))["model"][
        "coefficients"]["u"]  # fmt: skip
    assert surge["thrust"] == pytest.approx(5e-4, rel=0.02)
    assert surge["|u|*u"] == pytest.approx(-0.05, rel=0.02)
    score = float(out.split("free-run CV score ")[1].split()[0])
    assert score < 0.05

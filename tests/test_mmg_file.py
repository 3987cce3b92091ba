"""A ship's own MMG model from a file (``shipid.vessels.mmg_file``): the KVLCC2's coefficients
written out reproduce the built-in, compiled KVLCC2; the file runs where a ``VESSEL`` does and
as the reference ``shipid correct`` keeps whole; bad files are named field by field."""

import importlib
import json
from pathlib import Path

import numpy as np
import pytest
import yaml
from cli_helpers import run, validated

from shipid.data.io import write_log
from shipid.errors import ShipidError
from shipid.trials.manoeuvres import turning_circle, zigzag
from shipid.vessels.mmg_file import mmg_vessel, read_mmg

K = importlib.import_module("shipid.vessels.kvlcc2")  # the module (shipid.vessels.kvlcc2 is
# the function that builds the ship)


def kvlcc2_document() -> dict:
    """The built-in KVLCC2's coefficients (reference-ships.md §2) as an MMG file holds them."""
    return {"format": "shipid-mmg", "name": "kvlcc2-file", "length": K.L, "beam": K.B,
            "draught": K.D_DRAUGHT, "volume": K.VOLUME, "x_g": K.XG, "k_zz": 0.25,
            "rho": K.RHO, "approach_speed": K.APPROACH_SPEED, "rudder_rate": K.RUDDER_RATE_DEG,
            "scale": K.SCALE,
            "hull": {"m_x": K.MX, "m_y": K.MY, "j_z": K.JZ, "r0": K.R0, "x_vv": K.XVV,
                     "x_vr": K.XVR, "x_rr": K.XRR, "x_vvvv": K.XVVVV, "y_v": K.YV, "y_r": K.YR,
                     "y_vvv": K.YVVV, "y_vvr": K.YVVR, "y_vrr": K.YVRR, "y_rrr": K.YRRR,
                     "n_v": K.NV, "n_r": K.NR, "n_vvv": K.NVVV, "n_vvr": K.NVVR, "n_vrr": K.NVRR,
                     "n_rrr": K.NRRR},
            "propeller": {"diameter": K.DP, "t_p": K.TP, "w_p0": K.WP0, "k0": K.K0, "k1": K.K1,
                          "k2": K.K2, "x_p": K.XP_PRIME, "c1": K.C1, "c2_pos": 1.6,
                          "c2_neg": 1.1},
            "rudder": {"area": K.AR, "height": K.HR, "t_r": K.TR, "a_h": K.AH,
                       "x_h": K.XH_PRIME, "x_r": K.XR_PRIME, "l_r": K.LR_PRIME,
                       "epsilon": K.EPS, "kappa": K.KAPPA, "f_alpha": K.F_ALPHA,
                       "gamma_r_pos": 0.640, "gamma_r_neg": 0.395}}  # fmt: skip


def mmg_file(path, **changes):
    """The KVLCC2's MMG file (``kvlcc2_document`` with ``changes``) written to ``path``."""
    path.write_text(yaml.safe_dump({**kvlcc2_document(), **changes}), encoding="utf-8")
    return path


def test_the_kvlcc2_written_out_is_the_built_in_kvlcc2():
    ship, built_in = mmg_vessel(kvlcc2_document()), K.kvlcc2()
    assert ship.dynamics.n_prop == pytest.approx(built_in.dynamics.n_prop, rel=1e-10)
    rng = np.random.default_rng(0)
    nu = np.column_stack([rng.uniform(0.3, 1.4, 200), rng.uniform(-0.3, 0.3, 200),
                          rng.uniform(-0.1, 0.1, 200)])  # fmt: skip
    delta = rng.uniform(-0.6, 0.6, 200)
    np.testing.assert_allclose(ship.dynamics.derivatives(nu, delta),
                               built_in.dynamics.derivatives(nu, delta), rtol=0, atol=1e-14)
    ours, theirs = (turning_circle(s, 35.0).indices for s in (ship, built_in))
    assert ours["tactical_diameter"] == pytest.approx(theirs["tactical_diameter"], rel=1e-9)


@pytest.mark.parametrize(("edit", "said"), [
    (lambda d: d.pop("volume"), "missing field 'volume'"),
    (lambda d: d["rudder"].pop("gamma_r_neg"), "missing field rudder.gamma_r_neg"),
    (lambda d: d.update(length=-7.0), "length must be > 0"),
    (lambda d: d["hull"].update(n_r="big"), "hull.n_r must be a finite number"),
    (lambda d: d.update(format="shipid-model"), "not an MMG model file"),
    (lambda d: d.pop("propeller"), "missing section 'propeller'"),
])  # fmt: skip
def test_a_bad_file_is_named_field_by_field(edit, said):
    doc = kvlcc2_document()
    edit(doc)
    with pytest.raises(ShipidError) as info:
        mmg_vessel(doc, "ship.yml")
    assert said in str(info.value) and str(info.value).startswith("ship.yml: ")


def test_the_file_runs_where_a_vessel_does_and_is_corrected(tmp_path, capsys):
    """``validate``, ``manoeuvre`` and ``correct`` take the file; the corrected ship's file
    holds the MMG model whole and runs without it."""
    path = mmg_file(tmp_path / "ship.yml")
    ship = read_mmg(path)
    log = zigzag(ship, 20, 20, duration=60, dt=0.2, method="euler").log
    log_path = write_log(log, tmp_path / "zz.csv")
    record = validated(path, log_path, capsys, tmp_path, "--method", "euler")
    assert max(record["metrics"][s]["rmse"] for s in "uvr") < 1e-9
    code, _, err = run(["validate", path, log_path, "--report", tmp_path / "rep"], capsys)
    report = (tmp_path / "rep" / "report.html").read_text()
    assert code == 0 and "hull: m_x 0.022" in report and "f_alpha 2.747" in report, err
    for argv in (["manoeuvre", path, "zigzag", "--rudder", "10"],
                 ["simulate", path, log_path, "-o", tmp_path / "sim.csv"]):  # fmt: skip
        code, out, err = run(argv, capsys)
        assert code == 0, (argv, err)
    code, out, err = run(["linearise", path], capsys)
    _, built_in, _ = run(["linearise", "kvlcc2"], capsys)
    assert code == 0 and out.splitlines()[-1] == built_in.splitlines()[-1]  # Nomoto alike
    corrected = tmp_path / "corrected.json"
    code, out, err = run(["correct", path, log_path, "-o", corrected], capsys)
    assert code == 0 and "kvlcc2-file kept whole" in out, err
    assert json.loads(corrected.read_text())["reference"]["mmg"]["name"] == "kvlcc2-file"
    path.unlink()  # the corrected ship needs the MMG file no more
    code, _, err = run(["validate", corrected, log_path], capsys)
    assert code == 0, err
    code, _, err = run(["correct", tmp_path / "nothing.yml", log_path, "-o",
                        tmp_path / "x.json"], capsys)  # fmt: skip
    assert code == 1 and err.count("\n") == 1 and "neither a reference ship" in err


def test_a_propeller_that_follows_the_logs_runs_at_each_logs_rate(tmp_path, capsys):
    """``rps: logs``: each run at the propeller speed its log (or --rps) gives, as the same
    ship with that constant rps runs; a manoeuvre at --rps starts from the straight-running
    speed there; a log whose propeller stops or reverses is refused in one line."""
    follow = mmg_vessel({**kvlcc2_document(), "rps": "logs"})
    assert follow.dynamics.uses_rps
    rng = np.random.default_rng(1)
    nu = np.column_stack([rng.uniform(0.5, 1.3, 50), rng.uniform(-0.2, 0.2, 50),
                          rng.uniform(-0.05, 0.05, 50)])  # fmt: skip
    delta, n = rng.uniform(-0.6, 0.6, 50), rng.uniform(6.0, 14.0, 50)
    at_each = np.vstack([mmg_vessel({**kvlcc2_document(), "rps": float(k)}).dynamics.derivatives(
        row[None], d) for row, d, k in zip(nu, delta, n, strict=True)])  # fmt: skip
    np.testing.assert_allclose(follow.dynamics.derivatives(nu, delta, None, n), at_each,
                               rtol=1e-13, atol=1e-15)  # fmt: skip
    fixed = mmg_vessel({**kvlcc2_document(), "rps": 9.0})
    log = zigzag(fixed, 20, 20, duration=60, dt=0.2, method="euler").log.assign(n=9.0)
    path = mmg_file(tmp_path / "follow.yml", rps="logs")
    log_path = write_log(log, tmp_path / "zz9.csv")
    record = validated(path, log_path, capsys, tmp_path, "--method", "euler")
    assert max(record["metrics"][s]["rmse"] for s in "uvr") < 1e-9
    closed = record["indices"]["closed_loop"]
    measured = record["indices"]["measured"]
    assert closed["first_overshoot_deg"] == pytest.approx(measured["first_overshoot_deg"],
                                                          abs=0.05)  # fmt: skip
    code, out, err = run(["manoeuvre", path, "turning", "--rps", "9", "--json",
                          tmp_path / "t.json"], capsys)  # fmt: skip
    assert code == 0 and "straight-running speed at 9 rps" in out, err
    speed = float(out.split("approach: ")[1].split(" m/s")[0])
    assert fixed.dynamics.derivatives([[speed, 0.0, 0.0]], [0.0])[0, 0] == pytest.approx(0.0,
                                                                                      abs=1e-5)
    turn = turning_circle(fixed, 35.0, speed=speed).indices
    ours = json.loads((tmp_path / "t.json").read_text())["indices"]
    assert ours["tactical_diameter"] == pytest.approx(turn["tactical_diameter"], rel=1e-3)
    astern = write_log(log.assign(n=np.where(log["t"] > 30, -5.0, 9.0)), tmp_path / "astern.csv")
    code, _, err = run(["validate", path, astern], capsys)
    assert code == 1 and err.count("\n") == 1 and "propeller turning ahead only" in err
    assert "t = 30.2 s" in err
    with pytest.raises(ShipidError, match="rps"):
        mmg_vessel({**kvlcc2_document(), "rps": "fast"})


def _particulars(tmp_path, k: float = 1.0, **drop) -> str:
    """The KVLCC2's particulars (the built-in's values) of a ship k times as long."""
    values = {"length": K.L * k, "beam": K.B * k, "draught": K.D_DRAUGHT * k,
              "mass": K.RHO * K.VOLUME * k**3, "rudder_area": K.AR * k**2,
              "rudder_height": K.HR * k, "propeller_diameter": K.DP * k, "xg": K.XG * k,
              "rho": K.RHO}  # fmt: skip
    for key in drop:
        values.pop(key)
    path = tmp_path / f"p{k:g}.yml"
    path.write_text("".join(f"{key}: {v!r}\n" for key, v in values.items()), encoding="utf-8")
    return str(path)


def test_shipid_mmg_carries_a_similar_ships_coefficients_to_this_ships_particulars(tmp_path,
                                                                                  capsys):
    """``shipid mmg kvlcc2 --particulars``: with the KVLCC2's own particulars, the KVLCC2; with
    those of a ship twice as long, the KVLCC2 Froude-scaled (equal prime coefficients): its
    accelerations at Froude-similar states are the KVLCC2's (surge and sway) and half of them
    (yaw), its trimmed rps the KVLCC2's over √2, its approach √2 times the KVLCC2's."""
    built_in = K.kvlcc2()
    code, out, err = run(["mmg", "kvlcc2", "--particulars", _particulars(tmp_path), "--speed",
                          K.APPROACH_SPEED, "--rudder-rate", K.RUDDER_RATE_DEG, "-o",
                          tmp_path / "same.yml"], capsys)  # fmt: skip
    assert code == 0 and "MMG model written" in out, err
    same = read_mmg(tmp_path / "same.yml")
    rng = np.random.default_rng(3)
    nu = np.column_stack([rng.uniform(0.4, 1.4, 40), rng.uniform(-0.2, 0.2, 40),
                          rng.uniform(-0.05, 0.05, 40)])  # fmt: skip
    delta = rng.uniform(-0.6, 0.6, 40)
    np.testing.assert_allclose(same.dynamics.derivatives(nu, delta),
                               built_in.dynamics.derivatives(nu, delta), rtol=1e-9, atol=1e-13)
    code, _, err = run(["mmg", "kvlcc2", "--particulars", _particulars(tmp_path, 2.0), "-o",
                        tmp_path / "twice.yml"], capsys)  # fmt: skip
    assert code == 0 and "equal Froude number" in err
    twice = read_mmg(tmp_path / "twice.yml")
    root = np.sqrt(2.0)
    assert twice.approach_speed == pytest.approx(K.APPROACH_SPEED * root, rel=1e-12)
    assert twice.dynamics.n_prop == pytest.approx(built_in.dynamics.n_prop / root, rel=1e-8)
    scaled = twice.dynamics.derivatives(nu * [root, root, 1 / root], delta)
    np.testing.assert_allclose(scaled, built_in.dynamics.derivatives(nu, delta) * [1, 1, 0.5],
                               rtol=1e-9, atol=1e-13)  # fmt: skip
    # The ship's own gear where its particulars give it (the tanker's stops at 10°), else the
    # source's 35°.
    assert np.degrees(twice.steering.max_angle) == pytest.approx(35.0)
    geared = Path(_particulars(tmp_path, 2.0))
    geared.write_text(geared.read_text() + "rudder_limit: 10\n")
    code, _, err = run(["mmg", "kvlcc2", "--particulars", geared, "-o", tmp_path / "g.yml"],
                       capsys)  # fmt: skip
    assert code == 0, err
    assert np.degrees(read_mmg(tmp_path / "g.yml").steering.max_angle) == pytest.approx(10.0)


@pytest.mark.parametrize(("argv", "said"), [
    (["kvlcc2", "--drop", "mass"], "an MMG model needs mass"),
    (["mariner"], "mariner is not an MMG model"),
    (["kvlcc2", "--rps", "fast"], "--rps must be a number or 'logs'"),
    (["kvlcc2", "-o", "ship.txt"], "unknown extension"),
])  # fmt: skip
def test_shipid_mmg_bad_input_is_named(tmp_path, capsys, argv, said):
    drop = {}
    if "--drop" in argv:
        drop = {argv.pop(argv.index("--drop") + 1): None}
        argv.remove("--drop")
    output = [] if "-o" in argv else ["-o", tmp_path / "ship.yml"]
    argv = [a if a != "ship.txt" else tmp_path / "ship.txt" for a in argv]
    code, _, err = run(["mmg", *argv, "--particulars", _particulars(tmp_path, **drop), *output],
                       capsys)  # fmt: skip
    assert code == 1 and err.count("\n") == 1 and said in err, err
    assert not list(tmp_path.glob("ship.*"))


def test_an_mmg_file_is_a_prior_as_the_built_in_ship_is(tmp_path, capsys):
    """``identify --prior SHIP.yml``: the KVLCC2 written out gives the prior the built-in KVLCC2
    gives (its trials fitted in the structure), and so the same model."""
    path = mmg_file(tmp_path / "kvlcc2.yml")
    log = write_log(zigzag(K.kvlcc2(), 20, 20, duration=60, dt=0.2).log, tmp_path / "zz.csv")
    models = []
    for prior in ("kvlcc2", path):
        out = tmp_path / f"m{len(models)}.json"
        code, text, err = run(["identify", log, "--particulars", _particulars(tmp_path),
                               "--model", "blanke-speed", "--crossflow", "--prior", prior,
                               "--gamma", "1", "-o", out], capsys)  # fmt: skip
        assert code == 0 and "prior: the reference ship" in text, err
        models.append(json.loads(out.read_text())["model"]["coefficients"])
    for dof, terms in models[0].items():
        assert models[1][dof] == pytest.approx(terms, rel=1e-6, abs=1e-9), dof
    code, _, err = run(["identify", log, "--particulars", _particulars(tmp_path), "--model",
                        "blanke-speed", "--crossflow", "--gamma", "1", "-o",
                        tmp_path / "none.json"], capsys)  # fmt: skip
    plain = json.loads((tmp_path / "none.json").read_text())["model"]["coefficients"]
    assert code == 0 and plain["r"] != pytest.approx(models[0]["r"], rel=0.05), err


def test_an_mmg_ship_refuses_runs_outside_its_method_in_one_line(tmp_path, capsys):
    """The MMG standard method's propeller turns ahead and its hull forces need headway: a
    crash stop of a ship whose propeller follows the orders, and a run from rest, are refused
    in one line; criteria says why it does not judge the stopping ability."""
    path = mmg_file(tmp_path / "follow.yml", rps="logs")
    code, _, err = run(["manoeuvre", path, "stopping"], capsys)
    assert code == 1 and err.count("\n") == 1 and "propeller turning ahead only" in err
    code, out, err = run(["criteria", path], capsys)
    assert code == 0 and "MMG model has a propeller turning ahead only" in err
    rest = zigzag(read_mmg(path), 10, 10, duration=20, rps=10.0).log
    rest["u"] = rest["v"] = 0.0
    code, _, err = run(["simulate", path, write_log(rest, tmp_path / "rest.csv"), "-o",
                        tmp_path / "sim.csv"], capsys)  # fmt: skip
    assert code == 1 and err.count("\n") == 1 and "starts at rest" in err
    assert not (tmp_path / "sim.csv").exists()


def _module(path):
    import importlib.util

    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_an_mmg_ship_exports_as_a_standalone_module(tmp_path, capsys):
    """``shipid export`` of the KVLCC2, of an MMG file whose propeller follows the logs and of
    that file corrected with wind terms: each module's accelerations are the ship's in shipid
    (to rounding), and its simulate replays a log as shipid's Euler free run does."""
    from shipid.dynamics.model import ModelStructure
    from shipid.dynamics.simulate import simulate_log
    from shipid.identification.correction import correction_document, identify_correction

    follow = mmg_file(tmp_path / "follow.yml", rps="logs")
    ship = read_mmg(follow)
    wind = "wind_speed^2*sin(wind_angle)"
    log = zigzag(ship, 20, 20, duration=40, dt=0.1, method="euler", rps=9.0, speed=0.9,
                 wind=(3.0, 1.0)).log  # fmt: skip
    log["wind_speed"], log["wind_angle"] = 3.0 + 0.1 * np.sin(log["t"]), 0.5
    fit = identify_correction(log, ship, ModelStructure("w", {"r": ("u*r", wind)}), gamma=1e4)
    corrected = tmp_path / "corrected.json"
    corrected.write_text(json.dumps(correction_document(fit, {"mmg": yaml.safe_load(
        follow.read_text())})), encoding="utf-8")  # fmt: skip
    rng = np.random.default_rng(2)
    nu = np.column_stack([rng.uniform(0.5, 1.3, 30), rng.uniform(-0.2, 0.2, 30),
                          rng.uniform(-0.05, 0.05, 30)])  # fmt: skip
    delta, n = rng.uniform(-0.6, 0.6, 30), rng.uniform(6.0, 12.0, 30)
    gusts = {"wind_speed": rng.uniform(0.0, 4.0, 30), "wind_angle": rng.uniform(-3.0, 3.0, 30)}
    cases = (("kvlcc2", K.kvlcc2().dynamics, {}, ()),
             (follow, ship.dynamics, {"n": n}, ("n",)),
             (corrected, fit.vessel.dynamics, {"n": n, **gusts}, ("n", "wind_speed", "wind_angle")))
    for i, (source, dyn, inputs, columns) in enumerate(cases):
        out = tmp_path / f"ship{i}.py"
        code, text, err = run(["export", source, "-o", out], capsys)
        assert code == 0 and "standalone NumPy module" in text, err
        module = _module(out)
        assert module.INPUTS == ("delta", *columns)
        ours = np.column_stack(module.accelerations(nu[:, 0], nu[:, 1], nu[:, 2], delta,
                                                    *inputs.values()))  # fmt: skip
        theirs = dyn.derivatives(nu, delta, None, inputs.get("n"), **gusts) if len(columns) > 1 \
            else dyn.derivatives(nu, delta, None, inputs.get("n"))  # fmt: skip
        np.testing.assert_allclose(ours, theirs, rtol=1e-12, atol=1e-15)
        run_log = log if columns else log.drop(columns=["n", "wind_speed", "wind_angle"])
        replay = simulate_log(dyn, run_log, "euler").log
        states = module.simulate(run_log["t"], run_log[["delta", *columns]].to_numpy(),
                                 run_log[["u", "v", "r", "psi", "x", "y"]].iloc[0].to_numpy())
        np.testing.assert_allclose(states, replay[["u", "v", "r", "psi", "x", "y"]].to_numpy(),
                                   rtol=1e-9, atol=1e-10)  # fmt: skip
    code, _, err = run(["export", "mariner", "-o", tmp_path / "m.py"], capsys)
    assert code == 1 and err.count("\n") == 1 and "MMG ships" in err
    assert not (tmp_path / "m.py").exists()

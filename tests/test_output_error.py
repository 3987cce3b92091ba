"""Maximum-likelihood output error against independent truths: the closed-form least-squares line
of a constant-acceleration model, the known coefficients of the paper's ship under its sensor
noise, and the command line's files."""

import json
import math

import numpy as np
import pandas as pd
import pytest
from cli_helpers import run

from shipid.data.io import write_log
from shipid.demo import TRAINING, synthesise_trials
from shipid.dynamics.model import ManoeuvringModel, ModelStructure
from shipid.errors import ShipidError
from shipid.evaluation.study import Trial, run_trial
from shipid.identification.identify import identify
from shipid.identification.output_error import (
    DRAWS_METHOD,
    METHOD,
    coefficient_intervals,
    output_error,
)
from shipid.vessels import PAPER_IMU, scale_ship_model

DROP = {"u": ["r^2"]}


def constant_model(c=(0.01, -0.002, 0.001)) -> ManoeuvringModel:
    structure = ModelStructure("constant", {"u": ("1",), "v": ("1",), "r": ("1",)})
    return ManoeuvringModel(structure, {d: {"1": x} for d, x in zip("uvr", c, strict=True)})


def test_a_constant_acceleration_is_the_least_squares_line_with_its_textbook_errors():
    # u̇ = c integrates exactly to the line u0 + c t: output error is then ordinary least squares
    # of the measurements on [1, t], whose estimate and standard errors have closed forms.
    rng = np.random.default_rng(3)
    t = np.arange(200) * 0.2
    true = {"u": (1.5, 0.01), "v": (0.1, -0.002), "r": (-0.02, 0.001)}
    noise = {"u": 0.03, "v": 0.01, "r": 0.004}
    log = pd.DataFrame({"t": t, "delta": np.zeros_like(t)})
    for s, (x0, c) in true.items():
        log[s] = x0 + c * t + noise[s] * rng.standard_normal(t.size)
    fit, ensemble = output_error(constant_model((0.0, 0.0, 0.0)), log, draws=50)
    X = np.column_stack([np.ones_like(t), t])
    xtx_inv = np.linalg.inv(X.T @ X)
    inflation = fit.statistics["covariance_inflation"]
    for s in "uvr":
        beta, rss = np.linalg.lstsq(X, log[s].to_numpy(), rcond=None)[:2]
        sigma2 = float(rss[0]) / (t.size - 2)
        assert fit.model.coefficients[s]["1"] == pytest.approx(beta[1], rel=1e-5)
        assert fit.statistics["initial_states"][0][s] == pytest.approx(beta[0], rel=1e-5, abs=1e-9)
        assert fit.statistics["noise"][s] == pytest.approx(math.sqrt(sigma2), rel=1e-4)
        se = fit.statistics["standard_errors"][s]["1"] / math.sqrt(inflation)
        assert se == pytest.approx(math.sqrt(sigma2 * xtx_inv[1, 1]), rel=1e-3)
    assert 1.0 <= inflation < 1.5  # white noise: hardly any correlation to widen for
    assert fit.method == METHOD and ensemble.method == DRAWS_METHOD
    assert ensemble.thetas.shape == (50, 3, 1)


@pytest.fixture(scope="module")
def paper_fit():
    logs = synthesise_trials(0)
    start = identify(logs[TRAINING], drop=DROP, force=True).model
    return output_error(start, logs[TRAINING]), logs


def test_the_paper_ships_coefficients_lie_within_their_intervals(paper_fit):
    (fit, ensemble), _ = paper_fit
    truth = scale_ship_model().coefficients
    table = coefficient_intervals(fit)
    assert len(table) == 16
    z = (table["value"] - [truth[d][t] for d, t in zip(table["equation"], table["term"],
                                                        strict=True)]) / table["std_error"]
    assert np.all(np.abs(z) < 2.5), table.assign(z=z)
    # The equation-error start is biased by the noisy regressors (EIV): output error is not.
    assert fit.model.coefficients["r"]["u*r"] == pytest.approx(-1.1699, rel=0.15)
    assert abs(fit.initial.coefficients["r"]["u*r"] / -1.1699 - 1) > 0.25
    # The noise it finds is the sensor model's.
    for s in "uvr":
        assert fit.statistics["noise"][s] == pytest.approx(PAPER_IMU.white[s], rel=0.1)
    spread = ensemble.coefficient_table()
    assert np.allclose(spread["std"], table["std_error"], rtol=0.3)


def test_the_intervals_hold_the_truth_at_their_level_over_noise_draws(paper_fit):
    # The coverage the issue asks for is a frequency: over 40 noise draws on the demo's 20/20
    # zig-zag (one clean trial, the paper's sensors), each fit's 95 % intervals against the known
    # coefficients. The first 20 seeds of the study hold 88 %, an unlucky block: over 200 seeds
    # 95 % (benchmarks/study_uncertainty.py), as here.
    from shipid.identification.refine import coefficient_slots, with_coefficients
    from shipid.vessels import NOISE_FREE

    (fit, _), _ = paper_fit
    truth = scale_ship_model().coefficients
    rows, cols = coefficient_slots(fit.model)
    true_model = with_coefficients(fit.model, rows, cols, np.array(
        [truth[d][t] for d, ts in fit.model.coefficients.items() for t in ts]), "truth")
    clean = synthesise_trials(0, sensor=NOISE_FREE)[TRAINING]
    z = []
    for seed in range(40):
        draw, _ = output_error(true_model, PAPER_IMU.apply(clean, seed=5000 + seed), draws=10)
        table = coefficient_intervals(draw)
        want = [truth[d][t] for d, t in zip(table["equation"], table["term"], strict=True)]
        z.append((table["value"] - want) / table["std_error"])
    z = np.array(z)
    coverage = float(np.mean(np.abs(z) <= 1.96))
    assert 0.92 <= coverage <= 0.98, coverage
    # Standard errors neither too small nor too large in any equation.
    for dof in "uvr":
        spread = np.std(z[:, table["equation"].to_numpy() == dof])
        assert 0.8 <= spread <= 1.15, (dof, spread)


def test_output_error_predicts_held_out_trials_at_the_noise_floor(paper_fit):
    from shipid.evaluation.validate import validate

    (fit, _), logs = paper_fit
    held = [k for k in logs if k != TRAINING]
    ours = validate(fit.model, [logs[k] for k in held], held)
    truth = validate(scale_ship_model(), [logs[k] for k in held], held)
    for a, b in zip(ours, truth, strict=True):
        for s in "uvr":
            assert a.metrics[s]["std"] <= 1.05 * b.metrics[s]["std"], (a.name, s)


def test_a_model_without_surge_fits_and_labels_sway_and_yaw(paper_fit):
    # Surge held: only v and r are compared, and every per-state figure is theirs.
    _, logs = paper_fit
    start = identify(logs[TRAINING], model="linear-sway-yaw", force=True).model
    fit, _ = output_error(start, logs[TRAINING])
    st = fit.statistics
    assert fit.states == ("v", "r")
    assert set(st["noise"]) == set(st["residual_autocorrelation"]) == {"v", "r"}
    assert st["noise"]["v"] == pytest.approx(PAPER_IMU.white["v"], rel=0.5)
    assert st["noise"]["r"] < 0.1 * st["noise"]["v"] + PAPER_IMU.white["r"] * 3
    assert set(st["initial_states"][0]) == {"log", "v", "r"}


def test_an_undetermined_coefficient_is_named_and_gets_an_infinite_error():
    # δ never moves: nothing in the log tells its coefficient.
    t = np.arange(100) * 0.2
    rng = np.random.default_rng(0)
    log = pd.DataFrame({"t": t, "delta": np.zeros_like(t), "u": 1.0 + 0.01 * rng.standard_normal(100),
                        "v": 0.01 * rng.standard_normal(100), "r": 0.001 * rng.standard_normal(100)})
    structure = ModelStructure("c", {"u": ("1",), "v": ("1", "delta"), "r": ("1",)})
    model = ManoeuvringModel(structure, {"u": {"1": 0.0}, "v": {"1": 0.0, "delta": 0.1},
                                         "r": {"1": 0.0}})  # fmt: skip
    fit, _ = output_error(model, log)
    assert math.isinf(fit.statistics["standard_errors"]["v"]["delta"])
    assert math.isfinite(fit.statistics["standard_errors"]["v"]["1"])
    assert any("do not determine v: delta" in w for w in fit.warnings)


def test_correlated_residuals_widen_the_errors_and_say_so():
    # A slow oscillation the constant model cannot follow: model error, not noise.
    t = np.arange(300) * 0.2
    wobble = 0.05 * np.sin(2 * np.pi * t / 20)
    log = pd.DataFrame({"t": t, "delta": np.zeros_like(t), "u": 1.0 + wobble, "v": wobble,
                        "r": 0.1 * wobble})  # fmt: skip
    fit, _ = output_error(constant_model(), log)
    assert fit.statistics["covariance_inflation"] > 10
    assert any("correlated" in w for w in fit.warnings)


@pytest.mark.parametrize("kwargs, message", [({"draws": 3}, "at least 10 draws"),
                                             ({"method": "rk45"}, "method must be")])
def test_bad_arguments_are_refused(paper_fit, kwargs, message):
    (fit, _), logs = paper_fit
    with pytest.raises(ShipidError, match=message):
        output_error(fit.initial, logs[TRAINING], **kwargs)


def test_too_short_a_log_is_refused():
    # 12 measured values for the Blanke model's 17 coefficients and 3 initial states.
    t = np.arange(4) * 0.2
    log = pd.DataFrame({"t": t, "delta": [0.0, 0.1, 0.2, 0.3], "u": [1.0, 1.1, 1.0, 1.1],
                        "v": [0.0, 0.01, 0.0, 0.01], "r": [0.0, 0.001, 0.0, 0.001]})  # fmt: skip
    with pytest.raises(ShipidError, match="12 measured values for 20 parameters"):
        output_error(scale_ship_model(), log)


def test_the_command_writes_errors_draws_and_the_lssvm_start(tmp_path, capsys, paper_fit):
    _, logs = paper_fit
    train, held = tmp_path / "train.csv", tmp_path / "zz10.csv"
    write_log(logs[TRAINING], train)
    write_log(logs["zigzag 10/10"], held)
    out = tmp_path / "oe.json"
    code, text, err = run(["identify", train, "--drop", "u:r^2", "--output-error", "-o", out],
                          capsys)  # fmt: skip
    assert code == 0, err
    assert "± 1.96 standard errors" in text and "measurement noise from the residuals" in text
    doc = json.loads(out.read_text())
    ref = doc["identification"]["refinement"]
    assert ref["method"] == METHOD
    assert doc["model"] == ref["refined_model"]
    assert doc["uncertainty"]["method"] == DRAWS_METHOD and doc["uncertainty"]["replicates"] == 200
    se = ref["statistics"]["standard_errors"]
    assert se["r"]["delta"] > 0 and len(ref["statistics"]["covariance"]["matrix"]) == 16
    code, text, err = run(["validate", out, held], capsys)
    assert code == 0, err
    assert "95 %" in text
    # Rescaled with the model: every standard error in proportion to its coefficient.
    big = tmp_path / "big.json"
    assert run(["rescale", out, "--factor", "4", "-o", big], capsys)[0] == 0
    doc2 = json.loads(big.read_text())
    ref2 = doc2["identification"]["refinement"]
    for dof, terms in se.items():
        for term, s in terms.items():
            ratio = doc2["model"]["coefficients"][dof][term] / doc["model"]["coefficients"][dof][term]
            assert ref2["statistics"]["standard_errors"][dof][term] == pytest.approx(s * abs(ratio))


@pytest.mark.parametrize("extra", [["--refine"], ["--bootstrap", "20"]])
def test_the_command_refuses_two_fits_at_once(tmp_path, capsys, paper_fit, extra):
    _, logs = paper_fit
    train = tmp_path / "train.csv"
    write_log(logs[TRAINING], train)
    out = tmp_path / "oe.json"
    code, _, err = run(["identify", train, "--output-error", *extra, "-o", out], capsys)
    assert code == 1 and "--output-error is its own fit" in err and len(err.splitlines()) == 1
    assert not out.exists()


def test_a_study_trial_counts_the_output_error_coverage():
    row = run_trial(Trial(0, seed=0, estimator="output-error"))
    assert row["error"] == ""
    assert row["coverage"] == 1.0  # seed 0: every true coefficient inside (see the test above)
    assert row["turning δ = +20°: u error std"] <= 1.05 * row["turning δ = +20°: u truth error std"]


def _interval_hits(model, se, truth, dofs="uvr"):
    """How many true coefficients of ``dofs`` lie within the estimate ± 1.96 standard errors,
    and of how many."""
    from shipid.dynamics.astern import astern_form

    # A model file of logs that run ahead has u·v, u·r as |u|·v, |u|·r (the same term there).
    true = {d: {astern_form(d, t): w for t, w in truth[d].items()} for d in dofs}
    pairs = [(model[d][t], se[d].get(t, 0.0), true[d][astern_form(d, t)]) for d in dofs
             for t in model[d] if t != "1"]  # fmt: skip
    return sum(abs(v - w) <= 1.96 * s for v, s, w in pairs), len(pairs)


def test_the_default_fits_by_output_error_where_noise_is_all_the_lssvm_leaves(tmp_path, capsys,
                                                                             paper_fit):
    """Issue #10: plain ``shipid identify`` on the paper's noisy zig-zag. Its LS-SVM free run
    misses the log by 1.0–1.3 times the sensors' noise, so the default fits by output error,
    whose intervals hold the true coefficients (the LS-SVM's ± standard errors hold a third)."""
    _, logs = paper_fit
    train = write_log(logs[TRAINING], tmp_path / "train.csv")
    code, text, err = run(["identify", train, "-o", tmp_path / "m.json"], capsys)
    assert code == 0, err
    assert "noise is what it leaves: fitting by maximum-likelihood output error" in text
    doc = json.loads((tmp_path / "m.json").read_text())
    ref = doc["identification"]["refinement"]
    assert ref["method"] == METHOD and doc["model"] == ref["refined_model"]
    assert doc["uncertainty"]["method"] == DRAWS_METHOD
    choice = doc["identification"]["preprocessing"]["output_error"]  # why, kept in the file
    assert choice["fit"] == "output error" and max(choice["noise_ratios"].values()) <= 2.0
    truth = scale_ship_model().coefficients
    model, se = doc["model"]["coefficients"], ref["statistics"]["standard_errors"]
    # Sway and yaw all inside; surge's four (v·r and r² nearly collinear in one zig-zag) at
    # z = 2.0–2.3 together in this seed (95 % over 40 seeds: benchmarks/study_uncertainty.py).
    assert _interval_hits(model, se, truth, "vr") == (10, 10)
    assert _interval_hits(model, se, truth) == (10, 14)
    assert model["r"]["|u|*r"] == pytest.approx(-1.1699, rel=0.1)
    # --no-output-error keeps the equation-error fit, biased by the noisy regressors.
    code, text, err = run(["identify", train, "--no-output-error", "-o", tmp_path / "ls.json"],
                          capsys)  # fmt: skip
    assert code == 0, err
    assert "output error:" not in text
    ls = json.loads((tmp_path / "ls.json").read_text())
    assert ls["identification"].get("refinement") is None
    assert abs(ls["model"]["coefficients"]["r"]["|u|*r"] / -1.1699 - 1) > 0.25
    ls_se = {d: v.get("std_errors", {}) for d, v in ls["identification"]["diagnostics"].items()}
    assert _interval_hits(ls["model"]["coefficients"], ls_se, truth) == (6, 14)


def test_bootstrap_says_it_keeps_the_lssvm_fit_the_default_would_replace(tmp_path, capsys,
                                                                        paper_fit):
    """``--bootstrap`` describes the LS-SVM fit, so on the paper's zig-zag (noise is all the
    LS-SVM leaves) it keeps the fit a plain ``identify`` replaces by output error: said in one
    line and in the model file, where before the user asking for intervals got the other fit,
    with intervals that hold the truth a third as often, without a word."""
    _, logs = paper_fit
    train = write_log(logs[TRAINING], tmp_path / "train.csv")
    argv = ["identify", train, "--bootstrap", "10"]
    code, text, err = run([*argv, "-o", tmp_path / "b.json"], capsys)
    assert code == 0, err
    assert "output error: not fitted, since --bootstrap describes the LS-SVM fit" in text
    doc = json.loads((tmp_path / "b.json").read_text())
    choice = doc["identification"]["preprocessing"]["output_error"]
    assert choice["fit"] == "LS-SVM" and "--bootstrap" in choice["why"]
    assert max(choice["noise_ratios"].values()) <= 2.0
    assert doc["identification"].get("refinement") is None
    # Asked for the LS-SVM fit in so many words: nothing to say.
    code, text, err = run([*argv, "--no-output-error", "-o", tmp_path / "n.json"], capsys)
    assert code == 0, err
    assert "output error" not in text


def test_the_default_keeps_the_lssvm_where_model_error_is_what_is_left(tmp_path, capsys,
                                                                       paper_fit, monkeypatch):
    """A real log: the LS-SVM's free runs miss the KVLCC2's MARIN zig-zag by tens of times its
    noise; and where output error's residuals come out correlated, its fit is not kept."""
    from pathlib import Path

    import shipid.identification.output_error as oe

    marin = (Path(__file__).resolve().parents[2] / "shared" / "data" / "kvlcc2-marin"
             / "MARIN_FREE_KVLCC2_zz_20_m.dat")  # fmt: skip
    if marin.is_file():
        argv = ["identify", "--format", "simman-marin", "--scale", "45.7", "--dt", "0.2",
                "--model", "blanke-speed", marin]  # fmt: skip
        code, text, err = run([*argv, "-o", tmp_path / "k.json"], capsys)
        assert code == 0, err
        assert "output error: not fitted; the LS-SVM's free runs miss the logs by up to" in text
        choice = json.loads((tmp_path / "k.json").read_text())["identification"][
            "preprocessing"]["output_error"]
        assert choice["fit"] == "LS-SVM" and max(choice["noise_ratios"].values()) > 2.0
        assert run([*argv, "--no-output-error", "-o", tmp_path / "k2.json"], capsys)[0] == 0
        assert json.loads((tmp_path / "k.json").read_text())["model"] == \
            json.loads((tmp_path / "k2.json").read_text())["model"]
    _, logs = paper_fit
    train = write_log(logs[TRAINING], tmp_path / "train.csv")
    monkeypatch.setattr(oe, "INFLATION_WARNING", 1.0)  # every residual now counts as correlated
    code, text, err = run(["identify", train, "-o", tmp_path / "m.json"], capsys)
    assert code == 0, err
    assert "model error after all; the model file keeps the LS-SVM fit" in text
    ident = json.loads((tmp_path / "m.json").read_text())["identification"]
    assert ident.get("refinement") is None
    assert ident["preprocessing"]["output_error"]["fit"] == "LS-SVM"
    assert "correlated" in ident["preprocessing"]["output_error"]["why"]


def test_physics_the_output_error_fit_would_not_hold_keeps_the_lssvm(tmp_path, capsys, paper_fit):
    """Bug: output error fitted every coefficient freely, so a prior or stability asked for would
    have been fitted away by the default's output-error fit without a word. It holds sign
    constraints and bounds now (box bounds); the rest keeps the LS-SVM fit, and is refused with
    an explicit --output-error."""
    _, logs = paper_fit
    train = write_log(logs[TRAINING], tmp_path / "train.csv")
    code, text, err = run(["identify", train, "--constraints", "stable", "-o", tmp_path / "m.json"],
                          capsys)  # fmt: skip
    assert code == 0, err
    assert "output error: not fitted, since it would not hold --constraints stable" in text
    doc = json.loads((tmp_path / "m.json").read_text())
    assert doc["identification"].get("refinement") is None
    assert run(["identify", train, "--constraints", "stable", "--no-output-error", "-o",
                tmp_path / "ls.json"], capsys)[0] == 0  # fmt: skip
    assert doc["model"] == json.loads((tmp_path / "ls.json").read_text())["model"]
    code, _, err = run(["identify", train, "--output-error", "--constraints", "signs,stable", "-o",
                        tmp_path / "b.json"], capsys)  # fmt: skip
    assert code == 1 and "does not hold --constraints stable" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "b.json").exists()
    # Said before the logs are read (and a structure searched): a missing log is not reached.
    code, _, err = run(["identify", tmp_path / "missing.csv", "--output-error", "--prior",
                        "clarke", "-o", tmp_path / "c.json"], capsys)  # fmt: skip
    assert code == 1 and "does not hold --prior" in err


def test_the_default_output_error_fit_holds_the_sign_constraints(tmp_path, capsys, paper_fit):
    """`--constraints signs` on noise-dominated logs: output error with the sign table as bounds.
    The paper's own model has a sway |v|v of +0.54 against the table's ≤ 0, so it is held at
    0, and named; an explicit --bound past the free estimate is held too."""
    _, logs = paper_fit
    train = write_log(logs[TRAINING], tmp_path / "train.csv")
    code, text, err = run(["identify", train, "--constraints", "signs", "-o", tmp_path / "s.json"],
                          capsys)  # fmt: skip
    assert code == 0, err
    doc = json.loads((tmp_path / "s.json").read_text())
    assert doc["identification"]["preprocessing"]["output_error"]["fit"] == "output error"
    coefs, stats = doc["model"]["coefficients"], doc["identification"]["refinement"]["statistics"]
    assert coefs["v"]["|v|*v"] == 0.0 and ["v", "|v|*v"] in stats["at_bound"]
    assert "v: |v|v held at its bound 0 (sway damping): the unbounded output-error fit" in err
    for dof, terms in stats["bounds"].items():  # every sign the table sets, held
        for term, (lo, hi) in terms.items():
            assert (lo is None or coefs[dof][term] >= lo) and (hi is None or coefs[dof][term] <= hi)
    code, text, err = run(["identify", train, "--output-error", "--bound", "r: u*r >= -1",
                           "-o", tmp_path / "b.json"], capsys)  # fmt: skip
    assert code == 0, err
    doc = json.loads((tmp_path / "b.json").read_text())
    # (written |u|·r: the logs run ahead, shipid.dynamics.astern)
    assert doc["model"]["coefficients"]["r"]["|u|*r"] == -1.0  # the free fit: about -1.2
    assert "r: u r held at its bound -1 (bound [-1, inf])" in err


@pytest.mark.parametrize("fit", ["--no-output-error", "--output-error"])
def test_equal_bounds_give_a_coefficient(tmp_path, capsys, paper_fit, fit):
    """`--bound` both ways at one value holds the coefficient there, in the LS-SVM fit and in
    output error (whose trust-region solver, like the LS-SVM's BVLS, refused the empty box with
    SciPy's own message): given, not fitted, said so, a standard error of 0; the other
    coefficients fitted with it in every free run."""
    _, logs = paper_fit
    train = write_log(logs[TRAINING], tmp_path / "train.csv")
    out = tmp_path / "g.json"
    code, _, err = run(["identify", train, fit, "--bound", "r: u*r >= -0.9", "--bound",
                        "r: u*r <= -0.9", "-o", out], capsys)  # fmt: skip
    assert code == 0, err
    doc = json.loads(out.read_text())
    coefs = doc["model"]["coefficients"]
    assert coefs["r"]["|u|*r"] == -0.9  # the free fit: about -1.2
    assert "r: u r held at -0.9 (bound [-0.9, -0.9]): given, not fitted" in err
    assert "held at its bound" not in err
    if fit == "--output-error":
        refinement = doc["identification"]["refinement"]
        assert "1 coefficient given" in err
        assert refinement["statistics"]["standard_errors"]["r"]["|u|*r"] == 0.0
        # The rest fitted around it, from the LS-SVM fit that held it too.
        assert refinement["cost_final"] < refinement["cost_initial"]
        for key in ("initial_model", "refined_model"):
            assert refinement[key]["coefficients"]["r"]["|u|*r"] == -0.9


def test_a_bounded_constant_acceleration_is_the_line_with_its_slope_held():
    """A bound past the free slope: the estimate is the bound, the initial state the mean of
    u − c t (the closed form with the slope held), the other equations as without it; its
    interval is cut at the bound and so are the draws."""
    rng = np.random.default_rng(3)
    t = np.arange(200) * 0.2
    log = pd.DataFrame({"t": t, "delta": np.zeros_like(t)})
    for s, x0, c, sd in (("u", 1.5, 0.01, 0.03), ("v", 0.1, -0.002, 0.01), ("r", -0.02, 0.001,
                                                                          0.004)):  # fmt: skip
        log[s] = x0 + c * t + sd * rng.standard_normal(t.size)
    free, _ = output_error(constant_model((0.0, 0.0, 0.0)), log, draws=50)
    fit, ensemble = output_error(constant_model((0.0, 0.0, 0.0)), log, draws=50,
                                 bounds={"u": {"1": (-1.0, 0.005)}})  # fmt: skip
    assert fit.model.coefficients["u"]["1"] == 0.005
    u0 = float(np.mean(log["u"] - 0.005 * t))
    assert fit.statistics["initial_states"][0]["u"] == pytest.approx(u0, rel=1e-6)
    for s in "vr":
        assert fit.model.coefficients[s]["1"] == pytest.approx(free.model.coefficients[s]["1"],
                                                               rel=1e-6)  # fmt: skip
    assert fit.statistics["at_bound"] == [["u", "1"]]
    assert any("u: 1 held at its bound 0.005" in n for n in fit.warnings)
    row = coefficient_intervals(fit).set_index(["equation", "term"]).loc[("u", "1")]
    assert row["upper"] == 0.005
    assert row["lower"] == pytest.approx(0.005 - 1.96 * row["std_error"], rel=1e-4)
    assert ensemble.thetas[:, 0, 0].max() <= 0.005 < free.model.coefficients["u"]["1"]
    with pytest.raises(ShipidError, match=r"bounds: u: \|u\|\*u is not a term"):
        output_error(constant_model(), log, bounds={"u": {"|u|*u": (-1.0, 0.0)}})
    with pytest.raises(ShipidError, match="lower 2 is not below upper 1"):
        output_error(constant_model(), log, bounds={"u": {"1": (2.0, 1.0)}})
    # Equal bounds: the slope given, the same closed form for the initial state, draws at it.
    held, ensemble = output_error(constant_model((0.0, 0.0, 0.0)), log, draws=50,
                                  bounds={"u": {"1": (0.004, 0.004)}})  # fmt: skip
    assert held.model.coefficients["u"]["1"] == 0.004
    assert held.statistics["initial_states"][0]["u"] == pytest.approx(
        float(np.mean(log["u"] - 0.004 * t)), rel=1e-6)
    assert held.statistics["standard_errors"]["u"]["1"] == 0.0
    assert np.all(ensemble.thetas[:, 0, 0] == 0.004)
    assert any("u: 1 held at 0.004: given, not fitted" in n for n in held.warnings)


def test_the_default_keeps_the_lssvm_where_the_two_fits_turn_apart(tmp_path, capsys):
    """Bug: on the KVLCC2's MMG model through `blanke-race+race-damping` (a structure that is
    not the truth) at a quarter of the paper's sensor noise, the noise check chose output error,
    whose 35° turns' steady yaw rate came out 0.007 rad/s against the MMG model's 0.056 (the
    LS-SVM's 0.051): its tactical diameters doubled. Where the two fits' held-rudder turns are
    more than 25 % apart, the default keeps the LS-SVM and says why."""
    from shipid.trials.manoeuvres import zigzag
    from shipid.vessels import kvlcc2

    ship = kvlcc2()
    paths = [write_log(PAPER_IMU.scaled(0.25).apply(
        zigzag(ship, 20, 20, duration=150, dt=0.2, first=side).log, seed=10 + i),
        tmp_path / f"zz{i}.csv") for i, side in enumerate(("starboard", "port"))]  # fmt: skip
    code, text, err = run(["identify", *paths, "--model", "blanke-race+race-damping", "-o",
                           tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "noise is what it leaves" in text and "held-rudder turns and the LS-SVM fit's" in text
    doc = json.loads((tmp_path / "m.json").read_text())
    choice = doc["identification"]["preprocessing"]["output_error"]
    assert choice["fit"] == "LS-SVM" and "far apart" in choice["why"]
    ref = doc["identification"]["refinement"]
    assert doc["model"] == ref["initial_model"] and doc["uncertainty"] is None
    lssvm = doc["identification"]["plausibility"]["held_rudder"]["starboard"]["steady_yaw_rate"]
    assert abs(lssvm) == pytest.approx(0.0555, rel=0.15)  # the MMG model's 35° turn
    # Asked for, output error is kept, with the warning.
    code, _, err = run(["identify", *paths, "--model", "blanke-race+race-damping",
                        "--output-error", "-o", tmp_path / "oe.json"], capsys)  # fmt: skip
    assert code == 0 and "(kept, as --output-error asks" in err, err
    asked = json.loads((tmp_path / "oe.json").read_text())
    assert asked["model"] == asked["identification"]["refinement"]["refined_model"]


def test_the_default_keeps_output_error_where_the_lssvm_fits_own_turn_fails(tmp_path, capsys):
    """Bug: on seed 107 of the demo's trials the LS-SVM fit's 35° held-rudder turns never
    settled (their last tenth's mean yaw rate 0.21 rad/s) and output error's settled at 0.353
    (the true model: 0.345). Read as steady yaw rates 'far apart', the default handed out the
    LS-SVM fit. A turn that never settles has no steady yaw rate to doubt another fit's by."""
    from shipid.identification.plausibility import held_rudder

    train = write_log(synthesise_trials(107)[TRAINING], tmp_path / "train.csv")
    code, text, err = run(["identify", train, "-o", tmp_path / "m.json"], capsys)
    assert code == 0, err
    doc = json.loads((tmp_path / "m.json").read_text())
    choice = doc["identification"]["preprocessing"]["output_error"]
    assert choice["fit"] == "output error" and "no steady turn" in choice["turns"], choice
    assert "output error: kept; its 35° held-rudder turns" in text
    assert doc["model"] == doc["identification"]["refinement"]["refined_model"]
    assert doc["uncertainty"] is not None  # output error's draws go with its model
    held = doc["identification"]["plausibility"]["held_rudder"]
    truth = held_rudder(scale_ship_model(), speed=doc["identification"]["plausibility"][
        "approach_speed"], duration=300.0)  # fmt: skip
    for side in ("starboard", "port"):
        assert held[side]["settled"]
        assert held[side]["steady_yaw_rate"] == pytest.approx(
            truth[side]["steady_yaw_rate"], rel=0.05)


def test_the_report_of_an_output_error_model_gives_its_own_standard_errors(tmp_path, capsys,
                                                                           paper_fit):
    """Bug: ``validate --report`` printed an output-error model's coefficients with the LS-SVM
    fit's standard errors, labelled as the LS-SVM's (ṙ u·r ± 0.027 where output error's is
    0.15)."""
    import html
    import re

    _, logs = paper_fit
    train = write_log(logs[TRAINING], tmp_path / "train.csv")
    held = write_log(logs["zigzag 10/10"], tmp_path / "zz10.csv")
    assert run(["identify", train, "-o", tmp_path / "m.json"], capsys)[0] == 0
    doc = json.loads((tmp_path / "m.json").read_text())
    se = doc["identification"]["refinement"]["statistics"]["standard_errors"]["r"]["|u|*r"]
    ls_se = doc["identification"]["diagnostics"]["r"]["std_errors"]["|u|*r"]
    assert se > 3 * ls_se
    for extra, label, want in (([], "maximum-likelihood output error", se),
                               (["--lssvm"], "LS-SVM linear fit", ls_se)):
        report = tmp_path / f"rep{len(extra)}"
        # --no-bands: the coefficients' errors are the point, not the ensemble's bands (2.5 s)
        assert run(["validate", tmp_path / "m.json", held, "--report", report, "--no-bands",
                    *extra], capsys)[0] == 0  # fmt: skip
        text = html.unescape((report / "report.html").read_text(encoding="utf-8"))
        assert f"one standard error of each coefficient ({label}" in text
        shown = float(re.search(r"ṙ = −\([0-9.]+ ± ([0-9.e-]+)\) \|u\| r", text).group(1))
        assert shown == pytest.approx(want, rel=0.05)  # shown to two digits

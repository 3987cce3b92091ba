"""Models of logs that never go astern, written in their ahead forms (``shipid.dynamics.astern``):
the same accelerations ahead, damping that damps and a rudder that reverses astern."""

import json
from pathlib import Path

import numpy as np
import pytest

from shipid.data.io import write_log
from shipid.dynamics.astern import AHEAD_FORMS, ahead_forms, astern_form, logs_ahead, written_ahead
from shipid.dynamics.model import ManoeuvringModel, ModelStructure, get_structure
from shipid.trials.manoeuvres import stopping, zigzag
from shipid.vessels import PAPER_IMU, scale_ship

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
OSAKA = DATA / "esso-osaka"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="../shared/data is not present")
N0 = 12.0  # rps, logged constant: the model is carried to every rps, and can run a crash stop


def run(argv) -> tuple[int, str, str]:
    import contextlib
    import io

    from shipid.cli import main

    with contextlib.redirect_stdout(io.StringIO()) as out, \
            contextlib.redirect_stderr(io.StringIO()) as err:  # fmt: skip
        code = main([str(a) for a in argv])
    return code, out.getvalue(), err.getvalue()


def _states(n: int, ahead: bool, seed: int = 0) -> dict:
    rng = np.random.default_rng(seed)
    u = rng.uniform(0.0, 3.0, n) if ahead else -rng.uniform(0.1, 3.0, n)
    return {"u": u, "v": rng.normal(0, 0.3, n), "r": rng.normal(0, 0.2, n),
            "delta": rng.uniform(-0.6, 0.6, n)}  # fmt: skip


@pytest.mark.parametrize("structure", ["blanke", "blanke-speed", "blanke-race+race-damping",
                                       "abkowitz3"])  # fmt: skip
def test_ahead_the_written_model_is_the_fit(structure):
    """Where u ≥ 0 every term equals its ahead form: the accelerations to rounding."""
    fitted = get_structure(structure)
    rng = np.random.default_rng(1)
    model = ManoeuvringModel(fitted, {d: {t: float(rng.normal()) for t in ts}
                                      for d, ts in fitted.terms.items()})  # fmt: skip
    written = written_ahead(model)
    s = _states(500, ahead=True)
    n = np.full(500, 10.0)
    np.testing.assert_allclose(written.accelerations(**s, rps=n), model.accelerations(**s, rps=n),
                               rtol=1e-12, atol=1e-14)  # fmt: skip
    assert written.structure.name == model.structure.name


def test_astern_the_damping_damps_and_the_rudder_reverses():
    """Going astern (u < 0), by hand: the sway and yaw damping of the ahead forms still oppose
    v and r (the fitted u·v, u·r push them on), the rudder's force reverses with the flow over
    it (u²δ did not), and its drag opposes the motion (u²δ² pulled the ship further astern)."""
    model = ManoeuvringModel(
        ModelStructure("t", {"u": ("|u|*u", "u^2*delta^2"), "v": ("u*v", "u^2*delta"),
                             "r": ("u*r", "u^2*delta")}),
        {"u": {"|u|*u": -0.1, "u^2*delta^2": -0.2}, "v": {"u*v": -0.5, "u^2*delta": 0.05},
         "r": {"u*r": -0.8, "u^2*delta": -0.1}})  # fmt: skip
    written = written_ahead(model)
    assert written.structure.terms == {"u": ("|u|*u", "|u|*u*delta^2"),
                                       "v": ("|u|*v", "|u|*u*delta"),
                                       "r": ("|u|*r", "|u|*u*delta")}  # fmt: skip
    u, v, r, d = -1.0, 0.2, 0.1, 0.3
    fitted = model.accelerations(u, v, r, d)[0]
    ahead = written.accelerations(u, v, r, d)[0]
    assert ahead[1] == pytest.approx(-0.5 * 1 * v + 0.05 * -1 * d)  # |u|v, |u|uδ
    assert ahead[2] == pytest.approx(-0.8 * 1 * r - 0.1 * -1 * d)
    assert ahead[0] == pytest.approx(0.1 + 0.2 * d**2)  # both push the ship back toward rest
    assert fitted[2] == pytest.approx(-0.8 * u * r - 0.1 * d)  # u·r a drive astern: +0.08
    assert np.sign(ahead[2] + 0.1 * -1 * d) == -np.sign(r)  # the damping part opposes r


def test_a_term_whose_ahead_form_is_in_the_equation_keeps_its_own():
    """u·v beside |u|·v are the fit's two terms (a library can hold both): neither renamed."""
    found = ahead_forms(ModelStructure("both", {"v": ("u*v", "|u|*v", "u^2*delta")}))
    assert found.renamed["v"] == {"u*v": ("u*v", 1.0), "|u|*v": ("|u|*v", 1.0),
                                  "u^2*delta": ("|u|*u*delta", 1.0)}  # fmt: skip
    assert astern_form("u", "u*v") == "u*v"  # only the sway's u·v is its damping
    assert all(astern_form(d or "u", t) == f for (d, t), f in AHEAD_FORMS.items())


def test_logs_ahead_only_where_every_sample_runs_ahead():
    log = zigzag(scale_ship(), 20, 20, duration=30, dt=0.2).log
    assert logs_ahead([log]) and not logs_ahead([])
    assert not logs_ahead([log, log.assign(u=log["u"] - log["u"].iloc[5] * (log.index == 5))])


@pytest.fixture(scope="module")
def fitted_files(tmp_path_factory):
    """The paper's ship's noisy 20/20 zig-zag at a constant propeller speed, identified with
    and without its ahead forms."""
    folder = tmp_path_factory.mktemp("ahead")
    log = PAPER_IMU.apply(zigzag(scale_ship(rudder_rate_deg=9.6), 20, 20, duration=90, dt=0.2,
                                 method="euler", approach=2.0).log, seed=3).assign(n=N0)  # fmt: skip
    path = write_log(log, folder / "zz.csv")
    out = {}
    for key, extra in (("ahead", []), ("fitted", ["--no-ahead-forms", "--astern-thrust", "none"])):
        out[key] = folder / f"{key}.json"
        code, said, err = run(["identify", path, "--model", "blanke", "--no-output-error",
                               "--bootstrap", "10", *extra, "-o", out[key]])  # fmt: skip
        assert code == 0, err
        out[f"{key}_said"] = said
    out["log"] = path
    return out


def test_identify_writes_the_ahead_forms_and_says_so(fitted_files):
    from shipid.reporting.modelfile import ensemble_from_document, load_model, model_from_document

    ahead, fitted = (json.loads(fitted_files[k].read_text()) for k in ("ahead", "fitted"))
    assert "going astern: the logs never do" in fitted_files["ahead_said"]
    assert "going astern" not in fitted_files["fitted_said"]
    rec = ahead["identification"]["ahead_forms"]
    assert "u v → |u| v" in rec["terms"] and "u r → |u| r" in rec["terms"]
    assert "ahead_forms" not in fitted["identification"]
    # The fit is the same: coefficients, standard errors and replicates renamed as one.
    for dof in ("v", "r"):
        old = "u*v" if dof == "v" else "u*r"
        new = "|u|*" + old[-1]
        assert ahead["model"]["coefficients"][dof][new] == fitted["model"]["coefficients"][dof][old]
        assert ahead["identification"]["diagnostics"][dof]["std_errors"][new] == \
            fitted["identification"]["diagnostics"][dof]["std_errors"][old]  # fmt: skip
    model = model_from_document(ahead, "ahead.json")
    ens = ensemble_from_document(ahead, "ahead.json", model)
    assert list(ens.model.structure.all_terms) == ahead["uncertainty"]["terms"]
    assert ahead["identification"]["discrete"] == fitted["identification"]["discrete"]
    # ... and so are its free runs ahead: validate on the training log, the same errors.
    a, f = (load_model(fitted_files[k]) for k in ("ahead", "fitted"))
    from shipid.data.io import read_log
    from shipid.evaluation.validate import validate

    log = read_log(fitted_files["log"])
    va, vf = (validate(m, log, start_draws=False)[0] for m in (a, f))
    assert va.metrics["r"]["std"] == pytest.approx(vf.metrics["r"]["std"], rel=1e-9)


def test_a_crash_stop_of_the_ahead_forms_comes_to_rest(fitted_files):
    """The crash stop ``identify`` runs (full astern from the approach, 600 s): the fitted
    forms' yaw damping u·r drives the yaw once the ship makes sternway, and the run diverges
    (noise seeds 3 and 5 of 3–5); the ahead forms back the ship steadily astern."""
    from shipid.identification.plausibility import crash_stop
    from shipid.reporting.modelfile import load_model

    speed = json.loads(fitted_files["ahead"].read_text())["identification"]["preprocessing"][
        "approach_speed"]  # fmt: skip
    checks = {k: crash_stop(load_model(fitted_files[k]), speed, N0) for k in ("ahead", "fitted")}
    assert checks == {"ahead": {"diverged": False, "reason": "", "at": None, "coasting": None},
                      "fitted": {**checks["fitted"], "diverged": True}}  # fmt: skip
    run_ = stopping(load_model(fitted_files["ahead"]), N0, duration=600.0, dt=0.1, speed=speed)
    tail = run_.log.iloc[-500:]
    assert float(np.ptp(tail["u"])) < 0.01 and float(tail["u"].mean()) < 0  # steady sternway
    assert float(np.max(np.abs(tail["r"]))) < 0.01


def test_a_log_that_goes_astern_keeps_the_fitted_forms(tmp_path):
    log = PAPER_IMU.apply(zigzag(scale_ship(rudder_rate_deg=9.6), 20, 20, duration=60, dt=0.2,
                                 method="euler", approach=2.0).log, seed=5)  # fmt: skip
    log.loc[log.index[-3:], "u"] = -0.01  # three samples of sternway
    path = write_log(log, tmp_path / "zz.csv")
    code, said, err = run(["identify", path, "--model", "blanke", "--no-output-error", "-o",
                           tmp_path / "m.json"])  # fmt: skip
    assert code == 0, err
    doc = json.loads((tmp_path / "m.json").read_text())
    assert "ahead_forms" not in doc["identification"] and "u*r" in doc["model"]["coefficients"]["r"]


def test_a_model_file_prior_in_the_other_forms_holds_the_fit(fitted_files, tmp_path):
    """A model file written in the ahead forms as the prior of a fit in the fitted forms (and
    the other way round): each term takes its twin's value, not 0."""
    from shipid.identification.priors import prior_from_model, prior_in_forms
    from shipid.reporting.modelfile import load_model

    prior = prior_in_forms(prior_from_model(load_model(fitted_files["ahead"])),
                           get_structure("blanke"))  # fmt: skip
    truth = load_model(fitted_files["fitted"]).coefficients
    assert prior["v"]["u*v"] == truth["v"]["u*v"] and prior["r"]["u*r"] == truth["r"]["u*r"]
    assert prior_in_forms({"v": {"u*v": 1.0}}, ModelStructure("s", {"v": ("|u|*v",)})) == \
        {"v": {"u*v": 1.0, "|u|*v": 1.0}}  # fmt: skip


@needs_data
def test_one_esso_zigzag_file_no_longer_diverges_in_a_random_run():
    """The default model of the 30°/30° file at 12 rps (13_50_28) diverged in every random
    run, the hull's damping u·r a drive in their sternway (−0.07 m/s in 03-Aug 11_04_37 at
    260 s); in its ahead forms it runs the whole 807 s (``benchmarks/study_ahead_forms.py``)."""
    import contextlib
    import io
    import tempfile

    from shipid.cli import main
    from shipid.evaluation.validate import validate
    from shipid.reporting.modelfile import load_model
    from shipid.trials.reading import read_trial_log

    train = OSAKA / "zigzag" / "zigzag_31-Jul-2020_13_50_28.csv"
    held = read_trial_log(OSAKA / "random" / "random_03-Aug-2020_11_04_37.csv", fmt="osaka-frt")
    diverged = {}
    with tempfile.TemporaryDirectory() as tmp:
        for key, extra in (("ahead", []), ("fitted", ["--no-ahead-forms", "--astern-thrust", "none"])):
            out = Path(tmp) / f"{key}.json"
            with contextlib.redirect_stdout(io.StringIO()), \
                    contextlib.redirect_stderr(io.StringIO()):  # fmt: skip
                assert main(["identify", "--format", "osaka-frt", str(train), *extra, "-o",
                             str(out)]) == 0  # fmt: skip
            sim = validate(load_model(out), held, start_draws=False)[0].simulation
            diverged[key] = sim is None or sim.diverged
    assert diverged == {"ahead": False, "fitted": True}


def test_select_checks_the_model_as_written_from_a_given_approach_too(fitted_files, tmp_path):
    """select's report of its model is of the file's model: in its ahead forms, also where
    --speed and --rps set the approach (its own check of the fit, in the fitted forms, was
    kept there: a crash stop that diverged for a model that does not)."""
    for extra, diverges in (([], False), (["--no-ahead-forms", "--astern-thrust", "none"], True)):
        out = tmp_path / "sel.json"
        code, _, err = run(["select", fitted_files["log"], "--library", "blanke", "--cv",
                            "blocks:3", "--quiet", "--speed", "2.0", "--rps", str(N0), *extra,
                            "-o", out])  # fmt: skip
        assert code == 0, err
        report = json.loads(out.read_text())["identification"]["plausibility"]
        assert report["astern"]["diverged"] is diverges, report["astern"]

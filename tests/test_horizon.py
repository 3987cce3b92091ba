"""Predictions over a horizon (``shipid.evaluation.horizon``): against the truth, which predicts
every window exactly, and against a brute-force re-run of each window on its own."""

import json
import math

import numpy as np
import pytest
from cli_helpers import run

from shipid.data.io import write_log
from shipid.dynamics.model import ManoeuvringModel
from shipid.dynamics.simulate import simulate_log
from shipid.errors import ShipidError
from shipid.evaluation.envelope import envelope, outside_envelope
from shipid.evaluation.horizon import horizon_errors
from shipid.reporting.modelfile import save_model
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import scale_ship_model


@pytest.fixture(scope="module")
def truth_and_log():
    truth = scale_ship_model()
    return truth, zigzag(truth, 20, 20, duration=90, dt=0.2, method="euler", speed=1.93).log


def _off(truth: ManoeuvringModel) -> ManoeuvringModel:
    coefs = {d: dict(c) for d, c in truth.coefficients.items()}
    coefs["r"]["u*r"] *= 0.95
    coefs["v"]["1"] += 0.001
    return ManoeuvringModel(truth.structure, coefs)


def test_the_truth_predicts_every_window_exactly(truth_and_log):
    truth, log = truth_and_log
    found = horizon_errors(truth, log, 10.0)
    assert found.windows == math.ceil((len(log) - 1) / 50) and found.diverged == 0
    assert max(found.rmse.values()) < 1e-9


@pytest.mark.parametrize("horizon", [3.0, 10.0, 25.0])
def test_each_window_is_the_free_run_from_its_measured_start(truth_and_log, horizon):
    truth, log = truth_and_log
    model = _off(truth)
    found = horizon_errors(model, log, horizon)
    assert found.diverged == 0
    steps = int(round(horizon / 0.2))
    errors = {s: [] for s in "uvr"}
    for a in range(0, len(log) - 1, steps):
        window = log.iloc[a : a + steps + 1].reset_index(drop=True)
        window = window.assign(t=window["t"] - window["t"].iloc[0])
        sim = simulate_log(model, window).log
        for s in "uvr":
            errors[s].append((sim[s].to_numpy() - window[s].to_numpy())[1:])
    for s in "uvr":
        rmse = float(np.sqrt(np.mean(np.concatenate(errors[s]) ** 2)))
        assert found.rmse[s] == pytest.approx(rmse, rel=1e-9)
        assert found.over_spread[s] == pytest.approx(rmse / float(np.std(log[s])), rel=1e-9)
    # Longer horizons let the error grow: the whole-log free run's is the limit.
    assert horizon_errors(model, log, 3.0).rmse["r"] < horizon_errors(model, log, 25.0).rmse["r"]


def test_windows_within_the_envelope_and_beyond_are_split_as_each_window_alone(truth_and_log):
    """The windows whose every signal keeps the training envelope and the rest: counted, and
    their errors, as ``outside_envelope`` judges each window cut out on its own."""
    truth, log = truth_and_log
    model = _off(truth)
    # The first 15 s as the training logs: the zig-zag's later, larger yaw rates leave it.
    env = envelope([log[log["t"] <= 15.0]])
    found = horizon_errors(model, log, 5.0, envelope=env)
    parts = {True: {s: [] for s in "uvr"}, False: {s: [] for s in "uvr"}}
    for a in range(0, len(log) - 1, 25):
        window = log.iloc[a : a + 26].reset_index(drop=True)
        inside = not outside_envelope(env, window)
        sim = simulate_log(model, window.assign(t=window["t"] - window["t"].iloc[0])).log
        for s in "uvr":
            parts[inside][s].append((sim[s].to_numpy() - window[s].to_numpy())[1:])
    n_inside = len(parts[True]["r"])
    assert 0 < n_inside < found.windows and found.inside == n_inside
    for inside, got in ((True, found.over_spread_inside), (False, found.over_spread_outside)):
        for s in "uvr":
            rmse = float(np.sqrt(np.mean(np.concatenate(parts[inside][s]) ** 2)))
            assert got[s] == pytest.approx(rmse / float(np.std(log[s])), rel=1e-9)
    assert "inside_envelope" in found.to_dict() and "inside_envelope" not in \
        horizon_errors(model, log, 5.0).to_dict()  # fmt: skip


def test_bad_horizons_are_refused(truth_and_log):
    truth, log = truth_and_log
    with pytest.raises(ShipidError, match="spans the whole log"):
        horizon_errors(truth, log, 200.0, name="zz.csv")
    with pytest.raises(ShipidError, match="--horizon must be seconds > 0"):
        horizon_errors(truth, log, 0.0)


def test_validate_prints_and_keeps_the_horizons(tmp_path, capsys, truth_and_log):
    truth, log = truth_and_log
    from shipid.identification.identify import identify

    path = write_log(log, tmp_path / "zz.csv")
    model = tmp_path / "m.json"
    save_model(model, identify(log))
    out = tmp_path / "v.json"
    code, text, err = run(["validate", model, path, "--horizon", "10,30", "--no-bands", "--json",
                           out, "--report", tmp_path / "report"], capsys)  # fmt: skip
    assert code == 0, err
    assert "Predictions over a horizon" in text and "|            30 |" in text
    assert "<h2>Predictions over a horizon</h2>" in (tmp_path / "report" / "report.html").read_text()
    rec = json.loads(out.read_text())["logs"][0]["horizons"]
    assert [h["horizon_s"] for h in rec] == [pytest.approx(10.0), pytest.approx(30.0)]
    # Its own training log keeps the model's envelope in every window: none beyond it.
    assert [h["inside_envelope"] for h in rec] == [h["windows"] for h in rec]
    assert rec[0]["over_spread_inside"]["r"] == pytest.approx(rec[0]["over_spread"]["r"])
    assert "in envelope" in text and "r error / spread in it" in text
    # A horizon as long as the log is a warning naming the log once (it was named twice).
    code, _, err = run(["validate", model, path, "--horizon", "500", "--no-bands"], capsys)
    assert code == 0 and f"{path}: a horizon of 500 s spans the whole log" in err
    assert f"{path}: {path}" not in err
    with pytest.raises(SystemExit) as exited:
        run(["validate", model, path, "--horizon", "10,x"], capsys)
    assert exited.value.code == 2 and "expected seconds > 0" in capsys.readouterr().err

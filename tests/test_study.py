"""Monte Carlo studies (issue #13 item 6): the spec, one trial against a direct computation,
the same results serially and on a local Dask cluster, failures kept in their rows."""

import math

import numpy as np
import pandas as pd
import pytest

from shipid.errors import ShipidError
from shipid.evaluation import study
from shipid.evaluation.study import StudySpec, Trial, run_study, run_trial, summary


def test_the_spec_crosses_the_grid_with_the_seeds():
    spec = StudySpec.from_dict({"seeds": 3, "filter": ["auto", 0.5], "gamma": 1e3})
    trials = spec.trials()
    assert len(trials) == 6 and [t.index for t in trials] == list(range(6))
    assert [(t.filter, t.seed) for t in trials] == [("auto", 0), ("auto", 1), ("auto", 2),
                                                   ("0.5", 0), ("0.5", 1), ("0.5", 2)]
    assert {t.gamma for t in trials} == {1e3}
    assert StudySpec.from_dict({"seeds": [4, 7]}).seeds == (4, 7)


def test_the_documented_spec_reads(tmp_path):
    from pathlib import Path

    spec = StudySpec.read(Path(__file__).resolve().parents[1] / "docs" / "study.yml")
    assert spec.seeds == tuple(range(200)) and spec.gamma == (1e4,)  # YAML 1.1 reads 1.0e4 as text
    assert spec.filter == ("auto", "none") and len(spec.trials()) == 400
    (tmp_path / "s.yml").write_text("gamma: [1.0e4, ten]\n", encoding="utf-8")
    with pytest.raises(ShipidError, match="gamma: 'ten' is not a number"):
        StudySpec.read(tmp_path / "s.yml")


@pytest.mark.parametrize("spec, message", [
    ({"noice": 2}, "unknown key 'noice'"),
    ({"seeds": 0}, "seeds"),
    ({"seeds": [1, 1]}, "repeated seeds"),
    ({"seeds": "many"}, "seeds"),
    ({"filter": "soon"}, "filter: 'soon'"),
    ({"filter": -1}, "filter: '-1'"),
    ({"gamma": [0]}, "gamma"),
    ({"noise": [-0.5]}, "noise"),
    ({"structure": ["nonsense"]}, "structure"),
    ({"estimator": ["magic"]}, "estimator: 'magic'"),
    ({"bootstrap": 5}, "bootstrap"),
    ({"gamma": []}, "gamma: give at least one value"),
    ([1, 2], "mapping"),
])  # fmt: skip
def test_bad_specs_are_named(spec, message):
    with pytest.raises(ShipidError, match=message):
        StudySpec.from_dict(spec, source="s.yml")


def test_a_trial_is_the_direct_computation():
    from shipid.data.preprocess import lowpass
    from shipid.demo import TRAINING, synthesise_trials
    from shipid.evaluation.validate import validate
    from shipid.identification.identify import identify

    row = run_trial(Trial(0, seed=3, filter="0.5", noise=2.0))
    assert row["error"] == "" and row["cutoff_hz"] == 0.5
    from shipid.vessels import PAPER_IMU

    logs = synthesise_trials(3, sensor=PAPER_IMU.scaled(2.0))
    model = identify(lowpass(logs[TRAINING], 0.5), gamma=1e4, drop={"u": ["r^2"]}).model
    held = [k for k in logs if k != TRAINING]
    for v in validate(model, [logs[k] for k in held], held):
        for s in "uvr":
            assert row[f"{v.name}: {s} error std"] == pytest.approx(v.metrics[s]["std"], rel=1e-12)
    assert row["v: delta"] == pytest.approx(model.coefficients["v"]["delta"], rel=1e-12)


def test_without_noise_the_truth_is_recovered():
    from shipid.vessels import scale_ship_model

    # γ = 1e8: barely regularised, so the Euler-discretised truth is solved for exactly
    row = run_trial(Trial(0, seed=0, noise=0.0, filter="none", gamma=1e8))
    truth = scale_ship_model()
    for dof, terms in truth.coefficients.items():
        for term, value in terms.items():
            if (dof, term) != ("u", "r^2"):  # dropped, as the paper
                assert row[f"{dof}: {term}"] == pytest.approx(value, rel=1e-4, abs=1e-7)
    assert row["zigzag 10/10: r truth error std"] < 1e-9
    assert row["zigzag 10/10: r error std"] < 1e-6


def test_serial_and_dask_give_identical_results():
    spec = StudySpec(seeds=(0, 5), filter=("0.5",))
    serial = run_study(spec, "serial", progress=False)
    local = run_study(spec, None, workers=1, progress=False)
    assert len(serial) == 2 and (serial["error"] == "").all()
    pd.testing.assert_frame_equal(serial.drop(columns="seconds"), local.drop(columns="seconds"),
                                  check_exact=True)  # fmt: skip


def test_a_failed_trial_keeps_its_row_and_the_others_run(monkeypatch):
    real = study._trial_results

    def flaky(trial):
        if trial.seed == 1:
            raise np.linalg.LinAlgError("singular matrix")
        return real(trial)

    monkeypatch.setattr(study, "_trial_results", flaky)
    results = run_study(StudySpec(seeds=(0, 1, 2), filter=("none",)), "serial", progress=False)
    assert results["error"].tolist() == ["", "LinAlgError: singular matrix", ""]
    assert math.isnan(results.loc[1, "zigzag 10/10: u error std"])
    table = summary(results)
    assert table.loc[0, "failed"] == 1 and table.loc[0, "zigzag 10/10: beats paper"].endswith(" of 2")


def test_bootstrap_coverage_counts_the_true_coefficients_inside_their_intervals():
    from shipid.data.preprocess import lowpass
    from shipid.demo import TRAINING, synthesise_trials
    from shipid.identification.identify import identify
    from shipid.identification.uncertainty import bootstrap
    from shipid.vessels import scale_ship_model

    row = run_trial(Trial(0, seed=1, filter="0.5", bootstrap=10))
    assert row["error"] == ""
    train = lowpass(synthesise_trials(1)[TRAINING], 0.5)
    ens = bootstrap([train], lambda w: identify(train, drop={"u": ["r^2"]}, force=True,
                                                sample_weight=w).model, replicates=10, seed=1)
    truth = scale_ship_model().coefficients
    inside = [lo <= truth[d].get(t, 0.0) <= hi for d, t, lo, hi in
              ens.coefficient_table()[["equation", "term", "lower", "upper"]].itertuples(
                  index=False)]  # fmt: skip
    assert len(inside) == 16 and row["coverage"] == pytest.approx(np.mean(inside))
    assert 0 < row["coverage"] < 1  # this seed: some inside, some not (the bias of issue #10)


def test_workers_only_for_the_local_cluster():
    with pytest.raises(ShipidError, match="workers"):
        run_study(StudySpec(seeds=(0,)), "tcp://127.0.0.1:1", workers=2, progress=False)


def test_the_command_writes_one_row_per_trial(tmp_path, capsys):
    from shipid.cli import main

    spec = tmp_path / "s.yml"
    spec.write_text("seeds: [2, 3]\nfilter: [none, 0.5]\n", encoding="utf-8")
    out = tmp_path / "r.parquet"
    assert main(["study", str(spec), "-o", str(out), "--scheduler", "serial", "--quiet"]) == 0
    text = capsys.readouterr().out
    assert "4 trials (2 seeds × 2 grid points) on this process" in text
    assert "| filter none" in text and "| filter 0.5" in text
    results = pd.read_parquet(out)
    assert results[["seed", "filter"]].values.tolist() == [[2, "none"], [3, "none"], [2, "0.5"],
                                                           [3, "0.5"]]


@pytest.mark.parametrize("text, args, message", [
    ("seeds: 2\nnoice: 1\n", [], "s.yml: unknown key 'noice'"),
    ("seeds: [2\n", [], "s.yml: not valid YAML"),
    ("seeds: 2\n", ["--workers", "0"], "--workers"),
])  # fmt: skip
def test_the_command_refuses_a_bad_spec_in_one_line(tmp_path, capsys, text, args, message):
    from shipid.cli import main

    spec = tmp_path / "s.yml"
    spec.write_text(text, encoding="utf-8")
    out = tmp_path / "r.csv"
    assert main(["study", str(spec), "-o", str(out), *args]) == 1
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()

"""The cross-validated error band (issue #10): the conformal quantile against its definition and
its coverage of new errors from a known distribution; select's band against held-out free runs
recomputed by hand; the band in model files, validate and rescale."""

import json
import math

import numpy as np
import pytest
from cli_helpers import run
from generated_logs import noisy_zigzags

from shipid.data.io import read_log, write_log
from shipid.dynamics.simulate import simulate_log
from shipid.errors import ShipidError
from shipid.evaluation.error_band import ErrorBand, conformal_quantile, error_band, key_indices
from shipid.evaluation.validate import validate
from shipid.identification.identify import identify
from shipid.identification.select import select


def test_conformal_quantile_is_the_rank_of_its_definition():
    e = np.arange(1.0, 20.0)  # 19 errors: the ⌈20 · 0.95⌉ = 19th smallest
    assert conformal_quantile(e[::-1], 0.95) == 19.0
    assert conformal_quantile(e, 0.5) == 10.0  # ⌈20 · 0.5⌉ = 10th
    assert conformal_quantile(np.arange(10.0), 0.95) == math.inf  # ⌈11 · 0.95⌉ = 11 > 10


@pytest.mark.parametrize("level", [0.8, 0.95])
def test_the_band_holds_its_level_of_new_exchangeable_errors(level):
    rng = np.random.default_rng(4)
    runs = []
    for _ in range(20):  # 20 held-out "logs" of 300 samples, heavy-tailed errors per state
        measured = rng.normal(size=(300, 3))
        runs.append((measured, measured + rng.laplace(scale=[0.1, 0.02, 0.005], size=(300, 3))))
    band = error_band(runs, level)
    assert band.logs == 20 and band.samples == 6000
    fresh = rng.normal(size=(200_000, 3))
    shares = band.shares_within(fresh, fresh + rng.laplace(scale=[0.1, 0.02, 0.005],
                                                            size=(200_000, 3)))  # fmt: skip
    for s in "uvr":
        assert shares[s] == pytest.approx(level, abs=0.01)
    # Closed form of the Laplace quantile: |e| ≤ b ln(1 / (1 − level)) with probability level.
    assert band.half_width["u"] == pytest.approx(0.1 * math.log(1 / (1 - level)), rel=0.06)


def test_samples_after_a_divergence_are_outside():
    measured = np.zeros((100, 3))
    band = error_band([(measured, np.zeros((90, 3)))], 0.95)  # 10 % of the samples diverged
    assert band.half_width == {"u": math.inf, "v": math.inf, "r": math.inf}
    band = error_band([(measured, np.zeros((99, 3)))], 0.95)
    assert band.half_width["r"] == 0.0
    assert band.shares_within(measured, np.zeros((80, 3)))["u"] == 0.8


def test_each_held_out_run_is_summed_up_by_its_rms_error_over_its_spread():
    """A free run off its log by a constant c over a sine of amplitude a: rms error c, the log's
    standard deviation a/√2 (closed forms); its mean alone, the ratio 1; a run that diverged
    is judged over its part and says where it stopped."""
    t = np.linspace(0.0, 20 * np.pi, 4001)[:-1]  # whole periods
    measured = np.column_stack([2.0 * np.sin(t), 0.5 * np.cos(t), 0.1 * np.sin(t)])
    offset = measured + np.array([0.3, 0.0, 0.01])
    mean_only = np.tile(measured.mean(axis=0), (len(t), 1))
    band = error_band([(measured, offset), (measured, mean_only), (measured, offset[:1000])],
                      names=["a.csv", "b.csv", "c.csv"])  # fmt: skip
    a, b, c = band.runs
    assert a.name == "a.csv" and not a.diverged
    assert a.error_over_spread["u"] == pytest.approx(0.3 / (2.0 / math.sqrt(2)), rel=1e-9)
    assert a.error_over_spread["v"] == 0.0
    assert a.error_over_spread["r"] == pytest.approx(0.01 / (0.1 / math.sqrt(2)), rel=1e-9)
    assert b.error_over_spread == pytest.approx({"u": 1.0, "v": 1.0, "r": 1.0}, rel=1e-9)
    assert c.diverged and (c.samples, c.simulated) == (4000, 1000)
    assert band.run_rows()[2]["diverged"] == "after 1000 of 4000 samples"
    assert band.runs_summary() == ("its 3 held-out logs, each run free on the fit without it, "
                                   "missed their yaw rate by 0.14–1 of its spread (rms), 1 "
                                   "diverged")  # fmt: skip
    # Kept through the model file and a rescaling (ratios have no units); older files had none.
    back = ErrorBand.from_dict(json.loads(json.dumps(band.scaled(2.0).to_dict())))
    assert back.runs == band.runs
    old = band.to_dict()
    del old["runs"]
    assert ErrorBand.from_dict(old).runs == () and ErrorBand.from_dict(old).runs_summary() is None
    bad = band.to_dict()
    bad["runs"][1]["simulated"] = 0
    with pytest.raises(ShipidError, match=r"runs\[1\]: simulated must be within"):
        ErrorBand.from_dict(bad)
    with pytest.raises(ShipidError, match="3 runs got 2 names"):
        error_band([(measured, offset)] * 3, names=["a", "b"])


def test_a_held_out_trial_keeps_its_indices_measured_and_predicted():
    """The indices a held-out run reports by the kind of trial it is, read off a validation's
    measured and closed-loop ones; kept through the model file, a missing one as None."""
    indices = {"measured": {"tactical_diameter": 7.27, "steady_yaw_rate": 0.0452, "advance": 8.2},
               "closed_loop": {"tactical_diameter": 6.91, "steady_yaw_rate": None}}  # fmt: skip
    turn = key_indices("turning", indices)
    assert turn == {"tactical_diameter": (7.27, 6.91), "steady_yaw_rate": (0.0452, None)}
    assert key_indices("other", indices) == {} and key_indices(None, {}) == {}
    log = np.column_stack([np.sin(np.linspace(0, 6, 50))] * 3)
    band = error_band([(log, log), (log, log)], names=["turn.csv", "random.csv"],
                      indices=[turn, {}])  # fmt: skip
    rows = band.run_rows()
    assert rows[0]["indices: measured → predicted (closed loop)"] == \
        "tactical diameter, steady r 7.27, 0.0452 → 6.91, –"
    assert rows[1]["indices: measured → predicted (closed loop)"] == "–"
    back = ErrorBand.from_dict(json.loads(json.dumps(band.to_dict())))
    assert back.runs[0].indices == turn and back.runs[1].indices == {}
    # A ship with speeds 3 times these (Froude, 9 times as long): lengths ×9, rates ÷3.
    big = band.scaled(3.0).runs[0].indices
    assert big["tactical_diameter"] == pytest.approx((7.27 * 9, 6.91 * 9), rel=1e-12)
    assert big["steady_yaw_rate"][0] == pytest.approx(0.0452 / 3) and big["steady_yaw_rate"][1] is None
    zigzag = error_band([(log, log)], indices=[{"first_overshoot_deg": (10.0, 11.0)}])
    assert zigzag.scaled(3.0).runs[0].indices == {"first_overshoot_deg": (10.0, 11.0)}


@pytest.fixture(scope="module")
def zigzags():
    return noisy_zigzags(30)


def test_select_band_is_the_quantile_of_its_held_out_free_runs(zigzags):
    sel = select(zigzags, library="blanke", search="none", gammas=(1e4,))
    runs = []
    for i, log in enumerate(zigzags):
        fold = identify([x for j, x in enumerate(zigzags) if j != i], model=sel.model.structure,
                        gamma=sel.gamma, force=True).model  # fmt: skip
        runs.append(np.abs(simulate_log(fold, log).log[["u", "v", "r"]].to_numpy()
                           - log[["u", "v", "r"]].to_numpy()))  # fmt: skip
    errors = np.vstack(runs)
    k = math.ceil((len(errors) + 1) * 0.95)
    for j, s in enumerate("uvr"):
        assert sel.error_band.half_width[s] == pytest.approx(np.sort(errors[:, j])[k - 1],
                                                             rel=1e-9)  # fmt: skip
    assert sel.error_band.logs == 3 and sel.error_band.samples == len(errors)
    for run_of, err, log, fold in zip(sel.error_band.runs, runs, zigzags, sel.folds, strict=True):
        assert run_of.name == fold["held_out"]
        assert run_of.error_over_spread["r"] == pytest.approx(
            np.sqrt(np.mean(err[:, 2] ** 2)) / np.std(log["r"].to_numpy()), rel=1e-9)
    # Validated with it: each log's share of samples inside, as counted here.
    v = validate(sel.model, zigzags[:1], error_band=sel.error_band)[0]
    err = np.abs(v.simulation.log[["u", "v", "r"]].to_numpy() - zigzags[0][["u", "v", "r"]].to_numpy())
    assert v.band_shares["r"] == pytest.approx(np.mean(err[:, 2] <= sel.error_band.half_width["r"]))


def test_band_in_the_model_file_validate_and_rescale(zigzags, tmp_path, capsys):
    paths = [write_log(log, tmp_path / f"zz{i}.csv") for i, log in enumerate(zigzags)]
    code, out, err = run(["select", *paths, "--library", "blanke", "--quiet", "-o",
                          tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "cross-validated 95 % error band (free runs of 3 held-out logs" in out
    doc = json.loads((tmp_path / "m.json").read_text(encoding="utf-8"))
    band = ErrorBand.from_dict(doc["identification"]["selection"]["error_band"])
    code, out, err = run(["validate", tmp_path / "m.json", paths[0], "--json",
                          tmp_path / "v.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "in CV band r [%]" in out and f"r ±{band.half_width['r']:.4g} rad/s" in out
    assert f"; {band.runs_summary()}." in out and len(band.runs) == 3
    record = json.loads((tmp_path / "v.json").read_text(encoding="utf-8"))["logs"][0]
    assert 0.5 < record["within_error_band"]["r"] <= 1.0
    # A ship 16 times as long: speeds ×4, yaw rates ÷4.
    code, out, err = run(["rescale", tmp_path / "m.json", "--factor", "16", "-o",
                          tmp_path / "big.json"], capsys)  # fmt: skip
    assert code == 0, err
    big = json.loads((tmp_path / "big.json").read_text(encoding="utf-8"))
    scaled = big["identification"]["selection"]["error_band"]["half_width"]
    assert scaled["u"] == pytest.approx(4 * band.half_width["u"], rel=1e-12)
    assert scaled["r"] == pytest.approx(band.half_width["r"] / 4, rel=1e-12)
    # A malformed band: one line naming the file and the field, exit 1.
    doc["identification"]["selection"]["error_band"]["level"] = 2
    (tmp_path / "bad.json").write_text(json.dumps(doc), encoding="utf-8")
    code, out, err = run(["validate", tmp_path / "bad.json", paths[0]], capsys)
    assert code == 1 and "bad.json: identification.selection.error_band" in err
    with pytest.raises(ShipidError, match="not an error band"):
        ErrorBand.from_dict({"level": 0.95})


def test_a_band_from_blocks_says_so(zigzags):
    sel = select(zigzags[:1], library="blanke", search="none", gammas=(1e4,), cv="blocks:3")
    band = sel.error_band
    assert band.held_out == "blocks" and band.logs == 3
    assert "held-out blocks" in band.describe() and "whole logs stray further" in band.describe()
    assert ErrorBand.from_dict(band.to_dict()) == band
    with pytest.raises(ShipidError, match="held_out must be"):
        ErrorBand.from_dict(dict(band.to_dict(), held_out="folds"))


def test_the_report_draws_its_own_figures_with_both_bands(zigzags, monkeypatch):
    """The HTML report drew its own figures (no --plots PNGs to share) without the bootstrap
    bands; they carry both bands now."""
    from shipid.identification.selection_ensemble import selection_ensemble
    from shipid.reporting import plots
    from shipid.reporting.html import validation_report

    sel = select(zigzags, library="blanke+abkowitz3")
    ens = selection_ensemble(zigzags, sel, replicates=10)
    vals = validate(sel.model, zigzags[:1], ensemble=ens, error_band=sel.error_band)
    seen = []

    def record(measured, simulated, path, title="", out=None, bands=None, error_band=None,
               tied=None):
        seen.append((bands, error_band))
        path.write(b"png")

    monkeypatch.setattr(plots, "measured_vs_simulated", record)
    text = validation_report(sel.model, vals, zigzags[:1], "report")
    assert "in CV band r" in text
    # The model's training logs, each held out, as identify printed them.
    assert "The model's training logs, each held out" in text
    assert all(f"<td>{r.name}</td>" in text for r in sel.error_band.runs)
    assert seen and seen[0][0] is vals[0].bands and seen[0][1] is sel.error_band


def test_identify_error_band_is_its_fit_without_each_log(zigzags, tmp_path, capsys):
    paths = [write_log(log, tmp_path / f"zz{i}.csv") for i, log in enumerate(zigzags)]
    code, out, err = run(["identify", *paths, "--model", "blanke", "--filter", "none",
                          "--error-band", "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "cross-validated 95 % error band (free runs of 3 held-out logs" in out
    doc = json.loads((tmp_path / "m.json").read_text(encoding="utf-8"))
    band = ErrorBand.from_dict(doc["identification"]["error_band"])
    logs = [read_log(p) for p in paths]
    errors = []
    for i, log in enumerate(logs):
        fit = identify([x for j, x in enumerate(logs) if j != i], model="blanke", force=True).model
        errors.append(np.abs(simulate_log(fit, log).log[["u", "v", "r"]].to_numpy()
                             - log[["u", "v", "r"]].to_numpy()))  # fmt: skip
        # Each held-out log's own figure, printed and stored: rms error over its spread.
        run_of_it = band.runs[i]
        assert run_of_it.name == str(paths[i]) and not run_of_it.diverged
        # The held-out zig-zag run closed loop on the fit without it: its overshoots predicted.
        v = validate(fit, log, start_draws=False)[0]
        assert v.kind == "zigzag" and set(run_of_it.indices) == {"first_overshoot_deg",
                                                                  "second_overshoot_deg"}
        for k, (measured, predicted) in run_of_it.indices.items():
            assert measured == pytest.approx(v.indices["measured"][k], rel=1e-12)
            assert predicted == pytest.approx(v.indices["closed_loop"][k], rel=1e-12)
        for j, s in enumerate("uvr"):
            expected = np.sqrt(np.mean(errors[-1][:, j] ** 2)) / np.std(log[s].to_numpy())
            assert run_of_it.error_over_spread[s] == pytest.approx(expected, rel=1e-9)
    assert "each held-out log, run free on the model fitted without it" in out
    first = band.runs[0].indices
    assert (f"overshoots {first['first_overshoot_deg'][0]:.3g}, "
            f"{first['second_overshoot_deg'][0]:.3g} → {first['first_overshoot_deg'][1]:.3g}") in out
    assert f"| {paths[0]} |" in out
    errors = np.vstack(errors)
    k = math.ceil((len(errors) + 1) * 0.95)
    assert band.half_width["v"] == pytest.approx(np.sort(errors[:, 1])[k - 1], rel=1e-9)
    code, out, err = run(["validate", tmp_path / "m.json", paths[0]], capsys)
    assert code == 0 and "in CV band r [%]" in out, err
    code, out, err = run(["rescale", tmp_path / "m.json", "--factor", "4", "-o",
                          tmp_path / "big.json"], capsys)  # fmt: skip
    big = json.loads((tmp_path / "big.json").read_text(encoding="utf-8"))["identification"]
    assert code == 0 and big["error_band"]["half_width"]["r"] == pytest.approx(
        band.half_width["r"] / 2, rel=1e-12)
    # One log: four blocks of it; with --refine: refused (the band describes the LS-SVM fit).
    code, out, err = run(["identify", paths[0], "--filter", "none", "--error-band", "-o",
                          tmp_path / "one.json"], capsys)  # fmt: skip
    assert code == 0 and "4 held-out blocks" in out, err
    code, out, err = run(["identify", paths[0], "--refine", "--error-band", "-o",
                          tmp_path / "r.json"], capsys)  # fmt: skip
    assert code == 1 and "--error-band describes the LS-SVM fit" in err
    assert not (tmp_path / "r.json").exists()
    code, out, err = run(["identify", paths[0], "--error-band", "kfold:2", "-o",
                          tmp_path / "k.json"], capsys)  # fmt: skip
    assert code == 1 and "--error-band must be" in err and not (tmp_path / "k.json").exists()


def test_identify_gives_the_band_by_default_from_two_logs(zigzags, tmp_path, capsys):
    """Issue #10: honest uncertainty without flags. From two logs on, a plain ``identify`` whose
    file holds its LS-SVM fit stores the band of ``--error-band logo``; ``--error-band none``
    and one log store none."""
    paths = [write_log(log, tmp_path / f"zz{i}.csv") for i, log in enumerate(zigzags)]
    base = ["identify", *paths, "--model", "blanke", "--filter", "none"]
    code, out, err = run([*base, "-o", tmp_path / "d.json"], capsys)
    assert code == 0, err
    assert "(--error-band none to skip)" in out and "output error: not fitted" in out
    code, _, err = run([*base, "--error-band", "logo", "-o", tmp_path / "e.json"], capsys)
    assert code == 0, err
    default, explicit = (json.loads((tmp_path / f"{n}.json").read_text())["identification"]
                         for n in "de")  # fmt: skip
    assert default["error_band"] == explicit["error_band"]
    assert default["error_band"]["logs"] == 3
    for argv, name in (([*base, "--error-band", "none"], "n"),
                       (["identify", paths[0], "--model", "blanke", "--filter", "none"], "o")):
        code, out, err = run([*argv, "-o", tmp_path / f"{name}.json"], capsys)
        assert code == 0, err
        assert "error band" not in out
        # One log: nothing held out, and identify says so with what to do.
        assert ("one log: none was held out" in out) == (name == "o")
        assert json.loads((tmp_path / f"{name}.json").read_text())["identification"].get(
            "error_band") is None

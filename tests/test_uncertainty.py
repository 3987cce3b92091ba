"""Uncertainty (issue #10): the moving-block bootstrap against the closed-form standard error of
an autocorrelated mean, the ensemble in model files, and its intervals through the CLI."""

import json
import math

import numpy as np
import pytest
from cli_helpers import run

from shipid.data.io import write_log
from shipid.dynamics.model import ManoeuvringModel
from shipid.errors import ShipidError
from shipid.identification.identify import identify
from shipid.identification.uncertainty import (
    LOG_METHOD,
    Ensemble,
    block_weights,
    bootstrap,
    interval,
    log_weights,
)
from shipid.reporting.modelfile import ensemble_from_document, load_document, model_from_document
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import SensorModel, scale_ship


def test_blocks_stay_inside_their_log():
    rng = np.random.default_rng(1)
    for _ in range(200):
        # Blocks as long as the logs: each replicate takes whole logs, so its weights are
        # constant over each log.
        w = block_weights([40, 40, 40], 40, rng)
        assert w.sum() == 120
        assert all(len(set(w[i * 40:(i + 1) * 40])) == 1 for i in range(3))
        w = block_weights([7, 30], 10, rng)
        assert w.sum() >= 37 and w[:7].sum() % 7 == 0  # the short log only as a whole


def test_block_bootstrap_of_an_autocorrelated_mean_matches_the_closed_form():
    """AR(1) noise, φ = 0.8: the standard error of the mean is σ_e/(1 − φ)/√n, three times the
    i.i.d. formula. Blocks much longer than the correlation time recover it; single samples
    (blocks of one) give the i.i.d. value."""
    phi, n, sigma = 0.8, 4000, 1.0
    rng = np.random.default_rng(7)
    e = np.zeros(n)
    for k in range(1, n):
        e[k] = phi * e[k - 1] + sigma * rng.normal()
    log = __import__("pandas").DataFrame({"t": np.arange(n + 1) * 0.1})
    data = e

    class Mean:
        theta = None

    def fit(weights):
        w = np.ones(n) if weights is None else weights
        m = Mean()
        m.theta = np.array([[np.sum(w * data) / np.sum(w)]])
        return m

    closed = sigma / (1 - phi) / math.sqrt(n)
    iid = np.std(data) / math.sqrt(n)
    long_blocks = bootstrap([log], fit, replicates=400, block_s=5.0, seed=2).thetas[:, 0, 0]
    single = bootstrap([log], fit, replicates=400, block_s=0.1, seed=2).thetas[:, 0, 0]
    assert np.std(long_blocks) == pytest.approx(closed, rel=0.25)
    assert np.std(single) == pytest.approx(iid, rel=0.2)
    assert interval([1.0, 2.0, 3.0], 0.5) == (1.5, 2.5)
    # One of four without a value is more than the 25 % tail of a 50 % interval.
    assert interval([1.0, 2.0, math.nan, 3.0], 0.5) == (-math.inf, math.inf)


def test_whole_logs_are_drawn_with_replacement():
    rng = np.random.default_rng(4)
    lengths = [5, 9, 3, 12, 7]
    counts = np.zeros(5)
    for _ in range(2000):
        w = log_weights(lengths, rng)
        parts = np.split(w, np.cumsum(lengths)[:-1])
        assert all(len(set(p)) == 1 for p in parts)  # a log is drawn whole or not at all
        k = np.array([p[0] for p in parts])
        assert k.sum() == 5 and np.all(k == np.round(k))
        counts += k
    np.testing.assert_allclose(counts / 2000, 1.0, atol=0.06)  # each log once on average


def test_log_bootstrap_of_a_mean_holds_the_logs_spread():
    """Eight logs whose levels differ (a day's wind, a campaign's loading) by more than their
    samples' noise says: the standard error of the pooled mean is the spread of the log means
    over √8 (the plug-in of whole-log resampling, Σ(m_i − m̄)²/n/n). Blocks of a second count
    each log as 40 independent pieces of it and give about a sixth of that."""
    rng = np.random.default_rng(11)
    n_logs, n = 8, 400
    levels = rng.normal(0.0, 1.0, n_logs)
    data = np.concatenate([lv + 0.2 * rng.normal(size=n) for lv in levels])
    logs = [__import__("pandas").DataFrame({"t": np.arange(n + 1) * 0.1})] * n_logs

    class Mean:
        theta = None

    def fit(weights):
        w = np.ones(data.size) if weights is None else weights
        m = Mean()
        m.theta = np.array([[np.sum(w * data) / np.sum(w)]])
        return m

    means = data.reshape(n_logs, n).mean(axis=1)
    closed = math.sqrt(np.mean((means - means.mean()) ** 2) / n_logs)
    ens = bootstrap(logs, fit, replicates=600, block_s="log", seed=3)
    assert ens.method == ens.resampling == LOG_METHOD and ens.block_s == "log"
    assert np.std(ens.thetas[:, 0, 0]) == pytest.approx(closed, rel=0.1)
    blocks = bootstrap(logs, fit, replicates=200, block_s=1.0, seed=3).thetas[:, 0, 0]
    assert np.std(blocks) < closed / 4
    with pytest.raises(ShipidError, match="needs at least 5 of them, got 4"):
        bootstrap(logs[:4], fit, replicates=20, block_s="log")
    with pytest.raises(ShipidError, match="> 0 s or 'log'"):
        bootstrap(logs, fit, replicates=20, block_s="logs")


@pytest.fixture(scope="module")
def noisy_zigzag():
    log = zigzag(scale_ship(), 20, 20, duration=40, dt=0.2).log
    return SensorModel(white={"u": 0.005, "v": 0.005, "r": 0.003}).apply(log, seed=5)


def test_ensemble_round_trips_and_is_validated(noisy_zigzag):
    ens = bootstrap([noisy_zigzag], lambda w: identify(noisy_zigzag, sample_weight=w,
                                                       force=True).model, replicates=12)  # fmt: skip
    assert ens.thetas.shape == (12, *ens.model.theta.shape)
    again = Ensemble.from_dict(json.loads(json.dumps(ens.to_dict())), ens.model)
    np.testing.assert_array_equal(again.thetas, ens.thetas)
    table = ens.coefficient_table()
    assert (table["lower"] <= table["upper"]).all() and len(table) == 17
    members = ens.members()
    np.testing.assert_array_equal(members[3].theta, ens.thetas[3])
    other = ManoeuvringModel("nomoto1", {"r": {"r": -1.0, "delta": 0.1}})
    with pytest.raises(ShipidError, match="not the model's"):
        Ensemble.from_dict(ens.to_dict(), other)
    bad = ens.to_dict()
    bad["thetas"][0][0][0] = float("nan")
    with pytest.raises(ShipidError, match="non-finite"):
        Ensemble.from_dict(bad, ens.model)


def test_cli_bootstrap_bands_and_intervals(tmp_path, capsys, noisy_zigzag):
    log = write_log(noisy_zigzag, tmp_path / "zz.csv")
    model = tmp_path / "m.json"
    code, out, err = run(["identify", log, "--bootstrap", "20", "--block", "4", "-o", model],
                         capsys)  # fmt: skip
    assert code == 0, err
    assert "95 % intervals of the coefficients" in out
    doc = load_document(model)
    ens = ensemble_from_document(doc, model, model_from_document(doc, model))
    assert ens.replicates == 20 and ens.block_s == 4.0
    code, out, err = run(["validate", model, log, "--json", tmp_path / "v.json", "--quiet"],
                         capsys)  # fmt: skip
    assert code == 0, err
    assert "closed loop 95 %" in out
    rec = json.loads((tmp_path / "v.json").read_text())["logs"][0]
    lo, hi = rec["index_intervals"]["closed_loop"]["first_overshoot_deg"]
    assert lo <= hi and rec["ensemble_diverged"] == 0
    code, out, err = run(["manoeuvre", model, "turning", "--rudder", "20", "--duration", "40"],
                         capsys)  # fmt: skip
    assert code == 0, err
    line = next(ln for ln in out.splitlines() if ln.startswith("tactical_diameter:"))
    value = float(line.split()[1])
    lo, hi = (float(x) for x in line.split("[")[1].rstrip("]").split(","))
    width = hi - lo
    assert width > 0 and lo - width <= value <= hi + width
    code, out, err = run(["criteria", model, "--length", "4.389", "--json", tmp_path / "c.json"],
                         capsys)  # fmt: skip
    assert code == 0, err
    assert "pass_share" in out
    rows = json.loads((tmp_path / "c.json").read_text())["criteria"]
    assert all(0.0 <= r["pass_share"] <= 1.0 and r["lower"] <= r["upper"] for r in rows
               if r["value"] is not None)  # fmt: skip
    code, _, err = run(["identify", log, "--bootstrap", "20", "--refine", "-o",
                        tmp_path / "x.json"], capsys)  # fmt: skip
    assert code == 1 and "does not go with --refine" in err


@pytest.mark.parametrize("n", [40, 100, 401])
@pytest.mark.parametrize("missing", [0, 1, 2, 3, 6])
def test_interval_counts_replicates_without_a_value_at_the_worst_end(n, missing):
    """Against a brute force: NumPy's percentile with each missing replicate replaced by a huge
    value below every other (for the lower bound) or above (for the upper one). Whatever the
    sentinel touches is unbounded; the rest is NumPy's interval."""
    rng = np.random.default_rng(n + missing)
    values = rng.normal(size=n)
    values[rng.choice(n, missing, replace=False)] = np.nan
    big = 1e300
    lo_ref = np.percentile(np.where(np.isnan(values), -big, values), 2.5)
    hi_ref = np.percentile(np.where(np.isnan(values), big, values), 97.5)
    lo, hi = interval(values)
    for got, ref, worst in ((lo, lo_ref, -math.inf), (hi, hi_ref, math.inf)):
        if abs(ref) > 1e200:
            assert got == worst
        else:
            assert got == pytest.approx(ref, rel=1e-12, abs=1e-12)
    if missing == 0:
        assert (lo, hi) == pytest.approx(tuple(np.percentile(values, [2.5, 97.5])))
    # More missing than the tail (2.5 %) holds: not bounded at either end.
    assert math.isinf(lo) == (missing > 0.025 * (n - 1))


def test_diverged_replicates_unbound_the_index_intervals_and_the_bands():
    from types import SimpleNamespace

    import pandas as pd

    from shipid.identification.uncertainty import free_run_bands, index_intervals

    # 10 of 100 replicates diverged: leaving them out gave a narrow interval that could
    # exclude the model's own value (found on the KVLCC2's 35° turn).
    samples = [{"tactical_diameter": 20.0 + 0.01 * k} for k in range(90)] + [{}] * 10
    assert index_intervals(samples)["tactical_diameter"] == (-math.inf, math.inf)
    assert index_intervals(samples[:90] + [{}])["tactical_diameter"] == pytest.approx(
        interval([20.0 + 0.01 * k for k in range(90)] + [math.nan]))
    frame = pd.DataFrame({"u": np.ones(50), "v": np.zeros(50), "r": np.zeros(50)})
    runs = [SimpleNamespace(log=frame, diverged=False)] * 90 + [
        SimpleNamespace(log=frame.iloc[:20], diverged=True)] * 10
    bands, diverged = free_run_bands(runs, 50)
    lo, hi = bands["u"]
    assert diverged == 10
    np.testing.assert_array_equal(lo[:20], 1.0)
    assert np.all(np.isneginf(lo[20:])) and np.all(np.isposinf(hi[20:]))


def test_cli_manoeuvre_says_not_bounded_when_replicates_diverge(tmp_path, capsys, noisy_zigzag):
    log = write_log(noisy_zigzag, tmp_path / "zz.csv")
    model = tmp_path / "m.json"
    code, _, err = run(["identify", log, "--bootstrap", "20", "-o", model], capsys)
    assert code == 0, err
    doc = json.loads(model.read_text())
    thetas = np.array(doc["uncertainty"]["thetas"])
    # Four of twenty replicates with an explosive yaw equation (every coefficient ×1e4).
    thetas[:4, 2, :] *= 1e4
    doc["uncertainty"]["thetas"] = thetas.tolist()
    model.write_text(json.dumps(doc))
    code, out, err = run(["manoeuvre", model, "turning", "--rudder", "20", "--duration", "40"],
                         capsys)  # fmt: skip
    assert code == 0, err
    assert "(4 diverged" in out
    line = next(ln for ln in out.splitlines() if ln.startswith("tactical_diameter:"))
    assert line.endswith("[not bounded: 4 of 20 bootstrap replicates have none: 4 diverged]")


@pytest.mark.parametrize("kw", [
    {},
    {"form": "paper", "drop": {"u": ["r^2"]}},
    {"model": "blanke-race+race-damping", "gamma": 1e2},
    {"estimator": "ols", "fixed": {"u": {"delta^2": 0.0}}},
    {"physics": "signs"},
])  # fmt: skip
def test_weighted_refit_is_identify_with_sample_weight_to_the_bit(noisy_zigzag, kw):
    """The bootstrap's refits build the regression problems once (rebuilding them was most of
    a refit's time); each must still be identify's model for its weights, exactly."""
    from shipid.identification.identify import weighted_refit
    from shipid.identification.physics import PhysicsOptions

    kw = dict(kw)
    if kw.get("physics") == "signs":
        kw["physics"] = PhysicsOptions(signs=True)
    refit = weighted_refit(noisy_zigzag, **kw)
    rng = np.random.default_rng(3)
    for weights in (None, block_weights([len(noisy_zigzag) - 1], 25, rng),
                    rng.uniform(0, 2, len(noisy_zigzag) - 1)):  # fmt: skip
        ours = refit(weights)
        theirs = identify(noisy_zigzag, force=True, sample_weight=weights, **kw).model
        assert ours.term_texts == theirs.term_texts and ours.name == theirs.name
        np.testing.assert_array_equal(ours.theta, theirs.theta)
    with pytest.raises(ShipidError, match="sample_weight must be"):
        refit(np.ones(3))


def test_a_log_drawn_twice_weighs_as_the_log_given_twice(noisy_zigzag):
    """A whole-log replicate is identify on the drawn logs, each as often as drawn: the refit
    with the log bootstrap's weights equals identify of the logs repeated, to rounding."""
    from shipid.identification.identify import weighted_refit

    logs = [noisy_zigzag.iloc[k * 40:(k + 1) * 40 + 1].reset_index(drop=True) for k in range(5)]
    weights = log_weights([len(lg) - 1 for lg in logs], np.random.default_rng(2))
    counts = [int(w[0]) for w in np.split(weights, np.cumsum([40] * 4))]
    assert sorted(counts) != [1] * 5  # a resample, not the data
    ours = weighted_refit(logs, gamma=1e4)(weights)
    repeated = [lg for lg, c in zip(logs, counts, strict=True) for _ in range(c)]
    theirs = identify(repeated, gamma=1e4, force=True).model
    np.testing.assert_allclose(ours.theta, theirs.theta, rtol=1e-8, atol=1e-9)


def test_where_an_index_was_measured_gets_no_interval():
    """``manoeuvre`` printed intervals on the span of the steady turn ('steady_to: 480
    [480, 1920]' once runs last until the turn settles): bookkeeping, not a ship's index."""
    from shipid.identification.uncertainty import index_intervals

    samples = [{"tactical_diameter": 20.0 + 0.01 * k, "steady_from": 100.0 + k,
                "steady_to": 240.0 * (1 + k % 3), "first_execute_time": 0.0,
                "switch_heading_deg": 20.0} for k in range(100)]  # fmt: skip
    assert set(index_intervals(samples)) == {"tactical_diameter"}

"""How firm select's choice is, and an ensemble over the choice of terms (issue #10): the shares
against an exhaustive count of the resamples, the one-candidate case against the plain
bootstrap, the varied structure in model files and through rescaling."""

import itertools
import json
import math

import numpy as np
import pytest
from cli_helpers import run
from generated_logs import noisy_zigzags

from shipid.data.io import write_log
from shipid.dynamics.prime import froude_ratios
from shipid.errors import ShipidError
from shipid.identification.identify import weighted_refit
from shipid.identification.select import Candidate, select, selection_shares
from shipid.identification.selection_ensemble import selection_ensemble
from shipid.identification.uncertainty import SELECTION_LOG_METHOD, Ensemble, bootstrap
from shipid.reporting.modelfile import ensemble_from_document, model_from_document


def _cand(n_terms: int, folds) -> Candidate:
    c = Candidate({"r": tuple(f"v^{k + 1}" for k in range(n_terms))}, 1e4)
    c.fold_scores = list(folds)
    c.score = float(np.mean(folds))
    return c


def _exhaustive(cands, plausible, one_se) -> dict:
    """The choice rule over every one of the K^K equally likely resamples of K folds."""
    K = len(cands[0].fold_scores)
    counts: dict = {}
    for idx in itertools.product(range(K), repeat=K):
        f = {c.key: np.array(c.fold_scores)[list(idx)] for c in cands}
        ok = [c for c in cands if plausible(c)]
        best = min(ok, key=lambda c: f[c.key].mean())
        if one_se:
            limit = f[best.key].mean() + f[best.key].std(ddof=1) / math.sqrt(K)
            within = [c for c in ok if f[c.key].mean() <= limit]
            best = min(within, key=lambda c: (c.n_terms(), f[c.key].mean()))
        counts[best.key] = counts.get(best.key, 0) + 1
    return {k: v / K**K for k, v in counts.items()}


@pytest.mark.parametrize("one_se", [False, True])
def test_shares_match_an_exhaustive_count_of_the_resamples(one_se):
    cands = [_cand(3, [0.30, 0.50, 0.20]), _cand(2, [0.35, 0.40, 0.28]),
             _cand(1, [0.60, 0.30, 0.25]), _cand(4, [0.10, 0.20, 0.10])]  # fmt: skip
    plausible = lambda c: c.n_terms() != 4  # noqa: E731 (the best-scoring one is implausible)
    shares = selection_shares(cands, plausible, one_se, resamples=20000, seed=3)
    exact = _exhaustive(cands, plausible, one_se)
    assert cands[3].key not in shares
    assert sum(shares.values()) == pytest.approx(1.0)
    assert set(shares) == set(exact)
    for key, p in exact.items():
        assert shares[key] == pytest.approx(p, abs=0.01)


def test_a_candidate_best_on_every_log_is_always_chosen():
    cands = [_cand(2, [0.2, 0.3, 0.1, 0.2]), _cand(3, [0.4, 0.5, 0.3, 0.6])]
    assert selection_shares(cands, lambda c: True, True) == {cands[0].key: 1.0}


@pytest.fixture(scope="module")
def zigzags():
    return noisy_zigzags(20)


def test_one_candidate_gives_the_bootstrap_of_it_to_the_bit(zigzags):
    sel = select(zigzags, library="blanke", search="none", gammas=(1e4,))
    assert len(sel.shares) == 1 and sel.chosen_share == 1.0
    ens = selection_ensemble(zigzags, sel, replicates=12, seed=5)
    plain = bootstrap(zigzags, weighted_refit(zigzags, model=sel.model.structure,
                                              gamma=sel.gamma), replicates=12, seed=5)  # fmt: skip
    assert not ens.varies_structure and ens.term_texts == plain.model.term_texts
    np.testing.assert_array_equal(ens.thetas, plain.thetas)


def test_whole_logs_one_candidate_is_the_log_bootstrap_of_it_and_is_filed(zigzags, tmp_path,
                                                                          capsys):  # fmt: skip
    logs = zigzags + noisy_zigzags(23)
    sel = select(logs, library="blanke", search="none", gammas=(1e4,))
    ens = selection_ensemble(logs, sel, replicates=12, seed=5, block_s="log")
    plain = bootstrap(logs, weighted_refit(logs, model=sel.model.structure, gamma=sel.gamma),
                      replicates=12, seed=5, block_s="log")  # fmt: skip
    np.testing.assert_array_equal(ens.thetas, plain.thetas)
    assert ens.method == SELECTION_LOG_METHOD and "resamples of whole logs" in ens.members_label
    paths = [write_log(log, tmp_path / f"zz{i}.csv") for i, log in enumerate(logs)]
    code, out, err = run(["identify", *paths, "--model", "blanke", "--no-output-error",
                          "--bootstrap", "12", "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "(12 replicates: bootstrap of whole logs)" in out
    doc = json.loads((tmp_path / "m.json").read_text(encoding="utf-8"))
    assert doc["uncertainty"]["block_s"] == "log"
    again = ensemble_from_document(doc, "m.json", model_from_document(doc, "m.json"))
    assert again.block_s == "log" and again.replicates == 12
    code, _, err = run(["select", *paths[:3], "--library", "blanke", "--quiet", "--bootstrap",
                        "12", "--block", "log", "-o", tmp_path / "s.json"], capsys)  # fmt: skip
    assert code == 1 and "needs at least 5 of them, got 3" in err
    assert not (tmp_path / "s.json").exists()
    with pytest.raises(SystemExit) as exc:  # a usage error: argparse's exit code
        run(["select", *paths[:3], "--bootstrap", "12", "--block", "0", "-o",
             tmp_path / "s.json"], capsys)  # fmt: skip
    assert exc.value.code == 2
    assert "expected seconds > 0, 'log' or 'auto', got '0'" in capsys.readouterr().err
    # By default: whole logs from five logs on, 10 s blocks below.
    code, out, err = run(["identify", *paths[:3], "--model", "blanke", "--no-output-error",
                          "--bootstrap", "12", "-o", tmp_path / "b.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "(12 replicates: moving-block bootstrap of the regression equations, 10 s blocks)" in out


def test_varied_structure_members_file_and_rescale(zigzags, tmp_path, capsys):
    paths = [write_log(log, tmp_path / f"zz{i}.csv") for i, log in enumerate(zigzags)]
    code, out, err = run(["select", *paths, "--library", "blanke+abkowitz3", "--quiet",
                          "--bootstrap", "40", "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "resamples of the held-out logs: this candidate" in out and "inclusion" in out
    doc = json.loads((tmp_path / "m.json").read_text(encoding="utf-8"))
    model = model_from_document(doc, "m.json")
    ens = ensemble_from_document(doc, "m.json", model)
    # Its replicates through the checks, as identify's: counted, kept, printed.
    record = doc["uncertainty"]["plausibility"]
    assert record["checked"] == 40 and ens.plausibility == record
    assert f"plausibility of 40 of the 40 replicates: {record['implausible']} fail" in out
    shares = [c for c in doc["identification"]["selection"]["candidates"] if c["share"] > 0]
    assert sum(c["share"] for c in shares) == pytest.approx(1.0)
    assert len(shares) > 1 and ens.varies_structure  # these logs leave the choice open
    # Every member holds the terms of one shared candidate and nothing else (0 elsewhere).
    from shipid.dynamics.astern import astern_form

    # (the members as the file writes them: in their ahead forms, |u|·v for u·v, ...)
    allowed = [{(d, astern_form(d, t)) for d in "uvr" for t in c[f"terms_{d}"].split(", ")}
               for c in shares]  # fmt: skip
    for member in ens.members():
        held = {(d, t) for d, cs in member.coefficients.items() for t, x in cs.items() if x != 0}
        assert any(held <= a and len(a - held) == 0 for a in allowed)
    # The file's ensemble: the same members after a round trip.
    again = Ensemble.from_dict(json.loads(json.dumps(ens.to_dict())), model)
    np.testing.assert_array_equal(again.thetas, ens.thetas)
    assert again.structure == ens.structure
    broken = dict(ens.to_dict(), structure={"u": ["1"], "v": ["1"], "r": ["1"]}, terms=["1"],
                  thetas=ens.thetas[:, :, :1].tolist())  # fmt: skip
    with pytest.raises(ShipidError, match="lacks the model's term"):
        Ensemble.from_dict(broken, model)
    # Rescaled: every member term, in the model or not, by its own Froude ratio.
    code, out, err = run(["rescale", tmp_path / "m.json", "--factor", "10", "-o",
                          tmp_path / "big.json"], capsys)  # fmt: skip
    assert code == 0, err
    big = json.loads((tmp_path / "big.json").read_text(encoding="utf-8"))["uncertainty"]
    ratios = froude_ratios(ens.structure, 10.0)
    t0, t1 = np.asarray(doc["uncertainty"]["thetas"]), np.asarray(big["thetas"])
    outside = [(d, t) for d, ts in ens.structure.terms.items() for t in ts
               if t not in model.structure.terms[d]]  # fmt: skip
    assert outside
    for d, t in outside + [("r", model.structure.terms["r"][0])]:
        i, j = "uvr".index(d), ens.term_texts.index(t)
        np.testing.assert_allclose(t1[:, i, j], t0[:, i, j] * ratios[d][t], rtol=1e-12)


def _share_average(logs, shares):
    """Σ share · coefficient over the candidates, each identified on ``logs``, by hand."""
    from shipid.dynamics.model import ModelStructure
    from shipid.identification.identify import identify

    total: dict = {}
    for c in shares:
        fit = identify(logs, model=ModelStructure("c", c.terms), gamma=c.gamma, force=True).model
        for d, cs in fit.coefficients.items():
            for t, x in cs.items():
                total[(d, t)] = total.get((d, t), 0.0) + c.share * x
    return total


def test_average_is_the_share_weighted_mean_and_so_is_its_band(zigzags):
    from shipid.dynamics.model import ManoeuvringModel, ModelStructure
    from shipid.dynamics.simulate import simulate_log

    plain = select(zigzags, library="blanke+abkowitz3")
    sel = select(zigzags, library="blanke+abkowitz3", average=True)
    assert len(sel.shares) > 1
    np.testing.assert_array_equal(sel.chosen_model.theta, plain.model.theta)
    expected = _share_average(zigzags, sel.shares)
    got = {(d, t): x for d, cs in sel.model.coefficients.items() for t, x in cs.items()}
    assert set(got) == set(expected)
    for key, x in expected.items():
        assert got[key] == pytest.approx(x, rel=1e-7, abs=1e-12), key
    # The error band describes the averaged model: its folds averaged the same way.
    errors = []
    for i, log in enumerate(zigzags):
        mean = _share_average([x for j, x in enumerate(zigzags) if j != i], sel.shares)
        terms = {d: tuple(t for dd, t in mean if dd == d) for d in "uvr"}
        fold = ManoeuvringModel(ModelStructure("fold", terms),
                                {d: {t: x for (dd, t), x in mean.items() if dd == d}
                                 for d in "uvr"})  # fmt: skip
        errors.append(np.abs(simulate_log(fold, log).log[["u", "v", "r"]].to_numpy()
                             - log[["u", "v", "r"]].to_numpy()))  # fmt: skip
    errors = np.vstack(errors)
    k = math.ceil((len(errors) + 1) * 0.95)
    assert sel.error_band.half_width["r"] == pytest.approx(np.sort(errors[:, 2])[k - 1], rel=1e-6)
    assert sel.to_dict()["chosen_model"] is not None and plain.to_dict()["chosen_model"] is None
    # Its plausibility record is the averaged model's, as the checks give it afresh.
    from shipid.data.log import approach
    from shipid.identification.plausibility import plausibility_at_approach

    again, notes = plausibility_at_approach(sel.model, approach(zigzags[0], "u"), None)
    assert sel.plausibility["straight_line"] == again["straight_line"]
    assert sel.plausibility["held_rudder"] == again["held_rudder"]
    assert sel.plausibility_notes == notes


def test_cli_average_writes_the_average_and_keeps_the_chosen(zigzags, tmp_path, capsys):
    paths = [write_log(log, tmp_path / f"zz{i}.csv") for i, log in enumerate(zigzags)]
    code, out, err = run(["select", *paths, "--library", "blanke+abkowitz3", "--quiet",
                          "--average", "--bootstrap", "20", "-o", tmp_path / "m.json"], capsys)
    assert code == 0, err
    assert "The chosen candidate:" in out and "(--average)" in out
    doc = json.loads((tmp_path / "m.json").read_text(encoding="utf-8"))
    model = model_from_document(doc, "m.json")
    chosen = model_from_document({"model": doc["identification"]["selection"]["chosen_model"]},
                                 "m.json")  # fmt: skip
    assert doc["identification"]["selection"]["options"]["average"] is True
    assert sum(len(t) for t in model.structure.terms.values()) > \
        sum(len(t) for t in chosen.structure.terms.values())
    assert ensemble_from_document(doc, "m.json", model).replicates == 20
    code, out, err = run(["rescale", tmp_path / "m.json", "--factor", "4", "-o",
                          tmp_path / "big.json"], capsys)  # fmt: skip
    assert code == 0, err
    big = json.loads((tmp_path / "big.json").read_text(encoding="utf-8"))
    big_chosen = big["identification"]["selection"]["chosen_model"]["coefficients"]
    ratios = froude_ratios(chosen.structure, 4.0)
    for d, cs in chosen.coefficients.items():
        for t, x in cs.items():
            assert big_chosen[d][t] == pytest.approx(x * ratios[d][t], rel=1e-12)

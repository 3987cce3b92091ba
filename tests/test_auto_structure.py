"""`identify` without --model (`auto`): the paper's blanke where it can hold the logs, else a
structure chosen for them. Before, plain `shipid identify` fitted blanke to whatever it was given:
trained on the Esso Osaka's nine zig-zags and three random runs (10 to 16.7 rps, astern, an
outdoor pond) it put the held-out 35° turns' tactical diameters 236 % and 154 % long, on the
three random runs alone 635 % and 788 %, turning the −35° one the wrong way. The
truths here: a simulated ship whose thrust is |n|n (a known structure), and the real turns."""

import json
import re
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from shipid.data.io import read_log, write_log
from shipid.dynamics.model import ManoeuvringModel, ModelStructure
from shipid.evaluation.validate import validate
from shipid.identification.auto_structure import auto_structure
from shipid.identification.identify import identify
from shipid.reporting.modelfile import load_model
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import PAPER_IMU, scale_ship

DATA = Path(__file__).resolve().parents[2] / "shared" / "data" / "esso-osaka"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="../shared/data is not present")
STEADY = (0.0012 / 0.0321) ** 0.5  # u/n where |n|n balances |u|u (no surge constant)


def _rps_ship() -> ManoeuvringModel:
    """The paper's scale ship with its thrust as |n|n (10 rps gives the paper's constant) and
    its rudder force as u²δ (the paper's at its 1.93 m/s)."""
    c = scale_ship().dynamics.coefficients
    surge = {k: x for k, x in c["u"].items() if k != "1"} | {"|n|*n": c["u"]["1"] / 100.0}
    lateral = {d: {("u^2*delta" if k == "delta" else k): (x / 1.93**2 if k == "delta" else x)
                   for k, x in c[d].items()} for d in ("v", "r")}  # fmt: skip
    return ManoeuvringModel("blanke-rps", {"u": surge, **lateral})


def _run(n: float, rudder: float = 20.0, seed: int = 0):
    log = zigzag(_rps_ship(), rudder, rudder, duration=90, dt=0.2, method="euler", rps=n,
                 approach=2.0, speed=STEADY * n).log.assign(n=n)  # fmt: skip
    return PAPER_IMU.apply(log, seed=seed).assign(n=n)


@pytest.fixture(scope="module")
def paper_log():
    ship = scale_ship(rudder_rate_deg=9.6)
    return PAPER_IMU.apply(zigzag(ship, 20, 20, duration=90, dt=0.2, method="euler",
                                  approach=2.0).log, seed=0)  # fmt: skip


def _with_wind(log, true_wind: float):
    u, v = log["u"].to_numpy(), log["v"].to_numpy()
    ax, ay = u + true_wind, v  # a true wind from ahead, in the body frame
    return log.assign(wind_speed=np.hypot(ax, ay), wind_angle=np.arctan2(ay, ax))


def test_the_paper_structure_where_the_logs_hold_nothing_more(paper_log, tmp_path, capsys):
    assert auto_structure([paper_log]).how == "paper"
    path = write_log(paper_log, tmp_path / "zz.csv")
    # The paper drops r² from the surge: a --drop applies to whatever structure is chosen.
    common = ["--gamma", "500", "--drop", "u:r^2"]
    code, out, err = run(["identify", path, *common, "-o", tmp_path / "auto.json"], capsys)
    assert code == 0 and out.startswith("structure: blanke, the paper's (16 terms"), err
    code, _, _ = run(["identify", path, "--model", "blanke", *common, "-o", tmp_path / "b.json"],
                     capsys)  # fmt: skip
    auto, given = (json.loads((tmp_path / f).read_text()) for f in ("auto.json", "b.json"))
    assert auto["model"] == given["model"]  # to the bit: the default is the paper's fit
    assert auto["identification"]["gamma"] == 500  # a given γ is kept
    assert auto["identification"]["structure_choice"]["how"] == "paper"


@pytest.mark.parametrize(("columns", "name"), [
    ({"thrust"}, "blanke-thrust"),
    ({"wind"}, "blanke+wind"),
    ({"thrust", "wind"}, "blanke-thrust+wind"),
])  # fmt: skip
def test_a_varying_thrust_or_a_wind_takes_the_named_structure_that_holds_it(paper_log, columns,
                                                                           name):  # fmt: skip
    log = paper_log
    if "thrust" in columns:  # no rps logged: the thrust is the input
        log = log.assign(thrust=np.linspace(30.0, 50.0, len(log)))
    if "wind" in columns:
        log = _with_wind(log, 2.0)
    choice = auto_structure([log])
    assert choice.how == "named" and choice.structure.name == name
    assert len(choice.reasons) == len(columns)
    still = auto_structure([_with_wind(paper_log, 0.0)])  # the ship's own motion: no wind
    assert still.how == "paper"


def test_a_varying_propeller_speed_is_chosen_for_and_predicts_an_unseen_speed(tmp_path, capsys):
    train = [_run(n, seed=i) for i, n in enumerate((8.0, 10.0, 12.0))]
    held = _run(14.0, rudder=15.0, seed=7)  # another speed and rudder angle
    paths = [write_log(log, tmp_path / f"zz{i}.csv") for i, log in enumerate(train)]
    code, out, err = run(["identify", *paths, "-o", tmp_path / "auto.json"], capsys)
    assert code == 0, err
    # This truth itself diverges under a held 35° rudder (the paper's ship far outside its
    # trials), so none of select's candidates passes the plausibility checks either: the
    # simplest structure with n (the truth's) is fitted, and that is said.
    assert "structure: blanke-rps" in out and "the propeller speed n varies (8 to 12 rps)" in out
    assert "none of select's" in out and "plausible; blanke-rps instead" in out
    doc = json.loads((tmp_path / "auto.json").read_text())
    assert doc["identification"]["structure_choice"]["how"] == "named"
    model = load_model(tmp_path / "auto.json")
    assert "n" in model.structure.inputs
    assert "varies in the training logs" not in err  # the note of a structure that lacks it
    assert doc["identification"]["gamma"] == 1e4  # no γ from a search
    paper = identify(train, model="blanke", force=True)
    assert any("the propeller speed n varies" in w for w in paper.warnings)
    paper = paper.model
    chosen, lumped = (validate(m, [held])[0] for m in (model, paper))
    assert not chosen.simulation.diverged
    # The |n|n the logs show carries the model to 14 rps; blanke's constant thrust does not.
    assert chosen.metrics["u"]["std"] < 0.5 * lumped.metrics["u"]["std"]
    assert chosen.metrics["r"]["std"] < lumped.metrics["r"]["std"]


@needs_data
def test_plain_identify_predicts_the_esso_turns_it_never_saw(tmp_path, capsys):
    """Trained on the three random runs, judged on the two 35° turns (10 rps, six weeks later)."""
    runs = sorted((DATA / "random").glob("*.csv"))
    train = [p for p in runs if "12_29_58" not in p.name]
    args = ["--format", "osaka-frt", "--end", "dropout", "--dt", "0.5"]
    code, out, err = run(["identify", *train, *args, "-o", tmp_path / "esso.json"], capsys)
    assert code == 0, err
    assert "chosen by shipid select" in out
    assert "choosing the terms from" in err  # the search is announced: it takes seconds
    assert "warning: structure: only 3 folds" in err  # and its weakness said
    doc = json.loads((tmp_path / "esso.json").read_text())
    ident = doc["identification"]
    assert ident["structure_choice"]["how"] == "select"
    assert ident["gamma"] == ident["structure_choice"]["gamma"]  # select's γ
    model = load_model(tmp_path / "esso.json")
    # The model is the average of the candidates select's choice picks on resampled held-out
    # logs, each identified on the logs as read (and prefiltered) at its own γ, weighted by its
    # share: re-solved here one candidate at a time.
    members = ident["structure_choice"]["members"]
    assert len(members) >= 2 and "average" in model.name and "the average of" in out
    assert sum(m["weight"] for m in members) == pytest.approx(1.0)
    read = [read_log(p, fmt="osaka-frt", end="dropout", dt=0.5) for p in train]
    cutoff = ident["preprocessing"].get("filter_hz")
    if cutoff:
        from shipid.data.preprocess import lowpass

        read = [lowpass(x, cutoff) for x in read]
    fits = [(identify(read, model=ModelStructure("m", {d: tuple(t) for d, t in m["terms"].items()}),
                      gamma=m["gamma"], force=True).model, m["weight"]) for m in members]
    for dof, terms in model.coefficients.items():
        for term, value in terms.items():
            expected = sum(w * f.coefficients.get(dof, {}).get(term, 0.0) for f, w in fits)
            assert value == pytest.approx(expected, rel=1e-9, abs=1e-15), (dof, term)
    assert all(t in model.structure.terms[d] for m in members for d, ts in m["terms"].items()
               for t in ts)  # fmt: skip
    turns = [read_log(p, fmt="osaka-frt", start="auto", end="auto", dt=0.5)
             for p in sorted((DATA / "turning").glob("*.csv"))]  # fmt: skip
    for v in validate(model, turns):
        measured, simulated = v.indices["measured"], v.indices["simulated"]
        td = simulated["tactical_diameter"] / measured["tactical_diameter"] - 1
        r = simulated["steady_yaw_rate"] / measured["steady_yaw_rate"] - 1
        # Measured 2026-11-24: tactical diameters +12 % and +6 %, steady yaw rates −3 % and +2 %
        # (without the library's astern terms: −1 %, +4 %; +7 %, +1 %).
        assert abs(td) < 0.15 and abs(r) < 0.15, (td, r)
    # The random run left out, a third of it astern: r error 0.33 of its spread (0.39 without
    # the astern terms).
    held = read_log(DATA / "random" / "random_31-Jul-2020_12_29_58.csv", fmt="osaka-frt",
                    end="dropout", dt=0.5)  # fmt: skip
    (v,) = validate(model, [held])
    assert v.metrics["r"]["std"] / held["r"].std(ddof=0) < 0.36


KVLCC2 = DATA.parent / "kvlcc2-marin" / "MARIN_FREE_KVLCC2_zz_20_m.dat"


@needs_data
def test_a_speed_that_varies_at_constant_rps_compares_the_rudders_inflow(paper_log):
    """The KVLCC2's MARIN zig-zag loses 30 % of its speed at a constant 10.3 rps: the paper's
    rudder force in δ assumes one speed. Plain `identify` fitted blanke to it; blanke-speed
    predicts the unseen −20° run with 37 % and 35 % lower sway and yaw errors (README). Four
    blocks of the one log then chose blanke-speed, as the first block, the approach, held speeds
    no other block reached; scored on the other three, the race structure ties, and fitted on
    the whole log it predicts the unseen run better still."""
    log = read_log(KVLCC2, fmt="simman-marin", scale=45.7, dt=0.2)
    choice = auto_structure([log])
    assert choice.how == "compared" and choice.structure.name == "blanke-race+race-damping"
    assert "on blocks 2, 3, 4: block 1 reached speeds beyond the others'" in choice.describe()
    assert "the speed varies by 30 % at a constant 10.33 rps" in choice.describe()
    assert not [w for w in choice.warnings if "compared on blocks of one log" in w]
    # The other MARIN run, never seen: the chosen structure's free run against blanke-speed's.
    held = read_log(KVLCC2.parent / "MARIN_FREE_KVLCC2_zz_-20_m.dat", fmt="simman-marin",
                    scale=45.7, dt=0.2)  # fmt: skip
    errors = {name: validate(identify([log], model=name).model, held, start_draws=False)[0]
              .metrics for name in ("blanke-speed", choice.structure.name)}  # fmt: skip
    for state in ("v", "r"):
        assert errors[choice.structure.name][state]["std"] < 0.7 * errors["blanke-speed"][state]["std"]
    # The paper's ship with a logged rps: the race structure is fitted (the rudder in the race a
    # constant rps implies), on the blocks inside the approach's speed as well. blanke-speed
    # scores best on them but is ruled out by its 35° rudder held (this ship, whose own 35° turn
    # diverges, far beyond its trials), so the race with the drift terms is compared too, and
    # fitted (held-out 20° turns' yaw rate
    # 1.17–1.42 times the noise floor over three such seeds, where the race structure alone had
    # 1.60–1.93; benchmarks/study_auto_inflow.py).
    raced = auto_structure([paper_log.assign(n=10.0)])
    assert raced.structure.name == "blanke-race+race-damping+rudder-drift"
    assert "compared because blanke-speed, the best on the logs, is ruled out" in raced.describe()


def test_a_wind_at_constant_rps_compares_the_rudders_inflow_with_the_winds_terms(paper_log):
    """A wind beyond the paper took blanke+wind without a comparison, however the speed varied
    at a constant rps: the paper's ship with an rps and a wind logged is compared as in still
    air (the race structure fitted where it ties), every candidate with the wind's terms."""
    choice = auto_structure([_with_wind(paper_log, 2.0).assign(n=10.0)])
    assert choice.structure.name.endswith("+wind") and choice.how in ("compared", "named")
    assert "the logs carry a wind" in choice.describe()
    assert "blanke-speed+wind" in choice.describe() + " ".join(choice.warnings)


@needs_data
def test_one_esso_zig_zag_takes_the_structure_with_the_fewest_faults():
    """The Esso Osaka's 20/20 zig-zag at a constant 16.7 rps accelerates throughout: no
    structure compared has a steady straight speed. blanke+wind, fitted where none was plausible
    (and, before, named without a comparison), also diverges with 35° rudder held; it missed the
    30/30 zig-zag at the same rps by 3.9 times its yaw rate's spread."""
    from shipid.trials.reading import read_trial_log

    train, held = (read_trial_log(DATA / "zigzag" / f"zigzag_31-Jul-2020_{t}.csv",
                                  fmt="osaka-frt") for t in ("13_04_24", "13_14_21"))  # fmt: skip
    choice = auto_structure([train])
    # The file carries the 3 m model's length: the race structure with the hull's cross-flow
    # drag has the fewest faults now, as the race structure alone had before.
    assert choice.structure.name == "blanke-race+race-damping+wind+crossflow(3 m)"
    (warning,) = [w for w in choice.warnings if w.startswith("none of the structures")]
    assert "blanke+wind 0.500 (no steady straight speed; diverges" in warning
    spread = float(np.std(held["r"]))
    errors = {name: validate(identify([train], model=structure, force=True).model, held,
                             start_draws=False)[0].metrics["r"]["std"] / spread
              for name, structure in (("blanke+wind", "blanke+wind"),
                                      ("chosen", choice.structure))}  # fmt: skip
    assert errors["blanke+wind"] > 3.0 and errors["chosen"] < 0.4, errors


@needs_data
def test_the_comparison_offers_the_hulls_cross_flow_where_the_logs_give_its_length():
    """The Esso files carry the 3 m model's particulars: each structure of the inflow comparison
    is also compared with the hull's cross-flow drag, and one with it taken where it ties with
    the best (13_22_52's blanke-speed+wind; the nine files' 35° turns came 35 % wide in the
    median, now 23 %: benchmarks/study_crossflow.py). With --no-crossflow (or without the
    length, as every log of the other tests) the comparison is as before. 13_14_21 is widened
    by rudder-drift, whose structure the cross-flow candidates once left unknown (an internal
    error)."""
    from shipid.dynamics.model import StructureEdit
    from shipid.trials.reading import read_trial_log

    def log(t):
        return read_trial_log(DATA / "zigzag" / f"zigzag_31-Jul-2020_{t}.csv", fmt="osaka-frt")

    choice = auto_structure([log("13_22_52")])
    assert choice.structure.name == "blanke-speed+wind+crossflow(3 m)"
    assert "crossflow_sway(3)" in choice.structure.terms["v"]
    assert "blanke-race+race-damping+wind+crossflow(3 m) " in choice.notes[0]
    assert "the hull's cross-flow drag (its length from the particulars) where" in choice.notes[0]
    plain = auto_structure([log("13_22_52")], drop=StructureEdit(compare_crossflow=False))
    assert plain.structure.name == "blanke-speed+wind" and "crossflow" not in plain.notes[0]
    widened = auto_structure([log("13_14_21")])
    assert "rudder-drift" in widened.structure.name
    # The rudder in the race comes first: from the KVLCC2's MARIN 20/20 zig-zag with its
    # particulars, blanke-speed with the drag ties with the race structure (its −20° run's yaw
    # rate error 4.6 times the race structure's) and was taken; the race structure is.
    from shipid.data.particulars import read_particulars

    marin = DATA.parent / "kvlcc2-marin"
    kvlcc2 = read_log(marin / "MARIN_FREE_KVLCC2_zz_20_m.dat", fmt="simman-marin", scale=45.7,
                      dt=0.2)  # fmt: skip
    kvlcc2.attrs["particulars"] = read_particulars(marin / "ship_data.yml").to_dict()
    choice = auto_structure([kvlcc2])
    assert choice.structure.name == "blanke-race+race-damping"
    assert "blanke-speed+crossflow(7 m) " in choice.notes[0]


def test_logs_that_cannot_be_fitted_together_are_named_not_called_implausible(paper_log):
    """Bug: two logs at different sampling times (MARIN's 0.02 s and HSVA's 0.05 s at model
    scale) made every structure of the comparison fail, and the choice said "none of blanke,
    blanke-speed, blanke-race+race-damping is plausible" before the fit named the real reason."""
    from shipid.data.preprocess import resample
    from shipid.errors import ShipidError

    fine = paper_log.assign(n=10.0)
    coarse = resample(fine, 0.4, "coarse")
    with pytest.raises(ShipidError, match="sampling time 0.4 s differs from 0.2 s"):
        auto_structure([fine, coarse], ["fine.csv", "coarse.csv"])


def test_structures_the_logs_cannot_tell_apart_but_that_turn_apart_are_named():
    """The KVLCC2's MMG model through a noisy 20/20 zig-zag with its rps logged: blanke and
    blanke-race+race-damping score alike (blanke-speed too, before the blocks beyond the
    approach's speed were left out of the score). The simplest, blanke, was fitted, whose 35°
    turns' steady yaw rates are 2.7–3.9 times the truth's; now the race structure is (within
    14 %; benchmarks/study_auto_inflow.py). Fitted as identify fits them their turns differ by
    a factor of two, and the choice says so."""
    from shipid.vessels import kvlcc2
    from shipid.vessels.kvlcc2 import trimmed_revolutions

    ship = kvlcc2()
    log = zigzag(ship, 20, 20, duration=300, dt=0.2, approach=5).log
    log = PAPER_IMU.scaled(0.25).apply(log, seed=0).assign(n=trimmed_revolutions(1.179))
    choice = auto_structure([log])
    assert choice.structure.name == "blanke-race+race-damping"
    (warning,) = [w for w in choice.warnings if "turning circle apart" in w]
    rates = [float(x.split(" rad/s")[0].split()[-1]) for x in warning.split(", ")
             if "rad/s" in x]  # fmt: skip
    assert len(rates) >= 2 and max(rates) > 1.25 * min(rates)
    assert warning.startswith("blanke, ") and "blanke-race+race-damping" in warning
    # Their 10°/10° zig-zags too (blanke's second overshoot 16.1°, the race structure's 12.8°),
    # and the truth's own second overshoot (13.6°) lies between the tied fits': the spread is
    # the uncertainty; its first (4.9°) within 0.2° of the race structure's.
    (warning,) = [w for w in choice.warnings if "10°/10° zig-zag apart" in w]
    named = [[float(x) for x in re.findall(r"(-?\d+\.\d)°", part)]
             for part in warning.split("fits: ")[1].split(";")[:2]]  # fmt: skip
    first, second = zip(*named, strict=True)
    truth = zigzag(ship, 10, 10, dt=0.2, method="euler").indices
    assert min(first) - 0.2 <= truth["first_overshoot_deg"] <= max(first)
    assert min(second) <= truth["second_overshoot_deg"] <= max(second)
    assert max(second) - min(second) > 1.5


HSVA = DATA.parent / "kvlcc2-hsva" / "HSVA_CPMC_KVLCC2_Z_20_10_P.dat"


@needs_data
def test_the_real_kvlccs_zig_zags_tie_on_structures_whose_10_10_zig_zags_differ():
    """The KVLCC2's three real zig-zags (MARIN ±20°, HSVA 20/10): blanke-speed and
    blanke-race+race-damping tie, and the race structure is fitted (blanke-speed was, the
    simplest); their 35° turns agree, but their 10°/10° second overshoots lie 3° apart (11.5°
    and 14.5°). The choice said nothing of it."""
    logs = [read_log(KVLCC2.parent / f"MARIN_FREE_KVLCC2_zz_{a}_m.dat", fmt="simman-marin",
                     scale=45.7, dt=0.2) for a in ("20", "-20")]  # fmt: skip
    logs.append(read_log(HSVA, fmt="simman-hsva", dt=0.2))
    choice = auto_structure(logs)
    assert choice.structure.name == "blanke-race+race-damping"
    assert not [w for w in choice.warnings if "turning circle apart" in w]
    (warning,) = [w for w in choice.warnings if "10°/10° zig-zag apart" in w]
    assert "blanke-speed 7.9°, 11.5°; blanke-race+race-damping 9.5°, 14.5°" in warning


@pytest.fixture(scope="module")
def mmg_tied(tmp_path_factory):
    """The KVLCC2's MMG model through a noisy 20/20 zig-zag with its rps logged (blanke and
    blanke-race+race-damping tie), identified by the plain command."""
    from shipid.vessels import kvlcc2
    from shipid.vessels.kvlcc2 import trimmed_revolutions

    log = zigzag(kvlcc2(), 20, 20, duration=300, dt=0.2, approach=5).log
    log = PAPER_IMU.scaled(0.25).apply(log, seed=0).assign(n=trimmed_revolutions(1.179))
    folder = tmp_path_factory.mktemp("tied")
    model = folder / "m.json"
    import contextlib
    import io

    from shipid.cli import main

    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        assert main(["identify", str(write_log(log, folder / "zz.csv")), "-o", str(model)]) == 0
    return model


def test_a_bound_on_a_term_some_compared_structures_lack(mmg_tied, tmp_path, capsys):
    """A bound on the race's yaw damping r, which blanke and blanke-speed lack: where 0 meets it
    they hold it at 0 and are compared as without it (they were dropped as "implausible, not
    scored", select refusing a bound its library cannot hold), and blanke, tied, is refitted as
    the model (it kept the comparison's fit, "not a free term"); where 0 does not, they are not
    fitted, and the choice says why."""
    from shipid.cli import main
    from shipid.reporting.modelfile import alternatives_fit, load_document

    log = str(mmg_tied.parent / "zz.csv")
    code = main(["identify", log, "--bound", "r: r >= -10", "-o", str(tmp_path / "a.json")])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert "blanke 0.367, blanke-speed 0.442, blanke-race+race-damping 0.379" in out
    assert "keeps the comparison's fit" not in err
    doc = load_document(tmp_path / "a.json")
    assert alternatives_fit(doc) == "LS-SVM fits with the model's prefilter and γ"
    assert list(doc["identification"]["structure_choice"]["alternatives"]) == ["blanke"]
    code = main(["identify", log, "--bound", "r: r <= -0.01", "-o", str(tmp_path / "b.json")])
    out, err = capsys.readouterr()
    assert code == 0, err
    assert ("not fitted: blanke (bounds: r: r [-inf, -0.01] cannot be met: blanke has no such "
            "term, so its coefficient is 0)") in out


def test_the_tied_structures_are_fitted_as_the_models_own_fit(mmg_tied):
    """The file's tied fits are not the comparison's (γ 1e4, unfiltered): each is refitted on the
    logs as the file's model was (its prefilter and γ), so that a table of the model beside
    them shows the structures' difference, not the fitting's."""
    from shipid.data.io import read_log
    from shipid.data.preprocess import lowpass
    from shipid.identification.identify import identify
    from shipid.reporting.modelfile import (
        alternatives_fit,
        alternatives_from_document,
        load_document,
    )

    doc = load_document(mmg_tied)
    assert alternatives_fit(doc) == "LS-SVM fits with the model's prefilter and γ"
    # A file of an earlier version holds the comparison's fits, and is said to.
    del doc["identification"]["structure_choice"]["alternatives_fit"]
    assert alternatives_fit(doc) == "identify's comparison fits: γ 1e4, unfiltered"
    doc = load_document(mmg_tied)
    prep = doc["identification"]["preprocessing"]
    assert prep["filter_hz"] is not None  # the noisy log is prefiltered: the case that differs
    log = lowpass(read_log(mmg_tied.parent / "zz.csv"), prep["filter_hz"])
    gamma = doc["identification"]["gamma"]
    # At the log's one rps each is written to scale with it, as the model is.
    from shipid.dynamics.astern import AsternForms
    from shipid.dynamics.model import get_structure
    from shipid.dynamics.propeller import ASTERN_THRUST_RATIO
    from shipid.dynamics.similarity import rps_similar

    rps = doc["identification"]["rps_similarity"]["rps"]
    for name, model in alternatives_from_document(doc, mmg_tied).items():
        want = AsternForms(True, ASTERN_THRUST_RATIO).written(rps_similar(identify(
            log, model=get_structure(name), gamma=gamma, force=True).model, rps))  # fmt: skip
        for dof, terms in want.coefficients.items():
            for term, value in terms.items():
                assert model.coefficients[dof][term] == pytest.approx(value, rel=1e-9), (name, term)


def test_manoeuvre_runs_the_structures_the_logs_could_not_tell_apart(mmg_tied, tmp_path, capsys):
    """The tied structures' fits are kept in the model file, and `manoeuvre` runs the same
    manoeuvre on them: the same indices as the run on each alone, from the same approach. At full
    scale (rescale) they come along, Froude-scaled: the same overshoot angles."""
    from shipid.reporting.modelfile import alternatives_from_document, load_document

    doc = load_document(mmg_tied)
    alternatives = alternatives_from_document(doc, mmg_tied)
    assert doc["identification"]["structure_choice"]["how"] == "compared"
    # blanke ties with the race structure fitted; blanke-speed, worse on the blocks within the
    # approach's speed, does not.
    assert set(alternatives) == {"blanke"}
    out = tmp_path / "zz.json"
    code, text, err = run(["manoeuvre", mmg_tied, "zigzag", "--rudder", "10", "--no-bands",
                           "--json", out], capsys)  # fmt: skip
    assert code == 0, err
    assert "could not tell apart" in text
    rec = json.loads(out.read_text())
    speed = rec["approach"]["speed"]
    from shipid.dynamics.steering import SteeringMachine

    gear = SteeringMachine(max_rate=np.radians(rec["rudder_rate_deg_s"]))
    for name, model in alternatives.items():
        alone = zigzag(model, 10, 10, speed=speed, rps=rec["approach"]["rps"], steering=gear,
                       dt=0.05).indices  # fmt: skip
        for key in ("first_overshoot_deg", "second_overshoot_deg"):
            assert rec["tied_structures"][name][key] == pytest.approx(alone[key], abs=1e-9)
        assert f"  {name}: switch_heading_deg 10, first_overshoot_deg " in text
    full = tmp_path / "full.json"
    assert run(["rescale", mmg_tied, "--factor", "45.7", "-o", full], capsys)[0] == 0
    big = tmp_path / "big.json"
    assert run(["manoeuvre", full, "zigzag", "--rudder", "10", "--no-bands", "--json", big],
               capsys)[0] == 0  # fmt: skip
    scaled = json.loads(big.read_text())["tied_structures"]
    for name in alternatives:
        for key in ("first_overshoot_deg", "second_overshoot_deg"):
            assert scaled[name][key] == pytest.approx(rec["tied_structures"][name][key], abs=0.2)


def test_validate_judges_the_tied_structures_on_the_same_logs(mmg_tied, tmp_path, capsys,
                                                              monkeypatch):
    """On a log none of them was fitted to (the MMG model's 10/10 zig-zag), `validate` runs the
    tied fits too: each row is what validating that fit alone gives, and its figure draws each
    tied fit's free run (dashed) beside the model's."""
    from shipid.evaluation.validate import validate
    from shipid.reporting import plots
    from shipid.reporting.modelfile import alternatives_from_document, load_document
    from shipid.vessels import kvlcc2
    from shipid.vessels.kvlcc2 import trimmed_revolutions

    held = zigzag(kvlcc2(), 10, 10, duration=300, dt=0.2, approach=5).log
    held = PAPER_IMU.scaled(0.25).apply(held, seed=7).assign(n=trimmed_revolutions(1.179))
    path = write_log(held, tmp_path / "zz10.csv")
    out = tmp_path / "v.json"
    drawn = []
    save = plots._save

    def keep_lines(fig, target, out=None):
        drawn.append({line.get_label(): line.get_ydata() for ax in fig.axes
                      for line in ax.get_lines() if ax.get_ylabel() == plots.LABELS["r"]})
        return save(fig, target, out)

    monkeypatch.setattr(plots, "_save", keep_lines)
    code, text, err = run(["validate", mmg_tied, path, "--no-bands", "--json", out, "--report",
                           tmp_path / "report", "--plots", tmp_path / "figs"], capsys)  # fmt: skip
    assert code == 0, err
    assert "could not tell apart from this one" in text and "| (the model)" in text
    page = (tmp_path / "report" / "report.html").read_text()
    assert "<h2>Structures the training logs could not tell apart</h2>" in page
    rec = json.loads(out.read_text())["tied_structures"]
    alternatives = alternatives_from_document(load_document(mmg_tied), mmg_tied)
    assert set(rec) == set(alternatives)
    log = read_log(path)
    for name, model in alternatives.items():
        alone = validate(model, log, [str(path)])[0]
        (row,) = rec[name]
        for s in "uvr":
            assert row["metrics"][s]["std"] == pytest.approx(alone.metrics[s]["std"], rel=1e-12)
        assert row["closed_loop"]["second_overshoot_deg"] == pytest.approx(
            alone.indices["closed_loop"]["second_overshoot_deg"], abs=1e-9)  # fmt: skip
        (figure,) = [d for d in drawn if "simulated" in d]  # the validation figure's r panel
        np.testing.assert_allclose(figure[f"{name} (tied)"], alone.simulation.log["r"], rtol=1e-12)
    # A report without --plots draws its own figure: the tied runs are in it too.
    drawn.clear()
    assert run(["validate", mmg_tied, path, "--no-bands", "--report", tmp_path / "alone"],
               capsys)[0] == 0  # fmt: skip
    (figure,) = [d for d in drawn if "simulated" in d]
    assert {f"{name} (tied)" for name in alternatives} <= set(figure)


def test_criteria_give_the_tied_structures_values_beside_the_models(mmg_tied, tmp_path, capsys):
    """`criteria` adds a column per tied structure: the IMO criteria of that fit alone, run
    from the same approach at the same rudder rate."""
    from shipid.dynamics.steering import SteeringMachine
    from shipid.reporting.modelfile import alternatives_from_document, load_document
    from shipid.trials.criteria import imo_criteria

    out = tmp_path / "c.json"
    code, text, err = run(["criteria", mmg_tied, "--length", "7", "--scale", "45.7",
                           "--no-bands", "--json", out], capsys)  # fmt: skip
    assert code == 0, err
    rec = json.loads(out.read_text())
    cond = rec["conditions"]
    gear = SteeringMachine(max_rate=np.radians(cond["rudder_rate_deg_s"]))
    alternatives = alternatives_from_document(load_document(mmg_tied), mmg_tied)
    assert set(rec["tied_structures"]) == set(alternatives)
    for name, model in alternatives.items():
        alone = imo_criteria(model, length=7.0, scale=45.7, speed=cond["speed"], rps=cond["rps"],
                             steering=gear)  # fmt: skip
        keys = zip(alone.table["criterion"], alone.table["manoeuvre"], strict=True)
        expected = dict(zip(keys, alone.table["value"], strict=True))
        for row in rec["criteria"]:
            assert row[name] == pytest.approx(expected[(row["criterion"], row["manoeuvre"])],
                                              rel=1e-9, nan_ok=True)  # fmt: skip
    assert "could not tell apart from this one (LS-SVM fits with the model's prefilter and γ)" in text


def test_the_held_turns_of_two_choices_are_compared_by_their_paths():
    """The Esso's nine zig-zags at 0.1 s given 0.35 m/s at 10 rps: the widened library's choice
    scored the held-out zig-zags better and turned its 35° turns 85–92 % wide where the default
    library's (plausible too) turned 5–33 %: their held turns' paths tell them apart."""
    from shipid.identification.predictions_apart import held_turns_apart

    def report(speed, rate, settled=True):
        turn = {"steady_speed": speed, "settled": settled, "diverged": False}
        return {"rudder_deg": 35.0, "held_rudder": {
            "starboard": {**turn, "steady_yaw_rate": rate},
            "port": {**turn, "steady_yaw_rate": -rate}}}  # fmt: skip

    narrow = report(0.30, 0.080)
    assert held_turns_apart(narrow, report(0.30, 0.055)) == (
        "starboard 3.75 m against 5.45 m, port 3.75 m against 5.45 m")
    # Yaw rates within TURNS_APART (1.25) of each other: nothing to say.
    assert held_turns_apart(narrow, report(0.32, 0.070)) is None
    # A first turn that never settles: passed over, unless asked for (select's check).
    unsettled = report(0.30, 0.080, settled=False)
    assert held_turns_apart(unsettled, report(0.30, 0.055)) is None
    assert held_turns_apart(unsettled, report(0.30, 0.055), first_may_fail=True) == (
        "starboard no steady turn against 5.45 m, port no steady turn against 5.45 m")


def test_a_turn_among_the_logs_lets_the_scores_decide_how_the_model_turns():
    """The widened choice is kept over the default library's, where both pass and turn apart,
    only when a training log is a held turn: its free run is then scored (the tanker's 35°
    turn decided for the widened choice, 1 % off against 18 %)."""
    from test_turning_replica import turning_log

    from shipid.identification.auto_structure import _logs_hold_a_turn
    from shipid.trials.manoeuvres import zigzag
    from shipid.vessels import scale_ship

    zz = zigzag(scale_ship(), 20, 20, duration=60, dt=0.2).log
    assert not _logs_hold_a_turn([zz])
    assert _logs_hold_a_turn([zz, turning_log("port")])


def test_where_no_form_is_usable_the_searches_go_on_in_turn_and_say_why(monkeypatch):
    """``searched_with_the_constant`` after the similar library: the side force's form, then
    every constant, each search's reason carried into the notes; None where none is usable,
    and no form searched twice (a similar library that wrote the side force's constant alone
    goes straight to every constant)."""
    from shipid.dynamics.similarity import SIDE_FORCE
    from shipid.identification import auto_structure as auto

    searched = []

    def fake(logs, names, options, drop, announce, similar=auto.SIMILAR_FORMS[0],
             crossflow=True):  # fmt: skip
        searched.append(tuple(similar))
        usable = tuple(similar) == ()
        return auto._Search(object(), "lib", "", [f"widened in {similar}"], None,
                            None if usable else f"nothing plausible in {similar}",
                            tuple(similar))  # fmt: skip

    class Options:
        cv = "logo"

    monkeypatch.setattr(auto, "_searched", fake)
    said = []
    found = auto.searched_with_the_constant([], [], Options(), None, said.append, "first why")
    assert searched == [SIDE_FORCE, ()]
    assert found.widening[0].startswith("first why with its constant and δ² (n|n|, n⁺²δ²) "
                                        "written as advance-ratio similarity has them, so the "
                                        "library with its constant and δ² in the surge was "
                                        "searched instead")  # fmt: skip
    assert found.widening[1].startswith(f"nothing plausible in {SIDE_FORCE} with the constant "
                                        "of v, r (n|n|) written as advance-ratio similarity "
                                        "has them, so the library with its constant and δ² "
                                        "was searched instead: its model holds a force")
    assert found.widening[2] == "widened in ()"
    assert [m.split(";")[0] for m in said] == ["first why", f"nothing plausible in {SIDE_FORCE}"]
    searched.clear()
    auto.searched_with_the_constant([], [], Options(), None, said.append, "why", SIDE_FORCE)
    assert searched == [()]
    monkeypatch.setattr(auto, "SIMILAR_FORMS", (("u", "v", "r"), SIDE_FORCE))
    assert auto.searched_with_the_constant([], [], Options(), None, said.append, "why") is None


def test_where_no_form_is_usable_the_library_is_searched_with_the_advance_held(monkeypatch):
    """The last search before a named structure: every form of the library again, the thrust
    held to its fall with the advance (u·|n| ≤ 0, on top of the physics given), said so; not
    where the library has no u·|n| or the sign table already holds it, nor where that search
    finds nothing usable either. (Of the nine sets of eight Esso zig-zag files, the one without
    13_14_21 comes to it: random runs 0.75 of r's rms against 2.19 with blanke-rps+wind.)"""
    import math

    from shipid.dynamics.model import ModelStructure
    from shipid.identification import auto_structure as auto
    from shipid.identification import select as select_module
    from shipid.identification.physics import PhysicsOptions
    from shipid.identification.select import SelectOptions

    held = []

    def fake(logs, names, options, drop, announce, similar=auto.SIMILAR_FORMS[0],
             crossflow=True):  # fmt: skip
        held.append(options.physics)
        return auto._Search(object(), "lib", "", ["widened"], None, None, ())

    options = SelectOptions(cv="logo", physics=PhysicsOptions(bounds={"r": {"|u|*r": (
        -math.inf, 0.0)}}))  # fmt: skip
    library = ModelStructure("lib", {"u": ("|u|*u", "pos(n)^2", "u*|n|"), "v": ("v",),
                                     "r": ("r",)})  # fmt: skip
    monkeypatch.setattr(auto, "_searched", fake)
    monkeypatch.setattr(select_module, "default_library", lambda logs: (library, ""))
    said = []
    found = auto.searched_with_the_advance_held([], [], options, None, said.append, "why")
    (physics,) = held
    assert physics.bounds == {"r": {"|u|*r": (-math.inf, 0.0)}, "u": {"u*|n|": (-math.inf, 0.0)}}
    assert physics.bounds_where_present
    assert found.widening[0].startswith("why in any form of the library, so it was searched "
                                        "again with the thrust held to its fall with the "
                                        "advance (u·|n| ≤ 0, as --bound 'u: u*|n| <= 0'")
    assert found.widening[1] == "widened"
    assert said[0].startswith("why; choosing again with the thrust held")
    assert auto.ADVANCE_HELD_BOUNDS == ("u: u*|n| <= 0",)

    options = SelectOptions(cv="logo", physics=PhysicsOptions(signs=True))  # held already
    assert auto.searched_with_the_advance_held([], [], options, None, said.append, "w") is None
    options = SelectOptions(cv="logo")
    monkeypatch.setattr(select_module, "default_library", lambda logs: (
        library.without({"u": ["u*|n|"]}), ""))  # fmt: skip
    assert auto.searched_with_the_advance_held([], [], options, None, said.append, "w") is None
    assert len(held) == 1

    def nothing(logs, names, options, drop, announce, similar=auto.SIMILAR_FORMS[0],
                crossflow=True):  # fmt: skip
        return auto._Search(object(), "lib", "", [], None, "still nothing", ())

    monkeypatch.setattr(auto, "_searched", nothing)
    monkeypatch.setattr(select_module, "default_library", lambda logs: (library, ""))
    assert auto.searched_with_the_advance_held([], [], options, None, said.append, "w") is None


def test_identify_fits_the_chosen_structure_under_the_bounds_its_search_held(tmp_path, capsys,
                                                                            monkeypatch):  # fmt: skip
    """A choice found with the thrust held to its fall with the advance is fitted so: the
    bounds the search held (``StructureChoice.bounds``) go to the fit as ``--bound`` does."""
    from shipid.dynamics.model import get_structure
    from shipid.identification import auto_structure as auto
    from shipid.trials.manoeuvres import zigzag
    from shipid.vessels import scale_ship

    log = tmp_path / "zz.csv"
    write_log(zigzag(scale_ship(), 20, 20, duration=60, dt=0.2).log, log)

    def chosen(logs, names=None, physics=None, cv=None, estimator="lssvm", drop=None,
               announce=None, paper_out=None):  # fmt: skip
        return auto.StructureChoice(get_structure("blanke"), "named", ["a test"],
                                    bounds=["u: |u|*u <= -1"])  # fmt: skip

    monkeypatch.setattr(auto, "auto_structure", chosen)
    code, _, err = run(["identify", log, "--filter", "none", "--no-output-error", "-o",
                        tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    model = json.loads((tmp_path / "m.json").read_text())["model"]
    assert model["coefficients"]["u"]["|u|*u"] == pytest.approx(-1.0)  # the truth's −0.032
    assert "held at its bound" in err


def test_the_tied_fits_turns_are_compared_at_the_gears_rudder(paper_log):
    """Where the particulars' ``rudder_limit`` holds the checks at the gear's largest rudder, the
    tied fits' turns were still compared at 35°, a turn the ship cannot make, and named so."""
    from shipid.data.log import approach
    from shipid.identification.plausibility import held_rudder_at
    from shipid.identification.predictions_apart import predictions_apart
    from shipid.trials.manoeuvres import turning_circle
    from shipid.vessels import scale_ship_model

    ship = scale_ship_model()
    stronger = ManoeuvringModel("blanke", {
        d: {k: (3.0 * x if "delta" in k else x) for k, x in terms.items()}
        for d, terms in ship.coefficients.items()})  # fmt: skip
    models = {"paper": ship, "stronger": stronger}
    with held_rudder_at(20.0):
        (warning,) = [w for w in predictions_apart(models, [paper_log])
                      if "turning circle apart" in w]  # fmt: skip
    assert "a 20° turning circle apart" in warning
    dt = float(np.median(np.diff(paper_log["t"])))
    for name, model in models.items():
        r = turning_circle(model, 20.0, speed=approach(paper_log, "u"), method="euler",
                           dt=dt).indices["steady_yaw_rate"]  # fmt: skip
        assert f"{name} {abs(r):.3g} rad/s" in warning

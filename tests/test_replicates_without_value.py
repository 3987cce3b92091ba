"""An interval over a model's replicates is not bounded when more than its tail have no value; it
used to print "[not bounded]" (and "-inf, inf" in the criteria table) without saying how many
replicates lacked the value or why. On the KVLCC2 from one MARIN zig-zag, three of 100 bootstrap
replicates never check the yaw in a 10/10 zig-zag (their unstable loop is wider than 10°), and in
the criteria 18 of 100 have no 35° tactical diameter (12 have not turned 180° in the run, 6
diverge) while the point model passes with a margin of 1.45 L and only 49 % of the replicates
pass. The truth here is a model built to be unstable: the counter rudder cannot check it."""

import json
import math

import numpy as np
import pytest
from cli_helpers import run
from generated_logs import yaw_damped_ship

from shipid.dynamics.steering import SteeringMachine
from shipid.identification.uncertainty import Ensemble
from shipid.trials.criteria import imo_criteria, replicate_notes, with_intervals
from shipid.trials.manoeuvres import without_value, zigzag

STABLE, UNSTABLE = yaw_damped_ship(-0.8), yaw_damped_ship(0.3)


def test_a_zigzag_says_when_the_counter_rudder_never_checks_the_yaw():
    res = zigzag(UNSTABLE, 10.0, 10.0, speed=1.0, dt=0.05, duration=200.0)
    assert not res.diverged and res.indices["initial_turning_time"] > 0
    assert res.indices["first_overshoot_deg"] is None
    assert res.incomplete == "the counter rudder has not checked the yaw within 200 s"
    short = zigzag(STABLE, 10.0, 10.0, speed=1.0, dt=0.05, duration=30.0)
    assert short.indices["first_overshoot_deg"] is not None
    assert short.incomplete == "no second overshoot within 30 s"
    count, why = without_value([res, short, short], [None, 1.0, math.nan])
    assert count == 2
    assert why == ("1 the counter rudder has not checked the yaw within 200 s; "
                   "1 no second overshoot within 30 s")  # fmt: skip


def _ensemble(unstable: int, members: int = 20) -> Ensemble:
    rng = np.random.default_rng(0)
    j = STABLE.structure.all_terms.index("u*r")
    base = np.array([[STABLE.coefficients[d].get(t, 0.0) for t in STABLE.structure.all_terms]
                     for d in "uvr"])  # fmt: skip
    thetas = base * (1.0 + 0.02 * rng.standard_normal((members, 3, base.shape[1])))
    thetas[:unstable, 2, j] = 0.3
    return Ensemble(STABLE, thetas, block_s=10.0, seed=0)


def test_the_criteria_say_how_many_replicates_have_no_value_and_why():
    ens = _ensemble(unstable=3)
    kw = {"length": 2.0, "speed": 1.0, "scale": 1.0, "dt": 0.1,
          "steering": SteeringMachine(math.radians(35.0), math.radians(20.0))}
    point = imo_criteria(STABLE, **kw)
    replicates = [imo_criteria(m, **kw) for m in ens.members()]
    table = with_intervals(point, replicates)
    row = table[(table["criterion"] == "10/10 first overshoot")
                & (table["manoeuvre"] == "zigzag 10/10 starboard")].iloc[0]  # fmt: skip
    assert row["no_value"] == 3 and math.isinf(row["lower"]) and math.isinf(row["upper"])
    assert row["pass_share"] == pytest.approx(17 / 20)
    notes = replicate_notes(table, replicates, ens.members_label)
    assert any(n.startswith("10/10 first overshoot, zigzag 10/10 starboard: 3 of 20 bootstrap "
                            "replicates have no value (3 the counter rudder has not checked the "
                            "yaw within") for n in notes)  # fmt: skip
    split = [n for n in notes if "disagree on the verdict" in n]
    assert len(split) == 1 and "10/10 first overshoot (zigzag 10/10 starboard) 85%" in split[0]
    # The stable replicates all have turns: those rows have every value and no note.
    turns = table[table["manoeuvre"].str.startswith("turning")]
    assert (turns["no_value"] == 0).all()
    assert not any(n.startswith(("advance", "tactical diameter")) for n in notes)


def test_cli_manoeuvre_says_why_an_index_is_not_bounded(tmp_path, capsys):
    ens = _ensemble(unstable=3)
    model = tmp_path / "m.json"
    STABLE.save(model)
    doc = json.loads(model.read_text(encoding="utf-8"))
    doc["uncertainty"] = ens.to_dict()
    model.write_text(json.dumps(doc), encoding="utf-8")
    code, out, err = run(["manoeuvre", model, "zigzag", "--rudder", "10", "--speed", "1",
                          "--duration", "200", "--json", tmp_path / "z.json"], capsys)  # fmt: skip
    assert code == 0, err
    line = next(ln for ln in out.splitlines() if ln.startswith("first_overshoot_deg:"))
    assert line.endswith("[not bounded: 3 of 20 bootstrap replicates have none: 3 the counter "
                         "rudder has not checked the yaw within 200 s]")  # fmt: skip
    doc = json.loads((tmp_path / "z.json").read_text(encoding="utf-8"))
    assert doc["index_intervals"]["first_overshoot_deg"] == [None, None]  # JSON has no ±inf
    assert doc["index_not_bounded"]["first_overshoot_deg"].startswith("3 of 20 bootstrap")


def test_validate_says_why_an_interval_is_not_bounded():
    from shipid.evaluation.validate import validate_log

    log = zigzag(STABLE, 10.0, 10.0, speed=1.0, dt=0.1, duration=60.0, method="euler",
                 approach=2.0).log  # fmt: skip
    log.attrs["rudder_positive"] = "starboard"
    out = validate_log(STABLE, log, "zz.csv", ensemble=_ensemble(unstable=3))
    lo, hi = out.intervals["closed_loop"]["first_overshoot_deg"]
    assert math.isinf(lo) and math.isinf(hi)
    assert ("first_overshoot_deg (closed loop) is not bounded: 3 of 20 bootstrap replicates have "
            "none (3 the counter rudder has not checked the yaw within 60 s)") in out.warnings
    assert ("first_overshoot_deg (replay) is not bounded: 3 of 20 bootstrap replicates have none "
            "(3 never reach it within the log)") in out.warnings  # fmt: skip

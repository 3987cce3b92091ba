"""``shipid validate VESSEL LOG...``: a reference ship judged on logs as an identified model is
(the published KVLCC2 MMG model against MARIN's and HSVA's free-running runs), which refused
every vessel ("no such model file") and, through the Python API, failed inside its free run."""

import json
from pathlib import Path

import numpy as np
import pytest
from cli_helpers import run

from shipid.data.io import write_log
from shipid.evaluation.validate import validate
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import get_vessel

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
needs_data = pytest.mark.skipif(not (DATA / "kvlcc2-hsva").is_dir(),
                                reason="../shared/data is not present")  # fmt: skip


@pytest.fixture(scope="module")
def ship_and_log():
    """The paper's scale ship and its own 20/20 zig-zag (Euler, as validate runs it): the ship
    predicts it to rounding."""
    ship = get_vessel("scale-ship")
    return ship, zigzag(ship, 20, 20, duration=60, dt=0.1, method="euler").log


def test_a_reference_ship_predicts_its_own_log_exactly_in_either_rudder_convention(ship_and_log):
    ship, log = ship_and_log
    own = validate(ship, log, ["own"])[0]
    assert own.error is None
    assert max(own.metrics[s]["rmse"] for s in "uvr") < 1e-9
    closed, measured = own.indices["closed_loop"], own.indices["measured"]
    for k in ("first_overshoot_deg", "second_overshoot_deg"):
        assert closed[k] == pytest.approx(measured[k], abs=0.05)
    # The same log written in the other convention is turned back to the ship's, and said.
    other = "starboard" if ship.rudder_positive == "port" else "port"
    mirrored = log.assign(delta=-log["delta"])
    mirrored.attrs = {**log.attrs, "rudder_positive": other}
    again = validate(ship, mirrored, ["mirrored"])[0]
    assert max(again.metrics[s]["rmse"] for s in "uvr") < 1e-9
    assert any("its rudder angle is negated" in w for w in again.warnings)


def test_cli_validates_a_reference_ship_with_its_report_and_horizons(ship_and_log, tmp_path,
                                                                   capsys):  # fmt: skip
    ship, log = ship_and_log
    path = write_log(log, tmp_path / "zz.csv")
    code, out, err = run(["validate", "scale-ship", path, "--horizon", "10", "--report",
                          tmp_path / "rep", "--json", tmp_path / "v.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "first_overshoot_deg" in out and "Predictions over a horizon" in out
    assert "reference ship scale-ship" in (tmp_path / "rep" / "report.html").read_text()
    assert (tmp_path / "v.json").exists()
    code, _, err = run(["validate", "scale-ship", path, "--lssvm"], capsys)
    assert code == 1 and err.count("\n") == 1 and "is a reference ship" in err
    # A log of another scale runs at a speed the ship was never made for: said.
    fast = log.assign(u=7 * log["u"])
    code, _, err = run(["validate", "scale-ship", write_log(fast, tmp_path / "fast.csv")], capsys)
    assert "7 times scale-ship's approach" in err


@needs_data
def test_the_mmg_model_on_hsvas_run_as_the_benchmark_reads_it(tmp_path, capsys):
    """The published KVLCC2 MMG model on HSVA's 20/10 zig-zag (7 m model scale, as the MMG
    model): its free run follows the yaw rate to 0.11 of its spread (an independent fit to
    captive tests, not to this run), closed-loop overshoots 1.0° and 1.5° short of the measured
    ones: its replica runs at a seventh of the log's 0.2 s (``replica_step``; at the log's step
    its rudder reversed up to a step late, and the first overshoot read 10.39°, 0.4° nearer by
    that lag; from the log at 0.05 s, 9.93° and 11.30° against 11.09° and 12.99° measured)."""
    code, out, err = run(["validate", "kvlcc2", "--format", "simman-hsva", "--dt", "0.2",
                          DATA / "kvlcc2-hsva" / "HSVA_CPMC_KVLCC2_Z_20_10_P.dat",
                          "--json", tmp_path / "v.json"], capsys)  # fmt: skip
    assert code == 0, err
    (record,) = json.loads((tmp_path / "v.json").read_text())["logs"]
    r_std = record["metrics"]["r"]["std"]
    assert r_std == pytest.approx(0.00357, abs=2e-5)
    closed, measured = record["indices"]["closed_loop"], record["indices"]["measured"]
    assert np.allclose([closed["first_overshoot_deg"], closed["second_overshoot_deg"]],
                       [9.98, 11.37], atol=0.02)  # fmt: skip
    assert measured["first_overshoot_deg"] == pytest.approx(11.0, abs=0.01)


def test_identify_names_the_published_model_of_a_ship_it_has(tmp_path, capsys):
    """Logs that say they are the KVLCC2 (as MARIN's and HSVA's files do), at the built-in
    model's scale: identify points to validate and correct with it; at another scale it does
    not (the built-in ship is the 7 m model)."""
    ship = get_vessel("kvlcc2")
    log = zigzag(ship, 20, 20, duration=60, dt=0.2).log
    assert log.attrs["ship"] == "kvlcc2"
    said = {}
    for label, run_log in (("model scale", log), ("full scale", log.assign(u=6.76 * log["u"]))):
        path = write_log(run_log, tmp_path / f"{label}.csv")
        code, out, err = run(["identify", path, "--model", "blanke-speed", "-o",
                              tmp_path / f"{label}.json"], capsys)  # fmt: skip
        assert code == 0, err
        said[label] = out
    assert "shipid correct kvlcc2 LOG..." in said["model scale"]
    assert "published model" not in said["full scale"]


@pytest.mark.parametrize(("block_coefficient", "logs", "said"),
                         [(0.83, 1, True), (0.60, 1, False), (0.83, 2, False)])
def test_identify_points_one_log_of_a_full_form_hull_to_a_sister_ship(
        tmp_path, capsys, block_coefficient, logs, said):  # fmt: skip
    """One log of a full-form hull with no built-in model (the Esso Osaka's case: its sister,
    the KVLCC2's MMG model with its particulars, predicted its other logs better than a fit to
    one of its files): identify names ``shipid mmg`` and the prior; not for a finer hull, nor
    from two logs, where the fits did as well."""
    ship = get_vessel("scale-ship")
    particulars = {"length": 4.2, "beam": 0.8, "draught": 0.25, "mass": 600.0,
                   "block_coefficient": block_coefficient}  # fmt: skip
    paths = []
    for i, side in enumerate(("starboard", "port")[:logs]):
        log = zigzag(ship, 20, 20, first=side, duration=60, dt=0.2).log
        log.attrs["particulars"] = particulars
        paths.append(write_log(log, tmp_path / f"zz{i}.csv"))
    code, out, err = run(["identify", *paths, "--model", "blanke", "--no-output-error",
                          "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert (f"one log of a full-form hull (Cb {block_coefficient:.2f}" in out) is said
    if not said:
        assert "shipid mmg" not in out
        return
    # The command it gives runs as given: the particulars from the model file just written.
    import re
    import shlex

    (command,) = re.findall(r"shipid (mmg kvlcc2 --particulars .+? -o SHIP\.yml)", out)
    argv = shlex.split(command.replace("SHIP.yml", str(tmp_path / "sister.yml")))
    assert argv[3] == str(tmp_path / "m.json")
    code, _, err = run(argv, capsys)
    assert code == 0, err
    from shipid.vessels.mmg_file import read_mmg

    sister = read_mmg(tmp_path / "sister.yml")
    assert sister.length == pytest.approx(4.2)


def test_particulars_read_from_a_model_file_that_keeps_them(tmp_path):
    """``--particulars MODEL.json``: the particulars identify kept in the model file (what
    identify's note on one log of a full-form hull passes to ``shipid mmg``); a model file
    without them is named, not read as empty particulars."""
    from shipid.data.particulars import read_particulars
    from shipid.errors import ShipidError

    doc = {"format": "shipid-model", "particulars": {"length": 3.0, "beam": 0.489,
                                                     "draught": 0.201, "mass": 244.6}}
    (tmp_path / "m.json").write_text(json.dumps(doc), encoding="utf-8")
    found = read_particulars(tmp_path / "m.json")
    assert (found.length, found.beam, found.draught, found.mass) == (3.0, 0.489, 0.201, 244.6)
    (tmp_path / "bare.json").write_text(json.dumps({**doc, "particulars": None}), encoding="utf-8")
    with pytest.raises(ShipidError, match="bare.json: the model file keeps no particulars"):
        read_particulars(tmp_path / "bare.json")

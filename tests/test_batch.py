"""Identification of many log sets as a study (issue #13 item 6): each job is the command line
typed by hand, run by the same code; failures named; specs checked."""

import json
import threading

import pytest
from cli_helpers import run

from shipid.data.io import write_log
from shipid.errors import ShipidError
from shipid.evaluation.study import read_spec
from shipid.identification.batch import BatchSpec, run_batch
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import PAPER_IMU, scale_ship


@pytest.fixture(scope="module")
def logs(tmp_path_factory):
    d = tmp_path_factory.mktemp("batch")
    ship = scale_ship(rudder_rate_deg=9.6)
    for i, angle in enumerate((15, 20, 25)):
        log = zigzag(ship, angle, angle, duration=90, dt=0.2, method="euler").log
        write_log(PAPER_IMU.apply(log, seed=i), d / "logs" / f"zz{angle}.csv")
    return d


def _spec(d, jobs) -> BatchSpec:
    return BatchSpec.from_dict({"kind": "logs", "jobs": jobs}, source="s.yml", base=d)


def test_a_job_gives_the_model_of_the_command_typed_by_hand(logs, capsys):
    jobs = [{"name": "one", "logs": ["logs/zz20.csv"], "options": {"filter": 0.5, "drop": "u:r^2"}},
            {"name": "sel", "command": "select", "logs": ["logs/zz*.csv"],
             "options": {"library": "blanke", "search": "none"}}]  # fmt: skip
    table, texts = run_batch(_spec(logs, jobs), scheduler="serial", progress=False)
    assert table["error"].tolist() == ["", ""] and table["logs"].tolist() == [1, 3]
    assert run(["identify", logs / "logs" / "zz20.csv", "--filter", "0.5", "--drop", "u:r^2",
                "-o", logs / "by-hand.json"], capsys)[0] == 0  # fmt: skip
    by_hand = json.loads((logs / "by-hand.json").read_text(encoding="utf-8"))
    assert json.loads(texts["one"])["model"] == by_hand["model"]
    assert table.loc[0, "prefilter_hz"] == 0.5 and table.loc[0, "terms"] == 16
    chosen = json.loads(texts["sel"])
    assert chosen["identification"]["selection"]["score"] == pytest.approx(table.loc[1, "cv_score"])


def test_the_command_writes_every_model_and_names_a_failed_job(logs, capsys):
    spec = logs / "fleet.yml"
    spec.write_text("kind: logs\njobs:\n"
                    "  - {name: good, logs: [logs/zz15.csv], options: {filter: none}}\n"
                    "  - {name: bad, logs: [logs/zz25.csv], options: {model: nonsense}}\n",
                    encoding="utf-8")  # fmt: skip
    code, out, err = run(["study", spec, "--scheduler", "serial", "--quiet", "-o",
                          logs / "fleet.csv", "--models", logs / "models"], capsys)  # fmt: skip
    assert code == 1 and "2 jobs (2 logs) on this process" in out
    assert err.startswith("shipid: error: job bad: unknown model 'nonsense'")
    assert len(err.strip().splitlines()) == 1
    assert sorted(p.name for p in (logs / "models").iterdir()) == ["good.json"]
    assert (logs / "fleet.csv").exists()
    code, _, err = run(["study", spec, "--scheduler", "serial", "-o", logs / "f2.csv"], capsys)
    assert code == 1 and "give --models DIR" in err and not (logs / "f2.csv").exists()


@pytest.mark.parametrize("jobs, message", [
    ([{"name": "a b", "logs": ["logs/zz15.csv"]}], "name 'a b'"),
    ([{"name": "a", "logs": ["logs/zz15.csv"]}, {"name": "a", "logs": ["logs/zz20.csv"]}],
     "used twice"),
    ([{"name": "a", "command": "validate", "logs": ["logs/zz15.csv"]}], "command 'validate'"),
    ([{"name": "a", "logs": ["logs/none*.csv"]}], "no such file 'logs/none*.csv'"),
    ([{"name": "a", "logs": []}], "logs: give"),
    ([{"name": "a", "logs": ["logs/zz15.csv"], "options": ["--dt"]}], "options is a mapping"),
    ([{"name": "a", "logs": ["logs/zz15.csv"], "options": {"output": "x.json"}}], "set by the study"),
    ([{"name": "a", "logs": ["logs/zz15.csv"], "model": "blanke"}], "unknown key 'model'"),
    ([], "give a list of jobs"),
    # Each made argparse exit inside the job: the study ended with exit 2 and no word, or kept
    # the last of a list silently.
    ([{"name": "a", "logs": ["logs/zz15.csv"], "options": {"bogus": 1}}],
     r"jobs\[0\]: options: unrecognized arguments: --bogus 1 \(shipid identify --help\)"),
    ([{"name": "a", "logs": ["logs/zz15.csv"], "options": {"dt": "abc"}}],
     "argument --dt: invalid float value: 'abc'"),
    ([{"name": "a", "command": "select", "logs": ["logs/zz15.csv"], "options": {"filter": 1}}],
     "unrecognized arguments: --filter 1 \\(shipid select --help\\)"),
    ([{"name": "a", "logs": ["logs/zz15.csv"], "options": {"filter": [1, 2]}}],
     "filter takes one value, not a list"),
])  # fmt: skip
def test_bad_jobs_are_named(logs, jobs, message):
    with pytest.raises(ShipidError, match=message.replace("*", r"\*")):
        _spec(logs, jobs)


def test_read_spec_dispatches_on_kind(logs):
    (logs / "k.yml").write_text("kind: logs\njobs: [{name: a, logs: [logs/zz15.csv]}]\n")
    spec = read_spec(logs / "k.yml")
    assert isinstance(spec, BatchSpec) and spec.jobs[0].logs == (str(logs / "logs" / "zz15.csv"),)
    (logs / "m.yml").write_text("kind: monte-carlo\nseeds: 2\n")
    assert read_spec(logs / "m.yml").seeds == (0, 1)
    (logs / "x.yml").write_text("kind: fleet\n")
    with pytest.raises(ShipidError, match="kind 'fleet'"):
        read_spec(logs / "x.yml")


def test_the_command_line_runs_outside_the_main_thread(logs, capsys):
    """Dask workers run tasks in threads, where signal handlers cannot be installed."""
    from shipid.cli import main

    codes = []
    t = threading.Thread(target=lambda: codes.append(main(["identify", str(logs / "logs" / "zz15.csv"),
                                                           "--filter", "none", "-o",
                                                           str(logs / "thread.json")])))  # fmt: skip
    t.start()
    t.join()
    assert codes == [0] and (logs / "thread.json").exists()

"""A model asked a kind of manoeuvre none of its training logs is. The envelope names the signals
a run takes beyond the logs; a turn predicted from zig-zags can stay inside every signal's range
and still be an extrapolation, which its bootstrap intervals do not hold (on the Esso Osaka, its
turns' advances in a quarter of the cases). The model file records what its training logs read
as, and validate, manoeuvre and criteria say so."""

import json

import pytest
from cli_helpers import run

from shipid.data.io import write_log
from shipid.evaluation.envelope import unseen_kind_note
from shipid.trials.manoeuvres import turning_circle, zigzag
from shipid.vessels import PAPER_IMU, scale_ship

NOTE = "none of the model's"


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    folder = tmp_path_factory.mktemp("kinds")
    ship = scale_ship()
    logs = {"zz.csv": zigzag(ship, 20, 20, duration=60, dt=0.1, approach=5.0).log,
            "turn.csv": turning_circle(ship, 20, duration=60, dt=0.1, approach=5.0).log}
    for i, (name, log) in enumerate(logs.items()):
        write_log(PAPER_IMU.apply(log, seed=i), folder / name)
    return folder


def test_the_model_file_says_what_its_training_logs_read_as(files, tmp_path, capsys):
    # The record is the point, not the fit: the LS-SVM's alone (no output-error covariance,
    # whose draws each manoeuvre below would run).
    fast = ["--model", "blanke", "--no-output-error"]
    code, _, err = run(["identify", files / "zz.csv", *fast, "-o", tmp_path / "zz.json"], capsys)
    assert code == 0, err
    doc = json.loads((tmp_path / "zz.json").read_text())
    assert doc["identification"]["preprocessing"]["manoeuvres"] == ["zigzag"]
    # Its turn is carried from the zig-zag: validate, manoeuvre and criteria say so ...
    code, _, err = run(["validate", tmp_path / "zz.json", files / "turn.csv", files / "zz.csv"],
                       capsys)  # fmt: skip
    assert code == 0, err
    lines = [line for line in err.splitlines() if NOTE in line]
    assert len(lines) == 1 and "turn.csv" in lines[0] and "zz.csv" not in lines[0]
    assert ("none of the model's 1 training logs is a turning circle or pull-out (they read as "
            "1 zig-zag)") in lines[0]  # fmt: skip
    code, _, err = run(["manoeuvre", tmp_path / "zz.json", "turning"], capsys)
    assert code == 0 and NOTE in err
    code, _, err = run(["manoeuvre", tmp_path / "zz.json", "zigzag"], capsys)
    assert code == 0 and NOTE not in err
    # ... and not where a turn is among the training logs.
    code, _, err = run(["identify", files / "zz.csv", files / "turn.csv", *fast, "-o",
                        tmp_path / "both.json"], capsys)  # fmt: skip
    assert code == 0, err
    code, _, err = run(["validate", tmp_path / "both.json", files / "turn.csv"], capsys)
    assert code == 0 and NOTE not in err


@pytest.mark.parametrize(("trained", "kind", "said"), [
    (["zigzag", "other"], "turning", True),
    (["zigzag", "pull-out"], "turning", False),
    (["turning"], "pull-out", False),
    (["turning", None], "zigzag", True),
    (["zigzag"], "other", False),
    (None, "turning", False),  # a file from before the record: nothing to say
    ([None], "turning", False),
])  # fmt: skip
def test_which_kinds_count_as_seen(trained, kind, said):
    assert (unseen_kind_note(trained, kind) is not None) == said


def test_criteria_name_the_runs_of_a_kind_no_training_log_is():
    from shipid.cli.trials import _criteria_unseen_kinds

    runs = dict.fromkeys(["turning 35° starboard", "turning 35° port", "zigzag 10/10 starboard"])
    notes = _criteria_unseen_kinds(["zigzag", "zigzag"], runs)
    assert len(notes) == 1
    assert notes[0].startswith("criteria (turning 35° starboard, turning 35° port): " + NOTE)
    assert _criteria_unseen_kinds(["zigzag", "turning"], runs) == []

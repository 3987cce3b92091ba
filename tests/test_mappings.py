"""Hand-written YAML and JSON files read strictly (``shipid.data.mappings``): a key given twice
was kept at its last value without a word, a particulars file's second ``length`` judging the
IMO criteria at another ship's length."""

import json

import pytest
from cli_helpers import run

from shipid.data.mappings import DuplicateKeyError, load_json, load_yaml
from shipid.data.particulars import read_particulars
from shipid.errors import ShipidError
from shipid.evaluation.study import read_spec
from shipid.reporting.modelfile import load_document
from shipid.vessels.mmg_file import read_document


@pytest.mark.parametrize("text", ["length: 3\nbeam: 0.5\nlength: 4\n",
                                  "rudder:\n  area: 1\n  area: 2\n"])  # fmt: skip
def test_yaml_refuses_a_key_given_twice_at_any_depth(text):
    with pytest.raises(DuplicateKeyError, match="is given twice"):
        load_yaml(text)


def test_json_refuses_a_key_given_twice_and_reads_the_rest_as_json_does():
    with pytest.raises(DuplicateKeyError, match="'a' is given twice"):
        load_json('{"b": {"a": 1, "a": 2}}')
    text = '{"a": [1, {"c": null}], "b": 2.5}'
    assert load_json(text) == json.loads(text)
    assert load_yaml("a: 1\nb: [1, 2]\n") == {"a": 1, "b": [1, 2]}


def test_every_hand_written_file_names_the_key_given_twice(tmp_path, capsys):
    (tmp_path / "p.yml").write_text("length: 3\nbeam: 0.5\nlength: 4\n")
    with pytest.raises(ShipidError, match=r"p\.yml: 'length' is given twice \(line 3\)"):
        read_particulars(tmp_path / "p.yml")
    (tmp_path / "p.json").write_text('{"length": 3, "length": 4}')
    with pytest.raises(ShipidError, match=r"p\.json: 'length' is given twice"):
        read_particulars(tmp_path / "p.json")
    (tmp_path / "s.yml").write_text("seeds: 2\nseeds: 3\n")
    with pytest.raises(ShipidError, match=r"s\.yml: 'seeds' is given twice"):
        read_spec(tmp_path / "s.yml")
    (tmp_path / "m.yml").write_text("name: a\nname: b\n")
    with pytest.raises(ShipidError, match=r"m\.yml: 'name' is given twice"):
        read_document(tmp_path / "m.yml")
    (tmp_path / "f.json").write_text('{"format": "x", "format": "y"}')
    with pytest.raises(ShipidError, match=r"f\.json: 'format' is given twice"):
        load_document(tmp_path / "f.json")
    # Through a command: one line, exit 1.
    code, _, err = run(["criteria", "scale-ship", "--particulars", tmp_path / "p.yml"], capsys)
    assert code == 1 and err.count("\n") == 1 and "'length' is given twice" in err

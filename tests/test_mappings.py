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


@pytest.mark.parametrize(("name", "text", "read", "match"), [
    ("p.yml", "length: 3\nbeam: 0.5\nlength: 4\n", read_particulars,
     r"p\.yml: 'length' is given twice \(line 3\)"),
    ("p.json", '{"length": 3, "length": 4}', read_particulars, r"p\.json: 'length' is given twice"),
    ("s.yml", "seeds: 2\nseeds: 3\n", read_spec, r"s\.yml: 'seeds' is given twice"),
    ("m.yml", "name: a\nname: b\n", read_document, r"m\.yml: 'name' is given twice"),
    ("f.json", '{"format": "x", "format": "y"}', load_document, r"f\.json: 'format' is given twice"),
])  # fmt: skip
def test_every_hand_written_file_names_the_key_given_twice(tmp_path, name, text, read, match):
    (tmp_path / name).write_text(text)
    with pytest.raises(ShipidError, match=match):
        read(tmp_path / name)


def test_a_command_refuses_the_file_in_one_line(tmp_path, capsys):
    (tmp_path / "p.yml").write_text("length: 3\nbeam: 0.5\nlength: 4\n")
    code, _, err = run(["criteria", "scale-ship", "--particulars", tmp_path / "p.yml"], capsys)
    assert code == 1 and err.count("\n") == 1 and "'length' is given twice" in err

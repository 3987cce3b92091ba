"""Property-based fuzzing of the boundaries: malformed logs, model files and option values.

Properties, for every generated input: no exception but ``ShipidError`` from the API (exit 0 or 1
and no traceback from the CLI), no partial output file, and the inputs never modified.

The suite runs a small sample (profile ``ci``). The full run (profile ``fuzz``, 2 500 cases per
property, over 10 000 in all)::

    HYPOTHESIS_PROFILE=fuzz .venv/bin/python -m pytest tests/test_fuzz.py -q
"""

from __future__ import annotations

import copy
import io
import json
import math
import os
import tempfile
from contextlib import redirect_stderr, redirect_stdout
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from shipid.cli import main
from shipid.data.io import read_log, write_log
from shipid.errors import ShipidError
from shipid.identification.identify import identify
from shipid.reporting.modelfile import load_model
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import scale_ship

settings.register_profile("ci", max_examples=40, deadline=None, derandomize=True,
                          suppress_health_check=[HealthCheck.too_slow])  # fmt: skip
settings.register_profile("fuzz", max_examples=2500, deadline=None,
                          suppress_health_check=list(HealthCheck))  # fmt: skip
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "ci"))

COLUMNS = ["t", "delta", "u", "v", "r", "psi", "x", "y", "n", "thrust", "wind_speed", "junk"]
WEIRD = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True, width=64),
    st.integers(-10**12, 10**12),
    st.text(max_size=8),
    st.sampled_from(["", "nan", "inf", "-inf", "1e309", "TRUE", "0x10", "1,5", "  ", "∞", "\x00"]),
)


@pytest.fixture(scope="module")
def base():
    """A valid trial, its CSV text and a valid model document."""
    log = zigzag(scale_ship(rudder_rate_deg=9.6), 20, 20, duration=40, dt=0.2, method="euler",
                 approach=2.0).log  # fmt: skip
    fit = identify(log)
    from shipid.reporting.modelfile import model_document

    return log, model_document(fit)


def _run_cli(argv) -> tuple[int, str]:
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        try:
            code = main([str(a) for a in argv])
        except SystemExit as exc:  # argparse: usage errors
            code = exc.code
    return code, err.getvalue()


def _snapshot(folder: Path) -> dict:
    return {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file()}


# ---------------------------------------------------------------------------- logs
@st.composite
def malformed_logs(draw, valid: pd.DataFrame):
    """A valid log with up to 12 edits; columns are (name, values) pairs, so duplicate or empty
    names are just data."""
    cols = [(c, list(valid[c].to_numpy(dtype=object))) for c in valid.columns]
    n_rows = len(valid)
    for _ in range(draw(st.integers(0, 12))):
        if not cols or n_rows == 0:
            break
        action = draw(st.sampled_from(["cell", "drop_col", "rename", "drop_rows", "dup_row",
                                       "reverse", "scale", "add_col"]))  # fmt: skip
        j = draw(st.integers(0, len(cols) - 1))
        name, values = cols[j]
        if action == "cell":
            values[draw(st.integers(0, n_rows - 1))] = draw(WEIRD)
        elif action == "drop_col" and len(cols) > 1:
            cols.pop(j)
        elif action == "rename":
            cols[j] = (draw(st.sampled_from(COLUMNS + ["", "t [s]", "u [m/s]"])), values)
        elif action == "drop_rows":
            k = draw(st.integers(0, n_rows))
            keep = slice(0, k) if draw(st.booleans()) else slice(k, n_rows)
            cols = [(c, v[keep]) for c, v in cols]
            n_rows = len(cols[0][1])
        elif action == "dup_row":
            k = draw(st.integers(0, n_rows - 1))
            cols = [(c, v[: k + 1] + v[k:]) for c, v in cols]
            n_rows += 1
        elif action == "reverse":
            cols = [(c, v[::-1]) for c, v in cols]
        elif action == "scale":
            factor = draw(st.sampled_from([0.0, -1.0, 1e-9, 57.3, 1000.0, 1e300]))
            cols[j] = (name, [x * factor if isinstance(x, float) else x for x in values])
        else:
            cols.append((draw(st.sampled_from(COLUMNS)), [draw(WEIRD)] * n_rows))
    frame = pd.DataFrame({i: v for i, (_, v) in enumerate(cols)})
    frame.columns = [c for c, _ in cols]
    return frame


@given(data=st.data())
def test_read_log_and_identify_raise_only_shipid_errors(base, data):
    log, _ = base
    df = data.draw(malformed_logs(log))
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / ("log.csv" if data.draw(st.booleans()) else "log.parquet")
        try:
            if path.suffix == ".csv":
                df.to_csv(path, index=False)
            else:
                df.astype(str).to_parquet(path, index=False) if data.draw(st.booleans()) \
                    else df.to_parquet(path, index=False)
        except Exception:
            return  # pandas/pyarrow cannot write this frame: not an input a user can have
        before = path.read_bytes()
        try:
            read = read_log(path)
            identify(read)
        except ShipidError:
            pass
        assert path.read_bytes() == before


@given(text=st.text(max_size=400), raw=st.binary(max_size=200))
def test_read_log_of_arbitrary_text_and_bytes(text, raw):
    with tempfile.TemporaryDirectory() as tmp:
        for name, content in (("a.csv", text.encode("utf-8", "surrogatepass")), ("b.csv", raw),
                              ("c.parquet", raw)):  # fmt: skip
            path = Path(tmp) / name
            path.write_bytes(content)
            try:
                read_log(path)
            except ShipidError:
                pass


# ---------------------------------------------------------------------------- model files
def _paths(doc, prefix=()):
    if isinstance(doc, dict):
        for k, v in doc.items():
            yield (*prefix, k)
            yield from _paths(v, (*prefix, k))
    elif isinstance(doc, list):
        for i, v in enumerate(doc):
            yield (*prefix, i)
            yield from _paths(v, (*prefix, i))


JSON_VALUES = st.recursive(
    st.one_of(st.none(), st.booleans(), st.floats(allow_nan=True, allow_infinity=True),
              st.integers(), st.text(max_size=6)),
    lambda children: st.lists(children, max_size=3) | st.dictionaries(st.text(max_size=4),
                                                                      children, max_size=3),
    max_leaves=6,
)  # fmt: skip


@given(data=st.data())
def test_load_model_of_mutated_files(base, data):
    _, doc = base
    doc = copy.deepcopy(doc)
    paths = list(_paths(doc))
    for _ in range(data.draw(st.integers(1, 4))):
        path = data.draw(st.sampled_from(paths))
        target = doc
        try:
            for k in path[:-1]:
                target = target[k]
            if data.draw(st.booleans()):
                target[path[-1]] = data.draw(JSON_VALUES)
            elif isinstance(target, dict):
                del target[path[-1]]
        except (KeyError, IndexError, TypeError):
            continue
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "m.json"
        path.write_text(json.dumps(doc, allow_nan=True))
        try:
            model = load_model(path)
        except ShipidError:
            return
        assert np.all(np.isfinite(model.theta))


# ---------------------------------------------------------------------------- CLI options
NUMBERS = st.one_of(st.sampled_from(["0", "-1", "nan", "inf", "-inf", "1e308", "1e-300", "1e12",
                                     "abc", "", "1e7", "3"]),  # fmt: skip
                    st.floats(allow_nan=True, allow_infinity=True).map(repr))
COMMANDS = {
    "identify": ["identify", "{log}", "-o", "{out}/m.json"],
    "validate": ["validate", "{model}", "{log}", "--json", "{out}/v.json"],
    "manoeuvre": ["manoeuvre", "{model}", "zigzag", "--json", "{out}/z.json"],
    "indices": ["indices", "{log}", "--json", "{out}/i.json"],
    "import": ["import", "{log}", "-o", "{out}/x.csv"],
    "simulate": ["simulate", "{model}", "{log}", "-o", "{out}/s.csv"],
    "criteria": ["criteria", "{model}", "--length", "7", "--json", "{out}/c.json"],
    "linearise": ["linearise", "{model}"],
    "autopilot": ["autopilot", "{model}", "-o", "{out}/a.png"],
    "follow": ["follow", "{model}", "--json", "{out}/f.json"],
    "plot": ["plot", "{log}", "-o", "{out}/p.png"],
    "rescale": ["rescale", "{model}", "-o", "{out}/r.json"],
}
OPTIONS = {
    "identify": ["--gamma", "--dt", "--filter", "--lead", "--start", "--end", "--bootstrap",
                 "--block"],
    "validate": ["--dt", "--smooth", "--start", "--end"],
    "manoeuvre": ["--rudder", "--heading", "--duration", "--dt", "--speed", "--rps",
                  "--wind-speed", "--wind-from"],
    "indices": ["--heading", "--smooth", "--dt", "--start"],
    "import": ["--dt", "--start", "--end", "--scale"],
    "simulate": ["--dt", "--start"],
    "criteria": ["--length", "--speed", "--scale", "--rudder-rate", "--dt"],
    "linearise": ["--speed"],
    "autopilot": ["--omega", "--dt", "--heading", "--duration", "--speed"],
    "follow": ["--omega", "--dt", "--lookahead", "--speed"],
    "plot": ["--dt", "--start", "--end"],
    "rescale": ["--factor", "--length", "--rho"],
}


@given(data=st.data())
def test_cli_option_values_never_crash_or_leave_partial_files(base, data, tmp_path_factory):
    log, doc = base
    folder = tmp_path_factory.mktemp("fuzz")
    log_path = write_log(log, folder / "zz.csv")
    model = folder / "model.json"
    model.write_text(json.dumps(doc))
    inputs = _snapshot(folder)
    out = folder / "out"
    out.mkdir()
    command = data.draw(st.sampled_from(sorted(COMMANDS)))
    argv = [a.format(log=log_path, model=model, out=out) for a in COMMANDS[command]]
    for option in data.draw(st.lists(st.sampled_from(OPTIONS[command]), max_size=3, unique=True)):
        value = data.draw(NUMBERS)
        if option in ("--start", "--end") and data.draw(st.booleans()):
            value = "auto"
        argv += [option, value]
    code, err = _run_cli(argv)
    assert code in (0, 1, 2), (argv, code, err)
    assert "Traceback" not in err, (argv, err)
    if code == 1:
        errors = [ln for ln in err.splitlines() if ln.startswith("shipid: error:")]
        assert errors, (argv, err)
    written = list(out.iterdir())
    if code != 0 and written:
        # Only a validate batch in which some log validated writes on exit 1: its JSON then
        # records every log, the failed ones with their error.
        assert command == "validate", (argv, err)
        records = json.loads((out / "v.json").read_text())["logs"]
        assert any(r["error"] is None for r in records) and any(r["error"] for r in records)
    assert not [p for p in out.iterdir() if p.name.endswith(".tmp")]
    assert _snapshot(folder) == inputs  # inputs never modified
    for p in out.iterdir():
        if p.suffix == ".json":
            json.loads(p.read_text())  # complete, parseable


def test_fuzz_profile_is_documented():
    """The full run is what the closing note reports; keep its command in the docstring."""
    assert "HYPOTHESIS_PROFILE=fuzz" in __doc__ and math.isfinite(2500)

"""Files in and out: round trips of logs and metadata, output safety, model-file schema, readers,
and units that look wrong. Each test reproduces a defect of issue #11 (numbered there)."""

import json
import math
import os
import re
import stat
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from cli_helpers import copy_identified, identify_in, run

from shipid.data.io import read_log, write_log
from shipid.errors import ShipidError
from shipid.trials.manoeuvres import zigzag
from shipid.vessels import scale_ship

DATA = Path(__file__).resolve().parents[2] / "shared" / "data"
needs_data = pytest.mark.skipif(not DATA.is_dir(), reason="../shared/data is not present")
MARIN_ZZ20 = DATA / "kvlcc2-marin" / "MARIN_FREE_KVLCC2_zz_20_m.dat"
OSAKA_3030 = DATA / "esso-osaka" / "zigzag" / "zigzag_31-Jul-2020_13_14_21.csv"
HSVA = DATA / "kvlcc2-hsva" / "HSVA_CPMC_KVLCC2_Z_20_10_P.dat"


@pytest.fixture(scope="module")
def trial():
    log = zigzag(scale_ship(rudder_rate_deg=9.6), 20, 20, duration=60, dt=0.2, method="euler",
                 approach=2.0).log  # fmt: skip
    log.attrs.update({"ship": "scale-ship", "rudder_positive": "port"})
    return log


@pytest.fixture()
def trial_csv(tmp_path, trial):
    path = tmp_path / "zz.csv"
    write_log(trial, path)
    return path


# ---------------------------------------------------------------------------- 1, 2: round trips
@pytest.mark.parametrize("ext", [".csv", ".parquet"])
def test_log_round_trip_keeps_times_exactly_and_metadata(tmp_path, ext):
    t = np.arange(4481) * (606.0 / 4480) / math.sqrt(45.7)  # the MARIN rebuilt time grid
    log = pd.DataFrame({"t": t, "delta": 0.1 * np.sin(t), "u": 1.0 + 0 * t, "v": 0 * t,
                        "r": -0.01 * np.cos(t)})  # fmt: skip
    log.attrs.update({"ship": "KVLCC2", "rudder_positive": "starboard", "scale": 45.7,
                      "source": "test"})  # fmt: skip
    path = write_log(log, tmp_path / f"log{ext}")
    back = read_log(path)
    np.testing.assert_array_equal(back["t"].to_numpy(), t)  # bit for bit
    for k in ("ship", "rudder_positive", "scale"):
        assert back.attrs[k] == log.attrs[k]



@pytest.mark.parametrize("ext", [".csv", ".parquet"])
def test_nested_metadata_is_shared_read_only_and_survives_files_and_pickles(tmp_path, ext):
    """The particulars (and the sensors' noise) are handed to every column pandas cuts from a
    log: by reference, as a mapping nobody can change, and as plain JSON in files."""
    import copy
    import pickle

    from shipid.data.log import FrozenMapping, make_log

    particulars = {"length": 3.0, "beam": 0.489, "draught": 0.201}
    log = make_log({"t": np.arange(5.0), "delta": np.zeros(5), "u": np.ones(5),
                    "v": np.zeros(5), "r": np.zeros(5)}, particulars=particulars,
                   rudder_positive="starboard")  # fmt: skip
    shared = log.attrs["particulars"]
    assert isinstance(shared, FrozenMapping) and shared == particulars
    assert log["u"].attrs["particulars"] is shared and log.iloc[2:].attrs["particulars"] is shared
    assert copy.deepcopy(log).attrs["particulars"] is shared
    with pytest.raises(TypeError, match="read-only"):
        shared["length"] = 4.0
    with pytest.raises(TypeError, match="read-only"):
        shared.update(length=4.0)
    assert shared == particulars  # the log's own copy is untouched
    unpickled = pickle.loads(pickle.dumps(log))
    assert unpickled.attrs["particulars"] == particulars
    back = read_log(write_log(log, tmp_path / f"log{ext}"))
    assert {k: back.attrs["particulars"][k] for k in particulars} == particulars
    assert isinstance(back.attrs["particulars"], FrozenMapping)


def test_a_log_built_from_one_block_is_the_frame_of_its_columns():
    """make_log's one block and shared column index, and column_array's stacked columns: the
    frame and the arrays pandas gives from the columns themselves, owning their data."""
    from shipid.data.log import column_array, make_log

    rng = np.random.default_rng(0)
    columns = {c: rng.normal(size=7) for c in ("t", "delta", "u", "v", "r", "psi", "n")}
    columns["n"] = np.arange(7)  # integers, made floats
    log = make_log(columns, ship="x")
    expected = pd.DataFrame({c: np.asarray(v, dtype=float) for c, v in columns.items()})
    pd.testing.assert_frame_equal(log, expected)
    columns["u"][0] = 99.0  # the caller's arrays are not the log's
    assert log["u"].iloc[0] != 99.0
    assert log.columns.tolist() == ["t", "delta", "u", "v", "r", "psi", "n"]
    for names in (("u", "v", "r"), ("n", "delta"), ()):
        expected = log[list(names)].to_numpy(dtype=float)
        assert np.array_equal(column_array(log, names), expected)
        assert column_array(log, names).shape == (7, len(names))
    ragged = make_log({"t": np.arange(3.0), "u": 1.0})  # a scalar column broadcast, as pandas does
    assert ragged["u"].tolist() == [1.0, 1.0, 1.0]
    # Columns of different lengths are named (pandas said "All arrays must be of the same length").
    with pytest.raises(ValueError, match=r"^log columns of different lengths: t 3, delta 2$"):
        make_log({"t": np.arange(3.0), "delta": [0.0, 1.0], "u": 1.0})


def test_write_log_names_what_is_not_a_log(tmp_path):
    """write_log('notalog', path) raised "'str' object has no attribute 'copy'"; nothing is
    written."""
    with pytest.raises(ShipidError, match=r"^a log to write is a pandas DataFrame .*got the "
                                          r"path 'notalog'$"):  # fmt: skip
        write_log("notalog", tmp_path / "w.csv")
    assert not (tmp_path / "w.csv").exists()

def test_column_options_that_do_nothing_say_so(tmp_path):
    """--columns naming a column the file lacks, onto one it has, read the file's own column;
    --columns and --degrees with a known --format were dropped: both without a word."""
    from shipid.data.formats import read_simman_marin
    from shipid.errors import ShipidWarning

    log = zigzag(scale_ship(rudder_rate_deg=9.6), 20, 20, duration=30, dt=0.2, approach=2).log
    path = write_log(log, tmp_path / "zz.csv")
    with pytest.warns(ShipidWarning, match=r"--columns delta=rudr: the file has no column "
                                           r"'rudr', so its own 'delta' is read"):  # fmt: skip
        read = read_log(path, columns={"rudr": "delta"})
    np.testing.assert_array_equal(read["delta"], log["delta"])
    rows = np.zeros((40, 11))
    rows[:, 0], rows[:, 5], rows[:, 10] = np.arange(40) * 0.1, 8.0, 90.0
    marin = tmp_path / "MARIN_FREE_KVLCC2_zz_20_m.dat"
    marin.write_text("MARIN\nZig-zag\n" + "\n".join("\t".join(f"{x:.2E}" for x in row)
                                                    for row in rows), encoding="ascii")  # fmt: skip
    with pytest.warns(ShipidWarning, match=r"--columns delta=rudder and --degrees psi not "
                                           r"applied: --format simman-marin reads the file's "
                                           r"own columns and units"):  # fmt: skip
        read = read_log(marin, fmt="simman-marin", columns={"rudder": "delta"}, degrees=("psi",))
    pd.testing.assert_frame_equal(read, read_simman_marin(marin))


def test_a_marin_record_that_starts_after_zero_keeps_its_times(tmp_path):
    """MARIN's three-digit times are rebuilt uniform between the first and the last: a record
    that starts at 50 s was stretched from 0 over its end time (its step 1.34 times too long)."""
    t = np.linspace(50.0, 70.0, 201)  # 0.1 s, printed 5.00E+01, 5.01E+01, ...
    rows = np.zeros((t.size, 11))
    rows[:, 0], rows[:, 5], rows[:, 10] = t, 8.0, 90.0  # t, dx0/dt, n [rpm]
    path = tmp_path / "MARIN_FREE_KVLCC2_part_m.dat"
    path.write_text("MARIN(Maritime Research Institute Netherlands)\nZig-zag : 20 / -20\n\n"
                    + "\n".join("\t".join(f"{x:.2E}" for x in row) for row in rows) + "\n",
                    encoding="ascii")  # fmt: skip
    log = read_log(path, fmt="simman-marin")
    np.testing.assert_allclose(log["t"], t, rtol=0, atol=1e-12)
    scaled = read_log(path, fmt="simman-marin", scale=45.7)
    np.testing.assert_allclose(scaled["t"], t / math.sqrt(45.7), rtol=1e-13)
    rows[:, 0] = 50.0
    path.write_text("MARIN\nZig-zag\n" + "\n".join("\t".join(f"{x:.2E}" for x in row)
                                                    for row in rows), encoding="ascii")  # fmt: skip
    with pytest.raises(ShipidError, match="time runs from 50 to 50 s, not forward"):
        read_log(path, fmt="simman-marin")


@needs_data
def test_imported_marin_file_identifies_as_is(tmp_path, capsys):
    csv = tmp_path / "zz20.csv"
    code, _, err = run(["import", "--format", "simman-marin", "--scale", "45.7", MARIN_ZZ20,
                        "-o", csv], capsys)  # fmt: skip
    assert code == 0, err
    code, _, err = run(["identify", csv, "--model", "blanke-speed", "-o", tmp_path / "m.json"],
                       capsys)  # fmt: skip
    assert code == 0, err


@needs_data
def test_imported_osaka_log_keeps_its_rudder_convention(tmp_path, capsys):
    imported = tmp_path / "zz.csv"
    assert run(["import", "--format", "osaka-frt", "--start", "auto", "--end", "auto", OSAKA_3030,
                "-o", imported], capsys)[0] == 0  # fmt: skip
    direct = read_log(OSAKA_3030, fmt="osaka-frt", start="auto", end="auto")
    back = read_log(imported)
    assert back.attrs["rudder_positive"] == "starboard" == direct.attrs["rudder_positive"]
    assert back.attrs["ship"] == "Esso Osaka 3 m model"
    # The files do not say which ship the 3 m model is of: no scale, where 1 said full scale.
    assert "scale" not in direct.attrs and "scale" not in back.attrs
    from shipid.evaluation.validate import validate
    from shipid.identification.identify import identify

    fit = identify(direct, model="blanke-rps")
    a, b = validate(fit.model, direct)[0], validate(fit.model, back)[0]
    for key in ("first_overshoot_deg", "second_overshoot_deg"):
        assert a.indices["closed_loop"][key] == pytest.approx(b.indices["closed_loop"][key])


def test_uniformity_judged_with_a_relative_tolerance(trial):
    from shipid.identification.regression import sampling_time

    jittered = trial.copy()
    jittered["t"] = jittered["t"] * (1 + 1e-7 * np.sin(np.arange(len(trial))))  # printed times
    assert sampling_time(jittered) == pytest.approx(0.2)
    uneven = trial.copy()
    uneven.loc[5:, "t"] += 0.05
    with pytest.raises(ShipidError, match="not uniform.*--dt"):
        sampling_time(uneven)


# ---------------------------------------------------------------------------- 4, 5, 16, 21: outputs
def test_output_honours_the_umask_and_keeps_a_replaced_files_mode(tmp_path, trial):
    old = os.umask(0o022)
    try:
        path = write_log(trial, tmp_path / "a.csv")
        assert stat.S_IMODE(path.stat().st_mode) == 0o644
        os.chmod(path, 0o600)
        write_log(trial, path)
        assert stat.S_IMODE(path.stat().st_mode) == 0o600
    finally:
        os.umask(old)


@pytest.mark.parametrize("cmd", [
    ["import", "{log}", "-o", "{d}/turn.xlsx"],
    ["identify", "{log}", "-o", "{d}/model.txt"],
    ["validate", "{model}", "{log}", "--json", "{d}/v.csv"],
    ["manoeuvre", "kvlcc2", "turning", "--duration", "20", "-o", "{d}/tc.xlsx"],
])  # fmt: skip
def test_unknown_output_extensions_are_refused_before_any_work(tmp_path, trial_csv, capsys, cmd):
    model = tmp_path / "m.json"
    assert run(["identify", trial_csv, "-o", model], capsys)[0] == 0
    argv = [a.format(log=trial_csv, d=tmp_path, model=model) for a in cmd]
    code, _, err = run(argv, capsys)
    assert code == 1 and "unknown extension" in err and err.count("\n") == 1
    assert not list(tmp_path.glob("turn.xlsx")) and not list(tmp_path.glob("*.tmp"))


@pytest.mark.parametrize("cmd", [
    ["identify", "{log}", "-o", "{log}"],
    ["validate", "{model}", "{log}", "--json", "{model}"],
    ["simulate", "{model}", "{log}", "-o", "{log}"],
    ["import", "{log}", "-o", "{link}"],
    # The prior and the particulars are read too: `identify LOG --prior m.json -o m.json`
    # overwrote the prior with the fit.
    ["identify", "{log}", "--prior", "{model}", "-o", "{model}"],
    ["select", "{log}", "--prior", "{model}", "-o", "{model}"],
    ["compare", "{log}", "--particulars", "{part}", "--json", "{part}"],
    ["validate", "{model}", "{log}", "--particulars", "{part}", "--json", "{part}"],
    ["criteria", "{model}", "--particulars", "{part}", "--json", "{part}"],
    ["follow", "{model}", "--waypoints", "0,0;50,0", "--json", "{model}"],
])  # fmt: skip
def test_an_output_that_is_an_input_is_refused_and_the_input_kept(tmp_path, trial_csv, capsys,
                                                                   cmd):  # fmt: skip
    model = tmp_path / "m.json"
    assert run(["identify", trial_csv, "-o", model], capsys)[0] == 0
    link = tmp_path / "link.csv"
    link.symlink_to(trial_csv)
    part = tmp_path / "particulars.json"
    part.write_text('{"length": 4.0, "beam": 0.6, "draught": 0.2}')
    before = {p: p.read_bytes() for p in (trial_csv, model, part)}
    argv = [a.format(log=trial_csv, model=model, link=link, part=part) for a in cmd]
    code, _, err = run(argv, capsys)
    assert code == 1 and "is also an input" in err and err.count("\n") == 1
    assert {p: p.read_bytes() for p in before} == before


def test_output_through_a_symlink_writes_the_target(tmp_path, trial_csv, capsys):
    target = tmp_path / "real.csv"
    target.write_text("old")
    link = tmp_path / "out.csv"
    link.symlink_to(target)
    assert run(["import", trial_csv, "-o", link], capsys)[0] == 0
    assert link.is_symlink() and len(read_log(target)) == len(read_log(trial_csv))


@pytest.mark.parametrize(("out", "match"), [("", "empty path"), ("{file}/x.csv", "which is a file")])
def test_unwritable_output_paths_get_a_clear_message(tmp_path, trial_csv, capsys, out, match):
    code, _, err = run(["import", trial_csv, "-o", out.format(file=trial_csv)], capsys)
    assert code == 1 and match in err and "Errno" not in err


def test_plots_of_logs_with_the_same_file_name_do_not_overwrite_each_other(tmp_path, trial,
                                                                           capsys):  # fmt: skip
    a, b = tmp_path / "a" / "zz.csv", tmp_path / "b" / "zz.csv"
    for p in (a, b):
        p.parent.mkdir()
        write_log(trial, p)
    model = tmp_path / "m.json"
    # (the fit's own options are not the point: the quickest)
    assert run(["identify", a, "--filter", "none", "--no-output-error", "-o", model],
               capsys)[0] == 0  # fmt: skip
    assert run(["validate", model, a, b, "--no-bands", "--plots", tmp_path / "plots"],
               capsys)[0] == 0  # fmt: skip
    assert sorted(p.name for p in (tmp_path / "plots").iterdir()) == ["zz-2.png", "zz.png"]


def test_a_failed_multi_output_command_leaves_no_files(tmp_path, trial_csv, capsys, monkeypatch):
    """validate with --json and --plots: when the figures fail, the JSON is not written either."""
    import shipid.reporting.plots as plots

    model = tmp_path / "m.json"
    assert run(["identify", trial_csv, "-o", model], capsys)[0] == 0

    def broken(*args, **kwargs):
        raise OSError("disk full")

    monkeypatch.setattr(plots, "measured_vs_simulated", broken)
    code, _, err = run(["validate", model, trial_csv, "--json", tmp_path / "v.json", "--plots",
                        tmp_path / "plots"], capsys)  # fmt: skip
    assert code == 1 and "disk full" in err
    assert not (tmp_path / "v.json").exists() and not (tmp_path / "plots").exists()
    assert not list(tmp_path.glob(".*.tmp"))


# ---------------------------------------------------------------------------- 18, 23: model files
@pytest.fixture(scope="module")
def identified(tmp_path_factory, trial):
    folder = tmp_path_factory.mktemp("identified")
    write_log(trial, folder / "zz.csv")
    return identify_in(folder)


@pytest.fixture()
def model_doc(tmp_path, trial_csv, identified):
    """The trial's model by plain identify (``trial_csv`` is the same log in the same folder)."""
    _, model = copy_identified(identified, tmp_path)
    return model, json.loads(model.read_text())


@pytest.mark.parametrize(("edit", "match"), [
    (lambda d: d["model"]["coefficients"]["r"].update({"delta": float("nan")}), "NaN is not"),
    (lambda d: d["model"]["coefficients"]["r"].update({"delta": float("inf")}), "Infinity is not"),
    (lambda d: d["model"]["coefficients"]["r"].update({"delta": "x"}), r"model\.coefficients\.r\.delta"),
    (lambda d: d["model"]["structure"].update({"terms": "u v r"}), r"model\.structure\.terms"),
    (lambda d: d.update({"identification": "yes"}), "identification must be"),
    (lambda d: d.update({"identification": [1]}), "identification must be"),
    (lambda d: d["identification"]["preprocessing"].update({"approach_speed": "fast"}),
     "approach_speed"),
    (lambda d: d["model"]["structure"]["terms"]["u"].append("w^2"), "unknown signal 'w'"),
    # Read as 0 before: a ship without its yaw coefficients never turned, and nothing said so.
    (lambda d: d["model"]["coefficients"].pop("r"),
     r"model\.coefficients\.r has no value for '\|u\|\*r'"),
    (lambda d: d["model"]["coefficients"]["v"].pop("u*r"), r"coefficients\.v has no value for 'u\*r',"),
])  # fmt: skip
@pytest.mark.parametrize("command", ["validate", "simulate", "manoeuvre"])
def test_malformed_model_files_give_one_line(tmp_path, trial_csv, capsys, model_doc, edit, match,
                                             command):  # fmt: skip
    path, doc = model_doc
    edit(doc)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(doc, allow_nan=True))
    argv = {"validate": ["validate", bad, trial_csv],
            "simulate": ["simulate", bad, trial_csv, "-o", tmp_path / "s.csv"],
            "manoeuvre": ["manoeuvre", bad, "zigzag", "--duration", "20"]}[command]
    code, _, err = run(argv, capsys)
    assert code == 1 and err.startswith("shipid: error:") and err.count("\n") == 1, err
    assert __import__("re").search(match, err), err


def test_version_1_model_files_still_load(tmp_path, model_doc):
    from shipid.reporting.modelfile import load_model

    _, doc = model_doc
    doc["version"] = 1
    doc["provenance"].pop("model_sha256")  # version 1 kept none
    doc["model"]["structure"]["terms"]["u"] = ["|u|u", "vr", "r^2", "delta^2", "1"]
    old = {"|u|u": 1.0, "vr": 2.0, "r^2": 0.0, "delta^2": 3.0, "1": 4.0}
    doc["model"]["coefficients"]["u"] = old
    (tmp_path / "v1.json").write_text(json.dumps(doc))
    m = load_model(tmp_path / "v1.json")
    assert m.coefficients["u"]["v*r"] == 2.0 and m.coefficients["u"]["vr"] == 2.0


# ---------------------------------------------------------------------------- 13, 14: readers
@needs_data
def test_hsva_reader_model_scale_body_axes_port_positive():
    log = read_log(HSVA, fmt="simman-hsva")
    assert len(log) == 3801 and np.diff(log["t"]).max() == pytest.approx(0.05)
    assert log.attrs["rudder_positive"] == "port" and log.attrs["scale"] == 45.7
    assert log["u"].iloc[0] == pytest.approx(1.1775, abs=1e-3) and abs(log["v"].iloc[0]) < 1e-3
    assert log["n"].mean() == pytest.approx(10.23, abs=0.01) and "thrust" in log.columns
    # Starting to port with positive rudder: the heading first goes negative.
    from shipid.trials.indices import manoeuvre_indices

    ind = manoeuvre_indices(log)
    assert ind["kind"] == "zigzag" and ind["switch_heading_deg"] == pytest.approx(10, abs=1.0)
    k = int(np.argmax(np.abs(log["delta"].to_numpy()) > np.radians(5)))
    assert log["delta"].iloc[k] > 0 and log["psi"].iloc[k + 100] < 0


@needs_data
@pytest.mark.parametrize(("path", "fmt"), [(MARIN_ZZ20, "simman-marin"), (HSVA, "simman-hsva"),
                                           (OSAKA_3030, "osaka-frt")])  # fmt: skip
def test_a_known_format_read_without_format_names_it(capsys, path, fmt):
    # It stopped with "read it with --format"; it is read as that format, and says so.
    code, out, err = run(["indices", path], capsys)
    assert code == 0, err
    assert f"not a canonical log; read as {fmt}, whose layout it has (--format {fmt}" in err
    code, given, _ = run(["indices", path, "--format", fmt], capsys)
    assert code == 0 and out == given


def test_an_osaka_file_with_text_in_a_column_names_it(tmp_path, capsys):
    """A cell that is not a number: the file's own column and the data row, no output file
    (it said "a column is not numeric")."""
    from shipid.data.formats import OSAKA_COLUMNS

    t = np.arange(40) * 0.1
    df = pd.DataFrame({c: t if c.startswith("t ") else 0.1 + 0 * t for c in OSAKA_COLUMNS})
    df = df.astype(object)
    df.iloc[17, 2] = "abc"
    path = tmp_path / "frt.csv"
    df.to_csv(path, index=False)
    code, _, err = run(["import", "--format", "osaka-frt", path, "-o", tmp_path / "out.csv"],
                       capsys)  # fmt: skip
    column = list(OSAKA_COLUMNS)[2]
    assert code == 1 and f"column {column!r} is not numeric at data row 18 ('abc'" in err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "out.csv").exists()


def test_an_osaka_file_with_empty_cells_is_refused_by_rows_or_filled(tmp_path, capsys):
    """A sensor's dropout leaves cells empty mid-run (a wind vane's, a heading that wraps
    around it): the reader refused the file at its first ("column 'wind_speed' is empty at data
    row 1001") even with --fill-gaps, which a canonical log's empty cells take. Now the same
    check as a canonical log's: the rows and times named, or --fill-gaps interpolates them (the
    heading unwrapped around them, so across ±π it goes on, not back)."""
    from shipid.data.formats import OSAKA_COLUMNS

    t = np.arange(60) * 0.1
    psi = np.angle(np.exp(1j * (3.0 + 0.05 * np.arange(60))))  # wrapped past +π at row 3
    df = pd.DataFrame({c: t if c.startswith("t ") else 0.1 + 0 * t for c in OSAKA_COLUMNS})
    df["psi_hat [rad]"] = psi
    df.loc[20:22, "u_velo [m/s]"] = np.nan
    df.loc[2:4, "psi_hat [rad]"] = np.nan
    path = tmp_path / "frt.csv"
    df.to_csv(path, index=False)
    out = tmp_path / "out.csv"
    code, _, err = run(["import", "--format", "osaka-frt", path, "-o", out], capsys)
    assert code == 1 and "column 'u' has 3 missing values at data rows 21–23 (t = 2–2.2)" in err
    assert "--fill-gaps" in err and not out.exists()
    code, _, err = run(["import", "--format", "osaka-frt", "--fill-gaps", path, "-o", out], capsys)
    assert code == 0, err
    log = read_log(out)
    assert np.allclose(log["psi"], 3.0 + 0.05 * np.arange(60))  # unwrapped, the gap filled
    assert np.allclose(log["u"], 0.1)


def test_an_unknown_vessel_lists_the_known_ones(capsys):
    code, _, err = run(["manoeuvre", "titanic", "turning"], capsys)
    assert code == 1 and "scale-ship, mariner, kvlcc2" in err


# ---------------------------------------------------------------------------- 17, 19: types, units
def _write(tmp_path, df, name="log.parquet"):
    path = tmp_path / name
    if name.endswith(".parquet"):
        df.to_parquet(path, index=False)
    else:
        df.to_csv(path, index=False)
    return path


def test_a_column_named_twice_is_refused(tmp_path, trial, capsys):
    """Two columns named u: pandas read the second as 'u.1' and the log's u was the first,
    without a word. A name with a dot that is no repeat is read as before."""
    df = trial.copy()
    df.insert(3, "u_twice", 2 * df["u"])
    df.columns = ["u" if c == "u_twice" else c for c in df.columns]
    path = _write(tmp_path, df, "twice.csv")
    code, _, err = run(["identify", path, "-o", tmp_path / "m.json"], capsys)
    assert code == 1 and "column 'u' appears more than once in the header (columns 3, 4)" in err
    dotted = _write(tmp_path, trial.assign(**{"depth.m": 10.0}), "dotted.csv")
    assert len(read_log(dotted)) == len(trial)


def test_datetime_time_becomes_seconds(tmp_path, trial):
    df = trial.copy()
    df["t"] = pd.Timestamp("2020-07-31 13:04:24") + pd.to_timedelta(df["t"], unit="s")
    log = read_log(_write(tmp_path, df))
    np.testing.assert_allclose(log["t"], trial["t"] - trial["t"].iloc[0], atol=1e-6)
    assert log.attrs["time_origin"].startswith("2020-07-31 13:04:24")


@pytest.mark.parametrize(("start", "write"), [
    # A CSV has no datetime type: its times are text. Both were refused as non-numeric.
    ("2020-07-31 13:04:24", lambda s: s.astype(str)),
    ("2020-07-31 13:04:24", lambda s: s.dt.strftime("%Y-%m-%dT%H:%M:%S.%fZ")),
    ("2020-07-31 13:04:24", lambda s: s.dt.strftime("%Y-%m-%dT%H:%M:%S.%f+02:00")),
    ("2020-07-31 13:04:24", lambda s: s.dt.strftime("%H:%M:%S.%f")),
    ("2020-07-31 23:59:30", lambda s: s.dt.strftime("%H:%M:%S.%f")),  # past midnight
])  # fmt: skip
def test_times_a_csv_writes_as_text_become_seconds(tmp_path, trial, start, write):
    df = trial.copy()
    df["t"] = write(pd.Timestamp(start) + pd.to_timedelta(df["t"], unit="s"))
    log = read_log(_write(tmp_path, df, "log.csv"))
    np.testing.assert_allclose(log["t"], trial["t"] - trial["t"].iloc[0], atol=1e-9)
    origin, first = log.attrs["time_origin"], df["t"].iloc[0]
    # A date's origin is the same instant, in UTC; a time of day's is as written.
    assert origin == first if ":" in first[:3] else (pd.Timestamp(origin)
                                                     == pd.to_datetime(first, utc=True))


def test_a_unit_on_text_times_is_refused(tmp_path, trial):
    """Read as seconds, then scaled by the header's [ms]: 1000 times too short, without a word."""
    df = trial.copy()
    df["t"] = (pd.Timestamp("2020-07-31 13:04:24")
               + pd.to_timedelta(df["t"], unit="s")).dt.strftime("%H:%M:%S.%f")
    df = df.rename(columns={"t": "t [ms]"})
    with pytest.raises(ShipidError, match="'t' holds dates or times of day.* drop the unit"):
        read_log(_write(tmp_path, df, "log.csv"))


@pytest.mark.parametrize(("row", "value", "match"), [
    (5, "13:04:25.x", r"'t' is a time of day \(hh:mm:ss\) at data row 1 .* not at data row 6"),
    (5, "yesterday", r"'t' is an ISO date and time at data row 1 .* not at data row 6"),
    (5, "", r"'t' is missing at data rows? 6"),
])  # fmt: skip
def test_a_text_time_that_does_not_parse_is_named_with_its_row(tmp_path, trial, row, value,
                                                               match):
    df = trial.copy()
    stamps = pd.Timestamp("2020-07-31 13:04:24") + pd.to_timedelta(df["t"], unit="s")
    df["t"] = (stamps.dt.strftime("%H:%M:%S.%f") if "hh:mm" in match else stamps.astype(str))
    df["t"] = df["t"].astype(object)
    df.loc[row, "t"] = value or None
    with pytest.raises(ShipidError, match=match):
        read_log(_write(tmp_path, df, "log.csv"))


@pytest.mark.parametrize(("change", "match"), [
    (lambda d: d.assign(psi=np.degrees(d["psi"])), "psi looks like degrees"),
    (lambda d: d.assign(t=d["t"] * 1000), "not seconds|milliseconds"),
    (lambda d: d.assign(u=d["u"] > 1), "true/false"),
    (lambda d: d.assign(u=d["u"] * 3.6 * 20), "not a ship speed"),
    (lambda d: d.assign(r=np.degrees(d["r"])), "'r' reaches .* looks like degrees"),
    # Was read as radians without a word (a relative wind's angle in degrees, 0–360).
    (lambda d: d.assign(wind_speed=3.0, wind_angle=np.linspace(0.0, 359.0, len(d))),
     "'wind_angle' reaches 359, which looks like degrees; give --degrees wind_angle"),
    (lambda d: d.assign(psi=-d["psi"]), "opposite sign conventions"),
])  # fmt: skip
def test_misread_units_and_types_are_refused(tmp_path, trial, change, match):
    path = _write(tmp_path, change(trial.copy()))
    with pytest.raises(ShipidError, match=match):
        read_log(path)


def test_yaw_rate_in_degrees_on_a_gentle_manoeuvre_is_caught_by_the_heading(tmp_path):
    # A 5°/5° zig-zag turns at under 3 °/s, so only ψ̇ = r tells degrees from radians.
    log = zigzag(scale_ship(rudder_rate_deg=9.6), 5, 5, duration=60, dt=0.2).log
    assert np.degrees(log["r"]).abs().max() < 3
    with pytest.raises(ShipidError, match="r looks like degrees per second; give --degrees r"):
        read_log(_write(tmp_path, log.assign(r=np.degrees(log["r"]))))


@pytest.mark.parametrize(("column", "header", "said"), [
    ("psi", "psi [deg]", "the heading 'psi', read in degrees (its header or --degrees psi), "
                         "changes 57.3 times slower than the yaw rate 'r' says: psi looks like "
                         "radians already"),
    ("r", "r [deg/s]", "the heading 'psi' changes 57.3 times faster than the yaw rate 'r', read "
                       "in degrees per second (its header or --degrees r), turns: r looks like "
                       "radians per second already"),
])  # fmt: skip
def test_a_header_in_degrees_over_radians_names_its_own_column(tmp_path, trial, column, header,
                                                               said):  # fmt: skip
    """A heading whose header said '[deg]' over values in radians was refused with "r looks
    like degrees per second; give --degrees r": the right column named wrong."""
    path = _write(tmp_path, trial.rename(columns={column: header}))
    with pytest.raises(ShipidError, match=re.escape(said)):
        read_log(path)


def test_over_long_lines_are_refused_quickly(tmp_path):
    path = tmp_path / "wide.csv"
    path.write_text(",".join(f"c{i}" for i in range(200_000)) + "\n0\n")
    with pytest.raises(ShipidError, match="line 1 is .* characters long"):
        read_log(path)


def test_missing_column_from_the_api_is_a_named_error(trial):
    from shipid.identification.identify import identify

    with pytest.raises(ShipidError, match="column 'n'"):
        identify(trial, model="blanke-rps")


def test_a_log_that_cannot_be_validated_is_named_once(tmp_path):
    """A model with wind terms on a log without the wind: the message named the file twice
    (its path, then its file name), 'DIR/zz.csv: zz.csv: the model needs ...'."""
    from shipid.dynamics.model import ManoeuvringModel
    from shipid.evaluation.validate import validate

    model = ManoeuvringModel("u: |u|*u, U_A^2*cos(gamma_A); v: u*v, delta; r: u*r, delta",
                             {"u": {"|u|*u": -0.05}, "v": {"u*v": -0.5, "delta": 0.05},
                              "r": {"u*r": -0.8, "delta": -0.1}})  # fmt: skip
    path = write_log(zigzag(scale_ship(), 20, 20, duration=30, dt=0.2).log, tmp_path / "zz.csv")
    (v,) = validate(model, [read_log(path)], names=[str(path)])
    assert v.error.startswith(f"{path}: the model needs the log column 'wind_speed'"), v.error
    assert v.error.count("zz.csv") == 1


def test_a_log_at_another_scale_than_the_training_logs_is_named(tmp_path, capsys):
    """A model identified from model-scale logs, validated on a full-scale file read without
    --scale (the MARIN files' default), only said 'extrapolating'. The model file keeps its
    training logs' scale (rescaled with it); validate names the mismatch and the remedy."""
    log = zigzag(scale_ship(), 20, 20, duration=60, dt=0.2).log
    lam = log.attrs["scale"]
    assert lam > 1
    train = write_log(log, tmp_path / "train.csv")
    model = tmp_path / "m.json"
    assert run(["identify", train, "--filter", "none", "-o", model], capsys)[0] == 0
    assert json.loads(model.read_text())["identification"]["preprocessing"]["log_scale"] == lam
    other = log.copy()
    other.attrs = {**log.attrs, "scale": 1.0}
    full = write_log(other, tmp_path / "full.csv")
    code, _, err = run(["validate", model, full], capsys)
    assert code == 0, err
    assert f"at scale 1:1 and the model's training logs were at 1:{lam:g}" in err
    # A canonical log takes no --scale (only MARIN's reader Froude-scales by it): rescale.
    assert f"shipid rescale --factor {lam:g}" in err and "--scale" not in err
    code, _, err = run(["validate", model, train], capsys)
    assert "training logs were at" not in err
    code, _, err = run(["simulate", model, full, "-o", tmp_path / "sim.csv"], capsys)
    assert code == 0 and f"shipid rescale --factor {lam:g}" in err
    rescaled = tmp_path / "full.json"
    assert run(["rescale", model, "--factor", str(lam), "-o", rescaled], capsys)[0] == 0
    prep = json.loads(rescaled.read_text())["identification"]["preprocessing"]
    assert prep["log_scale"] == pytest.approx(1.0)


def test_criteria_judge_a_model_at_its_training_logs_scale(tmp_path, capsys):
    """`criteria` of a model identified from model-scale logs, without particulars: it judged
    the ship at λ = 1 (the KVLCC2's 7 m model by the 10/10 limits 10° and 25° of an L/V of
    5.8 s, where at full scale its L/V is 39 s and the limits 20° and 40°). The training logs'
    scale is the default; with none known, λ = 1 is said."""
    from shipid.trials.criteria import overshoot_limits

    log = zigzag(scale_ship(), 20, 20, duration=60, dt=0.2).log
    lam = log.attrs["scale"]
    model = tmp_path / "m.json"
    assert run(["identify", write_log(log, tmp_path / "zz.csv"), "--filter", "none",
                "--no-output-error", "-o", model], capsys)[0] == 0  # fmt: skip
    L = 4.0
    code, _, err = run(["criteria", model, "--length", L, "--dt", 0.2, "--no-bands",
                        "--json", tmp_path / "c.json"], capsys)  # fmt: skip
    assert code == 0, err
    doc = json.loads((tmp_path / "c.json").read_text())
    c = doc["conditions"]
    assert c["scale"] == pytest.approx(lam)
    assert c["L_over_V_full_scale"] == pytest.approx(L / c["speed"] * math.sqrt(lam))
    limits = {r["criterion"]: r["limit"] for r in doc["criteria"]}
    first, second = overshoot_limits(L / c["speed"] * math.sqrt(lam))
    assert limits["10/10 first overshoot"] == pytest.approx(first)
    assert limits["10/10 second overshoot"] == pytest.approx(second)
    assert "scale λ is not known" not in err
    code, _, err = run(["criteria", model, "--length", L, "--dt", 0.2, "--no-bands", "--scale",
                        "1", "--json", tmp_path / "c1.json"], capsys)  # fmt: skip
    assert json.loads((tmp_path / "c1.json").read_text())["conditions"]["scale"] == 1.0
    unknown = log.copy()
    unknown.attrs = {k: v for k, v in log.attrs.items() if k != "scale"}
    plain = tmp_path / "plain.json"
    assert run(["identify", write_log(unknown, tmp_path / "plain.csv"), "--filter", "none",
                "--no-output-error", "-o", plain], capsys)[0] == 0  # fmt: skip
    code, _, err = run(["criteria", plain, "--length", L, "--dt", 0.2, "--no-bands",
                        "--json", tmp_path / "c2.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert json.loads((tmp_path / "c2.json").read_text())["conditions"]["scale"] == 1.0
    assert "the scale λ is not known" in err and "judged as a full-scale ship" in err


def test_validate_judges_a_measured_zigzag_at_the_logs_scale(tmp_path, capsys):
    """validate's criteria of the logs took λ from the particulars alone: a model-scale 10/10
    zig-zag with particulars that give no scale was judged by the limits of its model-scale
    L/V. The log's own scale is the default."""
    from shipid.trials.criteria import overshoot_limits

    log = zigzag(scale_ship(), 10, 10, duration=60, dt=0.2).log
    lam = log.attrs["scale"]
    path = write_log(log, tmp_path / "zz.csv")
    (tmp_path / "p.yml").write_text("length: 10.0\n")  # L/V 5 s here, 20 s at full scale
    from shipid.vessels import scale_ship_model

    model = scale_ship_model().save(tmp_path / "m.json")
    code, out, err = run(["validate", model, path, "--particulars", tmp_path / "p.yml"], capsys)
    assert code == 0, err
    rows = {line.split("|")[2].strip(): line.split("|") for line in out.splitlines()
            if line.startswith("|") and "10/10" in line}  # fmt: skip
    speed = float(log["u"].iloc[: max(1, len(log) // 50)].mean())
    first, second = overshoot_limits(10.0 / speed * math.sqrt(lam))
    assert first > 10.0 and second > 25.0  # not the model-scale L/V's 10° and 25°
    assert float(rows["10/10 first overshoot"][4]) == pytest.approx(first, abs=0.05)  # 3 digits
    assert float(rows["10/10 second overshoot"][4]) == pytest.approx(second, abs=0.05)


def test_a_fit_at_a_finer_dt_than_its_logs_is_warned(tmp_path, capsys, trial):
    """identify --dt 0.05 on a log sampled at 0.1 s fitted interpolated samples without a
    word: the noise check then read r's sensor noise as none (an Esso zig-zag's free runs
    'missed by 2.17e+13 times the noise') and the fit was no better. validate may run finer."""
    from shipid.data.preprocess import resample, white_noise_variance

    rng = np.random.default_rng(3)
    noisy = trial.copy()
    noisy["r"] = noisy["r"] + rng.normal(0.0, 1e-3, len(noisy))
    assert "measured_dt" not in resample(noisy, 0.2).attrs
    assert "measured_dt" not in resample(noisy, 0.4).attrs
    fine = resample(noisy, 0.1)
    assert fine.attrs["measured_dt"] == pytest.approx(0.2)
    # Why it matters: the noise read from interpolated samples is none.
    assert white_noise_variance(fine["r"].to_numpy()) < 1e-3 * white_noise_variance(
        noisy["r"].to_numpy())  # fmt: skip
    path = write_log(noisy, tmp_path / "zz.csv")
    code, _, err = run(["identify", path, "--dt", "0.1", "--filter", "none",
                        "-o", tmp_path / "m.json"], capsys)  # fmt: skip
    assert code == 0, err
    assert "--dt 0.1 s is finer than its own sampling (0.2 s)" in err
    assert "measured_dt" not in json.dumps(json.loads((tmp_path / "m.json").read_text()))
    code, _, err = run(["identify", path, "--dt", "0.4", "--filter", "none",
                        "-o", tmp_path / "m2.json"], capsys)  # fmt: skip
    assert code == 0 and "finer than its own sampling" not in err
    code, _, err = run(["validate", tmp_path / "m.json", path, "--dt", "0.1"], capsys)
    assert code == 0 and "finer than its own sampling" not in err


def test_a_hand_edited_model_file_drops_the_fits_intervals(tmp_path, capsys, trial_csv):
    """A model file whose coefficient was edited by hand kept the bootstrap intervals and the
    standard errors of the fit: validate printed a tactical diameter of 27.62 m beside its
    interval [18.53, 18.6] m, the one of the coefficients before the edit. The file carries its
    model's fingerprint; an edited model's fit records are left out, with a warning."""
    import warnings

    from shipid.errors import ShipidWarning
    from shipid.reporting.modelfile import load_document
    from shipid.vessels import scale_ship_model

    model = tmp_path / "m.json"
    assert run(["identify", trial_csv, "--filter", "none", "--no-output-error", "--bootstrap",
                "10", "-o", model], capsys)[0] == 0  # fmt: skip
    doc = json.loads(model.read_text())
    assert doc["provenance"]["model_sha256"]
    same = tmp_path / "same.json"
    doc["model"]["name"] = "renamed"  # a name is not a coefficient
    same.write_text(json.dumps(doc))  # another layout, the same numbers
    edited = tmp_path / "edited.json"
    doc["model"]["coefficients"]["r"]["delta"] *= 0.5
    edited.write_text(json.dumps(doc, indent=1))
    plain = scale_ship_model().save(tmp_path / "plain.json")
    rescaled = tmp_path / "big.json"
    assert run(["rescale", model, "--factor", "4", "-o", rescaled], capsys)[0] == 0
    for path in (model, same, plain, rescaled):
        with warnings.catch_warnings():
            warnings.simplefilter("error", ShipidWarning)
            loaded = load_document(path)
        assert bool(loaded.get("uncertainty")) == (path != plain)
    with pytest.warns(ShipidWarning, match="edited.json: the model's coefficients are not those "
                      "it was fitted with") as caught:  # fmt: skip
        loaded = load_document(edited)
    assert "bootstrap intervals and the standard errors" in str(caught[0].message)
    assert loaded["uncertainty"] is None
    assert all(d["std_errors"] is None for d in loaded["identification"]["diagnostics"].values())
    code, out, err = run(["validate", edited, trial_csv, "--report", tmp_path / "rep"], capsys)
    assert code == 0, err
    assert "not those it was fitted with" in err
    assert "standard error of each coefficient" not in (tmp_path / "rep" / "report.html").read_text(
        encoding="utf-8")  # fmt: skip
    code, out, err = run(["validate", same, trial_csv, "--report", tmp_path / "rep0"], capsys)
    assert code == 0 and "fitted with" not in err
    assert "standard error of each coefficient" in (tmp_path / "rep0" / "report.html").read_text(
        encoding="utf-8")  # fmt: skip


PARTICULARS = {"length": 3.0, "beam": 0.489, "draught": 0.201, "mass": 244.6}


@pytest.mark.parametrize(("other", "said"), [
    ({"scale": 1.0}, r"full_scale.csv is at scale 1:1 and \S*model_scale.csv at 1:16.95: the logs "
                     "of one fit must be at one scale"),
    ({"ship": "Esso Osaka 3 m model"}, r"full_scale.csv is a log of ship 'Esso Osaka 3 m model' "
                                       r"and \S*model_scale.csv of 'scale-ship': the logs of one "
                                       "fit must be of one ship"),
    ({"particulars": {**PARTICULARS, "length": 7.0}},
     r"full_scale.csv's particulars give a length of 7 and \S*model_scale.csv's 3: the logs of "
     "one fit must be of one ship"),
])  # fmt: skip
def test_logs_of_two_ships_or_scales_are_not_fitted_together(tmp_path, capsys, other, said):
    """A model-scale and a full-scale run fitted together mix two time scales; the KVLCC2's and
    the Esso Osaka's logs fitted together were written as one model, with the first log's
    particulars for both, without a word. identify, select, compare and correct refuse them in
    one line naming both files; so do identify(), select() and the cross-validation of the
    Python API."""
    from shipid.evaluation.error_band import cross_validated_band
    from shipid.identification.identify import identify
    from shipid.identification.select import select

    log = zigzag(scale_ship(), 20, 20, duration=60, dt=0.2).log
    log.attrs["particulars"] = PARTICULARS
    a = write_log(log, tmp_path / "model_scale.csv")
    second = zigzag(scale_ship(), 10, 10, duration=60, dt=0.2).log
    second.attrs = {**log.attrs, **other}
    b = write_log(second, tmp_path / "full_scale.csv")
    for argv in (["identify", a, b, "-o", tmp_path / "m.json"],
                 ["select", a, b, "--library", "blanke", "-o", tmp_path / "m.json"],
                 ["correct", "scale-ship", a, b, "-o", tmp_path / "m.json"],
                 ["compare", a, b]):  # fmt: skip
        code, _, err = run(argv, capsys)
        lines = [ln for ln in err.splitlines() if not ln.startswith("warning:")]
        assert code == 1 and len(lines) == 1, err
        assert re.search(said, lines[0]), lines[0]
    assert not (tmp_path / "m.json").exists()
    for call in (lambda: identify([log, second], model="blanke"),
                 lambda: select([log, second], library="blanke"),
                 lambda: cross_validated_band(None, [log, second], ["a", "b"])):  # fmt: skip
        with pytest.raises(ShipidError, match="must be .*one (ship|scale)"):
            call()


def test_one_ship_however_its_name_is_spaced_is_fitted_and_a_model_names_its_ship(tmp_path,
                                                                                   capsys):
    """Names that differ in case and spacing alone are one ship; the model file keeps it, and
    validate and simulate say where a log is of another ship (by name, or by its particulars'
    main dimensions): a KVLCC2 model judged on an Esso Osaka log printed its errors as any
    other's."""
    log = zigzag(scale_ship(), 20, 20, duration=60, dt=0.2).log
    log.attrs["particulars"] = PARTICULARS
    a = write_log(log, tmp_path / "a.csv")
    second = zigzag(scale_ship(), 10, 10, duration=60, dt=0.2).log
    second.attrs = {**log.attrs, "ship": " Scale-Ship ", "particulars": {**PARTICULARS,
                                                                        "mass": 245.0}}
    b = write_log(second, tmp_path / "b.csv")
    model = tmp_path / "m.json"
    code, _, err = run(["identify", a, b, "--model", "blanke", "-o", model], capsys)
    assert code == 0, err
    assert json.loads(model.read_text())["identification"]["preprocessing"]["ship"] == "scale-ship"
    for attrs, said in (({"ship": "KVLCC2"}, "a log of ship 'KVLCC2', and the model was "
                                             "identified from logs of 'scale-ship'"),
                        ({"particulars": {**PARTICULARS, "beam": 0.6}},
                         "its particulars give a beam of 0.6, the model's training logs 0.489"),
                        ({}, None)):  # fmt: skip
        other = second.copy()
        other.attrs = {**log.attrs, **attrs}
        c = write_log(other, tmp_path / "c.csv")
        for argv in (["validate", model, c], ["simulate", model, c, "-o", tmp_path / "s.csv"]):
            code, _, err = run(argv, capsys)
            assert code == 0, err
            notes = [ln for ln in err.splitlines() if "it predicts another ship" in ln]
            assert (notes == []) if said is None else (len(notes) == 1 and said in notes[0]), err


def test_particulars_given_for_a_log_that_has_its_own_of_another_ship_are_named(tmp_path,
                                                                                 capsys):
    """``--particulars`` replaces a log's own (its header's, or its format's: the Esso Osaka's):
    the KVLCC2's 7 m particulars given for an Esso Osaka file judged its 3 m hull as a 7 m one,
    unsaid. A warning names both lengths; the file still wins, as given."""
    log = zigzag(scale_ship(), 20, 20, duration=60, dt=0.2).log
    log.attrs["particulars"] = PARTICULARS
    a = write_log(log, tmp_path / "a.csv")
    for given, warned in (({**PARTICULARS, "length": 7.0}, True), (PARTICULARS, False)):
        path = tmp_path / "p.yml"
        path.write_text("".join(f"{k}: {v}\n" for k, v in given.items()), encoding="utf-8")
        code, _, err = run(["identify", a, "--model", "blanke", "--particulars", path, "-o",
                            tmp_path / "m.json"], capsys)  # fmt: skip
        assert code == 0, err
        said = [ln for ln in err.splitlines() if "the file's replace them" in ln]
        expected = [f"warning: {a}: --particulars {path} gives a length of 7 where the log's own "
                    "particulars give 3: the file's replace them; check that both are of this "
                    "ship"] if warned else []  # fmt: skip
        assert said == expected, err
        document = json.loads((tmp_path / "m.json").read_text())
        assert document["particulars"]["length"] == given["length"]


@pytest.mark.parametrize(("columns", "what", "everywhere"), [
    ({"n": 10.0}, "the propeller speed n", {}),
    ({"wind_speed": 1.0, "wind_angle": 0.5}, "the relative wind", {}),
    ({"thrust": 50.0}, "the thrust", {}),
    ({"thrust": 50.0}, None, {"n": 10.0}),
])  # fmt: skip
def test_an_input_some_training_logs_lack_is_named(tmp_path, capsys, columns, what, everywhere):
    """An Esso Osaka file read without its propeller speed beside one with it was fitted by the
    paper's structure without n, unsaid (the two ran at 15 and 16.7 rps); a log without the
    wind beside one with it had the library's wind terms left out, the log unnamed. The thrust
    of one log (HSVA's KVLCC2 run beside MARIN's) is no input where every log has its rps."""
    a = write_log(zigzag(scale_ship(), 20, 20, duration=60, dt=0.2).log.assign(**columns,
                                                                               **everywhere),
                  tmp_path / "a.csv")  # fmt: skip
    b = write_log(zigzag(scale_ship(), 10, 10, duration=60, dt=0.2).log.assign(**everywhere),
                  tmp_path / "b.csv")
    both = write_log(zigzag(scale_ship(), 10, 10, duration=60, dt=0.2).log.assign(**columns,
                                                                                  **everywhere),
                     tmp_path / "c.csv")  # fmt: skip
    for logs, named in (([a, b], what is not None), ([a, both], False)):
        code, _, err = run(["identify", *logs, "--model", "blanke", "-o", tmp_path / "m.json"],
                           capsys)  # fmt: skip
        assert code == 0, err
        said = [ln for ln in err.splitlines() if "training logs, not in" in ln]
        assert len(said) == int(named), err
        if named:
            assert said[0].startswith(f"warning: {what} is logged in 1 of the 2 training logs, "
                                      f"not in {b}: "), said[0]  # fmt: skip


def test_a_log_given_twice_is_refused_by_name_or_as_a_copy(tmp_path, capsys):
    """A log given twice (a glob that overlaps, a copy under another name) was fitted twice as
    hard, and select's fold that held one out still fitted the other: its score was the fit's
    own samples, 0.43 of the spread for a 10/10 zig-zag "held out" from itself. One line, exit
    1, no file; through the Python API too."""
    from shipid.identification.select import select

    log = zigzag(scale_ship(), 10, 10, duration=60, dt=0.2).log
    a = write_log(log, tmp_path / "zz.csv")
    b = write_log(log, tmp_path / "copy.csv")
    other = write_log(zigzag(scale_ship(), 20, 20, duration=60, dt=0.2).log, tmp_path / "o.csv")
    for argv, said in (
            (["identify", a, other, tmp_path / "." / "zz.csv"], "zz.csv is given twice"),
            (["select", a, b, "--library", "blanke"], "copy.csv holds the same samples as"),
            (["compare", b, a], "zz.csv holds the same samples as"),
            (["correct", "scale-ship", a, b], "copy.csv holds the same samples as")):
        code, _, err = run([*argv, "-o", tmp_path / "m.json"] if argv[0] != "compare" else argv,
                           capsys)  # fmt: skip
        lines = [ln for ln in err.splitlines() if not ln.startswith("warning:")]
        assert code == 1 and len(lines) == 1, err
        assert said in lines[0] and lines[0].endswith("give each log once"), lines[0]
    assert not (tmp_path / "m.json").exists()
    with pytest.raises(ShipidError, match="^log 1 holds the same samples as log 0: "):
        select([log, log.copy()], library="blanke")
    code, _, err = run(["identify", a, other, "-o", tmp_path / "m.json"], capsys)
    assert code == 0, err


def test_scale_is_refused_where_it_would_be_ignored(tmp_path, capsys):
    """``--scale`` on a canonical or Osaka log was silently ignored: the user believed the log
    Froude-scaled. It is refused in one line."""
    path = write_log(zigzag(scale_ship(), 20, 20, duration=30, dt=0.2).log, tmp_path / "zz.csv")
    code, _, err = run(["identify", path, "--scale", "45.7", "-o", tmp_path / "m.json"], capsys)
    assert code == 1 and "--scale applies to the SIMMAN files" in err
    assert not (tmp_path / "m.json").exists()


# ---------------------------------------------------------------------------- header units
def _si_and_stated(trial):
    """The trial in SI, and written as a spreadsheet might: °, °/s, knots, rpm, ms."""
    si = trial[["t", "delta", "u", "v", "r", "psi", "x", "y"]].assign(n=10.0)
    stated = pd.DataFrame({
        "t [ms]": si["t"] * 1000, "delta [deg]": np.degrees(si["delta"]),
        "u [kn]": si["u"] * 3600 / 1852, "v [m/s]": si["v"], "r [°/s]": np.degrees(si["r"]),
        "psi [rad]": si["psi"], "x [m]": si["x"], "y [m]": si["y"], "n [rpm]": si["n"] * 60,
        "rudder_order [deg]": 1.0})  # fmt: skip
    return si, stated


def test_units_stated_in_the_header_are_converted(tmp_path, trial):
    si, stated = _si_and_stated(trial)
    path = tmp_path / "stated.csv"
    stated.to_csv(path, index=False)
    log = read_log(path)
    for c in si.columns:
        np.testing.assert_allclose(log[c], si[c], rtol=1e-12, atol=1e-12, err_msg=c)
    # Named by --columns, the file's own column keeps its unit.
    stated.rename(columns={"r [°/s]": "yaw_rate [deg/s]"}).to_csv(path, index=False)
    np.testing.assert_allclose(read_log(path, columns={"yaw_rate": "r"})["r"], si["r"],
                               rtol=1e-12)  # fmt: skip


def test_a_yaw_rate_in_degrees_per_second_is_read_so_without_a_heading(tmp_path, trial):
    """The bug: 'r [deg/s]' had its unit dropped and was read as rad/s. Without ψ to check it
    against and under 3 °/s (a big ship's turn), nothing said so."""
    slow = trial[["t", "delta", "u", "v", "r"]].assign(r=trial["r"] * 0.1)
    assert np.degrees(slow["r"]).abs().max() < 3
    path = tmp_path / "slow.csv"
    slow.assign(r=np.degrees(slow["r"])).rename(columns={"r": "r [deg/s]"}).to_csv(path,
                                                                                     index=False)
    np.testing.assert_allclose(read_log(path)["r"], slow["r"], rtol=1e-12)


def test_units_shipid_cannot_convert_or_that_contradict_degrees_are_refused(tmp_path, trial,
                                                                            capsys):  # fmt: skip
    _, stated = _si_and_stated(trial)
    path = tmp_path / "feet.csv"
    stated.rename(columns={"u [kn]": "u [ft/s]"}).to_csv(path, index=False)
    code, _, err = run(["identify", path, "-o", tmp_path / "m.json"], capsys)
    assert code == 1 and not (tmp_path / "m.json").exists()
    assert err.strip() == (f"shipid: error: {path}: column 'u' is in 'ft/s' by its header, which "
                           "shipid does not convert (it reads km/h, kn, knot, knots, kt, m/s); "
                           "convert the column, or drop the unit from its name")  # fmt: skip
    with pytest.raises(ShipidError, match="--degrees names 'psi', but its header says 'rad'"):
        read_log(_write(tmp_path, stated), degrees=("psi",))
    # Named in --degrees as the header says: converted once.
    np.testing.assert_allclose(read_log(_write(tmp_path, stated), degrees=("delta",))["delta"],
                               trial["delta"], rtol=1e-12)  # fmt: skip


@pytest.mark.parametrize(("sep", "decimal"), [(";", ","), (";", "."), ("\t", ".")])
def test_semicolon_and_tab_separated_files_read_as_comma_separated(tmp_path, trial, sep, decimal):
    cols = ["t", "delta", "u", "v", "r", "psi", "x", "y"]
    path = tmp_path / "spreadsheet.csv"
    trial[cols].to_csv(path, sep=sep, decimal=decimal, index=False)
    log = read_log(path)
    for c in cols:
        np.testing.assert_allclose(log[c], trial[c], rtol=1e-12, atol=1e-12, err_msg=c)
